/**
 * \file reference_model.cpp
 * \brief The goal and the rate-limited, delayed reference path (doc/active_inference.md,
 *        'Set-point dynamics').
 */
#include "jackal_aic/aic/reference_model.hpp"

#include "jackal_aic/aic/goal_rate.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace jackal_aic
{
namespace aic
{
ReferenceModel::ReferenceModel(const params::ReferenceModelParams& params, double goal_limit)
  : params_(params), goal_limit_(goal_limit)
{
  start(base::Vector3::Zero());
}

void ReferenceModel::setParams(const params::ReferenceModelParams& params, double goal_limit)
{
  params_ = params;
  goal_limit_ = goal_limit;
  if (!params.generalized_goal)
  {
    mu_d_dot_.setZero();
  }
}

bool ReferenceModel::setGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot)
{
  if (!mu_d.allFinite() || mu_d.cwiseAbs().maxCoeff() > goal_limit_ || !mu_d_dot.allFinite() ||
      mu_d_dot.cwiseAbs().maxCoeff() > goal_limit_)
  {
    return false;
  }
  mu_d_ = mu_d;
  mu_d_dot_ = params_.generalized_goal ? mu_d_dot : base::Vector3::Zero();
  return true;
}

base::Vector3 ReferenceModel::target() const
{
  if (!params_.generalized_goal)
  {
    return mu_d_;
  }
  return predictGoal(mu_d_, mu_d_dot_, base::Vector3(params_.goal_lead, params_.goal_lead, params_.goal_lead_angular));
}

base::Vector3 ReferenceModel::accelerationLimit() const
{
  return base::Vector3(params_.max_acceleration_linear, params_.max_acceleration_linear,
                       params_.max_acceleration_angular);
}

void ReferenceModel::accelerationBounds(base::Vector3* lo, base::Vector3* hi) const
{
  const base::Vector3 acc = accelerationLimit();
  *lo = -acc;
  *hi = acc;
  // A payload's tip-over bound along x_dot: braking, forward or in reverse, and speeding up in
  // reverse, which pitches the robot nose-down over its front wheels as braking forward does; a
  // start into reverse is never looser than the acceleration's bound. Speeding up forward keeps
  // the acceleration's bound.
  const double dec = params_.max_deceleration_linear;
  if (dec > 0.0)
  {
    (*lo)(0) = m_(0) > 0.0 ? -dec : std::max(-dec, -acc(0));
    if (m_(0) < 0.0)
    {
      (*hi)(0) = dec;
    }
  }
  (*lo)(0) = std::max((*lo)(0), -tip_front_);
  (*hi)(0) = std::min((*hi)(0), tip_rear_);
}

void ReferenceModel::setTipBounds(double front, double rear)
{
  if (front >= 0.0)  // false for NaN
  {
    tip_front_ = front;
  }
  if (rear >= 0.0)
  {
    tip_rear_ = rear;
  }
}

bool ReferenceModel::holdTipSpeed(double x_dot)
{
  if (!std::isfinite(x_dot))
  {
    return false;
  }
  if (tip_front_ == 0.0 && m_(0) < x_dot)
  {
    m_(0) = x_dot;
    return true;
  }
  if (tip_rear_ == 0.0 && m_(0) > x_dot)
  {
    m_(0) = x_dot;
    return true;
  }
  return false;
}

base::Vector3 ReferenceModel::rate() const
{
  base::Vector3 lo, hi;
  accelerationBounds(&lo, &hi);
  base::Vector3 r = (target() - m_) / params_.time_constant;
  clampWheels(&r, params_.max_acceleration_wheel);
  return r.cwiseMax(lo).cwiseMin(hi);
}

void ReferenceModel::setWheelSeparation(double b)
{
  if (std::isfinite(b) && b > 0.0)
  {
    wheel_separation_ = b;
  }
}

void ReferenceModel::clampWheels(base::Vector3* d, double bound) const
{
  if (!(params_.max_acceleration_wheel > 0.0))
  {
    return;
  }
  const double half = 0.5 * wheel_separation_;
  const double left = std::min(std::max((*d)(0) - (*d)(2) * half, -bound), bound);
  const double right = std::min(std::max((*d)(0) + (*d)(2) * half, -bound), bound);
  (*d)(0) = 0.5 * (left + right);
  (*d)(2) = (right - left) / wheel_separation_;
}

bool ReferenceModel::start(const base::Vector3& m0)
{
  if (!m0.allFinite())
  {
    return false;
  }
  m_ = m0;
  time_ = 0.0;
  head_ = 0;
  count_ = 1;
  line_[0] = Sample{ 0.0, m0, base::Vector3::Zero() };
  mu_r_ = m0;
  mu_r_dot_.setZero();
  return true;
}

base::Vector3 ReferenceModel::stepChange(double h) const
{
  // Exact step of m' = (target - m) / T_r with the target held over h, its change clamped to
  // the path's acceleration bounds at the present m (a slowing path may reach 0 and go on in the
  // other direction within the step: it stops at 0 there).
  base::Vector3 lo, hi;
  accelerationBounds(&lo, &hi);
  base::Vector3 change = (target() - m_) * (1.0 - std::exp(-h / params_.time_constant));
  clampWheels(&change, params_.max_acceleration_wheel * h);
  change = change.cwiseMax(lo * h).cwiseMin(hi * h);
  for (int i = 0; i < 2; ++i)
  {
    if (params_.max_deceleration_linear > 0.0 && m_(i) != 0.0 && (m_(i) + change(i)) * m_(i) < 0.0)
    {
      change(i) = -m_(i);
    }
  }
  return change;
}

base::Vector3 ReferenceModel::pathAhead(double h) const
{
  if (!enabled())
  {
    return target();
  }
  if (!std::isfinite(h) || h <= 0.0)
  {
    return m_;
  }
  return m_ + stepChange(h);
}

void ReferenceModel::advance(double h)
{
  if (params_.time_constant <= 0.0)
  {
    return;
  }
  // The exact step (stepChange()); m' from rate() at the new m.
  const base::Vector3 change = stepChange(h);
  m_ += change;
  const base::Vector3 m_dot = rate();
  time_ += h;
  // The delay line keeps samples at least kMaxReferenceDelay / 800 apart (kLine of them cover the
  // longest delay); between them m(t - d_r) is interpolated linearly.
  const double spacing = params::kMaxReferenceDelay / 800.0;
  if (time_ - line_[static_cast<std::size_t>(head_)].t >= spacing)
  {
    head_ = (head_ + 1) % kLine;
    count_ = std::min(count_ + 1, kLine);
  }
  line_[static_cast<std::size_t>(head_)] = Sample{ time_, m_, m_dot };
  const double t_query = time_ - params_.delay;
  // Walk back from the newest sample to the first one at or before t_query.
  int newer = head_;
  for (int k = 1; k < count_; ++k)
  {
    const int older = (head_ - k + kLine) % kLine;
    const Sample& o = line_[static_cast<std::size_t>(older)];
    if (o.t <= t_query)
    {
      const Sample& n = line_[static_cast<std::size_t>(newer)];
      const double w = n.t > o.t ? (t_query - o.t) / (n.t - o.t) : 1.0;
      mu_r_ = o.m + w * (n.m - o.m);
      mu_r_dot_ = o.m_dot + w * (n.m_dot - o.m_dot);
      return;
    }
    newer = older;
  }
  const Sample& oldest = line_[static_cast<std::size_t>(newer)];  // the delay reaches before the line
  mu_r_ = oldest.m;
  mu_r_dot_ = oldest.m_dot;
}

}  // namespace aic
}  // namespace jackal_aic
