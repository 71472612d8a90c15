#include "jackal_sim/plant/wheel_speed_servo.hpp"

#include <algorithm>
#include <cmath>

namespace jackal_aic
{
namespace plant
{
WheelSpeedServo::WheelSpeedServo(const MotorParams& params, double step) : params_(params), step_(step) {}

void WheelSpeedServo::reset()
{
  pending_.clear();
  enabled_ = false;
  setpoint_ = 0.0;
  ramped_setpoint_ = 0.0;
  filtered_setpoint_ = 0.0;
  integral_ = 0.0;
  torque_ = 0.0;
  torque_limited_ = false;
  last_command_time_ = 0.0;
  setpoint_rate_ = 0.0;
  feedforward_ = 0.0;
  observer_torque_ = 0.0;
  observer_speed_ = 0.0;
  load_estimate_ = 0.0;
}

void WheelSpeedServo::setSetpoint(double setpoint, double t)
{
  if (!std::isfinite(setpoint))
  {
    return;
  }
  const double s = std::clamp(setpoint, -params_.max_wheel_speed, params_.max_wheel_speed);
  pending_.push_back({ t + params_.command_delay, true, s });
}

void WheelSpeedServo::release(double t)
{
  pending_.push_back({ t + params_.command_delay, false, 0.0 });
}

std::pair<double, double> WheelSpeedServo::torqueLimits(double w) const
{
  double lo = -params_.max_torque;
  double hi = params_.max_torque;
  if (params_.stall_torque > 0.0)
  {
    const double ts = params_.stall_torque;
    const double w0 = params_.no_load_speed;
    hi = std::min(hi, ts * (1.0 - w / w0));
    lo = std::max(lo, -ts * (1.0 + w / w0));
  }
  return { lo, hi };
}

double WheelSpeedServo::update(double measured_speed, double t)
{
  // Commands whose transport delay has elapsed take effect in order.
  while (!pending_.empty() && pending_.front().time <= t + 1e-12)
  {
    const Command c = pending_.front();
    pending_.pop_front();
    if (c.enabled && !enabled_)
    {
      // Engaging from released: start the loop from the current state.
      filtered_setpoint_ = measured_speed;
      ramped_setpoint_ = measured_speed;
      integral_ = 0.0;
      observer_torque_ = 0.0;
      observer_speed_ = measured_speed;
      load_estimate_ = 0.0;
    }
    // Set-point rate for the feedforward: difference of consecutive commands over their interval
    // (a first command after release, or a release, has none).
    if (c.enabled && enabled_)
    {
      const double interval = std::max(c.time - last_command_time_, step_);
      setpoint_rate_ = (c.setpoint - setpoint_) / interval;
    }
    else
    {
      setpoint_rate_ = 0.0;
    }
    last_command_time_ = c.time;
    enabled_ = c.enabled;
    setpoint_ = c.setpoint;
  }
  if (!enabled_)
  {
    feedforward_ = 0.0;
    integral_ = 0.0;
    observer_torque_ = 0.0;
    observer_speed_ = measured_speed;
    load_estimate_ = 0.0;
    filtered_setpoint_ = measured_speed;
    ramped_setpoint_ = measured_speed;
    torque_ = 0.0;
    torque_limited_ = false;
    return 0.0;
  }
  if (params_.setpoint_slew_rate > 0.0)
  {
    const double max_change = params_.setpoint_slew_rate * step_;
    ramped_setpoint_ += std::clamp(setpoint_ - ramped_setpoint_, -max_change, max_change);
  }
  else
  {
    ramped_setpoint_ = setpoint_;
  }
  if (params_.setpoint_time_constant > 0.0)
  {
    filtered_setpoint_ +=
        (ramped_setpoint_ - filtered_setpoint_) * (1.0 - std::exp(-step_ / params_.setpoint_time_constant));
  }
  else
  {
    filtered_setpoint_ = ramped_setpoint_;
  }
  if (params_.load_observer_time_constant > 0.0)
  {
    // Disturbance observer: L_hat = Q[T] - J_n Q[s w], Q a first-order low-pass (header).
    const double a = 1.0 - std::exp(-step_ / params_.load_observer_time_constant);
    observer_torque_ += a * (torque_ - observer_torque_);
    observer_speed_ += a * (measured_speed - observer_speed_);
    const double acceleration = (measured_speed - observer_speed_) * a / ((1.0 - a) * step_);
    load_estimate_ = std::clamp(observer_torque_ - params_.load_observer_inertia * acceleration, -params_.max_torque,
                                params_.max_torque);
  }
  const double error = filtered_setpoint_ - measured_speed;
  const auto [lo, hi] = torqueLimits(measured_speed);
  double acceleration_feedforward = params_.accel_feedforward * setpoint_rate_;
  if (params_.accel_feedforward_limit > 0.0)
  {
    acceleration_feedforward =
        std::clamp(acceleration_feedforward, -params_.accel_feedforward_limit, params_.accel_feedforward_limit);
  }
  feedforward_ = acceleration_feedforward + params_.setpoint_feedforward * error;
  double proportional = params_.speed_kp * error;
  if (params_.proportional_limit > 0.0)
  {
    proportional = std::clamp(proportional, -params_.proportional_limit, params_.proportional_limit);
  }
  const double integrated_error = params_.integral_error_limit > 0.0 ?
                                      std::clamp(error, -params_.integral_error_limit, params_.integral_error_limit) :
                                      error;
  const double unsat =
      proportional + integral_ + params_.speed_ki * integrated_error * step_ + feedforward_ + load_estimate_;
  const double out = std::clamp(unsat, std::min(lo, hi), std::max(lo, hi));
  // Conditional integration: hold the integrator while saturated in the error's direction.
  const bool saturated_up = unsat > out && error > 0.0;
  const bool saturated_down = unsat < out && error < 0.0;
  if (!saturated_up && !saturated_down)
  {
    integral_ += params_.speed_ki * integrated_error * step_;
    const double limit = params_.integral_limit > 0.0 ? params_.integral_limit : params_.max_torque;
    integral_ = std::clamp(integral_, -limit, limit);
  }
  torque_ = std::isfinite(out) ? out : 0.0;
  torque_limited_ = unsat != out;
  return torque_;
}

}  // namespace plant
}  // namespace jackal_aic
