#pragma once
/**
 * \file learned_model_overlay.hpp
 * \brief What the controller learned on the robot that a restart keeps, and the YAML overlay that
 *        makes it the model's the next time the node starts (the node's ~save_learned_model;
 *        doc/jackal_aic_node.md, 'Learned model'). ROS-free.
 */

#include <optional>
#include <string>

namespace jackal_aic
{
namespace aic
{
class ActiveInferenceController;

/// What was learned and is saved: each value present is written as its key, an absent one is not.
struct LearnedModel
{
  /// The learned wheel separation b_hat [m] (learn_wheel_separation; SeparationLearner); key
  /// `wheel_separation`.
  std::optional<double> wheel_separation;
  /// The robot model's learned latency L [s] (learn_latency with belief_model robot;
  /// LatencyLearner); key `latency`.
  std::optional<double> latency;
  /// The starts from rest L was learned from (LatencyLearner::starts()) [-], >= 1 with a latency;
  /// named in the latency's comment.
  int latency_starts = 0;
};

/**
 * \brief What `controller` learned that an overlay keeps: b_hat while learn_wheel_separation is on;
 *        L while learn_latency is on with belief_model robot and at least one start from rest was
 *        seen (before that the latency learner holds the configured L, nothing learned).
 * \return the values; both absent when nothing is learned. No errors.
 */
LearnedModel learnedModel(const ActiveInferenceController& controller);

/**
 * \brief The YAML overlay that makes what was learned the model's the next time the node starts:
 *        `wheel_separation: <b_hat>` and `latency: <L>`, each present value after a comment line
 *        naming how it was learned and one naming its unit, with 6 significant digits. Loaded
 *        after config/default.yaml, config/robot.yaml and the base's overlay (the launch files'
 *        learned_model argument), the keys land in the node's private namespace, where it reads
 *        them; with the learners on, the learning then starts from them.
 * \param learned  wheel_separation finite and > 0 [m] if present; latency finite, > 0 and <=
 *                 params::kMaxReferenceDelay [s] (what the node accepts for `latency`) if present,
 *                 then latency_starts >= 1; at least one of the two present
 * \return the text, wheel_separation first.
 * \throws std::invalid_argument naming every violated rule.
 */
std::string learnedModelOverlay(const LearnedModel& learned);

}  // namespace aic
}  // namespace jackal_aic
