#pragma once
/**
 * \file command_guard.hpp
 * \brief The last line before a wheel command leaves the controller (ControlLoop's command
 *        stage, then /cmd_drive or the cmd_vel conversion): whatever the stages above did, the
 *        motors get finite wheel speeds within the wheel-speed limit.
 */

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace safety
{
/// What guardWheelCommand() lets through, and what it changed.
struct GuardedWheels
{
  base::Vector2 wheels = base::Vector2::Zero();  ///< (omega_L, omega_R) [rad/s]: finite, each within +-limit
  bool replaced = false;                         ///< the command (or the limit) was not finite: zero was sent instead
  bool clamped = false;                          ///< a finite wheel speed beyond +-limit was clamped to it
};

/**
 * \brief Guard one wheel command: a command with any non-finite element becomes zero on both
 *        wheels (stopping is the one safe reading of a broken number); a finite one is clamped
 *        element-wise to [-limit, +limit].
 * \param wheels  (omega_L, omega_R) [rad/s], any values
 * \param limit   the wheel-speed limit [rad/s] (`max_wheel_speed`); a limit that is not finite
 *                and positive gives zero (replaced), never an unbounded command
 * \return the guarded command; no allocation, no exceptions (called on the action path)
 */
GuardedWheels guardWheelCommand(const base::Vector2& wheels, double limit) noexcept;

}  // namespace safety
}  // namespace jackal_aic
