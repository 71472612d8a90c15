/**
 * \file goal_response.cpp
 * \brief First-order expected response to the goal's path (include/jackal_aic/aic/goal_response.hpp).
 */
#include "jackal_aic/aic/goal_response.hpp"

#include <cmath>

namespace jackal_aic
{
namespace aic
{
void GoalResponse::start(const base::Vector3& g0)
{
  if (!g0.allFinite())
  {
    return;
  }
  g_ = g0;
  g_dot_.setZero();
}

void GoalResponse::advance(double h, const base::Vector3& mu_r, const base::Vector3& mu_r_dot)
{
  if (!(std::isfinite(h) && h > 0.0) || !mu_r.allFinite() || !mu_r_dot.allFinite())
  {
    return;
  }
  if (!enabled())
  {
    g_ = mu_r;
    g_dot_ = mu_r_dot;
    return;
  }
  g_ += (mu_r - g_) * (1.0 - std::exp(-h / time_constant_));
  g_dot_ = (mu_r - g_) / time_constant_;
}

}  // namespace aic
}  // namespace jackal_aic
