#include "jackal_sim/harness/stock_controller.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace harness
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
  std::vector<std::string> e = jackal_aic::params::DiffDriveParams::validate();
  check(&e, cmd_vel_timeout, "cmd_vel_timeout", "> 0 s");
  check(&e, publish_rate, "publish_rate", "> 0 Hz");
  return e;
}

namespace
{
const StockControllerParams& validated(const StockControllerParams& params)
{
  const auto e = params.validate();
  if (!e.empty())
  {
    std::string msg = "invalid stock controller parameters:";
    for (const auto& s : e)
    {
      msg += " " + s + ";";
    }
    throw std::invalid_argument(msg);
  }
  return params;
}
}  // namespace

StockController::StockController(const StockControllerParams& params)
  : params_(validated(params)), limiter_(static_cast<const jackal_aic::params::DiffDriveParams&>(params))
{
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

void StockController::restartTimeline(double t)
{
  if (!std::isfinite(t))
  {
    return;
  }
  if (have_update_)
  {
    cmd_time_ = t - (last_update_ - cmd_time_);
  }
  have_update_ = false;
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
  const jackal_aic::loop::BodyTwist out = limiter_.limit({ target_lin, target_ang }, dt);
  const jackal_aic::base::Vector2 wheels = jackal_aic::loop::wheelsFromTwist(params_, out);
  WheelSpeedCommand c;
  c.left = wheels(0);
  c.right = wheels(1);
  return c;
}

}  // namespace harness
}  // namespace jackal_aic
