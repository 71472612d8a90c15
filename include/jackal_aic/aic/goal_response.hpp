#pragma once
/**
 * \file goal_response.hpp
 * \brief The goal's path as the robot is expected to follow it: a first-order lag of the reference
 *        path, the target of the unbiased model's goal prior on the action (not in the thesis;
 *        doc/active_inference.md, 'Unbiased beliefs'). ROS-free.
 */

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief g' = (mu_r - g) / T_g, integrated exactly with mu_r held over each step:
 *          g <- g + (mu_r - g)(1 - e^(-h / T_g)),   g' = (mu_r - g) / T_g
 *        (mu_r: the reference model's attractor goal, delayed by reference_delay). With unbiased
 *        beliefs the action's goal prior compares the beliefs, which estimate the robot, with g:
 *        the response the robot is expected to give to the goal's path (the wheel loop's first-order
 *        response T_g after its latency), so that the free-energy action does not integrate the
 *        part of every transient the robot's own response explains (the windup that overshoots).
 *        T_g = 0 = off: g = mu_r, g' = mu_r' (AicParams::goal_response_time_constant).
 *
 * No heap allocation, no exceptions.
 */
class GoalResponse
{
public:
  /// \param time_constant  T_g [s], >= 0 and finite (validated AicParams); 0 = off
  explicit GoalResponse(double time_constant = 0.0) : time_constant_(time_constant) {}

  /// T_g in use [s].
  double timeConstant() const { return time_constant_; }
  /// True when the lag acts (T_g > 0).
  bool enabled() const { return time_constant_ > 0.0; }

  /// Start at g0 [m/s, m/s, rad/s] with g' = 0; ignored if not finite.
  void start(const base::Vector3& g0);

  /**
   * \brief Advance g by h [s] (finite and > 0; otherwise no effect) towards mu_r held over the step.
   * \param mu_r      the attractor goal [m/s, m/s, rad/s] (ReferenceModel::attractorGoal())
   * \param mu_r_dot  its rate [m/s^2, m/s^2, rad/s^2] (ReferenceModel::attractorRate()), passed on
   *                  as g' when off
   */
  void advance(double h, const base::Vector3& mu_r, const base::Vector3& mu_r_dot);

  /// g [m/s, m/s, rad/s]: the expected response (mu_r when off, after advance()).
  const base::Vector3& goal() const { return g_; }
  /// g' [m/s^2, m/s^2, rad/s^2]: its rate (mu_r' when off, after advance()).
  const base::Vector3& rate() const { return g_dot_; }

private:
  double time_constant_;
  base::Vector3 g_ = base::Vector3::Zero();
  base::Vector3 g_dot_ = base::Vector3::Zero();
};

}  // namespace aic
}  // namespace jackal_aic
