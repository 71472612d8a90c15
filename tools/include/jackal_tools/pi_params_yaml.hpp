#pragma once
/**
 * \file pi_params_yaml.hpp
 * \brief The classical peer's settings (PiControllerParams,
 *        include/jackal_aic/classical/pi_controller.hpp) from a YAML file such as
 *        config/classical/pi.yaml. ROS-free; yaml-cpp only. Not the AIC's parameter schema: the
 *        peer is a tool's controller, not the node's.
 */

#include <string>
#include <vector>

#include "jackal_aic/classical/pi_controller.hpp"

namespace jackal_aic
{
/**
 * \brief PiControllerParams from a YAML map file with "key=value" overrides applied on top
 *        (dotted keys descend: "wheel.kp=0.4"), validated. Keys (every one optional; absent keys
 *        keep PiControllerParams' defaults): wheel {kp, ki}, yaw {kp, ki}, period, rest_linear,
 *        rest_angular, wheel_radius, wheel_separation, max_wheel_speed, goal_rate_hold,
 *        max_goal_rate_linear, max_goal_rate_angular, robot {latency, wheel_time_constant,
 *        wheel_acceleration, yaw_time_constant} (the AIC's robot.* keys of the same meaning).
 * \throws std::runtime_error naming the file on an unreadable file, a YAML error, a malformed
 *         override, an unknown key, a value that is not a number, or invalid parameters (every
 *         violation listed)
 */
classical::PiControllerParams loadPiParams(const std::string& file, const std::vector<std::string>& overrides = {});

}  // namespace jackal_aic
