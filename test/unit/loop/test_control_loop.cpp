/**
 * \file test_control_loop.cpp
 * \brief gtest of the ControlLoop (the node's logic, ROS-free) with a fake clock: activation
 *        and bumpless start, the sample-triggered action, both belief schedules giving the
 *        same beliefs and actions on one input sequence with ideal timing, the keep-alive,
 *        stale sensors, runaway, the MCU hold, the cmd_vel anti-windup feedback, set-point
 *        checks and parameter changes (doc/jackal_aic_node.md, 'Loops', 'Safety').
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "jackal_aic/loop/control_loop.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kTol = 1e-12;         // rad/s, m/s (copies and sums of a few doubles)
constexpr double kScheduleTol = 1e-9;  // the two schedules' beliefs and actions (issue of rounding only)
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A clock the test sets.
class FakeClock : public loop::Clock
{
public:
  double now() const override { return t; }
  double t = 0.0;  ///< [s]
};

/// Records what the loop emits.
class Recorder : public loop::ControlLoop::Output
{
public:
  void command(const loop::WheelCommand& c) override { commands.push_back(c); }
  void healthEvent(safety::FaultMonitor::Event event, int channel) override { events.emplace_back(event, channel); }
  void log(loop::LogLevel level, const std::string& text) override { lines.emplace_back(level, text); }
  std::vector<loop::WheelCommand> commands;
  std::vector<std::pair<safety::FaultMonitor::Event, int>> events;
  std::vector<std::pair<loop::LogLevel, std::string>> lines;
  /// Log lines containing `text`.
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

params::NodeParams params(params::BeliefSchedule schedule = params::BeliefSchedule::kEvent)
{
  params::NodeParams p;  // the schema's defaults (config/default.yaml): p = 2, 3 warm-up samples
  p.left_joints = { "front_left_wheel", "rear_left_wheel" };
  p.right_joints = { "front_right_wheel", "rear_right_wheel" };
  p.belief_schedule = schedule;
  return p;
}

/// A joint state and an IMU sample at one stamp, as the Jackal's drivers publish them.
struct Sensors
{
  std::vector<std::string> name{ "front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel" };
  std::vector<double> position{ 0.0, 0.0, 0.0, 0.0 };
  std::vector<double> velocity{ 0.0, 0.0, 0.0, 0.0 };
  std::vector<double> effort;
  double last_stamp = 0.0;
  bool has_last = false;

  /// Feed one paired sample (wheel speeds [rad/s], gyro z [rad/s], gyro y `pitch_rate` [rad/s],
  /// > 0 nose down, accel z `up_force` [m/s^2], -g on its back) stamped `stamp`.
  bool feed(loop::ControlLoop& loop, double stamp, double left, double right, double gyro, double pitch_rate = 0.0,
            double up_force = safety::TipGuard::kGravity)
  {
    loop::ImuInput imu;
    imu.stamp = stamp;
    imu.angular_velocity.z() = gyro;
    imu.angular_velocity.y() = pitch_rate;
    imu.linear_acceleration.z() = up_force;
    loop.imu(imu);
    velocity = { left, right, left, right };
    // The wheels travel at their speeds (constant travel with a turning wheel is a frozen stream).
    const double h = has_last ? stamp - last_stamp : 0.0;
    for (std::size_t i = 0; i < position.size(); ++i)
    {
      position[i] += velocity[i] * h;
    }
    last_stamp = stamp;
    has_last = true;
    loop::JointStateInput j;
    j.stamp = stamp;
    j.name = &name;
    j.position = &position;
    j.velocity = &velocity;
    j.effort = &effort;
    return loop.jointState(j);
  }
};

const double kStop[6] = { 0, 0, 0, 0, 0, 0 };

double setPointFields(double v, double w, double (&fields)[6])
{
  fields[0] = v;
  fields[1] = fields[2] = fields[3] = fields[4] = 0.0;
  fields[5] = w;
  return v;
}

/// The fixture: one loop, its clock and recorder; samples every 20 ms.
class ControlLoopTest : public ::testing::Test
{
protected:
  FakeClock clock;
  Recorder out;
  params::NodeParams p = params();
  std::unique_ptr<loop::ControlLoop> loop;
  Sensors sensors;

  void build() { loop = std::make_unique<loop::ControlLoop>(p, clock, out); }
  void SetUp() override { build(); }

  /// n samples 20 ms apart at the given wheel speeds, each with a set point (v [m/s]).
  void feed(int n, double wheels, double v)
  {
    double sp[6];
    setPointFields(v, 0.0, sp);
    for (int i = 0; i < n; ++i)
    {
      clock.t += 0.02;
      loop->setPoint(sp);
      sensors.feed(*loop, clock.t, wheels, wheels, 0.0);
    }
  }
};

TEST_F(ControlLoopTest, RefusesInvalidParameters)
{
  params::NodeParams bad = params();
  bad.aic.tau = -1.0;
  bad.sensor_timeout = 0.0;
  try
  {
    loop::ControlLoop l(bad, clock, out);
    FAIL() << "invalid parameters accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("tau"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sensor_timeout"), std::string::npos) << e.what();
  }
}

TEST_F(ControlLoopTest, StartsAfterWarmUpBumplessAndCommandsEverySample)
{
  feed(p.aic.numOrders() - 1, 2.0, 0.5);
  EXPECT_FALSE(loop->active());
  EXPECT_TRUE(out.commands.empty());
  feed(1, 2.0, 0.5);  // the (p+1)th sample: running, and this sample already runs the action
  ASSERT_TRUE(loop->active());
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(loop->actionSteps(), 1u);
  // Bumpless: beliefs at the measured twist (r omega), action from the measured wheels.
  EXPECT_NEAR(loop->controller().mu()(0, 0), p.aic.wheel_radius * 2.0, 1e-9);
  EXPECT_NEAR(out.commands[0].wheels(0), 2.0, 0.5);
  EXPECT_TRUE(std::isfinite(out.commands[0].latency));
  EXPECT_NEAR(out.commands[0].latency, 0.0, kTol);  // the sample's stamp is now
  EXPECT_EQ(out.linesWith("running (start from measured wheels"), 1);
  feed(10, 2.0, 0.5);
  EXPECT_EQ(out.commands.size(), 11u);
  // Event schedule: 200 ms at 1 kHz since the start, advanced at the sample events.
  EXPECT_EQ(loop->beliefSteps(), 200u);
  EXPECT_NEAR(loop->beliefTime(), clock.t, kTol);
  // The action pushes the wheels towards 0.5 m/s (5.1 rad/s): above the measured 2 rad/s.
  EXPECT_GT(out.commands.back().wheels(0), 2.0);
}

TEST_F(ControlLoopTest, CommandsRiseWhenSlowerAndFallWhenFaster)
{
  // The direction of the action update (thesis eq. 3-16) with wheels that never follow; the
  // anti-windup would hold the command at the measured speed +-max_action_lead.
  p.aic.anti_windup.max_action_lead = 0.0;
  build();
  feed(p.aic.numOrders(), 0.0, 0.5);  // standing still, 0.5 m/s asked
  ASSERT_TRUE(loop->active());
  const double early = out.commands.back().wheels(0);
  feed(40, 0.0, 0.5);  // 0.8 s
  EXPECT_GE(out.commands.back().wheels(0) - early, 2.0);
  EXPECT_NEAR(out.commands.back().wheels(0), out.commands.back().wheels(1), 1e-9);

  clock.t = 0.0;
  build();
  feed(p.aic.numOrders(), 10.204, 0.2);  // 1.0 m/s measured, 0.2 m/s asked
  ASSERT_TRUE(loop->active());
  const double start = out.commands.back().wheels(1);
  feed(40, 10.204, 0.2);
  EXPECT_LE(out.commands.back().wheels(1) - start, -2.0);
}

TEST_F(ControlLoopTest, KeepAliveSendsIdleCommandsWhileWaiting)
{
  clock.t = 0.01;
  loop->actionTimer(-1.0);
  EXPECT_TRUE(out.commands.empty());  // nothing measured yet: nothing to command from
  sensors.feed(*loop, clock.t, 0.0, 0.0, 0.0);
  clock.t = 0.02;
  loop->actionTimer(0.01);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].wheels, base::Vector2::Zero());  // the measured wheels (at rest)
  EXPECT_TRUE(std::isnan(out.commands[0].latency));
  EXPECT_EQ(loop->actionSteps(), 0u);
}

TEST_F(ControlLoopTest, KeepAliveRepeatsTheHeldCommandWhenSamplesAreLate)
{
  feed(p.aic.numOrders() + 2, 2.0, 0.5);
  const std::size_t n = out.commands.size();
  clock.t += 0.01;
  loop->actionTimer(0.02);  // a sample ran the action 10 ms ago: nothing to repeat
  EXPECT_EQ(out.commands.size(), n);
  clock.t += 0.03;  // 40 ms without a sample > 1.5 action periods, < sensor_timeout
  loop->actionTimer(0.02);
  ASSERT_EQ(out.commands.size(), n + 1);
  EXPECT_EQ(out.commands.back().wheels, loop->controller().action());
  EXPECT_TRUE(std::isnan(out.commands.back().latency));
}

TEST_F(ControlLoopTest, StaleSensorsCommandZeroAndWarmUpAgain)
{
  feed(p.aic.numOrders() + 2, 2.0, 0.5);
  ASSERT_TRUE(loop->active());
  double sp[6];
  setPointFields(0.5, 0.0, sp);
  clock.t += p.sensor_timeout + 0.01;
  loop->setPoint(sp);  // any event runs the watchdogs
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
  EXPECT_EQ(out.linesWith("commanding zero"), 1);
  // Sensors back: a new history, p+1 samples of warm-up, a bumpless restart.
  feed(p.aic.numOrders() - 1, 1.0, 0.5);
  EXPECT_FALSE(loop->active());
  feed(1, 1.0, 0.5);
  EXPECT_TRUE(loop->active());
  EXPECT_NEAR(loop->controller().mu()(0, 0), p.aic.wheel_radius * 1.0, 1e-9);
}

// A frozen MCU behind jackal_node: the joint states keep coming, freshly stamped, with the same
// travel and speeds. After kFrozenJointStateTime of them the loop treats the sensors as lost
// (kStale, the zero command at once, one warning naming the cause, the samples refused); new
// data restart it after the warm-up, as after sensor_timeout. Repeats at rest never count.
TEST_F(ControlLoopTest, FrozenJointStatesAreSensorLoss)
{
  feed(p.aic.numOrders() + 10, 5.0, 0.5);
  ASSERT_TRUE(loop->active());
  const std::vector<double> frozen_position = sensors.position;
  const std::size_t before = out.commands.size();
  double sp[6];
  setPointFields(0.5, 0.0, sp);
  auto repeat = [&] {
    clock.t += 0.02;
    loop->setPoint(sp);
    sensors.position = frozen_position;
    sensors.has_last = false;  // no travel
    return sensors.feed(*loop, clock.t, 5.0, 5.0, 0.0);
  };
  // The same data again, every 20 ms: 4 repeats (0.08 s) are still a healthy stream's worth.
  for (int k = 0; k < 4; ++k)
  {
    EXPECT_TRUE(repeat()) << k;
  }
  EXPECT_TRUE(loop->active());
  EXPECT_EQ(out.commands.size(), before + 4u);
  // The fifth is 0.1 s after the data's first (on the limit, up to rounding), the sixth 0.12 s: frozen.
  repeat();
  EXPECT_FALSE(repeat());
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
  EXPECT_TRUE(loop->supervisor().jointStatesFrozen());
  EXPECT_FALSE(loop->supervisor().sensorsFresh());
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
  EXPECT_EQ(out.linesWith("joint states frozen"), 1);
  EXPECT_EQ(out.linesWith("commanding zero"), 1);
  EXPECT_NE(loop->supervisor().reason().find("joint states frozen"), std::string::npos) << loop->supervisor().reason();
  EXPECT_EQ(loop->frozenJointStates().events(), 1u);
  const std::uint64_t refused = loop->frozenSamples();
  EXPECT_GE(refused, 1u);
  // It stays so while the data repeat (well within sensor_timeout of each other), commanding zero.
  for (int i = 0; i < 30; ++i)
  {
    EXPECT_FALSE(repeat());
    loop->actionTimer(0.02);
    EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
  }
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
  EXPECT_EQ(loop->frozenSamples(), refused + 30u);
  EXPECT_EQ(out.linesWith("joint states frozen"), 1);
  // The MCU is back: new data; a new history, its warm-up, a bumpless restart.
  sensors.has_last = false;
  feed(1, 1.0, 0.5);
  EXPECT_FALSE(loop->supervisor().jointStatesFrozen());
  EXPECT_EQ(out.linesWith("no longer frozen"), 1);
  EXPECT_FALSE(loop->active());
  feed(p.aic.numOrders(), 1.0, 0.5);
  EXPECT_TRUE(loop->active());
  EXPECT_EQ(loop->frozenJointStates().events(), 1u);
}

TEST_F(ControlLoopTest, FrozenJointStatesAtRestNeverCount)
{
  feed(p.aic.numOrders() + 2, 0.0, 0.0);  // standing, set point zero: constant travel
  for (int i = 0; i < 500; ++i)
  {
    feed(1, 0.0, 0.0);
  }
  EXPECT_TRUE(loop->active());
  EXPECT_EQ(loop->frozenJointStates().events(), 0u);
  EXPECT_EQ(loop->frozenSamples(), 0u);
}

TEST_F(ControlLoopTest, EventScheduleBoundsTheIntervalItIntegrates)
{
  feed(p.aic.numOrders(), 2.0, 0.5);
  const std::uint64_t before = loop->beliefSteps();
  clock.t += 0.2;  // a late sample, not yet stale: 200 steps of 1 ms
  sensors.feed(*loop, clock.t, 2.0, 2.0, 0.0);
  EXPECT_EQ(loop->beliefSteps() - before, 200u);
  EXPECT_DOUBLE_EQ(loop->maxEventInterval(), p.sensor_timeout);
  // Off the belief grid: 20.5 ms are 21 equal steps (never longer than 1 / belief_rate).
  const std::uint64_t mid = loop->beliefSteps();
  clock.t += 0.0205;
  loop->advance();
  EXPECT_EQ(loop->beliefSteps() - mid, 21u);
  EXPECT_NEAR(loop->beliefTime(), clock.t, kTol);
}

TEST_F(ControlLoopTest, RunawayResetsAndHoldsZero)
{
  // Forward Euler with a belief gain far beyond its stability bound at 1 kHz: the beliefs diverge.
  p.aic.integrator = params::Integrator::kEuler;
  p.aic.k_mu = 1.0e3;
  build();
  feed(p.aic.numOrders() + 1, 2.0, 0.5);
  ASSERT_TRUE(loop->active() || loop->supervisor().runaways() > 0);
  feed(2, 2.5, 0.5);  // the wheels speed up: a prediction error the unstable update amplifies
  EXPECT_GE(loop->supervisor().runaways(), 1u);
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kRunaway);
  EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero());
  EXPECT_EQ(out.linesWith("runaway beliefs in the"), 1);  // throttled to one a second
}

TEST_F(ControlLoopTest, NoActionStepDrivesADivergingControllerAfterARunaway)
{
  // The thesis's improved controller as printed (Euler, tau = 0.001 s, config/
  // thesis_improved_euler_diverges.yaml) re-diverges within a few belief steps of every restart. The timers of
  // the node (beliefs at 1 kHz, action at 50 Hz, samples at 50 Hz) at every phase of the action
  // timer against the samples: once the first runaway is caught, every command is zero (the
  // restart is on probation for one action period, which the divergence never survives); before
  // it, at most the one action step of the first start can read a belief part-way to divergence.
  p.aic = params::AicParams();  // the thesis's improved controller (thesis_improved_euler_diverges.yaml)
  ASSERT_EQ(p.aic.integrator, params::Integrator::kEuler);
  p.belief_schedule = params::BeliefSchedule::kTimer;
  p.action_trigger = params::ActionTrigger::kTimer;
  p.runaway_hold_time = 0.1;  // many restarts in the run
  int phases_with_an_early_step = 0;
  for (int phase = 0; phase < 20; ++phase)
  {
    SCOPED_TRACE("action timer " + std::to_string(phase) + " ms after the samples");
    clock.t = 0.0;
    out.commands.clear();
    build();
    double sp[6];
    setPointFields(0.5, 0.0, sp);
    bool diverged = false;
    std::size_t first_runaway_commands = 0;  // commands sent before the first runaway
    std::uint64_t steps_before = 0;
    for (int ms = 1; ms <= 3000; ++ms)
    {
      clock.t = 1e-3 * ms;
      if (ms % 20 == 0)
      {
        loop->setPoint(sp);
        sensors.feed(*loop, clock.t, 0.0, 0.0, 0.0);
      }
      loop->beliefTimer(1e-3);
      if (ms % 20 == phase)
      {
        steps_before = loop->actionSteps();
        loop->actionTimer(0.02);
        if (loop->actionSteps() > steps_before && loop->supervisor().runaways() == 0)
        {
          ++phases_with_an_early_step;
        }
      }
      if (!diverged && loop->supervisor().runaways() > 0)
      {
        diverged = true;
        first_runaway_commands = out.commands.size();
      }
    }
    ASSERT_TRUE(diverged) << "the controller never diverged";
    EXPECT_GE(loop->supervisor().runaways(), 10u);
    EXPECT_GE(loop->starts(), 10u) << "the hold never ended: no restart was tested";
    int early = 0;
    for (std::size_t i = 0; i < out.commands.size(); ++i)
    {
      const base::Vector2& w = out.commands[i].wheels;
      ASSERT_TRUE(w.allFinite());
      ASSERT_LE(w.cwiseAbs().maxCoeff(), p.aic.max_wheel_speed);
      if (i >= first_runaway_commands)
      {
        ASSERT_TRUE(w.isZero()) << "command " << i << " after the first runaway: " << w.transpose();
      }
      else
      {
        early += w.isZero() ? 0 : 1;
      }
    }
    EXPECT_LE(early, 1);
  }
  RecordProperty("phases_with_an_early_action_step", phases_with_an_early_step);
}

TEST_F(ControlLoopTest, McuStopHoldsTheMeasuredWheels)
{
  feed(p.aic.numOrders() + 1, 2.0, 0.5);
  ASSERT_TRUE(loop->active());
  loop->mcuStatus(true, true, true);  // external stop engaged
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kHeld);
  EXPECT_NEAR(out.commands.back().wheels(0), 2.0, kTol);
  EXPECT_NEAR(out.commands.back().wheels(1), 2.0, kTol);
  loop->mcuStatus(true, false, false);
  EXPECT_TRUE(loop->active());
}

TEST_F(ControlLoopTest, HeldCommandIsClampedToTheWheelLimit)
{
  // While the MCU stop holds, the command is the measured wheel speeds, which no controller
  // stage clamps: a robot pushed (or coasting) beyond max_wheel_speed must still get a command
  // within it. The command stage's guard is the only one on this path.
  p.aic.max_wheel_speed = 10.0;
  build();
  feed(p.aic.numOrders() + 1, 2.0, 0.5);
  ASSERT_TRUE(loop->active());
  loop->mcuStatus(true, true, true);
  ASSERT_EQ(loop->supervisor().state(), loop::NodeState::kHeld);
  feed(3, 15.0, 0.5);  // the wheels spin at 15 rad/s
  ASSERT_EQ(loop->supervisor().state(), loop::NodeState::kHeld);
  ASSERT_DOUBLE_EQ(loop->supervisor().measuredWheels()(0), 15.0);
  loop->actionTimer(0.02);  // the keep-alive sends the held command
  EXPECT_DOUBLE_EQ(out.commands.back().wheels(0), 10.0);
  EXPECT_DOUBLE_EQ(out.commands.back().wheels(1), 10.0);
  for (const loop::WheelCommand& c : out.commands)
  {
    EXPECT_LE(c.wheels.cwiseAbs().maxCoeff(), 10.0);
  }
}

TEST_F(ControlLoopTest, OutputBlockedPublishesNothingAndRestartsBumpless)
{
  feed(p.aic.numOrders() + 5, 2.0, 0.5);
  ASSERT_TRUE(loop->active());
  const std::size_t before = out.commands.size();
  loop->outputBlocked(true, "another node publishes on /cmd_drive: /jackal_node; publishing nothing there");
  EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kBlocked);
  EXPECT_FALSE(loop->active());
  // Samples, set points and the keep-alive timer go on; no command reaches the output.
  feed(20, 3.0, 0.5);
  for (int i = 0; i < 10; ++i)
  {
    clock.t += 0.02;
    loop->actionTimer(0.02);
  }
  EXPECT_EQ(out.commands.size(), before);
  EXPECT_GT(loop->blockedCommands(), 0u);
  EXPECT_EQ(out.linesWith("commanding zero"), 0);  // the node logs the conflict, once
  // Released: running again at once, from the measured wheels (bumpless), publishing again.
  loop->outputBlocked(false, "");
  feed(1, 3.0, 0.5);
  EXPECT_TRUE(loop->active());
  ASSERT_GT(out.commands.size(), before);
  // One action step (and the action prior's feed-forward) from the measured 3 rad/s towards
  // the goal's 5.1 rad/s: no wound-up action from the blocked time.
  EXPECT_NEAR(out.commands.back().wheels(0), 3.0, 1.0);
  EXPECT_NEAR(loop->controller().mu()(0, 0), p.aic.wheel_radius * 3.0, 0.05);
}

TEST_F(ControlLoopTest, SetPointTimeoutCommandsZeroAtOnce)
{
  // cmd_drive and cmd_vel: the first command after set_point_timeout is zero, not a ramp
  // (cmd_vel: the zero twist; the stock diff drive ramps down with its own limits).
  for (const std::string mode : { "cmd_drive", "cmd_vel" })
  {
    SCOPED_TRACE(mode);
    p.output_mode = mode;
    p.set_point_timeout = 0.2;
    build();
    out.commands.clear();
    feed(p.aic.numOrders() + 50, 10.0, 1.0);  // ~1 m/s
    ASSERT_TRUE(loop->active());
    ASSERT_GT(std::abs(out.commands.back().wheels(0)), 5.0);
    // The set point stops; samples go on at 50 Hz with the wheels still turning.
    double last_set_point = clock.t;
    while (loop->active())
    {
      clock.t += 0.02;
      sensors.feed(*loop, clock.t, 10.0, 10.0, 0.0);
      ASSERT_LE(clock.t - last_set_point, p.set_point_timeout + 0.02 + 1e-9);
    }
    EXPECT_EQ(loop->supervisor().state(), loop::NodeState::kStale);
    const loop::WheelCommand& c = out.commands.back();
    EXPECT_EQ(c.wheels(0), 0.0);
    EXPECT_EQ(c.wheels(1), 0.0);
    if (mode == "cmd_vel")
    {
      EXPECT_TRUE(c.cmd_vel);
      EXPECT_EQ(c.twist.linear, 0.0);
      EXPECT_EQ(c.twist.angular, 0.0);
      EXPECT_FALSE(c.clipped);
    }
    clock.t += 0.02;
    loop->actionTimer(0.02);  // the keep-alive repeats the zero
    EXPECT_EQ(out.commands.back().wheels(0), 0.0);
  }
}

TEST_F(ControlLoopTest, ARobotThatHasTurnedOverIsCommandedZeroUntilLevelAndTheLogSaysSo)
{
  ASSERT_TRUE(p.aic.tip_guard.enabled);
  feed(p.aic.numOrders() + 50, 10.0, 1.0);  // ~1 m/s
  ASSERT_TRUE(loop->active());
  ASSERT_GT(out.commands.back().wheels.minCoeff(), 5.0);
  // The body goes over its front axle at 3 rad/s, its wheels spinning on at the speed they had:
  // past tip_guard_turnover_pitch (0.4 rad) within 0.14 s.
  double sp[6];
  setPointFields(1.0, 0.0, sp);
  int turned = -1;
  for (int i = 0; i < 15; ++i)
  {
    clock.t += 0.02;
    loop->setPoint(sp);
    sensors.feed(*loop, clock.t, 10.0, 10.0, 0.0, 3.0);
    if (turned < 0 && loop->tipGuard().turnedOver())
    {
      turned = static_cast<int>(out.commands.size());
      EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero()) << "this sample's command already";
    }
  }
  ASSERT_GE(turned, 0) << "pitch estimate " << loop->tipGuard().pitch();
  EXPECT_EQ(out.linesWith("the robot has turned over; zero command"), 1);
  // On its back: no rotation, the estimate (0.9 rad) fades with T_theta = 1 s; the set point and
  // the free wheels' 10 rad/s go on, and every command is zero while it is past 0.4 rad.
  int zeros = 0;
  for (;;)
  {
    clock.t += 0.02;
    loop->setPoint(sp);
    sensors.feed(*loop, clock.t, 10.0, 10.0, 0.0, 0.0);
    if (!loop->tipGuard().turnedOver())
    {
      break;
    }
    EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero()) << "at " << clock.t;
    ++zeros;
    ASSERT_LT(clock.t, 10.0);
  }
  EXPECT_GT(zeros, 25) << "about ln(0.9 / 0.4) s of fade";
  EXPECT_EQ(out.linesWith("the body is upright again: the command resumes"), 1);
  EXPECT_NE(out.commands.back().wheels, base::Vector2::Zero()) << "back within it, the command resumes";
  EXPECT_TRUE(loop->active()) << "a stop of the command, not of the node";
}

TEST_F(ControlLoopTest, ARobotOnItsBackIsCommandedZeroUntilUprightAndTheLogSaysSo)
{
  // Rolled onto its back without a pitch the guard integrates (a roll, or a flip whose half turn
  // has faded): the IMU's z specific force reads -g. The wheels spin free at the speed they had.
  feed(p.aic.numOrders() + 50, 10.0, 1.0);  // ~1 m/s
  ASSERT_TRUE(loop->active());
  double sp[6];
  setPointFields(1.0, 0.0, sp);
  int zeros = 0;
  for (double t_end = clock.t + 10.0; clock.t < t_end;)  // ten seconds on its back
  {
    clock.t += 0.02;
    loop->setPoint(sp);
    sensors.feed(*loop, clock.t, 10.0, 10.0, 0.0, 0.0, -safety::TipGuard::kGravity);
    if (loop->tipGuard().turnedOver())
    {
      EXPECT_EQ(out.commands.back().wheels, base::Vector2::Zero()) << "at " << clock.t;
      ++zeros;
    }
  }
  EXPECT_GT(zeros, 470) << "turned over within 0.6 s of lying on its back (T_f = 0.5 s), and for good";
  EXPECT_EQ(out.linesWith("the robot has turned over; zero command until it is upright"), 1);
  EXPECT_EQ(out.linesWith("upside down)"), 1);
  // Righted: the low-passed force passes g cos(0.4 rad) within 1.7 s (T_f = 0.5 s), the command
  // resumes, and the log says so.
  for (double t_end = clock.t + 2.0; clock.t < t_end;)
  {
    clock.t += 0.02;
    loop->setPoint(sp);
    sensors.feed(*loop, clock.t, 10.0, 10.0, 0.0);
  }
  EXPECT_FALSE(loop->tipGuard().turnedOver());
  EXPECT_EQ(out.linesWith("the body is upright again: the command resumes"), 1);
  EXPECT_NE(out.commands.back().wheels, base::Vector2::Zero());
}

TEST_F(ControlLoopTest, SetPointsAreCheckedAndBecomeTheGoal)
{
  double sp[6];
  setPointFields(0.3, 0.2, sp);
  EXPECT_EQ(loop->setPoint(sp), loop::SetPointResult::kAccepted);
  EXPECT_NEAR(loop->controller().goal()(0), 0.3, kTol);
  EXPECT_NEAR(loop->controller().goal()(2), 0.2, kTol);
  setPointFields(5.0, 0.0, sp);
  EXPECT_EQ(loop->setPoint(sp), loop::SetPointResult::kClamped);
  EXPECT_NEAR(loop->controller().goal()(0), p.max_linear_speed, kTol);
  sp[3] = kNaN;
  EXPECT_EQ(loop->setPoint(sp), loop::SetPointResult::kDropped);
  EXPECT_EQ(loop->setPoint(sp), loop::SetPointResult::kDropped);
  EXPECT_NEAR(loop->controller().goal()(0), p.max_linear_speed, kTol);
  EXPECT_EQ(out.linesWith("dropped a set point"), 1);  // throttled
  clock.t += 1.0;
  loop->setPoint(sp);
  EXPECT_EQ(out.linesWith("dropped a set point"), 2);
}

TEST_F(ControlLoopTest, TheRobotModelsGoalRateIsBoundedWithinWhatItsWheelsCanFollow)
{
  // A set point that jumps 1 m/s and 2 rad/s within 0.1 s (10 m/s^2, 20 rad/s^2): the goal model's
  // rate is bounded by max_goal_rate_linear / _angular, the robot model's by them too but within its
  // wheel loop's A_w (params::goalRateParams()): with bounds of 100 the goal model takes the jump's
  // rate and the robot model the wheels' bound.
  for (const double bound : { 0.0, 100.0 })
  {
    for (const bool robot : { false, true })
    {
      p.aic.belief_model = robot ? params::BeliefModel::kRobot : params::BeliefModel::kGoal;
      if (bound > 0.0)
      {
        p.aic.reference.max_goal_rate_linear = bound;
        p.aic.reference.max_goal_rate_angular = bound;
      }
      build();
      double sp[6];
      setPointFields(0.0, 0.0, sp);
      loop->setPoint(sp);
      clock.t += 0.1;
      setPointFields(1.0, 2.0, sp);
      loop->setPoint(sp);
      const double wheel = p.aic.robot.wheel_acceleration * p.aic.wheel_radius * p.aic.slip_factor;
      const double linear =
          robot ? std::min(p.aic.reference.max_goal_rate_linear, wheel) : p.aic.reference.max_goal_rate_linear;
      const double angular = robot ?
                                 std::min(p.aic.reference.max_goal_rate_angular, 2.0 * wheel / p.aic.wheel_separation) :
                                 p.aic.reference.max_goal_rate_angular;
      SCOPED_TRACE("robot " + std::to_string(robot) + ", configured bounds " +
                   std::to_string(p.aic.reference.max_goal_rate_linear) + ", " +
                   std::to_string(p.aic.reference.max_goal_rate_angular));
      EXPECT_NEAR(loop->controller().goalRate()(0), std::min(linear, 10.0), 1e-9);
      EXPECT_NEAR(loop->controller().goalRate()(2), std::min(angular, 20.0), 1e-9);
    }
  }
}

TEST_F(ControlLoopTest, CmdVelClipsAndFeedsTheActionBack)
{
  p.output_mode = "cmd_vel";
  p.cmd_vel.max_linear_velocity = 0.3;  // below the 0.5 m/s set point
  build();
  feed(p.aic.numOrders() + 20, 3.0, 0.5);
  ASSERT_TRUE(loop->active());
  const loop::WheelCommand& c = out.commands.back();
  EXPECT_TRUE(c.cmd_vel);
  EXPECT_TRUE(c.clipped);
  EXPECT_NEAR(c.twist.linear, 0.3, 1e-9);
  EXPECT_GT(loop->outputClips(), 0u);
  EXPECT_TRUE(loop->lastOutputClipped());
  // Anti-windup: the controller's action is what the stock controller will command.
  EXPECT_NEAR(loop->controller().action()(0), c.wheels(0), kTol);
  EXPECT_NEAR(loop->controller().action()(1), c.wheels(1), kTol);
}

TEST_F(ControlLoopTest, DroppedInputsAreCountedAndLoggedOnce)
{
  loop::JointStateInput bad;
  bad.stamp = 0.1;
  const std::vector<std::string> names{ "front_left_wheel" };
  const std::vector<double> v{ 1.0 };
  bad.name = &names;
  bad.velocity = &v;
  EXPECT_FALSE(loop->jointState(bad));
  EXPECT_FALSE(loop->jointState(bad));
  EXPECT_EQ(loop->pairing().drops(loop::DropReason::kJointNames), 2u);
  EXPECT_EQ(out.linesWith("dropped input (joint_states: unknown or missing joint name)"), 1);
  loop::ImuInput imu;
  imu.stamp = kNaN;  // an unset stamp
  EXPECT_FALSE(loop->imu(imu));
  EXPECT_EQ(loop->pairing().drops(loop::DropReason::kImuStamp), 1u);
}

TEST_F(ControlLoopTest, EmbeddingOrderChangeWarmsUpAgain)
{
  feed(p.aic.numOrders() + 1, 2.0, 0.5);
  ASSERT_TRUE(loop->active());
  params::NodeParams next = p;
  next.aic.embedding_order = 1;
  next.aic.var_mu = { 0.5, 0.6667 };
  next.aic.var_y = { 2.0, 38.25 };
  loop->setParams(next);
  EXPECT_FALSE(loop->active());
  EXPECT_NEAR(out.commands.back().wheels(0), 2.0, kTol);  // warming up: the measured wheels (bumpless)
  feed(next.aic.numOrders(), 2.0, 0.5);
  EXPECT_TRUE(loop->active());
  EXPECT_EQ(loop->controller().mu().cols(), 2);
  params::NodeParams invalid = next;
  invalid.aic.k_a = -1.0;
  EXPECT_THROW(loop->setParams(invalid), std::invalid_argument);
  EXPECT_EQ(loop->params().aic.k_a, next.aic.k_a);
}

/**
 * One recorded input sequence, ideal timing (every event on the 1 ms belief grid): paired
 * samples every 20 ms (wheel speeds of a first-order plant following the command, with seeded
 * noise), set points streamed at 20 Hz with steps, the action timer at 50 Hz. The event
 * schedule (beliefs advanced at each event) and the timer schedule (a belief tick every 1 ms,
 * before the events of its instant) give the same beliefs and actions.
 */
void compareSchedules(params::Integrator integrator, params::ActionTrigger trigger, bool driving = false)
{
  FakeClock clock_e, clock_t;
  Recorder out_e, out_t;
  params::NodeParams pe = params(params::BeliefSchedule::kEvent);
  pe.aic.integrator = integrator;
  pe.action_trigger = trigger;
  if (driving)
  {
    // Set-point dynamics and the action prior, on a ramped set point.
    pe.aic.reference.generalized_goal = true;
    pe.aic.reference.goal_lead = 0.1;
    pe.aic.reference.time_constant = 0.1;
    pe.aic.reference.delay = 0.06;
    pe.aic.action_prior.gain = 0.8;
    pe.aic.action_prior.time_constant = 0.15;
  }
  params::NodeParams pt = pe;
  pt.belief_schedule = params::BeliefSchedule::kTimer;
  loop::ControlLoop event(pe, clock_e, out_e);
  loop::ControlLoop timer(pt, clock_t, out_t);
  Sensors se, st;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  double wheels = 0.0;
  double max_mu = 0.0, max_a = 0.0;
  int compared = 0;
  for (int k = 1; k <= 3000; ++k)  // 3 s
  {
    const double t = k * 1e-3;
    clock_e.t = clock_t.t = t;
    timer.beliefTimer(1e-3);
    if (k % 50 == 0)
    {
      double sp[6];
      const double step = t < 1.0 ? 0.0 : (t < 2.0 ? 0.5 : 0.2);
      const double ramp = std::min(0.5, std::max(0.0, t - 1.0));  // 1 m/s^2 in 50 ms stairs
      setPointFields(driving ? ramp : step, t < 1.5 ? 0.0 : 0.4, sp);
      event.setPoint(sp);
      timer.setPoint(sp);
    }
    if (k % 20 == 10)
    {
      event.actionTimer(0.02);
      timer.actionTimer(0.02);
    }
    if (k % 20 == 0)
    {
      // The wheels follow the last command with a 50 ms lag.
      const double command = out_e.commands.empty() ? 0.0 : out_e.commands.back().wheels(0);
      wheels += (command - wheels) * 0.02 / 0.05;
      const double left = wheels + noise(rng);
      const double right = wheels + noise(rng);
      const double gyro = noise(rng);
      se.feed(event, t, left, right, gyro);
      st.feed(timer, t, left, right, gyro);
    }
    ASSERT_EQ(event.active(), timer.active()) << "t = " << t;
    if (k % 20 == 0 && event.active())
    {
      max_mu = std::max(max_mu, (event.controller().mu() - timer.controller().mu()).cwiseAbs().maxCoeff());
      max_a = std::max(max_a, (event.controller().action() - timer.controller().action()).cwiseAbs().maxCoeff());
      ++compared;
    }
  }
  EXPECT_GT(compared, 100);
  EXPECT_LE(max_mu, kScheduleTol);
  EXPECT_LE(max_a, kScheduleTol);
  ASSERT_EQ(out_e.commands.size(), out_t.commands.size());
  for (std::size_t i = 0; i < out_e.commands.size(); ++i)
  {
    EXPECT_LE((out_e.commands[i].wheels - out_t.commands[i].wheels).cwiseAbs().maxCoeff(), kScheduleTol) << i;
  }
  EXPECT_EQ(event.beliefSteps(), timer.beliefSteps());
  // The beliefs moved: the comparison is not of two idle controllers.
  EXPECT_GT(std::abs(event.controller().mu()(0, 0)), 0.1);
  EXPECT_GT(event.actionSteps(), 50u);
}

TEST(ControlLoopSchedules, SameBeliefsAndActionsExactIntegratorSampleTrigger)
{
  compareSchedules(params::Integrator::kExact, params::ActionTrigger::kSample);
}

TEST(ControlLoopSchedules, SameBeliefsAndActionsEulerTimerTrigger)
{
  compareSchedules(params::Integrator::kEuler, params::ActionTrigger::kTimer);
}

TEST(ControlLoopSchedules, SameBeliefsAndActionsWithSetPointDynamicsAndPrior)
{
  compareSchedules(params::Integrator::kExact, params::ActionTrigger::kSample, true);
}

}  // namespace
}  // namespace jackal_aic
