#pragma once
/**
 * \file node_outputs.hpp
 * \brief The jackal_AIC node's publishers with the final finiteness guard
 *        (doc/jackal_aic_node.md, 'Topics' and 'Safety'): no topic ever carries a
 *        non-finite number.
 */

#include <cstdint>
#include <string>

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/time.h>

#include "jackal_aic/controller.hpp"

namespace jackal_aic
{
/**
 * \brief The command (/cmd_drive, or jackal_velocity_controller/cmd_vel in output mode
 *        cmd_vel), ~belief, ~free_energy, ~eps_y, ~eps_mu.
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
   * \param output_mode  "cmd_drive" or "cmd_vel" (validated by NodeParams::validate())
   */
  NodeOutputs(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& output_mode = "cmd_drive");

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
   * \brief Compute the free energy of `controller` (0 before its first measurement; kept for
   *        diagnostics) and publish it, eps_y (5 x (p+1)) and eps_mu (3 x (p+1), rows =
   *        channels, cols = orders), each only for subscribers and only when finite.
   */
  void debug(const ActiveInferenceController& controller);

  /// Free energy F of the last debug() call.
  double lastFreeEnergy() const { return last_free_energy_; }
  /// Non-finite outputs suppressed so far.
  std::uint64_t guardedOutputs() const { return guarded_outputs_; }

private:
  bool cmd_vel_mode_ = false;
  ros::Publisher cmd_pub_, belief_pub_, free_energy_pub_, eps_y_pub_, eps_mu_pub_;
  double last_free_energy_ = 0.0;
  std::uint64_t guarded_outputs_ = 0;
};

}  // namespace jackal_aic
