#pragma once
/**
 * \file learned_model.hpp
 * \brief The jackal_AIC node's services over what its controller learned on the robot
 *        (learn_wheel_separation; doc/active_inference.md, 'Learning the generative model';
 *        doc/jackal_aic_node.md, 'Learned model'):
 *
 *   ~save_learned_model  (std_srvs/Trigger) writes the learned wheel separation b_hat as a YAML
 *                        overlay (learnedSeparationOverlay()) to ~learned_model_file, atomically
 *                        (a temporary file renamed over the old one); the launch files load it
 *                        next time with learned_model:=FILE, and the learning starts from it;
 *   ~reset_learned_model (std_srvs/Trigger) forgets what was learned: b_hat back to the
 *                        wheel_separation the node started with.
 *
 * Both answer success false, with the reason, while learn_wheel_separation is off; a file that
 * cannot be written is an error in the answer and the log, never a crash.
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
   * \param loop   the node's control loop (its controller's separation learner)
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
   * \brief Write the overlay (the service's body). \param[out] message what was written where, or
   *        why not. \return true if the file was written
   */
  bool save(std::string* message);
  /// Forget what was learned (the service's body). \param[out] message the b_hat now in use. \return false if learning is off
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
