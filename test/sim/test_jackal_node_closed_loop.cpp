/**
 * \file test_jackal_node_closed_loop.cpp
 * \brief The closed loop on jackal_node's re-sampled joint states (ClosedLoopConfig::jackal_node),
 *        headless and deterministic (simulated time, ideal sensors, the re-sampler's fixed seed):
 *        the phenomenon through one period of the phase (repeats, ages, the stock odometry's step)
 *        and the AIC against its clean-sample figures (regression guards of today's figures:
 *        `jackal_node_sweep` prints them all).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_tools/params_yaml.hpp"

namespace jackal_aic
{
namespace harness
{
namespace
{
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;
constexpr double kRest = 1.0;         // [s] before the step
constexpr double kHold = 5.0;         // [s] of the step
constexpr double kPeriod = 0.02;      // the MCU's and the loop's period [s]
constexpr int kPhases = 20;           // through one period, 1 ms apart
constexpr double kRatioBound = 1.05;  // the AIC's figure on re-sampled data over its clean one [-]

double settling(const ClosedLoopRecord& r, const std::vector<double>& y, double target, double* overshoot = nullptr)
{
  StepMetricsOptions o;
  o.step_time = kRest;
  o.initial = 0.0;
  o.target = target;
  const StepMetrics m = computeStepMetrics(r.time, y, o);
  if (overshoot != nullptr)
  {
    *overshoot = m.overshoot_percent;
  }
  return m.settling_time;
}

class JackalNodeClosedLoop : public ::testing::Test
{
protected:
  void SetUp() override
  {
    description_ = plant::loadRobotDescription(kRoot + "/sim/urdf/jackal.urdf");
    params_ = plant::loadPlantParams(kRoot + "/sim/config/plant.yaml");
  }
  ClosedLoopConfig step(LoopController controller, double v) const
  {
    ClosedLoopConfig c;
    c.controller = controller;
    if (controller == LoopController::kAic)
    {
      c.node = loadNodeParamsFiles({ kRoot + "/config/default.yaml" });
      c.aic = c.node.aic;
    }
    c.profile = stepProfile(kRest, v);
    c.duration = kRest + kHold;
    return c;
  }
  static void resample(ClosedLoopConfig* c, int phase)
  {
    c->jackal_node = true;
    c->jackal_node_sampler.phase = phase * kPeriod / kPhases;
  }
  plant::RobotDescription description_;
  plant::PlantParams params_;
};
}  // namespace

// Through one period of the phase: repeats from none to more than the robot's 15 %, ages within one
// MCU period, and diff_drive_controller's odometry of a stock 0.5 m/s step overshooting by 5-20 %
// where samples repeat (each repeat takes a tenth off the rolling mean, its double step adds it).
TEST_F(JackalNodeClosedLoop, PhaseSweepReproducesTheRobotsJointStatesAndOdometry)
{
  const ClosedLoopRecord clean = runClosedLoop(description_, params_, step(LoopController::kStock, 0.5));
  double clean_overshoot = 0.0;
  settling(clean, clean.v_diff_drive, 0.5, &clean_overshoot);
  EXPECT_LT(clean_overshoot, 5.0);
  double lowest = 1.0, highest = 0.0, worst_overshoot = 0.0;
  for (int p = 0; p < kPhases; ++p)
  {
    ClosedLoopConfig c = step(LoopController::kStock, 0.5);
    resample(&c, p);
    const ClosedLoopRecord r = runClosedLoop(description_, params_, c);
    const auto& s = r.jackal_node_stats;
    lowest = std::min(lowest, s.repeatRate());
    highest = std::max(highest, s.repeatRate());
    EXPECT_GE(s.min_age, 0.0);
    EXPECT_LE(s.max_age, kPeriod + 1e-9);
    double overshoot = 0.0;
    settling(r, r.v_diff_drive, 0.5, &overshoot);
    worst_overshoot = std::max(worst_overshoot, overshoot);
  }
  EXPECT_LT(lowest, 0.005);
  EXPECT_GE(highest, 0.15);
  EXPECT_GE(worst_overshoot, 5.0);
  EXPECT_LE(worst_overshoot, 20.0);
}

// Regression guard of today's figure: the AIC's 0.5 m/s step settles (ground truth) within 5 % of
// its clean-sample time at every phase, with no runaway, no fault-monitor event, no dropped input and
// no joint state paired without an IMU.
TEST_F(JackalNodeClosedLoop, AicStepOverThePhaseSweepWithinFivePercentOfClean)
{
  const ClosedLoopRecord clean = runClosedLoop(description_, params_, step(LoopController::kAic, 0.5));
  const double t_clean = settling(clean, clean.v_true, 0.5);
  ASSERT_GT(t_clean, 0.0);
  for (int p = 0; p < kPhases; p += 2)
  {
    ClosedLoopConfig c = step(LoopController::kAic, 0.5);
    resample(&c, p + 1);  // the odd phases: 1, 3, ..., 19 ms (19 ms repeats the most)
    const ClosedLoopRecord r = runClosedLoop(description_, params_, c);
    EXPECT_LE(settling(r, r.v_true, 0.5), kRatioBound * t_clean) << "phase " << p + 1 << " ms";
    EXPECT_EQ(r.runaways, 0u);
    EXPECT_TRUE(r.health_events.empty()) << "phase " << p + 1 << " ms";
    EXPECT_TRUE(r.drops.empty()) << "phase " << p + 1 << " ms: " << (r.drops.empty() ? "" : r.drops.front().first);
    EXPECT_TRUE(r.imu_missing.empty()) << "phase " << p + 1 << " ms";
  }
}

}  // namespace harness
}  // namespace jackal_aic
