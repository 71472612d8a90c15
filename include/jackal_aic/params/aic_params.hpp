#pragma once
/**
 * \file params.hpp
 * \brief Parameters of the active inference controller, with validation.
 *
 * One struct for the whole controller (rates, gains, precisions, robot geometry,
 * limits). A default-constructed AicParams is the thesis's "improved" controller as printed
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

namespace jackal_aic
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

/// \name Sanity bounds of AicParams::validate(), used by the parameter schema (guards against
/// absurd values that would overflow the free energy or its gradient; far outside any useful setting).
///@{
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
  /**
   * Anti-windup [rad/s], >= 0; 0 = off (the thesis controller). When > 0, after each action
   * step every wheel command a_i is kept within +-max_action_lead of the measured wheel speed
   * y^(0)[omega_i] (conditional integration). Not part of the thesis: the action update
   * (eq. 3-16) integrates the prediction error whatever the plant can follow, so while the
   * wheel loop is slew- or torque-limited on a large step the action runs ahead of the
   * wheels and the velocity overshoots when they catch up. In steady state a = measured
   * wheel speed, so the limit is inactive; set it above the lead the wheel loop needs for a
   * step the plant follows without saturating.
   */
  double max_action_lead = 0.0;
  /**
   * Anti-windup of turning [rad/s], >= 0; 0 = off. When > 0, after the max_action_lead clamp
   * the differential lead d = ((a_R - y[omega_R]) - (a_L - y[omega_L])) / 2 is kept within
   * +-max_action_lead_turn, the common lead unchanged (so each wheel's lead stays within
   * max_action_lead); not applied while a wheel channel is isolated (its reading is not trusted). A turn in place needs far more torque than a straight run (the wheels
   * skid sideways), so while the wheels are held by friction a lead that suits a straight
   * step winds the wheel loop up, and the turn overshoots when the wheels break free.
   * Not in the thesis; doc/experiments.md, 'Tuning'.
   */
  double max_action_lead_turn = 0.0;
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
  /**
   * Generalized goal [-]: false = every set point is a step (mu_d' = 0); true = the goal's rate
   * mu_d' is estimated from the set-point stream by finite differences (GoalRateEstimator:
   * goal_rate_hold, max_goal_rate_linear, max_goal_rate_angular) and the goal is predicted
   * t_lead ahead, mu_d + t_lead mu_d' (t_lead = goal_lead for x_dot and y_dot, goal_lead_angular
   * for theta_dot). Without a reference model (reference_time_constant 0) the attractor becomes
   * f(mu) = mu_d' + (mu_d - mu) / tau. Not in the thesis (its section
   * 6-1: a generative model "that predicts the path towards the desired state");
   * doc/active_inference.md, 'Set-point dynamics'.
   */
  bool generalized_goal = false;
  /// Generalized goal: a set-point change within this of the previous one [s] continues a ramp
  /// (mu_d' = change / interval); a later one is a step (mu_d' = 0); a slope is held for 1.25
  /// change intervals, at most this long. > 0, <= 10.
  double goal_rate_hold = 0.15;
  /// Generalized goal: |mu_d'| of x_dot is clamped to this [m/s^2]. > 0.
  double max_goal_rate_linear = 4.0;
  /// Generalized goal: |mu_d'| of theta_dot is clamped to this [rad/s^2]. > 0.
  double max_goal_rate_angular = 8.0;
  /// Generalized goal: the linear channels' goal (x_dot, y_dot) is predicted this far ahead
  /// along its rate [s], mu_d + goal_lead mu_d' (the wheel loop's latency). >= 0, <= 1.
  double goal_lead = 0.0;
  /// Generalized goal: the yaw rate's goal is predicted this far ahead along its rate [s]; a
  /// turn's body lags its wheels further than a speed change does (the tyres' lateral slip).
  /// >= 0, <= 1.
  double goal_lead_angular = 0.0;
  /**
   * Reference model T_r [s], >= 0, <= 10; 0 = off (the thesis: f(mu) = (mu_d - mu) / tau, eq. 3-7).
   * When > 0 the attractor is the path a wheel loop is expected to take to the (predicted) goal:
   * m' = (mu_d + t_lead mu_d' - m) / T_r, each channel's m' clamped to
   * max_reference_acceleration_linear / _angular, delayed by reference_delay, mu_r(t) = m(t - d_r),
   * and f(mu) = mu_r' + (mu_r - mu) / tau. The sensory prediction error then measures the
   * deviation from the expected path, not the path itself, so the free-energy action does not
   * wind up against the wheel loop's latency. doc/active_inference.md, 'Set-point dynamics'.
   */
  double reference_time_constant = 0.0;
  /// Reference model: the path's acceleration is clamped to this along x_dot [m/s^2], > 0 (the
  /// acceleration the wheels' torque allows: a rate-limited path is what a wheel loop with
  /// acceleration feed-forward follows best).
  double max_reference_acceleration_linear = 1.0e3;
  /// Reference model: as max_reference_acceleration_linear, along theta_dot [rad/s^2], > 0.
  double max_reference_acceleration_angular = 1.0e3;
  /// Reference model: each wheel's rim-speed rate along the path, |m'_x -+ m'_theta b_hat / 2|, is
  /// clamped to this [m/s^2], >= 0, before the body channels' bounds; 0 = none. A turn started with
  /// the forward speed then waits for the inner wheel, as the wheel loops do (ReferenceModel).
  double max_reference_acceleration_wheel = 0.0;
  /// Reference model: the path's deceleration along x_dot (a rate that slows it toward 0) is
  /// clamped to this [m/s^2], >= 0; 0 = max_reference_acceleration_linear. Below the deceleration
  /// g d / h at which the robot tips over its front (rear) wheels, d the horizontal distance of the
  /// centre of mass (with the payload) behind the front (ahead of the rear) axle, h its height
  /// above the ground (ReferenceModel::accelerationBounds; doc/usage.md, 'Payloads').
  double max_reference_deceleration_linear = 0.0;
  /// Reference model: the latency d_r [s] between a command and the wheels' response that the
  /// beliefs expect. >= 0, <= kMaxReferenceDelay.
  double reference_delay = 0.0;
  /// Unbiased beliefs: time constant T_g [s] of the goal's path as the robot is expected to
  /// follow it, the target of the action's goal prior (GoalResponse: g' = (mu_r - g) / T_g);
  /// >= 0, <= 10; 0 = off (the goal prior on the reference path mu_r itself). No effect with
  /// belief_model goal.
  double goal_response_time_constant = 0.0;
  /**
   * Action prior gain k_ff [-], in [0, 2]; 0 = off (the thesis: the action only descends the
   * free energy, eq. 3-16). The action is a = a_F + a_ff, a_ff = k_ff W (m + T_p m') (with no
   * reference model: k_ff W (mu_d + t_lead mu_d')), W the wheel rows of R (the inverse
   * kinematics G^+, eq. 3-3), T_p = action_prior_time_constant: the wheel speeds the goal's path
   * predicts, through the inverse of a first-order wheel loop, handed to the MCU's wheel-speed
   * loop as a reflex arc fulfils a proprioceptive prediction (Adams, Shipp & Friston, Brain
   * Struct. Funct. 2013); the free-energy gradient a_F (eq. 3-16) corrects what it does not
   * deliver. doc/active_inference.md, 'Action prior'.
   */
  double action_prior_gain = 0.0;
  /// Action prior: the wheel loop's time constant T_p [s] that the prior inverts (with a
  /// reference model only). >= 0, <= 10.
  double action_prior_time_constant = 0.0;
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
  /**
   * Learning of the effective wheel separation b_hat on the robot (not in the thesis): false =
   * b_hat = wheel_separation, fixed. true = b_hat descends the free energy of the gyro-encoder
   * disagreement at the belief rate (SeparationLearner; Baioumy, Duckworth, Lacerda & Hawes,
   * arXiv 2005.05894), starting from wheel_separation; doc/active_inference.md, 'Learning the
   * generative model'.
   */
  bool learn_wheel_separation = false;
  /// Learning rate kappa_b of b_hat [m^2 s / rad^2 per unit precision], >= 0, <= kMaxGain.
  double separation_learning_rate = 4.0;
  /// Lower bound of the learned b_hat [m], in [kMinLength, kMaxLength], <= separation_max.
  double separation_min = 0.3;
  /// Upper bound of the learned b_hat [m], in [kMinLength, kMaxLength].
  double separation_max = 1.5;
  /// b_hat is frozen while |gyro| is below this [rad/s], >= 0, <= 10.
  double separation_min_yaw_rate = 0.1;
  /// b_hat is frozen while |d gyro/dt| (y^(1) of the gyro) is above this [rad/s^2], > 0, <= kMaxGain.
  double separation_max_yaw_acceleration = 0.5;
  /// |db_hat/dt| <= separation_max_rate b_hat [1/s], >= 0, <= 10; 0 = unlimited.
  double separation_max_rate = 0.1;
  /**
   * Learning of the order-0 sensory precisions Pi_y^(0) of the gyro, the wheels (and accelerometer x
   * with accel_in_model) from the prediction errors seen (not in the thesis): false = Pi_y = 1 / var_y,
   * fixed. true = ln Pi_j descends the free energy, Pi_j -> 1 / E[eps_j^2] (PrecisionLearner;
   * Baioumy, Duckworth, Lacerda & Hawes, arXiv 2005.05894), starting from 1 / var_y;
   * doc/active_inference.md, 'Learning the sensory precisions'.
   */
  bool learn_precision = false;
  /// Learning rate kappa_pi of ln Pi_j [1/s], >= 0, <= kMaxGain (ln Pi relaxes with 2 / kappa_pi).
  double precision_learning_rate = 0.2;
  /// Lower bound of a learned precision as a factor of the configured one [-], > 0, <= 1.
  double precision_min_factor = 0.1;
  /// Upper bound of a learned precision as a factor of the configured one [-], >= 1, <= kMaxGain.
  double precision_max_factor = 10.0;
  /// Time constant T_w of the low-pass of the squared prediction errors [s], > 0, <= 1000.
  double precision_time_constant = 1.0;
  /// The precisions are frozen while both |omega_L|, |omega_R| are below this [rad/s], >= 0, <= 100.
  double precision_min_wheel_speed = 0.5;
  /**
   * Learning of the gyro's offset beta_hat at standstill (not in the thesis): false = the gyro is
   * used as it reads. true = beta_hat is the mean of the gyro's readings while the wheels and their
   * commands stand still, subtracted from every gyro sample (GyroBiasEstimator);
   * doc/active_inference.md, 'Learning the gyro's offset'.
   */
  bool learn_gyro_bias = false;
  /// |beta_hat| bound, and the largest |y_gyro| at rest taken as an offset [rad/s], > 0, <= 1.
  double gyro_bias_max = 0.1;
  /// At rest: both wheels' and both commands' |speed| below this [rad/s], > 0, <= 10.
  double gyro_bias_rest_speed = 0.05;
  /// beta_hat learns from this long after a rest began [s], >= 0, <= 10.
  double gyro_bias_rest_time = 0.5;
  /// Forgetting time constant T_beta once the first rest is averaged [s], > 0, <= 1e5.
  double gyro_bias_time_constant = 30.0;
  /// beta_hat is removed from the gyro once this much rest has been learned from [s], >= 0, <= 600.
  double gyro_bias_min_rest = 5.0;
  /**
   * Tip-over guard (not in the thesis): false = none. true = the body's pitch is integrated from
   * the IMU's gyro y; when it exceeds tip_guard_pitch while the robot brakes (speeds up), the
   * reference path stops braking (speeding up) until the body is level again, and later paths are
   * bounded by tip_guard_margin x the deceleration (acceleration) at which the wheels lifted
   * (TipGuard). It acts on the reference path: no effect with reference_time_constant 0;
   * doc/active_inference.md, 'The tip-over guard'.
   */
  bool tip_guard = false;
  /// |pitch| [rad] that trips the tip-over guard, > 0, <= 0.5.
  double tip_guard_pitch = 0.02;
  /// The learned bound is this factor of the wheels' acceleration at the lift's onset [-], in (0, 1]
  /// (braked wheels slip: their deceleration there is 1.2-1.5 x the body's tipping limit).
  double tip_guard_margin = 0.6;
  /// Floor of the tip-over guard's learned bounds [m/s^2], > 0, <= 100.
  double tip_guard_min_acceleration = 1.0;

  /// Number of generalized orders, p + 1.
  int numOrders() const { return embedding_order + 1; }

  /**
   * \brief Check every rule; report every violation (empty vector = valid).
   *
   * The ranges are those of the parameter schema (include/jackal_aic/params/param_spec.hpp,
   * the controller keys): rates finite, > 0 and <= kMaxRate; tau in [kMinTau, kMaxTau];
   * k_mu, k_a finite, > 0 and <= kMaxGain; 1 <= embedding_order <= kMaxEmbeddingOrder;
   * var_mu of size p+1 or 3(p+1), var_y of size p+1 or 5(p+1), every variance in
   * [kMinVariance, kMaxVariance]; wheel_radius, wheel_separation in [kMinLength, kMaxLength];
   * slip_factor in [kMinSlipFactor, kMaxSlipFactor]; max_wheel_speed in (0, kMaxWheelSpeedLimit];
   * runaway_limit in (0, kMaxRunawayLimit]; max_action_lead and max_action_lead_turn in [0, kMaxWheelSpeedLimit];
   * action_release_time in [0, 10];
   * integrator a known enumerator. Plus the cross rule belief_rate >= action_rate.
   * Each violation names the YAML key (e.g. "var_mu[2]"), the value and the allowed range.
   */
  std::vector<ParamViolation> validate() const;

  /// One line for logs: "belief B Hz, action A Hz, tau T s, k_mu K, k_a K, p P, integrator I".
  std::string summary() const;

  /// Precision Pi_mu^(i) per channel, 3 x (p+1) (column i = order i), 1/sigma^2. Requires a valid struct.
  MuTilde precisionMu() const;
  /// Precision Pi_y^(i) per channel, 5 x (p+1), 1/sigma^2. Requires a valid struct.
  YTilde precisionY() const;
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

}  // namespace jackal_aic
