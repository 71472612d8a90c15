/**
 * \file precision_learner.cpp
 * \brief Free-energy descent of the log sensory precisions ln Pi_y^(0)
 *        (include/jackal_aic/aic/precision_learner.hpp; doc/active_inference.md, 'Learning the
 *        sensory precisions').
 */
#include "jackal_aic/aic/precision_learner.hpp"

#include "jackal_aic/base/rule_list.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "jackal_aic/params/aic_params.hpp"

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

std::string check(const params::PrecisionLearnerParams& p, const PrecisionChannels& channels)
{
  base::RuleList rules;
  for (int j = 0; j < base::kYDim; ++j)
  {
    const double c = channels.configured[static_cast<std::size_t>(j)];
    rules.require(finite(c) && c > 0.0, "configured precision of channel " + std::to_string(j) + " finite and > 0");
  }
  rules.require(finite(p.rate) && p.rate >= 0.0, "precision_learning_rate finite and >= 0");
  rules.require(finite(p.min_factor) && p.min_factor > 0.0 && p.min_factor <= 1.0, "precision_min_factor finite, > 0 "
                                                                                   "and <= 1");
  rules.require(finite(p.max_factor) && p.max_factor >= 1.0, "precision_max_factor finite and >= 1");
  rules.require(finite(p.time_constant) && p.time_constant > 0.0, "precision_time_constant finite and > 0");
  rules.require(finite(p.min_wheel_speed) && p.min_wheel_speed >= 0.0, "precision_min_wheel_speed finite and >= 0");
  return rules.violations();
}

}  // namespace

PrecisionLearner::PrecisionLearner() : PrecisionLearner(params::PrecisionLearnerParams(), PrecisionChannels()) {}

PrecisionLearner::PrecisionLearner(const params::PrecisionLearnerParams& params, const PrecisionChannels& channels)
  : params_(params), channels_(channels)
{
  const std::string violations = check(params, channels);
  if (!violations.empty())
  {
    throw std::invalid_argument("invalid PrecisionLearnerParams:" + violations);
  }
  reset();
}

void PrecisionLearner::setParams(const params::PrecisionLearnerParams& params, const PrecisionChannels& channels)
{
  const std::string violations = check(params, channels);
  if (!violations.empty())
  {
    throw std::invalid_argument("invalid PrecisionLearnerParams:" + violations);
  }
  const bool keep = channels.learned == channels_.learned && channels.configured == channels_.configured;
  params_ = params;
  channels_ = channels;
  if (!keep)
  {
    reset();
    return;
  }
  for (int j = 0; j < base::kYDim; ++j)
  {
    const auto k = static_cast<std::size_t>(j);
    const double c = channels_.configured[k];
    lambda_[k] = std::clamp(lambda_[k], std::log(params_.min_factor * c), std::log(params_.max_factor * c));
    pi_[k] = std::exp(lambda_[k]);
  }
}

PrecisionLearner::State PrecisionLearner::update(double h, const base::Vector5& eps, double omega_l, double omega_r,
                                                 std::uint8_t sensor_mask, bool saturated)
{
  bool ok = finite(h) && h > 0.0 && finite(omega_l) && finite(omega_r);
  for (int j = 0; j < base::kYDim && ok; ++j)
  {
    ok = !learned(j) || finite(eps(j));
  }
  if (!ok)
  {
    state_ = State::kBadInput;
    return state_;
  }
  if ((sensor_mask & channels_.learned) != channels_.learned)
  {
    state_ = State::kSensorFault;
  }
  else if (saturated)
  {
    state_ = State::kSaturated;
  }
  else if (std::abs(omega_l) < params_.min_wheel_speed && std::abs(omega_r) < params_.min_wheel_speed)
  {
    state_ = State::kNearRest;
  }
  else
  {
    const double alpha = -std::expm1(-h / params_.time_constant);  // 1 - exp(-h / T_w)
    for (int j = 0; j < base::kYDim; ++j)
    {
      if (!learned(j))
      {
        continue;
      }
      const auto k = static_cast<std::size_t>(j);
      const double c = channels_.configured[k];
      // s_j <- low-pass of eps_j^2, one sample at most a kOutlierClip-sigma error of Pi_j.
      const double e2 = std::min(eps(j) * eps(j), kOutlierClip * kOutlierClip / pi_[k]);
      s_[k] += alpha * (e2 - s_[k]);
      // dF_j/d lambda_j = Pi_j dF_j/dPi_j = 1/2 (Pi_j s_j - 1).
      const double grad = 0.5 * (pi_[k] * s_[k] - 1.0);
      lambda_[k] = std::clamp(lambda_[k] - h * params_.rate * grad, std::log(params_.min_factor * c),
                              std::log(params_.max_factor * c));
      pi_[k] = std::exp(lambda_[k]);
    }
    ++steps_;
    state_ = State::kLearning;
  }
  return state_;
}

double PrecisionLearner::precision(int j) const
{
  return j >= 0 && j < base::kYDim ? pi_[static_cast<std::size_t>(j)] : std::numeric_limits<double>::quiet_NaN();
}

double PrecisionLearner::meanSquaredError(int j) const
{
  return j >= 0 && j < base::kYDim ? s_[static_cast<std::size_t>(j)] : std::numeric_limits<double>::quiet_NaN();
}

void PrecisionLearner::applyTo(base::YTilde* pi_y)
{
  for (int j = 0; j < base::kYDim; ++j)
  {
    if (learned(j) && pi_y->cols() > 0)
    {
      (*pi_y)(j, 0) = pi_[static_cast<std::size_t>(j)];
    }
  }
  applied_ = pi_;
}

bool PrecisionLearner::changedSince(double tolerance) const
{
  for (int j = 0; j < base::kYDim; ++j)
  {
    const auto k = static_cast<std::size_t>(j);
    if (learned(j) && std::abs(pi_[k] - applied_[k]) > tolerance * applied_[k])
    {
      return true;
    }
  }
  return false;
}

void PrecisionLearner::reset()
{
  for (std::size_t k = 0; k < static_cast<std::size_t>(base::kYDim); ++k)
  {
    pi_[k] = channels_.configured[k];
    lambda_[k] = std::log(pi_[k]);
    s_[k] = 1.0 / pi_[k];  // start at the optimum of the configured precision
  }
  applied_ = pi_;
  steps_ = 0;
  state_ = State::kNearRest;
}

PrecisionChannels precisionChannels(const params::AicParams& params)
{
  PrecisionChannels channels;
  const base::YTilde pi_y = params.precisionY();
  for (int j = 0; j < base::kYDim; ++j)
  {
    channels.configured[static_cast<std::size_t>(j)] = pi_y(j, 0);
  }
  channels.learned =
      static_cast<std::uint8_t>((1u << base::kGyroZ) | (1u << base::kOmegaLeft) | (1u << base::kOmegaRight) |
                                (params.accel_in_model ? (1u << base::kAccelX) : 0u));
  return channels;
}

const char* toString(PrecisionLearner::State state)
{
  switch (state)
  {
    case PrecisionLearner::State::kLearning:
      return "learning";
    case PrecisionLearner::State::kSensorFault:
      return "sensor fault";
    case PrecisionLearner::State::kNearRest:
      return "near rest";
    case PrecisionLearner::State::kSaturated:
      return "saturated";
    case PrecisionLearner::State::kBadInput:
      return "bad input";
  }
  return "unknown";
}

}  // namespace aic
}  // namespace jackal_aic
