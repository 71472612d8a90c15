/**
 * \file test_sensor_pairing.cpp
 * \brief gtest of SensorPairing: joint lookup by name, validation, drop counting, IMU pairing
 *        by stamp, sample intervals and gaps.
 */
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "jackal_aic/loop/sensor_pairing.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kValueTol = 1e-12;    // rad/s, m/s^2 (values are copied or averaged)
constexpr double kIntervalTol = 1e-9;  // s
constexpr double kT0 = 1000.0;         // s, an arbitrary non-zero start stamp

loop::SensorPairing::Config config()
{
  loop::SensorPairing::Config c;
  c.left_joints = { "front_left_wheel", "rear_left_wheel" };
  c.right_joints = { "front_right_wheel", "rear_right_wheel" };
  c.imu_max_skew = 0.025;
  c.min_sample_interval = 0.005;
  c.max_gap = 0.25;
  return c;
}

/// A joint-state message's fields; stamp 0 stands for an unset ROS stamp.
struct Joints
{
  double stamp = 0.0;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};

Joints joints(double t, double left = 1.0, double right = 2.0)
{
  Joints msg;
  msg.stamp = t;
  // non-standard order with an extra joint: lookup must be by name
  msg.name = { "rear_right_wheel", "caster", "front_left_wheel", "rear_left_wheel", "front_right_wheel" };
  msg.velocity = { right + 0.5, 99.0, left - 0.5, left + 0.5, right - 0.5 };
  msg.position = { 0.0, 0.0, 0.0, 0.0, 0.0 };
  return msg;
}

/// The input as the node passes it: a zero stamp as NaN.
loop::JointStateInput in(const Joints& m)
{
  loop::JointStateInput j;
  j.stamp = m.stamp == 0.0 ? std::numeric_limits<double>::quiet_NaN() : m.stamp;
  j.name = &m.name;
  j.position = &m.position;
  j.velocity = &m.velocity;
  j.effort = &m.effort;
  return j;
}

loop::ImuInput imu(double t, double gyro_z = 0.3)
{
  loop::ImuInput msg;
  msg.stamp = t == 0.0 ? std::numeric_limits<double>::quiet_NaN() : t;
  msg.angular_velocity << 0.05, -0.2, gyro_z;  // roll, pitch, yaw rates
  msg.linear_acceleration << 0.4, -0.1, 9.81;
  return msg;
}

std::uint64_t drops(const loop::SensorPairing& s, loop::DropReason r)
{
  return s.drops(r);
}

TEST(SensorPairing, PairsByNameAndAverages)
{
  loop::SensorPairing sync(config());
  ASSERT_TRUE(sync.addImu(imu(kT0 + 0.005)));
  loop::SensorSample s;
  ASSERT_TRUE(sync.addJointState(in(joints(kT0)), &s));
  EXPECT_TRUE(s.first);
  EXPECT_NEAR(s.y(base::kOmegaLeft), 1.0, kValueTol);
  EXPECT_NEAR(s.y(base::kOmegaRight), 2.0, kValueTol);
  EXPECT_NEAR(s.y(base::kGyroZ), 0.3, kValueTol);
  EXPECT_NEAR(s.y(base::kAccelX), 0.4, kValueTol);
  EXPECT_NEAR(s.y(base::kAccelY), -0.1, kValueTol);
  EXPECT_NEAR(s.pitch_rate, -0.2, kValueTol) << "gyro y, for the tip-over guard";
  EXPECT_NEAR(s.up_force, 9.81, kValueTol) << "accel z, for the tip-over guard";

  ASSERT_TRUE(sync.addImu(imu(kT0 + 0.025, 0.7)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 0.02)), &s));
  EXPECT_FALSE(s.first);
  EXPECT_NEAR(s.h, 0.02, kIntervalTol);
  EXPECT_NEAR(s.y(base::kGyroZ), 0.7, kValueTol);  // closest IMU (5 ms) rather than the older one (15 ms)
}

TEST(SensorPairing, DropsInvalidJointStates)
{
  loop::SensorPairing sync(config());
  ASSERT_TRUE(sync.addImu(imu(kT0)));
  loop::SensorSample s;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  auto missing = joints(kT0);
  missing.name[3] = "unknown";
  EXPECT_FALSE(sync.addJointState(in(missing), &s));
  EXPECT_EQ(drops(sync, loop::DropReason::kJointNames), 1u);

  auto short_velocity = joints(kT0);
  short_velocity.velocity.pop_back();
  EXPECT_FALSE(sync.addJointState(in(short_velocity), &s));
  auto long_position = joints(kT0);
  long_position.position.push_back(0.0);
  EXPECT_FALSE(sync.addJointState(in(long_position), &s));
  auto short_effort = joints(kT0);
  short_effort.effort = { 0.0, 0.0 };  // neither empty nor name size
  EXPECT_FALSE(sync.addJointState(in(short_effort), &s));
  EXPECT_EQ(drops(sync, loop::DropReason::kJointArrays), 3u);

  for (double bad : { nan, inf, -inf })
  {
    auto v = joints(kT0);
    v.velocity[2] = bad;
    EXPECT_FALSE(sync.addJointState(in(v), &s));
    auto p = joints(kT0);
    p.position[0] = bad;
    EXPECT_FALSE(sync.addJointState(in(p), &s));
    auto e = joints(kT0);
    e.effort = { 0.0, 0.0, 0.0, 0.0, 0.0 };
    e.effort[4] = bad;
    EXPECT_FALSE(sync.addJointState(in(e), &s));
  }
  EXPECT_EQ(drops(sync, loop::DropReason::kJointNonFinite), 9u);

  auto unused = joints(kT0);
  unused.velocity[1] = nan;  // the caster is not configured: ignored
  EXPECT_TRUE(sync.addJointState(in(unused), &s));

  EXPECT_FALSE(sync.addJointState(in(joints(kT0)), &s));        // same stamp
  EXPECT_FALSE(sync.addJointState(in(joints(kT0 - 1.0)), &s));  // backwards
  EXPECT_FALSE(sync.addJointState(in(joints(0.0)), &s));        // zero
  EXPECT_EQ(drops(sync, loop::DropReason::kJointStamp), 3u);
  EXPECT_EQ(sync.acceptedSamples(), 1u);
}

TEST(SensorPairing, DropsInvalidImu)
{
  loop::SensorPairing sync(config());
  auto bad = imu(kT0);
  bad.linear_acceleration.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(sync.addImu(bad));
  bad = imu(kT0);
  bad.angular_velocity.y() = -std::numeric_limits<double>::infinity();
  EXPECT_FALSE(sync.addImu(bad));
  EXPECT_EQ(drops(sync, loop::DropReason::kImuNonFinite), 2u);
  auto unused = imu(kT0);
  EXPECT_TRUE(sync.addImu(unused));  // (orientation is not an input at all)
  EXPECT_FALSE(sync.addImu(imu(kT0)));
  EXPECT_FALSE(sync.addImu(imu(0.0)));
  EXPECT_EQ(drops(sync, loop::DropReason::kImuStamp), 2u);
}

TEST(SensorPairing, NoImuWithinSkew)
{
  loop::SensorPairing sync(config());
  loop::SensorSample s;
  // Degraded mode: without an IMU within the skew the sample goes on, flagged, IMU fields zero.
  ASSERT_TRUE(sync.addJointState(in(joints(kT0)), &s));  // no IMU at all
  EXPECT_FALSE(s.imu_ok);
  EXPECT_EQ(s.y(base::kGyroZ), 0.0);
  EXPECT_EQ(s.pitch_rate, 0.0);
  ASSERT_TRUE(sync.addImu(imu(kT0 + 0.02)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 0.1)), &s));  // IMU 80 ms old: stale
  EXPECT_FALSE(s.imu_ok);
  EXPECT_EQ(drops(sync, loop::DropReason::kNoImu), 2u);
  ASSERT_TRUE(sync.addImu(imu(kT0 + 0.12, 0.4)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 0.12)), &s));
  EXPECT_TRUE(s.imu_ok);
  EXPECT_NEAR(s.y(base::kGyroZ), 0.4, kValueTol);
}

TEST(SensorPairing, TooCloseAndGaps)
{
  loop::SensorPairing sync(config());
  loop::SensorSample s;
  ASSERT_TRUE(sync.addImu(imu(kT0)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0)), &s));
  EXPECT_FALSE(sync.addJointState(in(joints(kT0 + 0.001)), &s));
  EXPECT_EQ(drops(sync, loop::DropReason::kTooClose), 1u);
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 0.02)), &s));
  EXPECT_NEAR(s.h, 0.02, kIntervalTol);  // from the last accepted sample
  ASSERT_TRUE(sync.addImu(imu(kT0 + 1.0)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 1.0)), &s));
  EXPECT_TRUE(s.first);  // 0.98 s > max_gap: new history
  EXPECT_EQ(s.h, 0.0);
  sync.restartHistory();
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 1.02)), &s));  // IMU cache emptied by the restart
  EXPECT_FALSE(s.imu_ok);
  EXPECT_TRUE(s.first);  // the restart starts a new history
  ASSERT_TRUE(sync.addImu(imu(kT0 + 1.03)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 1.04)), &s));
  EXPECT_TRUE(s.imu_ok);
  EXPECT_FALSE(s.first);
}

TEST(SensorPairing, RecoversFromAFutureStampAfterRestart)
{
  loop::SensorPairing sync(config());
  loop::SensorSample s;
  ASSERT_TRUE(sync.addImu(imu(kT0)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0)), &s));
  ASSERT_TRUE(sync.addImu(imu(kT0 + 1.0e6)));  // one message stamped far in the future
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 1.0e6)), &s));
  EXPECT_FALSE(sync.addImu(imu(kT0 + 0.02)));  // every later message now looks backwards
  EXPECT_FALSE(sync.addJointState(in(joints(kT0 + 0.02)), &s));
  sync.restartHistory();  // what the node does once the sensors went stale
  ASSERT_TRUE(sync.addImu(imu(kT0 + 0.3)));
  ASSERT_TRUE(sync.addJointState(in(joints(kT0 + 0.3)), &s));
  EXPECT_TRUE(s.first);
  EXPECT_NEAR(s.y(base::kGyroZ), 0.3, kValueTol);
}

TEST(SensorPairing, NegativeStampsAndTextsOfDrops)
{
  // Stamps in the node's epoch may be negative (messages stamped before the node started).
  loop::SensorPairing sync(config());
  loop::SensorSample s;
  ASSERT_TRUE(sync.addImu(imu(-0.5)));
  ASSERT_TRUE(sync.addJointState(in(joints(-0.49)), &s));
  EXPECT_TRUE(s.imu_ok);
  loop::DropReason reason = loop::DropReason::kCount;
  std::string why;
  EXPECT_FALSE(sync.addJointState(in(joints(-0.6)), &s, &reason, &why));
  EXPECT_EQ(reason, loop::DropReason::kJointStamp);
  EXPECT_NE(why.find("not after the previous"), std::string::npos) << why;
  EXPECT_STREQ(loop::toString(loop::DropReason::kJointStamp), "joint_states: zero or backwards stamp");
}

}  // namespace
}  // namespace jackal_aic
