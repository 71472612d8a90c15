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
  line_[0] = Entry{ t, u };
}

void WheelLoopModel::record(double t, const base::Vector2& u)
{
  const double newest = line_[head_].t;
  head_ = (head_ + 1) % kCapacity;
  line_[head_] = Entry{ std::max(t, newest), u };
  count_ = std::min(count_ + 1, kCapacity);
}

base::Vector2 WheelLoopModel::commandAt(double t) const
{
  const double sent_by = t - params_.latency;
  for (int k = 0; k < count_; ++k)
  {
    const Entry& e = line_[(head_ - k + kCapacity) % kCapacity];
    if (e.t <= sent_by + 1.0e-12)
    {
      return e.u;
    }
  }
  return line_[(head_ - count_ + 1 + kCapacity) % kCapacity].u;  // older than the line: its oldest
}

base::Vector2 WheelLoopModel::lastCommand() const
{
  return line_[head_].u;
}

double WheelLoopModel::step(double omega, double u, double h, double* gain) const
{
  const double decay = params_.wheel_time_constant > 0.0 ? std::exp(-h / params_.wheel_time_constant) : 0.0;
  const double change = (u - omega) * (1.0 - decay);
  const double bound = params_.wheel_acceleration * h;
  if (std::abs(change) > bound)
  {
    if (gain != nullptr)
    {
      *gain = 1.0;
    }
    return omega + std::copysign(bound, change);
  }
  if (gain != nullptr)
  {
    *gain = decay;
  }
  return omega + change;
}

base::Vector2 WheelLoopModel::predict(const base::Vector2& omega0, const base::Vector2& d, double t0, double t1) const
{
  base::Vector2 omega = omega0;
  double t = t0;
  while (t < t1 - 1.0e-12)
  {
    const double h = std::min(kSubstep, t1 - t);
    const base::Vector2 u = commandAt(t) - d;
    omega(0) = step(omega(0), u(0), h);
    omega(1) = step(omega(1), u(1), h);
    t += h;
  }
  return omega;
}

}  // namespace aic
}  // namespace jackal_aic
