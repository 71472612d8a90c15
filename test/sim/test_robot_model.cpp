/**
 * \file test_robot_model.cpp
 * \brief Closed-loop checks of belief_model robot (config/default.yaml)
 *        on the simulated Jackal (doc/active_inference.md, 'The robot model'): the beliefs are the
 *        robot's state, the arcs' steady yaw rate is the command, the wheel separation is learned,
 *        the action does the driving. Seeded sensor noise: deterministic. The step and overshoot
 *        bounds are regression guards of today's figures (doc/active_inference.md, 'Measured').
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "jackal_aic/analysis/steady_estimate.hpp"
#include "jackal_aic/analysis/stop_reversal.hpp"
#include "jackal_aic/analysis/twist_profile.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_test/closed_loop_runs.hpp"

namespace jackal_aic
{
namespace harness
{
namespace
{
using namespace plant;
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;
using jackal_test::firstIsolation;
using jackal_test::separationMove;
using jackal_test::windowMaxDeviation;
using jackal_test::windowMean;
using jackal_test::windowMeanAbsDiff;
using jackal_test::windowPeak;

/// The robot model's parameters (config/default.yaml), with the overrides `more` (KEY=VALUE).
params::NodeParams robotModel(const std::vector<std::string>& more = {})
{
  return loadNodeParamsFiles({ kRoot + "/config/default.yaml" }, more);
}

/// The set-point profile `profile` run for `duration` [s] on the noisy plant with the plant overlays
/// (files or "key=value") and faults (FaultSpec lines).
ClosedLoopRecord runProfile(const params::NodeParams& node, std::vector<SetPointSegment> profile, double duration,
                            const std::vector<std::string>& faults = {}, const std::vector<std::string>& overlays = {})
{
  ClosedLoopConfig c;
  for (const std::string& line : faults)
  {
    FaultSpec f;
    std::string error;
    if (!parseFaultSpec(line, &f, &error))
    {
      ADD_FAILURE() << line << ": " << error;
    }
    c.faults.push_back(f);
  }
  c.controller = LoopController::kAic;
  c.node = node;
  c.aic = node.aic;
  c.profile = std::move(profile);
  c.duration = duration;
  c.ideal_sensors = false;
  return jackal_test::runOnJackal(kRoot, c, overlays);
}

/// A step to (linear [m/s], angular [rad/s]) at `start` [s] after rest, run for `duration` [s] on the
/// noisy plant with the plant overlays and faults (as runProfile()).
ClosedLoopRecord run(const params::NodeParams& node, double linear, double angular, double duration,
                     const std::vector<std::string>& overlays = {}, const std::vector<std::string>& faults = {},
                     double start = 1.0)
{
  return runProfile(node, { { 0.0, 0.0, 0.0 }, { start, linear, angular } }, duration, faults, overlays);
}
}  // namespace

TEST(RobotModel, ArcsHoldTheCommandedYawRateAndAreBelieved)
{
  // Three arcs from rest at t = 1 s: the steady true yaw rate within 1.5 % of the command, the
  // beliefs within 0.01 of the truth in the steady segment.
  const params::NodeParams node = robotModel();
  ASSERT_EQ(node.aic.belief_model, params::BeliefModel::kRobot);
  const double arcs[3][2] = { { 0.5, 0.5 }, { 1.0, 0.3 }, { 0.3, 1.0 } };
  for (const auto& arc : arcs)
  {
    SCOPED_TRACE("arc " + std::to_string(arc[0]) + " m/s + " + std::to_string(arc[1]) + " rad/s");
    const ClosedLoopRecord r = run(node, arc[0], arc[1], 9.0);
    EXPECT_EQ(r.runaways, 0u);
    EXPECT_NEAR(windowMean(r, r.yaw_true, 6.0, 9.0), arc[1], 0.015 * arc[1]);
    EXPECT_LE(windowMeanAbsDiff(r, r.belief_yaw, r.yaw_true, 6.0, 9.0), 0.01);
    EXPECT_LE(windowMeanAbsDiff(r, r.belief, r.v_true, 6.0, 9.0), 0.01);
  }
}

TEST(RobotModel, StepsAndTheArcsOvershootRegressionGuard)
{
  // Regression guard of the measured figures (doc/active_inference.md, 'The robot model'):
  // 0.5 m/s settles within 0.30 s with under 1 % overshoot (default: 0.284 s); the 0.5 m/s +
  // 0.5 rad/s arc's true yaw overshoots under 7 % (measured 5.9 %; the default 6.95 %).
  const params::NodeParams node = robotModel();
  const ClosedLoopRecord step = run(node, 0.5, 0.0, 4.0);
  EXPECT_LE(windowPeak(step, step.v_true, 1.0, 4.0), 0.505);
  double settled = NAN;
  for (std::size_t k = step.time.size(); k-- > 0;)
  {
    if (std::abs(step.v_true[k] - 0.5) > 0.025)
    {
      settled = step.time[k] - 1.0;
      break;
    }
  }
  EXPECT_LE(settled, 0.30);
  const ClosedLoopRecord arc = run(node, 0.5, 0.5, 6.0);
  EXPECT_LE(windowPeak(arc, arc.yaw_true, 1.2, 6.0), 0.5 * 1.07);
}

TEST(RobotModel, ASmallStepIsNotOverdrivenAtAnyPhaseOfTheActionClock)
{
  // A 0.1 m/s step 10, 17.5 and 25 ms after a 50 Hz tick (closed_loop_run --rest 1, 1.0075, 1.015):
  // the goal the action aims at is the reference path one action step ahead by the path's own
  // exact step, which never passes the target; extrapolated along its rate (T_r = T_w 6.6 ms against
  // a 20 ms step) it would, and the wheels would be overdriven (doc/active_inference.md, 'The robot
  // model'). Each peak within 1 %.
  const params::NodeParams node = robotModel();
  for (const double phase : { 0.0, 0.0075, 0.015 })
  {
    const ClosedLoopRecord r = run(node, 0.1, 0.0, 3.0, {}, {}, 1.01 + phase);
    EXPECT_LE(windowPeak(r, r.v_true, 1.0, 3.0), 0.101) << "step at 1.01 s + " << phase << " s";
  }
}

TEST(RobotModel, WithTheMcusFeedForwardInTheModelASmallStepIsNotSentAboveTheSetPoint)
{
  // The identified MCU feeds the command's rate forward (plant motor.accel_feedforward). Without
  // that term in the model the first command of a 0.1 m/s step is above the set point (the most a
  // first-order loop gives in one action step) and the next comes back, which the MCU turns into a
  // brake; with it (c = J_ff / J_n, A_ff = accel_feedforward_limit / J_n, T_w = set-point lag +
  // J_n / K_p: doc/active_inference.md, 'The MCU's acceleration feed-forward'; the overlay's) the
  // command rises to the set point and stays, and the wheels reach 95 % no later. At three phases
  // of the action clock.
  const params::NodeParams on = robotModel();
  const params::NodeParams off =
      robotModel({ "wheel_feedforward=0", "wheel_feedforward_acceleration=0", "wheel_time_constant=0.00657" });
  const auto reached = [](const ClosedLoopRecord& r) -> double {
    for (std::size_t k = 0; k < r.time.size(); ++k)
    {
      if (r.time[k] >= 1.0 && r.v_true[k] >= 0.095)
      {
        return r.time[k];
      }
    }
    return std::numeric_limits<double>::infinity();
  };
  for (const double phase : { 0.0, 0.0075, 0.015 })
  {
    SCOPED_TRACE("step at 1.01 s + " + std::to_string(phase) + " s");
    const ClosedLoopRecord with = run(on, 0.1, 0.0, 2.0, {}, {}, 1.01 + phase);
    const ClosedLoopRecord without = run(off, 0.1, 0.0, 2.0, {}, {}, 1.01 + phase);
    EXPECT_LE(windowPeak(with, with.command, 1.0, 2.0), 0.1005);
    EXPECT_GT(windowPeak(without, without.command, 1.0, 2.0), 0.105);
    EXPECT_LE(reached(with), reached(without));
  }
}

TEST(RobotModel, TheActionDoesTheDriving)
{
  // The action's loop gain x 0.001: the robot does not follow a 0.5 m/s step within 3 s.
  const ClosedLoopRecord cut = run(robotModel({ "action_gain=0.05" }), 0.5, 0.0, 4.0);
  EXPECT_LT(windowMean(cut, cut.v_true, 3.5, 4.0), 0.4);
}

TEST(RobotModel, AGyroOffsetAppearingMidArcIsTheOffset)
{
  // A 0.1 rad/s gyro offset from 6 s to 10 s into a 0.5 m/s + 0.5 rad/s arc (started at 1 s): b_hat
  // moves less than 2 % and the true yaw rate stays within 5 % of the command; the offset is believed.
  const ClosedLoopRecord r = run(robotModel(), 0.5, 0.5, 10.0, {}, { "gyro bias 0.1 6 4" });
  EXPECT_EQ(r.runaways, 0u);
  const double before = windowMean(r, r.separation, 5.5, 6.0);
  double worst = 0.0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= 6.0 && std::isfinite(r.separation[k]))
    {
      worst = std::max(worst, std::abs(r.separation[k] - before) / before);
    }
  }
  EXPECT_LT(worst, 0.02);
  EXPECT_NEAR(windowMean(r, r.yaw_true, 6.5, 10.0), 0.5, 0.025);
  EXPECT_NEAR(windowMean(r, r.gyro_offset, 7.0, 10.0), 0.1, 0.01);
}

TEST(RobotModel, ASpeedRampInATurnDoesNotTeachTheSeparation)
{
  // stop_and_go's start (sim/profiles/stop_and_go.csv at 10.5 s): from rest, 0.3 rad/s while the
  // speed ramps to 0.8 m/s in a 10 Hz stream. While the tyres' grip goes to the change of speed the
  // body's yaw does not follow the wheels as in a steady turn, and the learning gate's
  // common-acceleration part holds b_hat (without it b_hat moves 7.3 % here, 7.9 % in stop_and_go).
  const ClosedLoopRecord r = runProfile(
      robotModel(), { { 0.0, 0.0, 0.0 }, { 1.0, 0.2, 0.3 }, { 1.1, 0.4, 0.3 }, { 1.2, 0.6, 0.3 }, { 1.3, 0.8, 0.3 } },
      3.0);
  EXPECT_EQ(r.runaways, 0u);
  EXPECT_LT(separationMove(r, 0.0, 3.0), 0.015);
}

TEST(RobotModel, AJoystickFlickIsFollowedNotExtrapolated)
{
  // A turn in place from rest with the stick pushed to its stop at a quickening pace: the field
  // trial's mirror of sim/profiles/teleop_joystick.csv's turn (aic_field_trial.py drives every run
  // back time-reversed), 20 Hz, 0 -> 1.4 rad/s in 0.35 s in steps growing to 0.37 rad/s. The goal
  // is predicted one latency ahead along the stream's slope, and the ramp's end is seen only after
  // it. The standard field plan (config/field_trials/standard.yaml) stops the session when the
  // robot turns faster than 1.3 x its 1.5 rad/s limit. With max_goal_rate_angular at the stock
  // controller's 4 rad/s^2 the true yaw peaks at 1.79 rad/s; bounded only by what the wheels follow
  // (14.95 rad/s^2) at 2.08, and the session stops.
  constexpr double kOverspeed = 1.3 * 1.5;
  const std::vector<SetPointSegment> flick = { { 0.0, 0.0, 0.0 },     { 1.0, 0.0, 0.0558 },  { 1.05, 0.0, 0.0748 },
                                               { 1.1, 0.0, 0.1609 },  { 1.15, 0.0, 0.3333 }, { 1.2, 0.0, 0.506 },
                                               { 1.25, 0.0, 0.7358 }, { 1.3, 0.0, 1.0319 },  { 1.35, 0.0, 1.4 } };
  const ClosedLoopRecord r = runProfile(robotModel(), flick, 3.5);
  EXPECT_EQ(r.runaways, 0u);
  EXPECT_LE(windowPeak(r, r.yaw_true, 1.0, 3.5), kOverspeed);
  EXPECT_NEAR(windowMean(r, r.yaw_true, 2.5, 3.5), 1.4, 0.03);
  const ClosedLoopRecord wheels = runProfile(robotModel({ "max_goal_rate_angular=15" }), flick, 3.5);
  EXPECT_GT(windowPeak(wheels, wheels.yaw_true, 1.0, 3.5), kOverspeed);  // the ablation: the bound does the work
}

TEST(RobotModel, AStallIsBelieved)
{
  // A turn in place at 1 rad/s with a 100 kg payload: the wheels cannot turn the robot (it turns
  // at about 0.03 rad/s). The shortfall jumps take up the stall, so the believed yaw rate is the
  // robot's (within 0.03 rad/s) from 3 s after the set point on; without the jumps the believed
  // wheels are pulled toward their command between samples and the belief reads about 0.1 rad/s.
  const ClosedLoopRecord r =
      run(robotModel(), 0.0, 1.0, 5.0, { "sim/config/variants/payload_20kg.yaml", "payload.mass=100" });
  ASSERT_FALSE(r.time.empty());
  EXPECT_LT(windowMean(r, r.yaw_true, 4.0, 5.0), 0.1);  // stalled
  double worst = 0.0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= 4.0)
    {
      worst = std::max(worst, std::abs(r.belief_yaw[k] - r.yaw_true[k]));
    }
  }
  EXPECT_LE(worst, 0.03);
}

TEST(RobotModel, SeparationLearnedFromOnceAndTwiceTheTrack)
{
  // b_hat within 5 % of the plant's effective separation 10 s into a 0.5 m/s + 0.5 rad/s arc,
  // started from the track and from twice it.
  constexpr double kTrack = 0.37559;  // sim/urdf/jackal.urdf
  for (int i = 1; i <= 2; ++i)
  {
    const double start = i * kTrack;
    SCOPED_TRACE("b_hat from " + std::to_string(start) + " m");
    const ClosedLoopRecord r = run(robotModel({ "wheel_separation=" + std::to_string(start) }), 0.5, 0.5, 11.0);
    EXPECT_EQ(r.runaways, 0u);
    const double b_eff = start * windowMean(r, r.yaw_wheels, 8.0, 11.0) / windowMean(r, r.yaw_true, 8.0, 11.0);
    EXPECT_NEAR(r.separation.back(), b_eff, 0.05 * b_eff);
  }
}

// ---------------------------------------------------------------------------
// Sensor faults with the robot model: the fault monitor (doc/active_inference.md, 'Fault detection
// and isolation') against honest beliefs. The scenarios are those of test_closed_loop_acceptance.cpp.

TEST(RobotModelFaults, ABiasedEncoderIsIsolatedAgainstTheModelsPrediction)
{
  // A 2.5 rad/s bias on one encoder at 0.5 m/s straight, from 3.5 s. The beliefs follow the
  // encoders, so tested against the corrected beliefs the two biased-in channels would agree and
  // the gyro be isolated; while the fault is tested the beliefs follow the model instead, and the
  // biased encoder is the one isolated. The speed holds and b_hat learns nothing from it.
  for (const auto& side : { std::make_pair(std::string("left"), 2.5), std::make_pair(std::string("right"), -2.5) })
  {
    SCOPED_TRACE(side.first);
    const ClosedLoopRecord r = runProfile(robotModel(), { { 0.0, 0.0, 0.0 }, { 0.5, 0.5, 0.0 } }, 11.5,
                                          { side.first + "_encoder bias " + std::to_string(side.second) + " 3.5" });
    EXPECT_EQ(r.runaways, 0u);
    const HealthEvent* iso = firstIsolation(r, 3.5);
    ASSERT_NE(iso, nullptr) << "the biased encoder was never isolated";
    EXPECT_EQ(iso->channel, side.first == "left" ? base::kOmegaLeft : base::kOmegaRight);
    EXPECT_LE(iso->time - 3.5, 0.5);
    EXPECT_EQ(firstIsolation(r, 0.0), iso) << "a channel isolated before the fault";
    EXPECT_NEAR(windowMean(r, r.v_true, 10.5, 11.5), 0.5, 0.025);
    EXPECT_LT(separationMove(r, 3.5, 11.5), 0.02);
  }
}

TEST(RobotModelFaults, AFrozenGyroIsIsolatedAndTheRobotGoesStraightWithOrWithoutIt)
{
  // A (0.4 m/s, 0.8 rad/s) turn from 0.5 s, the gyro frozen from 6.5 s, straight from 7.5 s. With
  // isolation the gyro is isolated and b_hat learns nothing from it. Without, the robot goes straight
  // too: the action is on the wheels, whose belief the frozen gyro does not move (the goal model's
  // beliefs keep part of the frozen turn and the robot turns the other way).
  const std::vector<SetPointSegment> profile = { { 0.0, 0.0, 0.0 }, { 0.5, 0.4, 0.8 }, { 7.5, 0.4, 0.0 } };
  const ClosedLoopRecord r = runProfile(robotModel(), profile, 15.5, { "gyro freeze 6.5" });
  const HealthEvent* iso = firstIsolation(r, 6.5);
  ASSERT_NE(iso, nullptr) << "the frozen gyro was never isolated";
  EXPECT_EQ(iso->channel, base::kGyroZ);
  EXPECT_LT(std::abs(windowMean(r, r.yaw_true, 13.5, 15.5)), 0.01);
  EXPECT_LT(separationMove(r, 6.5, 15.5), 0.02);
  const ClosedLoopRecord open = runProfile(robotModel({ "fdi_enabled=false" }), profile, 15.5, { "gyro freeze 6.5" });
  EXPECT_EQ(firstIsolation(open, 0.0), nullptr);
  EXPECT_LT(std::abs(windowMean(open, open.yaw_true, 13.5, 15.5)), 0.01);
}

TEST(RobotModelFaults, TheOffsetLearnedAtRestIsNotCountedTwice)
{
  // A 0.03 rad/s gyro offset from power-on, 6 s at rest, then a (0.5 m/s, +-0.5 rad/s) arc. beta
  // learns the offset at rest before the offset learner's estimate is removed from the gyro (5.5 s);
  // then beta gives it back (gyroOffsetRemoved()), so the arc's yaw rate and b_hat are those of a run
  // without the offset. beta alone (learn_gyro_bias off) holds the arc too.
  for (const double turn : { 0.5, -0.5 })
  {
    SCOPED_TRACE(turn);
    const std::vector<SetPointSegment> arc = { { 0.0, 0.0, 0.0 }, { 6.0, 0.5, turn } };
    const ClosedLoopRecord clean = runProfile(robotModel(), arc, 16.0);
    const ClosedLoopRecord r = runProfile(robotModel(), arc, 16.0, { "gyro bias 0.03 0" });
    EXPECT_EQ(firstIsolation(r, 0.0), nullptr) << "an offset below the threshold is no isolated fault";
    EXPECT_NEAR(windowMean(r, r.yaw_true, 13.0, 16.0), turn, 0.015 * 0.5);
    EXPECT_NEAR(r.separation.back() / clean.separation.back(), 1.0, 0.02);
    EXPECT_NEAR(windowMean(r, r.gyro_offset, 5.8, 6.0), 0.03, 0.003);
    const ClosedLoopRecord alone =
        runProfile(robotModel({ "learn_gyro_bias=false" }), arc, 16.0, { "gyro bias 0.03 0" });
    EXPECT_NEAR(windowMean(alone, alone.yaw_true, 13.0, 16.0), turn, 0.015 * 0.5);
  }
}

TEST(RobotModelFaults, GyroFaultsAtRestDoNotTeachTheOffset)
{
  // Standing 12 s with a 0.03 rad/s offset from power-on; at 7 s a 0.5 rad/s gyro bias for 3 s
  // (isolated) or 1 s of 3 rad/s spikes every 0.1 s (not isolated); an arc from 12 s. The learned
  // offset (the learner's plus beta) moves during the fault no more than it does at rest without
  // one, plus 0.001 rad/s (beta's own noise at rest with q_beta 0.01 is about 0.0016 rad/s), and
  // the arc holds its yaw rate.
  const std::vector<SetPointSegment> profile = { { 0.0, 0.0, 0.0 }, { 12.0, 0.5, 0.5 } };
  const ClosedLoopRecord clean = runProfile(robotModel(), profile, 20.0, { "gyro bias 0.03 0" });
  const double clean_before = windowMean(clean, clean.gyro_offset, 6.8, 6.98);
  const double clean_moved = windowMaxDeviation(clean, clean.gyro_offset, clean_before, 7.0, 12.0);
  for (const auto& k : { std::make_pair(std::string("gyro bias 0.5 7 3"), true),
                         std::make_pair(std::string("gyro spikes 3 7 1 0.1"), false) })
  {
    SCOPED_TRACE(k.first);
    const ClosedLoopRecord r = runProfile(robotModel(), profile, 20.0, { "gyro bias 0.03 0", k.first });
    const double before = windowMean(r, r.gyro_offset, 6.8, 6.98);
    EXPECT_NEAR(before, 0.03, 0.003);
    EXPECT_LT(windowMaxDeviation(r, r.gyro_offset, before, 7.0, 12.0), clean_moved + 0.001);
    EXPECT_EQ(firstIsolation(r, 7.0) != nullptr, k.second);
    EXPECT_NEAR(windowMean(r, r.yaw_true, 17.0, 20.0), 0.5, 0.015 * 0.5);
  }
}

TEST(RobotModelFaults, TheInnovationTestIsolatesFaultsTheThesissThresholdMisses)
{
  // The robot model tests each sample against its own prediction (FaultMonitor's innovation test:
  // 5 standard deviations of the innovations' parity, about 0.19 rad/s of yaw, from sigma_g,
  // sigma_e and the yaw model's q_theta), where the goal model's parity threshold comes from its
  // var_y (about 0.36 rad/s). A 1.5 rad/s left encoder bias in a (0.5 m/s, 0.5 rad/s) arc and a
  // 0.25 rad/s gyro bias at 0.5 m/s straight, each from 4 s: the robot model isolates each, the
  // goal model (config/goal_model.yaml over config/default.yaml) neither.
  const params::NodeParams goal =
      loadNodeParamsFiles({ kRoot + "/config/default.yaml", kRoot + "/config/goal_model.yaml" }, {});
  const struct
  {
    std::string fault;
    double turn;
    int channel;
  } cases[] = { { "left_encoder bias 1.5 4", 0.5, base::kOmegaLeft }, { "gyro bias 0.25 4", 0.0, base::kGyroZ } };
  for (const auto& k : cases)
  {
    SCOPED_TRACE(k.fault);
    const ClosedLoopRecord r = run(robotModel(), 0.5, k.turn, 12.0, {}, { k.fault });
    EXPECT_EQ(r.runaways, 0u);
    const HealthEvent* iso = firstIsolation(r, 4.0);
    ASSERT_NE(iso, nullptr) << "not isolated";
    EXPECT_EQ(iso->channel, k.channel);
    EXPECT_LE(iso->time - 4.0, 0.5);
    EXPECT_EQ(firstIsolation(r, 0.0), iso) << "a channel isolated before the fault";
    const ClosedLoopRecord thesis = run(goal, 0.5, k.turn, 12.0, {}, { k.fault });
    EXPECT_EQ(firstIsolation(thesis, 0.0), nullptr) << "the goal model's threshold caught it too";
  }
}

TEST(RobotModelFaults, HealthyDrivingRaisesNoFault)
{
  // The innovation test on every profile of the tracking benchmark, on the nominal plant, the
  // turn-deficit firmware and the 20 kg payload, noisy sensors: no event. A fast set-point change
  // lifts single samples above the threshold (the parity takes the wheels' yaw at once, the body
  // follows them through its scrub lag), never fdi_detect_time of them in a row.
  for (const std::string name : { "creep", "fast", "planner_10hz", "s_curves", "stop_and_go", "teleop_joystick" })
  {
    const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/" + name + ".csv");
    for (const std::string overlay :
         { "", "sim/config/variants/turn_deficit.yaml", "sim/config/variants/payload_20kg.yaml" })
    {
      SCOPED_TRACE(name + " " + overlay);
      const ClosedLoopRecord r =
          runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, {},
                     overlay.empty() ? std::vector<std::string>{} : std::vector<std::string>{ overlay });
      EXPECT_TRUE(r.health_events.empty()) << r.health_events.size() << " fault monitor events";
    }
  }
}

/// RMS of (set point - truth) over the samples of two series of one run (NaN without a finite sample).
double rmsError(const std::vector<double>& set_point, const std::vector<double>& truth)
{
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < std::min(set_point.size(), truth.size()); ++k)
  {
    const double e = set_point[k] - truth[k];
    if (std::isfinite(e))
    {
      sum += e * e;
      ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / n) : NAN;
}

/// RMS of (yaw-rate set point - true yaw rate) over run r [rad/s] (NaN without a finite sample).
double rmsYawError(const ClosedLoopRecord& r)
{
  return rmsError(r.angular_set_point, r.yaw_true);
}

TEST(RobotModel, AWheelLoopWithoutLoadCompensationIsLearnedThroughTheTurnShortfalls)
{
  // The turn-deficit firmware (sim/config/variants/turn_deficit.yaml: a proportional wheel servo
  // alone, its wheels ~1 rad/s short against a turn's scrub) on s_curves, whose turn reverses every
  // few seconds. The turn shortfalls (turn_shortfall_noise 0.3, what plant_identify.py --bag writes
  // for a wheel loop it identifies without load compensation) learn each side's shortfall against
  // the turn and carry it into the next turn: RMS(set point - true yaw rate) 0.058 rad/s against
  // 0.181 with the schema's default 0 (regression guard of the measured figures; the ablation is
  // the same run with them off). Neither raises a fault monitor event.
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/s_curves.csv");
  const std::vector<std::string> firmware{ "sim/config/variants/turn_deficit.yaml" };
  const ClosedLoopRecord off =
      runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, {}, firmware);
  const ClosedLoopRecord on = runProfile(robotModel({ "turn_shortfall_noise=0.3" }), profileSegments(profile, 1.0),
                                         1.0 + profile.duration, {}, firmware);
  std::printf("s_curves on the turn-deficit firmware: RMS yaw-rate error %.4f rad/s with the turn shortfalls, %.4f "
              "without\n",
              rmsYawError(on), rmsYawError(off));
  EXPECT_LE(rmsYawError(on), 0.07);
  EXPECT_GE(rmsYawError(off), 0.15);
  EXPECT_TRUE(on.health_events.empty()) << on.health_events.size() << " fault monitor events";
  EXPECT_EQ(on.runaways, 0u);
}

/// RMS of (linear set point - true speed) over run r [m/s] (NaN without a finite sample).
double rmsSpeedError(const ClosedLoopRecord& r)
{
  return rmsError(r.set_point, r.v_true);
}

namespace
{
/// creep on the firmware variant `variant`: RMS error AIC / stock controller of (vx, wz), same
/// profile, plant and seeds.
std::pair<double, double> creepAgainstStock(const std::string& variant)
{
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/creep.csv");
  const std::vector<std::string> firmware{ "sim/config/variants/" + variant + ".yaml" };
  const ClosedLoopRecord aic =
      runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, {}, firmware);
  ClosedLoopConfig c;
  c.controller = LoopController::kStock;
  c.profile = profileSegments(profile, 1.0);
  c.duration = 1.0 + profile.duration;
  c.ideal_sensors = false;
  const ClosedLoopRecord stock = jackal_test::runOnJackal(kRoot, c, firmware);
  EXPECT_EQ(aic.runaways, 0u) << variant;
  const std::pair<double, double> ratio(rmsSpeedError(aic) / rmsSpeedError(stock),
                                        rmsYawError(aic) / rmsYawError(stock));
  std::printf("%s creep: RMS error AIC / stock %.3f (vx), %.3f (wz)\n", variant.c_str(), ratio.first, ratio.second);
  return ratio;
}
}  // namespace

TEST(RobotModel, InAnArcAShortfallIsMadeUpAsTheTurnNotAsSpeed)
{
  // creep's 0.1 m/s, -0.2 rad/s arc on the turn-deficit firmware (sim/config/variants/turn_deficit.yaml):
  // the body resists the turn, the outer wheel falls short, the body pushes the inner one over its
  // command, and the wheels roll at the body's speed. Made up on the outer side alone, the
  // shortfall drives the robot faster (scorecard 6d's run of this pair, closed_loop_run: AIC / stock
  // 1.15 on vx; the ablation: dev/ablations.txt 'arc_shortfall'); made up as the turn
  // (LatencyAction::inArc()), 0.78 there and 0.81 here. Acceptance: the per-pair bound of scorecard
  // 6d, AIC / stock <= 1.02 on both channels.
  const std::pair<double, double> ratio = creepAgainstStock("turn_deficit");
  EXPECT_LE(ratio.first, 1.02);
  EXPECT_LE(ratio.second, 1.02);
}

TEST(RobotModel, InAnArcOnTheSlowBreakawayTheSpeedIsNotRaisedRegressionGuard)
{
  // The same arc on the slow break-away firmware (sim/config/variants/slow_breakaway.yaml), whose
  // integral path takes the turn's load up over seconds. Measured AIC / stock: 1.083 (vx), 1.016
  // (wz) in this run; 1.19 on vx with the shortfall made up on the outer side alone. Scorecard
  // 6d's run of the same pair (closed_loop_run, another start phase of the 50 Hz clocks) gives
  // 1.02 / 1.01. Regression guard of today's figures.
  const std::pair<double, double> ratio = creepAgainstStock("slow_breakaway");
  EXPECT_LE(ratio.first, 1.10);
  EXPECT_LE(ratio.second, 1.03);
}

TEST(RobotModel, AShortfallBeyondASaturatedProportionalPathIsNotChasedRegressionGuard)
{
  // The slow break-away firmware (sim/config/variants/slow_breakaway.yaml): its proportional path
  // saturates at 0.065 rad/s of error and its integral path, without load observer, takes a
  // turn's load up over seconds. A command raised beyond what the proportional path answers only
  // winds that integral up, and the wheel overshoots when it breaks away. With
  // shortfall_compensation_limit at what plant_identify.py --bag writes for that firmware's bag
  // (proportional_limit / speed_kp = 1.036 / 6.987 = 0.148 rad/s): creep's RMS speed error
  // 0.0170 m/s against 0.0169 without (creep's arc shortfall is made up as the turn,
  // LatencyAction::inArc(); without that rule, 0.0172 against 0.0185). Without the key, creep's chase of jumps and the 0.3 rad/s
  // turn in place's are ended by the saturated sides (RobotBelief::saturated(): a jump the raised
  // command did not answer) and the stalled ones (RobotBelief::stalled(): a held wheel's shortfall
  // is not made up): the turn peaks at 0.377 rad/s without the key, 0.329 with it (the stock
  // controller's 0.30); with the unanswered jumps' rule taken out (dev/ablations.txt 'unanswered_jump_hold')
  // creep's error is 0.0238 m/s and the turn without the key peaks at 0.64 rad/s. Regression guards
  // of the measured figures; the ablation is the same run without the key.
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/creep.csv");
  const std::vector<std::string> firmware{ "sim/config/variants/slow_breakaway.yaml" };
  const params::NodeParams bounded = robotModel({ "shortfall_compensation_limit=0.148" });
  const double on =
      rmsSpeedError(runProfile(bounded, profileSegments(profile, 1.0), 1.0 + profile.duration, {}, firmware));
  const double off =
      rmsSpeedError(runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, {}, firmware));
  const ClosedLoopRecord turn_on = run(bounded, 0.0, 0.3, 6.0, firmware);
  const ClosedLoopRecord turn_off = run(robotModel(), 0.0, 0.3, 6.0, firmware);
  const double peak_on = windowPeak(turn_on, turn_on.yaw_true, 1.0, 6.0);
  const double peak_off = windowPeak(turn_off, turn_off.yaw_true, 1.0, 6.0);
  std::printf("slow break-away: creep RMS speed error %.4f m/s with the bound, %.4f without; 0.3 rad/s turn in "
              "place peaks at %.3f rad/s with, %.3f without, ends at %.3f with\n",
              on, off, peak_on, peak_off, windowMean(turn_on, turn_on.yaw_true, 5.0, 6.0));
  EXPECT_LE(on, 0.018);
  EXPECT_LE(off, 0.018);
  EXPECT_LE(peak_on, 0.35);
  EXPECT_LE(peak_off, 0.40);
  EXPECT_NEAR(windowMean(turn_off, turn_off.yaw_true, 5.0, 6.0), 0.3, 0.015);
  EXPECT_NEAR(windowMean(turn_on, turn_on.yaw_true, 5.0, 6.0), 0.3, 0.015);
  EXPECT_EQ(turn_on.runaways, 0u);
}

namespace
{
/// A 1 rad/s turn in place stalled by 100 kg from the start for 4 s, then freed (run once, shared
/// by the tests of the stall).
const ClosedLoopRecord& stalledTurnInPlace()
{
  static const ClosedLoopRecord r = run(robotModel(), 0.0, 1.0, 9.0, {}, { "payload set 100 1 4" });
  return r;
}
}  // namespace

TEST(RobotModel, AStallThatFreesGivesItsShortfallBack)
{
  // In the stall the shortfall's jumps take it (the first 3.88 rad/s). When it frees, the wheels
  // run ahead of u - d at a held command, and the jumps are dropped
  // (RobotBelief::shortfallReleases()): the turn settles at the stock controller's 1.04 rad/s
  // (mean over 6 to 8 s after the start: 1.000). Kept, the jumps left the robot turning at 2.09
  // rad/s (the ablation: the release rule taken out of RobotBelief::detectShortfallJump()).
  const ClosedLoopRecord& r = stalledTurnInPlace();
  ASSERT_FALSE(r.time.empty());
  const double stalled = windowMean(r, r.yaw_true, 3.0, 5.0);
  const double freed = windowMean(r, r.yaw_true, 7.0, 9.0);
  std::printf("stall that frees: %.3f rad/s stalled, %.3f rad/s from 2 s after it frees\n", stalled, freed);
  EXPECT_LT(stalled, 0.1);
  EXPECT_NEAR(freed, 1.0, 0.06);
  EXPECT_EQ(r.runaways, 0u);
}

TEST(RobotModel, AStallDoesNotWindTheCommandUpRegressionGuard)
{
  // The wheels do not answer the MCU's feed-forward kicks: the side is stalled
  // (RobotBelief::stalled()) and its command stays within one kick range of its steady command
  // (WheelLoopModel::kickRange()); the jump whose raised command does not move the wheel saturates
  // the side (RobotBelief::saturated()): none of its shortfall is made up and it is commanded the
  // goal's wheel speed; a wheel held again after its jump's compensation saturates its side at
  // once. The belief stays on the stalled wheel. Measured: the command's yaw rate peaks at 2.93
  // rad/s in the stall (the first jump's compensation, before the wheel is held again), the freed
  // turn at 1.03 rad/s (the stock controller: 1.04) and the believed yaw rate is within 0.003 rad/s
  // of the truth from 1.5 s into the stall (0.14 without the held-again rule, which leaves the
  // command swinging between the kick range and the jump's compensation); with the saturated side commanded as a stalled one, 1.32;
  // with its first jump's compensation held instead of none, 1.54; without the unanswered jumps
  // the command's yaw rate climbs to 6.97 rad/s and the freed turn peaks at 1.95 rad/s, and without
  // the stall's reach too to max_wheel_speed (7.0 rad/s of yaw) and 2.58 rad/s. Regression guard of
  // today's figures.
  const ClosedLoopRecord& r = stalledTurnInPlace();
  ASSERT_FALSE(r.time.empty());
  const double command = windowPeak(r, r.command_yaw, 1.0, 5.0);
  const double freed = windowPeak(r, r.yaw_true, 5.0, 9.0);
  std::printf("stall: the command's yaw rate peaks at %.3f rad/s, the freed turn at %.3f rad/s (%llu stalls, %llu "
              "unanswered jumps)\n",
              command, freed, static_cast<unsigned long long>(r.stalls),
              static_cast<unsigned long long>(r.unanswered_jumps));
  // The believed yaw rate against the truth from 1.5 s into the stall to its end (test time 2.5 to
  // 4.9 s; the stall from 1 to 5 s).
  double belief_off = 0.0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= 2.5 && r.time[k] <= 4.9)
    {
      belief_off = std::max(belief_off, std::abs(r.belief_yaw[k] - r.yaw_true[k]));
    }
  }
  std::printf("stall: |belief - truth| of the yaw rate from 1.5 s into the stall at most %.4f rad/s\n", belief_off);
  EXPECT_LE(command, 3.0);
  EXPECT_LE(freed, 1.10);
  EXPECT_LE(belief_off, 0.03);  // the stall bound on the beliefs
  EXPECT_GE(r.stalls, 2u);      // both sides: the rules acted
  EXPECT_GE(r.unanswered_jumps, 2u);
}

TEST(RobotModel, AWheelThatSticksAndSlipsStaysStalledRegressionGuard)
{
  // The slow break-away firmware's 1 rad/s turn in place (sim/config/variants/slow_breakaway.yaml):
  // its integral path takes the scrub up over seconds, and the wheels stick and slip until it has.
  // Once a wheel has been held still below half the model's steady speed, its side stays stalled
  // (RobotBelief::stalled()) through the slipping, until the wheel answers: its command stays
  // within a kick of the goal's and none of its shortfall is made up. Measured: the command's yaw
  // rate peaks at 2.55 rad/s, the turn at 1.17 rad/s, within 5 % from 3.77 s after the step (the
  // stock controller: 1.03, from 3.26 s). With the stall ended when the wheel moves (before it
  // answers), the command's yaw rate climbs to 6.0 rad/s and the turn peaks at 1.27 rad/s, within
  // 5 % from 6.59 s. Regression guard of today's figures.
  const ClosedLoopRecord r = run(robotModel(), 0.0, 1.0, 9.0, { "sim/config/variants/slow_breakaway.yaml" });
  ASSERT_FALSE(r.time.empty());
  const double command = windowPeak(r, r.command_yaw, 1.0, 9.0);
  const double peak = windowPeak(r, r.yaw_true, 1.0, 9.0);
  const double end = windowMean(r, r.yaw_true, 7.0, 9.0);
  std::printf("slow break-away 1 rad/s turn in place: the command's yaw rate peaks at %.3f rad/s, the turn at %.3f "
              "rad/s, %.3f rad/s over its last 2 s (%llu stalls)\n",
              command, peak, end, static_cast<unsigned long long>(r.stalls));
  EXPECT_LE(command, 3.0);
  EXPECT_LE(peak, 1.22);
  EXPECT_NEAR(end, 1.0, 0.03);
  EXPECT_EQ(r.runaways, 0u);
}

TEST(RobotModel, TheTurnShortfallsKeepTheBeliefHonestOnAWheelLoopThatHoldsNoTurnLoad)
{
  // planner_10hz on the turn-deficit firmware (scorecard 6g's run, as closed_loop_run plays it:
  // the profile from 1.01 s, the steady mean |belief - truth| from 0.5 s after each change). With
  // the schema's turn_shortfall_noise 0 the inner wheel runs over its command in a turn, which a
  // shortfall's jump does not take; between joint states the model's wheels move toward speeds
  // the robot does not have and carry the belief's yaw rate above the truth (0.0107 rad/s
  // measured, over 6g's 0.01). With the turn shortfalls on (0.3, what plant_identify.py --bag
  // writes for such a wheel loop) the belief is within the bound (0.0033 measured); the ablation
  // is the same run with them off (regression guard of the measured pair: on at most half of off).
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/planner_10hz.csv");
  const double t0 = 1.01;
  const std::vector<std::string> firmware{ "sim/config/variants/turn_deficit.yaml" };
  auto steady = [&](const ClosedLoopRecord& r) {
    std::vector<double> t;
    for (const double x : r.time)
    {
      t.push_back(x - t0);
    }
    return analysis::steadyEstimateError(profile, t, r.belief, r.belief_yaw, r.v_true, r.yaw_true, 0.5);
  };
  const analysis::SteadyEstimateError off =
      steady(runProfile(robotModel(), profileSegments(profile, t0), t0 + profile.duration, {}, firmware));
  const analysis::SteadyEstimateError on = steady(runProfile(
      robotModel({ "turn_shortfall_noise=0.3" }), profileSegments(profile, t0), t0 + profile.duration, {}, firmware));
  std::printf("planner_10hz on the turn-deficit firmware: steady mean |belief - truth| of the yaw rate %.4f rad/s "
              "with the turn shortfalls, %.4f without (speed %.4f / %.4f m/s)\n",
              on.wz.mean_abs, off.wz.mean_abs, on.vx.mean_abs, off.vx.mean_abs);
  ASSERT_GT(on.wz.samples, 0);
  EXPECT_LE(on.wz.mean_abs, 0.01);
  EXPECT_LE(on.vx.mean_abs, 0.01);
  EXPECT_LE(on.wz.mean_abs, 0.5 * off.wz.mean_abs);
}

TEST(RobotModel, ARampIntoAStopDoesNotBackTheRobotUp)
{
  // stop_and_go: 2 m/s^2 ramps at 10 Hz that end in stops. The goal rate is held 1.25 change
  // intervals past the stream's last change; predicted through the stop it asked for reverse, and
  // the robot backed up at up to 0.237 m/s (doc/active_inference.md, 'Set-point dynamics'). The speed
  // is not predicted through a stop (aic::predictGoal()): the robot stops as the stock controller
  // does, whose reversal there is at most 0.003 m/s; bound: scorecard 6k's, the stock controller's
  // + 0.02 m/s (driving.STOP_MARGIN), with the stock controller's taken as 0.
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/stop_and_go.csv");
  const double t0 = 1.01;
  const ClosedLoopRecord r = runProfile(robotModel(), profileSegments(profile, t0), t0 + profile.duration);
  std::vector<double> t;
  std::vector<double> v;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0)
    {
      t.push_back(r.time[k] - t0);
      v.push_back(r.v_true[k]);
    }
  }
  const analysis::StopReversal stop = analysis::stopReversal(profile, t, v, analysis::kStopWindow);
  std::printf("stop_and_go: %d stops, largest reverse speed %.4f m/s, reverse travel %.4f m\n", stop.stops,
              stop.reverse_speed, stop.reverse_travel);
  ASSERT_GE(stop.stops, 3);
  EXPECT_LE(stop.reverse_speed, 0.02);
  EXPECT_LE(stop.reverse_travel, 0.005);
}

/// The robot model on sim/profiles/planner_10hz.csv from 1 s of rest, noisy sensors, with the
/// faults `faults` (FaultSpec lines, times from the run's start).
ClosedLoopRecord planner(const std::vector<std::string>& faults = {})
{
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/planner_10hz.csv");
  return runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, faults);
}

/// The largest finite value of `b` (the learned separation is NaN before the controller starts).
double finiteMax(const std::vector<double>& b)
{
  double m = -std::numeric_limits<double>::infinity();
  for (const double x : b)
  {
    m = std::isfinite(x) ? std::max(m, x) : m;
  }
  return m;
}

TEST(RobotModel, TheSlipRatioMovesTheSeparationOnlyInATurn)
{
  // planner_10hz with every joint state 20 ms late (the wheels' readings older than the gyro's, as
  // on a loaded robot): at a turn's end the gyro's yaw rate and the wheels' part at different
  // times, and the slip ratio takes some of it. b_hat follows the slip ratio only in a turn (the
  // believed wheels' |yaw rate| at least separation_min_yaw_rate), so it ends within 2 % of the
  // clean run's; following it in straight driving as well, b_hat moved on after the last turn to
  // 0.5923 m against the clean run's 0.5386 m.
  const ClosedLoopRecord clean = planner();
  const ClosedLoopRecord late = planner({ "joint_states delay 0.02 0 40" });
  ASSERT_FALSE(clean.separation.empty());
  ASSERT_FALSE(late.separation.empty());
  std::printf("planner_10hz, b_hat at the end: %.4f m clean, %.4f m with the joint states 20 ms late\n",
              clean.separation.back(), late.separation.back());
  EXPECT_NEAR(late.separation.back(), clean.separation.back(), 0.02 * clean.separation.back());
  EXPECT_EQ(late.runaways, 0u);
}

TEST(RobotModelFaults, AFrozenEncoderDoesNotSpinTheRobot)
{
  // s_curves with the left encoder frozen for 4 s from 2, 4 and 6 s (its reading repeats bit for
  // bit while the wheel follows its command): the frozen samples are skipped, the belief follows
  // the model and the innovation test isolates a channel. Without the frozen-encoder check the belief
  // took the frozen reading, the innovation test isolated the gyro, and the action drove the left
  // wheel to max_wheel_speed: the robot spun at up to 3.3 rad/s (the set point at most 0.70).
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/s_curves.csv");
  for (const std::string start : { "2", "4", "6" })
  {
    SCOPED_TRACE("frozen from " + start + " s");
    const ClosedLoopRecord r = runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration,
                                          { "left_encoder freeze " + start + " 4" });
    double yaw = 0.0;
    double command = 0.0;
    for (std::size_t k = 0; k < r.time.size(); ++k)
    {
      yaw = std::isfinite(r.yaw_true[k]) ? std::max(yaw, std::abs(r.yaw_true[k])) : yaw;
      command = std::isfinite(r.command_yaw[k]) ? std::max(command, std::abs(r.command_yaw[k])) : command;
    }
    std::printf("s_curves, left encoder frozen from %s s: |true yaw rate| at most %.3f rad/s, |commanded| %.3f\n",
                start.c_str(), yaw, command);
    EXPECT_LE(yaw, 0.85);
    EXPECT_LE(command, 1.0);
    EXPECT_EQ(r.runaways, 0u);
  }
}

TEST(RobotModelFaults, AnIsolatedChannelIsNotReadmittedOnTheSlipRatiosUncertainty)
{
  // While a channel is isolated the slip ratio cannot be learned, so its variance does not grow
  // with the turn: the innovation test's parity keeps its sensors' variance and the faulty channel
  // stays isolated through the next turn. Growing it as in healthy driving, a 0.5 rad/s gyro bias
  // isolated on planner_10hz's straight was re-admitted in the next turn, whose slip ratio then
  // took the bias in and b_hat rose to 0.684 m (b_hat_0 0.5621 m); a left encoder biased by
  // 2.5 rad/s on s_curves was re-admitted in each turn: RMS yaw-rate error 0.128 rad/s against
  // 0.036 without the fault.
  const ClosedLoopRecord gyro = planner({ "gyro bias 0.5 9 8" });
  ASSERT_FALSE(gyro.separation.empty());
  const double highest = finiteMax(gyro.separation);
  std::printf("planner_10hz, gyro biased 0.5 rad/s from 9 s for 8 s: b_hat at most %.4f m\n", highest);
  EXPECT_LE(highest, 0.5621 * 1.01);
  const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/s_curves.csv");
  const ClosedLoopRecord encoder =
      runProfile(robotModel(), profileSegments(profile, 1.0), 1.0 + profile.duration, { "left_encoder bias 2.5 4 10" });
  std::printf("s_curves, left encoder biased 2.5 rad/s from 4 s for 10 s: RMS yaw-rate error %.4f rad/s\n",
              rmsYawError(encoder));
  EXPECT_LE(rmsYawError(encoder), 0.045);
  EXPECT_EQ(encoder.runaways, 0u);
}

TEST(RobotModelFaults, AFrozenGyroInATurnDoesNotMoveTheSeparation)
{
  // planner_10hz with the gyro frozen from 5 s for 6 s (through its first turn and the straight
  // after it): a reading that repeats bit for bit teaches the slip ratio nothing, and b_hat takes
  // no slip ratio in while a channel is isolated or a fault suspected. Without those, the slip
  // ratio learned the frozen turn and b_hat rose to 0.783 m (b_hat_0 0.5621 m).
  const ClosedLoopRecord clean = planner();
  const ClosedLoopRecord frozen = planner({ "gyro freeze 5 6" });
  ASSERT_FALSE(clean.separation.empty());
  ASSERT_FALSE(frozen.separation.empty());
  const double highest = finiteMax(frozen.separation);
  std::printf("planner_10hz, gyro frozen 5-11 s: b_hat at most %.4f m (clean %.4f m), at the end %.4f m (clean %.4f "
              "m)\n",
              highest, finiteMax(clean.separation), frozen.separation.back(), clean.separation.back());
  EXPECT_LE(highest, 1.02 * finiteMax(clean.separation));
  EXPECT_NEAR(frozen.separation.back(), clean.separation.back(), 0.02 * clean.separation.back());
  EXPECT_EQ(frozen.runaways, 0u);
}

}  // namespace harness
}  // namespace jackal_aic
