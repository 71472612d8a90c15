/**
 * \file goal_rate.cpp
 * \brief mu_d' of a set-point stream by finite differences of its changes
 *        (include/jackal_aic/aic/goal_rate.hpp; doc/active_inference.md, 'Set-point dynamics').
 */
#include "jackal_aic/aic/goal_rate.hpp"

#include <algorithm>
#include <cmath>

namespace jackal_aic
{
namespace aic
{
base::Vector3 predictGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot, const base::Vector3& t_lead)
{
  base::Vector3 ahead = mu_d + t_lead.cwiseProduct(mu_d_dot);
  for (int i = 0; i < 2; ++i)  // x_dot, y_dot: not through a stop
  {
    if (mu_d(i) == 0.0 || ahead(i) * mu_d(i) < 0.0)
    {
      ahead(i) = 0.0;
    }
  }
  return ahead;
}

GoalRateEstimator::GoalRateEstimator(const params::ReferenceModelParams& params)
{
  setParams(params);
}

void GoalRateEstimator::setParams(const params::ReferenceModelParams& params)
{
  hold_ = params.goal_rate_hold;
  max_rate_ = base::Vector3(params.max_goal_rate_linear, params.max_goal_rate_linear, params.max_goal_rate_angular);
}

void GoalRateEstimator::reset()
{
  has_value_ = false;
  value_.setZero();
  change_time_ = 0.0;
  slope_.setZero();
  slope_until_ = 0.0;
}

bool GoalRateEstimator::update(double t, const base::Vector3& mu_d)
{
  if (!std::isfinite(t) || !mu_d.allFinite() || (has_value_ && t < change_time_))
  {
    return false;
  }
  if (!has_value_)
  {
    has_value_ = true;
    value_ = mu_d;
    change_time_ = t;
    return true;
  }
  if (mu_d == value_)
  {
    return true;  // a repeat: no new information
  }
  const double interval = t - change_time_;
  if (interval > 0.0 && interval <= hold_)
  {
    slope_ = ((mu_d - value_) / interval).cwiseMax(-max_rate_).cwiseMin(max_rate_);
    slope_until_ = t + std::min(kRampHoldIntervals * interval, hold_);
  }
  else
  {
    slope_.setZero();  // a step after a hold (or two changes at one instant)
    slope_until_ = t;
  }
  value_ = mu_d;
  change_time_ = t;
  return true;
}

base::Vector3 GoalRateEstimator::rate(double t) const
{
  return t < slope_until_ ? slope_ : base::Vector3::Zero();
}

}  // namespace aic
}  // namespace jackal_aic
