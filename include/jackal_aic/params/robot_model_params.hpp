#pragma once
/**
 * \file robot_model_params.hpp
 * \brief Settings of the robot belief model (belief_model robot; doc/active_inference.md, 'The robot
 *        model'): the identified latency and wheel loop, the sensors' measured noise and the
 *        action's loop gain. ROS-free.
 */

namespace jackal_aic
{
namespace params
{
/// Bounds of the learned latency, as factors of the configured one.
constexpr double kLatencyMinFactor = 0.5;
constexpr double kLatencyMaxFactor = 2.0;

/**
 * \brief The generative model of the robot as it is (AicParams::robot; used only with
 *        belief_model robot). Each value is identified, measured or a named gain; the source of
 *        each default is in doc/active_inference.md, 'The robot model', table 'Parameters'.
 *
 * Per side s in {L, R} the wheel speed omega_s follows the commanded wheel speed u_s through the
 * latency L and the MCU's wheel loop: a first-order lag T_w whose rate is bounded by A_w - A_ff,
 * less the side's actuation shortfall d_s (a slowly varying state), plus the MCU's acceleration
 * feed-forward of the command's rate, the share c of it bounded by A_ff:
 *   omega_s' = clamp((u_s(t - L) - d_s - omega_s) / T_w, -(A_w - A_ff), A_w - A_ff)
 *              + clamp(c u_s'(t - L), -A_ff, A_ff),                        d_s' = w_d (white),
 * u_s' the rate of the command stream (consecutive commands' difference over their interval, held
 * while the newer is in effect: what the MCU differentiates). c = 0 and A_ff = 0: no feed-forward.
 * The body's yaw rate follows the wheels' yaw rate u = r alpha (omega_R - omega_L) / b through the
 * effective separation b (learned), a yaw slip ratio s (a state that moves with the turn) and the
 * scrub lag T_s: theta_dot' = ((1 - s) u - theta_dot) / T_s + w_theta. The encoders read
 * omega_s + n_e, the gyro theta_dot + beta + n_g (beta: the gyro's offset, a state).
 */
struct RobotModelParams
{
  /// L [s]: /cmd_drive to the wheels' response (plant_identify: the plant's motor.command_delay).
  double latency = 0.1187;
  /// T_w [s], >= 0: the wheel loop's lag (identified motor keys). With c = 0 (below), its lag to a
  /// ramped command: the set-point lag plus the part (1 - J_ff / J_n) J_n / K_p the acceleration
  /// feedforward leaves to the P path. With the feed-forward in the model, the P path's own: the
  /// set-point lag plus J_n / K_p (0.01365 s).
  double wheel_time_constant = 0.00657;
  /// A_w [rad/s^2], > 0: the largest wheel acceleration the wheel loop gives (identified motor keys:
  /// (accel_feedforward_limit + proportional_limit) / J_n).
  double wheel_acceleration = 42.87;
  /// c [-], in [0, 2]: the share of the command stream's rate the MCU's acceleration feed-forward
  /// gives the wheel (identified motor keys: J_ff / J_n); 0 = none.
  double wheel_feedforward = 0.0;
  /// A_ff [rad/s^2], in [0, A_w): the bound of that feed-forward's acceleration (identified motor
  /// keys: accel_feedforward_limit / J_n); the lag's bound is the rest, A_w - A_ff.
  double wheel_feedforward_acceleration = 0.0;
  /// T_s [s], > 0: the scrub lag of the body's yaw rate behind the wheels' (a turn's transient);
  /// identified by plant_identify.py --bag on a bag's turns in place (the simulated Jackal's bags:
  /// 0.0091 / 0.0100 s).
  double yaw_time_constant = 0.01;
  /// sigma_e [rad/s], > 0: the noise of one side's measured wheel speed (a rest segment).
  double encoder_noise = 0.0071;
  /// sigma_g [rad/s], > 0: the gyro's noise (a rest segment).
  double gyro_noise = 0.005;
  /// q_w [rad/s^1.5], > 0: the wheel model's error, the spectral density of w on omega_s'.
  double wheel_model_noise = 1.0;
  /// q_d [rad/s^0.5], >= 0: the drift of the actuation shortfall d_s (its random walk).
  double shortfall_noise = 0.002;
  /// q_e [rad/s^0.5], >= 0: the drift of each side's turn shortfall e (the side's shortfall on top
  /// of d in a turn that loads it against its motion: the turn's scrub load over the MCU's wheel
  /// loop, RobotBelief::turnSigns()), a random walk while the robot turns; 0 = e fixed at 0.
  double turn_shortfall_noise = 0.0;
  /// e_c [rad/s], >= 0: the largest shortfall the action makes up by raising the command, per side;
  /// 0 = no bound. On a wheel loop whose proportional path saturates and whose integral path, without
  /// a load observer, takes the rest up over seconds (identified by plant_identify.py --bag:
  /// proportional_limit / speed_kp), a command raised further delivers nothing at once and winds the
  /// integral up for an overshoot (LatencyAction::compensated()).
  double shortfall_compensation_limit = 0.0;
  /// q_theta [rad/s^1.5], > 0: the yaw model's error on theta_dot'.
  double yaw_model_noise = 0.3;
  /// sigma_s [(rad/s)^-0.5], >= 0: how far the yaw slip ratio s may move with the turn: its
  /// variance grows by sigma_s^2 |du| when the wheels' yaw rate u changes by du; 0 = s fixed at 0.
  double yaw_slip_noise = 0.3;
  /// q_beta [rad/s^0.5], >= 0: the drift of the gyro's offset beta (its random walk in time); it sets
  /// how fast an offset jump is taken up; 0 = beta fixed at 0.
  double gyro_offset_noise = 0.01;
  /// k_a [1/s], > 0: the action's loop gain, the rate of its Gauss-Newton descent of the action's
  /// free energy; k_a h_a >= 1 (h_a the action step) reaches the minimiser in one step.
  double action_gain = 50.0;
  /// Learn L from the wheels' first motion after rest (LatencyLearner), within [kLatencyMinFactor,
  /// kLatencyMaxFactor] x `latency`; false: L as configured.
  bool learn_latency = false;
};

}  // namespace params
}  // namespace jackal_aic
