#pragma once
/**
 * \file diff_drive.hpp
 * \brief The Jackal's stock velocity controller, ros_controllers' diff_drive_controller
 *        with jackal_control/config/control.yaml, as ROS-free functions: its twist -> wheel
 *        speed mapping, the exact inverse of that mapping, and its velocity and acceleration
 *        limits (diff_drive_controller's SpeedLimiter, jerk limits off). doc/jackal.md,
 *        'The stock velocity controller'.
 *
 * Forward (diff_drive_controller's update):
 *   omega_L = (v - w s / 2) / r,   omega_R = (v + w s / 2) / r,   s = multiplier * separation.
 * Inverse (this package's cmd_vel output mode, so the stock controller reproduces a wheel
 * command exactly):
 *   v = r (omega_L + omega_R) / 2,   w = r (omega_R - omega_L) / s.
 * The simulated stock controller (sim/harness/include/jackal_sim/harness/stock_controller.hpp) and the
 * jackal_AIC node's cmd_vel output (CmdVelOutput) both use these functions.
 */

#include <cstdint>
#include <string>
#include <vector>

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/diff_drive_params.hpp"

namespace jackal_aic
{
namespace loop
{
/// A limit changed a twist component by more than this [m/s or rad/s]: DiffDriveLimiter's
/// `clipped` (smaller changes are rounding of a twist computed at exactly a limit).
constexpr double kClipTolerance = 1e-9;

/// A body twist as diff_drive_controller sees it: linear.x [m/s], angular.z [rad/s].
struct BodyTwist
{
  double linear = 0.0;   ///< forward speed v [m/s]
  double angular = 0.0;  ///< yaw rate w [rad/s]
};

/**
 * \brief diff_drive_controller's mapping of a twist to wheel speeds (see file comment).
 * \return (omega_L, omega_R) [rad/s]; no limits applied
 */
base::Vector2 wheelsFromTwist(const params::DiffDriveParams& p, const BodyTwist& twist);

/**
 * \brief The exact inverse of wheelsFromTwist(): the twist for which the stock controller
 *        commands `wheels` (see file comment).
 * \param wheels  (omega_L, omega_R) [rad/s]
 */
BodyTwist twistFromWheels(const params::DiffDriveParams& p, const base::Vector2& wheels);

/**
 * \brief diff_drive_controller's SpeedLimiter on both axes (velocity, then acceleration
 *        against the previous output; jerk limits off, as in the Jackal's control.yaml).
 */
class DiffDriveLimiter
{
public:
  /// \throws std::invalid_argument if params do not validate (the message lists every violation)
  explicit DiffDriveLimiter(const params::DiffDriveParams& params = params::DiffDriveParams());

  /**
   * \brief Limit a target twist.
   * \param target   wanted twist; a non-finite component is taken as 0
   * \param dt       time since the previous output [s]; non-finite or < 0 is taken as 0
   * \param clipped  optional: set true if a limit changed the target by more than kClipTolerance
   * \return the limited twist, which becomes the previous output
   */
  BodyTwist limit(const BodyTwist& target, double dt, bool* clipped = nullptr);
  /// Set the previous output (e.g. the measured twist when control (re)starts); non-finite -> 0.
  void reset(const BodyTwist& previous);
  /// The previous output.
  const BodyTwist& last() const { return last_; }
  /// The parameters in force.
  const params::DiffDriveParams& params() const { return params_; }

private:
  params::DiffDriveParams params_;
  BodyTwist last_;
};

/**
 * \brief The jackal_AIC node's cmd_vel output mode, ROS-free: a wheel command becomes the
 *        twist the stock controller turns back into that command; when the stock
 *        controller's limits would change it, the clipped command is what the robot gets,
 *        and the node feeds it back to the controller as its action (anti-windup).
 */
class CmdVelOutput
{
public:
  /// One converted command.
  struct Result
  {
    BodyTwist twist;          ///< to publish on jackal_velocity_controller/cmd_vel
    base::Vector2 wheels;     ///< what the stock controller will command, wheelsFromTwist(twist) [rad/s]
    bool clipped = false;     ///< a velocity or acceleration limit changed the command
    bool non_finite = false;  ///< the input had a NaN/Inf (replaced by 0)
  };

  /// \throws std::invalid_argument if params do not validate
  explicit CmdVelOutput(const params::DiffDriveParams& params = params::DiffDriveParams());

  /**
   * \brief Convert a wheel command: twistFromWheels(), then the limits against the previous
   *        output over dt.
   * \param wheels  (omega_L, omega_R) [rad/s]; a non-finite element is taken as 0
   * \param dt      time since the previous command [s], >= 0
   */
  Result convert(const base::Vector2& wheels, double dt);
  /// Restart the acceleration limit from a wheel state [rad/s] (control (re)starts).
  void reset(const base::Vector2& wheels);
  /// Commands changed by a limit since construction.
  std::uint64_t clips() const { return clips_; }
  /// The limiter (parameters, previous output).
  const DiffDriveLimiter& limiter() const { return limiter_; }

private:
  DiffDriveLimiter limiter_;
  std::uint64_t clips_ = 0;
};

}  // namespace loop
}  // namespace jackal_aic
