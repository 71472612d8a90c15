/// Tests of the robot model (belief_model robot): the wheel loop with its commands in flight, the
/// beliefs in their filter form and the action through the latency (doc/active_inference.md,
/// 'The robot model').
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/latency_action.hpp"
#include "jackal_aic/aic/latency_learner.hpp"
#include "jackal_aic/aic/residual_run.hpp"
#include "jackal_aic/aic/robot_belief.hpp"
#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "wheel_loop_drive.hpp"

using namespace jackal_aic;
using Status = aic::ActiveInferenceController::Status;

namespace
{
/// The recommended controller with the robot model.
params::AicParams robotParams()
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  return p;
}

params::RobotModelParams model()
{
  params::RobotModelParams p;
  p.latency = 0.1;
  p.wheel_time_constant = 0.01;
  p.wheel_acceleration = 40.0;
  return p;
}

/// Drive `belief` for `samples` gyro-free samples 20 ms apart: each 20 ms of 1 ms predictions with
/// the wheels commanded `command` [rad/s] (left, right) and the goal's yaw rate `turn` [rad/s], then
/// a correction by the measured wheel speeds `measured` [rad/s] (gyro reading 0, every channel used)
/// with +-1e-4 rad/s of alternating noise (a real encoder's reading of a moving wheel never repeats
/// bit for bit; one that does is frozen: RobotBelief::frozenEncoderSamples()).
void drive(aic::RobotBelief* belief, const aic::WheelLoopModel& loop, const base::Vector2& command,
           const base::Vector2& measured, int samples, double turn = 0.0)
{
  for (int k = 0; k < 20 * samples; ++k)
  {
    belief->predict(0.001, loop, command, base::Vector2::Zero(), 0.0, turn);
    if (k % 20 == 19)
    {
      const double noise = (k / 20) % 2 == 0 ? 1e-4 : -1e-4;
      ASSERT_TRUE(belief->correct(measured + base::Vector2::Constant(noise), 0.0));
    }
  }
}

/// Run controller `c` for `steps` belief steps of 1 ms with the measurement `y` set every 20 ms
/// and an action step of 20 ms after every 20th belief step (the node's 1 kHz / 50 Hz schedule).
/// `jitter` [rad/s]: alternating +-jitter on the wheel readings (an encoder's noise: a reading
/// that repeats bit for bit while the command moves is a frozen encoder's).
void runController(aic::ActiveInferenceController* c, const base::YTilde& y, int steps, double jitter = 0.0)
{
  for (int k = 0; k < steps; ++k)
  {
    if (k % 20 == 0)
    {
      base::YTilde sample = y;
      const double noise = (k / 20) % 2 == 0 ? jitter : -jitter;
      sample(base::kOmegaLeft, 0) += noise;
      sample(base::kOmegaRight, 0) += noise;
      ASSERT_TRUE(c->setMeasurement(sample));
    }
    ASSERT_EQ(c->updateBeliefs(0.001), Status::kOk);
    if (k % 20 == 19)
    {
      ASSERT_EQ(c->updateAction(0.02), Status::kOk);
    }
  }
}
}  // namespace

TEST(WheelLoopModel, CommandsTakeEffectOneLatencyLater)
{
  aic::WheelLoopModel loop(model());
  loop.record(0.0, base::Vector2(1.0, 2.0));
  loop.record(0.02, base::Vector2(3.0, 4.0));
  EXPECT_TRUE(loop.commandAt(0.05).isZero());  // before the first command reached the wheels
  EXPECT_DOUBLE_EQ(loop.commandAt(0.1)(0), 1.0);
  EXPECT_DOUBLE_EQ(loop.commandAt(0.119)(1), 2.0);
  EXPECT_DOUBLE_EQ(loop.commandAt(0.12)(0), 3.0);
  EXPECT_DOUBLE_EQ(loop.lastCommand()(1), 4.0);
}

TEST(WheelLoopModel, StepIsTheExactLagThenTheRateBound)
{
  const aic::WheelLoopModel loop(model());
  double gain = 0.0;
  // A small change: the lag, exactly.
  EXPECT_NEAR(loop.step(0.0, 0.01, 0.0, 0.001, &gain), 0.01 * (1.0 - std::exp(-0.1)), 1e-15);
  EXPECT_NEAR(gain, std::exp(-0.1), 1e-15);
  // A large one: A_w h.
  EXPECT_NEAR(loop.step(0.0, 10.0, 0.0, 0.001, &gain), 0.04, 1e-15);
  EXPECT_EQ(gain, 1.0);
  EXPECT_NEAR(loop.step(0.0, -10.0, 0.0, 0.001), -0.04, 1e-15);
}

TEST(WheelLoopModel, ACommandBeyondTheKickRangeBuysNothingMoreInItsStep)
{
  // The default configuration's identified loop: c 0.787, A_ff 34.76, A_w 42.87 rad/s^2, T_w 0.01365 s.
  params::RobotModelParams p = model();
  p.wheel_feedforward = 0.787;
  p.wheel_feedforward_acceleration = 34.76;
  p.wheel_acceleration = 42.87;
  p.wheel_time_constant = 0.01365;
  const aic::WheelLoopModel loop(p);
  const double h = 0.02;
  const double lag = (42.87 - 34.76) * h / (1.0 - std::exp(-h / 0.01365));
  EXPECT_NEAR(loop.kickRange(h), lag + 34.76 * h / 0.787, 1e-12);
  // From a wheel at rest, the previous command at the lag's bound: a command at the kick range
  // gives what the bound of 20 rad/s gives within the step; one 0.1 rad/s short gives less.
  const auto response = [&](double u) { return loop.step(0.0, u, (u - lag) / h, h); };
  EXPECT_NEAR(response(loop.kickRange(h)), response(20.0), 1e-12);
  EXPECT_LT(response(loop.kickRange(h) - 0.1), response(20.0) - 1e-3);
  // A step that is no step reaches nothing.
  EXPECT_EQ(loop.kickRange(0.0), 0.0);
  EXPECT_EQ(loop.kickRange(-0.02), 0.0);
  EXPECT_EQ(loop.kickRange(std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_EQ(loop.kickRange(std::numeric_limits<double>::infinity()), 0.0);
  // Without the feed-forward, the lag's bound alone.
  EXPECT_NEAR(aic::WheelLoopModel(model()).kickRange(h), 40.0 * h / (1.0 - std::exp(-2.0)), 1e-12);
}

TEST(WheelLoopModel, TheCommandStreamsRateIsFedForward)
{
  params::RobotModelParams p = model();
  p.wheel_feedforward = 0.8;
  p.wheel_feedforward_acceleration = 30.0;
  aic::WheelLoopModel loop(p);
  loop.record(0.02, base::Vector2(1.0, -0.2));
  // The rate is the difference to the command before over their interval, from L on.
  EXPECT_TRUE(loop.commandRateAt(0.11).isZero());
  EXPECT_NEAR(loop.commandRateAt(0.12)(0), 50.0, 1e-12);
  EXPECT_NEAR(loop.commandRateAt(0.12)(1), -10.0, 1e-12);
  const base::Vector2 next = loop.rateOf(0.04, base::Vector2(1.5, 0.0));
  EXPECT_NEAR(next(0), 25.0, 1e-12);
  EXPECT_NEAR(next(1), 10.0, 1e-12);
  // The feed-forward c u' within +-A_ff, on top of the lag; the lag's bound is A_w - A_ff.
  EXPECT_NEAR(loop.step(0.0, 0.0, 50.0, 0.001), 0.030, 1e-15);
  EXPECT_NEAR(loop.step(0.0, 0.0, -10.0, 0.001), -0.008, 1e-15);
  double gain = 0.0;
  EXPECT_NEAR(loop.step(0.0, 10.0, 0.0, 0.001, &gain), 0.010, 1e-15);
  EXPECT_EQ(gain, 1.0);
  EXPECT_NEAR(loop.step(0.0, 10.0, 50.0, 0.001), 0.040, 1e-15);
  // predict() applies it while the command is in effect at the wheels: over 20 ms the left side gets
  // c u' = 40 rad/s^2 capped at 30, plus the lag at its bound of 10 (1 - omega stays above the
  // 0.105 rad/s where the lag's 1 ms change would drop below the bound).
  const base::Vector2 w = loop.predict(base::Vector2::Zero(), base::Vector2::Zero(), 0.12, 0.14);
  EXPECT_NEAR(w(0), 0.02 * (30.0 + 10.0), 1e-9);
}

TEST(LatencyAction, WithTheFeedForwardInTheModelASmallStepIsNotSentAboveAndBack)
{
  // A plant whose wheel loop feeds the command's rate forward (c 0.8 within A_ff 30 rad/s^2), a
  // goal step of 1 rad/s, more than the loop gives in one 20 ms action step: the action that knows
  // the feed-forward raises its command to the goal and holds it there; the one that does not sends
  // a first command above the goal and brings it back, which the feed-forward turns into a brake.
  params::RobotModelParams plant = model();
  plant.wheel_feedforward = 0.8;
  plant.wheel_feedforward_acceleration = 30.0;
  const double h = 0.02;
  // The largest command, and the wheel speed 40 ms after the first command reached the wheels.
  const auto run = [&](const params::RobotModelParams& assumed, double* peak_command, double* at_40ms) {
    aic::WheelLoopModel truth(plant);
    aic::WheelLoopModel believed(assumed);
    base::Vector2 omega = base::Vector2::Zero();
    base::Vector2 a = base::Vector2::Zero();
    *peak_command = 0.0;
    for (int k = 0; k < 30; ++k)
    {
      const double now = k * h;
      // The wheels as the plant moves them to now (the belief is the truth here).
      if (k > 0)
      {
        omega = truth.predict(omega, base::Vector2::Zero(), now - h, now);
      }
      const aic::LatencyActionResult r = aic::LatencyAction::step(believed, omega, base::Vector2::Zero(), now,
                                                                  base::Vector2(1.0, 1.0), a, h, 1.0 / h, 20.0, 1.0);
      a = r.command;
      truth.record(now, a);
      believed.record(now, a);
      *peak_command = std::max(*peak_command, a(0));
      if (k == 7)  // now = L + 40 ms
      {
        *at_40ms = omega(0);
      }
    }
  };
  double peak = 0.0;
  double rise = 0.0;
  run(plant, &peak, &rise);
  EXPECT_LE(peak, 1.0 + 1e-6);
  double peak_without = 0.0;
  double rise_without = 0.0;
  run(model(), &peak_without, &rise_without);
  EXPECT_GT(peak_without, 1.05);
  EXPECT_GT(rise, rise_without);
}

TEST(WheelLoopModel, PredictRunsTheCommandsInFlight)
{
  aic::WheelLoopModel loop(model());
  loop.record(0.0, base::Vector2(1.0, -1.0));
  // Nothing reaches the wheels before L; 0.3 s after the command the sides sit at u - d.
  const base::Vector2 early = loop.predict(base::Vector2::Zero(), base::Vector2::Zero(), 0.0, 0.1);
  EXPECT_TRUE(early.isZero());
  const base::Vector2 late = loop.predict(base::Vector2::Zero(), base::Vector2(0.1, 0.0), 0.0, 0.4);
  EXPECT_NEAR(late(0), 0.9, 1e-9);
  EXPECT_NEAR(late(1), -1.0, 1e-9);
}

TEST(ResidualRun, NResidualsInARowBeyondTheirLimitCompleteARun)
{
  aic::ResidualRun run;
  EXPECT_FALSE(run.add(1.0, true, INFINITY, 3));
  EXPECT_FALSE(run.add(2.0, true, INFINITY, 3));
  EXPECT_TRUE(run.add(3.0, true, INFINITY, 3));
  EXPECT_DOUBLE_EQ(run.mean(), 2.0);
  EXPECT_EQ(run.count(), 0);  // the next run starts afresh
  // A residual within its limit ends the run; clear() ends it too.
  EXPECT_FALSE(run.add(1.0, true, INFINITY, 3));
  EXPECT_FALSE(run.add(0.1, false, INFINITY, 3));
  EXPECT_EQ(run.count(), 0);
  EXPECT_FALSE(run.add(1.0, true, INFINITY, 3));
  run.clear();
  EXPECT_EQ(run.count(), 0);
  EXPECT_FALSE(run.add(NAN, true, INFINITY, 3));  // a non-finite residual ends it
  EXPECT_EQ(run.count(), 0);
}

TEST(ResidualRun, AResidualOutsideTheBandOfTheFirstStartsANewRun)
{
  aic::ResidualRun run;
  EXPECT_FALSE(run.add(1.0, true, 0.1, 2));
  EXPECT_FALSE(run.add(1.5, true, 0.1, 2));  // still moving: a new run from 1.5
  EXPECT_EQ(run.count(), 1);
  EXPECT_TRUE(run.add(1.55, true, 0.1, 2));
  EXPECT_DOUBLE_EQ(run.mean(), 1.525);
}

TEST(RobotBelief, FollowsTheEncodersAndTheGyroAtTheirPrecision)
{
  params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // The wheels turn at 2 rad/s each way while the model thinks nothing was commanded: the
  // measurement wins (the model's noise q_w against sigma_e).
  for (int k = 0; k < 200; ++k)
  {
    belief.predict(0.001, loop, base::Vector2::Zero(), base::Vector2::Zero(), 0.2, 0.0);
    if (k % 20 == 19)
    {
      // A transient: the slow states are held (the controller's learning gate).
      aic::RobotBelief::SampleUse held;
      held.learn = false;
      ASSERT_TRUE(belief.correct(base::Vector2(-2.0, 2.0), 0.75, held));
    }
  }
  EXPECT_NEAR(belief.wheelSpeeds()(0), -2.0, 0.05);
  EXPECT_NEAR(belief.wheelSpeeds()(1), 2.0, 0.05);
  EXPECT_NEAR(belief.yawRate(), 0.75, 0.02);
  EXPECT_GT(belief.sensoryFreeEnergy(), 0.0);
  EXPECT_GT(belief.priorFreeEnergy(), 0.0);
}

TEST(RobotBelief, LearnsTheShortfallTheWheelsDoNotDeliver)
{
  params::RobotModelParams p = model();
  p.shortfall_noise = 0.05;
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // Commanded 5 rad/s, delivered 4.8 rad/s (a load): after a few seconds d = 0.2.
  drive(&belief, loop, base::Vector2(5.0, 5.0), base::Vector2(4.8, 4.8), 500);
  EXPECT_NEAR(belief.shortfalls()(0), 0.2, 0.01);
  EXPECT_NEAR(belief.shortfalls()(1), 0.2, 0.01);
}

TEST(RobotBelief, AStalledWheelIsAShortfallJump)
{
  const params::RobotModelParams p = model();  // the default shortfall drift: 0.002 rad/s^0.5
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // Commanded 3 rad/s, the wheels held at 0.05 rad/s (a stall): once the wheel loop would have
  // settled (3 / 40 + 5 x 0.01 = 0.125 s) five samples beyond the threshold make d the stall.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  EXPECT_EQ(belief.shortfallJumps(), 2u);  // one per side
  EXPECT_NEAR(belief.shortfalls()(0), 2.95, 0.01);
  EXPECT_NEAR(belief.wheelSpeeds()(1), 0.05, 0.01);
  // Released: the wheels deliver the command again, ahead of the jumps; they are dropped.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(3.0, 3.0), 50);
  EXPECT_EQ(belief.shortfallReleases(), 2u);
  EXPECT_EQ(belief.shortfallJumps(), 2u);
  EXPECT_NEAR(belief.shortfalls()(0), 0.0, 0.01);
  EXPECT_NEAR(belief.shortfalls()(1), 0.0, 0.01);
}

TEST(RobotBelief, AWheelHeldAgainAfterItsJumpSaturatesItsSide)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // A stall at 0.05 rad/s: commanded 3 rad/s, the jump takes d = 2.95 rad/s, which explains the
  // wheel: the stall ends.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  ASSERT_NEAR(belief.shortfalls()(0), 2.95, 0.01);
  ASSERT_FALSE(belief.stalled(0));
  ASSERT_FALSE(belief.saturated(0));
  const std::uint64_t jumps = belief.shortfallJumps();
  // The command raised by that jump does not move the wheel: held again within five samples, long
  // before the command has held still for a second jump; the side is saturated.
  drive(&belief, loop, base::Vector2(5.95, 5.95), base::Vector2(0.05, 0.05), 6);
  EXPECT_TRUE(belief.saturated(0));
  EXPECT_TRUE(belief.saturated(1));
  EXPECT_EQ(belief.unansweredJumps(), 2u);  // one per side
  EXPECT_EQ(belief.shortfallJumps(), jumps);
  // A wheel the raised command moves is not saturated: the same stall, the wheel answering at 1 rad/s.
  aic::RobotBelief answered(p);
  drive(&answered, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  drive(&answered, loop, base::Vector2(5.95, 5.95), base::Vector2(1.0, 1.0), 6);
  EXPECT_FALSE(answered.saturated(0));
  EXPECT_EQ(answered.unansweredJumps(), 0u);
}

TEST(RobotBelief, ASecondJumpOfAWheelThatIsShortNotHeldSaturatesItsSide)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // Commanded 3 rad/s the wheel gives 2 (short, not held: more than half): a jump takes d = 1.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(2.0, 2.0), 50);
  ASSERT_NEAR(belief.shortfalls()(0), 1.0, 0.01);
  ASSERT_FALSE(belief.stalled(0));
  // Made up (4 rad/s), the wheel stays at 2: never held, so the second jump shows it unanswered.
  drive(&belief, loop, base::Vector2(4.0, 4.0), base::Vector2(2.0, 2.0), 50);
  EXPECT_FALSE(belief.stalled(0));
  EXPECT_TRUE(belief.saturated(0));
  EXPECT_EQ(belief.shortfallJumps(), 4u);
  EXPECT_EQ(belief.unansweredJumps(), 2u);
}

TEST(RobotBelief, AJumpTheWheelDoesNotAnswerSaturatesItsSide)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // A stall at 0.05 rad/s: commanded 3 rad/s, the jump takes d = 2.95 rad/s, made up in full.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  ASSERT_NEAR(belief.shortfalls()(0), 2.95, 0.01);
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), belief.shortfallsAt(0.0));
  EXPECT_FALSE(belief.saturated(0));
  // The command raised by that jump does not move the wheel: the sides are saturated (held again,
  // AWheelHeldAgainAfterItsJumpSaturatesItsSide), the belief stays honest (d follows the command)
  // and none of their shortfall is made up.
  drive(&belief, loop, base::Vector2(5.95, 5.95), base::Vector2(0.05, 0.05), 50);
  EXPECT_NEAR(belief.shortfalls()(0), 5.9, 0.01);
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), base::Vector2::Zero());
  EXPECT_EQ(belief.unansweredJumps(), 2u);  // one per side
  EXPECT_TRUE(belief.saturated(0));
  EXPECT_TRUE(belief.saturated(1));
  EXPECT_FALSE(belief.saturated(2));  // no such side
  // Its speed does not depend on its command: the command back at 3 rad/s, the model's wheel stays
  // where the jump found it (d follows the command), and no jump or release is taken.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  EXPECT_NEAR(belief.shortfalls()(0), 2.95, 0.01);
  EXPECT_NEAR(belief.wheelSpeeds()(0), 0.05, 0.01);
  EXPECT_EQ(belief.shortfallJumps(), 2u);  // the first, one per side
  EXPECT_EQ(belief.shortfallReleases(), 0u);
  EXPECT_TRUE(belief.saturated(0));
  // Freed: the wheels run ahead of the jumps, which are dropped with the saturation.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(3.0, 3.0), 50);
  EXPECT_GE(belief.shortfallReleases(), 2u);
  EXPECT_FALSE(belief.saturated(0));
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), belief.shortfallsAt(0.0));
  EXPECT_NEAR(belief.shortfalls()(0), 0.0, 0.01);
}

TEST(RobotBelief, AJumpAfterACommandThatWasNotRaisedIsMadeUp)
{
  // The command at the wheels stays at 3 rad/s after the first jump (the raised command has not
  // reached them yet, one latency behind the action, or was not made up), and the wheel settles a
  // little lower, beyond the jump limit but within the band of a wheel that does not move. No raised command went unanswered: the second jump is
  // made up too.
  const params::RobotModelParams p = model();
  const double band = aic::RobotBelief::kJumpThreshold * std::sqrt(2.0) * p.encoder_noise;
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(2.0, 2.0), 50);
  ASSERT_NEAR(belief.shortfalls()(0), 1.0, 0.01);
  ASSERT_EQ(belief.shortfallJumps(), 2u);
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2::Constant(2.0 - 0.9 * band), 50);
  EXPECT_EQ(belief.shortfallJumps(), 4u);
  EXPECT_NEAR(belief.shortfalls()(0), 1.0 + 0.9 * band, 0.2 * band);
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), belief.shortfallsAt(0.0));
  EXPECT_EQ(belief.unansweredJumps(), 0u);
}

TEST(RobotBelief, AJumpTheWheelAnswersIsMadeUp)
{
  // A stuck wheel that the first jump's compensation moves (0.05 -> 1 rad/s): the second jump is a
  // load's, made up in full.
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);
  drive(&belief, loop, base::Vector2(5.95, 5.95), base::Vector2(1.0, 1.0), 50);
  EXPECT_NEAR(belief.shortfalls()(0), 4.95, 0.01);
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), belief.shortfallsAt(0.0));
  EXPECT_EQ(belief.unansweredJumps(), 0u);
}

/// Ramp both sides' command at the wheels 0 -> 3 rad/s at 10 rad/s^2 for 0.4 s (1 ms predictions),
/// each 20 ms sample reading `wheel(u)` [rad/s] (u the command then) with +-1e-4 rad/s of
/// alternating noise; `each` is called after every prediction.
void rampAgainst(
    aic::RobotBelief* belief, const aic::WheelLoopModel& loop, const std::function<double(double)>& wheel,
    const std::function<void()>& each = [] {})
{
  double u = 0.0;
  for (int k = 0; k < 20 * 20; ++k)
  {
    u = std::min(3.0, u + 0.01);
    belief->predict(0.001, loop, base::Vector2(u, u), base::Vector2::Zero(), 0.0, 0.0);
    if (k % 20 == 19)
    {
      const double noise = (k / 20) % 2 == 0 ? 1e-4 : -1e-4;
      ASSERT_TRUE(belief->correct(base::Vector2::Constant(wheel(u) + noise), 0.0));
    }
    each();
  }
}

TEST(RobotBelief, AWheelThatDoesNotFollowItsCommandIsStalled)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // The command ramps, the wheels stay at 0.05 rad/s.
  rampAgainst(&belief, loop, [](double) { return 0.05; });
  EXPECT_TRUE(belief.stalled(0));
  EXPECT_TRUE(belief.stalled(1));
  EXPECT_FALSE(belief.stalled(2));  // no such side
  EXPECT_FALSE(belief.stalled(-1));
  EXPECT_EQ(belief.stalls(), 2u);
  // A held wheel's shortfall is not made up.
  EXPECT_EQ(belief.compensableShortfallsAt(0.0), base::Vector2::Zero());
  // The wheels stick and slip, moving between 0.05 and 1 rad/s under the 3 rad/s command: still
  // held, still stalled.
  for (int k = 0; k < 10; ++k)
  {
    drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2::Constant(k % 2 == 0 ? 1.0 : 0.05), 1);
    ASSERT_TRUE(belief.stalled(0)) << "sample " << k;
    ASSERT_TRUE(belief.stalled(1)) << "sample " << k;
  }
  EXPECT_EQ(belief.stalls(), 2u);
  // The wheels answer their command: no longer stalled.
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(3.0, 3.0), 2);
  EXPECT_FALSE(belief.stalled(0));
  EXPECT_FALSE(belief.stalled(1));
}

TEST(RobotBelief, AWheelThatFollowsItsCommandIsNotStalled)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // The same ramp, the wheels 0.1 rad/s behind it (moving 0.2 rad/s a sample) until it ends.
  rampAgainst(
      &belief, loop, [](double u) { return u < 3.0 ? u - 0.1 : u; }, [&] { ASSERT_FALSE(belief.stalled(0)); });
  EXPECT_EQ(belief.stalls(), 0u);
}

TEST(RobotBelief, ForgettingTheSlowStatesKeepsTheWheels)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  drive(&belief, loop, base::Vector2(3.0, 3.0), base::Vector2(0.05, 0.05), 50);  // a stall: d = 2.95 rad/s per side
  ASSERT_NEAR(belief.shortfalls()(0), 2.95, 0.01);
  belief.forgetSlowStates();
  EXPECT_EQ(belief.shortfalls()(0), 0.0);
  EXPECT_EQ(belief.shortfalls()(1), 0.0);
  EXPECT_EQ(belief.slipRatio(), 0.0);
  EXPECT_EQ(belief.gyroOffset(), 0.0);
  EXPECT_EQ(belief.variances()(1), 0.0);
  EXPECT_EQ(belief.variances()(6), 0.0);
  EXPECT_NEAR(belief.wheelSpeeds()(0), 0.05, 0.01);
}

TEST(RobotBelief, AShortfallJumpIsDroppedWhenTheTurnMovesOn)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // A turn (the goal's yaw rate 0.5 rad/s) in which the right wheel delivers 2 of its 3 rad/s.
  drive(&belief, loop, base::Vector2(-3.0, 3.0), base::Vector2(-3.0, 2.0), 50, 0.5);
  ASSERT_NEAR(belief.shortfalls()(1), 1.0, 0.01);
  // The turn ends: the load the jump measured was the turn's; d goes back to its drift.
  belief.predict(0.001, loop, base::Vector2(1.0, 1.0), base::Vector2::Zero(), 0.0, 0.0);
  EXPECT_NEAR(belief.shortfalls()(1), 0.0, 0.01);
}

TEST(RobotBelief, AFrozenEncoderIsNotTheWheel)
{
  // The left encoder repeats 2.0 rad/s bit for bit while the wheels' command ramps 2 -> 4 rad/s:
  // from the first repeat across the command's change its samples are skipped (the belief follows
  // the model), for as long as the reading repeats; the right side, noisy, is used throughout.
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  double u = 2.0;
  for (int k = 0; k < 20 * 50; ++k)
  {
    u = std::min(4.0, u + 0.004);  // 4 rad/s^2: 0.08 rad/s a sample
    belief.predict(0.001, loop, base::Vector2(u, u), base::Vector2::Zero(), 0.0, 0.0);
    if (k % 20 == 19)
    {
      const double noise = (k / 20) % 2 == 0 ? 1e-4 : -1e-4;
      ASSERT_TRUE(belief.correct(base::Vector2(2.0, u + noise), 0.0));
    }
  }
  EXPECT_EQ(belief.frozenEncoderSamples(), 49u);  // every sample but the first (no repeat yet)
  EXPECT_NEAR(belief.wheelSpeeds()(0), 4.0, 0.01);
  EXPECT_EQ(belief.shortfallJumps(), 0u);  // nor a stall
  // Unfrozen: a reading that moves again is used at once.
  belief.predict(0.001, loop, base::Vector2(4.0, 4.0), base::Vector2::Zero(), 0.0, 0.0);
  ASSERT_TRUE(belief.correct(base::Vector2(3.9, 4.0), 0.0));
  EXPECT_EQ(belief.frozenEncoderSamples(), 49u);
  EXPECT_LT(belief.wheelSpeeds()(0), 3.95);
  // A repeating reading under a steady command (an ideal sensor, a wheel held) is used.
  aic::RobotBelief steady(p);
  for (int k = 0; k < 20 * 20; ++k)
  {
    steady.predict(0.001, loop, base::Vector2(4.0, 4.0), base::Vector2::Zero(), 0.0, 0.0);
    if (k % 20 == 19)
    {
      ASSERT_TRUE(steady.correct(base::Vector2(3.0, 4.0), 0.0));
    }
  }
  EXPECT_EQ(steady.frozenEncoderSamples(), 0u);
  EXPECT_NEAR(steady.wheelSpeeds()(0), 3.0, 0.01);
}

TEST(RobotBelief, TurnSignsFadeToZeroTowardStraightDriving)
{
  // sigma_R = clamp(turn / kStraightTurn, -1, 1), sigma_L = -sigma_R.
  EXPECT_EQ(aic::RobotBelief::turnSigns(0.0), base::Vector2(-0.0, 0.0));
  EXPECT_EQ(aic::RobotBelief::turnSigns(0.5), base::Vector2(-1.0, 1.0));
  EXPECT_EQ(aic::RobotBelief::turnSigns(-2.0), base::Vector2(1.0, -1.0));
  const base::Vector2 half = aic::RobotBelief::turnSigns(0.5 * aic::RobotBelief::kStraightTurn);
  EXPECT_DOUBLE_EQ(half(1), 0.5);
  EXPECT_DOUBLE_EQ(half(0), -0.5);
  EXPECT_TRUE(aic::RobotBelief::turnSigns(std::nan("")).isZero(0.0));
}

namespace
{
/// Drive `belief` through a turn whose wheel commands ramp (no steady command, so no shortfall
/// jump): `seconds` of the sides' commands (-c, c), c rising by 0.5 rad/s per second from
/// `start` [rad/s] (sign of `turn`), the wheels delivering each side's command less `deficit`
/// [rad/s] against the turn (a P-only wheel servo under the turn's scrub load).
void rampTurn(aic::RobotBelief* belief, const aic::WheelLoopModel& loop, double turn, double start, double deficit,
              double seconds)
{
  const double sign = turn > 0.0 ? 1.0 : -1.0;
  const int steps = static_cast<int>(std::lround(seconds / 0.001));
  for (int k = 0; k < steps; ++k)
  {
    const double c = sign * (start + 0.5 * 0.001 * k);
    const base::Vector2 command(-c, c);
    belief->predict(0.001, loop, command, base::Vector2(-0.5 * sign, 0.5 * sign), 0.0, turn);
    if (k % 20 == 19)
    {
      ASSERT_TRUE(belief->correct(command - sign * base::Vector2(-deficit, deficit), 0.0));
    }
  }
}

/// model() with the turn shortfalls on (q_e 0.3 rad/s^0.5, what plant_identify.py --bag writes).
params::RobotModelParams turnModel()
{
  params::RobotModelParams p = model();
  p.turn_shortfall_noise = 0.3;
  return p;
}
}  // namespace

TEST(RobotBelief, TheTurnShortfallIsLearnedInOneTurnAndKeptForTheNext)
{
  // A wheel loop without load compensation: each side delivers 0.8 rad/s less than its command
  // against the turn (the right side less in a left turn, the left side more). With q_e > 0 the
  // turn shortfalls learn it in the left turn; the right turn's shortfalls are then predicted
  // before its first sample: d + sigma e flips with the turn's direction.
  aic::RobotBelief belief(turnModel());
  aic::WheelLoopModel loop(turnModel());
  rampTurn(&belief, loop, 0.5, 2.0, 0.8, 3.0);
  EXPECT_EQ(belief.shortfallJumps(), 0u);
  EXPECT_NEAR(belief.shortfallsAt(0.5)(1), 0.8, 0.05);   // right, held back
  EXPECT_NEAR(belief.shortfallsAt(0.5)(0), -0.8, 0.05);  // left, pushed on
  EXPECT_NEAR(belief.turnShortfalls()(0), 0.8, 0.05);
  EXPECT_NEAR(belief.turnShortfalls()(1), 0.8, 0.05);
  EXPECT_NEAR(belief.shortfallsAt(-0.5)(0), 0.8, 0.05);  // the right turn, before it starts
  EXPECT_NEAR(belief.shortfallsAt(-0.5)(1), -0.8, 0.05);
  EXPECT_NEAR(belief.shortfallsAt(0.0)(0), belief.shortfalls()(0), 1e-12);  // straight: d alone
  // The right turn is delivered as the model predicts: the turn shortfalls stay.
  rampTurn(&belief, loop, -0.5, 2.0, 0.8, 1.0);
  EXPECT_NEAR(belief.turnShortfalls()(0), 0.8, 0.05);
  EXPECT_NEAR(belief.turnShortfalls()(1), 0.8, 0.05);
  EXPECT_GT(belief.turnShortfallVariances()(0), 0.0);
}

TEST(RobotBelief, WithoutTheTurnShortfallsDriftTheyStayZero)
{
  // q_e = 0 (the schema's default): the same turns leave e at zero and the shortfalls d alone.
  aic::RobotBelief belief(model());
  aic::WheelLoopModel loop(model());
  rampTurn(&belief, loop, 0.5, 2.0, 0.8, 3.0);
  EXPECT_EQ(belief.turnShortfalls(), base::Vector2::Zero());
  EXPECT_EQ(belief.turnShortfallVariances(), base::Vector2::Zero());
  EXPECT_EQ(belief.shortfallsAt(0.5), belief.shortfalls());
}

TEST(RobotBelief, ForgettingTheSlowStatesForgetsTheTurnShortfalls)
{
  aic::RobotBelief belief(turnModel());
  aic::WheelLoopModel loop(turnModel());
  rampTurn(&belief, loop, 0.5, 2.0, 0.8, 3.0);
  ASSERT_GT(belief.turnShortfalls()(1), 0.5);
  belief.forgetSlowStates();
  EXPECT_EQ(belief.turnShortfalls(), base::Vector2::Zero());
  EXPECT_EQ(belief.turnShortfallVariances(), base::Vector2::Zero());
}

namespace
{
/// Step `belief` from rest to the command `u` [rad/s] on both sides at the wheels for 1 s (belief
/// steps of 1 ms, a sample every 20 ms) while both wheels read wheel_at(k) [rad/s] at step k.
void stepAgainstWheels(aic::RobotBelief* belief, const aic::WheelLoopModel& loop, double u,
                       const std::function<double(int)>& wheel_at)
{
  for (int k = 0; k < 1000; ++k)
  {
    belief->predict(0.001, loop, base::Vector2(u, u), base::Vector2::Zero(), 0.0, 0.0);
    if (k % 20 == 19)
    {
      const double wheel = wheel_at(k);
      ASSERT_TRUE(belief->correct(base::Vector2(wheel, wheel), 0.0));
    }
  }
}
}  // namespace

TEST(RobotBelief, AWheelStillRampingIsNoShortfallJump)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // A 3 rad/s step that the wheels follow at 10 rad/s^2 (a heavy robot, slower than A_w): the
  // residuals exceed the threshold after the model has settled but change by 0.2 rad/s a sample,
  // so the wheel is still moving: no jump; d stays near zero.
  stepAgainstWheels(&belief, loop, 3.0, [](int k) { return std::min(3.0, 10.0 * 0.001 * (k + 1)); });
  EXPECT_EQ(belief.shortfallJumps(), 0u);
  EXPECT_NEAR(belief.shortfalls()(0), 0.0, 0.05);
}

TEST(RobotBelief, TheSlipRatioIsNotMadeUncertainWhileItCannotLearn)
{
  // The goal's turn moves on while the slip ratio cannot learn (a channel isolated, a fault): its
  // variance P_s stays where it was, so a channel's re-admission is not judged against a slip
  // uncertainty that no sample could have reduced. With slip_observed it grows with |dw|.
  aic::RobotBelief held(model());
  aic::RobotBelief observed(model());
  aic::WheelLoopModel loop(model());
  for (int k = 0; k < 1000; ++k)
  {
    const double turn = 0.5 * std::sin(0.01 * k);
    held.predict(0.001, loop, base::Vector2(2.0, 3.0), base::Vector2::Zero(), 0.2, turn, false);
    observed.predict(0.001, loop, base::Vector2(2.0, 3.0), base::Vector2::Zero(), 0.2, turn, true);
  }
  EXPECT_EQ(held.variances()(5), 0.0);
  EXPECT_GT(observed.variances()(5), 1e-6);
}

TEST(RobotBelief, AChannelIsReleasedOnTheSensorsVarianceNotTheSlipRatios)
{
  // In a turn the parity's variance holds the slip ratio's share u^2 P_s; the release variance
  // leaves it out (at least the sensors' own), so an isolated channel's agreement within an
  // uncertain slip ratio does not restore it. Straight, u = 0: the two are the same.
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  for (int k = 0; k < 2000; ++k)
  {
    belief.predict(0.001, loop, base::Vector2(2.0, 4.0), base::Vector2::Zero(), 0.2, 0.5 * std::sin(0.01 * k));
  }
  const double u = belief.wheelsYawRate();
  const double p_s = belief.variances()(5);
  ASSERT_GT(u * u * p_s, 1e-4);
  const base::SampleInnovation in = belief.sampleInnovation(belief.wheelSpeeds(), belief.yawRate());
  const double k = (1.0 - belief.slipRatio()) * 0.2;
  const double sensors = p.gyro_noise * p.gyro_noise + 2.0 * k * k * p.encoder_noise * p.encoder_noise;
  EXPECT_NEAR(in.release_variance, std::max(in.parity_variance - u * u * p_s, sensors), 1e-12);
  EXPECT_LT(in.release_variance, in.parity_variance - 0.5 * u * u * p_s);
  aic::RobotBelief straight(p);
  for (int k = 0; k < 500; ++k)
  {
    straight.predict(0.001, loop, base::Vector2(3.0, 3.0), base::Vector2::Zero(), 0.2, 0.0);
  }
  const base::SampleInnovation s = straight.sampleInnovation(straight.wheelSpeeds(), straight.yawRate());
  EXPECT_DOUBLE_EQ(s.release_variance, s.parity_variance);
}

TEST(RobotBelief, AWheelThatStartsLateIsNoShortfallJump)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // A 5 rad/s step at the wheels that the wheels start 0.1 s late (a latency longer than the
  // model's) and then follow at A_w: for five samples they read their old speed, steady, far
  // below u - d. That is the loop not yet settled (RobotBelief::settleTime(): 5 / A_w plus its
  // lags), not a stall: no jump, d stays near zero.
  const double a_w = p.wheel_acceleration;
  stepAgainstWheels(&belief, loop, 5.0, [a_w](int k) { return std::clamp(a_w * 0.001 * (k - 99), 0.0, 5.0); });
  EXPECT_EQ(belief.shortfallJumps(), 0u);
  EXPECT_NEAR(belief.shortfalls()(0), 0.0, 0.05);
  EXPECT_NEAR(belief.wheelSpeeds()(0), 5.0, 0.05);
}

namespace
{
/// Drive `belief` for `seconds` with both sides' command and measurement held (left, right
/// [rad/s]), the goal's turn their yaw rate through yaw gain 0.2 m/m, and the gyro reading `gyro`
/// [rad/s]; a sample every 20 ms. The first 0.3 s are the change's transient: the slow states are
/// held then, as the controller's learning gate holds them.
void hold(aic::RobotBelief* belief, const aic::WheelLoopModel& loop, const base::Vector2& wheels, double gyro,
          double seconds)
{
  const int steps = static_cast<int>(std::lround(seconds / 0.001));
  for (int k = 0; k < steps; ++k)
  {
    belief->predict(0.001, loop, wheels, base::Vector2::Zero(), 0.2, 0.2 * (wheels(1) - wheels(0)));
    if (k % 20 == 19)
    {
      aic::RobotBelief::SampleUse use;
      use.learn = k >= 300;
      ASSERT_TRUE(belief->correct(wheels, gyro, use));
    }
  }
}

/// `belief` after 1 s at rest and 5 s of a steady turn (wheels (-1.25, 1.25) rad/s, gyro 0.45 rad/s,
/// hold()'s yaw gain 0.2): it has learned the slip ratio s = 0.1.
void learnASteadyTurn(aic::RobotBelief* belief, const aic::WheelLoopModel& loop)
{
  hold(belief, loop, base::Vector2::Zero(), 0.0, 1.0);
  hold(belief, loop, base::Vector2(-1.25, 1.25), 0.45, 5.0);
}
}  // namespace

TEST(RobotBelief, TheSlipRatioIsLearnedInATurnAndTheOffsetWhenStraight)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  // At rest the gyro reads 0.02 rad/s: its offset.
  hold(&belief, loop, base::Vector2::Zero(), 0.02, 3.0);
  EXPECT_NEAR(belief.gyroOffset(), 0.02, 0.002);
  // A turn whose wheels say 0.5 rad/s (yaw gain 0.2 x 2.5 rad/s of difference) while the body
  // turns at 0.45: the slip ratio is 0.1, the offset stays.
  hold(&belief, loop, base::Vector2(-1.25, 1.25), 0.47, 3.0);
  EXPECT_NEAR(belief.slipRatio(), 0.1, 0.01);
  EXPECT_NEAR(belief.gyroOffset(), 0.02, 0.003);
  EXPECT_NEAR(belief.yawRate(), 0.45, 0.003);
}

TEST(RobotBelief, AGyroOffsetJumpInASteadyTurnIsTheOffset)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  learnASteadyTurn(&belief, loop);  // learned: s = 0.1
  const double s = belief.slipRatio();
  EXPECT_NEAR(s, 0.1, 0.01);
  // The gyro jumps by 0.1 rad/s with the wheels unchanged: the body's yaw rate is unchanged.
  const std::uint64_t jumps = belief.offsetJumps();
  hold(&belief, loop, base::Vector2(-1.25, 1.25), 0.55, 2.0);
  EXPECT_EQ(belief.offsetJumps(), jumps + 1);
  EXPECT_NEAR(belief.gyroOffset(), 0.1, 0.01);
  EXPECT_NEAR(belief.slipRatio(), s, 0.01);
  EXPECT_NEAR(belief.yawRate(), 0.45, 0.005);
}

TEST(RobotBelief, TheSampleInnovationIsThePredictionErrorAndItsParityCancelsACommonChange)
{
  const params::RobotModelParams p = model();
  aic::RobotBelief belief(p);
  aic::WheelLoopModel loop(p);
  learnASteadyTurn(&belief, loop);  // learned: s = 0.1
  const double s = belief.slipRatio();
  const double k = (1.0 - s) * 0.2;  // the wheels' yaw per unit speed difference, with hold()'s yaw gain
  // The sample the model predicts: every error near zero.
  const base::Vector2 w = belief.wheelSpeeds();
  const double g = belief.yawRate() + belief.gyroOffset();
  base::SampleInnovation in = belief.sampleInnovation(w, g);
  EXPECT_NEAR(in.error.cwiseAbs().maxCoeff(), 0.0, 1e-12);
  EXPECT_NEAR(in.parity, 0.0, 1e-12);
  // Variances: the model's uncertainty plus the sensors' noise; the parity's the sum.
  const Eigen::Matrix<double, 7, 1> v = belief.variances();
  EXPECT_NEAR(in.variance(base::kOmegaLeft), v(0) + p.encoder_noise * p.encoder_noise, 1e-15);
  EXPECT_NEAR(in.variance(base::kOmegaRight), v(2) + p.encoder_noise * p.encoder_noise, 1e-15);
  EXPECT_GT(in.variance(base::kGyroZ), p.gyro_noise * p.gyro_noise);
  EXPECT_NEAR(in.parity_variance,
              in.variance(base::kGyroZ) + k * k * (in.variance(base::kOmegaLeft) + in.variance(base::kOmegaRight)),
              1e-15);
  // The body turns faster and the wheels show it: every channel errs, the parity does not.
  in = belief.sampleInnovation(w + base::Vector2(-0.5, 0.5), g + k * 1.0);
  EXPECT_NEAR(in.error(base::kOmegaLeft), -0.5, 1e-12);
  EXPECT_NEAR(in.error(base::kOmegaRight), 0.5, 1e-12);
  EXPECT_NEAR(in.error(base::kGyroZ), k, 1e-12);
  EXPECT_NEAR(in.parity, 0.0, 1e-12);
  // One wheel reads 0.5 rad/s high alone: the parity is the yaw it implies; the gyro alone: its error.
  EXPECT_NEAR(belief.sampleInnovation(w + base::Vector2(0.5, 0.0), g).parity, k * 0.5, 1e-12);
  EXPECT_NEAR(belief.sampleInnovation(w, g + 0.1).parity, 0.1, 1e-12);
}

TEST(RobotBelief, RescalingTheSlipRatioKeepsTheModelsYawRate)
{
  aic::RobotBelief belief(model());
  aic::WheelLoopModel loop(model());
  hold(&belief, loop, base::Vector2::Zero(), 0.0, 1.0);
  hold(&belief, loop, base::Vector2(-1.25, 1.25), 0.4, 3.0);  // s = 0.2
  const double s = belief.slipRatio();
  ASSERT_TRUE(belief.rescaleSlip(0.8));  // b_hat x 0.8: the wheels' yaw gain x 1.25
  EXPECT_NEAR(1.0 - belief.slipRatio(), 0.8 * (1.0 - s), 1e-12);
  EXPECT_FALSE(belief.rescaleSlip(0.0));
  EXPECT_FALSE(belief.rescaleSlip(std::nan("")));
}

TEST(RobotBelief, RejectsANonFiniteSampleAndSkipsAnIsolatedChannel)
{
  aic::RobotBelief belief(model());
  EXPECT_FALSE(belief.correct(base::Vector2(std::nan(""), 0.0), 0.0));
  aic::RobotBelief::SampleUse left_isolated;
  left_isolated.left = false;
  EXPECT_TRUE(belief.correct(base::Vector2(std::nan(""), 1.0), 0.0, left_isolated));
  EXPECT_TRUE(belief.wheelSpeeds().allFinite());
  EXPECT_EQ(belief.wheelSpeeds()(0), 0.0);
  EXPECT_GT(belief.wheelSpeeds()(1), 0.9);
}

TEST(LatencyAction, TheMinimiserIsTheModelsInverseThroughTheLatency)
{
  aic::WheelLoopModel loop(model());
  loop.record(0.0, base::Vector2(1.0, 1.0));
  // Everything in flight is 1 rad/s; the goal 1.2 rad/s one latency and one step ahead.
  const aic::LatencyActionResult r =
      aic::LatencyAction::step(loop, base::Vector2(1.0, 1.0), base::Vector2::Zero(), 0.5, base::Vector2(1.2, 0.8),
                               base::Vector2(1.0, 1.0), 0.02, 50.0, 20.0, 1.0);
  EXPECT_NEAR(r.predicted(0), 1.2, 1e-5);
  EXPECT_NEAR(r.predicted(1), 0.8, 1e-5);
  // The lag asks for a little more than the goal (the exact inverse: 0.2 / (1 - exp(-2))).
  EXPECT_NEAR(r.command(0), 1.0 + 0.2 / (1.0 - std::exp(-2.0)), 1e-4);
  EXPECT_NEAR(r.free_energy, 0.0, 1e-8);
}

TEST(LatencyAction, AGoalBeyondTheRateBoundAsksNoMoreThanTheLoopGives)
{
  aic::WheelLoopModel loop(model());
  const aic::LatencyActionResult r =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), base::Vector2::Zero(), 0.5, base::Vector2(10.0, -10.0),
                               base::Vector2::Zero(), 0.02, 50.0, 20.0, 1.0);
  // 40 rad/s^2 for 0.02 s: 0.8 rad/s at most, reached by a command below 2 rad/s, not the bound 20.
  EXPECT_NEAR(r.predicted(0), 0.8, 1e-6);
  EXPECT_LT(r.command(0), 2.0);
  EXPECT_GT(r.command(1), -2.0);
  EXPECT_GT(r.free_energy, 0.0);
}

TEST(LatencyAction, AStalledSideKeepsItsCommandWithinItsReach)
{
  aic::WheelLoopModel loop(model());
  // A goal (3 rad/s) far beyond what a wheel at rest reaches in one step, the shortfall 0.2 rad/s,
  // the previous command 5 rad/s. Unbounded, the command drops to what gives the loop's most (about
  // 0.93 rad/s); the left side's reach of 0.5 rad/s holds it within 0.5 of g + d = 3.2 rad/s.
  const base::Vector2 d(0.2, 0.2);
  const base::Vector2 goal(3.0, 3.0);
  const base::Vector2 previous(5.0, 5.0);
  const aic::LatencyActionResult free =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), d, 0.5, goal, previous, 0.02, 50.0, 20.0, 1.0);
  const aic::LatencyActionResult held =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), d, 0.5, goal, previous, 0.02, 50.0, 20.0, 1.0,
                               base::Vector2(0.5, std::numeric_limits<double>::infinity()));
  ASSERT_LT(free.command(0), 2.7);
  EXPECT_NEAR(held.command(0), 2.7, 1e-12);
  EXPECT_EQ(held.command(1), free.command(1));
  // Near the command's bound the reach stays within it.
  const aic::LatencyActionResult top =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), d, 0.5, base::Vector2(19.9, -19.9),
                               base::Vector2(20.0, -20.0), 0.02, 50.0, 20.0, 1.0, base::Vector2(0.5, 0.5));
  EXPECT_LE(top.command(0), 20.0);
  EXPECT_GE(top.command(0), 19.6 - 1e-9);
  EXPECT_GE(top.command(1), -20.0);
  // A negative reach is none beyond the steady command; NaN is no bound.
  const aic::LatencyActionResult odd =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), d, 0.5, goal, previous, 0.02, 50.0, 20.0, 1.0,
                               base::Vector2(-1.0, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_NEAR(odd.command(0), 3.2, 1e-12);
  EXPECT_EQ(odd.command(1), free.command(1));
}

TEST(LatencyAction, TheLoopGainScalesTheStep)
{
  aic::WheelLoopModel loop(model());
  const aic::LatencyActionResult full =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), base::Vector2::Zero(), 0.5, base::Vector2(0.3, 0.3),
                               base::Vector2::Zero(), 0.02, 50.0, 20.0, 1.0);
  const aic::LatencyActionResult half =
      aic::LatencyAction::step(loop, base::Vector2::Zero(), base::Vector2::Zero(), 0.5, base::Vector2(0.3, 0.3),
                               base::Vector2::Zero(), 0.02, 25.0, 20.0, 1.0);
  EXPECT_NEAR(half.command(0), 0.5 * full.command(0), 1e-9);
  EXPECT_NEAR(full.minimiser(0), half.minimiser(0), 1e-12);
}

TEST(ControllerRobotModel, BeliefsAreTheMeasuredTwistAndTheActionTheGoalsWheels)
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  p.separation_learner.enabled = false;
  aic::ActiveInferenceController c(p);
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.0)));
  // The robot drives at 0.5 m/s on both wheels; after a few seconds the belief is the measured
  // twist and the command holds the goal's wheel speeds.
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  const double omega = 0.5 / (p.wheel_radius * p.slip_factor);
  y(base::kOmegaLeft, 0) = omega;
  y(base::kOmegaRight, 0) = omega;
  runController(&c, y, 3000);
  EXPECT_NEAR(c.mu()(0, 0), 0.5, 1e-3);
  EXPECT_NEAR(c.mu()(2, 0), 0.0, 1e-3);
  EXPECT_NEAR(c.action()(0), omega, 0.05);
  EXPECT_NEAR(c.action()(1), omega, 0.05);
  EXPECT_TRUE(std::isfinite(c.freeEnergy()));
  EXPECT_NEAR(c.freeEnergy(), c.sensoryFreeEnergy() + c.priorFreeEnergy(), 1e-12);
  // A zero goal stops the wheels at once.
  ASSERT_TRUE(c.setGoal(base::Vector3::Zero()));
  for (int k = 0; k < 200; ++k)
  {
    ASSERT_EQ(c.updateBeliefs(0.001), Status::kOk);
  }
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  EXPECT_TRUE(c.action().isZero());
}

TEST(ControllerRobotModel, TheCommandMakesUpAShortfall)
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  p.separation_learner.enabled = false;
  aic::ActiveInferenceController c(p);
  // Each wheel delivers 0.6 rad/s less than it is sent: once d has learned it (a jump, then the
  // drift), the command is the goal's wheel speed plus d, and the wheels reach the goal's.
  const double omega = 0.5 / (p.wheel_radius * p.slip_factor);
  jackal_test::driveAgainstWheelLoop(&c, p.robot, base::Vector3(0.5, 0.0, 0.0), 3.0, base::Vector2(0.6, 0.6));
  EXPECT_NEAR(c.robotBelief().shortfalls()(0), 0.6, 0.05);
  EXPECT_NEAR(c.action()(0), omega + 0.6, 0.05);
  EXPECT_NEAR(c.action()(1), omega + 0.6, 0.05);
  EXPECT_NEAR(c.mu()(0, 0), 0.5, 0.005);
}

TEST(LatencyAction, TheShortfallMadeUpIsBoundedByTheCompensationLimit)
{
  const base::Vector2 d(0.6, -0.05);
  EXPECT_EQ(aic::LatencyAction::compensated(d, 0.0), d);  // 0: no bound
  EXPECT_EQ(aic::LatencyAction::compensated(d, 0.2), base::Vector2(0.2, -0.05));
  EXPECT_EQ(aic::LatencyAction::compensated(base::Vector2(-0.6, 0.3), 0.2), base::Vector2(-0.2, 0.2));
  const base::Vector2 nan(std::nan(""), 0.6);
  const base::Vector2 out = aic::LatencyAction::compensated(nan, 0.2);
  EXPECT_TRUE(std::isnan(out(0)));  // left to the caller's runaway check
  EXPECT_EQ(out(1), 0.2);
}

TEST(LatencyAction, InAnArcTheTurnsShortfallIsMadeUpInFullAndTheSpeedsOnlyAsFarAsTheWheelsAreShort)
{
  // An arc at 1.6 / 0.46 rad/s (0.1 m/s, -0.2 rad/s): the outer (left) wheel 0.4 short, the wheels
  // rolling at the goal's mean speed. The turn's part (0.2 each way) is made up, the speed's not.
  const base::Vector2 goal(1.6, 0.46);
  const base::Vector2 d(0.4, 0.0);
  const base::Vector2 at_speed = aic::LatencyAction::inArc(d, goal, base::Vector2(1.03, 1.03));
  EXPECT_NEAR(at_speed(0), 0.2, 1e-12);
  EXPECT_NEAR(at_speed(1), -0.2, 1e-12);
  EXPECT_NEAR(at_speed(0) - at_speed(1), d(0) - d(1), 1e-12);  // the turn's part in full
  // The wheels 0.1 rad/s short of the goal's mean speed: that much of the speed's part too.
  const base::Vector2 slow = aic::LatencyAction::inArc(d, goal, base::Vector2(0.93, 0.93));
  EXPECT_NEAR(slow(0), 0.3, 1e-12);
  EXPECT_NEAR(slow(1), -0.1, 1e-12);
  // Far short (a payload): the whole shortfall, as without the rule.
  EXPECT_NEAR((aic::LatencyAction::inArc(d, goal, base::Vector2(0.5, 0.5)) - d).norm(), 0.0, 1e-12);
  // Backward, mirrored.
  const base::Vector2 back = aic::LatencyAction::inArc(-d, -goal, base::Vector2(-1.03, -1.03));
  EXPECT_NEAR(back(0), -0.2, 1e-12);
  EXPECT_NEAR(back(1), 0.2, 1e-12);
  // A turn in place, a stop: unchanged.
  EXPECT_EQ(aic::LatencyAction::inArc(d, base::Vector2(-1.0, 1.0), base::Vector2::Zero()), d);
  EXPECT_EQ(aic::LatencyAction::inArc(d, base::Vector2(0.0, 1.0), base::Vector2::Zero()), d);
  // A non-finite wheel speed is left to the caller's runaway check.
  EXPECT_FALSE(aic::LatencyAction::inArc(d, goal, base::Vector2(std::nan(""), 1.0)).allFinite());
}

TEST(ControllerRobotModel, TheCommandMakesUpAShortfallOnlyToTheCompensationLimit)
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  p.separation_learner.enabled = false;
  p.robot.shortfall_compensation_limit = 0.2;
  aic::ActiveInferenceController c(p);
  // As above, each wheel 0.6 rad/s short; with e_c = 0.2 rad/s (a wheel loop whose proportional
  // path saturates there) the command makes up 0.2 of it, and the belief keeps the whole 0.6.
  const double omega = 0.5 / (p.wheel_radius * p.slip_factor);
  jackal_test::driveAgainstWheelLoop(&c, p.robot, base::Vector3(0.5, 0.0, 0.0), 3.0, base::Vector2(0.6, 0.6));
  EXPECT_NEAR(c.robotBelief().shortfalls()(0), 0.6, 0.05);
  EXPECT_NEAR(c.robotBelief().shortfalls()(1), 0.6, 0.05);
  EXPECT_NEAR(c.action()(0), omega + 0.2, 0.05);
  EXPECT_NEAR(c.action()(1), omega + 0.2, 0.05);
  EXPECT_NEAR(c.mu()(0, 0), (omega - 0.4) * p.wheel_radius * p.slip_factor, 0.005);
}

TEST(ControllerRobotModel, AStepLongerThanTheLongestIsRefusedNotSimulated)
{
  // The robot model predicts a step in 1 ms substeps: a step of 1e300 s would never end. Every
  // step beyond params::kMaxStep is refused and the state kept; the longest one is taken.
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  aic::ActiveInferenceController c(p);
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.3)));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, p.numOrders())));
  ASSERT_EQ(c.updateBeliefs(0.001), Status::kOk);
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  const base::MuTilde mu = c.mu();
  const base::Vector2 a = c.action();
  for (double too_long : { std::nextafter(params::kMaxStep, 2.0), 1.0e3, 1.0e300, 1.7976931348623157e308 })
  {
    // ASSERT: a step taken instead of refused would not end at the next one.
    ASSERT_EQ(c.updateBeliefs(too_long), Status::kBadInterval) << too_long;
    ASSERT_EQ(c.updateAction(too_long), Status::kBadInterval) << too_long;
    EXPECT_EQ(c.mu(), mu);
    EXPECT_EQ(c.action(), a);
  }
  EXPECT_EQ(c.updateBeliefs(params::kMaxStep), Status::kOk);
  EXPECT_EQ(c.updateAction(params::kMaxStep), Status::kOk);
  EXPECT_TRUE(c.action().allFinite());
  EXPECT_LE(c.action().cwiseAbs().maxCoeff(), p.max_wheel_speed);
}

TEST(ControllerRobotModel, ResetLearningForgetsTheSlowStates)
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  aic::ActiveInferenceController c(p);
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.0)));
  // The wheels deliver 80 % of the goal's speed whatever they are asked: a shortfall is learned.
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  const double omega = 0.8 * 0.5 / (p.wheel_radius * p.slip_factor);
  y(base::kOmegaLeft, 0) = omega;
  y(base::kOmegaRight, 0) = omega;
  runController(&c, y, 3000, 1e-4);
  ASSERT_GT(c.robotBelief().shortfalls()(0), 0.1);
  c.resetLearning();
  EXPECT_EQ(c.robotBelief().shortfalls()(0), 0.0);
  EXPECT_EQ(c.robotBelief().shortfalls()(1), 0.0);
  EXPECT_EQ(c.robotBelief().slipRatio(), 0.0);
  EXPECT_EQ(c.robotBelief().gyroOffset(), 0.0);
  EXPECT_NEAR(c.robotBelief().wheelSpeeds()(0), omega, 0.05);
}

TEST(ControllerRobotModel, WhileAFaultIsTestedTheBeliefsFollowTheModel)
{
  // The wheels read 0.5 m/s while nothing was commanded (the goal is zero): normally the beliefs
  // take the reading; while a fault is suspected and not yet confirmed they follow the model
  // (wheels at rest), so the fault monitor's test compares with the model's prediction.
  params::AicParams p = robotParams();
  p.separation_learner.enabled = false;
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  const double omega = 0.5 / (p.wheel_radius * p.slip_factor);
  y(base::kOmegaLeft, 0) = omega;
  y(base::kOmegaRight, 0) = omega;
  aic::ActiveInferenceController held(p);
  held.setFaultState(true, true);
  runController(&held, y, 200);
  EXPECT_NEAR(held.robotBelief().wheelSpeeds()(0), 0.0, 1e-9);
  // Released, the readings pull the belief toward them (the model, commanding nothing, pulls back).
  held.setFaultState(false, false);
  runController(&held, y, 200);
  EXPECT_GT(held.robotBelief().wheelSpeeds()(0), 0.5 * omega);
}

TEST(ControllerRobotModel, ARepeatedJointStateGivesNoWheelReading)
{
  // The wheels read 0.5 m/s while nothing was commanded. Flagged as repeats of the previous joint
  // state (the MCU's last reading re-published), the readings are not taken: the beliefs follow the
  // model (wheels at rest), while the gyro's reading is still taken.
  params::AicParams p = robotParams();
  p.separation_learner.enabled = false;
  p.robot.learn_latency = false;
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  const double omega = 0.5 / (p.wheel_radius * p.slip_factor);
  y(base::kOmegaLeft, 0) = omega;
  y(base::kOmegaRight, 0) = omega;
  y(base::kGyroZ, 0) = 0.2;
  aic::ActiveInferenceController repeated(p), fresh(p);
  for (int k = 0; k < 200; ++k)
  {
    if (k % 20 == 0)
    {
      ASSERT_TRUE(repeated.setMeasurement(y, true));
      ASSERT_TRUE(fresh.setMeasurement(y, false));
    }
    ASSERT_EQ(repeated.updateBeliefs(0.001), Status::kOk);
    ASSERT_EQ(fresh.updateBeliefs(0.001), Status::kOk);
  }
  EXPECT_NEAR(repeated.robotBelief().wheelSpeeds()(0), 0.0, 1e-9);
  // The gyro's reading is new: it is taken (at rest the offset beta takes most of it).
  EXPECT_GT(repeated.robotBelief().yawRate() + repeated.robotBelief().gyroOffset(), 0.1);
  EXPECT_GT(fresh.robotBelief().wheelSpeeds()(0), 0.5 * omega) << "a new reading is taken";
}

TEST(ControllerRobotModel, AFaultPresentHoldsTheGyroOffset)
{
  // The gyro reads 0.03 rad/s at rest: the offset beta learns it, unless a fault is present.
  params::AicParams p = robotParams();
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  y(base::kGyroZ, 0) = 0.03;
  aic::ActiveInferenceController learning(p);
  runController(&learning, y, 5000);
  EXPECT_NEAR(learning.robotBelief().gyroOffset(), 0.03, 0.005);
  aic::ActiveInferenceController held(p);
  held.setFaultState(false, true);
  runController(&held, y, 5000);
  EXPECT_EQ(held.robotBelief().gyroOffset(), 0.0);
}

TEST(ControllerRobotModel, AChangeOfTheOffsetRemovedBeforeIsTakenBackByBeta)
{
  // beta is what remains of the gyro's offset after the one removed before the controller: when
  // that removal grows by 0.02 rad/s, beta drops by as much, and the model's reading of the same
  // gyro, theta_dot + beta, is unchanged. Other belief models: no effect.
  params::AicParams p = robotParams();
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  y(base::kGyroZ, 0) = 0.03;
  aic::ActiveInferenceController c(p);
  runController(&c, y, 5000);
  const double beta = c.robotBelief().gyroOffset();
  c.gyroOffsetRemoved(0.02);
  EXPECT_NEAR(c.robotBelief().gyroOffset(), beta - 0.02, 1e-12);
  c.gyroOffsetRemoved(std::nan(""));
  EXPECT_NEAR(c.robotBelief().gyroOffset(), beta - 0.02, 1e-12);
  params::AicParams goal_model = p;
  goal_model.belief_model = params::BeliefModel::kGoal;
  aic::ActiveInferenceController g(goal_model);
  g.gyroOffsetRemoved(0.02);
  EXPECT_EQ(g.robotBelief().gyroOffset(), 0.0);
}

namespace
{
/// A start from rest: the wheels' commands ramp by 0.9 rad/s every 20 ms from t = 0.02 s to 4.5 rad/s,
/// sent to `plant` (the truth, its own latency) and `believed` (the controller's record); the
/// noise-free wheel samples every 20 ms go to `learner` until it completes the start or 0.4 s pass.
/// \return the number of samples that completed a start (0 or 1)
int rampFromRest(aic::LatencyLearner* learner, aic::WheelLoopModel* plant, aic::WheelLoopModel* believed,
                 bool wheels_at_rest = true)
{
  base::Vector2 previous = base::Vector2::Zero();
  int completed = 0;
  for (int k = 1; k <= 20; ++k)
  {
    const double t = 0.02 * k;
    const base::Vector2 y = plant->predict(base::Vector2::Zero(), base::Vector2::Zero(), 0.0, t);
    completed += learner->sample(t, y, *believed) ? 1 : 0;
    const base::Vector2 u = base::Vector2::Constant(std::min(0.9 * k, 4.5));
    plant->record(t, u);
    believed->record(t, u);
    learner->commandSent(t, u, previous, wheels_at_rest);
    previous = u;
  }
  return completed;
}

params::RobotModelParams mcu(double latency)
{
  params::RobotModelParams p;
  p.latency = latency;
  p.wheel_feedforward = 0.787;
  p.wheel_feedforward_acceleration = 34.76;
  p.wheel_time_constant = 0.01365;
  return p;
}
}  // namespace

TEST(LatencyLearner, TheWheelsFirstMotionAfterRestGivesTheLatency)
{
  // The model believes L = 0.1187 s; plants 20 % slower and faster: one start gives their latency
  // to the wheel loop model's 1 ms substep (noise-free samples: the prediction's time grid is what
  // limits it).
  for (const double truth : { 0.1424, 0.0950, 0.1187 })
  {
    SCOPED_TRACE(truth);
    aic::WheelLoopModel plant(mcu(truth));
    aic::WheelLoopModel believed(mcu(0.1187));
    aic::LatencyLearner learner(0.1187, 0.5 * 0.1187, 2.0 * 0.1187, 0.0071);
    EXPECT_EQ(rampFromRest(&learner, &plant, &believed), 1);
    EXPECT_EQ(learner.starts(), 1);
    EXPECT_NEAR(learner.latency(), truth, 1.5e-3);
  }
}

TEST(LatencyLearner, OnlyACommandLeavingZeroWithTheWheelsAtRestIsAStart)
{
  aic::WheelLoopModel plant(mcu(0.1424));
  aic::WheelLoopModel believed(mcu(0.1187));
  aic::LatencyLearner learner(0.1187, 0.5 * 0.1187, 2.0 * 0.1187, 0.0071);
  EXPECT_EQ(rampFromRest(&learner, &plant, &believed, false), 0);
  EXPECT_EQ(learner.latency(), 0.1187);
  // A command that changes while moving is no start.
  learner.commandSent(1.0, base::Vector2(2.0, 2.0), base::Vector2(1.0, 1.0), true);
  EXPECT_FALSE(learner.sample(1.2, base::Vector2(1.5, 1.5), believed));
  EXPECT_EQ(learner.starts(), 0);
}

TEST(LatencyLearner, AStartWithoutMotionIsDroppedAndTheEstimateIsBoundedAndAveraged)
{
  // Armed, but the wheels have not moved by max + kWindow: dropped, a later reading is no start.
  aic::WheelLoopModel believed(mcu(0.1));
  aic::LatencyLearner learner(0.1, 0.05, 0.2, 0.0071);
  believed.record(0.0, base::Vector2(1.0, 1.0));
  learner.commandSent(0.0, base::Vector2(1.0, 1.0), base::Vector2::Zero(), true);
  EXPECT_FALSE(learner.sample(0.2 + aic::LatencyLearner::kWindow + 0.01, base::Vector2::Zero(), believed));
  EXPECT_FALSE(learner.sample(0.35, base::Vector2(1.0, 1.0), believed));
  EXPECT_EQ(learner.starts(), 0);
  // A non-finite sample or time is no reading: the armed start waits for a finite one.
  learner.commandSent(1.0, base::Vector2(1.0, 1.0), base::Vector2::Zero(), true);
  EXPECT_FALSE(learner.sample(1.15, base::Vector2(1.0, std::nan("")), believed));
  EXPECT_FALSE(learner.sample(std::nan(""), base::Vector2(1.0, 1.0), believed));
  EXPECT_EQ(learner.starts(), 0);
  learner.reset();
  // Two starts, 0.19 and 0.15 s: their mean; a plant beyond max reads as max; reset() forgets.
  const auto start = [&](double truth) {
    aic::WheelLoopModel plant(mcu(truth));
    aic::WheelLoopModel record(mcu(0.1));
    return rampFromRest(&learner, &plant, &record);
  };
  ASSERT_EQ(start(0.19), 1);
  EXPECT_NEAR(learner.latency(), 0.19, 1.5e-3);
  ASSERT_EQ(start(0.15), 1);
  EXPECT_NEAR(learner.latency(), 0.17, 1.5e-3);
  ASSERT_EQ(start(0.25), 1);
  EXPECT_NEAR(learner.lastStart(), 0.2, 1e-9);
  learner.reset();
  EXPECT_EQ(learner.latency(), 0.1);
  EXPECT_EQ(learner.starts(), 0);
}

TEST(ControllerRobotModel, TheGoalsPathIsTheWheelLoopsLagToARamp)
{
  // With the MCU's feed-forward in the model (c 0.787, T_w 0.01365 s) the wheels follow a ramped
  // command (1 - c) T_w behind, and the goal's path lags by that much: a 0.1 m/s step from rest is
  // sent whole by the second action step (two feed-forward kicks) and never more than 1 % above.
  // On the proportional path's lag T_w the path lags what the wheels can do and the command creeps
  // up over five action steps (99.1 % of the step at the second).
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  p.robot.wheel_feedforward = 0.787;
  p.robot.wheel_feedforward_acceleration = 34.76;
  p.robot.wheel_time_constant = 0.01365;
  const double wheel_goal = 0.1 / p.wheel_radius;
  aic::ActiveInferenceController two_steps(p);
  EXPECT_GT(jackal_test::driveAgainstWheelLoop(&two_steps, p.robot, base::Vector3(0.1, 0.0, 0.0), 0.04),
            0.999 * wheel_goal);
  aic::ActiveInferenceController whole(p);
  EXPECT_LT(jackal_test::driveAgainstWheelLoop(&whole, p.robot, base::Vector3(0.1, 0.0, 0.0), 1.0), 1.01 * wheel_goal);
}

TEST(ControllerRobotModel, AtItsFirstStartALatePlantIsWaitedForNotPushed)
{
  // The MCU's feed-forward in the model (c 0.787, A_ff 34.76 rad/s^2), L = 0.1187 s, a 0.5 m/s
  // step from rest (5.10 rad/s per wheel). Against a plant whose commands act 0.1424 s later, with
  // learn_latency the wheels' readings at rest wait for the start to show, and the command goes
  // no higher than against a plant of the model's own L. Without, the model has the wheels moving
  // 24 ms before they do, the belief falls behind and the action pushes the command 10 % higher.
  const auto highestCommand = [](double plant_latency, bool learn) {
    params::AicParams p = params::recommendedAicParams();
    p.belief_model = params::BeliefModel::kRobot;
    p.robot.wheel_feedforward = 0.787;
    p.robot.wheel_feedforward_acceleration = 34.76;
    p.robot.wheel_time_constant = 0.01365;
    p.robot.learn_latency = learn;
    aic::ActiveInferenceController c(p);
    params::RobotModelParams truth = p.robot;
    truth.latency = plant_latency;
    return jackal_test::driveAgainstWheelLoop(&c, truth, base::Vector3(0.5, 0.0, 0.0));
  };
  const double wheel_goal = 0.5 / params::recommendedAicParams().wheel_radius;
  const double own_latency = highestCommand(0.1187, false);
  EXPECT_LT(own_latency, 1.05 * wheel_goal);
  EXPECT_NEAR(highestCommand(0.1424, true), own_latency, 0.005 * wheel_goal);
  EXPECT_GT(highestCommand(0.1424, false), own_latency + 0.1 * wheel_goal);
}

TEST(ControllerRobotModel, LearnsTheLatencyOfAPlantAtItsFirstStart)
{
  // The controller (L = 0.1187 s, learn_latency) against a wheel-loop plant whose commands act
  // 0.1424 s later: after the first start from rest its wheel loop's L is the plant's within 2 ms,
  // and the goal is predicted ahead by that L too; with learn_latency off it stays as configured;
  // resetLearning() forgets it.
  for (const bool learn : { true, false })
  {
    SCOPED_TRACE(learn);
    params::AicParams p = params::recommendedAicParams();
    p.belief_model = params::BeliefModel::kRobot;
    p.robot.learn_latency = learn;
    aic::ActiveInferenceController c(p);
    params::RobotModelParams truth = p.robot;
    truth.latency = 0.1424;
    jackal_test::driveAgainstWheelLoop(&c, truth, base::Vector3(0.5, 0.0, 0.0));
    EXPECT_NEAR(c.wheelLoop().latency(), learn ? 0.1424 : 0.1187, learn ? 2e-3 : 1e-12);
    EXPECT_EQ(c.referenceModel().params().goal_lead, c.wheelLoop().latency());
    EXPECT_EQ(c.referenceModel().params().goal_lead_angular, c.wheelLoop().latency());
    // A parameter change that keeps the latency's settings keeps the learned L, in the wheel loop
    // and in the goal's lead alike.
    const double latency = c.wheelLoop().latency();
    params::AicParams changed = p;
    changed.robot.action_gain *= 0.5;
    c.setParams(changed);
    EXPECT_EQ(c.wheelLoop().latency(), latency);
    EXPECT_EQ(c.referenceModel().params().goal_lead, latency);
    c.setParams(p);
    c.resetLearning();
    EXPECT_EQ(c.wheelLoop().latency(), 0.1187);
    EXPECT_EQ(c.referenceModel().params().goal_lead, 0.1187);
  }
}
