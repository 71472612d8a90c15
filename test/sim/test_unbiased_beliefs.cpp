/**
 * \file test_unbiased_beliefs.cpp
 * \brief Closed-loop checks of belief_model unbiased and learn_wheel_separation on the simulated
 *        Jackal (doc/active_inference.md, 'Unbiased beliefs', 'Learning the generative model'):
 *        the beliefs are the robot's state where the plant follows and where it cannot, and arcs
 *        are tracked once b_hat is learned. config/default.yaml with the unbiased settings below,
 *        seeded sensor noise: deterministic.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/yaml_overrides.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_aic
{
namespace harness
{
namespace
{
using namespace plant;
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;

/// The unbiased configuration: the motion prior a first-order lag of 0.1 s with a low precision,
/// fast beliefs (exact integrator), and a gentler action integral than the goal model's.
NodeParams unbiasedNode(bool learn, const std::vector<std::string>& more = {})
{
  std::vector<std::string> overrides = { "belief_model=unbiased", "tau=0.1", "k_mu=5", "var_mu=[1000,1000,1000]",
                                         "k_a=2", std::string("learn_wheel_separation=") + (learn ? "true" : "false") };
  overrides.insert(overrides.end(), more.begin(), more.end());
  return loadNodeParamsFiles({ kRoot + "/config/default.yaml" }, overrides);
}

ClosedLoopRecord run(const NodeParams& node, double linear, double angular, double duration,
                     const std::vector<std::string>& overlays = {})
{
  ClosedLoopConfig c;
  c.controller = LoopController::kAic;
  c.node = node;
  c.aic = node.aic;
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.0, linear, angular } };
  c.duration = duration;
  c.ideal_sensors = false;
  std::vector<std::string> overrides;
  for (const std::string& o : overlays)
  {
    const std::vector<std::string> extra = loadOverlayFile(kRoot + "/" + o);
    overrides.insert(overrides.end(), extra.begin(), extra.end());
  }
  return runClosedLoop(loadRobotDescription(kRoot + "/sim/urdf/jackal.urdf"),
                       loadPlantParams(kRoot + "/sim/config/plant.yaml", overrides), c);
}

/// Mean of v over samples with time in [t0, t1].
double mean(const ClosedLoopRecord& r, const std::vector<double>& v, double t0, double t1)
{
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      sum += v[k];
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

/// Mean |a - b| over samples with time in [t0, t1].
double meanAbsDiff(const ClosedLoopRecord& r, const std::vector<double>& a, const std::vector<double>& b, double t0,
                   double t1)
{
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      sum += std::abs(a[k] - b[k]);
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}
}  // namespace

TEST(UnbiasedBeliefs, ArcTrackedAndBelievedOnceTheSeparationIsLearned)
{
  // 0.5 m/s + 0.5 rad/s: the plant's effective separation is ~1.4 x track; learning from the track.
  const ClosedLoopRecord r = run(unbiasedNode(true), 0.5, 0.5, 21.0);
  EXPECT_EQ(r.runaways, 0u);
  EXPECT_NEAR(mean(r, r.yaw_true, 16.0, 21.0), 0.5, 0.015 * 0.5);
  EXPECT_LE(meanAbsDiff(r, r.belief_yaw, r.yaw_true, 16.0, 21.0), 0.01);
  EXPECT_LE(meanAbsDiff(r, r.belief, r.v_true, 16.0, 21.0), 0.01);
}

TEST(UnbiasedBeliefs, BeliefHonestWhenTheWheelsSaturate)
{
  // 2.0 m/s: the wheels saturate at max_wheel_speed below it; the belief reads the speed reached.
  const ClosedLoopRecord s = run(unbiasedNode(false), 2.0, 0.0, 11.0);
  EXPECT_LT(mean(s, s.v_true, 6.0, 11.0), 1.99);  // the plant does not follow (the case exists)
  EXPECT_LE(meanAbsDiff(s, s.belief, s.v_true, 6.0, 11.0), 0.01);
}

}  // namespace harness
}  // namespace jackal_aic
