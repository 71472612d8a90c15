/**
 * \file gyro_bias_estimator.cpp
 * \brief The gyro's offset learned at standstill (include/jackal_aic/aic/gyro_bias_estimator.hpp;
 *        doc/active_inference.md, 'Learning the gyro's offset').
 */
#include "jackal_aic/aic/gyro_bias_estimator.hpp"

#include "jackal_aic/base/rule_list.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace aic
{
namespace
{
void check(const params::GyroBiasEstimatorParams& p)
{
  base::RuleList rules;
  rules.require(std::isfinite(p.max_bias) && p.max_bias > 0.0, "gyro_bias_max finite and > 0");
  rules.require(std::isfinite(p.rest_speed) && p.rest_speed > 0.0, "gyro_bias_rest_speed finite and > 0");
  rules.require(std::isfinite(p.rest_time) && p.rest_time >= 0.0, "gyro_bias_rest_time finite and >= 0");
  rules.require(std::isfinite(p.time_constant) && p.time_constant > 0.0, "gyro_bias_time_constant finite and > 0");
  rules.require(std::isfinite(p.min_rest) && p.min_rest >= 0.0, "gyro_bias_min_rest finite and >= 0");
  if (!rules.ok())
  {
    throw std::invalid_argument("invalid GyroBiasEstimatorParams:" + rules.violations());
  }
}
}  // namespace

GyroBiasEstimator::GyroBiasEstimator(const params::GyroBiasEstimatorParams& params) : params_(params)
{
  check(params);
}

void GyroBiasEstimator::setParams(const params::GyroBiasEstimatorParams& params)
{
  check(params);
  params_ = params;
  bias_ = std::clamp(bias_, -params_.max_bias, params_.max_bias);
}

GyroBiasEstimator::State GyroBiasEstimator::update(double h, double gyro_z, double omega_l, double omega_r,
                                                   double command_l, double command_r, bool gyro_ok)
{
  if (!(std::isfinite(h) && h > 0.0) || !std::isfinite(gyro_z) || !std::isfinite(omega_l) || !std::isfinite(omega_r) ||
      !std::isfinite(command_l) || !std::isfinite(command_r))
  {
    state_ = State::kBadInput;
    return state_;
  }
  const double v = params_.rest_speed;
  const bool at_rest =
      std::abs(omega_l) < v && std::abs(omega_r) < v && std::abs(command_l) < v && std::abs(command_r) < v;
  if (!at_rest)
  {
    rest_for_ = 0.0;
    state_ = State::kMoving;
    return state_;
  }
  rest_for_ += h;
  if (rest_for_ < params_.rest_time)
  {
    state_ = State::kSettling;
  }
  else if (!gyro_ok)
  {
    state_ = State::kSensorFault;
  }
  else if (std::abs(gyro_z) > params_.max_bias)
  {
    state_ = State::kImplausible;
  }
  else
  {
    ++samples_;
    learned_time_ += h;
    const double gain =
        std::max(1.0 / (static_cast<double>(samples_) + kPriorSamples), std::min(1.0, h / params_.time_constant));
    bias_ = std::clamp(bias_ + gain * (gyro_z - bias_), -params_.max_bias, params_.max_bias);
    state_ = State::kLearning;
  }
  return state_;
}

void GyroBiasEstimator::reset()
{
  bias_ = 0.0;
  rest_for_ = 0.0;
  learned_time_ = 0.0;
  samples_ = 0;
  state_ = State::kMoving;
}

const char* toString(GyroBiasEstimator::State state)
{
  switch (state)
  {
    case GyroBiasEstimator::State::kLearning:
      return "learning";
    case GyroBiasEstimator::State::kMoving:
      return "moving";
    case GyroBiasEstimator::State::kSettling:
      return "settling";
    case GyroBiasEstimator::State::kSensorFault:
      return "sensor fault";
    case GyroBiasEstimator::State::kImplausible:
      return "implausible reading";
    case GyroBiasEstimator::State::kBadInput:
      return "bad input";
  }
  return "unknown";
}

std::string statusText(const GyroBiasEstimator& estimator)
{
  std::string text = toString(estimator.state());
  const double learned = estimator.learnedTime();
  const double needed = estimator.params().min_rest;
  if (learned < needed)
  {
    char more[96];
    std::snprintf(more, sizeof more, "; not removed yet (%.1f of %.1f s of rest learned)", learned, needed);
    text += more;
  }
  return text;
}

}  // namespace aic
}  // namespace jackal_aic
