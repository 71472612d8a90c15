/**
 * \file test_time_jump.cpp
 * \brief gtest of the TimeJumpDetector and of the ControlLoop on a clock that moves backwards
 *        (a simulator's /clock restarting at 0, a `rosbag play --loop --clock` loop, a wall
 *        clock stepped back) and of its restarts without a command jump: the idle command
 *        before the first sample, while warming up and after a stale spell
 *        (doc/jackal_aic_node.md, 'Time moving backwards and restarts').
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/loop/time_jump.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kTol = 1e-12;          // s, rad/s: copies and sums of a few doubles
constexpr double kSamplePeriod = 0.02;  // s: the Jackal's 50 Hz sensors
constexpr double kWheels = 5.1;         // rad/s: 0.5 m/s at r = 0.098 m

TEST(TimeJumpDetector, ReportsBackwardStepsBeyondTheTolerance)
{
  loop::TimeJumpDetector d(0.001);
  EXPECT_TRUE(std::isnan(d.latest()));
  EXPECT_EQ(d.observe(10.0), 0.0);     // the first reading
  EXPECT_EQ(d.observe(12.0), 0.0);     // forward, by any amount
  EXPECT_EQ(d.observe(11.9995), 0.0);  // within the tolerance: no jump, the latest stays
  EXPECT_DOUBLE_EQ(d.latest(), 12.0);
  EXPECT_EQ(d.observe(std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_EQ(d.observe(std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_NEAR(d.observe(0.5), 11.5, kTol);
  EXPECT_EQ(d.jumps(), 1u);
  EXPECT_NEAR(d.lastJump(), 11.5, kTol);
  EXPECT_DOUBLE_EQ(d.latest(), 0.5);  // the new timeline
  EXPECT_EQ(d.observe(0.52), 0.0);
  EXPECT_NEAR(d.observe(0.0), 0.52, kTol);
  EXPECT_EQ(d.jumps(), 2u);
  EXPECT_EQ(loop::TimeJumpDetector(-1.0).tolerance(), 0.0);
  EXPECT_EQ(loop::TimeJumpDetector(std::nan("")).tolerance(), 0.0);
}

class FakeClock : public loop::Clock
{
public:
  double now() const override { return t; }
  double t = 0.0;  ///< [s]
};

class Recorder : public loop::ControlLoop::Output
{
public:
  void command(const loop::WheelCommand& c) override { commands.push_back(c); }
  void log(loop::LogLevel level, const std::string& text) override { lines.emplace_back(level, text); }
  std::vector<loop::WheelCommand> commands;
  std::vector<std::pair<loop::LogLevel, std::string>> lines;
  int linesWith(const std::string& text) const
  {
    int n = 0;
    for (const auto& l : lines)
    {
      n += l.second.find(text) != std::string::npos ? 1 : 0;
    }
    return n;
  }
};

/// The loop on a fake clock, fed paired samples (stamp = clock) and a set point each 20 ms.
class TimelineTest : public ::testing::Test
{
protected:
  FakeClock clock;
  Recorder out;
  params::NodeParams p;
  std::unique_ptr<loop::ControlLoop> loop;
  std::vector<std::string> names{ "front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel" };
  std::vector<double> position{ 0.0, 0.0, 0.0, 0.0 };
  std::vector<double> velocity{ 0.0, 0.0, 0.0, 0.0 };

  void SetUp() override
  {
    p.left_joints = { "front_left_wheel", "rear_left_wheel" };
    p.right_joints = { "front_right_wheel", "rear_right_wheel" };
    loop = std::make_unique<loop::ControlLoop>(p, clock, out);
  }
  bool sample(double wheels)
  {
    loop::ImuInput imu;
    imu.stamp = clock.t;
    loop->imu(imu);
    velocity.assign(4, wheels);
    for (double& x : position)
    {
      x += 0.02 * wheels;  // the wheels travel (constant travel while turning is a frozen stream)
    }
    loop::JointStateInput j;
    j.stamp = clock.t;
    j.name = &names;
    j.position = &position;
    j.velocity = &velocity;
    return loop->jointState(j);
  }
  void setPoint(double v)
  {
    const double sp[6] = { v, 0.0, 0.0, 0.0, 0.0, 0.0 };
    loop->setPoint(sp);
  }
  /// n periods: set point, sample (unless `wheels` is NaN), action tick.
  void drive(int n, double wheels, double v = 0.5)
  {
    for (int i = 0; i < n; ++i)
    {
      clock.t += kSamplePeriod;
      setPoint(v);
      if (!std::isnan(wheels))
      {
        sample(wheels);
      }
      loop->actionTimer(kSamplePeriod);
    }
  }
  /// Largest rise of |command| between consecutive commands from index `from` [rad/s].
  double largestRise(std::size_t from) const
  {
    double rise = 0.0;
    for (std::size_t i = std::max<std::size_t>(from, 1); i < out.commands.size(); ++i)
    {
      for (int w = 0; w < 2; ++w)
      {
        rise = std::max(rise, std::abs(out.commands[i].wheels(w)) - std::abs(out.commands[i - 1].wheels(w)));
      }
    }
    return rise;
  }
};

TEST_F(TimelineTest, ClockBackToZeroRestartsOnTheNewTimelineAtOnce)
{
  clock.t = 17.0;
  drive(30, kWheels);
  ASSERT_TRUE(loop->active());
  const std::size_t before = out.commands.size();
  // The simulator restarts: /clock and the stamps begin again at 0 (a robot at rest).
  clock.t = 0.0;
  loop->advance();
  EXPECT_EQ(loop->timeJumps(), 1u);
  EXPECT_NEAR(loop->lastTimeJump(), 17.6, 1e-9);
  EXPECT_FALSE(loop->active());
  EXPECT_EQ(out.linesWith("ROS time moved back 17.6 s"), 1);
  EXPECT_EQ(out.commands.size(), before);  // nothing until the new timeline's first sample
  loop->actionTimer(kSamplePeriod);
  EXPECT_EQ(out.commands.size(), before);
  // The new timeline's samples are accepted from the first (none dropped as "backwards").
  drive(1, 0.0);
  EXPECT_EQ(loop->pairing().drops(loop::DropReason::kJointStamp), 0u);
  EXPECT_EQ(out.commands.size(), before + 1);
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());  // warming up: the measured wheels
  drive(p.aic.numOrders() - 1, 0.0);
  EXPECT_TRUE(loop->active());  // p+1 samples of the new timeline
  EXPECT_EQ(loop->starts(), 2u);
  EXPECT_EQ(out.linesWith("resumed after: ROS time moved back"), 1);
  drive(25, 2.0);  // 0.5 s
  EXPECT_GT(out.commands.back().wheels(0), 2.0);
  EXPECT_LE(largestRise(before), p.aic.anti_windup.max_action_lead + 2.0 + kTol);  // measured 0 -> 2 rad/s, lead 1.6
  EXPECT_EQ(out.linesWith("restart on the new timeline"), 1);                      // one warning per jump
  EXPECT_EQ(loop->timeJumps(), 1u);
}

TEST_F(TimelineTest, ClockStepBackWhileDrivingIsBumpless)
{
  // A wall clock stepped back 5 s while the robot drives on at 0.5 m/s.
  clock.t = 100.0;
  drive(50, kWheels);
  ASSERT_TRUE(loop->active());
  const std::size_t before = out.commands.size();
  const double last = out.commands.back().wheels(0);
  clock.t -= 5.0;
  drive(1, kWheels);  // the first sample of the new timeline: the measured wheels
  EXPECT_FALSE(loop->active());
  drive(p.aic.numOrders(), kWheels);
  EXPECT_TRUE(loop->active());
  ASSERT_GT(out.commands.size(), before);
  for (std::size_t i = before; i < out.commands.size(); ++i)
  {
    EXPECT_NEAR(out.commands[i].wheels(0), last, 0.3) << i;  // no jump: measured, then bumpless
  }
  EXPECT_EQ(loop->pairing().drops(loop::DropReason::kJointStamp), 0u);
  EXPECT_EQ(loop->timeJumps(), 1u);
}

TEST_F(TimelineTest, TimeoutsKeepTheirAgesAcrossAJump)
{
  clock.t = 50.0;
  drive(10, kWheels);
  ASSERT_TRUE(loop->active());
  clock.t += 0.1;  // 0.1 s without a sample or a set point
  loop->advance();
  clock.t = 3.0;  // back 47.2 s
  loop->advance();
  EXPECT_NEAR(loop->supervisor().sampleAge(), 0.1, 1e-9);
  EXPECT_NEAR(loop->supervisor().setPointAge(), 0.1, 1e-9);
  // No sample of the new timeline: stale after sensor_timeout of the kept age, then zero.
  clock.t += p.sensor_timeout - 0.1 + 0.01;
  loop->actionTimer(kSamplePeriod);
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
  ASSERT_FALSE(out.commands.empty());
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
}

TEST_F(TimelineTest, GoalRateStartsAfreshOnTheNewTimeline)
{
  clock.t = 20.0;
  for (int i = 1; i <= 10; ++i)  // a ramp of the set point: mu_d' > 0
  {
    clock.t += kSamplePeriod;
    setPoint(0.05 * i);
    sample(kWheels);
  }
  ASSERT_GT(loop->controller().goalRate()(0), 0.5);
  clock.t = 1.0;
  loop->advance();
  EXPECT_EQ(loop->controller().goalRate()(0), 0.0);
  EXPECT_NEAR(loop->controller().goal()(0), 0.5, kTol);  // the set point is kept
}

TEST_F(TimelineTest, ResetTimelineOnRequestKeepsAges)
{
  clock.t = 5.0;
  drive(10, kWheels);
  ASSERT_TRUE(loop->active());
  loop->resetTimeline();
  EXPECT_FALSE(loop->active());
  EXPECT_EQ(loop->timeJumps(), 0u);
  EXPECT_NEAR(loop->supervisor().sampleAge(), 0.0, kTol);
  drive(p.aic.numOrders(), kWheels);
  EXPECT_TRUE(loop->active());
}

TEST_F(TimelineTest, IdleCommandBeforeTheFirstSampleAndWhileWarmingUp)
{
  // A node (re)started beside a moving robot: nothing before its first sample, then the
  // measured wheels, then the controller from them.
  clock.t = 0.01;
  loop->actionTimer(-1.0);
  EXPECT_TRUE(out.commands.empty());
  drive(1, kWheels, std::nan(""));  // NaN: a set point that is dropped (no set point yet)
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_NEAR(out.commands.back().wheels(0), kWheels, kTol);
  drive(p.aic.numOrders(), kWheels);
  EXPECT_TRUE(loop->active());
  EXPECT_LE(largestRise(0), p.aic.anti_windup.max_action_lead + kTol);
  // Without a set point for set_point_timeout after the first sample: zero.
  clock.t = 0.0;
  out.commands.clear();
  loop = std::make_unique<loop::ControlLoop>(p, clock, out);
  drive(static_cast<int>(std::ceil(p.set_point_timeout / kSamplePeriod)) + 1, kWheels, std::nan(""));
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
}

TEST_F(TimelineTest, SensorsBackAfterAPauseResumeFromTheMeasuredWheels)
{
  // The sensor driver stops for 5 s (stale: zero), the robot coasts to 1 rad/s, the driver
  // comes back: the warm-up holds the measured wheels, the controller starts from them.
  clock.t = 1.0;
  drive(20, kWheels);
  ASSERT_TRUE(loop->active());
  drive(250, std::nan(""));
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
  const std::size_t back = out.commands.size();
  drive(1, 1.0);
  EXPECT_NEAR(out.commands.back().wheels(0), 1.0, kTol);
  drive(p.aic.numOrders(), 1.0);
  EXPECT_TRUE(loop->active());
  EXPECT_EQ(out.linesWith("resumed after: no sensor sample for"), 1);
  EXPECT_LE(largestRise(back + 1), p.aic.anti_windup.max_action_lead + kTol);
}

}  // namespace
}  // namespace jackal_aic
