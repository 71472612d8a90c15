#pragma once
/**
 * \file rest_release.hpp
 * \brief Release of the free-energy action at rest: the part of a_F that drives a channel whose
 *        goal is zero decays (not in the thesis; doc/active_inference.md, 'Update rules', Release at rest).
 *        ROS-free.
 */

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Before each action step, with c = (a_F,L + a_F,R) / 2 and d = (a_F,R - a_F,L) / 2:
 *          c <- c e^(-h / T_rel)  while the linear goal (x_dot, y_dot) is zero,
 *          d <- d e^(-h / T_rel)  while the yaw-rate goal is zero,
 *          a_F <- (c - d, c + d).
 *        A channel in motion keeps its correction. T_rel = action_release_time; 0 = off (the thesis).
 *
 * No heap allocation, no exceptions.
 */
class RestRelease
{
public:
  /// \param release_time  T_rel [s], in [0, 10]; 0 = off (AicParams::action_release_time)
  explicit RestRelease(double release_time = 0.0) : release_time_(release_time) {}

  /// T_rel in use [s].
  double releaseTime() const { return release_time_; }
  /// True when the release acts (T_rel > 0).
  bool enabled() const { return release_time_ > 0.0; }

  /**
   * \brief The free-energy action a_F = (omega_L, omega_R) [rad/s] after the release over one
   *        action step.
   * \param a_F   free-energy part of the action [rad/s]
   * \param goal  the predicted goal mu_hat_d = (x_dot [m/s], y_dot [m/s], theta_dot [rad/s])
   *              (ReferenceModel::target()); a channel is at rest when its element is exactly 0
   * \param h     action step [s], finite and > 0
   * \return a_F unchanged (bit for bit) when !enabled().
   */
  base::Vector2 apply(const base::Vector2& a_F, const base::Vector3& goal, double h) const;

private:
  double release_time_;
};

}  // namespace aic
}  // namespace jackal_aic
