#pragma once
/**
 * \file controller.hpp
 * \brief The active inference controller for a skid-steer robot's body velocity
 *        (van der Meer 2022, thesis eq. 3-6 ... 3-16; Pezzato et al. 2020), composed of its
 *        stages (doc/active_inference.md, 'Structure of the controller'). ROS-free.
 */

#include <cstdint>

#include "jackal_aic/aic/action_delay_line.hpp"
#include "jackal_aic/aic/action_prior.hpp"
#include "jackal_aic/aic/action_slew_limit.hpp"
#include "jackal_aic/aic/anti_windup.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/aic/precision_learner.hpp"
#include "jackal_aic/aic/goal_response.hpp"
#include "jackal_aic/aic/latency_action.hpp"
#include "jackal_aic/aic/robot_belief.hpp"
#include "jackal_aic/aic/latency_learner.hpp"
#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/aic/reference_model.hpp"
#include "jackal_aic/aic/rest_release.hpp"
#include "jackal_aic/aic/separation_learner.hpp"
#include "jackal_aic/aic/skid_steer_model.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Active inference controller: beliefs mu_tilde (3 x (p+1)), action a (2) [rad/s].
 *
 * Usage (double loop, thesis table 5-8; doc/active_inference.md, 'Update rules'):
 * setGoal(mu_d); whenever a generalized sensor sample arrives, setMeasurement(y_tilde);
 * at the belief rate updateBeliefs(h_mu); at the action rate updateAction(h_a); send action().
 * Neither update moves before the first setMeasurement().
 *
 * The controller holds the thesis's beliefs mu_tilde and action a (the free-energy part a_F,
 * eq. 3-15, 3-16) and composes these nine stages, each off with its parameter at the thesis
 * value, each taking its settings struct nested in AicParams as it is:
 *  - ReferenceModel (AicParams::reference): goal mu_d, mu_d' -> predicted goal -> delayed
 *    reference path (the attractor);
 *  - ActionDelayLine (reference.delay): the twist G a(t - d_r) of the sent action (belief_model
 *    unbiased's prior);
 *  - GoalResponse (goal_response_time_constant): the goal's path as the robot is expected to
 *    follow it (belief_model unbiased's goal prior on the action);
 *  - ActionPrior (action_prior): a_ff, the wheel speeds of the goal's path (a = a_F + a_ff);
 *  - RestRelease (action_release_time): a_F's part along a channel whose goal is zero decays;
 *  - AntiWindup (anti_windup, max_wheel_speed): the lead and wheel-speed clamps and the
 *    conditional integration of a_F;
 *  - ActionSlewLimit (action_slew): each wheel command's rate of change bounded, after the clamps;
 *  - SeparationLearner (separation_learner): learning the model's effective wheel separation b_hat;
 *  - PrecisionLearner (precision_learner): learning the order-0 sensory precisions.
 * With belief_model robot, WheelLoopModel, RobotBelief and LatencyAction (AicParams::robot)
 * replace the belief and action updates. The order the stages run in, with the sample pipeline's
 * and the control loop's around them: include/jackal_aic/loop/control_loop.hpp, 'The
 * controller's composition'; updateBeliefs() and updateAction() are its two middle parts.
 *
 * Not thread-safe; no heap allocation and no exceptions in setGoal,
 * setMeasurement, updateBeliefs, updateAction (the matrix exponential of the exact
 * integrator is recomputed only when h or the parameters change).
 */
class ActiveInferenceController
{
public:
  /// Result of an update.
  enum class Status
  {
    kOk,             ///< state advanced
    kNoMeasurement,  ///< no measurement yet: state not moved
    kBadInterval,    ///< h <= 0, non-finite or > params::kMaxStep: state not moved
    kRunaway         ///< beliefs or action became non-finite, a belief exceeded runaway_limit, or one action
                     ///< step moved a wheel's command by more than 2 max_wheel_speed (a diverging action):
                     ///< beliefs and action reset to zero (goal and held measurement kept), runawayCount()
                     ///< incremented
  };

  /// \throws std::invalid_argument listing every violation if params.validate() is not empty.
  explicit ActiveInferenceController(const params::AicParams& params);

  /**
   * \brief Replace the parameters. If the embedding order changes the state is reset,
   *        otherwise beliefs and action are kept (the action clamped to the new max_wheel_speed).
   * \throws std::invalid_argument (state unchanged) if params.validate() is not empty.
   */
  void setParams(const params::AicParams& params);
  /// The parameters in use (always valid).
  const params::AicParams& params() const { return params_; }
  /// The generative model (G, R, K; eq. 3-1 ... 3-4) built from params().
  const SkidSteerModel& model() const { return model_; }

  /**
   * \brief Desired twist mu_d = (v_x [m/s], 0, omega_z [rad/s]) and its rate mu_d' [m/s^2, m/s^2,
   *        rad/s^2] (used only with params().reference.generalized_goal). The attractor (eq. 3-7, extended,
   *        doc/active_inference.md 'Set-point dynamics'):
   *        no reference model: f(mu) = mu_d' + (mu_d - mu) / tau;
   *        reference model (reference_time_constant T_r > 0): f(mu) = mu_r' + (mu_r - mu) / tau
   *        with mu_r(t) = m(t - d_r), m' = (mu_d + t_lead mu_d' - m) / T_r advanced with the
   *        beliefs (updateBeliefs()); t_lead per channel (goal_lead, goal_lead_angular).
   * \return false (goal unchanged) for a non-finite element or one beyond runaway_limit.
   */
  bool setGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot = base::Vector3::Zero());
  /// The goal mu_d in use [m/s, m/s, rad/s]; zero until setGoal().
  const base::Vector3& goal() const { return reference_.goal(); }
  /// The goal's rate mu_d' in use [m/s^2, m/s^2, rad/s^2] (zero unless params().reference.generalized_goal).
  const base::Vector3& goalRate() const { return reference_.goalRate(); }
  /// The attractor's goal mu_r [m/s, m/s, rad/s]: the delayed reference path m(t - d_r) with a
  /// reference model, else mu_d.
  base::Vector3 attractorGoal() const;
  /**
   * \brief The target of the beliefs' state prior f(mu) = g' + (g - mu) / tau [m/s, m/s, rad/s]:
   *        belief_model goal: g = attractorGoal() (eq. 3-7, extended); belief_model unbiased:
   *        g = G a(t - d_r), the body twist of the action sent reference_delay d_r ago
   *        (ActionDelayLine: zero-order hold over the action steps; the delay line holds kActionLine
   *        steps, a longer delay uses the oldest), g' = 0 (doc/active_inference.md, 'Unbiased beliefs').
   */
  base::Vector3 priorGoal() const;
  /// The rate g' of priorGoal() [m/s^2, m/s^2, rad/s^2]: attractorRate() (goal), zero (unbiased).
  base::Vector3 priorRate() const;
  /**
   * \brief Start the reference model at the twist m0 [m/s, m/s, rad/s] (its whole delay line;
   *        e.g. the measured twist at a bumpless start) and the goal's expected response
   *        (GoalResponse) with it. No effect on anything else.
   * \return false (unchanged) if m0 is not finite.
   */
  bool startReference(const base::Vector3& m0);
  /**
   * \brief The action prior a_ff [rad/s] = k_ff W (m + T_p m') with a reference model, else
   *        k_ff W (mu_d + t_lead mu_d') (W: the wheel rows of R, the inverse kinematics G^+ of
   *        eq. 3-3; k_ff = action_prior_gain, T_p = action_prior_time_constant): the wheel speeds
   *        the goal's path predicts (ActionPrior). Zero when action_prior_gain is 0.
   */
  base::Vector2 actionPrior() const;

  /**
   * \brief Latest generalized measurement y_tilde (5 x (p+1)), held until the next one.
   * \param wheels_repeated  the joint state repeats the previous one exactly, travel and speeds
   *        (jackal_node re-published the MCU's last reading: a reading one MCU period late, no new
   *        information): the robot model takes no wheel reading from this sample (its gyro reading
   *        is new); the goal and unbiased models, which low-pass the wheels, ignore the flag
   * \return false (and ignored) if it has the wrong number of columns, a non-finite entry, or an
   *         entry beyond kMaxMeasurementMagnitude.
   */
  bool setMeasurement(const base::YTilde& y_tilde, bool wheels_repeated = false);
  /// True once a measurement has been accepted (since construction or the last reset()).
  bool hasMeasurement() const { return has_measurement_; }

  /**
   * \brief One belief step (thesis eq. 3-15) with the measurement and goal held.
   *
   * Euler: mu_tilde += h * (D mu_tilde - k_mu dF/dmu_tilde).
   * Exact: the belief dynamics are linear, dx/dt = M x + c with x = vec(mu_tilde) and c constant
   * over the step, so x(h) = x + Psi(h) (M x + c) with Psi(h) = int_0^h exp(M s) ds, computed with
   * exp([[M, I], [0, 0]] h0) (Eigen MatrixFunctions) when the parameters change or
   * |h - h0| ||M||_inf exceeds kExactSeriesLimit, otherwise reused through
   * Psi(h) = Psi(h0) + exp(M h0) Psi(h - h0), Psi(dh) by its series to the dh^3 term (a
   * jittery loop interval then costs three matrix-vector products, not an exponential).
   * Stable for any h > 0 when the continuous dynamics are.
   * \param h  belief step [s], finite, > 0 and <= params::kMaxStep
   * \return kOk; kBadInterval (state kept); kNoMeasurement (state kept); kRunaway (see Status).
   */
  Status updateBeliefs(double h);

  /**
   * \brief One action step. First, if action_release_time T_rel > 0 (RestRelease), the common part
   *        (a_F,L + a_F,R) / 2 of a_F decays by exp(-h / T_rel) while the linear goal is zero
   *        and the differential part (a_F,R - a_F,L) / 2 while the yaw-rate goal is zero
   *        (release at rest, not in the thesis; doc/active_inference.md, 'Update rules').
   *        Then a = a_F + a_ff with a_F += h * (-k_a sum_i K Pi_y^(i) eps_y^(i))
   *        (eq. 3-16) and a_ff = actionPrior() (zero with action_prior_gain 0: the thesis), then
   *        clamp to within +-max_action_lead of the measured wheel speeds y^(0)[omega_L],
   *        y^(0)[omega_R] (widened to include a_ff: the prior alone is never cut) if
   *        max_action_lead > 0, the wheels' differential lead to
   *        +-max_action_lead_turn if > 0 (AntiWindup, not in the thesis; not applied to a wheel
   *        whose channel setSensorMask() masked), and to +-max_wheel_speed. Anti-windup:
   *        where a clamp cut a wheel's command in the direction a_F integrates, a_F integrates
   *        only up to the clamp and is never pulled back by it (a cut of the prior is not stored).
   *        Then, if action_slew_limit S > 0 (ActionSlewLimit), the change of the command since the
   *        previous step is scaled down so that neither wheel's exceeds S h, a_F integrating
   *        behind it in the same way.
   *        da_F/dt does not depend on a, so this Euler step is exact for held beliefs and
   *        measurement, whatever the integrator setting.
   *        Divergence, checked before any clamp: a non-finite a, or a step h da_F/dt beyond
   *        2 max_wheel_speed on a wheel (more than the wheels' whole speed range in one step),
   *        resets beliefs and action to zero (kRunaway) instead of clamping it to
   *        +-max_wheel_speed.
   * \param h  action step [s], finite, > 0 and <= params::kMaxStep
   * \return kOk; kBadInterval (state kept); kNoMeasurement (state kept); kRunaway (see Status).
   */
  Status updateAction(double h);

  /// Zero beliefs and action, forget the measurement (goal kept).
  void reset();
  /// Set the action a = (omega_L, omega_R) [rad/s] (e.g. to the measured wheel speeds for a bumpless start);
  /// clamped to +-max_wheel_speed; a non-finite input is ignored (action unchanged). The free-energy
  /// part becomes a - actionPrior(), so the next step does not jump.
  void setAction(const base::Vector2& a);

  const base::MuTilde& mu() const { return mu_; }          ///< beliefs, 3 x (p+1)
  const base::Vector2& action() const { return a_; }       ///< wheel speed commands (omega_L, omega_R) [rad/s]
  const base::YTilde& yTilde() const { return y_tilde_; }  ///< held measurement, 5 x (p+1)

  /// Sensory prediction errors eps_y^(i) = y^(i) - R mu^(i), 5 x (p+1) (eq. 3-8).
  base::YTilde epsY() const;
  /// State prediction errors eps_mu^(i), 3 x (p+1) (eq. 3-9).
  base::MuTilde epsMu() const;
  /// Variational free energy F (eq. 3-10) at the current state [-].
  double freeEnergy() const;
  /// The sensory part of F, (1/2) sum_i eps_y^(i)T Pi_y^(i) eps_y^(i) [-] (eq. 3-10, first sum).
  double sensoryFreeEnergy() const;
  /// The prior part of F, (1/2) sum_i eps_mu^(i)T Pi_mu^(i) eps_mu^(i) [-] (eq. 3-10, second sum);
  /// sensoryFreeEnergy() + priorFreeEnergy() = freeEnergy() up to rounding.
  double priorFreeEnergy() const;
  /// Gradient dF/dmu_tilde, 3 x (p+1) (eq. 3-13).
  base::MuTilde dFdMu() const;
  /// Belief rate of change dmu_tilde/dt = D mu_tilde - k_mu dF/dmu_tilde, 3 x (p+1) (eq. 3-15).
  base::MuTilde muDot() const;
  /// Action rate of change da/dt = -k_a sum_i K Pi_y^(i) eps_y^(i) [rad/s^2] (eq. 3-16); with
  /// belief_model unbiased eps_y is replaced by eps_g^(i) = R (mu^(i) - g^(i)), g = (mu_r, mu_r', 0, ...)
  /// the goal's path (the goal prior on the action; doc/active_inference.md, 'Unbiased beliefs').
  base::Vector2 aDot() const;

  /**
   * \brief Use only some sensor channels: Pi_y^(i) of every order is set to zero for a channel whose
   *        bit is clear (fault isolation, Baioumy et al. ECC 2021; doc/active_inference.md, 'Fault
   *        detection and isolation'), so eps_y of that channel leaves the free energy (eq. 3-10), the
   *        belief update (eq. 3-15) and the action update (eq. 3-16). Kept across setParams().
   * \param mask  bit j (SensorIndex) set = channel j used; bits above kYDim are ignored
   * Recomputes the belief dynamics (and, for the exact integrator, its matrix exponential at the next
   * step) only if the mask changes. No heap allocation.
   */
  void setSensorMask(std::uint8_t mask);
  /// The channel mask in use (all kYDim bits set by default).
  std::uint8_t sensorMask() const { return sensor_mask_; }
  /**
   * \brief The fault monitor's state for the robot model's beliefs (belief_model robot; no effect on
   *        the others, whose monitor tests against their goal-pulled beliefs as before).
   * \param suspected  a fault is suspected and not yet confirmed (FaultMonitor::awaitingConfirmation()):
   *                   a sample does not correct the beliefs, which follow the model, so the test that
   *                   isolates a channel (agreement with the beliefs) compares with the model's
   *                   prediction, not with beliefs already pulled toward the faulty channel
   * \param present    a fault is present, confirmed or not (FaultMonitor::faultPresent()): the slow
   *                   states (shortfalls' jumps, slip ratio, gyro offset) learn nothing, as under a mask
   * Kept across setParams() and reset(); cleared by passing false.
   */
  void setFaultState(bool suspected, bool present);
  /**
   * \brief The offset removed from the gyro before setMeasurement() (the offset learned at rest,
   *        GyroBiasEstimator) changed by `change` [rad/s]: the robot model's gyro offset beta, the
   *        offset that remains, moves by -change, so the model's reading theta_dot + beta of the
   *        same gyro stays what it was (RobotBelief::shiftGyroOffset()). No effect on the other
   *        belief models or for a non-finite change.
   */
  void gyroOffsetRemoved(double change);
  /// Precisions Pi_y in use, 5 x (p+1): params().modelPrecisionY() (learned with learnsPrecision())
  /// with the masked channels' rows zero.
  const base::YTilde& precisionY() const { return pi_y_; }

  /**
   * \brief The learner of the effective wheel separation b_hat (params().separation_learner.enabled;
   *        doc/active_inference.md, 'Learning the generative model'). It steps with updateBeliefs()
   *        on y^(0) of the gyro and wheels, with Pi_b = Pi_y^(0) of the gyro, frozen while the
   *        sensor mask isolates one of them or actionSaturated(); the model's
   *        G, R, K take its b_hat whenever it moved by more than kSeparationApplyTolerance
   *        (relative) from the b_hat in use.
   */
  const SeparationLearner& separationLearner() const { return learner_; }
  /// The goal stage: goal, predicted goal, reference path and its delay line.
  const ReferenceModel& referenceModel() const { return reference_; }
  /// Bound the reference path's rate along x_dot to [-front, rear] [m/s^2] (the TipGuard's
  /// bounds; +inf = none; ReferenceModel::setTipBounds). No effect without a reference model.
  void setTipBounds(double front, double rear) { reference_.setTipBounds(front, rear); }
  /// The TipGuard's turned-over state (TipGuard::turnedOver()): while true every action step
  /// commands zero and restarts the reference path from rest (stopTurnedOver()), in every belief
  /// model.
  void setTurnedOver(bool turned_over) { turned_over_ = turned_over; }
  /// True while setTurnedOver(true) holds the command at zero.
  bool turnedOver() const { return turned_over_; }
  /// The delay line of the sent action's twist (belief_model unbiased's state prior).
  const ActionDelayLine& actionLine() const { return action_line_; }

  /// Set the learned b_hat [m] (e.g. from a saved overlay), clamped to [separation_min, separation_max];
  /// the model takes it at once if learning is on. \return false (unchanged) if not finite.
  bool setLearnedSeparation(double b);
  /// Forget what was learned: b_hat back to wheel_separation (clamped to the learner's bounds);
  /// with belief_model robot also the robot model's slow states (RobotBelief::forgetSlowStates():
  /// shortfalls, slip ratio, gyro offset).
  void resetLearning();
  /// True if max_wheel_speed cut the last action step's command (the actuator saturates; the
  /// lead limits, anti-windup, do not count).
  bool actionSaturated() const { return action_saturated_; }
  /// Relative change of the learned b_hat that rebuilds the model (and the exact integrator) [-].
  static constexpr double kSeparationApplyTolerance = 1.0e-3;

  /**
   * \brief The learner of the order-0 sensory precisions (params().precision_learner.enabled;
   *        doc/active_inference.md, 'Learning the sensory precisions'). It steps with
   *        updateBeliefs() on eps_y^(0) after the belief step, frozen while the sensor mask
   *        isolates a learned channel, near rest or actionSaturated(); precisionY() takes its
   *        precisions whenever one moved by more than PrecisionLearner::kApplyTolerance.
   */
  const PrecisionLearner& precisionLearner() const { return precision_learner_; }

  /// belief_model robot: the beliefs (wheel speeds, shortfalls, yaw rate; RobotBelief).
  const RobotBelief& robotBelief() const { return robot_belief_; }
  /// belief_model robot: the sent commands and the wheel loop's model (WheelLoopModel).
  const WheelLoopModel& wheelLoop() const { return wheel_loop_; }
  /// The robot model's latency learner (learn_latency; its latency() is the wheel loop's L when on).
  const LatencyLearner& latencyLearner() const { return latency_learner_; }
  /// belief_model robot: F_a of the last action step, the goal prior on the predicted wheel speeds [-].
  double actionFreeEnergy() const { return action_free_energy_; }

  /// Number of runaway resets since construction.
  std::uint64_t runawayCount() const { return runaway_count_; }

  /**
   * \brief Overwrite the beliefs (e.g. to start from the measured twist, or for analysis).
   * \param mu  3 x (p+1) beliefs, finite, each |entry| <= runaway_limit
   * \return false (state unchanged) on a wrong number of columns, a non-finite entry or one beyond runaway_limit.
   */
  bool setBeliefs(const base::MuTilde& mu);

  /// The exact integrator recomputes its matrices when |h - h0| ||M||_inf exceeds this [-];
  /// smaller changes of h use Psi(h) = Psi(h0) + Phi(h0) Psi(h - h0) with Psi(h - h0) summed to
  /// its third term (truncation error <= kExactSeriesLimit^3 / 24 ~ 7e-4 of the correction,
  /// itself |h - h0| / h0 of the step).
  static constexpr double kExactSeriesLimit = 0.25;

  /// Largest accepted |entry| of a generalized measurement [channel units / s^i]. Far above any
  /// finite difference of a real signal (20 rad/s / (1 ms)^5 = 2e16), low enough that the free
  /// energy and its gradient cannot overflow with validated parameters.
  static constexpr double kMaxMeasurementMagnitude = 1.0e100;

  /// Length of the action delay line (belief_model unbiased) [action steps].
  static constexpr int kActionLine = ActionDelayLine::kCapacity;

  /// belief_model robot: with a zero goal, the goal's path below this on every channel [m/s, rad/s]
  /// is rest: the action is zero (the MCU holds the wheels; no shortfall to make up). Not while a
  /// tip bound is tripped (ReferenceModel::tipTripped()): the held path asks for the body's speed.
  static constexpr double kRobotRestPath = 1.0e-3;

  /// Number of times the exact integrator computed its matrix exponential (for tests and diagnostics).
  std::uint64_t exactRecomputeCount() const { return exact_recompute_count_; }

private:
  /// Max size of the stacked belief vector vec(mu_tilde) = 3 (p+1).
  static constexpr int kMaxStateDim = base::kMuDim * base::kMaxOrders;
  using StateMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxStateDim, kMaxStateDim>;
  using StateVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxStateDim, 1>;

  /// Whether the robot model's slow states (slip ratio, gyro offset, turn shortfalls, b_hat's
  /// transfer) may learn from the sample: gyro and both wheels in the sensor mask, no fault present.
  bool slowStatesMayLearn() const;
  /// eps_y for given beliefs and measurement (eq. 3-8; plus the optional accelerometer coupling).
  void computeEpsY(const base::MuTilde& mu, const base::YTilde& y_tilde, base::YTilde* eps_y) const;
  /// Column i of eps_y, eps_y^(i) = y^(i) - R mu^(i) (eq. 3-8; accelerometer x also minus x_dot^(i+1)
  /// with accel_in_model), 5 x 1 per SensorIndex [sensor units]; 0 <= i <= p.
  base::Vector5 epsYOrder(const base::MuTilde& mu, const base::YTilde& y_tilde, int i) const;
  /// eps_mu for given beliefs, attractor goal g and its rate g_dot (eq. 3-9, with g_dot).
  void computeEpsMu(const base::MuTilde& mu, const base::Vector3& g, const base::Vector3& g_dot,
                    base::MuTilde* eps_mu) const;
  /// dF/dmu_tilde (eq. 3-13).
  void computeDfDmu(const base::MuTilde& mu, const base::YTilde& y_tilde, const base::Vector3& g,
                    const base::Vector3& g_dot, base::MuTilde* grad) const;
  /// dmu_tilde/dt (eq. 3-15).
  void computeMuDot(const base::MuTilde& mu, const base::YTilde& y_tilde, const base::Vector3& g,
                    const base::Vector3& g_dot, base::MuTilde* mu_dot) const;
  /// Cache precisions, model, the belief dynamics matrix M; invalidate the exact step.
  void applyParams(const params::AicParams& params);
  /// Pi_y from params_ and the sensor mask, the belief dynamics matrix M; invalidate the exact step.
  void rebuildDynamics();
  /// Compute Phi = exp(M h), Psi = int_0^h exp(M s) ds for the exact integrator (no heap).
  void computeExactStep(double h);
  /// The belief integration of updateBeliefs() (Euler or exact, eq. 3-15) towards priorGoal(),
  /// priorRate(). \return false (mu_ unchanged) if the result is not finite or beyond runaway_limit.
  bool integrateBeliefs(double h);
  /// Zero beliefs and action after a runaway.
  void runawayReset();
  /// The action step while the body has turned over (setTurnedOver()): a zero command, the
  /// reference path restarted from rest, the command recorded as sent (the robot model's commands
  /// in flight, the unbiased model's action line) over the step of h [s]; the beliefs go on.
  void stopTurnedOver(double h);
  /// Learning, the last stage: one SeparationLearner step on y^(0), y^(1) of the gyro and wheels
  /// (frozen while the mask isolates one of them or actionSaturated()), then applyLearnedSeparation().
  void learn(double h);
  /// Precision learning (learn_precision): one PrecisionLearner step on eps_y^(0) of the beliefs
  /// just integrated, then Pi_y and M rebuilt if a precision moved beyond its apply tolerance.
  void learnPrecision(double h);
  /// The robot model's learning of b_hat over a step of h [s]: the believed slip ratio s beyond
  /// kSeparationApplyTolerance moves b_hat toward b_hat / (1 - s), at most separation_max_rate b_hat
  /// per second and within the learner's bounds, and the slip ratio is re-expressed on the b_hat
  /// reached (RobotBelief::rescaleSlip()); held under a fault mask (s is).
  void learnRobotSeparation(double h);
  /// The robot model's wheel sample `wheels` [rad/s] into the latency learner (learn_latency; both
  /// wheels unmasked and no fault present, else an armed start is dropped); a new L is used
  /// (useLatency()).
  void learnLatency(const base::Vector2& wheels);
  /// Use the latency L [s] (configured, or learned with learn_latency): the wheel loop's, and with
  /// belief_model robot the goal's lead, so that the action's inverse and the goal it aims at are
  /// one latency ahead by the same L (doc/active_inference.md, 'Learning the latency').
  void useLatency(double latency);
  /// Give the model the learner's b_hat if it moved beyond kSeparationApplyTolerance.
  void applyLearnedSeparation(bool force);
  /// belief_model robot: the belief step (RobotBelief: the model's prediction, then the sample).
  Status updateRobotBeliefs(double h);
  /// belief_model robot: the action step (LatencyAction through WheelLoopModel).
  Status updateRobotAction(double h);

  params::AicParams params_;
  SkidSteerModel model_;
  base::MuTilde mu_;
  base::YTilde y_tilde_;
  // The stages (class comment). A belief step integrates mu_ towards reference_'s attractor (or
  // action_line_'s twist), then advances reference_ and response_, then learner_ and
  // precision_learner_; an action step runs release_, action_prior_, anti_windup_, slew_limit_, then
  // records into action_line_.
  ReferenceModel reference_;
  ActionDelayLine action_line_;
  ActionPrior action_prior_;
  RestRelease release_;
  GoalResponse response_;
  AntiWindup anti_windup_;
  ActionSlewLimit slew_limit_;
  SeparationLearner learner_;
  PrecisionLearner precision_learner_;  ///< used only with params_.precision_learner.enabled
  // belief_model robot: the commands in flight and the wheel loop, the beliefs, the model's clock [s].
  WheelLoopModel wheel_loop_;
  RobotBelief robot_belief_;
  LatencyLearner latency_learner_{ 0.1187, 0.0, 1.0, 1.0 };  ///< robot model with learn_latency (applyParams())
  double robot_clock_ = 0.0;
  bool robot_sample_pending_ = false;   ///< a sample arrived since the last robot belief step
  bool robot_wheels_repeated_ = false;  ///< the pending sample's joint state repeated the previous one
  double action_free_energy_ = 0.0;     ///< F_a of the last robot action step [-]
  bool action_saturated_ = false;
  bool turned_over_ = false;  ///< setTurnedOver(): the command is zero

  base::Vector2 a_ = base::Vector2::Zero();
  base::Vector2 a_F_ =
      base::Vector2::Zero();  ///< the free-energy part a_F of the action (eq. 3-16); a_ = clamps(a_F_ + a_ff)
  bool has_measurement_ = false;
  std::uint64_t runaway_count_ = 0;
  std::uint8_t sensor_mask_ = (1u << base::kYDim) - 1u;  ///< bit j set = channel j used
  bool latency_learner_configured_ = false;              ///< latency_learner_ built from params_ (applyParams())
  bool fault_suspected_ = false;                         ///< setFaultState(): hold the robot model's corrections
  bool fault_present_ = false;                           ///< setFaultState(): hold the robot model's learning

  base::MuTilde pi_mu_;   ///< Pi_mu, 3 x (p+1)
  base::YTilde pi_y_;     ///< Pi_y, 5 x (p+1)
  StateMatrix M_;         ///< linear part of dmu_tilde/dt on vec(mu_tilde)
  StateMatrix phi_;       ///< exp(M h_exact)
  StateMatrix psi_;       ///< int_0^h exp(M s) ds
  double exact_h_ = 0.0;  ///< h for which phi_/psi_ hold; 0 = not computed
  double m_norm_ = 0.0;   ///< ||M||_inf [1/s], for the series criterion
  std::uint64_t exact_recompute_count_ = 0;
};

/// Human-readable name of a status, e.g. "runaway".
const char* toString(ActiveInferenceController::Status status);

}  // namespace aic
}  // namespace jackal_aic
