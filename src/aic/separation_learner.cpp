/**
 * \file separation_learner.cpp
 * \brief Free-energy descent of the effective wheel separation b_hat (include/jackal_aic/aic/separation_learner.hpp;
 *        doc/active_inference.md, 'Learning the generative model').
 */
#include "jackal_aic/aic/separation_learner.hpp"

#include "jackal_aic/base/rule_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace aic
{
namespace
{
bool finite(double v)
{
  return std::isfinite(v);
}

std::string check(const params::SeparationLearnerParams& p, double wheel_radius, double slip_factor, double initial)
{
  base::RuleList rules;
  rules.require(finite(wheel_radius) && wheel_radius > 0.0, "wheel_radius finite and > 0");
  rules.require(finite(slip_factor) && slip_factor > 0.0, "slip_factor finite and > 0");
  rules.require(finite(p.min) && p.min > 0.0, "separation_min finite and > 0");
  rules.require(finite(p.max) && p.max >= p.min, "separation_max finite and >= separation_min");
  rules.require(finite(initial) && initial >= p.min && initial <= p.max, "initial separation within [min, max]");
  rules.require(finite(p.rate) && p.rate >= 0.0, "separation_learning_rate finite and >= 0");
  rules.require(finite(p.min_yaw_rate) && p.min_yaw_rate >= 0.0, "separation_min_yaw_rate finite and >= 0");
  rules.require(finite(p.max_yaw_acceleration) && p.max_yaw_acceleration > 0.0, "separation_max_yaw_acceleration "
                                                                                "finite and > 0");
  rules.require(finite(p.max_rate) && p.max_rate >= 0.0, "separation_max_rate finite and >= 0");
  return rules.violations();
}
}  // namespace

SeparationLearner::SeparationLearner(const params::SeparationLearnerParams& params, double wheel_radius,
                                     double slip_factor, double initial)
  : params_(params), wheel_radius_(wheel_radius), slip_factor_(slip_factor), initial_(initial), b_(initial)
{
  const std::string violations = check(params, wheel_radius, slip_factor, initial);
  if (!violations.empty())
  {
    throw std::invalid_argument("invalid SeparationLearnerParams:" + violations);
  }
}

SeparationLearner::State SeparationLearner::update(double h, double gyro_z, double gyro_rate, double omega_l,
                                                   double omega_r, double omega_l_rate, double omega_r_rate,
                                                   double precision, bool sensors_ok, bool saturated)
{
  if (!(finite(h) && h > 0.0) || !finite(gyro_z) || !finite(gyro_rate) || !finite(omega_l) || !finite(omega_r) ||
      !finite(omega_l_rate) || !finite(omega_r_rate) || !(finite(precision) && precision >= 0.0))
  {
    state_ = State::kBadInput;
    return state_;
  }
  const double r_alpha = wheel_radius_ * slip_factor_;
  const double phi = r_alpha * (omega_r - omega_l);  // b_hat times the wheels' yaw rate [m rad/s]
  if (!sensors_ok)
  {
    state_ = State::kSensorFault;
  }
  else if (saturated)
  {
    state_ = State::kSaturated;
  }
  else if (std::abs(gyro_z) < params_.min_yaw_rate)
  {
    state_ = State::kNearRest;
  }
  else if (gyro_rate == 0.0)
  {
    state_ = State::kStuckGyro;
  }
  else if (std::abs(gyro_rate) > params_.max_yaw_acceleration ||
           std::abs(r_alpha * (omega_r_rate - omega_l_rate)) > params_.max_yaw_acceleration * b_)
  {
    state_ = State::kTransient;
  }
  else if (!(phi / gyro_z >= kImplausibleFactor * params_.min && phi / gyro_z <= params_.max / kImplausibleFactor))
  {
    state_ = State::kImplausible;  // gyro_z = 0 (min_yaw_rate 0): +-Inf or NaN, refused as well
  }
  else
  {
    // eps_b = y_gyro - r alpha (omega_R - omega_L) / b_hat;  dF_b/db_hat = Pi_b eps_b r alpha dw / b_hat^2.
    eps_ = gyro_z - phi / b_;
    const double grad = precision * eps_ * phi / (b_ * b_);
    double step = -h * params_.rate * grad;
    if (params_.max_rate > 0.0)
    {
      const double most = h * params_.max_rate * b_;
      step = std::clamp(step, -most, most);
    }
    b_ = std::clamp(b_ + step, params_.min, params_.max);
    ++steps_;
    state_ = State::kLearning;
  }
  return state_;
}

bool SeparationLearner::setSeparation(double b)
{
  if (!finite(b))
  {
    return false;
  }
  b_ = std::clamp(b, params_.min, params_.max);
  return true;
}

void SeparationLearner::reset()
{
  b_ = initial_;
  eps_ = 0.0;
  steps_ = 0;
  state_ = State::kNearRest;
}

const char* toString(SeparationLearner::State state)
{
  switch (state)
  {
    case SeparationLearner::State::kLearning:
      return "learning";
    case SeparationLearner::State::kSensorFault:
      return "sensor fault";
    case SeparationLearner::State::kNearRest:
      return "near rest";
    case SeparationLearner::State::kSaturated:
      return "saturated";
    case SeparationLearner::State::kTransient:
      return "transient";
    case SeparationLearner::State::kImplausible:
      return "implausible disagreement";
    case SeparationLearner::State::kStuckGyro:
      return "stuck gyro";
    case SeparationLearner::State::kBadInput:
      return "bad input";
  }
  return "unknown";
}

}  // namespace aic
}  // namespace jackal_aic
