/**
 * \file pi_controller.cpp
 * \brief The classical peer: PI loops on the wheel speeds and the yaw rate around the robot
 *        model's feed-forward through the latency (doc/active_inference.md, 'A classical peer').
 */
#include "jackal_aic/classical/pi_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "jackal_aic/aic/latency_action.hpp"

namespace jackal_aic
{
namespace classical
{
namespace
{
std::string violation(const std::string& key, double value, const std::string& allowed)
{
  std::ostringstream os;
  os << key << " = " << value << " (" << allowed << ")";
  return os.str();
}

bool positive(double x)
{
  return std::isfinite(x) && x > 0.0;
}

bool nonNegative(double x)
{
  return std::isfinite(x) && x >= 0.0;
}

/// The goal's rate estimator and the goal predicted one latency ahead, without a reference path.
params::ReferenceModelParams goalParams(const PiControllerParams& p)
{
  params::ReferenceModelParams r;
  r.generalized_goal = true;
  r.goal_rate_hold = p.goal_rate_hold;
  r.max_goal_rate_linear = p.max_goal_rate_linear;
  r.max_goal_rate_angular = p.max_goal_rate_angular;
  r.goal_lead = p.robot.latency;
  r.goal_lead_angular = p.robot.latency;
  r.time_constant = 0.0;  // no reference path: the predicted goal alone
  return r;
}

const PiControllerParams& validated(const PiControllerParams& p)
{
  const std::vector<std::string> v = p.validate();
  if (!v.empty())
  {
    std::string msg = "PiControllerParams invalid:";
    for (const std::string& s : v)
    {
      msg += " " + s + ";";
    }
    throw std::invalid_argument(msg);
  }
  return p;
}
}  // namespace

std::vector<std::string> PiControllerParams::validate() const
{
  std::vector<std::string> out;
  if (!(nonNegative(robot.latency) && robot.latency <= 1.0))
  {
    out.push_back(violation("latency", robot.latency, "[0, 1] s"));
  }
  if (!nonNegative(robot.wheel_time_constant))
  {
    out.push_back(violation("wheel_time_constant", robot.wheel_time_constant, ">= 0 s"));
  }
  if (!positive(robot.yaw_time_constant))
  {
    out.push_back(violation("yaw_time_constant", robot.yaw_time_constant, "> 0 s"));
  }
  if (!positive(robot.wheel_acceleration))
  {
    out.push_back(violation("wheel_acceleration", robot.wheel_acceleration, "> 0 rad/s^2"));
  }
  const std::pair<const char*, double> positives[] = { { "wheel_radius", wheel_radius },
                                                       { "wheel_separation", wheel_separation },
                                                       { "max_wheel_speed", max_wheel_speed },
                                                       { "max_goal_rate_linear", max_goal_rate_linear },
                                                       { "max_goal_rate_angular", max_goal_rate_angular },
                                                       { "rest_linear", rest_linear },
                                                       { "rest_angular", rest_angular } };
  for (const auto& kv : positives)
  {
    if (!positive(kv.second))
    {
      out.push_back(violation(kv.first, kv.second, "> 0, finite"));
    }
  }
  if (!nonNegative(goal_rate_hold))
  {
    out.push_back(violation("goal_rate_hold", goal_rate_hold, ">= 0 s"));
  }
  if (!(positive(period) && period <= 1.0))
  {
    out.push_back(violation("period", period, "(0, 1] s"));
  }
  const std::pair<const char*, double> gains[] = {
    { "wheel.kp", wheel.kp }, { "wheel.ki", wheel.ki }, { "yaw.kp", yaw.kp }, { "yaw.ki", yaw.ki }
  };
  for (const auto& kv : gains)
  {
    if (!nonNegative(kv.second))
    {
      out.push_back(violation(kv.first, kv.second, ">= 0, finite"));
    }
  }
  return out;
}

const char* toString(PiStatus status)
{
  switch (status)
  {
    case PiStatus::kOk:
      return "ok";
    case PiStatus::kNotFinite:
      return "not_finite";
    case PiStatus::kNonPositiveStep:
      return "non_positive_step";
    case PiStatus::kGoalOutOfOrder:
      return "goal_out_of_order";
    case PiStatus::kRestarted:
      return "restarted";
  }
  return "unknown";
}

PiController::PiController(const PiControllerParams& params)
  : params_(validated(params))
  , model_(params.wheel_radius, 1.0, params.wheel_separation)
  , goal_rate_(goalParams(params))
  , goal_(goalParams(params), std::numeric_limits<double>::max())
  , ff_loop_(params.robot)
  , ref_loop_(params.robot)
{
  goal_.setWheelSeparation(params.wheel_separation);
  reset();
}

void PiController::reset()
{
  goal_rate_.reset();
  goal_.setGoal(base::Vector3::Zero());
  ff_loop_.reset(0.0, base::Vector2::Zero());
  ref_loop_.reset(0.0, base::Vector2::Zero());
  started_ = false;
  last_t_ = 0.0;
  goal_now_.setZero();
  w_ff_.setZero();
  w_ref_.setZero();
  yaw_expected_ = 0.0;
  u_ff_.setZero();
  wheel_integral_.setZero();
  yaw_integral_ = 0.0;
  last_ = PiCommand();
}

PiStatus PiController::setGoal(double t, double linear, double angular)
{
  if (!(std::isfinite(t) && std::isfinite(linear) && std::isfinite(angular)))
  {
    return PiStatus::kNotFinite;
  }
  if (!goal_rate_.update(t, base::Vector3(linear, 0.0, angular)))
  {
    return PiStatus::kGoalOutOfOrder;
  }
  goal_now_ = base::Vector2(linear, angular);
  return PiStatus::kOk;
}

PiCommand PiController::update(double t, const base::Vector2& wheels, double gyro_z)
{
  if (!(std::isfinite(t) && wheels.allFinite() && std::isfinite(gyro_z)))
  {
    PiCommand held = last_;
    held.status = PiStatus::kNotFinite;
    return held;
  }
  if (started_ && !(t > last_t_))
  {
    PiCommand held = last_;
    held.status = PiStatus::kNonPositiveStep;
    return held;
  }
  const double h = params_.period;
  double dt = h;
  // A gap longer than the longest step restarts the expected responses as the first update starts
  // them: the commands in flight are long done, and the models would simulate the gap in 1 ms steps.
  const bool restart = started_ && t - last_t_ > params::kMaxStep;
  if (!started_ || restart)
  {
    // The models start from the wheels as measured with no command in flight: what was sent
    // before the first update is unknown, the wheels' speeds are not.
    ff_loop_.reset(t, base::Vector2::Zero());
    ref_loop_.reset(t, base::Vector2::Zero());
    w_ff_ = wheels;
    w_ref_ = wheels;
    yaw_expected_ = model_.twistFromWheels(wheels)(2);
    started_ = true;
  }
  else
  {
    dt = t - last_t_;
    w_ff_ = ff_loop_.predict(w_ff_, base::Vector2::Zero(), last_t_, t);
    w_ref_ = ref_loop_.predict(w_ref_, base::Vector2::Zero(), last_t_, t);
    // The body's yaw rate follows the wheels' through the scrub lag T_s (the robot model's).
    const double T_s = params_.robot.yaw_time_constant;
    yaw_expected_ += (model_.twistFromWheels(w_ff_)(2) - yaw_expected_) * (1.0 - std::exp(-dt / T_s));
  }
  last_t_ = t;

  // Feed-forward: the goal one latency ahead, to the wheels, through the wheel loop's inverse.
  const base::Vector3 rate = goal_rate_.rate(t);
  goal_.setGoal(base::Vector3(goal_now_(0), 0.0, goal_now_(1)), rate);
  const base::Vector3 target = goal_.target();
  const base::Vector2 g_wheels = model_.wheelsFromTwist(target);
  const double max_speed = params_.max_wheel_speed;
  const aic::LatencyActionResult inverse =
      aic::LatencyAction::step(ff_loop_, w_ff_, base::Vector2::Zero(), t, g_wheels, u_ff_, h, 1.0 / h, max_speed, 1.0);
  u_ff_ = inverse.command;

  // Outer loop: the yaw rate against the feed-forward's expected yaw rate.
  const bool at_rest = std::abs(goal_now_(0)) < params_.rest_linear && std::abs(goal_now_(1)) < params_.rest_angular &&
                       std::abs(target(0)) < params_.rest_linear && std::abs(target(2)) < params_.rest_angular;
  double trim = 0.0;
  double yaw_error = 0.0;
  if (at_rest)
  {
    yaw_integral_ = 0.0;
  }
  else
  {
    yaw_error = yaw_expected_ - gyro_z;
    trim = params_.yaw.kp * yaw_error + yaw_integral_;
  }
  const base::Vector2 trim_wheels = model_.wheelsFromTwist(base::Vector3(0.0, 0.0, trim));

  // Inner loops: each wheel against its expected speed under the feed-forward and the trim.
  const base::Vector2 wheel_error = w_ref_ - wheels;
  const base::Vector2 unclamped = u_ff_ + trim_wheels + params_.wheel.kp * wheel_error + wheel_integral_;
  PiCommand out;
  out.status = restart ? PiStatus::kRestarted : PiStatus::kOk;
  for (int s = 0; s < 2; ++s)
  {
    out.wheels(s) = std::clamp(unclamped(s), -max_speed, max_speed);
    const bool clamped = out.wheels(s) != unclamped(s);
    out.saturated = out.saturated || clamped;
    // Conditional integration: a clamped side integrates only an error that pulls it back.
    const bool pushes_further = clamped && (unclamped(s) > 0.0) == (wheel_error(s) > 0.0);
    if (!pushes_further)
    {
      wheel_integral_(s) += params_.wheel.ki * wheel_error(s) * dt;
    }
  }
  if (!at_rest && !out.saturated)
  {
    yaw_integral_ += params_.yaw.ki * yaw_error * dt;
  }
  // The expected responses: u_ff alone, and u_ff with the trim (clamped as the command is).
  ff_loop_.record(t, u_ff_);
  const base::Vector2 reference = (u_ff_ + trim_wheels).cwiseMax(-max_speed).cwiseMin(max_speed);
  ref_loop_.record(t, reference);
  out.feed_forward = u_ff_;
  out.expected = w_ref_;
  out.yaw_trim = trim;
  last_ = out;
  return out;
}

}  // namespace classical
}  // namespace jackal_aic
