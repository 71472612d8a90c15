/**
 * \file test_supervisor.cpp
 * \brief gtest (no roscore) of the node's ROS-free Supervisor with a fake clock: every state
 *        transition and watchdog, set-point checks, catch-up scheduling and loop statistics
 *        (doc/jackal_aic_node.md, 'Loops' and 'Safety').
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "jackal_aic/loop/supervisor.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kTol = 1e-12;  // s (times and steps are sums of a few doubles)
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A clock the test sets.
class FakeClock : public loop::Clock
{
public:
  double now() const override { return t; }
  double t = 100.0;  ///< [s], an arbitrary non-zero start
};

params::NodeParams params()
{
  params::NodeParams p;  // p = 3 (4 warm-up samples), sensor_timeout 0.25 s, set_point_timeout 0.5 s, hold 1 s
  p.left_joints = { "l" };
  p.right_joints = { "r" };
  return p;
}

const double kZeroSetPoint[6] = { 0, 0, 0, 0, 0, 0 };

class SupervisorTest : public ::testing::Test
{
protected:
  FakeClock clock;
  params::NodeParams p = params();
  loop::Supervisor s{ p, clock };

  /// Feed n samples (one every 20 ms) with a set point, as the node does.
  void feed(int n, bool with_set_point = true)
  {
    for (int i = 0; i < n; ++i)
    {
      clock.t += 0.02;
      s.sampleAccepted(base::Vector2(1.0, 2.0));
      if (with_set_point)
      {
        s.setPoint(kZeroSetPoint);
      }
    }
  }

  /// Bring the supervisor to kRunning.
  void run()
  {
    feed(p.aic.numOrders());
    const auto t = s.update();
    ASSERT_TRUE(t.activate());
    ASSERT_EQ(s.state(), loop::NodeState::kRunning);
  }
};

TEST_F(SupervisorTest, StartsWaitingForSensors)
{
  EXPECT_EQ(s.state(), loop::NodeState::kWaiting);
  EXPECT_EQ(s.reason(), "no sensor sample yet");
  EXPECT_FALSE(s.active());
  const auto t = s.update();
  EXPECT_FALSE(t.changed);
  EXPECT_FALSE(t.restart_history);
  // A set point alone does not start anything.
  s.setPoint(kZeroSetPoint);
  EXPECT_FALSE(s.update().changed);
  EXPECT_EQ(s.state(), loop::NodeState::kWaiting);
}

TEST_F(SupervisorTest, WaitsForSetPointThenWarmsUpThenRuns)
{
  feed(p.aic.numOrders(), /*with_set_point=*/false);
  EXPECT_FALSE(s.update().changed);  // still waiting (for the set point)
  EXPECT_EQ(s.state(), loop::NodeState::kWaiting);

  s.historyRestarted();  // e.g. a gap: the warm-up starts over
  s.sampleAccepted(base::Vector2::Zero());
  s.setPoint(kZeroSetPoint);
  EXPECT_FALSE(s.update().changed);  // warming up: 1 of p+1 samples
  EXPECT_EQ(s.warmSamples(), 1);
  feed(p.aic.numOrders() - 2);
  EXPECT_FALSE(s.update().changed);  // p of p+1 samples
  feed(1);
  const auto t = s.update();
  EXPECT_TRUE(t.changed);
  EXPECT_TRUE(t.activate());
  EXPECT_FALSE(t.deactivate());
  EXPECT_FALSE(t.warn());
  EXPECT_EQ(s.state(), loop::NodeState::kRunning);
  EXPECT_EQ(s.reason(), "controlling");
  EXPECT_TRUE(s.active());
  EXPECT_EQ(s.measuredWheels(), base::Vector2(1.0, 2.0));
}

TEST_F(SupervisorTest, WarmUpCountIsBounded)
{
  feed(100);
  EXPECT_EQ(s.warmSamples(), base::kMaxOrders + 1);
}

TEST_F(SupervisorTest, StaleSensorsStopAndRestartTheHistory)
{
  run();
  clock.t += p.sensor_timeout - 0.001;  // within the timeout: still fresh
  s.setPoint(kZeroSetPoint);
  EXPECT_FALSE(s.update().changed);
  clock.t += 0.002;
  s.setPoint(kZeroSetPoint);
  const auto t = s.update();
  EXPECT_TRUE(t.changed);
  EXPECT_TRUE(t.deactivate());
  EXPECT_TRUE(t.warn());
  EXPECT_TRUE(t.restart_history);
  EXPECT_EQ(s.state(), loop::NodeState::kStale);
  EXPECT_NE(s.reason().find("no sensor sample for 0.251 s (sensor_timeout 0.25 s)"), std::string::npos) << s.reason();
  EXPECT_EQ(s.staleEvents(), 1u);
  EXPECT_EQ(s.warmSamples(), 0);
  // Stays stale, and the history is restarted only once.
  clock.t += 0.1;
  s.setPoint(kZeroSetPoint);
  const auto again = s.update();
  EXPECT_FALSE(again.changed);
  EXPECT_FALSE(again.restart_history);
  EXPECT_EQ(s.staleEvents(), 1u);
}

TEST_F(SupervisorTest, SensorsBackWarmUpThenRun)
{
  run();
  clock.t += 1.0;
  s.setPoint(kZeroSetPoint);
  ASSERT_EQ(s.update().to, loop::NodeState::kStale);
  s.historyRestarted();
  feed(1);
  auto t = s.update();
  EXPECT_TRUE(t.changed);
  EXPECT_EQ(t.to, loop::NodeState::kWaiting);
  EXPECT_EQ(s.reason(), "warming up the generalizer");
  EXPECT_FALSE(t.activate());
  EXPECT_FALSE(t.deactivate());
  feed(p.aic.numOrders() - 1);
  t = s.update();
  EXPECT_TRUE(t.activate());
}

TEST_F(SupervisorTest, SensorsLostWithoutSetPointIsStale)
{
  feed(2, /*with_set_point=*/false);
  clock.t += 1.0;
  const auto t = s.update();
  EXPECT_EQ(t.to, loop::NodeState::kStale);
  EXPECT_TRUE(t.warn());
  EXPECT_FALSE(t.deactivate());  // was not running
  EXPECT_TRUE(t.restart_history);
}

TEST_F(SupervisorTest, StaleSetPointStopsAndResumesWithoutWarmUp)
{
  run();
  for (int i = 0; i < 30; ++i)  // sensors keep coming, the set point does not
  {
    clock.t += 0.02;
    s.sampleAccepted(base::Vector2::Zero());
  }
  const auto t = s.update();
  EXPECT_TRUE(t.deactivate());
  EXPECT_TRUE(t.warn());
  EXPECT_FALSE(t.restart_history);
  EXPECT_EQ(s.state(), loop::NodeState::kStale);
  EXPECT_NE(s.reason().find("no set point for 0.6"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("(set_point_timeout 0.5 s)"), std::string::npos) << s.reason();
  s.setPoint(kZeroSetPoint);
  EXPECT_TRUE(s.update().activate());  // the generalizer is still warm
}

TEST_F(SupervisorTest, RunawayHoldsThenRestarts)
{
  run();
  const auto t = s.runaway("belief update");
  EXPECT_TRUE(t.changed);
  EXPECT_TRUE(t.deactivate());
  EXPECT_FALSE(t.warn());
  EXPECT_EQ(s.state(), loop::NodeState::kRunaway);
  EXPECT_EQ(s.reason(), "runaway in the belief update");
  EXPECT_EQ(s.runaways(), 1u);
  EXPECT_FALSE(s.active());
  // During the hold, fresh inputs do not restart the controller.
  for (int i = 0; i < 45; ++i)
  {
    feed(1);
    EXPECT_FALSE(s.update().changed) << i;
  }
  EXPECT_EQ(s.state(), loop::NodeState::kRunaway);
  feed(6);  // 1.02 s after the runaway: the hold is over
  const auto back = s.update();
  EXPECT_TRUE(back.activate());
  EXPECT_EQ(back.from, loop::NodeState::kRunaway);
}

TEST_F(SupervisorTest, RunawayHoldEndsStaleWithoutInputs)
{
  run();
  s.runaway("action update");
  clock.t += 0.5;
  const auto during = s.update();  // the sensors timed out during the hold: history restarted, still runaway
  EXPECT_FALSE(during.changed);
  EXPECT_TRUE(during.restart_history);
  clock.t += 0.6;
  const auto t = s.update();
  EXPECT_EQ(t.to, loop::NodeState::kStale);
  EXPECT_TRUE(t.warn());
  EXPECT_FALSE(t.deactivate());
}

TEST_F(SupervisorTest, RunawayHoldOfZeroEndsAtOnce)
{
  p.runaway_hold_time = 0.0;
  s.setParams(p);
  run();
  s.runaway("belief update");
  EXPECT_TRUE(s.update().activate());
}

TEST_F(SupervisorTest, EmbeddingOrderChangeWarmsUpAgain)
{
  run();
  const auto t = s.embeddingOrderChanged();
  EXPECT_TRUE(t.deactivate());
  EXPECT_EQ(s.state(), loop::NodeState::kWaiting);
  EXPECT_EQ(s.reason(), "embedding order changed; warming up");
  p.aic.embedding_order = 5;
  p.aic.var_mu.assign(6, 1.0);
  p.aic.var_y.assign(6, 1.0);
  s.setParams(p);
  feed(5);
  EXPECT_FALSE(s.update().changed);  // p+1 = 6 samples needed
  feed(1);
  EXPECT_TRUE(s.update().activate());
}

TEST_F(SupervisorTest, EmbeddingOrderChangeWhileWaitingOnlyResetsWarmUp)
{
  feed(10, /*with_set_point=*/false);
  const auto t = s.embeddingOrderChanged();
  EXPECT_FALSE(t.changed);
  EXPECT_EQ(s.warmSamples(), 0);
  EXPECT_EQ(s.state(), loop::NodeState::kWaiting);
}

TEST_F(SupervisorTest, NewTimeoutsApply)
{
  run();
  p.sensor_timeout = 2.0;
  p.set_point_timeout = 2.0;
  s.setParams(p);
  clock.t += 1.0;
  EXPECT_FALSE(s.update().changed);
  EXPECT_TRUE(s.sensorsFresh());
  EXPECT_TRUE(s.setPointFresh());
}

TEST_F(SupervisorTest, SetPointsAreCheckedAndClamped)
{
  const double ok[6] = { 0.5, 0, 0, 0, 0, -1.0 };
  EXPECT_EQ(s.setPoint(ok), loop::SetPointResult::kAccepted);
  EXPECT_EQ(s.goal(), base::Vector3(0.5, 0.0, -1.0));
  const double fast[6] = { 3.0, 0.7, 0, 0, 0, -9.0 };
  EXPECT_EQ(s.setPoint(fast), loop::SetPointResult::kClamped);
  EXPECT_EQ(s.goal(), base::Vector3(2.0, 0.0, -4.0));  // max_linear_speed, max_angular_speed; linear.y ignored
  EXPECT_EQ(s.setPointClamps(), 1u);
  for (int field = 0; field < 6; ++field)
  {
    double bad[6] = { 0.1, 0, 0, 0, 0, 0.1 };
    bad[field] = field % 2 ? kNaN : std::numeric_limits<double>::infinity();
    EXPECT_EQ(s.setPoint(bad), loop::SetPointResult::kDropped) << field;
  }
  EXPECT_EQ(s.setPointDrops(), 6u);
  EXPECT_EQ(s.goal(), base::Vector3(2.0, 0.0, -4.0));  // unchanged by dropped set points
}

TEST_F(SupervisorTest, AgesAndFreshness)
{
  EXPECT_EQ(s.sampleAge(), -1.0);
  EXPECT_EQ(s.imuAge(), -1.0);
  EXPECT_EQ(s.setPointAge(), -1.0);
  EXPECT_FALSE(s.sensorsFresh());
  EXPECT_FALSE(s.setPointFresh());
  s.sampleAccepted(base::Vector2::Zero());
  s.imuAccepted();
  s.setPoint(kZeroSetPoint);
  clock.t += 0.3;
  EXPECT_NEAR(s.sampleAge(), 0.3, kTol);
  EXPECT_NEAR(s.imuAge(), 0.3, kTol);
  EXPECT_NEAR(s.setPointAge(), 0.3, kTol);
  EXPECT_FALSE(s.sensorsFresh());  // > 0.25 s
  EXPECT_TRUE(s.setPointFresh());  // <= 0.5 s
}

// ---- MCU stop (jackal_msgs/Status, jackal_msgs/Feedback)

TEST_F(SupervisorTest, ExternalStopHoldsThenResumesBumpless)
{
  run();
  s.mcuStatus(true, true, true);  // external stop present and stopped
  feed(1);
  const auto held = s.update();
  EXPECT_TRUE(held.deactivate());  // the node publishes the idle command (measured wheels) at once
  EXPECT_TRUE(held.warn());
  EXPECT_EQ(s.state(), loop::NodeState::kHeld);
  EXPECT_FALSE(s.active());
  EXPECT_NE(s.reason().find("external stop"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("measured wheel speeds"), std::string::npos) << s.reason();
  EXPECT_EQ(s.mcuStops(), 1u);
  // Held while the stop lasts, however long (inputs fresh).
  for (int i = 0; i < 100; ++i)
  {
    feed(1);
    EXPECT_FALSE(s.update().changed);
  }
  s.mcuStatus(true, true, false);  // released
  feed(1);
  const auto resumed = s.update();
  EXPECT_TRUE(resumed.activate());  // reset + start from the measured wheels: bumpless
  EXPECT_FALSE(resumed.restart_history);
  EXPECT_EQ(s.state(), loop::NodeState::kRunning);
}

TEST_F(SupervisorTest, DriversInactiveHold)
{
  run();
  s.mcuStatus(false, false, false);
  feed(1);
  EXPECT_TRUE(s.update().deactivate());
  EXPECT_EQ(s.state(), loop::NodeState::kHeld);
  EXPECT_NE(s.reason().find("drivers_active false"), std::string::npos) << s.reason();
  // An external stop present but not stopped is not a stop.
  s.mcuStatus(true, true, false);
  feed(1);
  EXPECT_TRUE(s.update().activate());
}

TEST_F(SupervisorTest, FeedbackModeNoneHoldsAndExpires)
{
  run();
  s.mcuFeedback(loop::kMcuModeNone);
  feed(1);
  EXPECT_TRUE(s.update().deactivate());
  EXPECT_EQ(s.state(), loop::NodeState::kHeld);
  EXPECT_NE(s.reason().find("MODE_NONE"), std::string::npos) << s.reason();
  // Back to MODE_VELOCITY: running again.
  s.mcuFeedback(0);
  feed(1);
  EXPECT_TRUE(s.update().activate());
  // A MODE_NONE not repeated for longer than kMcuFeedbackExpiry no longer holds.
  s.mcuFeedback(loop::kMcuModeNone);
  feed(1);
  EXPECT_EQ(s.update().to, loop::NodeState::kHeld);
  for (int i = 0; i * 0.02 <= loop::kMcuFeedbackExpiry; ++i)
  {
    feed(1);
    s.update();
  }
  EXPECT_EQ(s.state(), loop::NodeState::kRunning);
}

TEST_F(SupervisorTest, StaleSensorsOutrankAnMcuStop)
{
  // Without fresh sensors there are no measured wheel speeds to hold: zero command (kStale).
  run();
  s.mcuStatus(true, true, true);
  clock.t += p.sensor_timeout + 0.01;
  EXPECT_EQ(s.update().to, loop::NodeState::kStale);
  // Before any sample: waiting, not held.
  FakeClock c2;
  loop::Supervisor fresh{ p, c2 };
  fresh.mcuStatus(false, false, false);
  EXPECT_EQ(fresh.update().to, loop::NodeState::kWaiting);
  EXPECT_TRUE(fresh.mcuStopped());
}

TEST_F(SupervisorTest, KeepAliveOnlyWhileRunningAndActionLate)
{
  // action_trigger sample: the timer repeats the command after 1.5 action periods (30 ms at
  // 50 Hz) without an action step, and only while running.
  EXPECT_FALSE(s.keepAliveDue());  // waiting
  run();
  s.actionPublished();
  clock.t += 0.029;
  EXPECT_FALSE(s.keepAliveDue());
  clock.t += 0.002;
  EXPECT_TRUE(s.keepAliveDue());
  s.actionPublished();
  EXPECT_FALSE(s.keepAliveDue());
  clock.t += 0.5;  // sensors and set point stale: not running, no keep-alive (zeros instead)
  s.update();
  ASSERT_FALSE(s.active());
  EXPECT_FALSE(s.keepAliveDue());
}

TEST(LoopScheduler, OnTimeTicksAreOneStep)
{
  loop::LoopScheduler loop(1000.0, loop::kMaxBeliefIntervalFactor, true);
  const auto first = loop.tick(-1.0);  // first tick: nominal period
  EXPECT_EQ(first.steps, 1);
  EXPECT_NEAR(first.h, 0.001, kTol);
  for (int i = 0; i < 100; ++i)
  {
    const auto t = loop.tick(i % 2 ? 0.0012 : 0.0008);  // jitter +-0.2 ms
    EXPECT_EQ(t.steps, 1) << i;
  }
  EXPECT_EQ(loop.stats().catch_up_steps, 0u);
  EXPECT_EQ(loop.stats().overruns, 0u);
  EXPECT_EQ(loop.stats().ticks, 101u);
  EXPECT_NEAR(loop.stats().window_max_interval, 0.0012, kTol);
}

TEST(LoopScheduler, LateTickCatchesUp)
{
  loop::LoopScheduler loop(1000.0, loop::kMaxBeliefIntervalFactor, true);
  const auto t = loop.tick(0.004);  // 3 ticks missed
  EXPECT_EQ(t.steps, 4);
  EXPECT_NEAR(t.h, 0.001, kTol);
  EXPECT_NEAR(t.interval, 0.004, kTol);
  EXPECT_EQ(loop.stats().catch_up_steps, 3u);
  EXPECT_EQ(loop.stats().overruns, 1u);
  EXPECT_EQ(loop.stats().clamped, 0u);
}

TEST(LoopScheduler, LongGapIsClampedToTenPeriods)
{
  loop::LoopScheduler loop(1000.0, loop::kMaxBeliefIntervalFactor, true);
  const auto t = loop.tick(0.5);
  EXPECT_EQ(t.steps, 10);
  EXPECT_NEAR(t.interval, 0.010, kTol);
  EXPECT_NEAR(t.h, 0.001, kTol);
  EXPECT_EQ(loop.stats().clamped, 1u);
}

TEST(LoopScheduler, FastLoopsCatchUpAtLeastTenMilliseconds)
{
  // At 10 kHz ten periods are 1 ms, less than a preemption on a loaded machine: the belief
  // loop still catches up to kMinBeliefCatchUpInterval (10 ms), in steps of one period.
  loop::LoopScheduler loop(10000.0, loop::kMaxBeliefIntervalFactor, true, loop::kMinBeliefCatchUpInterval);
  auto t = loop.tick(0.005);
  EXPECT_EQ(t.steps, 50);
  EXPECT_NEAR(t.h, 1e-4, kTol);
  EXPECT_EQ(loop.stats().clamped, 0u);
  t = loop.tick(0.5);
  EXPECT_EQ(t.steps, 100);
  EXPECT_NEAR(t.interval, 0.010, kTol);
  EXPECT_EQ(loop.stats().clamped, 1u);
  EXPECT_NEAR(loop.stats().maxInterval(), 0.010, kTol);
  // Slow loops keep ten periods (longer than the minimum).
  loop::LoopScheduler slow(50.0, loop::kMaxBeliefIntervalFactor, true, loop::kMinBeliefCatchUpInterval);
  EXPECT_NEAR(slow.tick(1.0).interval, 0.2, kTol);
  EXPECT_EQ(slow.tick(1.0).steps, 10);
}

TEST(LoopScheduler, NoIntervalIsLongerThanTheControllersLongestStep)
{
  // At the slowest rate the parameters allow, three action periods and ten belief periods are
  // longer than the controller's longest step, params::kMaxStep.
  loop::LoopScheduler action(params::kMinRate, loop::kMaxActionIntervalFactor, false);
  EXPECT_DOUBLE_EQ(action.stats().maxInterval(), params::kMaxStep);
  EXPECT_DOUBLE_EQ(action.tick(4.0).h, params::kMaxStep);
  loop::LoopScheduler belief(params::kMinRate, loop::kMaxBeliefIntervalFactor, true, loop::kMinBeliefCatchUpInterval);
  const auto t = belief.tick(100.0);
  EXPECT_EQ(t.steps, 1);
  EXPECT_DOUBLE_EQ(t.h, params::kMaxStep);
}

TEST(LoopScheduler, FractionsAverageOut)
{
  // 1.5 periods per tick: steps alternate 2, 1, 2, 1 ... so 1.5 steps per tick on average.
  loop::LoopScheduler loop(1000.0, loop::kMaxBeliefIntervalFactor, true);
  int total = 0;
  for (int i = 0; i < 100; ++i)
  {
    total += loop.tick(0.0015).steps;
  }
  EXPECT_EQ(total, 150);
}

TEST(LoopScheduler, ActionLoopIsOneClampedStep)
{
  loop::LoopScheduler loop(50.0, loop::kMaxActionIntervalFactor, false);
  auto t = loop.tick(0.1);  // 5 periods
  EXPECT_EQ(t.steps, 1);
  EXPECT_NEAR(t.h, 0.06, kTol);  // clamped to 3 periods
  EXPECT_EQ(loop.stats().clamped, 1u);
  EXPECT_EQ(loop.stats().catch_up_steps, 0u);
  t = loop.tick(std::numeric_limits<double>::quiet_NaN());
  EXPECT_NEAR(t.h, 0.02, kTol);  // non-finite: nominal
}

TEST(LoopScheduler, StatisticsWindowAndRate)
{
  loop::LoopScheduler loop(100.0, loop::kMaxBeliefIntervalFactor, true);
  loop.tick(0.012);
  loop.recordDuration(0.003);
  loop.recordDuration(0.001);
  EXPECT_NEAR(loop.stats().window_max_duration, 0.003, kTol);
  EXPECT_NEAR(loop.stats().window_abs_jitter_sum, 0.002, kTol);
  loop.resetWindow();
  EXPECT_EQ(loop.stats().window_ticks, 0u);
  EXPECT_EQ(loop.stats().window_max_duration, 0.0);
  EXPECT_EQ(loop.stats().ticks, 1u);  // counters kept
  loop.setRate(200.0);
  EXPECT_NEAR(loop.nominalPeriod(), 0.005, kTol);
  EXPECT_NEAR(loop.rate(), 200.0, 1e-9);
}

TEST(NodeStateNames, AreTheDiagnosticsStrings)
{
  EXPECT_STREQ(loop::toString(loop::NodeState::kWaiting), "waiting");
  EXPECT_STREQ(loop::toString(loop::NodeState::kRunning), "running");
  EXPECT_STREQ(loop::toString(loop::NodeState::kStale), "stale");
  EXPECT_STREQ(loop::toString(loop::NodeState::kRunaway), "runaway");
  EXPECT_STREQ(loop::toString(loop::NodeState::kHeld), "held");
}

}  // namespace
}  // namespace jackal_aic
