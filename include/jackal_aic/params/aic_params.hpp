#pragma once
/**
 * \file params.hpp
 * \brief Parameters of the active inference controller, with validation.
 *
 * One struct for the whole controller (rates, gains, precisions, robot geometry,
 * limits), each stage's settings nested in it as the struct its stage takes
 * (include/jackal_aic/params/stage_params.hpp, robot_model_params.hpp). A default-constructed AicParams is the thesis's "improved" controller as printed
 * (table 5-8: belief loop 1 kHz, action loop 50 Hz, tau = 0.001, k_mu = 0.01, k_a = 8,
 * p = 3, forward Euler) with the variances of table C-1: the reference the analysis and
 * the controller's unit tests start from. It diverges on the Jackal at 1 kHz
 * (doc/active_inference.md, 'Analysis notes'); the node, the tools and the parameter schema
 * start from recommendedAicParams() instead (the schema's defaults). ROS-free.
 */

#include <string>
#include <vector>

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/param_violation.hpp"
#include "jackal_aic/params/robot_model_params.hpp"
#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace params
{
/// Integration scheme for the belief (and action) updates (doc/active_inference.md, 'Integrators').
enum class Integrator
{
  kEuler,  ///< forward Euler, as in the thesis (eq. 3-15, 3-16)
  kExact   ///< zero-order-hold exact discretization of the linear belief dynamics (Phi = exp(M h))
};

/// Parse "euler" / "exact" (case-sensitive). \return false if the name is unknown (out untouched).
bool integratorFromString(const std::string& name, Integrator* out);
/// "euler" or "exact".
std::string toString(Integrator integrator);

/// The state prior f of the beliefs (doc/active_inference.md, 'Unbiased beliefs').
enum class BeliefModel
{
  kGoal,      ///< the thesis: f(mu) = (mu_d - mu) / tau pulls the beliefs to the goal (eq. 3-7)
  kUnbiased,  ///< f(mu, a) = (G a(t - d_r) - mu) / tau, the robot's response to the action it sends;
              ///< the goal enters through the action (Baioumy, Pezzato, Ferrari & Hawes, IROS 2022)
  kRobot      ///< the identified model of the wheels through the latency and of the yaw rate
              ///< (RobotModelParams); the action descends F through it (doc/active_inference.md,
              ///< 'The robot model')
};

/// Parse "goal" / "unbiased" / "robot" (case-sensitive). \return false if the name is unknown (out untouched).
bool beliefModelFromString(const std::string& name, BeliefModel* out);
/// "goal", "unbiased" or "robot".
std::string toString(BeliefModel model);

/// The longest belief or action step the controller takes [s]: ActiveInferenceController refuses a
/// longer one (kBadInterval), and the node's loops clamp their intervals to it (a loop stalled for
/// longer has stale sensors; the stall is integrated as this long). A step predicts the robot over
/// its whole interval, the robot model in 1 ms substeps (WheelLoopModel::kSubstep), so its cost is
/// bounded by this.
constexpr double kMaxStep = 1.0;

/// \name Sanity bounds of AicParams::validate(), used by the parameter schema (guards against
/// absurd values that would overflow the free energy or its gradient; far outside any useful setting).
///@{
constexpr double kMinRate = 1.0 / kMaxStep;    ///< smallest belief/action rate [Hz] (a period of at most kMaxStep)
constexpr double kMaxRate = 1.0e6;             ///< largest belief/action rate [Hz]
constexpr double kMinTau = 1.0e-6;             ///< smallest tau [s]
constexpr double kMaxTau = 1.0e3;              ///< largest tau [s]
constexpr double kMaxGain = 1.0e6;             ///< largest k_mu and k_a [-]
constexpr double kMinVariance = 1.0e-9;        ///< smallest sigma^2 (precision <= 1e9)
constexpr double kMaxVariance = 1.0e12;        ///< largest sigma^2
constexpr double kMinLength = 1.0e-4;          ///< smallest wheel_radius, wheel_separation [m]
constexpr double kMaxLength = 100.0;           ///< largest wheel_radius, wheel_separation [m]
constexpr double kMinSlipFactor = 1.0e-3;      ///< smallest slip_factor [-]
constexpr double kMaxSlipFactor = 1.0e3;       ///< largest slip_factor [-]
constexpr double kMaxWheelSpeedLimit = 1.0e4;  ///< largest max_wheel_speed [rad/s]
constexpr double kMaxRunawayLimit = 1.0e12;    ///< largest runaway_limit
constexpr double kMaxReferenceDelay = 0.4;     ///< largest reference_delay [s] (the controller's delay line)
///@}

/**
 * \brief Parameters of ActiveInferenceController (thesis tables C-1 and 5-8).
 *
 * Variances: `var_mu` and `var_y` hold sigma^2 per generalized order; precisions are
 * Pi = 1 / sigma^2 (following Pezzato et al. 2020's var_q / var_mu; doc/active_inference.md).
 * Either p+1 values (one scalar per order, used for every channel) or, optionally,
 * one value per channel and order, order-major: 3(p+1) values for var_mu
 * (index i*3 + channel) and 5(p+1) values for var_y (index i*5 + channel).
 */
struct AicParams
{
  double belief_rate = 1000.0;  ///< belief update rate [Hz], > 0, >= action_rate
  double action_rate = 50.0;    ///< action update rate [Hz], > 0
  double tau = 0.001;           ///< attractor time constant tau [s], > 0 (eq. 3-7)
  double k_mu = 0.01;           ///< belief learning rate k_mu [-], > 0 (eq. 3-15)
  double k_a = 8.0;             ///< action learning rate k_a [-], > 0 (eq. 3-16)
  int embedding_order = 3;      ///< p: generalized orders 0..p, 1 <= p <= kMaxEmbeddingOrder

  /// sigma^2_mu per order (size p+1) or per order and channel (size 3(p+1)); each finite and > 0.
  std::vector<double> var_mu{ 1.5, 2.0, 4.0, 8.0 };
  /// sigma^2_y per order (size p+1) or per order and channel (size 5(p+1)); each finite and > 0.
  std::vector<double> var_y{ 2.0, 2.0, 1.0e5, 1.0e5 };

  double wheel_radius = 0.098;       ///< r [m], > 0
  double slip_factor = 1.0;          ///< alpha [-], > 0
  double wheel_separation = 0.5621;  ///< virtual wheel separation b_hat [m], > 0
  double max_wheel_speed = 20.0;     ///< |a_i| clamp [rad/s], > 0 (2.0 m/s top speed / 0.098 m ~ 20.4 rad/s)
  /// Beliefs whose any element exceeds this magnitude are declared runaway [SI units of each order], > 0.
  double runaway_limit = 1.0e3;
  /// The anti-windup of the action (AntiWindupParams: max_action_lead, max_action_lead_turn).
  AntiWindupParams anti_windup;
  /**
   * Release of the free-energy action at rest [s], >= 0, <= 10; 0 = off. When > 0, after each
   * action step the part of a_F that drives a channel whose goal is zero decays as
   * exp(-h / action_release_time): the common part (a_F,L + a_F,R) / 2 while the linear goal is
   * zero, the differential part (a_F,R - a_F,L) / 2 while the yaw-rate goal is zero. What a_F has
   * integrated (a turn deficit, a payload, a wheel held by friction) belongs to the motion that
   * needed it; a stop command must stop the wheels, as the stock base's zero command does, and
   * not leave them pushed by a correction that friction absorbs. Not in the thesis;
   * doc/active_inference.md, 'Update rules'.
   */
  double action_release_time = 0.0;
  /// The slew limit of the action (ActionSlewLimitParams: action_slew_limit).
  ActionSlewLimitParams action_slew;
  /// The goal stage (ReferenceModelParams: generalized_goal, goal_rate_hold, max_goal_rate_*,
  /// goal_lead, goal_lead_angular, reference_time_constant, max_reference_*, reference_delay).
  ReferenceModelParams reference;
  /// Unbiased beliefs: time constant T_g [s] of the goal's path as the robot is expected to
  /// follow it, the target of the action's goal prior (GoalResponse: g' = (mu_r - g) / T_g);
  /// >= 0, <= 10; 0 = off (the goal prior on the reference path mu_r itself). No effect with
  /// belief_model goal.
  double goal_response_time_constant = 0.0;
  /// The action prior (ActionPriorParams: action_prior_gain, action_prior_time_constant).
  ActionPriorParams action_prior;
  /// If true, the accelerometer-x row of R maps onto mu^(1) (kinematically better option, not in the thesis):
  /// eps_y^(i)[accel_x] = y^(i)[accel_x] - x_dot^(i+1) for i < p (and the gradient gains the matching
  /// term); K is unchanged (the accelerometer depends on da/dt, not a). false = thesis model
  /// (accelerometer rows zero). Note: /imu/data includes gravity; on level ground accel x has none.
  bool accel_in_model = false;
  Integrator integrator = Integrator::kEuler;  ///< belief integrator
  /**
   * The beliefs' state prior. kGoal (the thesis): f(mu) = (mu_d - mu) / tau (eq. 3-7, with the
   * reference model and generalized goal as above). kUnbiased: f(mu, a) = (G a(t - d_r) - mu) / tau,
   * a first-order lag tau of the body twist the sent action a commands (G: eq. 3-1), delayed by
   * reference_delay d_r, so the beliefs estimate the robot's state; the action then descends the
   * free energy of the goal prior on its outcome, da_F/dt = -k_a sum_i K Pi_y^(i) R (mu^(i) - g^(i)),
   * g = (mu_r, mu_r', 0, ...), plus the action prior a_ff (Baioumy, Pezzato, Ferrari & Hawes,
   * IROS 2022; doc/active_inference.md, 'Unbiased beliefs').
   */
  BeliefModel belief_model = BeliefModel::kGoal;
  /// The robot model's settings (belief_model robot only; doc/active_inference.md, 'The robot model').
  RobotModelParams robot;
  /// Learning the wheel separation b_hat (SeparationLearnerParams: learn_wheel_separation, separation_*).
  SeparationLearnerParams separation_learner;
  /// Learning the sensory precisions (PrecisionLearnerParams: learn_precision, precision_*).
  PrecisionLearnerParams precision_learner;
  /// Learning the gyro's offset (GyroBiasEstimatorParams: learn_gyro_bias, gyro_bias_*).
  GyroBiasEstimatorParams gyro_bias;
  /// The tip-over guard (TipGuardParams: tip_guard, tip_guard_*).
  TipGuardParams tip_guard;

  /// Number of generalized orders, p + 1.
  int numOrders() const { return embedding_order + 1; }

  /**
   * \brief Check every rule; report every violation (empty vector = valid).
   *
   * The ranges are those of the parameter schema (include/jackal_aic/params/param_spec.hpp,
   * the controller keys): rates finite, >= kMinRate and <= kMaxRate; tau in [kMinTau, kMaxTau];
   * k_mu, k_a finite, > 0 and <= kMaxGain; 1 <= embedding_order <= kMaxEmbeddingOrder;
   * var_mu of size p+1 or 3(p+1), var_y of size p+1 or 5(p+1), every variance in
   * [kMinVariance, kMaxVariance]; wheel_radius, wheel_separation in [kMinLength, kMaxLength];
   * slip_factor in [kMinSlipFactor, kMaxSlipFactor]; max_wheel_speed in (0, kMaxWheelSpeedLimit];
   * runaway_limit in (0, kMaxRunawayLimit]; max_action_lead and max_action_lead_turn in [0, kMaxWheelSpeedLimit];
   * action_release_time in [0, 10]; action_slew_limit in [0, kMaxGain];
   * integrator a known enumerator. Plus the cross rule belief_rate >= action_rate.
   * Each violation names the YAML key (e.g. "var_mu[2]"), the value and the allowed range.
   */
  std::vector<ParamViolation> validate() const;

  /// One line for logs: "belief B Hz, action A Hz, belief model M, " then, for the goal and unbiased
  /// models, "tau T s, k_mu K, k_a K, p P, integrator I", for the robot model "latency L s (learned |
  /// fixed), action_gain K 1/s, b_hat_0 B m" (its keys; the others have no effect).
  std::string summary() const;

  /// Precision Pi_mu^(i) per channel, 3 x (p+1) (column i = order i), 1/sigma^2. Requires a valid struct.
  base::MuTilde precisionMu() const;
  /// Precision Pi_y^(i) per channel, 5 x (p+1), 1/sigma^2. Requires a valid struct.
  base::YTilde precisionY() const;
  /// The precisions the belief model weighs the sensors by, 5 x (p+1) [1/(channel unit)^2]: the
  /// goal and unbiased models' precisionY(); the robot model's measured noises at order 0,
  /// 1 / robot.gyro_noise^2 and 1 / robot.encoder_noise^2 (doc/active_inference.md, 'The robot
  /// model'), zero for the accelerometers and the higher orders, which it does not read.
  /// Requires a valid struct.
  base::YTilde modelPrecisionY() const;
};

/**
 * \brief The recommended controller, the one place its values are written: what the node, the
 *        tools and cfg/AIC.cfg use for a key no YAML sets (NodeParams::aic; config/default.yaml
 *        sets none of them). Tuned for real driving on the measure of
 *        scripts/aic_tune.py --driving on the simulated Jackal (doc/active_inference.md, 'Parameter
 *        sets of the thesis'; doc/experiments.md, 'Tuning'; figures in doc/results/scorecard.txt): table 5-8's rates with the exact integrator,
 *        p = 2, the generalized goal, the rate-limited reference model and the action prior
 *        (doc/active_inference.md, 'Set-point dynamics', 'Action prior'), max_action_lead on,
 *        max_action_lead_turn off, action_release_time on. Valid (validate() empty).
 */
AicParams recommendedAicParams();

/**
 * \brief True if the controller learns the latency L: belief_model robot with robot.learn_latency
 *        (doc/active_inference.md, 'Learning the latency'); the other belief models keep the
 *        configured L.
 */
bool learnsLatency(const AicParams& params);

/**
 * \brief True if the controller learns its sensory precisions Pi_y^(0): belief_model goal or
 *        unbiased with precision_learner.enabled (doc/active_inference.md, 'Learning the sensory
 *        precisions'); the robot model weighs its sensors by their measured noises instead.
 */
bool learnsPrecision(const AicParams& params);

/**
 * \brief The robot model's largest wheel acceleration at the rim, A_w r alpha [m/s^2]
 *        (robot.wheel_acceleration [rad/s^2], wheel_radius [m], slip_factor [-]): the bound of its
 *        goal's path per wheel and, over the separation, of the goal's rate
 *        (doc/active_inference.md, 'The robot model').
 */
double robotWheelAcceleration(const AicParams& params);

/**
 * \brief The goal stage's settings for the set-point stream's rate estimator (GoalRateEstimator):
 *        params.reference, but with belief_model robot the bounds of the goal's predicted rate,
 *        max_goal_rate_linear and max_goal_rate_angular, are held within what the wheel loop's
 *        wheels can follow: |x_dot'| <= min(max_goal_rate_linear, A_w r alpha) and
 *        |theta_dot'| <= min(max_goal_rate_angular, 2 A_w r alpha / b_0) [m/s^2, rad/s^2]
 *        (A_w = robot.wheel_acceleration, r = wheel_radius, alpha = slip_factor,
 *        b_0 = wheel_separation; doc/active_inference.md, 'Set-point dynamics' and 'The robot model').
 * \param params  validated (b_0 > 0)
 */
ReferenceModelParams goalRateParams(const AicParams& params);

}  // namespace params
}  // namespace jackal_aic
