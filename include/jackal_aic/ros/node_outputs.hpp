#pragma once
/**
 * \file node_outputs.hpp
 * \brief The jackal_AIC node's publishers with the final finiteness guard
 *        (doc/jackal_aic_node.md, 'Topics' and 'Safety'): no topic ever carries a
 *        non-finite number.
 */

#include <atomic>
#include <cstdint>
#include <string>
#include <functional>

#include <memory>
#include <mutex>

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/time.h>
#include <ros/timer.h>

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/inference_sample.hpp"

namespace jackal_aic
{
namespace node
{
/**
 * \brief The controller's state for the debug topics, copied under the node's lock by the
 *        debug timer (debug_rate) so the publishing happens outside it. Fixed-size matrices:
 *        no allocation.
 */
struct DebugSnapshot
{
  ros::Time stamp;                 ///< time of the newest belief step the snapshot holds (~belief)
  ros::Time sample_stamp;          ///< stamp of the newest accepted sensor sample (~inference); 0 before the first
  bool has_measurement = false;    ///< the controller has accepted a measurement (else F is published as 0)
  aic::InferenceSample inference;  ///< F and its parts, mu, eps_y, eps_mu, the action, its prior, mu_r, Pi_y^(0), b_hat
  double gyro_offset = 0.0;        ///< the gyro offset beta_hat removed from the gyro [rad/s] (learn_gyro_bias)
};

/**
 * \brief The node's outputs: the wheel command (/cmd_drive, or in output mode cmd_vel the
 *        twist the stock diff drive maps back onto it), and ~belief, ~free_energy, ~eps_y,
 *        ~eps_mu, ~wheel_separation (the model's b_hat [m]), ~gyro_offset (the gyro offset beta_hat removed
 *        from the gyro [rad/s]) at debug_rate while anyone subscribes, and ~inference
 *        (jackal_aic/InferenceState: all of them and the rest of the inference in one stamped
 *        message) once per accepted sensor sample, at most at debug_rate, while anyone subscribes.
 *
 * Every suppressed non-finite output is counted (guardedOutputs(), shown in diagnostics).
 * Threading: wheels() and resetWheels() from the node's locked sections (either thread); the
 * debug timer runs on the spinner and takes the node's lock only to copy a DebugSnapshot.
 */
class NodeOutputs
{
public:
  /// Copies the controller's state into a snapshot under the node's lock; false if there is
  /// no new belief step since the last call (nothing to publish).
  using Capture = std::function<bool(DebugSnapshot*)>;

  /**
   * \param nh           public node handle: cmd_drive (jackal_msgs/Drive, queue 1) in output mode
   *                     cmd_drive, jackal_velocity_controller/cmd_vel (geometry_msgs/Twist, queue 1)
   *                     in output mode cmd_vel; only the one of the mode is advertised
   * \param pnh          private node handle: ~belief (geometry_msgs/TwistStamped, queue 50),
   *                     ~free_energy (std_msgs/Float64), ~eps_y, ~eps_mu (std_msgs/Float64MultiArray), queue 10,
   *                     ~inference (jackal_aic/InferenceState, queue 50)
   * \param output_mode  "cmd_drive" or "cmd_vel" (validated by NodeParams::validate())
   * \param debug_rate   [Hz] > 0: the debug topics' rate (startDebug())
   */
  NodeOutputs(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& output_mode = "cmd_drive",
              double debug_rate = 100.0);

  /**
   * \brief Publish the debug topics from `capture` at debug_rate, the timer running only while
   *        any of them has a subscriber (no wake-ups otherwise). Call once, after construction.
   */
  void startDebug(ros::NodeHandle& nh, Capture capture);
  /// True if any of ~belief, ~free_energy, ~eps_y, ~eps_mu, ~wheel_separation, ~gyro_offset, ~inference has a
  /// subscriber.
  bool debugWanted() const;
  /// True in output mode cmd_vel.
  bool cmdVelMode() const { return cmd_vel_mode_; }
  /// The command topic's resolved name (/cmd_drive, or jackal_velocity_controller/cmd_vel resolved).
  std::string commandTopic() const { return cmd_pub_.getTopic(); }

  /**
   * \brief Publish a command of the ControlLoop's command stage: output mode cmd_drive a
   *        jackal_msgs/Drive MODE_VELOCITY with command.wheels [rad/s], output mode cmd_vel a
   *        geometry_msgs/Twist with command.twist; a non-finite value (never expected after the
   *        command stage) becomes zero (counted, ERROR logged at most once a second).
   */
  void publish(const loop::WheelCommand& command);
  /**
   * \brief Publish mu^(0) = (linear.x, linear.y, angular.z) of `mu` (3 x (p+1)) in frame
   *        base_link with `stamp`; a non-finite belief is published as zero (counted).
   */
  void belief(const ros::Time& stamp, const base::MuTilde& mu);
  /**
   * \brief Fill `snapshot` from `controller` (call under the node's lock): its inference
   *        (inferenceSample(), jackal_aic/aic/inference_sample.hpp), whether it has a measurement,
   *        the gyro offset in use `gyro_offset` [rad/s] (GyroBiasEstimator::offset()), the belief
   *        time `stamp` and the newest accepted sensor sample's stamp `sample_stamp`.
   */
  void capture(const aic::ActiveInferenceController& controller, double gyro_offset, const ros::Time& stamp,
               const ros::Time& sample_stamp, DebugSnapshot* snapshot) const;
  /**
   * \brief Publish a snapshot: ~belief (as belief()), the free energy (0 before the first
   *        measurement), b_hat, the gyro offset and eps_y / eps_mu (rows = channels, cols =
   *        orders), each only for subscribers and only when finite; ~inference (inference()).
   */
  void debug(const DebugSnapshot& snapshot);
  /**
   * \brief Publish ~inference from `snapshot` if it has a subscriber, the controller has a
   *        measurement, its sample stamp is set and differs from the last one published (one
   *        message per sensor sample: the stamps increase, except after the clock moved back), and
   *        every value is finite (else counted in guardedOutputs()). Header: sample_stamp, frame
   *        base_link. \return true if published.
   */
  bool inference(const DebugSnapshot& snapshot);
  /// Non-finite outputs suppressed so far (any thread).
  std::uint64_t guardedOutputs() const { return guarded_outputs_.load(); }

private:
  void debugSubscribersChanged();

  bool cmd_vel_mode_ = false;
  ros::Publisher cmd_pub_, belief_pub_, free_energy_pub_, eps_y_pub_, eps_mu_pub_;
  ros::Publisher wheel_separation_pub_;  ///< ~wheel_separation (std_msgs/Float64): the model's b_hat [m]
  ros::Publisher gyro_offset_pub_;       ///< ~gyro_offset (std_msgs/Float64): the gyro offset beta_hat in use [rad/s]
  ros::Publisher inference_pub_;         ///< ~inference (jackal_aic/InferenceState): the whole inference, stamped
  ros::Time last_inference_stamp_;       ///< sample stamp of the last ~inference message (spinner thread only)
  std::atomic<std::uint64_t> guarded_outputs_{ 0 };  ///< commands may be guarded on the belief thread
  double debug_rate_;
  Capture capture_;
  ros::Timer debug_timer_;
  std::mutex debug_mutex_;  ///< the timer against subscriber callbacks starting / stopping it
  DebugSnapshot snapshot_;  ///< the debug timer's copy (spinner thread only)
};
}  // namespace node
}  // namespace jackal_aic
