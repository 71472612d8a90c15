#pragma once
/**
 * \file diff_drive_params.hpp
 * \brief Kinematics and limits of the Jackal's stock diff_drive_controller (ros_controllers;
 *        defaults: jackal_control/config/control.yaml), the parameters of DiffDriveLimiter and
 *        CmdVelOutput (include/jackal_aic/loop/diff_drive.hpp). ROS-free.
 */

#include <string>
#include <vector>

namespace jackal_aic
{
namespace params
{
/// diff_drive_controller's kinematics and limits; defaults: the Jackal's control.yaml.
struct DiffDriveParams
{
  double wheel_radius = 0.098;               ///< r [m], > 0
  double wheel_separation = 0.37559;         ///< wheel joint separation (track) [m], > 0
  double wheel_separation_multiplier = 1.5;  ///< absorbs the skid-steer slip [-], > 0
  double max_linear_velocity = 2.0;          ///< |v| limit [m/s], > 0
  double max_linear_acceleration = 20.0;     ///< |dv/dt| limit [m/s^2], > 0
  double max_angular_velocity = 4.0;         ///< |w| limit [rad/s], > 0
  double max_angular_acceleration = 25.0;    ///< |dw/dt| limit [rad/s^2], > 0

  /// Effective separation s = wheel_separation_multiplier * wheel_separation [m].
  double effectiveSeparation() const { return wheel_separation_multiplier * wheel_separation; }
  /// Every violation as "key = value (allowed: > 0, finite)"; empty when valid.
  std::vector<std::string> validate() const;
};
}  // namespace params
}  // namespace jackal_aic
