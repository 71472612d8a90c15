/**
 * \file latency_learner.cpp
 * \brief The robot model's latency from the wheels' first motion after rest
 *        (doc/active_inference.md, 'Learning the latency').
 */
#include "jackal_aic/aic/latency_learner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace jackal_aic
{
namespace aic
{
LatencyLearner::LatencyLearner(double initial, double min, double max, double encoder_noise)
  : initial_(std::clamp(initial, min, max))
  , min_(min)
  , max_(max)
  , threshold_(kOnsetSigmas * encoder_noise)
  , latency_(initial_)
  , last_(std::numeric_limits<double>::quiet_NaN())
{
}

void LatencyLearner::reset()
{
  latency_ = initial_;
  last_ = std::numeric_limits<double>::quiet_NaN();
  armed_ = false;
  starts_ = 0;
}

void LatencyLearner::commandSent(double t, const base::Vector2& u, const base::Vector2& previous, bool wheels_at_rest)
{
  if (!armed_ && previous.isZero(0.0) && !u.isZero(0.0) && wheels_at_rest && u.allFinite() && std::isfinite(t))
  {
    armed_ = true;
    start_time_ = t;
  }
}

bool LatencyLearner::sample(double t, const base::Vector2& y, const WheelLoopModel& loop)
{
  if (!armed_ || !std::isfinite(t) || !y.allFinite())
  {
    return false;
  }
  if (t - start_time_ > max_ + kWindow)
  {
    armed_ = false;
    return false;
  }
  const int side = std::abs(y(1)) > std::abs(y(0)) ? 1 : 0;
  if (!(std::abs(y(side)) > threshold_))
  {
    return false;
  }
  armed_ = false;
  // The reading's size from rest under L': falls as L' grows (the commands act later).
  const double sign = y(side) > 0.0 ? 1.0 : -1.0;
  const auto reached = [&](double l) {
    return sign * loop.predictWithLatency(base::Vector2::Zero(), base::Vector2::Zero(), start_time_, t, l)(side);
  };
  const double target = sign * y(side);
  double lo = min_;
  double hi = max_;
  if (reached(lo) <= target)
  {
    hi = lo;
  }
  else if (reached(hi) >= target)
  {
    lo = hi;
  }
  while (hi - lo > kTolerance)
  {
    const double mid = 0.5 * (lo + hi);
    if (reached(mid) > target)
    {
      lo = mid;
    }
    else
    {
      hi = mid;
    }
  }
  last_ = 0.5 * (lo + hi);
  ++starts_;
  const double weight = 1.0 / std::min(starts_, kMemory);
  latency_ = std::clamp(latency_ + weight * (last_ - latency_), min_, max_);
  return true;
}

}  // namespace aic
}  // namespace jackal_aic
