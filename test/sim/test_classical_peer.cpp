/**
 * \file test_classical_peer.cpp
 * \brief The classical peer (config/classical/pi.yaml; include/jackal_aic/classical/pi_controller.hpp)
 *        in closed loop on the simulated Jackal with seeded sensor noise (deterministic): an arc
 *        step settles on both channels on the nominal plant and comes within a few per cent on the
 *        turn-deficit firmware (the yaw loop's integral makes up most of the missing turn; the
 *        tuned wheel integral is slow, 1 / ki ~ 10 s), with a bounded overshoot. The bounds are
 *        regression guards of the tuned gains' figures.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "jackal_aic/overrides/yaml_overrides.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_test/closed_loop_runs.hpp"
#include "jackal_tools/pi_params_yaml.hpp"

namespace jackal_aic
{
namespace harness
{
namespace
{
using namespace plant;
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;

ClosedLoopRecord arc(const std::vector<std::string>& overlays)
{
  ClosedLoopConfig c;
  c.controller = LoopController::kPi;
  c.pi = loadPiParams(kRoot + "/config/classical/pi.yaml");
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.0, 0.5, 0.5 } };
  c.duration = 6.0;
  c.ideal_sensors = false;
  return jackal_test::runOnJackal(kRoot, c, overlays);
}

TEST(ClassicalPeer, ArcSettlesOnTheNominalPlantAndTheTurnDeficitFirmware)
{
  const std::vector<std::string> deficit = { "sim/config/variants/turn_deficit.yaml" };
  for (const std::vector<std::string>& overlays : { std::vector<std::string>{}, deficit })
  {
    SCOPED_TRACE(overlays.empty() ? "nominal" : overlays[0]);
    const double tolerance = overlays.empty() ? 0.01 : 0.03;  // [m/s], [rad/s]
    const ClosedLoopRecord r = arc(overlays);
    EXPECT_NEAR(jackal_test::windowMean(r, r.v_true, 5.0, 6.0), 0.5, tolerance);
    EXPECT_NEAR(jackal_test::windowMean(r, r.yaw_true, 5.0, 6.0), 0.5, tolerance);
    EXPECT_LT(jackal_test::windowPeak(r, r.v_true, 1.0, 6.0), 0.5 * 1.1);    // overshoot below 10 %
    EXPECT_LT(jackal_test::windowPeak(r, r.yaw_true, 1.0, 6.0), 0.5 * 1.3);  // the turn's scrub transient, ground truth
  }
}
}  // namespace
}  // namespace harness
}  // namespace jackal_aic
