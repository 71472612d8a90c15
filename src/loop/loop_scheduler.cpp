/**
 * \file loop_scheduler.cpp
 * \brief A timer loop's interval clamping, catch-up steps and statistics
 *        (doc/jackal_aic_node.md, 'Loops'). ROS-free.
 */
#include "jackal_aic/loop/loop_scheduler.hpp"

#include <algorithm>
#include <cmath>

#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace loop
{
double LoopStats::maxInterval() const
{
  return std::min(std::max(max_factor * nominal_period, min_max_interval), params::kMaxStep);
}

double LoopStats::record(double interval)
{
  if (!std::isfinite(interval) || interval <= 0.0)
  {
    interval = nominal_period;
  }
  ++ticks;
  ++window_ticks;
  window_max_interval = std::max(window_max_interval, interval);
  window_abs_jitter_sum += std::abs(interval - nominal_period);
  if (interval > 2.0 * nominal_period)
  {
    ++overruns;
  }
  if (interval > maxInterval())
  {
    ++clamped;
    interval = maxInterval();
  }
  return interval;
}

void LoopStats::resetWindow()
{
  window_max_interval = 0.0;
  window_abs_jitter_sum = 0.0;
  window_ticks = 0;
  window_max_duration = 0.0;
}

LoopScheduler::LoopScheduler(double rate, double max_factor, bool catch_up, double min_max_interval)
  : catch_up_(catch_up)
{
  stats_.nominal_period = 1.0 / rate;
  stats_.max_factor = max_factor;
  stats_.min_max_interval = min_max_interval;
}

void LoopScheduler::setRate(double rate)
{
  stats_.nominal_period = 1.0 / rate;
}

LoopScheduler::Tick LoopScheduler::tick(double measured_interval)
{
  Tick t;
  t.interval = stats_.record(measured_interval);
  if (!catch_up_)
  {
    t.h = t.interval;
    return t;
  }
  // A late tick integrates its interval in steps of about one nominal period; the fractional
  // remainder is carried over (bounded), so early and late ticks average out to `rate` steps
  // per second; every tick runs at least one step.
  debt_ += t.interval / stats_.nominal_period;
  const int max_steps = std::max(1, static_cast<int>(std::lround(stats_.maxInterval() / stats_.nominal_period)));
  t.steps = std::clamp(static_cast<int>(std::floor(debt_ + 0.5)), 1, max_steps);
  debt_ = std::clamp(debt_ - t.steps, -1.0, 1.0);
  t.h = t.interval / t.steps;
  stats_.catch_up_steps += static_cast<std::uint64_t>(t.steps - 1);
  return t;
}

void LoopScheduler::recordDuration(double seconds)
{
  stats_.window_max_duration = std::max(stats_.window_max_duration, seconds);
}
}  // namespace loop
}  // namespace jackal_aic
