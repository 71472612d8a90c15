#pragma once
/**
 * \file stage_params.hpp
 * \brief The settings of the controller's stages, one struct per stage, each nested in AicParams
 *        (AicParams::reference, ::action_prior, ::anti_windup, ::action_slew, ::separation_learner,
 *        ::precision_learner, ::gyro_bias, ::tip_guard) and taken as it is by its stage's class.
 *        Each member's YAML key is its schema row's (src/params/param_spec.cpp); the ranges below
 *        are the schema's. None is in the thesis (doc/active_inference.md, 'Structure of the
 *        controller'). ROS-free.
 */

namespace jackal_aic
{
namespace params
{
/**
 * \brief The goal stage (ReferenceModel, GoalRateEstimator; AicParams::reference): the goal's rate
 *        from the set-point stream, the predicted goal and the rate-limited, delayed reference
 *        path the beliefs' attractor follows (doc/active_inference.md, 'Set-point dynamics').
 *
 * Generalized goal (generalized_goal true): the goal's rate mu_d' is estimated from the set-point
 * stream by finite differences (GoalRateEstimator) and the goal is predicted t_lead ahead,
 * mu_d + t_lead mu_d' (t_lead = goal_lead for x_dot and y_dot, goal_lead_angular for theta_dot; the speed not
 * predicted through a stop, aic::predictGoal()).
 * Without a reference model the attractor becomes f(mu) = mu_d' + (mu_d - mu) / tau. The thesis's
 * section 6-1 names such a generative model "that predicts the path towards the desired state".
 *
 * Reference model (time_constant T_r > 0; 0 = off, the thesis: f(mu) = (mu_d - mu) / tau, eq. 3-7):
 * the attractor is the path a wheel loop is expected to take to the (predicted) goal,
 * m' = (mu_d + t_lead mu_d' - m) / T_r, each channel's m' clamped to the acceleration bounds,
 * delayed by `delay`, mu_r(t) = m(t - d_r), and f(mu) = mu_r' + (mu_r - mu) / tau. The sensory
 * prediction error then measures the deviation from the expected path, not the path itself, so the
 * free-energy action does not wind up against the wheel loop's latency.
 */
struct ReferenceModelParams
{
  /// generalized_goal [-]: true = the goal's rate mu_d' is used; false = every set point is a step (mu_d' = 0).
  bool generalized_goal = false;
  /// goal_rate_hold [s], > 0, <= 10: a set-point change within this of the previous one continues a
  /// ramp (mu_d' = change / interval), a later one is a step; a slope is held for 1.25 change
  /// intervals, at most this long.
  double goal_rate_hold = 0.15;
  /// max_goal_rate_linear [m/s^2], > 0: |mu_d'| of x_dot is clamped to this.
  double max_goal_rate_linear = 4.0;
  /// max_goal_rate_angular [rad/s^2], > 0: |mu_d'| of theta_dot is clamped to this.
  double max_goal_rate_angular = 8.0;
  /// goal_lead [s], >= 0, <= 1: the linear channels' goal (x_dot, y_dot) is predicted this far ahead
  /// along its rate, mu_d + goal_lead mu_d' (the wheel loop's latency).
  double goal_lead = 0.0;
  /// goal_lead_angular [s], >= 0, <= 1: the yaw rate's goal is predicted this far ahead; a turn's
  /// body lags its wheels further than a speed change does (the tyres' lateral slip).
  double goal_lead_angular = 0.0;
  /// reference_time_constant T_r [s], >= 0, <= 10; 0 = no reference model.
  double time_constant = 0.0;
  /// max_reference_acceleration_linear [m/s^2], > 0: the path's acceleration along x_dot and y_dot
  /// (the acceleration the wheels' torque allows: a rate-limited path is what a wheel loop with
  /// acceleration feed-forward follows best).
  double max_acceleration_linear = 1.0e3;
  /// max_reference_acceleration_angular [rad/s^2], > 0: as max_acceleration_linear, along theta_dot.
  double max_acceleration_angular = 1.0e3;
  /// max_reference_acceleration_wheel [m/s^2], >= 0; 0 = none: each wheel's rim-speed rate along the
  /// path, |m'_x -+ m'_theta b_hat / 2|, is clamped to this before the body channels' bounds; a turn
  /// started with the forward speed then waits for the inner wheel, as the wheel loops do.
  double max_acceleration_wheel = 0.0;
  /// max_reference_deceleration_linear [m/s^2], >= 0; 0 = none (the path's other bounds): a payload's
  /// tip-over bound along x_dot, read by every belief model: m'_x >= -max_deceleration_linear
  /// (braking forward, and speeding up in reverse, which tips the robot over its front wheels as
  /// braking forward does; that start never looser than max_acceleration_linear) and, in reverse,
  /// m'_x <= max_deceleration_linear (braking); speeding up forward keeps max_acceleration_linear. Below the lower of the accelerations g d / h at which the
  /// robot tips over its front or rear wheels, d the horizontal distance of the centre of mass (with
  /// the payload) from that axle, h its height above the ground (ReferenceModel::accelerationBounds;
  /// plant_payload; doc/usage.md, 'Payloads').
  double max_deceleration_linear = 0.0;
  /// reference_delay d_r [s], >= 0, <= kMaxReferenceDelay: the latency between a command and the
  /// wheels' response that the beliefs expect (also the delay of belief_model unbiased's prior).
  double delay = 0.0;
};

/**
 * \brief The action prior (ActionPrior; AicParams::action_prior): a = a_F + a_ff,
 *        a_ff = k_ff W (m + T_p m') (with no reference model: k_ff W (mu_d + t_lead mu_d')), W the
 *        wheel rows of R (the inverse kinematics G^+, eq. 3-3): the wheel speeds the goal's path
 *        predicts, through the inverse of a first-order wheel loop, handed to the MCU's wheel-speed
 *        loop as a reflex arc fulfils a proprioceptive prediction (Adams, Shipp & Friston, Brain
 *        Struct. Funct. 2013); the free-energy gradient a_F (eq. 3-16) corrects what it does not
 *        deliver. doc/active_inference.md, 'Action prior'.
 */
struct ActionPriorParams
{
  /// action_prior_gain k_ff [-], in [0, 2]; 0 = off (the thesis: the action only descends F, eq. 3-16).
  double gain = 0.0;
  /// action_prior_time_constant T_p [s], >= 0, <= 10: the wheel loop's time constant the prior
  /// inverts (with a reference model only).
  double time_constant = 0.0;
};

/**
 * \brief The anti-windup of the action (AntiWindup; AicParams::anti_windup; doc/active_inference.md,
 *        'Update rules'). The action update (eq. 3-16) integrates the prediction error whatever the
 *        plant can follow, so while the wheel loop is slew- or torque-limited on a large step the
 *        action runs ahead of the wheels and the velocity overshoots when they catch up.
 */
struct AntiWindupParams
{
  /// max_action_lead [rad/s], >= 0, <= kMaxWheelSpeedLimit; 0 = off (the thesis). After each action
  /// step every wheel command a_i is kept within +-this of the measured wheel speed y^(0)[omega_i]
  /// (conditional integration). In steady state a = measured wheel speed, so the limit is inactive;
  /// set it above the lead the wheel loop needs for a step the plant follows without saturating.
  double max_action_lead = 0.0;
  /// max_action_lead_turn [rad/s], >= 0, <= kMaxWheelSpeedLimit; 0 = off. After the max_action_lead
  /// clamp the differential lead d = ((a_R - y[omega_R]) - (a_L - y[omega_L])) / 2 is kept within
  /// +-this, the common lead unchanged (so each wheel's lead stays within max_action_lead); not
  /// applied while a wheel channel is isolated (its reading is not trusted). A turn in place needs
  /// far more torque than a straight run (the wheels skid sideways), so while the wheels are held by
  /// friction a lead that suits a straight step winds the wheel loop up, and the turn overshoots
  /// when the wheels break free (doc/experiments.md, 'Tuning').
  double max_action_lead_turn = 0.0;
};

/**
 * \brief The slew limit of the action (ActionSlewLimit; AicParams::action_slew; doc/extending.md, the
 *        guide's worked example): after the anti-windup clamps, each wheel command moves by at most
 *        max_rate h per action step of h seconds. The Jackal's MCU slews its wheel-speed loop itself;
 *        a limit on the command keeps a noisy or aggressive action (an order-1 derivative term, a
 *        large step) from asking for accelerations the wheels answer only with slip and current
 *        peaks, as the stock diff drive's acceleration limits do for a twist.
 */
struct ActionSlewLimitParams
{
  /// action_slew_limit [rad/s^2], >= 0, <= kMaxGain; 0 = off (the thesis). The largest rate of change
  /// of either wheel's command; a larger change of the pair is scaled down as a whole.
  double max_rate = 0.0;
};

/**
 * \brief Learning the effective wheel separation b_hat on the robot (SeparationLearner;
 *        AicParams::separation_learner): b_hat descends the free energy of the gyro-encoder
 *        disagreement at the belief rate (Baioumy, Duckworth, Lacerda & Hawes, arXiv 2005.05894),
 *        starting from wheel_separation; doc/active_inference.md, 'Learning the generative model'.
 */
struct SeparationLearnerParams
{
  /// learn_wheel_separation: false = b_hat = wheel_separation, fixed.
  bool enabled = false;
  /// separation_learning_rate kappa_b [m^2 s / rad^2 per unit precision], >= 0, <= kMaxGain.
  double rate = 4.0;
  /// separation_min [m], in [kMinLength, kMaxLength], <= max: lower bound of b_hat.
  double min = 0.3;
  /// separation_max [m], in [kMinLength, kMaxLength]: upper bound of b_hat.
  double max = 1.5;
  /// separation_min_yaw_rate [rad/s], >= 0, <= 10: b_hat is frozen while |gyro| is below this (the
  /// robot model: while the believed wheels' |yaw rate| is).
  double min_yaw_rate = 0.1;
  /// separation_max_yaw_acceleration [rad/s^2], > 0, <= kMaxGain: b_hat is frozen while |d gyro/dt|
  /// (y^(1) of the gyro) is above this; with belief_model robot, b_hat, the slip ratio and the gyro
  /// offset also while the believed wheels' yaw acceleration or their common acceleration counted as
  /// one side's (2 |x_dot'| / b_hat) is (ActiveInferenceController::updateRobotBeliefs()).
  double max_yaw_acceleration = 0.5;
  /// separation_max_rate [1/s], >= 0, <= 10; 0 = unlimited: |db_hat/dt| <= max_rate b_hat.
  double max_rate = 0.1;
};

/**
 * \brief Learning the order-0 sensory precisions Pi_y^(0) of the gyro, the wheels (and accelerometer
 *        x with accel_in_model) from the prediction errors seen (PrecisionLearner;
 *        AicParams::precision_learner): ln Pi_j descends the free energy, Pi_j -> 1 / E[eps_j^2]
 *        (Baioumy, Duckworth, Lacerda & Hawes, arXiv 2005.05894), starting from 1 / var_y;
 *        doc/active_inference.md, 'Learning the sensory precisions'.
 */
struct PrecisionLearnerParams
{
  /// learn_precision: false = Pi_y = 1 / var_y, fixed.
  bool enabled = false;
  /// precision_learning_rate kappa_pi [1/s], >= 0, <= kMaxGain (near the optimum ln Pi relaxes with 2 / kappa_pi).
  double rate = 0.2;
  /// precision_min_factor [-], > 0, <= 1: Pi_min = min_factor x the configured precision.
  double min_factor = 0.1;
  /// precision_max_factor [-], >= 1, <= kMaxGain: Pi_max = max_factor x the configured precision.
  double max_factor = 10.0;
  /// precision_time_constant T_w [s], > 0, <= 1000: the low-pass of the squared prediction errors.
  double time_constant = 1.0;
  /// precision_min_wheel_speed [rad/s], >= 0, <= 100: frozen while both |omega_L|, |omega_R| are below this.
  double min_wheel_speed = 0.5;
};

/**
 * \brief Learning the gyro's offset beta_hat at standstill (GyroBiasEstimator, for the gyro z and,
 *        for the tip-over guard, the gyro y; AicParams::gyro_bias): beta_hat is the mean of the
 *        gyro's readings while the wheels and their commands stand still, subtracted from every gyro
 *        sample; doc/active_inference.md, 'Learning the gyro's offset'.
 */
struct GyroBiasEstimatorParams
{
  /// learn_gyro_bias: false = the gyro is used as it reads.
  bool enabled = false;
  /// gyro_bias_max [rad/s], > 0, <= 1: |beta_hat| bound, and the largest |y_gyro| at rest taken as an offset.
  double max_bias = 0.1;
  /// gyro_bias_rest_speed [rad/s], > 0, <= 10: at rest, both wheels' and both commands' |speed| are below this.
  double rest_speed = 0.05;
  /// gyro_bias_rest_time [s], >= 0, <= 10: beta_hat learns from this long after a rest began.
  double rest_time = 0.5;
  /// gyro_bias_time_constant T_beta [s], > 0, <= 1e5: the forgetting once the first rest is averaged.
  double time_constant = 30.0;
  /// gyro_bias_min_rest [s], >= 0, <= 600: beta_hat is removed from the gyro once this much rest has
  /// been learned from (offset() is 0 before).
  double min_rest = 5.0;
};

/**
 * \brief The tip-over guard (TipGuard; AicParams::tip_guard): the body's pitch is integrated from
 *        the IMU's gyro y; when it exceeds trip_pitch while the robot brakes (speeds up), the
 *        reference path stops braking (speeding up) until the body is level again, and later paths
 *        are bounded by margin x the deceleration (acceleration) at which the wheels lifted. It acts
 *        on the reference path: no effect with reference_time_constant 0; doc/active_inference.md,
 *        'The tip-over guard'.
 */
struct TipGuardParams
{
  /// tip_guard: false = none.
  bool enabled = false;
  /// tip_guard_pitch [rad], > 0, <= 0.5: the |pitch| that trips the guard.
  double trip_pitch = 0.02;
  /// tip_guard_margin [-], in (0, 1]: the learned bound is this factor of the wheels' acceleration at
  /// the lift's onset (braked wheels slip: their deceleration there is 1.2-1.5 x the body's tipping limit).
  double margin = 0.6;
  /// tip_guard_min_acceleration [m/s^2], > 0, <= 100: the floor of the learned bounds.
  double min_acceleration = 1.0;
  /// tip_guard_turnover_pitch [rad], > trip_pitch, <= 1.5: the |pitch| past which the body has
  /// turned over (no wheel command rolls it back) and the wheels are stopped; a body read on its
  /// back by the accelerometer is released within this tilt of upright. 0.4 = atan(4.20 /
  /// 9.81): braking tips a robot only when g d / h is below the wheels' deceleration A_w r (4.20
  /// m/s^2 on the Jackal), so its centre of mass is over the front axle by the pitch atan(d / h)
  /// < 0.405 rad (doc/active_inference.md, 'The tip-over guard').
  double turnover_pitch = 0.4;
};

}  // namespace params
}  // namespace jackal_aic
