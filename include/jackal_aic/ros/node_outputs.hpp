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

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/time.h>

#include "jackal_aic/controller.hpp"

namespace jackal_aic
{
/**
 * \brief The controller's state for the debug topics, copied under the node's lock by the
 *        debug timer (debug_rate) so the publishing happens outside it. Fixed-size matrices:
 *        no allocation.
 */
struct DebugSnapshot
{
  ros::Time stamp;           ///< time of the newest belief step the snapshot holds
  MuTilde mu;                ///< beliefs, 3 x (p+1)
  double free_energy = 0.0;  ///< F (thesis eq. 3-12); 0 before the first measurement
  YTilde eps_y;              ///< eps_y, 5 x (p+1); 0 columns when nobody subscribes
  MuTilde eps_mu;            ///< eps_mu, 3 x (p+1); 0 columns when nobody subscribes
};

/**
 * \brief /cmd_drive, ~belief, ~free_energy, ~eps_y, ~eps_mu.
 *
 * Every suppressed non-finite output is counted (guardedOutputs(), shown in diagnostics).
 */
class NodeOutputs
{
public:
  /**
   * \param nh           public node handle: cmd_drive (jackal_msgs/Drive, queue 1) in output mode
   *                     cmd_drive, jackal_velocity_controller/cmd_vel (geometry_msgs/Twist, queue 1)
   *                     in output mode cmd_vel; only the one of the mode is advertised
   * \param pnh          private node handle: ~belief (geometry_msgs/TwistStamped, queue 50),
   *                     ~free_energy (std_msgs/Float64), ~eps_y, ~eps_mu (std_msgs/Float64MultiArray), queue 10
   * \param debug_subscribers_changed  called (on the spinner thread) whenever a debug topic
   *                     gains or loses a subscriber, so the node runs its debug timer only when
   *                     someone listens; may be empty
   * \param output_mode  "cmd_drive" or "cmd_vel" (validated by NodeParams::validate())
   */
  NodeOutputs(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::function<void()> debug_subscribers_changed = {},
              const std::string& output_mode = "cmd_drive");

  /// True if any of ~belief, ~free_energy, ~eps_y, ~eps_mu has a subscriber.
  bool debugWanted() const;

  /// True in output mode cmd_vel.
  bool cmdVelMode() const { return cmd_vel_mode_; }

  /**
   * \brief Output mode cmd_vel: publish a twist (linear.x [m/s], angular.z [rad/s]); a
   *        non-finite value becomes zero (counted, ERROR logged at most once a second).
   */
  void twist(double linear, double angular);

  /**
   * \brief Publish a MODE_VELOCITY wheel command [rad/s], each wheel clamped to +-limit; a
   *        non-finite command becomes zero (counted, ERROR logged at most once a second).
   */
  void command(double omega_left, double omega_right, double limit);

  /**
   * \brief Publish mu^(0) = (linear.x, linear.y, angular.z) of `mu` (3 x (p+1)) in frame
   *        base_link with `stamp`; a non-finite belief is published as zero (counted).
   */
  void belief(const ros::Time& stamp, const MuTilde& mu);

  /**
   * \brief Fill `snapshot` from `controller` (call under the node's lock): mu, the free
   *        energy (0 before the first measurement), and eps_y / eps_mu only when someone
   *        subscribes to them (else 0 columns).
   */
  void capture(const ActiveInferenceController& controller, const ros::Time& stamp, DebugSnapshot* snapshot) const;

  /**
   * \brief Publish a snapshot: ~belief (as belief()), the free energy and eps_y / eps_mu
   *        (rows = channels, cols = orders), each only for subscribers and only when finite.
   */
  void debug(const DebugSnapshot& snapshot);
  /// Non-finite outputs suppressed so far (any thread).
  std::uint64_t guardedOutputs() const { return guarded_outputs_.load(); }

private:
  bool cmd_vel_mode_ = false;
  ros::Publisher cmd_pub_, belief_pub_, free_energy_pub_, eps_y_pub_, eps_mu_pub_;
  std::atomic<std::uint64_t> guarded_outputs_{ 0 };  ///< commands may be guarded on the belief thread
};

}  // namespace jackal_aic
