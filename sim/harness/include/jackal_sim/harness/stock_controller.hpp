#pragma once
/**
 * \file stock_controller.hpp
 * \brief The Jackal's stock velocity controller: diff_drive_controller's open-loop
 *        twist -> wheel-speed mapping with the limits of jackal_control/config/control.yaml.
 *
 * ROS-free, so the calibration tool can run it against the plant faster than real time.
 * Per update (50 Hz on the robot): if the last command is older than cmd_vel_timeout the
 * target is zero; the target linear and angular speeds are clamped to the velocity limits
 * and rate limited by the acceleration limits (diff_drive_controller's SpeedLimiter,
 * jerk limits off); then
 *   omega_L = (v - w * s / 2) / r,   omega_R = (v + w * s / 2) / r,
 * with s = wheel_separation_multiplier * wheel_separation. No body-velocity feedback.
 * The mapping and the limits are the core's (include/jackal_aic/loop/diff_drive.hpp), shared with
 * the jackal_AIC node's cmd_vel output mode, which inverts them.
 */

#include <string>
#include <vector>

#include "jackal_aic/loop/diff_drive.hpp"

namespace jackal_aic
{
namespace harness
{
/// Parameters of the stock controller (defaults: the Jackal's control.yaml).
struct StockControllerParams : public jackal_aic::params::DiffDriveParams
{
  // Kinematics and limits: jackal_aic::params::DiffDriveParams (wheel_separation, wheel_separation_multiplier,
  // wheel_radius, max_linear_velocity, max_linear_acceleration, max_angular_velocity,
  // max_angular_acceleration), defaults from the Jackal's control.yaml.
  double cmd_vel_timeout = 0.25;  ///< command age after which the target is zero [s], > 0
  double publish_rate = 50.0;     ///< update / publication rate [Hz], > 0

  /// Every violation as "key = value (allowed range)"; empty when valid.
  std::vector<std::string> validate() const;
};

/// Wheel-speed command of the two sides [rad/s].
struct WheelSpeedCommand
{
  double left = 0.0;
  double right = 0.0;
};

/// diff_drive_controller's open-loop mapping (see file comment).
class StockController
{
public:
  /// \throws std::invalid_argument if params do not validate (message lists violations)
  explicit StockController(const StockControllerParams& params = StockControllerParams());

  /**
   * \brief Store a twist command received at time t.
   * \param linear  body forward speed [m/s]
   * \param angular yaw rate [rad/s]
   * \param t       receive time [s]
   * \return false (command ignored) if any value is non-finite
   */
  bool setCommand(double linear, double angular, double t);

  /**
   * \brief One controller update at time t [s] (call at publish_rate).
   * \return wheel speeds [rad/s], always finite and bounded by the velocity limits
   */
  WheelSpeedCommand update(double t);

  /**
   * \brief The caller's clock moved backwards (TimeJumpDetector): move the controller onto the
   *        new timeline at time t [s]: the command keeps its age at the last update, the next
   *        update() integrates one nominal period (its limiter's state is kept).
   */
  void restartTimeline(double t);

  /// Limited linear and angular speed of the last update [m/s], [rad/s].
  /// Linear velocity [m/s] of the last output twist, after the velocity and acceleration limits.
  double lastLinear() const { return limiter_.last().linear; }
  /// Angular velocity [rad/s] of the last output twist, after the velocity and acceleration limits.
  double lastAngular() const { return limiter_.last().angular; }
  /// True if the last update found the command older than cmd_vel_timeout.
  bool timedOut() const { return timed_out_; }
  /// The parameters in force (validated at construction).
  const StockControllerParams& params() const { return params_; }

private:
  StockControllerParams params_;
  jackal_aic::loop::DiffDriveLimiter limiter_;
  double cmd_linear_ = 0.0;
  double cmd_angular_ = 0.0;
  double cmd_time_ = -1e9;
  bool have_update_ = false;
  double last_update_ = 0.0;
  bool timed_out_ = true;
};

}  // namespace harness
}  // namespace jackal_aic
