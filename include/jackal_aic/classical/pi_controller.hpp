#pragma once
/**
 * \file pi_controller.hpp
 * \brief A classical peer of the active inference controller: PI loops on the wheel speeds
 *        (encoders) and on the yaw rate (gyro) around the robot model's feed-forward through the
 *        latency (doc/active_inference.md, 'A classical peer'). ROS-free.
 *
 * Sources: K. J. Åström and R. M. Murray, Feedback Systems (Princeton University Press, 2008),
 * ch. 10 (PID control: the PI law, integrator windup and anti-windup by conditional integration)
 * and ch. 11 (frequency domain design: feedforward of the reference, feedback on the error
 * against the reference's expected response, the two-degree-of-freedom structure); the
 * feed-forward's model of the wheels and their latency, doc/active_inference.md, 'The robot model'.
 */

#include <string>
#include <vector>

#include "jackal_aic/aic/goal_rate.hpp"
#include "jackal_aic/aic/reference_model.hpp"
#include "jackal_aic/aic/skid_steer_model.hpp"
#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/params/robot_model_params.hpp"

namespace jackal_aic
{
namespace classical
{
/// Proportional and integral gain of one PI loop.
struct PiGains
{
  double kp = 0.0;  ///< proportional gain [-] (command per unit of error, both in the loop's unit), finite, >= 0
  double ki = 0.0;  ///< integral gain [1/s], finite, >= 0
};

/**
 * \brief Settings of a PiController. The wheel loop's model (latency L, T_w, A_w) is the robot
 *        model's RobotModelParams (its defaults are the identified values); the geometry, the goal
 *        estimator's limits and the wheel clamp default to AicParams' defaults, so that the peer
 *        and the AIC see the same robot (config/classical/pi.yaml sets the yaw-rate goal's rate
 *        bound that config/default.yaml gives the AIC).
 */
struct PiControllerParams
{
  /// The identified wheel loop and the body's scrub lag: latency, wheel_time_constant,
  /// wheel_acceleration, yaw_time_constant (the rest unused).
  params::RobotModelParams robot;
  double wheel_radius = params::AicParams().wheel_radius;          ///< r [m], > 0
  double wheel_separation = params::AicParams().wheel_separation;  ///< b [m] of the skid-steer map, > 0
  double max_wheel_speed = params::AicParams().max_wheel_speed;    ///< |command| clamp [rad/s], > 0
  /// The goal's rate estimator (GoalRateEstimator): hold [s] and rate bounds [m/s^2], [rad/s^2].
  double goal_rate_hold = params::ReferenceModelParams().goal_rate_hold;
  double max_goal_rate_linear = params::ReferenceModelParams().max_goal_rate_linear;
  double max_goal_rate_angular = params::ReferenceModelParams().max_goal_rate_angular;
  /// The nominal update period h [s], > 0 and <= 1: the step the feed-forward's inverse of the
  /// wheel loop plans over (the joint-state period, 50 Hz on the Jackal).
  double period = 0.02;
  /// Inner loops, one per side: wheel speed [rad/s] error -> wheel command [rad/s].
  PiGains wheel{ 0.3, 3.0 };
  /// Outer loop: yaw rate [rad/s] error -> yaw-rate trim [rad/s] of the wheels' differential.
  PiGains yaw{ 0.3, 3.0 };
  /// At rest (|goal| and |predicted goal| below these on both channels [m/s], [rad/s], > 0) the
  /// yaw loop is off and its integral cleared: a gyro offset does not turn a robot at rest.
  double rest_linear = 1.0e-3;
  double rest_angular = 1.0e-3;

  /// Every violation as "key = value (allowed range)"; empty when valid.
  std::vector<std::string> validate() const;
};

/// What an input of the PiController was.
enum class PiStatus
{
  kOk,               ///< accepted
  kNotFinite,        ///< a time, goal or measurement is NaN or infinite: ignored
  kNonPositiveStep,  ///< the time did not advance past the previous update's: ignored
  kGoalOutOfOrder,   ///< a goal older than the previous change: ignored
  kRestarted         ///< more than params::kMaxStep since the previous update: the expected responses
                     ///< restart from the measured wheels (as at the first update); the command is computed
};

/// "ok", "not_finite", "non_positive_step", "goal_out_of_order", "restarted".
const char* toString(PiStatus status);

/// One update's output.
struct PiCommand
{
  PiStatus status = PiStatus::kOk;
  /// The wheel command (omega_L, omega_R) [rad/s], always finite and within +-max_wheel_speed
  /// (on a rejected input: the previous command, zero before the first).
  base::Vector2 wheels = base::Vector2::Zero();
  base::Vector2 feed_forward = base::Vector2::Zero();  ///< its feed-forward part [rad/s]
  base::Vector2 expected =
      base::Vector2::Zero();  ///< the wheels' expected speeds now (the inner loops' reference) [rad/s]
  double yaw_trim = 0.0;      ///< the outer loop's yaw-rate trim [rad/s]
  bool saturated = false;     ///< a side's command was clamped (the integrators held)
};

/**
 * \brief Per side a PI on the wheel speed plus an outer PI on the yaw rate that trims the wheels'
 *        differential, around a feed-forward through the latency (a two-degree-of-freedom loop).
 *
 * Feed-forward: the goal (v_d, w_d) and its rate (GoalRateEstimator, from the set-point stream)
 * predicted one latency ahead, g = mu_d + L mu_d' (ReferenceModel::target() with the goal lead L: aic::predictGoal(),
 * the speed not predicted through a stop),
 * mapped to the wheels by the skid-steer model (SkidSteerModel::wheelsFromTwist()), and through the
 * wheel loop's inverse over the period h (LatencyAction::step() with k_a h = 1: the command whose
 * response, after the commands in flight, reaches g at t + L + h): u_ff.
 *
 * Expected responses: two WheelLoopModel's carry the commands in flight through L, T_w, A_w: w_ff
 * of u_ff alone, and w_ref of u_ff + the yaw trim. The outer loop's reference psi_ff is the yaw
 * rate of w_ff, r (w_ff,R - w_ff,L) / b, through the body's scrub lag T_s (the robot model's
 * yaw_time_constant, integrated exactly over each step), its error e_psi = psi_ff - gyro; its PI gives the trim psi, a
 * differential (-psi b / (2 r), +psi b / (2 r)) added to the command and to w_ref. The inner
 * loops' errors are e_s = w_ref,s - omega_s (encoders); their PIs give u_fb. The command is
 * u = clamp(u_ff + trim + u_fb, +-max_wheel_speed). The feedback acts only on what the model does
 * not expect: a shortfall of the wheels, a turn the skid does not deliver.
 *
 * Each PI is u = kp e + I, I <- I + ki e dt (dt the time since the previous update), with
 * anti-windup by conditional integration (Åström & Murray, ch. 10): a side whose command is
 * clamped holds its integral where the error would push it further, and the yaw integral holds
 * while either side is clamped. At rest (goal and predicted goal within rest_linear,
 * rest_angular) the yaw loop is off and its integral cleared.
 *
 * No heap allocation after construction, no exceptions after construction. Bad input (a non-finite
 * time, goal or measurement, a time that does not advance) is refused with its PiStatus and leaves
 * the state and the command unchanged, so the command is never non-finite; a gap longer than
 * params::kMaxStep restarts the expected responses (kRestarted).
 */
class PiController
{
public:
  /// \throws std::invalid_argument if params do not validate (the message lists every violation)
  explicit PiController(const PiControllerParams& params = PiControllerParams());

  /// The settings in use.
  const PiControllerParams& params() const { return params_; }

  /**
   * \brief The set point (v_d [m/s], w_d [rad/s]) received at time t [s] (a stream: each message,
   *        repeated values too; the rate estimator counts the changes).
   * \return kOk, kNotFinite (ignored), or kGoalOutOfOrder (t before the previous change; ignored)
   */
  PiStatus setGoal(double t, double linear, double angular);

  /**
   * \brief One update at time t [s] with the measured wheel speeds (omega_L, omega_R) [rad/s]
   *        (the encoders' side means) and the gyro's yaw rate [rad/s].
   * \return the command; status kNotFinite or kNonPositiveStep (t not after the previous
   *         update's) leave every state unchanged and repeat the previous command; kRestarted
   *         (t more than params::kMaxStep after the previous update: nothing predicted over such a
   *         gap holds, and simulating it would take without bound) restarts the expected responses
   *         from the measured wheels, as the first update does, and integrates one period
   */
  PiCommand update(double t, const base::Vector2& wheels, double gyro_z);

  /// Back to the start: integrals, models and goal cleared, command zero.
  void reset();

  /// The inner loops' integrals (left, right) [rad/s].
  const base::Vector2& wheelIntegral() const { return wheel_integral_; }
  /// The outer loop's integral [rad/s].
  double yawIntegral() const { return yaw_integral_; }

private:
  PiControllerParams params_;
  aic::SkidSteerModel model_;
  aic::GoalRateEstimator goal_rate_;
  aic::ReferenceModel goal_;
  aic::WheelLoopModel ff_loop_;   ///< the commands u_ff
  aic::WheelLoopModel ref_loop_;  ///< the commands u_ff + trim
  bool started_ = false;
  double last_t_ = 0.0;
  base::Vector2 goal_now_ = base::Vector2::Zero();  ///< (v_d, w_d) [m/s, rad/s]
  base::Vector2 w_ff_ = base::Vector2::Zero();      ///< expected wheel speeds under u_ff [rad/s]
  base::Vector2 w_ref_ = base::Vector2::Zero();     ///< expected wheel speeds under u_ff + trim [rad/s]
  double yaw_expected_ = 0.0;                       ///< psi_ff: the yaw rate expected of u_ff [rad/s]
  base::Vector2 u_ff_ = base::Vector2::Zero();      ///< the last feed-forward [rad/s]
  base::Vector2 wheel_integral_ = base::Vector2::Zero();
  double yaw_integral_ = 0.0;
  PiCommand last_;
};

}  // namespace classical
}  // namespace jackal_aic
