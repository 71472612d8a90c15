#pragma once
/**
 * \file reference_model.hpp
 * \brief The controller's goal stage: the goal (mu_d, mu_d'), its prediction and the rate-limited,
 *        delayed reference path the beliefs' attractor follows (not in the thesis; its section
 *        6-1 names it as future work; doc/active_inference.md, 'Set-point dynamics'). ROS-free.
 */

#include <array>
#include <limits>

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Goal -> predicted goal -> reference path with its delay line.
 *
 * The goal mu_d = (x_dot [m/s], y_dot [m/s], theta_dot [rad/s]) and its rate mu_d' (zero unless
 * generalized_goal) give the predicted goal mu_hat_d = mu_d + t_lead mu_d' (target(), predictGoal(); t_lead per
 * channel: goal_lead for x_dot and y_dot, goal_lead_angular for theta_dot). With
 * T_r > 0 a first-order model m follows it,
 *   m' = clamp(W((mu_hat_d - m) / T_r, A_w), lo, hi),   (lo, hi) = accelerationBounds(),
 * integrated exactly with the target held over each step, m <- m + clamp(W((mu_hat_d - m)(1 -
 * e^(-h/T_r)), A_w h), lo h, hi h), and delayed by d_r. W(d, c) bounds a change d of the body's
 * twist in the wheels' frame: each rim speed's change d_x -+ d_theta b / 2 is clamped to [-c, c]
 * and the body's change recomputed from the two (d_y untouched; A_w = max_acceleration_wheel,
 * W the identity when it is 0). A skid-steer's wheel loops saturate per wheel: a turn commanded
 * with a forward start waits for the inner wheel, and the path waits with it instead of asking the
 * action for a yaw rate the wheels cannot give yet (doc/active_inference.md, 'Set-point dynamics').
 * The body bounds only shrink a channel toward 0 (a max_deceleration_linear above
 * max_acceleration_linear excepted, for braking), so |m'_x| + |m'_theta| b / 2 <= A_w still holds
 * after them. Then the delay: mu_r(t) = m(t - d_r), mu_r' = m'(t - d_r), from a delay line of kLine
 * samples at least kMaxReferenceDelay / 800 apart (linear interpolation; a delay beyond the line uses
 * its oldest sample). The beliefs' attractor is then f(mu) = mu_r' + (mu_r - mu) / tau; with T_r = 0
 * it is f(mu) = mu_d' + (mu_d - mu) / tau (attractorGoal(), attractorRate()).
 *
 * No heap allocation (the delay line has a fixed capacity), no exceptions.
 */
class ReferenceModel
{
public:
  /// Delay-line length [samples]: samples >= kMaxReferenceDelay / 800 apart cover the longest delay.
  static constexpr int kLine = 1024;

  /// Goal, path and delay line at zero; the wheel separation b 0.5 m until setWheelSeparation().
  /// \param params      the settings (AicParams::reference, validated; the stage does not check them)
  /// \param goal_limit  largest accepted |element| of mu_d and mu_d' (AicParams::runaway_limit), > 0
  explicit ReferenceModel(const params::ReferenceModelParams& params = params::ReferenceModelParams(),
                          double goal_limit = 1.0e3);

  /// Replace the settings and the goal limit (as the constructor's); goal, path, delay line and
  /// wheel separation kept, the goal's rate zeroed unless generalized_goal.
  void setParams(const params::ReferenceModelParams& params, double goal_limit);
  /// The settings in use.
  const params::ReferenceModelParams& params() const { return params_; }
  /// Set the wheel separation b [m] of the wheel bound (the model's, as it is learned); ignored
  /// unless finite and > 0. Path and line kept.
  void setWheelSeparation(double b);
  /// The wheel separation b of the wheel bound [m].
  double wheelSeparation() const { return wheel_separation_; }
  /**
   * \brief Bound the path's rate along x_dot to [-front, rear] [m/s^2] (the TipGuard's bounds:
   *        the deceleration that lifts the rear wheels, the acceleration that lifts the front
   *        ones), on top of accelerationBounds()' other bounds. +inf = none (the default); a value
   *        that is NaN or < 0 is ignored. Kept by setParams() and start().
   */
  void setTipBounds(double front, double rear);
  /**
   * \brief While a tip bound is tripped (0: the TipGuard stops the path's braking or its
   *        acceleration along x_dot), move the path's x_dot to `x_dot` [m/s] where the tripped
   *        bound would have kept it had the path not been ahead of the robot: a front trip raises
   *        it to at least x_dot, a rear trip lowers it to at most x_dot. The robot model's path
   *        leads the wheels by the latency (its goal is predicted that far ahead), so its value is
   *        what the wheels reach one latency later; with x_dot the body's believed speed now, the
   *        wheels stop braking (or accelerating) one latency after the trip instead of going on
   *        to the path's value. The delay line is not touched (the robot model's path is not
   *        delayed).
   * \return true if the path moved; false (unchanged) when no bound is tripped, when x_dot is
   *         not finite or when the path is already on the allowed side of it.
   */
  bool holdTipSpeed(double x_dot);
  /// True while a tip bound is tripped (front or rear at 0: the TipGuard holds the path's braking
  /// or its acceleration along x_dot until the body is level again).
  bool tipTripped() const { return tip_front_ == 0.0 || tip_rear_ == 0.0; }
  /// The tip bounds in force (front, rear) [m/s^2] (+inf: none).
  double tipBoundFront() const { return tip_front_; }
  /// See tipBoundFront().
  double tipBoundRear() const { return tip_rear_; }
  /// True with a reference model (time_constant > 0).
  bool enabled() const { return params_.time_constant > 0.0; }

  /**
   * \brief Set the goal mu_d [m/s, m/s, rad/s] and its rate mu_d' [m/s^2, m/s^2, rad/s^2]
   *        (the rate is stored as zero unless generalized_goal).
   * \return false (goal unchanged) for a non-finite element or one beyond the goal limit.
   */
  bool setGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot = base::Vector3::Zero());
  /// The goal mu_d [m/s, m/s, rad/s]; zero until setGoal().
  const base::Vector3& goal() const { return mu_d_; }
  /// The goal's rate mu_d' [m/s^2, m/s^2, rad/s^2] (zero unless generalized_goal).
  const base::Vector3& goalRate() const { return mu_d_dot_; }
  /// The predicted goal mu_hat_d = predictGoal(mu_d, mu_d', t_lead) with generalized_goal (t_lead =
  /// goal_lead for x_dot and y_dot, goal_lead_angular for theta_dot; the linear channels are not
  /// predicted through a stop), else mu_d [m/s, m/s, rad/s]: the reference model's input.
  base::Vector3 target() const;

  /**
   * \brief Start the path at m0 [m/s, m/s, rad/s]: m = m0, m' = 0, the delay line one sample at
   *        time 0, mu_r = m0, mu_r' = 0. The goal is kept.
   * \return false (unchanged) if m0 is not finite.
   */
  bool start(const base::Vector3& m0);
  /// Advance m and its delay line by h [s] (h finite and > 0) with the goal held; no effect
  /// without a reference model.
  void advance(double h);

  /// The undelayed path m [m/s, m/s, rad/s].
  const base::Vector3& path() const { return m_; }
  /**
   * \brief The undelayed path h [s] ahead with the goal held, m(t + h) [m/s, m/s, rad/s]: advance()'s
   *        exact step, without advancing. Unlike the extrapolation m + h m', it never passes the
   *        target: with T_r shorter than h the path is there before h.
   *
   * path() for h <= 0 or non-finite; target() without a reference model.
   */
  base::Vector3 pathAhead(double h) const;
  /// The path's rate m' = clamp((target() - m) / T_r, lo, hi) [m/s^2, m/s^2, rad/s^2], (lo, hi) =
  /// accelerationBounds(). Requires enabled().
  base::Vector3 rate() const;
  /// The path's largest acceleration per channel acc = (max_acceleration_linear,
  /// max_acceleration_linear, max_acceleration_angular) [m/s^2, m/s^2, rad/s^2].
  base::Vector3 accelerationLimit() const;
  /**
   * \brief The bounds lo <= m' <= hi of the path's rate at its present value m [m/s^2, m/s^2, rad/s^2].
   *
   * acc = accelerationLimit() both ways, except along x_dot when max_deceleration_linear > 0 (a
   * payload's tip-over bound; doc/usage.md, 'Payloads'): while m_x > 0, lo_x =
   * -max_deceleration_linear (braking forward); at rest and in reverse, lo_x = -min(acc,
   * max_deceleration_linear) (speeding up in reverse, which tips the robot over its front wheels as
   * braking forward does, and never looser than acc); while m_x < 0, hi_x = max_deceleration_linear
   * (braking in reverse); speeding up forward keeps acc. Then along x_dot lo >= -tipBoundFront(),
   * hi <= tipBoundRear() (setTipBounds()).
   */
  void accelerationBounds(base::Vector3* lo, base::Vector3* hi) const;
  /// The attractor's goal [m/s, m/s, rad/s]: mu_r = m(t - d_r) with a reference model, else mu_d.
  base::Vector3 attractorGoal() const { return enabled() ? mu_r_ : mu_d_; }
  /// The attractor's rate [m/s^2, m/s^2, rad/s^2]: mu_r' with a reference model, else mu_d'.
  base::Vector3 attractorRate() const { return enabled() ? mu_r_dot_ : mu_d_dot_; }
  /// The path's clock: the time advanced since start() [s].
  double time() const { return time_; }
  /// Samples in the delay line, 1 ... kLine.
  int lineSize() const { return count_; }

private:
  /// W(d, bound): each rim speed's change d_x -+ d_theta b / 2 of the body change d [m/s or m/s^2]
  /// clamped to [-bound, bound], d_x and d_theta recomputed; no change when max_acceleration_wheel is 0.
  void clampWheels(base::Vector3* d, double bound) const;
  /// The path's change over h [s] > 0 with the target held (advance()'s step) [m/s, m/s, rad/s].
  base::Vector3 stepChange(double h) const;
  /// One delay-line sample: time [s], m, m'.
  struct Sample
  {
    double t;
    base::Vector3 m;
    base::Vector3 m_dot;
  };

  params::ReferenceModelParams params_;
  double goal_limit_;              ///< largest accepted |element| of mu_d, mu_d'
  double wheel_separation_ = 0.5;  ///< b [m] of the wheel bound (setWheelSeparation())
  base::Vector3 mu_d_ = base::Vector3::Zero();
  base::Vector3 mu_d_dot_ = base::Vector3::Zero();
  base::Vector3 m_ = base::Vector3::Zero();
  double time_ = 0.0;
  std::array<Sample, kLine> line_{};
  int head_ = 0;                                                ///< index of the newest sample
  int count_ = 1;                                               ///< samples in the line
  base::Vector3 mu_r_ = base::Vector3::Zero();                  ///< the delayed path mu_r at time_
  base::Vector3 mu_r_dot_ = base::Vector3::Zero();              ///< its rate mu_r'
  double tip_front_ = std::numeric_limits<double>::infinity();  ///< setTipBounds()' front [m/s^2]
  double tip_rear_ = std::numeric_limits<double>::infinity();   ///< setTipBounds()' rear [m/s^2]
};

}  // namespace aic
}  // namespace jackal_aic
