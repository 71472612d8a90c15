#pragma once
/**
 * \file separation_learner.hpp
 * \brief Learning the generative model's effective wheel separation b_hat on the robot from the
 *        disagreement of gyro and wheel encoders: d b_hat / dt = -kappa_b dF_b / d b_hat
 *        (learning as free-energy descent on a model parameter: Baioumy, Duckworth, Lacerda &
 *        Hawes, arXiv 2005.05894; doc/active_inference.md, 'Learning the generative model').
 *        ROS-free.
 */

#include <cstdint>
#include <string>

#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Gradient descent of b_hat on the free energy of the gyro-encoder disagreement.
 *
 * The skid-steer model (thesis eq. 3-1) predicts the gyro from the wheel speeds,
 *   theta_dot = r alpha (omega_R - omega_L) / b_hat,
 * so with the sensory prediction error eps_b = y_gyro - r alpha (omega_R - omega_L) / b_hat and
 * its precision Pi_b, F_b = Pi_b eps_b^2 / 2 and
 *   dF_b / d b_hat = Pi_b eps_b r alpha (omega_R - omega_L) / b_hat^2,
 *   b_hat <- clamp(b_hat - h kappa_b dF_b / d b_hat, min, max).
 * Near a consistent b_hat the error decays with the time constant b_hat^2 / (kappa_b Pi_b theta_dot^2)
 * (faster turning, faster learning), and b_hat moves by at most max_rate b_hat per second: a fault
 * the fault monitor has not yet isolated (it needs fdi_detect_time) cannot be explained away by
 * b_hat in the meantime, which would also hide it from the monitor's residual (active inference's
 * slow timescale for parameters). The parameter is frozen (not moved) while a sensor the
 * disagreement needs is flagged by the fault monitor, near rest (|y_gyro| < min_yaw_rate: no
 * information about b_hat, and wheel dead-bands dominate), while the action saturates (the
 * wheels then slip against their limit and the kinematics do not hold), or in a transient
 * (|d y_gyro/dt| > max_yaw_acceleration: the tyres' lateral slip builds up with a lag, so gyro and
 * wheels disagree for a while whatever b_hat is; the wheels' yaw acceleration
 * r alpha (d omega_R/dt - d omega_L/dt) / b_hat is held to the same bound, so a gyro that stops
 * following a changing turn, frozen, does not teach the model), or while the disagreement is one no
 * plausible separation explains (the separation it implies, r alpha (omega_R - omega_L) / y_gyro,
 * is outside [kImplausibleFactor min, max / kImplausibleFactor] or of the wrong sign: a sensor
 * fault, not the model; the fault monitor isolates it fdi_detect_time later), or while the gyro's
 * reading repeats bit for bit (its finite-difference rate exactly 0: a live gyro's noise never
 * repeats while the robot turns, so this is a stuck sensor or a repeated message, no new
 * information; a frozen gyro would otherwise teach b_hat to follow the drift the frozen reading
 * causes, and hide the fault from the fault monitor's residual). Between the bounds and that
 * window b_hat moves to the bound it is clamped to.
 *
 * No heap allocation, no exceptions after construction.
 */
class SeparationLearner
{
public:
  /// The implied separation is implausible beyond [kImplausibleFactor min, max / kImplausibleFactor].
  static constexpr double kImplausibleFactor = 0.5;

  /// Why the last update() did or did not move b_hat.
  enum class State
  {
    kLearning,     ///< b_hat moved (or stayed at a bound)
    kSensorFault,  ///< frozen: the gyro or a wheel channel is flagged
    kNearRest,     ///< frozen: |y_gyro| < min_yaw_rate
    kSaturated,    ///< frozen: the action saturates
    kTransient,    ///< frozen: |d y_gyro/dt| or the wheels' |yaw acceleration| > max_yaw_acceleration
    kImplausible,  ///< frozen: the implied separation is outside [min / 2, 2 max] or negative
    kStuckGyro,    ///< frozen: d y_gyro/dt is exactly 0 (the reading repeats: a stuck gyro or a repeated message)
    kBadInput      ///< ignored: non-finite input, h <= 0 or precision < 0
  };

  /**
   * \param params        the learning's settings (AicParams::separation_learner; `enabled` is the
   *                      caller's): min finite and > 0, max >= min, rate, min_yaw_rate, max_rate
   *                      finite and >= 0, max_yaw_acceleration finite and > 0
   * \param wheel_radius  r [m], finite and > 0 (AicParams::wheel_radius)
   * \param slip_factor   alpha [-], finite and > 0 (AicParams::slip_factor)
   * \param initial       b_hat at construction and reset() [m], in [min, max] (the controller's
   *                      wheel_separation clamped to the bounds)
   * \throws std::invalid_argument naming every violated rule.
   */
  SeparationLearner(const params::SeparationLearnerParams& params, double wheel_radius, double slip_factor,
                    double initial);

  /**
   * \brief One learning step.
   * \param h           step [s], finite and > 0
   * \param gyro_z      measured yaw rate y_gyro [rad/s]
   * \param gyro_rate   its rate d y_gyro/dt [rad/s^2] (generalized order 1)
   * \param omega_l     measured left wheel speed [rad/s]
   * \param omega_r     measured right wheel speed [rad/s]
   * \param omega_l_rate its rate d omega_L/dt [rad/s^2] (generalized order 1)
   * \param omega_r_rate its rate d omega_R/dt [rad/s^2] (generalized order 1)
   * \param precision   Pi_b [1/(rad/s)^2], finite and >= 0 (e.g. the gyro's Pi_y^(0))
   * \param sensors_ok  false while the fault monitor flags the gyro or a wheel channel
   * \param saturated   true while the action is clamped (wheel speed, lead limits)
   * \return the reason the step did or did not learn; b_hat unchanged unless kLearning.
   */
  State update(double h, double gyro_z, double gyro_rate, double omega_l, double omega_r, double omega_l_rate,
               double omega_r_rate, double precision, bool sensors_ok, bool saturated);

  /// The learned effective wheel separation b_hat [m], within [min, max].
  double separation() const { return b_; }
  /// The gyro-encoder prediction error eps_b of the last learning step [rad/s] (0 before one).
  double predictionError() const { return eps_; }
  /// The state of the last update() (kNearRest before any).
  State state() const { return state_; }
  /// Number of update() calls that learned.
  std::uint64_t learningSteps() const { return steps_; }

  /// Set b_hat [m] (e.g. a value learned before, loaded from an overlay), clamped to [min, max].
  /// \return false (unchanged) if not finite.
  bool setSeparation(double b);
  /// Back to the initial b_hat; the step count and error cleared.
  void reset();
  /// The settings in use.
  const params::SeparationLearnerParams& params() const { return params_; }

private:
  params::SeparationLearnerParams params_;
  double wheel_radius_;
  double slip_factor_;
  double initial_;
  double b_;
  double eps_ = 0.0;
  State state_ = State::kNearRest;
  std::uint64_t steps_ = 0;
};

/// Name of a learner state, e.g. "near rest".
const char* toString(SeparationLearner::State state);

}  // namespace aic
}  // namespace jackal_aic
