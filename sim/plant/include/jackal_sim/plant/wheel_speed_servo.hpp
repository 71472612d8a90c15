#pragma once
/**
 * \file wheel_speed_servo.hpp
 * \brief The Jackal MCU's wheel-speed loop for one side (one motor per side).
 *
 * ROS-free. A PI speed servo on the side's measured wheel speed, whose torque is limited
 * by the motor current limit (max_torque) and, optionally, by the supply voltage: a DC
 * motor's torque at speed w can lie only between -T_s (1 + w / w_0) and T_s (1 - w / w_0)
 * (stall torque T_s, no-load speed w_0). An optional first-order lag on the set point and a
 * transport delay model the command path. Anti-windup: the integrator does not grow while
 * the output is saturated in the direction of the error; the integrator is clamped to
 * +-integral_limit. Acceleration feedforward: the rate of change of the received set point,
 * estimated from consecutive commands (difference over their interval, held until the next
 * command), times accel_feedforward, is added to the PI torque before the limits.
 * Set-point path: transport delay, then slew-rate limit (ramp), then first-order lag, each
 * optional. Torque = clamp(sat(Kp e) + I + K_v e + J_ff * rate, limits) with e = filtered set
 * point - measured speed, sat() the optional proportional_limit, K_v the voltage (set-point)
 * feedforward's back-EMF gain (setpoint_feedforward).
 *
 * Load-torque observer (optional, load_observer_time_constant > 0): a disturbance observer
 * (K. Ohnishi, "Motion control for advanced mechatronics", IEEE/ASME Trans. Mechatronics 1(1),
 * 1996). With Q(s) = 1 / (tau_L s + 1) and the nominal side inertia J_n,
 *     L_hat = Q[T] - J_n Q[s w] = T_f - J_n (w - w_f) / tau_L     (w_f = Q[w], T_f = Q[T])
 * is the torque the side needs beyond J_n dw/dt (scrub, friction, slope); it is clamped to
 * +-max_torque and added to the torque above before the limits. A side then accelerates under
 * the PI torque as J_n would, whatever the load: a turn's scrub torque is delivered within a few
 * tau_L. Discrete form (step h, a = 1 - exp(-h / tau_L)): T_f += a (T_prev - T_f),
 * w_f += a (w - w_f), dw/dt ~ (w - w_f) a / ((1 - a) h), exact for a constant acceleration.
 */

#include <deque>
#include <utility>

#include "jackal_sim/plant/plant_params.hpp"

namespace jackal_aic
{
namespace plant
{
/// PI wheel-speed servo with torque and voltage limits (one side).
class WheelSpeedServo
{
public:
  /// \param params motor parameters (validated by the caller)
  /// \param step   update period [s], > 0
  WheelSpeedServo(const MotorParams& params, double step);

  /// Command a wheel speed [rad/s] (clamped to +-max_wheel_speed) at time t [s].
  void setSetpoint(double setpoint, double t);
  /// Release the motor at time t [s] (MODE_NONE): zero torque, integrator cleared.
  void release(double t);

  /**
   * \brief One servo update.
   * \param measured_speed side wheel speed [rad/s]
   * \param t              current time [s] (for the command delay)
   * \return drive torque of the side at the wheels [N m], within the limits; 0 when released
   */
  double update(double measured_speed, double t);

  /// Torque limits [N m] (min, max) available at wheel speed w [rad/s].
  std::pair<double, double> torqueLimits(double w) const;

  /// Set point in effect after delay and lag [rad/s].
  double effectiveSetpoint() const { return filtered_setpoint_; }
  /// True when the motor is driven (a velocity command is in effect).
  bool enabled() const { return enabled_; }
  /// Last torque output [N m].
  double torque() const { return torque_; }
  /// True when the last torque output was clamped to the motor's limits (current limit
  /// max_torque, or the voltage limit at the measured speed: torqueLimits()); false when released.
  bool torqueLimited() const { return torque_limited_; }
  /// Acceleration feedforward part of the last torque, before the limits [N m].
  double feedforward() const { return feedforward_; }
  /// Load-torque observer's estimate in the last torque, clamped to +-max_torque [N m]; 0 without observer.
  double loadEstimate() const { return load_estimate_; }
  /// Clear all state (released, zero set point, empty delay line).
  void reset();

private:
  struct Command
  {
    double time;
    bool enabled;
    double setpoint;
  };

  MotorParams params_;
  double step_;
  std::deque<Command> pending_;  ///< commands waiting out the transport delay
  bool enabled_ = false;
  double setpoint_ = 0.0;
  double ramped_setpoint_ = 0.0;
  double filtered_setpoint_ = 0.0;
  double integral_ = 0.0;           ///< integrator state [N m]
  double last_command_time_ = 0.0;  ///< when the last received set point took effect [s]
  double setpoint_rate_ = 0.0;      ///< rate of change of the received set point [rad/s^2], held
  double feedforward_ = 0.0;        ///< last feedforward torque [N m]
  double observer_torque_ = 0.0;    ///< observer: low-pass filtered applied torque T_f [N m]
  double observer_speed_ = 0.0;     ///< observer: low-pass filtered side speed w_f [rad/s]
  double load_estimate_ = 0.0;      ///< observer: load-torque estimate L_hat [N m]
  double torque_ = 0.0;
  bool torque_limited_ = false;  ///< the last output was clamped to torqueLimits()
};

}  // namespace plant
}  // namespace jackal_aic
