#include "jackal_sim/stock_controller.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace sim
{
namespace
{
void check(std::vector<std::string>* e, double v, const std::string& key, const std::string& range)
{
  if (!(v > 0.0) || !std::isfinite(v))
  {
    std::ostringstream s;
    s << key << " = " << v << " (allowed: " << range << ")";
    e->push_back(s.str());
  }
}
}  // namespace

std::vector<std::string> StockControllerParams::validate() const
{
  std::vector<std::string> e;
  check(&e, wheel_separation, "wheel_separation", "> 0 m");
  check(&e, wheel_separation_multiplier, "wheel_separation_multiplier", "> 0");
  check(&e, wheel_radius, "wheel_radius", "> 0 m");
  check(&e, max_linear_velocity, "max_linear_velocity", "> 0 m/s");
  check(&e, max_linear_acceleration, "max_linear_acceleration", "> 0 m/s^2");
  check(&e, max_angular_velocity, "max_angular_velocity", "> 0 rad/s");
  check(&e, max_angular_acceleration, "max_angular_acceleration", "> 0 rad/s^2");
  check(&e, cmd_vel_timeout, "cmd_vel_timeout", "> 0 s");
  check(&e, publish_rate, "publish_rate", "> 0 Hz");
  return e;
}

StockController::StockController(const StockControllerParams& params) : params_(params)
{
  const auto e = params_.validate();
  if (!e.empty())
  {
    std::string msg = "invalid stock controller parameters:";
    for (const auto& s : e)
    {
      msg += " " + s + ";";
    }
    throw std::invalid_argument(msg);
  }
}

bool StockController::setCommand(double linear, double angular, double t)
{
  if (!std::isfinite(linear) || !std::isfinite(angular) || !std::isfinite(t))
  {
    return false;
  }
  cmd_linear_ = linear;
  cmd_angular_ = angular;
  cmd_time_ = t;
  return true;
}

double StockController::limit(double target, double previous, double max_vel, double max_acc, double dt)
{
  const double v = std::clamp(target, -max_vel, max_vel);
  const double dv = std::clamp(v - previous, -max_acc * dt, max_acc * dt);
  return previous + dv;
}

WheelSpeedCommand StockController::update(double t)
{
  // First update: one nominal period.
  const double dt = have_update_ ? std::max(0.0, t - last_update_) : 1.0 / params_.publish_rate;
  have_update_ = true;
  last_update_ = t;
  timed_out_ = (t - cmd_time_) > params_.cmd_vel_timeout;
  const double target_lin = timed_out_ ? 0.0 : cmd_linear_;
  const double target_ang = timed_out_ ? 0.0 : cmd_angular_;
  last0_linear_ =
      limit(target_lin, last0_linear_, params_.max_linear_velocity, params_.max_linear_acceleration, dt);
  last0_angular_ =
      limit(target_ang, last0_angular_, params_.max_angular_velocity, params_.max_angular_acceleration, dt);
  const double s = params_.wheel_separation_multiplier * params_.wheel_separation;
  WheelSpeedCommand c;
  c.left = (last0_linear_ - last0_angular_ * s / 2.0) / params_.wheel_radius;
  c.right = (last0_linear_ + last0_angular_ * s / 2.0) / params_.wheel_radius;
  return c;
}

}  // namespace sim
}  // namespace jackal_aic
