/**
 * \file test_payload.cpp
 * \brief A payload's tip-over limit and the AIC's deceleration bound (doc/usage.md, 'Payloads'):
 *        plant_payload's figures for the rated 20 kg payload mounted 0.15 m forward and 0.25 m up
 *        (sim/config/variants/payload_20kg_forward.yaml) and its refusals of bad arguments; in
 *        closed loop on that plant, a planner's stop from 1.5 m/s (0.2 m/s every 0.1 s, as the
 *        fast profile ends) tips the robot over its front wheels without the tip-over guard, and
 *        leaves it on its wheels with the guard (which learns a bound below the limit; the goal
 *        model and the robot model) or with plant_payload's bound. config/default.yaml, seeded sensor noise: deterministic.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_test/run_command.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"

namespace jackal_aic
{
namespace harness
{
namespace
{
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;
const std::string kForward = "sim/config/variants/payload_20kg_forward.yaml";

using Result = jackal_test::CommandResult;

/// plant_payload with `args`, the package's share folder the source tree.
Result runTool(const std::string& args)
{
  return jackal_test::runCommand(std::string("JACKAL_AIC_SHARE=") + kRoot + " " + PLANT_PAYLOAD_BIN + " " + args);
}

/// The number after `key` in `text` (NaN if absent).
double after(const std::string& text, const std::string& key)
{
  const std::size_t at = text.find(key);
  return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + key.size()));
}

TEST(PlantPayload, TheForwardPayloadTipsOverTheFrontWheelsAboveTwoMetresPerSecondSquared)
{
  const Result r = runTool("--overlay " + kRoot + "/" + kForward);
  ASSERT_EQ(r.code, 0) << r.out;
  // By hand from sim/urdf/jackal.urdf: chassis 16.523 kg at (0.012, 0.067) m, four 0.477 kg wheels
  // at x +-0.131 m, z 0.0345 m, radius 0.098 m; 20 kg at (0.15, 0.25) m: centre of mass x 0.0832 m,
  // 0.2241 m above the ground, 0.0478 m behind the front axle: g 0.0478 / 0.2241 = 2.09 m/s^2.
  EXPECT_NEAR(after(r.out, "deceleration of "), 2.091, 0.002) << r.out;
  EXPECT_NEAR(after(r.out, "acceleration of "), 9.373, 0.002) << r.out;
  EXPECT_NEAR(after(r.out, "max_reference_deceleration_linear: "), 0.8 * 2.091, 0.002) << r.out;
  // The robot model (config/default.yaml) does not read the acceleration key: no line for it, and
  // its wheels' 4.2 m/s^2 forward is below the rear limit's bound.
  EXPECT_EQ(r.out.find("max_reference_acceleration_linear"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("belief_model robot"), std::string::npos) << r.out;
  // The goal model reads it; the schema's 3.689 m/s^2 is above the bound, which follows.
  const Result goal = runTool("--overlay " + kRoot + "/" + kForward + " --aic-set belief_model=goal");
  ASSERT_EQ(goal.code, 0) << goal.out;
  EXPECT_NEAR(after(goal.out, "max_reference_acceleration_linear: "), 0.8 * 2.091, 0.002) << goal.out;
}

TEST(PlantPayload, WithoutAPayloadTheDefaultsAccelerationKeepsTheRobotOnItsWheels)
{
  const Result r = runTool("--mass 0 --position 0,0,0 --margin 0.5");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NEAR(after(r.out, "deceleration of "), 9.275, 0.002) << r.out;
  EXPECT_NEAR(after(r.out, "max_reference_deceleration_linear: "), 0.5 * 9.275, 0.002) << r.out;
  EXPECT_EQ(r.out.find("max_reference_acceleration_linear:"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("belief_model robot"), std::string::npos) << r.out;
}

TEST(PlantPayload, ARearPayloadsLimitSetsTheBoundAndTheRobotModelsForwardStartIsNamed)
{
  // 20 kg 0.2 m behind base_link and 0.3 m up: over the rear wheels above 1.258 m/s^2 (speeding
  // up forward, braking in reverse), over the front ones above 9.0.
  const Result r = runTool("--mass 20 --position -0.2,0,0.3");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NEAR(after(r.out, "max_reference_deceleration_linear: "), 0.8 * 1.258, 0.002) << r.out;
  // The robot model's path speeds up forward at its wheels' 4.2 m/s^2: only the guard bounds that.
  EXPECT_NE(r.out.find("# belief_model robot:"), std::string::npos) << r.out;
}

TEST(PlantPayload, ARobotThatTipsOverAtRestIsAnError)
{
  // The centre of mass behind the rear axle: no acceleration bound keeps it on its wheels (a bound
  // of 0 would read as none).
  const Result r = runTool("--mass 20 --position -0.3,0,0.3");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_EQ(r.out.find("max_reference_deceleration_linear"), std::string::npos) << r.out;
}

TEST(PlantPayload, AFrontHeavyLoadBoundsTheTurnInPlace)
{
  // sim/config/variants/front_heavy.yaml: the centre of mass 0.1125 m ahead of base_link and 0.02 m
  // behind the front axle (0.942 m/s^2). Turning in place at w it is pulled back at w^2 x: over the
  // front wheels above sqrt(0.942 / 0.1125) = 2.894 rad/s, within the node's 4 rad/s.
  const Result r = runTool("--overlay " + kRoot + "/sim/config/variants/front_heavy.yaml");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NEAR(after(r.out, "above a yaw rate of "), 2.894, 0.002) << r.out;
  EXPECT_NEAR(after(r.out, "max_angular_speed: "), std::sqrt(0.8) * 2.894, 0.002) << r.out;
  // The forward payload's 5.0 rad/s is above it: no line.
  const Result fwd = runTool("--overlay " + kRoot + "/" + kForward);
  EXPECT_EQ(fwd.out.find("max_angular_speed"), std::string::npos) << fwd.out;
}

TEST(PlantPayload, RefusesBadArguments)
{
  EXPECT_EQ(runTool("--margin 0").code, 2);
  EXPECT_EQ(runTool("--margin 1.5").code, 2);
  EXPECT_EQ(runTool("--mass 20").code, 2);
  EXPECT_EQ(runTool("--mass 20 --position 0.1,0").code, 2);
  EXPECT_EQ(runTool("--mass 20 --position 2,0,0").code, 2);
  EXPECT_EQ(runTool("--mass nan --position 0,0,0").code, 2);
  EXPECT_EQ(runTool("--mass 20 --position 0,x,0").code, 2);
  EXPECT_EQ(runTool("--urdf /nonexistent.urdf").code, 1);
}

/// What a stop does on the forward payload's plant with the AIC (config/default.yaml, or
/// `configs`, with `overrides`).
struct StopResult
{
  double heading = 0.0;  ///< the largest |heading| after the stop begins [rad] (~pi: turned over)
  double pitch = 0.0;    ///< the largest |pitch| [rad] (the tip-over angle is 0.21 rad)
  ClosedLoopRecord record;
};

/// The run of `profile` (t [s], vx [m/s], wz [rad/s] rows, zero-order hold) for `duration` [s] on
/// the forward payload's plant (or `plant_overlay`'s), noisy sensors; the heading counted from
/// `stop_start` [s].
StopResult runWithThePayload(const std::vector<SetPointSegment>& profile, double duration, double stop_start,
                             const std::vector<std::string>& overrides, const std::vector<std::string>& configs,
                             const std::string& plant_overlay = kForward)
{
  ClosedLoopConfig c;
  c.controller = LoopController::kAic;
  std::vector<std::string> files;
  for (const std::string& f : configs)
  {
    files.push_back(kRoot + "/" + f);
  }
  c.node = loadNodeParamsFiles(files, overrides);
  c.aic = c.node.aic;
  c.profile = profile;
  c.duration = duration;
  c.ideal_sensors = false;
  const std::vector<std::string> plant = overrides::loadOverlayFile(kRoot + "/" + plant_overlay);
  StopResult out;
  out.record = runClosedLoop(plant::loadRobotDescription(kRoot + "/sim/urdf/jackal.urdf"),
                             plant::loadPlantParams(kRoot + "/sim/config/plant.yaml", plant), c);
  const ClosedLoopRecord& r = out.record;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    out.heading = std::max(out.heading, r.time[k] >= stop_start ? std::abs(r.heading_true[k]) : 0.0);
    out.pitch = std::max(out.pitch, std::abs(r.pitch_true[k]));
  }
  return out;
}

/// A planner's stop, `stops` times: 1.5 m/s straight, then down by 0.2 m/s every 0.1 s (2 m/s^2).
StopResult stopWithThePayload(const std::vector<std::string>& overrides, int stops = 1,
                              const std::vector<std::string>& configs = { "config/default.yaml" })
{
  std::vector<SetPointSegment> profile = { { 0.0, 0.0, 0.0 } };
  for (int s = 0; s < stops; ++s)
  {
    const double t0 = 4.0 * s;
    profile.push_back({ t0 + 0.5, 1.5, 0.0 });
    for (int k = 1; k <= 8; ++k)
    {
      profile.push_back({ t0 + 3.0 + 0.1 * k, 1.5 - 0.2 * k < 0.05 ? 0.0 : 1.5 - 0.2 * k, 0.0 });
    }
  }
  return runWithThePayload(profile, 4.0 * stops + 2.0, 3.0, overrides, configs);
}

/// A set point dropped from 1 m/s to zero at once (a joystick let go, ~set_point_timeout's zero).
StopResult dropToZeroWithThePayload(const std::vector<std::string>& overrides)
{
  return runWithThePayload({ { 0.0, 0.0, 0.0 }, { 0.5, 1.0, 0.0 }, { 3.0, 0.0, 0.0 } }, 5.0, 3.0, overrides,
                           { "config/default.yaml" });
}

TEST(PayloadStop, WithoutTheTipGuardTheStopTipsTheForwardPayloadOverItsFrontWheels)
{
  // The robot turned upside down over its front wheels: its yaw reads ~pi (roll and pitch
  // through pi/2).
  const StopResult r = stopWithThePayload({ "tip_guard=false" });
  EXPECT_GT(r.heading, 2.5);
  EXPECT_GT(r.pitch, 1.0);
}

TEST(PayloadStop, TheTipGuardKeepsItOnItsWheelsAndLearnsABoundBelowTheLimit)
{
  // The goal model (config/goal_model.yaml). Two stops: the first lifts the rear wheels and trips
  // the guard (the path stops braking until the body is level), the second is planned below the
  // learned bound and does not lift them.
  const StopResult r = stopWithThePayload({}, 2, { "config/default.yaml", "config/goal_model.yaml" });
  EXPECT_LT(r.heading, 0.1);
  EXPECT_LT(r.pitch, 0.18) << "the rear wheels came down before the tip-over angle (0.21 rad)";
  EXPECT_EQ(r.record.tip_trips, 1u) << "the second stop stays below the learned bound";
  // plant_payload's limit for this payload is 2.09 m/s^2.
  EXPECT_GT(r.record.tip_front, 1.2);
  EXPECT_LT(r.record.tip_front, 2.09);
  EXPECT_TRUE(std::isinf(r.record.tip_rear));
}

TEST(PayloadStop, WithTheRobotModelTheTipGuardKeepsItOnItsWheelsToo)
{
  // The robot model's path leads the wheels by the latency: at the trip the wheels are still
  // braking toward the path's value, and without holding the path at the speed the robot has
  // (ReferenceModel::holdTipSpeed()) they brake on for a latency: the pitch passes the
  // tip-over angle (0.51 rad measured). With it, as with the goal model.
  const std::vector<std::string> robot = { "config/default.yaml" };
  const StopResult r = stopWithThePayload({}, 2, robot);
  EXPECT_LT(r.heading, 0.1);
  EXPECT_LT(r.pitch, 0.18) << "the rear wheels came down before the tip-over angle (0.21 rad)";
  // Its first trip learns 2.03 m/s^2 (0.6 x the 3.38 m/s^2 it measured as the wheels left the
  // ground: the robot model brakes harder than the goal model, whose first bound is 1.79), so the
  // second stop lifts the rear wheels a little (0.043 rad) and trips again; it learns 1.27.
  EXPECT_LE(r.record.tip_trips, 2u);
  EXPECT_GT(r.record.tip_front, 1.2);
  EXPECT_LT(r.record.tip_front, 2.09);
  const StopResult off = stopWithThePayload({ "tip_guard=false" }, 1, robot);
  EXPECT_GT(off.pitch, 1.0) << "without the guard the robot model's stop tips it over: the test checks something";
}

TEST(PayloadStop, WithTheRobotModelATripAfterThePathReachedZeroStillStopsTheBraking)
{
  // A set point dropped to zero: the robot model's path (one latency ahead of the wheels) is down
  // at the wheel loop's rate and at zero before the rear wheels lift, and the MCU brakes on at
  // about 4 m/s^2 through the lift. At the trip the held path asks for the speed the body has
  // (ReferenceModel::holdTipSpeed()); were the zero path taken as rest (zero command) instead, the
  // robot would turn over (1.53 rad measured).
  const StopResult r = dropToZeroWithThePayload({});
  EXPECT_EQ(r.record.tip_trips, 1u);
  EXPECT_LT(r.heading, 0.1);
  EXPECT_LT(r.pitch, 0.18) << "the rear wheels came down before the tip-over angle (0.21 rad)";
  const StopResult off = dropToZeroWithThePayload({ "tip_guard=false" });
  EXPECT_GT(off.pitch, 1.0) << "without the guard this stop tips it over: the test checks something";
}

TEST(PayloadStop, ARobotThatTurnedOverGetsAZeroCommand)
{
  // sim/config/variants/front_heavy.yaml tips at 0.94 m/s^2: a set point dropped from 1.5 m/s to
  // zero turns it over its front wheels with the guard or without it (the stock controller too).
  // Turned over, its wheels spin free and report the speed they are commanded: held at the speed
  // its wheels believe (ReferenceModel::holdTipSpeed()), the robot model commanded 1.84 m/s to a
  // robot on its back, for as long as the guard's pitch took to fade (about 6 s). Past
  // tip_guard_turnover_pitch the command is zero, and it stays zero while the robot lies on its back
  // (the accelerometer's f_z < 0), a new set point 6 s later included: without that the pitch
  // estimate faded and the wheels followed the 0.5 m/s set point.
  const std::vector<SetPointSegment> drop = {
    { 0.0, 0.0, 0.0 }, { 0.5, 1.5, 0.0 }, { 3.0, 0.0, 0.0 }, { 9.0, 0.5, 0.0 }
  };
  const std::string heavy = "sim/config/variants/front_heavy.yaml";
  for (const std::vector<std::string>& configs : std::vector<std::vector<std::string>>{
           { "config/default.yaml" }, { "config/default.yaml", "config/goal_model.yaml" } })
  {
    const StopResult r = runWithThePayload(drop, 11.0, 3.0, {}, configs, heavy);
    ASSERT_GT(r.pitch, 1.0) << configs.back() << ": the stop turns it over: the test checks something";
    const ClosedLoopRecord& rec = r.record;
    // The guard integrates the gyro's pitch rate; its estimate passes 0.4 rad within a sample or two
    // of the body's.
    double past = std::nan("");
    double largest = 0.0;
    for (std::size_t k = 0; k < rec.time.size(); ++k)
    {
      if (std::isnan(past) && std::abs(rec.pitch_true[k]) > 0.45)
      {
        past = rec.time[k];
      }
      if (!std::isnan(past) && rec.time[k] > past + 0.05)
      {
        largest = std::max(largest, std::abs(rec.command[k]));
      }
    }
    ASSERT_FALSE(std::isnan(past));
    EXPECT_EQ(largest, 0.0) << configs.back() << ": a command after the turnover at " << past << " s";
    EXPECT_LT(std::abs(rec.v_wheels.back()), 0.01) << configs.back() << ": the wheels stand still";
    EXPECT_LT(rec.up_true.back(), -0.9) << configs.back() << ": it lies on its back at the end";
  }
}

TEST(PayloadStop, PlantPayloadsDecelerationBoundKeepsItOnItsWheelsWithoutATrip)
{
  const StopResult r = stopWithThePayload({ "tip_guard=false", "max_reference_deceleration_linear=1.672" });
  EXPECT_LT(r.heading, 0.1);
  EXPECT_LT(r.pitch, 0.02) << "below the limit the rear wheels stay down";
}

TEST(PayloadStop, PlantPayloadsDecelerationBoundAlsoHoldsAStartInReverse)
{
  // Speeding up in reverse pitches the robot nose-down as braking forward does. The robot model
  // (config/default.yaml) starts from rest to -1.5 m/s at once: its path speeds up at the wheel
  // loop's 4.2 m/s^2, twice this payload's limit (2.09 m/s^2), and without the guard the robot
  // turns over its front wheels (1.54 rad). plant_payload's bound holds the path's deceleration
  // along x_dot in either direction of travel.
  const std::vector<SetPointSegment> reverse = { { 0.0, 0.0, 0.0 }, { 0.5, -1.5, 0.0 } };
  const std::vector<std::string> robot = { "config/default.yaml" };
  const StopResult r =
      runWithThePayload(reverse, 3.0, 0.0, { "tip_guard=false", "max_reference_deceleration_linear=1.672" }, robot);
  EXPECT_LT(r.heading, 0.1);
  EXPECT_LT(r.pitch, 0.02) << "below the limit the rear wheels stay down";
  EXPECT_LT(r.record.v_true.back(), -1.4) << "it reached the set point";
  const StopResult off = runWithThePayload(reverse, 3.0, 0.0, { "tip_guard=false" }, robot);
  EXPECT_GT(off.pitch, 1.0) << "without the bound this start tips it over: the test checks something";
}
TEST(PayloadStop, PlantPayloadsYawRateBoundKeepsAFrontHeavyRobotOnItsWheelsInATurnInPlace)
{
  // A turn in place at 4 rad/s, the node's default bound, turns front_heavy over its front wheels
  // with either controller (stock: 1.53 rad, `closed_loop_run --controller stock`); clamped to
  // plant_payload's 2.588 rad/s (0.8 of the limit's w^2 x) it stays on its wheels.
  const std::string heavy = "sim/config/variants/front_heavy.yaml";
  const std::vector<SetPointSegment> spin = { { 0.0, 0.0, 0.0 }, { 0.5, 0.0, 4.0 } };
  const std::vector<std::string> robot = { "config/default.yaml" };
  const StopResult r = runWithThePayload(spin, 3.0, 0.0, { "max_angular_speed=2.588" }, robot, heavy);
  EXPECT_LT(r.pitch, 0.02) << "below the limit the rear wheels stay down";
  EXPECT_GT(r.record.yaw_true.back(), 2.4) << "it turns at the bound";
  const StopResult off = runWithThePayload(spin, 3.0, 0.0, {}, robot, heavy);
  EXPECT_GT(off.pitch, 1.0) << "at 4 rad/s it turns over: the test checks something";
}
}  // namespace
}  // namespace harness
}  // namespace jackal_aic
