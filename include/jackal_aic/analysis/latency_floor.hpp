#pragma once
/**
 * \file latency_floor.hpp
 * \brief The latency floor: the tracking error of an ideal servo that only lags the set-point
 *        stream by the plant's latency (doc/tools.md, 'Tracking benchmark'). ROS-free.
 */

#include <vector>

#include "jackal_aic/analysis/tracking_error.hpp"
#include "jackal_aic/analysis/twist_profile.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace analysis
{
/// The ideal servo of latencyFloor(): what it knows of the stream and what it can do.
struct LatencyFloorSettings
{
  double latency = 0.0;        ///< L: command-to-motion latency of the plant [s], finite, in [0, 10]
  double accel_linear = 0.0;   ///< largest |dvx/dt| [m/s^2]; 0 = unlimited; finite, >= 0
  double accel_angular = 0.0;  ///< largest |dwz/dt| [rad/s^2]; 0 = unlimited; finite, >= 0
  /// true: the servo aims at the set point predicted L ahead, mu_d + L mu_d' (aic::predictGoal(),
  /// mu_d' by the GoalRateEstimator, as the AIC's generalized goal: v_x not predicted through a
  /// stop); false: at the set point it has (hold)
  bool predict = false;
  /// T_h: the servo takes a new aim every T_h [s] and holds it between, as a controller holds its
  /// command for its action period (the node's 1 / action_rate); a prediction then aims
  /// L + T_h / 2 ahead, the middle of the hold. 0 = a new aim every dt. Finite, in [0, 1]
  double period = 0.0;
  /// A_w: the largest |d omega / dt| [rad/s^2] of each of two wheels that carry the servo's twist
  /// (aic::SkidSteerModel with wheel_radius, slip factor 1 and track): a speed change and a turn
  /// share what the wheels give. 0 = no wheel bound; > 0 needs wheel_radius and track > 0 and
  /// accel_linear = accel_angular = 0. Finite, >= 0
  double wheel_acceleration = 0.0;
  double wheel_radius = 0.0;  ///< r [m] of the wheel bound, finite, > 0 with it
  /// The wheels' left-right distance [m] of the wheel bound, finite, > 0 with it (the geometric
  /// track, not the larger effective skid separation, keeps the result a floor)
  double track = 0.0;
  double dt = 0.001;  ///< sample period of the servo and of the error [s], finite, in [1e-5, 0.1]
};

/**
 * \brief The latency floor of a profile: the velocity tracking error of an ideal servo, the
 *        best any controller can do through a plant that moves only L after it is commanded,
 *        for a given way of predicting the stream.
 *
 * The servo receives each profile point at its time, as the controller receives the stream, and
 * its body twist is y(t) = clamp_a(u(t - L)) with u the held set point mu_d(t) (predict false) or
 * its prediction mu_d(t) + L mu_d'(t) (predict true, aic::predictGoal(), mu_d' from a GoalRateEstimator with
 * goal_rate's goal_rate_hold and max_goal_rate_*); with a hold period T_h > 0, u is taken at the
 * multiples of T_h only and held between (the prediction's lead L + T_h / 2); clamp_a a rate limit of
 * accel_linear / accel_angular (none where 0), or with wheel_acceleration A_w > 0 of each wheel
 * speed of the twist (omega_L,R = (v_x -+ track w_z / 2) / r, each at most A_w), y = 0 before t = L. No wheel loop, no slip, no
 * torque limit, no noise: a controller on the plant cannot do better than this servo with the same
 * predictor (doc/tools.md, 'Latency floor'). The error is velocityTrackingError() of y sampled
 * every dt over [0, duration].
 * \param goal_rate  parameters of the goal-rate estimator (validated AicParams; only its
 *                   goal-rate keys are used)
 * \throws std::invalid_argument on an invalid profile or settings out of range (message says which)
 */
VelocityTrackingError latencyFloor(const TwistProfile& profile, const params::AicParams& goal_rate,
                                   const LatencyFloorSettings& settings);
}  // namespace analysis
}  // namespace jackal_aic
