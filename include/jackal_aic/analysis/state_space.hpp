#pragma once
/**
 * \file state_space.hpp
 * \brief Linear closed-loop model of the active inference controller for analysis
 *        (thesis ch. 4 and appendix A; doc/active_inference.md): beliefs + action +
 *        finite-difference generalizer + an optional first-order wheel-speed plant,
 *        discretized at the belief and the action rates (dual rate), with step response,
 *        spectral radius and stability scans. ROS-free.
 */

#include <string>
#include <vector>

#include <Eigen/Core>

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace analysis
{
/// Plant in the loop: the wheel-speed response to the command a.
struct PlantModel
{
  /// Kind of wheel-speed response.
  enum class Type
  {
    kPointMass,  ///< the wheels follow the command exactly and at once (thesis ch. 4: y = a)
    kFirstOrder  ///< per side d(omega)/dt = (a - omega) / time_constant
  };
  Type type = Type::kPointMass;  ///< kind of plant
  double time_constant = 0.1;    ///< [s], > 0 (first order only)
  /// Static gain K of the wheel loop [-], > 0: the wheels settle at K times the command
  /// (first order: d(omega)/dt = (K a(t - delay) - omega) / time_constant; point mass: omega = K a(t - delay)).
  double gain = 1.0;
  /// Dead time between a command and the wheel loop's response [s], >= 0, at most 50 action
  /// periods (the MCU's and the bus's latency; the simulated Jackal's wheel loop: ~0.12 s,
  /// doc/robot_data.md). Modelled exactly for a multiple of the action period and, in between,
  /// by splitting the period at the switching instant (the command is piecewise constant).
  double delay = 0.0;
};

/// One sample of a predicted response, at the start of an action period (just after the sensor sample).
struct ResponseSample
{
  double t;             ///< time since the step [s]
  base::Vector3 twist;  ///< plant body twist G omega (v_x [m/s], 0, omega_z [rad/s])
  base::Vector3 mu;     ///< belief mu^(0) [m/s, m/s, rad/s]
  base::Vector2 a;      ///< wheel speed command [rad/s]
};

/**
 * \brief The closed loop controller + plant as one linear, periodic discrete-time system.
 *
 * State z = [vec(mu_tilde) (3(p+1)), a (2), vec(y_tilde) (5(p+1)), omega (2), past commands (2L)],
 * sampled at the start of each action period T = 1/action_rate; L = ceil(delay / T) past
 * commands a_{k-1}, ..., a_{k-L} (none without delay). One period, in the order the node runs it:
 *  1. sensor sample of the plant: y^(0) = (gyro = G_3 omega, omega_L, omega_R, accel_x = G_1 d(omega)/dt, 0)
 *     (accel_x is 0 for the point mass), generalized with the thesis's Q (eq. 3-22) at h = T;
 *  2. N = belief_rate / action_rate belief steps of h = 1/belief_rate (Euler, eq. 3-15, or exact ZOH),
 *     measurement and goal held;
 *  3. one action step a += T da/dt (eq. 3-16);
 *  4. the plant over T with the delayed command a(t - delay) (point mass: omega = K a(t - delay) at
 *     the period's end; first order: exact ZOH over the two pieces of the period).
 * z_{k+1} = Phi z_k + Gamma mu_d. The continuous belief and action dynamics are taken from
 * ActiveInferenceController::muDot()/aDot() (so model and controller share one implementation
 * of the equations); the clamp, max_action_lead and the runaway reset are not modelled (linear analysis),
 * nor are the set-point dynamics, the action prior and the action's slew limit
 * (AicParams::reference.generalized_goal, reference_time_constant, action_prior_gain,
 * action_slew_limit: the model is the thesis's controller with the given gains). It represents
 * belief_model goal only: the unbiased model's prior on the delayed action and the robot model's
 * filter and latency action are not linear dynamics the probe of muDot()/aDot() sees, so another
 * belief model is refused (doc/extending.md, 'The stability model').
 */
class ClosedLoopModel
{
public:
  /**
   * \param params  controller parameters (rates, integrator and all gains are used)
   * \param plant   plant in the loop
   * \throws std::invalid_argument if params are invalid, belief_model is not goal, the plant time
   *         constant or gain is not > 0 and finite, the delay is negative, non-finite or above 50 action periods, or
   *         belief_rate / action_rate is not an integer (within 1e-9 relative)
   */
  ClosedLoopModel(const params::AicParams& params, const PlantModel& plant = PlantModel());

  /// Dimension of z: 3(p+1) + 2 + 5(p+1) + 2 + 2L.
  int stateDim() const { return static_cast<int>(phi_.rows()); }
  /// Belief steps per action period N.
  int beliefStepsPerPeriod() const { return n_belief_steps_; }
  /// Period map Phi (stateDim x stateDim).
  const Eigen::MatrixXd& phi() const { return phi_; }
  /// Goal input map Gamma (stateDim x 3).
  const Eigen::MatrixXd& gamma() const { return gamma_; }
  /// Largest |eigenvalue| of Phi.
  double spectralRadius() const;
  /// spectralRadius() < 1.
  bool stable() const { return spectralRadius() < 1.0; }

  /**
   * \brief Predicted response to a step of the goal from rest (z = 0) at t = 0.
   * \param mu_d      goal after the step (v_x [m/s], 0, omega_z [rad/s]), finite
   * \param duration  [s], > 0
   * \return one sample per action period, from t = 0 to duration.
   * \throws std::invalid_argument if duration is not > 0 or mu_d is not finite
   */
  std::vector<ResponseSample> stepResponse(const base::Vector3& mu_d, double duration) const;

  /// Continuous-time belief dynamics (eq. 3-15 before discretization): dmu/dt = M vec(mu) + N_y vec(y_tilde)
  /// + N_d mu_d; M is 3(p+1) x 3(p+1).
  const Eigen::MatrixXd& M() const { return m_; }

private:
  params::AicParams params_;
  PlantModel plant_;
  int n_belief_steps_ = 1;
  int i_w_ = 0;                    ///< index of omega in z
  Eigen::MatrixXd m_, n_y_, n_d_;  ///< belief dynamics
  Eigen::MatrixXd a_mu_, a_y_;     ///< action dynamics da/dt = a_mu vec(mu) + a_y vec(y)
  Eigen::MatrixXd phi_, gamma_;
};

/// Predicted step metrics of the forward speed v_x of the plant and of the action.
struct PredictedStep
{
  bool stable;             ///< spectral radius < 1
  double spectral_radius;  ///< of the period map
  StepMetrics velocity;    ///< metrics of v_x (NaN fields if unstable or undefined)
  bool velocity_valid;     ///< false if the metrics could not be computed (e.g. diverging response)
};

/**
 * \brief Predicts the step response of v_x from 0 to `target` [m/s] and its metrics
 *        (thesis ch. 4, 5; doc/active_inference.md).
 * \param params    controller parameters (valid)
 * \param plant     plant in the loop
 * \param target    goal v_x after the step [m/s], finite (0 gives velocity_valid = false)
 * \param duration  simulated time [s], > 0 (the steady-state error uses its last 0.5 s)
 * \return stability and metrics; an unstable or diverging response gives velocity_valid = false, not an error.
 * \throws std::invalid_argument as ClosedLoopModel's constructor and stepResponse() do (invalid params or
 *         plant, non-integer rate ratio, duration <= 0, non-finite target).
 */
PredictedStep predictStep(const params::AicParams& params, const PlantModel& plant, double target, double duration);

/// A parameter that a stability scan varies.
enum class ScanParameter
{
  kTau,  ///< smallest stable tau
  kKMu,  ///< largest stable k_mu
  kKA    ///< largest stable k_a
};

/// Result of a stability-limit scan.
struct StabilityLimit
{
  /// The limit [parameter units]: for tau the smallest stable value, for k_mu / k_a the largest;
  /// NaN if no value in the range is stable.
  double value;
  /// True if the whole range is stable (value is then the end of the range: a bound, not a limit).
  bool unbounded;
  /// Where the stable band found begins, seen from the stable end of the range (tau: its largest
  /// stable value; gains: the smallest). Equals the range end if that end is stable; otherwise the
  /// parameter is unstable between the range end and band_start too. NaN if nothing is stable.
  double band_start;
  /// True if the range end on the stable side (tau: hi; gains: lo) is stable.
  bool stable_at_range_end;
};

/**
 * \brief Stability limit of one parameter, others fixed, at the rates and integrator of params.
 *
 * A log-spaced grid over [lo, hi], walked from the end where the parameter is normally stable
 * (tau: hi; gains: lo), finds the first stable band; bisection in log space refines its edges to 0.1 %.
 * The limit is the edge of that band away from the stable end.
 * \param params       controller parameters; the scanned one is overwritten by each grid value
 * \param plant        plant in the loop
 * \param parameter    which of tau [s], k_mu [-], k_a [-] to vary
 * \param lo, hi       the range [parameter units], 0 < lo < hi, finite
 * \param grid_points  number of log-spaced grid values, >= 2
 * \throws std::invalid_argument on invalid params, a bad range or grid_points < 2.
 */
StabilityLimit scanStabilityLimit(const params::AicParams& params, const PlantModel& plant, ScanParameter parameter,
                                  double lo, double hi, int grid_points = 61);

}  // namespace analysis
}  // namespace jackal_aic
