/**
 * \file tip_guard.cpp
 * \brief The tip-over guard (include/jackal_aic/safety/tip_guard.hpp; doc/active_inference.md,
 *        'The tip-over guard').
 */
#include "jackal_aic/safety/tip_guard.hpp"

#include "jackal_aic/base/rule_list.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace safety
{
namespace
{
constexpr double kNone = std::numeric_limits<double>::infinity();

void check(const params::TipGuardParams& p)
{
  base::RuleList rules;
  rules.require(std::isfinite(p.trip_pitch) && p.trip_pitch > 0.0, "tip_guard_pitch finite and > 0");
  rules.require(std::isfinite(p.margin) && p.margin > 0.0 && p.margin <= 1.0, "tip_guard_margin in (0, 1]");
  rules.require(std::isfinite(p.min_acceleration) && p.min_acceleration > 0.0, "tip_guard_min_acceleration finite and "
                                                                               "> 0");
  const bool turnover_ok =
      std::isfinite(p.turnover_pitch) && p.turnover_pitch > p.trip_pitch && p.turnover_pitch <= 1.5;
  rules.require(turnover_ok, "tip_guard_turnover_pitch finite, > tip_guard_pitch and <= 1.5");
  if (!rules.ok())
  {
    throw std::invalid_argument("invalid TipGuardParams:" + rules.violations());
  }
}

/// "1.84 m/s^2" or "none" for a bound not learned.
std::string boundText(double bound)
{
  if (!std::isfinite(bound))
  {
    return "none";
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.2f m/s^2", bound);
  return text;
}
}  // namespace

TipGuard::TipGuard(const params::TipGuardParams& params) : params_(params), front_(kNone), rear_(kNone)
{
  check(params);
}

void TipGuard::setParams(const params::TipGuardParams& params)
{
  check(params);
  params_ = params;
  front_ = std::max(front_, params_.min_acceleration);
  rear_ = std::max(rear_, params_.min_acceleration);
}

TipGuard::State TipGuard::update(double h, double pitch_rate, double speed, bool imu_ok, double up_force)
{
  if (!(std::isfinite(h) && h > 0.0) || !std::isfinite(speed) ||
      (imu_ok && !(std::isfinite(pitch_rate) && std::isfinite(up_force))))
  {
    state_ = State::kBadInput;
    return state_;
  }
  const double gain = std::min(1.0, h / kAccelTimeConstant);
  accel_ += has_speed_ ? gain * ((speed - speed_) / h - accel_) : 0.0;
  speed_ = speed;
  has_speed_ = true;
  if (!imu_ok)
  {
    theta_ *= std::exp(-h / kPitchTimeConstant);
    state_ = State::kNoImu;
    return state_;
  }
  if (std::abs(pitch_rate) < kStillRate)
  {
    theta_ *= std::exp(-h / kPitchTimeConstant);  // not rotating: fade toward the ground's plane
  }
  theta_ += pitch_rate * h;
  up_ += std::min(1.0, h / kUpForceTimeConstant) * (up_force - up_);
  upside_down_ = upside_down_ ? up_ <= kGravity * std::cos(params_.turnover_pitch) : up_ < 0.0;
  follow(&front_trip_, &front_, +1.0);
  follow(&rear_trip_, &rear_, -1.0);

  if (turnedOver())
  {
    state_ = State::kTurnedOver;
  }
  else if (front_trip_.active)
  {
    state_ = State::kTippingFront;
  }
  else if (rear_trip_.active)
  {
    state_ = State::kTippingRear;
  }
  else
  {
    state_ = std::abs(theta_) > params_.trip_pitch ? State::kPitched : State::kLevel;
  }
  return state_;
}

void TipGuard::follow(Trip* trip, double* bound, double sign)
{
  const double pitch = sign * theta_;                  // > 0: tipping this way
  const double tipping_acceleration = -sign * accel_;  // > 0: the acceleration that tips this way
  if (pitch < kOnsetFraction * params_.trip_pitch)
  {
    trip->onset_acceleration = -1.0;  // level: the next rise starts a new onset
  }
  else if (trip->onset_acceleration < 0.0)
  {
    trip->onset_acceleration = std::max(tipping_acceleration, 0.0);  // the wheels left the ground here
  }
  if (!trip->active && pitch > params_.trip_pitch && tipping_acceleration > kBrakingThreshold)
  {
    ++trips_;
    trip->active = true;
    const double at_onset = trip->onset_acceleration > 0.0 ? trip->onset_acceleration : tipping_acceleration;
    *bound = std::min(*bound, std::max(params_.min_acceleration, params_.margin * at_onset));
  }
  trip->active = trip->active && pitch >= 0.5 * params_.trip_pitch;
}

bool TipGuard::turnedOver() const
{
  return upside_down_ || std::abs(theta_) > params_.turnover_pitch;
}

double TipGuard::frontBound() const
{
  return front_trip_.active ? 0.0 : front_;
}

double TipGuard::rearBound() const
{
  return rear_trip_.active ? 0.0 : rear_;
}

void TipGuard::reset()
{
  theta_ = 0.0;
  accel_ = 0.0;
  speed_ = 0.0;
  has_speed_ = false;
  front_ = kNone;
  rear_ = kNone;
  front_trip_ = Trip{};
  rear_trip_ = Trip{};
  state_ = State::kLevel;
  trips_ = 0;
}

const char* toString(TipGuard::State state)
{
  switch (state)
  {
    case TipGuard::State::kLevel:
      return "level";
    case TipGuard::State::kTippingFront:
      return "tipping nose-down";
    case TipGuard::State::kTippingRear:
      return "tipping tail-down";
    case TipGuard::State::kPitched:
      return "pitched (slope)";
    case TipGuard::State::kTurnedOver:
      return "turned over (wheels stopped)";
    case TipGuard::State::kNoImu:
      return "no IMU";
    case TipGuard::State::kBadInput:
      return "bad input";
  }
  return "unknown";
}

std::string statusText(const TipGuard& guard)
{
  char trips[48];
  std::snprintf(trips, sizeof trips, "; %llu trip%s", static_cast<unsigned long long>(guard.trips()),
                guard.trips() == 1 ? "" : "s");
  return std::string(toString(guard.state())) + "; front " + boundText(guard.learnedFront()) + ", rear " +
         boundText(guard.learnedRear()) + trips;
}

}  // namespace safety
}  // namespace jackal_aic
