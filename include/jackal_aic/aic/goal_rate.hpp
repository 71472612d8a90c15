#pragma once
/**
 * \file goal_rate.hpp
 * \brief The goal's rate mu_d' from a set-point stream by finite differences: the generalized
 *        goal (mu_d, mu_d') of the attractor f(mu) = mu_d' + (mu_d - mu) / tau
 *        (doc/active_inference.md, 'Set-point dynamics'). ROS-free.
 */

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief The goal predicted t_lead ahead: mu_hat_d = mu_d + t_lead mu_d' per channel, except that
 *        a linear channel (x_dot, y_dot) is not predicted through a stop: where mu_d is 0, or where
 *        mu_d + t_lead mu_d' has the sign opposite to mu_d, its prediction is 0.
 *
 * A stream's ramp into a stop ends at the stop, but the estimator holds its slope for
 * GoalRateEstimator::kRampHoldIntervals after the last change; extrapolated, it would ask for
 * reverse for that long, and the robot would back up. A change of travel direction is made from
 * rest, not through a ramp's extrapolation. The yaw rate is predicted through 0: a turn's rate
 * sweeps through 0 inside one manoeuvre (an S-curve), and its prediction there is what the
 * latency needs (doc/active_inference.md, 'Set-point dynamics', 'A ramp's end').
 *
 * \param mu_d      the goal [m/s, m/s, rad/s]
 * \param mu_d_dot  its rate [m/s^2, m/s^2, rad/s^2] (GoalRateEstimator::rate())
 * \param t_lead    the prediction horizon per channel [s]
 * \return mu_hat_d [m/s, m/s, rad/s]; elementwise arithmetic, so a non-finite input gives a
 *         non-finite output (callers validate their inputs).
 */
base::Vector3 predictGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot, const base::Vector3& t_lead);

/**
 * \brief Estimates mu_d' [m/s^2, m/s^2, rad/s^2] of a zero-order-hold set-point stream.
 *
 * A planner or a joystick publishes a ramp as a staircase: the same value repeated, then a
 * change every 1/rate. Only changes count (a repeated value is no new information): for a change
 * Delta at time t_k after the previous change at t_{k-1},
 *   mu_d' = Delta / (t_k - t_{k-1})   if t_k - t_{k-1} <= goal_rate_hold (the ramp continues),
 *   mu_d' = 0                         otherwise (a step after a hold: no motion to predict),
 * each channel clamped to max_goal_rate_linear / max_goal_rate_angular. The slope is held until
 * kRampHoldIntervals change intervals (at most goal_rate_hold) pass without a further change, then mu_d' = 0:
 * the ramp has ended. The first difference of a ramp is a step; prediction starts at its second.
 *
 * No allocation; a non-finite or out-of-order input is ignored (returns false).
 */
class GoalRateEstimator
{
public:
  /// \param params  the goal stage's settings (AicParams::reference, validated): uses goal_rate_hold,
  ///                max_goal_rate_linear, max_goal_rate_angular
  explicit GoalRateEstimator(const params::ReferenceModelParams& params);

  /// New limits (goal_rate_hold, max_goal_rate_*); the state is kept.
  void setParams(const params::ReferenceModelParams& params);

  /**
   * \brief A set point mu_d [m/s, m/s, rad/s] received at time t [s].
   * \return false (state unchanged) for a non-finite mu_d or t, or t before the previous change.
   */
  bool update(double t, const base::Vector3& mu_d);

  /// mu_d' in force at time t [s] (zero once the slope's hold has passed, and before two changes).
  base::Vector3 rate(double t) const;

  /// Forget the stream (no slope, no previous change).
  void reset();

  /// A slope is held this many change intervals after its change (at most goal_rate_hold): a
  /// stream's next change is due after one interval, a little later with the publisher's jitter.
  static constexpr double kRampHoldIntervals = 1.25;

private:
  double hold_;
  base::Vector3 max_rate_;
  bool has_value_ = false;
  base::Vector3 value_ = base::Vector3::Zero();
  double change_time_ = 0.0;  ///< time of the last change [s]
  base::Vector3 slope_ = base::Vector3::Zero();
  double slope_until_ = 0.0;  ///< the slope holds until this time [s]
};

}  // namespace aic
}  // namespace jackal_aic
