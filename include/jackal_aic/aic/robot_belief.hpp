#pragma once
/**
 * \file robot_belief.hpp
 * \brief The robot model's beliefs: the wheel speeds, the actuation shortfalls and the yaw rate,
 *        descending the free energy of the robot model in its filter form (doc/active_inference.md,
 *        'The robot model'). ROS-free.
 */

#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "jackal_aic/aic/residual_run.hpp"
#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/robot_model_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Beliefs mu = (omega_L, d_L, e_L, omega_R, d_R, e_R, theta_dot, s, beta) with their
 *        covariance, under the robot model (RobotModelParams). e_s is side s's turn shortfall: its
 *        shortfall on top of d_s in a turn that loads it against its motion (sign turnSigns()). s is the yaw slip ratio: the body turns at (1 - s) times
 *        the wheels' yaw rate u = r alpha (omega_R - omega_L) / b_hat in steady state; beta is the
 *        gyro's offset (the gyro reads theta_dot + beta).
 *
 * A Gaussian belief N(mu, P) on a linear-Gaussian model: the free energy of a measurement y with
 * the model's prediction N(mu_-, P_-) as the prior (the Laplace form, Friston et al. 2007),
 *   F(mu) = 1/2 eps_y^T Pi_y eps_y + 1/2 eps_mu^T P_-^{-1} eps_mu,  eps_y = y - H mu,  eps_mu = mu - mu_-,
 * is quadratic, so its gradient descent dmu/dt = -k dF/dmu converges to the one minimiser
 * mu = mu_- + P_- H^T (H P_- H^T + Pi_y^{-1})^{-1} (y - H mu_-), the Kalman filter's correction, and
 * the curvature P^{-1} = P_-^{-1} + H^T Pi_y H is its covariance update. correct() takes that
 * minimiser directly (the descent run to convergence); predict() carries the belief through the
 * model's dynamics with its process noise (the prior's precision between samples).
 * Each side's triple (omega_s, d_s, e_s) and the yaw triple (theta_dot, s, beta) are filtered on their own
 * (their covariances are not coupled: the yaw triple takes the believed wheel speeds as its input).
 *
 * The slip ratio moves with the turn, not with time: its variance grows by sigma_s^2 |dw| over a
 * step in which the goal's yaw rate changes by dw (RobotModelParams::yaw_slip_noise), so it is
 * learned after a turn changes and held in a steady turn. The offset is a random walk in time
 * (gyro_offset_noise) at rest and in straight driving, where the gyro observes it alone (u = 0), and
 * jumps (kJumpThreshold, kJumpSamples): in a steady turn, a gyro that leaves the wheels' prediction
 * for several samples in a row has jumped.
 *
 * The shortfalls are random walks that drift slowly (shortfall_noise) and jump: once a side's
 * command at the wheels has held still long enough for the wheel loop to have settled
 * (settleTime()), kShortfallJumpSamples wheel samples in a row beyond kJumpThreshold standard
 * deviations of the model's steady wheel speed u - d, all within kJumpThreshold sqrt(2) sigma_e of
 * the first (the wheel has stopped moving), are a step in the load: a stall, a payload's
 * scrub in a turn, a firmware that delivers less while turning. d takes their mean at once, bounded
 * to a shortfall: between 0 and the command u (a wheel faster than its command is left to the drift).
 * A jump belongs to the turn it was taken in: when the goal's turn moves on by more than
 * kJumpTurnBand, the jumps' part of d is dropped (the drift's part stays). And to the load it took:
 * when the wheel, at a command held as for a jump, runs faster than u - d toward its command for
 * kShortfallJumpSamples samples in a row beyond the same threshold, moving or not (a stall that has
 * freed), the jumps' part is dropped too (shortfallReleases()); a shortfall that remains is taken
 * again once the wheel has stopped moving.
 *
 * A jump the wheel did not answer is a torque limit's: a jump in the same direction as the side's
 * last one, taken with the command raised since that jump by more than kJumpThreshold sqrt(2)
 * sigma_e (an answer would show) and the wheel within that band of where the last one found it (the
 * raised command did not move the wheel). The side is then saturated (saturated()): its wheel holds
 * the speed the jump found whatever its command, so d is re-expressed on the command at the wheels
 * at every predict() (u - d - sigma e stays that speed: the belief stays honest when the command
 * changes), and the action makes none of it up (compensableShortfallsAt(); unansweredJumps()),
 * until the side's jumps are dropped (a release, or the turn moving on). And a side is stalled
 * (stalled()) once its wheel is held: kShortfallJumpSamples readings in a row within the same band
 * (it does not move), each less than kHeldFraction of the model's steady speed u - d - sigma e and
 * short of it by more than the jump test's limit, the command moving or not. A held wheel is at its
 * torque limit, not short by a load the MCU's loop makes up: the action makes none of a stalled
 * side's shortfall up either (compensableShortfallsAt()). The stall ends when the wheel answers (it
 * gives the model's steady speed within the limit) or the command comes back within the limit of
 * the wheel; not when the wheel merely moves, as one that sticks and slips does while held. A wheel
 * held again after its last jump was made up, the command raised since that jump by more than the
 * band and the wheel within the band of where the jump found it, did not answer that jump: the
 * side is saturated, as a second jump would show once the command held still.
 *
 * The turn shortfalls are random walks while the robot turns (turn_shortfall_noise |sigma|), zero
 * with q_e = 0. A side's nonzero reading that repeats bit for bit across a change of its command at
 * the wheels is a frozen encoder's and is skipped (frozenEncoderSamples()).
 *
 * No heap allocation, no exceptions.
 */
class RobotBelief
{
public:
  /// Beliefs at zero (reset()).
  explicit RobotBelief(const params::RobotModelParams& params = params::RobotModelParams());

  /// Replace the settings (beliefs kept).
  void setParams(const params::RobotModelParams& params);

  /// Forget the slow states (what the robot model learned): the shortfalls d_L, d_R, the slip ratio
  /// s and the gyro offset beta back to zero with variance zero, as after reset(), their jumps'
  /// bookkeeping cleared; the wheel speeds and the yaw rate are kept.
  void forgetSlowStates();

  /// Beliefs: wheel speeds omega (rad/s), yaw rate theta_dot (rad/s) with variance kInitialVariance;
  /// the shortfalls d_L, d_R, the slip ratio s and the gyro offset beta zero with variance zero
  /// (they drift from there at their noise rates).
  void reset(const base::Vector2& omega, double theta_dot);

  /**
   * \brief Carry the beliefs h [s] forward under the command u_at_wheels [rad/s] (the command in
   *        effect at the wheels, WheelLoopModel::commandAt()) and its stream's rate rate_at_wheels
   *        [rad/s^2] (WheelLoopModel::commandRateAt()) through the wheel loop, and the yaw
   *        rate toward (1 - s) u, u = yaw_gain (omega_R - omega_L), with the scrub lag T_s.
   * \param yaw_gain  r alpha / b_hat [m/m]: the wheels' yaw rate per unit of their speed difference
   * \param turn      the yaw rate [rad/s] the goal asks for: the slip ratio's variance grows by
   *                  yaw_slip_noise^2 times its change since the last predict() (a turn that changes)
   * \param slip_observed  false: the slip ratio cannot be learned (a channel isolated, a fault
   *                  present), so its variance does not grow with the turn: an isolated gyro's
   *                  disagreement is not read as slip the model may learn, and is not re-admitted on it
   */
  void predict(double h, const WheelLoopModel& loop, const base::Vector2& u_at_wheels,
               const base::Vector2& rate_at_wheels, double yaw_gain, double turn, bool slip_observed = true);

  /**
   * \brief What one sample may do in correct(): the channels it reads and the slow states it may
   *        move. Every field true by default: all three channels read, every state learns.
   */
  struct SampleUse
  {
    bool left = true;   ///< the left encoder is read (false: isolated or absent)
    bool right = true;  ///< the right encoder is read
    bool gyro = true;   ///< the gyro is read
    /// false: the slow states (s, beta) are held, the gyro corrects theta_dot only (a fault mask on
    /// one of the three channels: nothing is learned from two)
    bool learn = true;
    /// false: the slip ratio s is held, beta learns as `learn` says (a gyro whose reading repeats
    /// exactly: frozen, or ideal at rest)
    bool learn_slip = true;
    /// false: the turn shortfalls e are held (a fault present or a channel isolated: what a faulty
    /// encoder reads is not the side's load)
    bool learn_turn = true;
  };

  /**
   * \brief Take a measurement: the sides' wheel speeds y_omega [rad/s] and the gyro's yaw rate
   *        y_gyro [rad/s] (theta_dot + beta + noise); a channel `use` does not read is skipped.
   *        Sets the free energy's parts at the new beliefs (sensoryFreeEnergy(),
   *        priorFreeEnergy()).
   * \param use  the channels read and the slow states that may learn (SampleUse)
   * \return false (nothing changed) if a read value is not finite
   */
  bool correct(const base::Vector2& y_omega, double y_gyro, const SampleUse& use);

  /// correct() with every channel read and every slow state learning (SampleUse's defaults).
  bool correct(const base::Vector2& y_omega, double y_gyro) { return correct(y_omega, y_gyro, SampleUse()); }

  /**
   * \brief The sample's innovations at the beliefs as they are (the model's prediction, before
   *        correct() takes the sample), with their variances: eps_L = y_L - omega_L, eps_R = y_R -
   *        omega_R (variance P_omega + sigma_e^2), eps_gyro = y_gyro - (theta_dot + beta) (variance
   *        H P_yaw H^T + sigma_g^2, H = (1, 0, 1): the yaw model's noise q_theta and the slow states'
   *        uncertainty included), and their parity eps_gyro - k (eps_R - eps_L), k = (1 - s) yaw_gain
   *        of the last predict(): the residual of the fault monitor's innovation test. The three
   *        filters are not coupled, so the parity's variance is the sum.
   * \param y_omega  the sides' wheel speeds [rad/s]; y_gyro the gyro's yaw rate [rad/s]
   */
  base::SampleInnovation sampleInnovation(const base::Vector2& y_omega, double y_gyro) const;

  /**
   * \brief Re-express the slip ratio after the wheels' yaw gain changed by the factor k =
   *        yaw_gain_old / yaw_gain_new (b_hat_new / b_hat_old): (1 - s_new) = k (1 - s), so the
   *        model's yaw rate (1 - s) u is unchanged; the covariance follows (ds_new = k ds).
   * \return false (unchanged) unless k is finite and > 0
   */
  bool rescaleSlip(double k);

  /**
   * \brief Move the gyro offset beta by delta [rad/s] (its variance kept): the offset removed from
   *        the gyro before correct() changed by -delta, and beta is what remains.
   * \return false (unchanged) unless delta is finite
   */
  bool shiftGyroOffset(double delta);

  /// Believed wheel speeds (omega_L, omega_R) [rad/s].
  base::Vector2 wheelSpeeds() const { return base::Vector2(side_[0](0), side_[1](0)); }
  /// Believed shortfalls (d_L, d_R) [rad/s]: the command the sides do not deliver in steady state
  /// whatever the turn (a payload, a slope, friction).
  base::Vector2 shortfalls() const { return base::Vector2(side_[0](1), side_[1](1)); }
  /**
   * \brief Believed turn shortfalls (e_L, e_R) [rad/s]: what each side does not deliver on top of d
   *        in a turn that loads it against its motion (the turn's scrub load over the MCU's wheel
   *        loop; a P-only wheel servo leaves it as a steady speed error): shortfallsAt().
   */
  base::Vector2 turnShortfalls() const { return base::Vector2(side_[0](2), side_[1](2)); }
  /// Their variances (P_eL, P_eR) [(rad/s)^2].
  base::Vector2 turnShortfallVariances() const { return base::Vector2(p_side_[0](2, 2), p_side_[1](2, 2)); }
  /**
   * \brief The believed shortfall of each side [rad/s] when the goal turns at `turn` [rad/s]:
   *        d_s + sigma_s e_s, (sigma_L, sigma_R) = turnSigns(turn).
   */
  base::Vector2 shortfallsAt(double turn) const;
  /**
   * \brief The shortfall of each side the action makes up [rad/s] when the goal turns at `turn`
   *        [rad/s]: shortfallsAt(turn), zero on a saturated() or stalled() side (the class's
   *        description).
   */
  base::Vector2 compensableShortfallsAt(double turn) const;
  /// Whether side s (0 left, 1 right; any other: false) is stalled: its wheel is held below
  /// kHeldFraction of the model's steady speed until it answers (the class's description).
  bool stalled(int side) const { return (side == 0 || side == 1) && stalled_[side]; }
  /// Whether side s (0 left, 1 right; any other: false) is saturated: a jump went unanswered, and
  /// until its jumps are dropped its speed does not depend on its command (the class's description).
  bool saturated(int side) const { return (side == 0 || side == 1) && saturated_[side]; }
  /// Whether either side is stalled() or saturated(): a side whose wheel speed does not follow its
  /// command.
  bool anySideHeld() const { return stalled_[0] || stalled_[1] || saturated_[0] || saturated_[1]; }
  /**
   * \brief The sides' signs (sigma_L, sigma_R) = (-c, c), c = clamp(turn / kStraightTurn, -1, 1), of
   *        the turn shortfalls at the goal's yaw rate `turn` [rad/s]: a left turn's scrub load holds
   *        the right side back and pushes the left side on; toward straight driving (|turn| below
   *        kStraightTurn) it fades to zero. (0, 0) unless turn is finite.
   */
  static base::Vector2 turnSigns(double turn);
  /// Believed yaw rate theta_dot [rad/s].
  double yawRate() const { return yaw_(0); }
  /// Believed yaw slip ratio s [-]: the body turns at (1 - s) times the wheels' yaw rate.
  double slipRatio() const { return yaw_(1); }
  /// The believed wheels' yaw rate u = r alpha (omega_R - omega_L) / b_hat at the last predict() [rad/s].
  double wheelsYawRate() const { return wheels_yaw_; }
  /// Believed gyro offset beta [rad/s] (on top of any offset removed before correct()).
  double gyroOffset() const { return yaw_(2); }
  /// Its rate theta_dot' [rad/s^2] under the model (the last predict()).
  double yawAcceleration() const { return yaw_rate_; }
  /// Believed wheel accelerations (omega_L', omega_R') [rad/s^2] under the model (the last predict()).
  base::Vector2 wheelAccelerations() const { return omega_rate_; }
  /// Covariance diagonal of (omega_L, d_L, omega_R, d_R, theta_dot, s, beta).
  Eigen::Matrix<double, 7, 1> variances() const;

  /// Sensory part of F at the last correct(): 1/2 sum eps_y^2 / sigma^2 [-].
  double sensoryFreeEnergy() const { return f_sensory_; }
  /// Prior part of F at the last correct(): 1/2 eps_mu^T P_-^{-1} eps_mu [-].
  double priorFreeEnergy() const { return f_prior_; }
  /// Sensory prediction errors of the last correct() (eps_L, eps_R, eps_gyro) at the prior beliefs [rad/s].
  const base::Vector3& innovation() const { return innovation_; }

  /// Number of gyro offset jumps taken since construction.
  std::uint64_t offsetJumps() const { return offset_jumps_; }
  /// Number of shortfall jumps taken since construction (both sides).
  std::uint64_t shortfallJumps() const { return shortfall_jumps_; }
  /// Number of times a side's jumps were dropped because its wheel ran ahead of them (a stall that
  /// freed) since construction (both sides).
  std::uint64_t shortfallReleases() const { return shortfall_releases_; }
  /// Number of shortfall jumps the wheel did not answer since construction (both sides): each makes
  /// its side saturated() until its jumps are dropped.
  std::uint64_t unansweredJumps() const { return unanswered_jumps_; }
  /// Number of times a side became stalled() since construction (both sides).
  std::uint64_t stalls() const { return stalls_; }
  /// Number of wheel samples skipped as a frozen encoder's since construction (both sides): a
  /// nonzero reading that repeats bit for bit, from the first repeat across a change of the side's
  /// command at the wheels beyond kSteadyBand, for as long as it repeats.
  std::uint64_t frozenEncoderSamples() const { return frozen_samples_; }

  /**
   * \brief The time [s] the wheel loop needs to settle after its command at the wheels changed by
   *        du [rad/s]: the rate-bounded ramp |du| / A_w plus kSettleLags lags T_w.
   */
  double settleTime(double du) const;

  /// Variance of omega_L, omega_R and theta_dot after reset() [(rad/s)^2].
  static constexpr double kInitialVariance = 1.0;
  /// |goal's yaw rate| [rad/s] below which the robot drives straight: the gyro offset drifts there.
  static constexpr double kStraightTurn = 0.05;
  /// An offset jump: kJumpSamples gyro residuals in a row, against the model's steady yaw rate
  /// (1 - s) u + beta, beyond kJumpThreshold times their standard deviation
  /// sqrt(sigma_g^2 + u^2 P_s + P_beta) (a false alarm about once in (1.7e6)^3 samples of a healthy
  /// gyro in a steady turn); checked only while the slow states learn (no transient).
  static constexpr double kJumpThreshold = 5.0;
  static constexpr int kJumpSamples = 3;
  /// A shortfall jump: this many wheel samples in a row (0.1 s at the MCU's 50 Hz).
  static constexpr int kShortfallJumpSamples = 5;
  /// A wheel steady below this share of the model's steady speed is held (stalled()), not short: a
  /// stall, or a firmware's slow integral creeping the wheel up [-]. A named threshold, measured
  /// (doc/active_inference.md, 'The robot model', 'A held wheel'): 0.4 gives the same slow
  /// break-away turns in place; 0.25, 0.6 and 0.75 let their creeping wheels be chased.
  static constexpr double kHeldFraction = 0.5;
  /// A shortfall jump is dropped when the goal's turn moves this far [rad/s] from the turn it
  /// was taken in (the load it measured was the turn's).
  static constexpr double kJumpTurnBand = 0.05;
  /// A side's command at the wheels [rad/s] that stays within kSteadyBand of where it settled is
  /// steady (the action's own jitter in a steady drive is a few 1e-3 rad/s).
  static constexpr double kSteadyBand = 0.05;
  /// Lags T_w after the ramp before the wheel loop counts as settled (e^-5 of the step left).
  static constexpr double kSettleLags = 5.0;

private:
  /// One side's shortfall jump test on its sample y [rad/s] (before its correction); d and p are
  /// that side's shortfall and (omega, d, e) covariance, r_e = sigma_e^2.
  void detectShortfallJump(int side, double y, bool used, double r_e, double* d, const Eigen::Matrix3d& p);
  /// One side's stall test on its sample y [rad/s] (stalled()): `shortfall` the side's d + sigma e
  /// [rad/s], `limit` the jump test's limit on a residual and `band` its band of a wheel that does
  /// not move [rad/s] (detectShortfallJump() computes them).
  void detectStall(int side, double y, bool used, double shortfall, double limit, double band);
  /// Saturates side s (saturated()) when its jump went unanswered: its last jump was in
  /// `direction` (+1 or -1, toward a larger command), the command has since been raised that way
  /// by more than `band` [rad/s], and `wheel` [rad/s], the wheel's steady speed now, is within
  /// `band` of where that jump found it. Called on a second jump (detectShortfallJump()) and on a
  /// held wheel (detectStall()).
  void saturateIfUnanswered(int side, double direction, double wheel, double band);
  /// Drop side's jumps: d loses their part, the stall compensation is lifted.
  void dropJumps(int side);
  /// Whether side's reading y [rad/s] is a frozen encoder's (frozenEncoderSamples()).
  bool frozenReading(int side, double y);

  params::RobotModelParams params_;
  /// Per side (L, R): the belief (omega_s, d_s, e_s) and its covariance.
  Eigen::Vector3d side_[2] = { Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero() };
  Eigen::Matrix3d p_side_[2] = { Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity() };
  Eigen::Vector3d yaw_ = Eigen::Vector3d::Zero();       ///< (theta_dot, s, beta)
  base::Vector2 turn_signs_ = base::Vector2::Zero();    ///< turnSigns() at the last predict()
  base::Vector2 last_reading_ = base::Vector2::Zero();  ///< each side's previous reading [rad/s] (NaN: none)
  std::uint64_t frozen_samples_ = 0;
  Eigen::Matrix<bool, 2, 1> frozen_ = Eigen::Matrix<bool, 2, 1>::Constant(false);  ///< each side's reading frozen
  /// Each side's command at the wheels at the last sample [rad/s].
  base::Vector2 sample_command_ = base::Vector2::Zero();
  Eigen::Matrix3d p_yaw_ = Eigen::Matrix3d::Identity();
  double turn_ = 0.0;        ///< the goal's yaw rate at the last predict() [rad/s] (NaN: none yet)
  double yaw_gain_ = 0.0;    ///< r alpha / b_hat at the last predict() [m/m]
  double wheels_yaw_ = 0.0;  ///< u at the last predict() [rad/s]
  ResidualRun offset_run_;   ///< gyro residuals in a row beyond kJumpThreshold
  std::uint64_t offset_jumps_ = 0;
  /// Per side: the command at the wheels at the last predict(), where it settled, how long it has
  /// held there, how long the wheel loop needs to settle from the change before it [s].
  base::Vector2 wheel_command_ = base::Vector2::Zero();
  base::Vector2 steady_command_ = base::Vector2::Zero();
  base::Vector2 steady_time_ = base::Vector2::Zero();
  base::Vector2 settle_needed_ = base::Vector2::Zero();
  ResidualRun shortfall_runs_[2];  ///< wheel residuals in a row beyond the threshold, per side
  ResidualRun release_runs_[2];    ///< wheel residuals in a row beyond the threshold toward the command, per side
  base::Vector2 shortfall_jump_ = base::Vector2::Zero();  ///< the part of d the jumps made, per side [rad/s]
  base::Vector2 jump_turn_ = base::Vector2::Zero();       ///< the goal's turn at the last jump, per side [rad/s]
  base::Vector2 jump_wheel_ = base::Vector2::Zero();    ///< the wheel's mean reading at the last jump, per side [rad/s]
  base::Vector2 jump_command_ = base::Vector2::Zero();  ///< the wheel command at the last jump, per side [rad/s]
  bool saturated_[2] = { false, false };                ///< per side: a jump went unanswered (saturated())
  ResidualRun stall_runs_[2];                           ///< wheel readings in a row that do not move, per side
  bool stalled_[2] = { false, false };
  std::uint64_t unanswered_jumps_ = 0;
  std::uint64_t stalls_ = 0;
  std::uint64_t shortfall_jumps_ = 0;
  std::uint64_t shortfall_releases_ = 0;
  base::Vector2 omega_rate_ = base::Vector2::Zero();
  double yaw_rate_ = 0.0;
  double f_sensory_ = 0.0;
  double f_prior_ = 0.0;
  base::Vector3 innovation_ = base::Vector3::Zero();
};

}  // namespace aic
}  // namespace jackal_aic
