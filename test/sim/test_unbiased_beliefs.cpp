/**
 * \file test_unbiased_beliefs.cpp
 * \brief Closed-loop checks of belief_model unbiased and learn_wheel_separation on the simulated
 *        Jackal (doc/active_inference.md, 'Unbiased beliefs', 'Learning the generative model'):
 *        the beliefs are the robot's state where the plant follows and where it cannot, and arcs
 *        are tracked once b_hat is learned; the learned b_hat converges from once and twice the
 *        track with fault isolation on. config/default.yaml (with the unbiased settings below where
 *        named, or config/unbiased.yaml), seeded sensor noise: deterministic.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
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
using jackal_test::windowMean;
using jackal_test::windowMeanAbsDiff;

/// The unbiased configuration: the motion prior a first-order lag of 0.1 s with a low precision,
/// fast beliefs (exact integrator), and a gentler action integral than the goal model's.
params::NodeParams unbiasedNode(bool learn, const std::vector<std::string>& more = {})
{
  std::vector<std::string> overrides = {
    "belief_model=unbiased",   "tau=0.1", "k_mu=5",
    "var_mu=[1000,1000,1000]", "k_a=2",   std::string("learn_wheel_separation=") + (learn ? "true" : "false")
  };
  overrides.insert(overrides.end(), more.begin(), more.end());
  return loadNodeParamsFiles({ kRoot + "/config/default.yaml" }, overrides);
}

ClosedLoopRecord run(const params::NodeParams& node, double linear, double angular, double duration,
                     const std::vector<std::string>& overlays = {})
{
  ClosedLoopConfig c;
  c.controller = LoopController::kAic;
  c.node = node;
  c.aic = node.aic;
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.0, linear, angular } };
  c.duration = duration;
  c.ideal_sensors = false;
  return jackal_test::runOnJackal(kRoot, c, overlays);
}
}  // namespace

TEST(UnbiasedBeliefs, ArcTrackedAndBelievedOnceTheSeparationIsLearned)
{
  // 0.5 m/s + 0.5 rad/s: the plant's effective separation is ~1.4 x track; learning from the track.
  const ClosedLoopRecord r = run(unbiasedNode(true), 0.5, 0.5, 21.0);
  EXPECT_EQ(r.runaways, 0u);
  EXPECT_NEAR(windowMean(r, r.yaw_true, 16.0, 21.0), 0.5, 0.015 * 0.5);
  EXPECT_LE(windowMeanAbsDiff(r, r.belief_yaw, r.yaw_true, 16.0, 21.0), 0.01);
  EXPECT_LE(windowMeanAbsDiff(r, r.belief, r.v_true, 16.0, 21.0), 0.01);
}

TEST(LearnedSeparation, ConvergesFromOnceAndTwiceTheTrackWithFaultIsolationOn)
{
  // The goal model (config/goal_model.yaml over config/default.yaml: learning and fault isolation
  // on; the robot model's: RobotModel.SeparationLearnedFromOnceAndTwiceTheTrack), 0.5 m/s + 0.5 rad/s from t = 1 s, b_hat
  // started at the track (0.3756 m) and at twice it. The plant's effective separation is measured
  // on the ground truth: the configured b_hat times the true wheels' yaw rate over the true yaw
  // rate, over the steady arc. b_hat must be within 5 % of it 10 s into the arc and stay there (to
  // 20 s); both starts must end within 1 % of each other.
  constexpr double kTrack = 0.37559;  // sim/urdf/jackal.urdf
  double ends[2] = { 0.0, 0.0 };
  for (int i = 0; i < 2; ++i)
  {
    const double start = (i + 1) * kTrack;
    SCOPED_TRACE("b_hat from " + std::to_string(start) + " m");
    const params::NodeParams node = loadNodeParamsFiles({ kRoot + "/config/default.yaml", kRoot + "/config/"
                                                                                                  "goal_model.yaml" },
                                                        { "wheel_separation=" + std::to_string(start) });
    ASSERT_TRUE(node.aic.separation_learner.enabled);
    ASSERT_TRUE(node.fdi.enabled);
    const ClosedLoopRecord r = run(node, 0.5, 0.5, 21.0);
    EXPECT_EQ(r.runaways, 0u);
    const double b_eff = start * windowMean(r, r.yaw_wheels, 6.0, 21.0) / windowMean(r, r.yaw_true, 6.0, 21.0);
    EXPECT_GT(b_eff, 1.2 * kTrack) << "no effective separation to learn";
    double worst = 0.0;
    for (std::size_t k = 0; k < r.time.size(); ++k)
    {
      if (r.time[k] >= 11.0)
      {
        worst = std::max(worst, std::abs(r.separation[k] - b_eff) / b_eff);
      }
    }
    std::printf("b_hat from %.4f m: effective %.4f m, b_hat at 21 s %.4f m, worst deviation from 11 s %.2f %%\n", start,
                b_eff, r.separation.back(), 100.0 * worst);
    EXPECT_LE(worst, 0.05);
    ends[i] = r.separation.back();
  }
  EXPECT_NEAR(ends[1], ends[0], 0.01 * ends[0]);
}

TEST(UnbiasedBeliefs, BeliefHonestWhenTheWheelsSaturate)
{
  // 2.0 m/s: the wheels saturate at max_wheel_speed below it; the belief reads the speed reached.
  const ClosedLoopRecord s = run(unbiasedNode(false), 2.0, 0.0, 11.0);
  EXPECT_LT(windowMean(s, s.v_true, 6.0, 11.0), 1.99);  // the plant does not follow (the case exists)
  EXPECT_LE(windowMeanAbsDiff(s, s.belief, s.v_true, 6.0, 11.0), 0.01);
}

TEST(UnbiasedConfig, TracksAndBelievesOnArcsDeficitsAndSaturation)
{
  // config/unbiased.yaml over config/default.yaml, as a robot loads it: the arc's steady yaw
  // rate within 1.5 % of the command and the belief within 0.01 where the plant follows; a turn
  // in place on the turn-deficit firmware held within 2 % after 3 s and believed; at 2.0 m/s,
  // which the wheels cannot reach, the belief is the speed reached (doc/experiments.md, 'Driving
  // acceptance', honest belief: 0.03 where the plant cannot follow).
  const params::NodeParams node = loadNodeParamsFiles({ kRoot + "/config/default.yaml", kRoot + "/config/"
                                                                                                "unbiased.yaml" });
  ASSERT_EQ(node.aic.belief_model, params::BeliefModel::kUnbiased);
  const ClosedLoopRecord arc = run(node, 0.5, 0.5, 13.0);
  EXPECT_EQ(arc.runaways, 0u);
  EXPECT_NEAR(windowMean(arc, arc.yaw_true, 9.0, 13.0), 0.5, 0.015 * 0.5);
  EXPECT_LE(windowMeanAbsDiff(arc, arc.belief_yaw, arc.yaw_true, 9.0, 13.0), 0.01);
  EXPECT_LE(windowMeanAbsDiff(arc, arc.belief, arc.v_true, 9.0, 13.0), 0.01);
  const ClosedLoopRecord deficit = run(node, 0.0, 0.5, 4.0, { "sim/config/variants/turn_deficit.yaml" });
  EXPECT_NEAR(windowMean(deficit, deficit.yaw_true, 3.0, 4.0), 0.5, 0.02 * 0.5);
  EXPECT_LE(windowMeanAbsDiff(deficit, deficit.belief_yaw, deficit.yaw_true, 3.0, 4.0), 0.01);
  const ClosedLoopRecord fast = run(node, 2.0, 0.0, 11.0);
  EXPECT_LT(windowMean(fast, fast.v_true, 6.0, 11.0), 1.99);  // the plant does not follow (the case exists)
  EXPECT_LE(windowMeanAbsDiff(fast, fast.belief, fast.v_true, 6.0, 11.0), 0.03);
}

}  // namespace harness
}  // namespace jackal_aic
