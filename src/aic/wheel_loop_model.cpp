/**
 * \file wheel_loop_model.cpp
 * \brief The robot model's wheel loop (doc/active_inference.md, 'The robot model').
 */
#include "jackal_aic/aic/wheel_loop_model.hpp"

#include <algorithm>
#include <cmath>

namespace jackal_aic
{
namespace aic
{
WheelLoopModel::WheelLoopModel(const params::RobotModelParams& params) : params_(params)
{
  reset(0.0, base::Vector2::Zero());
}

void WheelLoopModel::setParams(const params::RobotModelParams& params)
{
  params_ = params;
}

void WheelLoopModel::reset(double t, const base::Vector2& u)
{
  head_ = 0;
  count_ = 1;
  line_[0] = Entry{ t, u, base::Vector2::Zero() };
}

base::Vector2 WheelLoopModel::rateOf(double t, const base::Vector2& u) const
{
  return base::Vector2(rateOf(t, u(0), 0), rateOf(t, u(1), 1));
}

double WheelLoopModel::rateOf(double t, double u, int s) const
{
  const Entry& newest = line_[head_];
  return (u - newest.u(s)) / std::max(t - newest.t, kSubstep);
}

void WheelLoopModel::record(double t, const base::Vector2& u)
{
  const double newest = line_[head_].t;
  const base::Vector2 rate = rateOf(t, u);
  head_ = (head_ + 1) % kCapacity;
  line_[head_] = Entry{ std::max(t, newest), u, rate };
  count_ = std::min(count_ + 1, kCapacity);
}

const WheelLoopModel::Entry& WheelLoopModel::entryAt(double t, double latency) const
{
  const double sent_by = t - latency;
  for (int k = 0; k < count_; ++k)
  {
    const Entry& e = line_[(head_ - k + kCapacity) % kCapacity];
    if (e.t <= sent_by + 1.0e-12)
    {
      return e;
    }
  }
  return line_[(head_ - count_ + 1 + kCapacity) % kCapacity];  // older than the line: its oldest
}

base::Vector2 WheelLoopModel::commandAt(double t) const
{
  return entryAt(t, params_.latency).u;
}

base::Vector2 WheelLoopModel::commandRateAt(double t) const
{
  return rateIn(entryAt(t, params_.latency), t, params_.latency);
}

base::Vector2 WheelLoopModel::rateIn(const Entry& e, double t, double latency)
{
  // Before the oldest remembered command (which stands in for the older ones) the stream is held.
  return e.t <= t - latency + 1.0e-12 ? e.rate : base::Vector2::Zero();
}

base::Vector2 WheelLoopModel::lastCommand() const
{
  return line_[head_].u;
}

double WheelLoopModel::kickRange(double h) const
{
  if (!(h > 0.0) || !std::isfinite(h))
  {
    return 0.0;
  }
  const double decay = params_.wheel_time_constant > 0.0 ? std::exp(-h / params_.wheel_time_constant) : 0.0;
  const double a_ff = params_.wheel_feedforward_acceleration;
  const double lag = std::max(params_.wheel_acceleration - a_ff, 0.0) * h / (1.0 - decay);
  const double feedforward = params_.wheel_feedforward > 0.0 ? a_ff * h / params_.wheel_feedforward : 0.0;
  return lag + feedforward;
}

double WheelLoopModel::step(double omega, double u, double rate, double h, double* gain) const
{
  const double decay = params_.wheel_time_constant > 0.0 ? std::exp(-h / params_.wheel_time_constant) : 0.0;
  const double change = (u - omega) * (1.0 - decay);
  const double a_ff = params_.wheel_feedforward_acceleration;
  const double feedforward = std::clamp(params_.wheel_feedforward * rate, -a_ff, a_ff) * h;
  const double bound = std::max(params_.wheel_acceleration - a_ff, 0.0) * h;
  if (std::abs(change) > bound)
  {
    if (gain != nullptr)
    {
      *gain = 1.0;
    }
    return omega + std::copysign(bound, change) + feedforward;
  }
  if (gain != nullptr)
  {
    *gain = decay;
  }
  return omega + change + feedforward;
}

base::Vector2 WheelLoopModel::predict(const base::Vector2& omega0, const base::Vector2& d, double t0, double t1) const
{
  return predictWithLatency(omega0, d, t0, t1, params_.latency);
}

base::Vector2 WheelLoopModel::predictWithLatency(const base::Vector2& omega0, const base::Vector2& d, double t0,
                                                 double t1, double latency) const
{
  base::Vector2 omega = omega0;
  double t = t0;
  while (t < t1 - 1.0e-12)
  {
    const double h = std::min(kSubstep, t1 - t);
    const Entry& e = entryAt(t, latency);
    const base::Vector2 u = e.u - d;
    const base::Vector2 rate = rateIn(e, t, latency);
    omega(0) = step(omega(0), u(0), rate(0), h);
    omega(1) = step(omega(1), u(1), rate(1), h);
    t += h;
  }
  return omega;
}

}  // namespace aic
}  // namespace jackal_aic
