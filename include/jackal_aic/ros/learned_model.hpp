#pragma once
/**
 * \file learned_model.hpp
 * \brief The jackal_AIC node's services over what its controller learned on the robot
 *        (learn_wheel_separation, and learn_latency with belief_model robot;
 *        doc/active_inference.md, 'Learning the generative model', 'Learning the latency';
 *        doc/jackal_aic_node.md, 'Learned model'):
 *
 *   ~save_learned_model  (std_srvs/Trigger) writes what was learned (aic::learnedModel()): the
 *                        wheel separation b_hat [m] while learn_wheel_separation is on, the robot
 *                        model's latency L [s] while learn_latency is on and a start from rest was
 *                        seen, as a YAML overlay (aic::learnedModelOverlay()) to
 *                        ~learned_model_file, atomically (a temporary file renamed over the old
 *                        one); the launch files load it next time with learned_model:=FILE, and the
 *                        model and the learning start from it;
 *   ~reset_learned_model (std_srvs/Trigger) forgets what was learned: b_hat back to the
 *                        configured wheel_separation and L to the configured latency (a
 *                        loaded overlay's values).
 *
 * Both answer success false, with the reason, while both learners are off; save also when the
 * only learner on is learn_latency and no start was seen yet (with b_hat saved, the answer names
 * the latency as not written). A file that cannot be written, or a learned value the overlay
 * refuses (aic::learnedModelOverlay()'s rules), is an error in the answer and the log, never a crash.
 */

#include <mutex>
#include <string>

#include <ros/ros.h>

namespace jackal_aic
{
namespace loop
{
class ControlLoop;
}

namespace node
{

/// ~save_learned_model and ~reset_learned_model over the node's ControlLoop (guarded by the node's lock).
class LearnedModelService
{
public:
  /**
   * \param pnh    the node's private handle (the services)
   * \param mutex  the node's lock, held while the controller is read or changed
   * \param loop   the node's control loop (its controller's separation and latency learners)
   * \param file   the overlay's path; empty = defaultFile()
   */
  LearnedModelService(ros::NodeHandle& pnh, std::mutex& mutex, loop::ControlLoop& loop, const std::string& file);
  LearnedModelService(const LearnedModelService&) = delete;
  LearnedModelService& operator=(const LearnedModelService&) = delete;

  /// $ROS_HOME/jackal_aic/learned_model.yaml ($HOME/.ros when ROS_HOME is unset, as roslaunch's logs).
  static std::string defaultFile();
  /// The overlay's path in use.
  const std::string& file() const { return file_; }

  /**
   * \brief Write the overlay (the service's body).
   * \param[out] message what was written where (b_hat [m], L [s] and its starts), what was not
   *             learned yet, or why nothing was written
   * \return true if the file was written; false (no exception) if both learners are off, nothing
   *         is learned yet, or the file or its folder cannot be written
   */
  bool save(std::string* message);
  /**
   * \brief Forget what was learned (the service's body; loop::ControlLoop::resetLearning()).
   * \param[out] message what was forgotten and the b_hat [m] and L [s] now in use
   * \return false (nothing changed) if learn_wheel_separation and learn_latency (with
   *         belief_model robot) are both off
   */
  bool reset(std::string* message);

private:
  std::mutex& mutex_;
  loop::ControlLoop& loop_;
  std::string file_;
  ros::ServiceServer save_server_;
  ros::ServiceServer reset_server_;
};

}  // namespace node
}  // namespace jackal_aic
