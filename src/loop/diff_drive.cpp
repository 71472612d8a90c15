/**
 * \file diff_drive.cpp
 * \brief diff_drive_controller's mapping, its inverse and its limits
 *        (include/jackal_aic/loop/diff_drive.hpp; doc/jackal.md, 'The stock velocity controller').
 */
#include "jackal_aic/loop/diff_drive.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace loop
{
namespace
{
double finiteOrZero(double x)
{
  return std::isfinite(x) ? x : 0.0;
}

/// SpeedLimiter::limit of one axis: velocity clamp, then the acceleration clamp over dt. A
/// target within both limits is returned unchanged (bit-exact: previous + (v - previous) may
/// differ from v in the last bit, which is no limit acting).
double limitAxis(double target, double previous, double max_vel, double max_acc, double dt)
{
  const double v = std::clamp(target, -max_vel, max_vel);
  const double dv_max = max_acc * dt;
  if (std::abs(v - previous) <= dv_max)
  {
    return v;
  }
  return previous + std::clamp(v - previous, -dv_max, dv_max);
}

params::DiffDriveParams validated(const params::DiffDriveParams& p)
{
  const auto e = p.validate();
  if (!e.empty())
  {
    std::string msg = "invalid diff-drive parameters:";
    for (const auto& s : e)
    {
      msg += " " + s + ";";
    }
    throw std::invalid_argument(msg);
  }
  return p;
}
}  // namespace

base::Vector2 wheelsFromTwist(const params::DiffDriveParams& p, const BodyTwist& twist)
{
  const double s = p.effectiveSeparation();
  return base::Vector2((twist.linear - twist.angular * s / 2.0) / p.wheel_radius,
                       (twist.linear + twist.angular * s / 2.0) / p.wheel_radius);
}

BodyTwist twistFromWheels(const params::DiffDriveParams& p, const base::Vector2& wheels)
{
  BodyTwist t;
  t.linear = p.wheel_radius * (wheels(0) + wheels(1)) / 2.0;
  t.angular = p.wheel_radius * (wheels(1) - wheels(0)) / p.effectiveSeparation();
  return t;
}

DiffDriveLimiter::DiffDriveLimiter(const params::DiffDriveParams& params) : params_(validated(params)) {}

BodyTwist DiffDriveLimiter::limit(const BodyTwist& target, double dt, bool* clipped)
{
  dt = std::isfinite(dt) ? std::max(0.0, dt) : 0.0;
  const BodyTwist want{ finiteOrZero(target.linear), finiteOrZero(target.angular) };
  BodyTwist out;
  out.linear = limitAxis(want.linear, last_.linear, params_.max_linear_velocity, params_.max_linear_acceleration, dt);
  out.angular =
      limitAxis(want.angular, last_.angular, params_.max_angular_velocity, params_.max_angular_acceleration, dt);
  if (clipped != nullptr)
  {
    // Rounding (a twist computed from wheel speeds at exactly a limit) is no limit acting.
    *clipped =
        std::abs(out.linear - want.linear) > kClipTolerance || std::abs(out.angular - want.angular) > kClipTolerance;
  }
  last_ = out;
  return out;
}

void DiffDriveLimiter::reset(const BodyTwist& previous)
{
  last_ = BodyTwist{ finiteOrZero(previous.linear), finiteOrZero(previous.angular) };
}

CmdVelOutput::CmdVelOutput(const params::DiffDriveParams& params) : limiter_(params) {}

CmdVelOutput::Result CmdVelOutput::convert(const base::Vector2& wheels, double dt)
{
  Result r;
  r.non_finite = !wheels.allFinite();
  const base::Vector2 w(finiteOrZero(wheels(0)), finiteOrZero(wheels(1)));
  const BodyTwist wanted = twistFromWheels(limiter_.params(), w);
  r.twist = limiter_.limit(wanted, dt, &r.clipped);
  // Unclipped: the command itself (bit-exact); clipped: what the stock controller will do.
  r.wheels = r.clipped ? wheelsFromTwist(limiter_.params(), r.twist) : w;
  if (r.clipped)
  {
    ++clips_;
  }
  return r;
}

void CmdVelOutput::reset(const base::Vector2& wheels)
{
  limiter_.reset(twistFromWheels(limiter_.params(), wheels));
}

}  // namespace loop
}  // namespace jackal_aic
