/**
 * \file learned_model_overlay.cpp
 * \brief What the controller learned, as the YAML overlay ~save_learned_model writes
 *        (include/jackal_aic/aic/learned_model_overlay.hpp; doc/jackal_aic_node.md, 'Learned model').
 */
#include "jackal_aic/aic/learned_model_overlay.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/base/rule_list.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace aic
{
namespace
{
/// `v` with 6 significant digits (%g).
std::string format(double v)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}
}  // namespace

LearnedModel learnedModel(const ActiveInferenceController& controller)
{
  const params::AicParams& p = controller.params();
  LearnedModel learned;
  if (p.separation_learner.enabled)
  {
    learned.wheel_separation = controller.separationLearner().separation();
  }
  const LatencyLearner& latency = controller.latencyLearner();
  if (params::learnsLatency(p) && latency.starts() > 0)
  {
    learned.latency = latency.latency();
    learned.latency_starts = latency.starts();
  }
  return learned;
}

std::string learnedModelOverlay(const LearnedModel& learned)
{
  base::RuleList rules;
  rules.require(learned.wheel_separation || learned.latency, "something learned (wheel_separation or latency)");
  if (learned.wheel_separation)
  {
    const double b = *learned.wheel_separation;
    rules.require(std::isfinite(b) && b > 0.0, "wheel_separation = " + format(b) + " m finite and > 0");
  }
  if (learned.latency)
  {
    const double l = *learned.latency;
    rules.require(std::isfinite(l) && l > 0.0 && l <= params::kMaxReferenceDelay,
                  "latency = " + format(l) + " s finite, > 0 and <= " + format(params::kMaxReferenceDelay) + " s");
    rules.require(learned.latency_starts >= 1,
                  "latency_starts = " + std::to_string(learned.latency_starts) + " >= 1 with a latency");
  }
  if (!rules.ok())
  {
    throw std::invalid_argument("learnedModelOverlay:" + rules.violations());
  }
  std::string text = "# What jackal_AIC learned on the robot (~save_learned_model; doc/jackal_aic_node.md, 'Learned\n"
                     "# model'). Load it as an overlay after config/robot.yaml (learned_model:=FILE).\n";
  if (learned.wheel_separation)
  {
    text += "# The wheel separation learned from the gyro-encoder disagreement (learn_wheel_separation;\n"
            "# doc/active_inference.md, 'Learning the generative model').\n"
            "# [m] Wheel separation b_hat of the skid-steer model (thesis eq. 3-1 to 3-4).\n"
            "wheel_separation: " +
            format(*learned.wheel_separation) + "\n";
  }
  if (learned.latency)
  {
    text += "# The robot model's latency learned from the wheels' first motion after rest, the running\n"
            "# mean of " +
            std::to_string(learned.latency_starts) + (learned.latency_starts == 1 ? " start" : " starts") +
            " (learn_latency; doc/active_inference.md, 'Learning the latency').\n"
            "# [s] Robot model: L, /cmd_drive to the wheels' response.\n"
            "latency: " +
            format(*learned.latency) + "\n";
  }
  return text;
}

}  // namespace aic
}  // namespace jackal_aic
