/// Tests of the plant's fault injection (sim/plant/include/jackal_sim/plant/fault_injection.hpp): the fault-line
/// parser (every error case logged by the node has a case here) and the injector's effect on samples.
#include <gtest/gtest.h>

#include "jackal_sim/plant/fault_injection.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;

namespace
{
constexpr double kTol = 1e-12;

JointStateSample joints(double t, double v)
{
  JointStateSample s;
  s.stamp = t;
  s.velocity.fill(v);
  return s;
}
}  // namespace

TEST(FaultSpec, ParsesEveryField)
{
  FaultSpec f;
  std::string error;
  ASSERT_TRUE(parseFaultSpec("left_encoder spikes 3.5 1.0 2.0 0.2", &f, &error)) << error;
  EXPECT_EQ(f.target, FaultSpec::Target::kLeftEncoder);
  EXPECT_EQ(f.kind, FaultSpec::Kind::kSpikes);
  EXPECT_DOUBLE_EQ(f.value, 3.5);
  EXPECT_DOUBLE_EQ(f.start, 1.0);
  EXPECT_DOUBLE_EQ(f.duration, 2.0);
  EXPECT_DOUBLE_EQ(f.period, 0.2);
  ASSERT_TRUE(parseFaultSpec("  imu   dropout ", &f, &error)) << error;
  EXPECT_EQ(f.target, FaultSpec::Target::kImu);
  EXPECT_LE(f.duration, 0.0);  // for ever
  ASSERT_TRUE(parseFaultSpec("payload set 10", &f, &error)) << error;
  ASSERT_TRUE(parseFaultSpec("friction_right set 0.2", &f, &error)) << error;
  // freeze and dropout take no VALUE: the numbers are START and DURATION.
  ASSERT_TRUE(parseFaultSpec("gyro freeze 0 4", &f, &error)) << error;
  EXPECT_DOUBLE_EQ(f.start, 0.0);
  EXPECT_DOUBLE_EQ(f.duration, 4.0);
  ASSERT_TRUE(parseFaultSpec("joint_states dropout 1.5 0.15", &f, &error)) << error;
  EXPECT_DOUBLE_EQ(f.start, 1.5);
  EXPECT_DOUBLE_EQ(f.duration, 0.15);
}

TEST(FaultSpec, RejectsBadLinesWithAReason)
{
  const char* bad[][2] = {
    { "", "expected TARGET KIND" },
    { "wheel bias 1", "unknown target" },
    { "gyro wobble", "unknown kind" },
    { "gyro bias nan", "not a finite number" },
    { "gyro bias 1x", "not a finite number" },
    { "gyro set 1", "does not apply" },
    { "payload bias 1", "does not apply" },
    { "imu freeze", "needs a channel target" },
    { "gyro bias 1 -1", "START must be >= 0" },
    { "gyro spikes 1 0 0 0", "PERIOD must be > 0" },
    { "imu delay 0", "delay VALUE" },
    { "payload set -1", "payload VALUE" },
    { "friction_left set 11", "friction scale" },
    { "gyro bias 1 0 0 0.1 7", "expected TARGET KIND" },
    { "gyro bias 1 0 0 0.1", "too many numbers" },  // PERIOD is for spikes only
    { "gyro freeze 0 0 4", "too many numbers" },    // freeze takes no VALUE
    { "imu dropout 1 2 3", "too many numbers" },
    { "gyro bias", "needs a VALUE" },
    { "payload set", "needs a VALUE" },
  };
  for (const auto& c : bad)
  {
    FaultSpec f;
    std::string error;
    EXPECT_FALSE(parseFaultSpec(c[0], &f, &error)) << c[0];
    EXPECT_NE(error.find(c[1]), std::string::npos) << "'" << c[0] << "': " << error;
  }
}

TEST(FaultInjector, BiasFreezeDropoutDelayAndWindows)
{
  FaultInjector inj;
  FaultSpec bias, freeze, drop, delay;
  std::string e;
  ASSERT_TRUE(parseFaultSpec("left_encoder bias 2 1.0 1.0", &bias, &e));
  ASSERT_TRUE(parseFaultSpec("gyro freeze 0.5", &freeze, &e));
  ASSERT_TRUE(parseFaultSpec("joint_states dropout 3.0 0.5", &drop, &e));
  ASSERT_TRUE(parseFaultSpec("imu delay 0.3 0 4.0", &delay, &e));
  inj.setFaults({ bias, freeze, drop, delay }, 10.0);  // activated at plant time 10 s
  double d = 0.0;
  JointStateSample s = joints(10.5, 1.0);
  ASSERT_TRUE(inj.applyJoints(10.5, &s, &d));
  EXPECT_NEAR(s.velocity[kFrontLeft], 1.0, kTol);  // bias not yet active
  s = joints(11.2, 1.0);
  ASSERT_TRUE(inj.applyJoints(11.2, &s, &d));
  EXPECT_NEAR(s.velocity[kFrontLeft], 3.0, kTol);
  EXPECT_NEAR(s.velocity[kRearLeft], 3.0, kTol);
  EXPECT_NEAR(s.velocity[kFrontRight], 1.0, kTol);
  s = joints(12.1, 1.0);
  ASSERT_TRUE(inj.applyJoints(12.1, &s, &d));
  EXPECT_NEAR(s.velocity[kFrontLeft], 1.0, kTol);  // bias over after its 1 s
  s = joints(13.2, 1.0);
  EXPECT_FALSE(inj.applyJoints(13.2, &s, &d));  // dropout burst from 13 s for 0.5 s
  s = joints(13.6, 1.0);
  EXPECT_TRUE(inj.applyJoints(13.6, &s, &d));
  ImuSample imu;
  imu.angular_velocity.z() = 0.4;
  ASSERT_TRUE(inj.applyImu(10.2, &imu, &d));  // before the freeze: passes, remembered
  EXPECT_NEAR(imu.angular_velocity.z(), 0.4, kTol);
  EXPECT_NEAR(d, 0.3, kTol);  // the delay acts from 10 s
  imu.angular_velocity.z() = -1.0;
  ASSERT_TRUE(inj.applyImu(10.6, &imu, &d));
  EXPECT_NEAR(imu.angular_velocity.z(), 0.4, kTol);  // frozen
  EXPECT_NEAR(d, 0.3, kTol);                         // delayed
  EXPECT_DOUBLE_EQ(inj.payload(11.0), 0.0);
  EXPECT_DOUBLE_EQ(inj.frictionScale(kLeft, 11.0), 1.0);
}

TEST(FaultInjector, SpikeTrainAndPhysicalFaults)
{
  FaultInjector inj;
  FaultSpec spikes, payload, patch;
  std::string e;
  ASSERT_TRUE(parseFaultSpec("gyro spikes 5 0 0 0.1", &spikes, &e));
  ASSERT_TRUE(parseFaultSpec("payload set 10 1.0", &payload, &e));
  ASSERT_TRUE(parseFaultSpec("friction_left set 0.2 0 2.0", &patch, &e));
  inj.setFaults({ spikes, payload, patch }, 0.0);
  int spiked = 0;
  double d = 0.0;
  for (int k = 0; k < 50; ++k)  // 1 s at 50 Hz
  {
    ImuSample imu;
    ASSERT_TRUE(inj.applyImu(0.02 * k, &imu, &d));
    spiked += imu.angular_velocity.z() > 4.0 ? 1 : 0;
  }
  EXPECT_EQ(spiked, 10);  // one every 0.1 s
  EXPECT_DOUBLE_EQ(inj.payload(0.5), 0.0);
  EXPECT_DOUBLE_EQ(inj.payload(1.5), 10.0);
  EXPECT_DOUBLE_EQ(inj.frictionScale(kLeft, 1.0), 0.2);
  EXPECT_DOUBLE_EQ(inj.frictionScale(kRight, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(inj.frictionScale(kLeft, 2.5), 1.0);
}
