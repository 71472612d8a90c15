/**
 * \file param_spec.cpp
 * \brief The controller's parameter rows (the keys of AicParams; thesis tables C-1 and 5-8
 *        for the ranges) and the table's rules, shared by both scopes
 *        (include/jackal_aic/params/param_spec.hpp; doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_aic/params/param_spec.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <type_traits>

namespace jackal_aic
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// Accessors of a member of AicParams (p.m); no NodeParams accessors.
#define JACKAL_AIC_CONTROLLER(member)                        \
  [](const AicParams& p) -> ParamValue { return p.member; }, \
      [](AicParams& p, const ParamValue& v) { return assignParamValue(&p.member, v); }, nullptr, nullptr

ParamValue getIntegrator(const AicParams& p)
{
  return toString(p.integrator);
}

bool setIntegrator(AicParams& p, const ParamValue& v)
{
  const std::string* name = std::get_if<std::string>(&v);
  return name != nullptr && integratorFromString(*name, &p.integrator);
}

ParamValue getBeliefModel(const AicParams& p)
{
  return toString(p.belief_model);
}

bool setBeliefModel(AicParams& p, const ParamValue& v)
{
  const std::string* name = std::get_if<std::string>(&v);
  return name != nullptr && beliefModelFromString(*name, &p.belief_model);
}

std::vector<ParamSpec> buildControllerRows()
{
  using T = ParamType;
  const ParamScope C = ParamScope::kController;
  // clang-format off
  return {
    // ---- loops
    { "belief_rate", T::kDouble, C, "loops", 0.0, true, kMaxRate, "Hz",
      "Belief update rate (timer); >= action_rate; the node runs at most 10000 Hz",
      true, 1, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(belief_rate), kMaxLoopRate },
    { "action_rate", T::kDouble, C, "loops", 0.0, true, kMaxRate, "Hz",
      "Action update rate; /cmd_drive is published at this rate; the node runs at most 10000 Hz",
      true, 1, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(action_rate), kMaxLoopRate },
    { "integrator", T::kString, C, "loops", kNone, false, kNone, "-",
      "Belief integrator: euler (thesis eq. 3-15, forward Euler) or exact (zero-order-hold exact step of the "
      "linear belief dynamics)",
      true, 0, false, 0, { "euler", "exact" }, 0, &getIntegrator, &setIntegrator, nullptr, nullptr },
    // ---- active inference (thesis tables C-1 / 5-8)
    { "tau", T::kDouble, C, "active_inference", kMinTau, false, kMaxTau, "s",
      "Attractor time constant tau of f(mu) = (mu_d - mu) / tau (thesis eq. 3-7)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(tau) },
    { "k_mu", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "-",
      "Belief learning rate k_mu (thesis eq. 3-15)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(k_mu) },
    { "k_a", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "-",
      "Action learning rate k_a (thesis eq. 3-16)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(k_a) },
    { "embedding_order", T::kInt, C, "active_inference", 1.0, false, static_cast<double>(kMaxEmbeddingOrder), "-",
      "Embedding order p: generalized orders 0..p are used (thesis eq. 3-17)",
      true, 2, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(embedding_order) },
    { "var_mu", T::kDoubleList, C, "active_inference", kMinVariance, false, kMaxVariance, "SI^2 of each order",
      "Belief variances sigma^2_mu, one per order 0..p or one per order and channel (x_dot, y_dot, theta_dot; "
      "order-major); precision Pi_mu = 1/sigma^2 (thesis table C-1)",
      true, 0, false, kMuDim, {}, kMaxOrders, JACKAL_AIC_CONTROLLER(var_mu) },
    { "var_y", T::kDoubleList, C, "active_inference", kMinVariance, false, kMaxVariance, "SI^2 of each order",
      "Sensor variances sigma^2_y, one per order 0..p or one per order and channel (gyro z, omega_L, omega_R, "
      "accel x, accel y; order-major); precision Pi_y = 1/sigma^2 (thesis table C-1)",
      true, 0, false, kYDim, {}, kMaxOrders, JACKAL_AIC_CONTROLLER(var_y) },
    { "accel_in_model", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the accelerometer-x row of the sensor model maps onto mu^(1); false is the thesis model "
      "(accelerometer rows zero)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(accel_in_model) },
    { "runaway_limit", T::kDouble, C, "active_inference", 0.0, true, kMaxRunawayLimit, "SI",
      "Any belief element beyond this magnitude (or non-finite) is a runaway: reset, zero command, diagnostics "
      "ERROR",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(runaway_limit) },
    { "max_action_lead", T::kDouble, C, "robot", 0.0, false, kMaxWheelSpeedLimit, "rad/s",
      "Anti-windup, not in the thesis: each wheel command is kept within +-this of the measured wheel speed; "
      "0 = off",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(anti_windup.max_action_lead) },
    { "max_action_lead_turn", T::kDouble, C, "robot", 0.0, false, kMaxWheelSpeedLimit, "rad/s",
      "Anti-windup of turning, not in the thesis: half the difference of the two wheels' leads is kept within "
      "+-this (a turn in place winds the wheel loop up while friction holds the wheels); 0 = off",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(anti_windup.max_action_lead_turn) },
    { "action_release_time", T::kDouble, C, "robot", 0.0, false, 10.0, "s",
      "Release at rest, not in the thesis: the free-energy action's common (differential) part decays with this "
      "time constant while the linear (yaw-rate) goal is zero, so a stop stops the wheels; 0 = off",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(action_release_time) },
    // ---- set-point dynamics and the action prior (not in the thesis; doc/active_inference.md)
    { "generalized_goal", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the goal's rate mu_d' comes from the set-point stream by finite differences and the goal is "
      "predicted goal_lead ahead (a generalized goal); false: every set point is a step",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.generalized_goal) },
    { "goal_rate_hold", T::kDouble, C, "active_inference", 0.0, true, 10.0, "s",
      "Generalized goal: a set-point change within this of the previous one continues a ramp (mu_d' = change / "
      "interval), a later one is a step; a slope is held 1.25 change intervals, at most this long",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.goal_rate_hold) },
    { "max_goal_rate_linear", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "m/s^2",
      "Generalized goal: |mu_d'| of x_dot is clamped to this",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_goal_rate_linear) },
    { "max_goal_rate_angular", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^2",
      "Generalized goal: |mu_d'| of theta_dot is clamped to this",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_goal_rate_angular) },
    { "goal_lead", T::kDouble, C, "active_inference", 0.0, false, 1.0, "s",
      "Generalized goal: the linear goal (x_dot, y_dot) is predicted this far ahead, mu_d + goal_lead mu_d'",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.goal_lead) },
    { "goal_lead_angular", T::kDouble, C, "active_inference", 0.0, false, 1.0, "s",
      "Generalized goal: the yaw-rate goal is predicted this far ahead, mu_d + goal_lead_angular mu_d'",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.goal_lead_angular) },
    { "reference_time_constant", T::kDouble, C, "active_inference", 0.0, false, 10.0, "s",
      "Reference model T_r: the beliefs are drawn to the path m' = (goal - m) / T_r delayed by reference_delay, "
      "f(mu) = mu_r' + (mu_r - mu) / tau; 0 = off (the thesis's f(mu) = (mu_d - mu) / tau, eq. 3-7)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.time_constant) },
    { "goal_response_time_constant", T::kDouble, C, "active_inference", 0.0, false, 10.0, "s",
      "Unbiased beliefs: the action's goal prior targets the goal's path as the robot follows it, "
      "g' = (mu_r - g) / T_g; 0 = off (the reference path mu_r itself); no effect with belief_model goal",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(goal_response_time_constant) },
    { "max_reference_acceleration_linear", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "m/s^2",
      "Reference model: the path's acceleration along x_dot is clamped to this (what the wheels' torque allows)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_acceleration_linear) },
    { "max_reference_acceleration_angular", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^2",
      "Reference model: the path's acceleration along theta_dot is clamped to this",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_acceleration_angular) },
    { "max_reference_acceleration_wheel", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "m/s^2",
      "Reference model: each wheel's rim-speed rate along the path, |m'_x -+ m'_theta b_hat / 2|, is clamped to "
      "this before the body channels' bounds (the wheel loops saturate per wheel: a turn started with the "
      "forward speed waits for the inner wheel); 0 = none",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_acceleration_wheel) },
    { "max_reference_deceleration_linear", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "m/s^2",
      "Reference model: the path's deceleration along x_dot (slowing toward 0) is clamped to this: below the "
      "deceleration at which the robot with its payload tips over (g d / h; doc/usage.md, 'Payloads'); 0 = "
      "max_reference_acceleration_linear",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.max_deceleration_linear) },
    { "reference_delay", T::kDouble, C, "active_inference", 0.0, false, kMaxReferenceDelay, "s",
      "Reference model: the latency from command to wheel response that the beliefs expect",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(reference.delay) },
    { "action_prior_gain", T::kDouble, C, "active_inference", 0.0, false, 2.0, "-",
      "Action prior k_ff: a = a_F + k_ff W (m + T_p m'), the reference path's wheel speeds (inverse model, "
      "eq. 3-3) handed to the MCU's wheel loop, a_F the free-energy action (eq. 3-16); 0 = off (the thesis)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(action_prior.gain) },
    { "action_prior_time_constant", T::kDouble, C, "active_inference", 0.0, false, 10.0, "s",
      "Action prior: the wheel loop's time constant T_p that the prior inverts (with a reference model)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(action_prior.time_constant) },
    // ---- unbiased beliefs and learning the generative model (not in the thesis; doc/active_inference.md)
    { "belief_model", T::kString, C, "active_inference", kNone, false, kNone, "-",
      "State prior of the beliefs: goal (the thesis, f(mu) = (mu_d - mu) / tau, eq. 3-7) or unbiased "
      "(f = (G a(t - d_r) - mu) / tau, the robot's response to the sent action; the goal drives the action) or "
      "robot (the identified model of the wheels, their latency and the yaw rate; the action descends F through it)",
      true, 0, false, 0, { "goal", "unbiased", "robot" }, 0, &getBeliefModel, &setBeliefModel, nullptr, nullptr },
    // ---- the robot model (belief_model robot; doc/active_inference.md, 'The robot model')
    { "latency", T::kDouble, C, "active_inference", 0.0, false, kMaxReferenceDelay, "s",
      "Robot model: L, /cmd_drive to the wheels' response (identified: plant_identify's command_delay)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.latency) },
    { "wheel_time_constant", T::kDouble, C, "active_inference", 0.0, false, 1.0, "s",
      "Robot model: T_w, the MCU wheel loop's lag to a ramped command (identified motor keys)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.wheel_time_constant) },
    { "wheel_acceleration", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^2",
      "Robot model: A_w, the largest wheel acceleration the MCU's wheel loop gives (identified motor keys)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.wheel_acceleration) },
    { "yaw_time_constant", T::kDouble, C, "active_inference", 0.0, true, 10.0, "s",
      "Robot model: T_s, the scrub lag of the body's yaw rate behind the wheels'",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.yaw_time_constant) },
    { "encoder_noise", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s",
      "Robot model: sigma_e, one side's wheel-speed noise (measured on a rest segment); Pi = 1 / sigma_e^2",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.encoder_noise) },
    { "gyro_noise", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s",
      "Robot model: sigma_g, the gyro's noise (measured on a rest segment); Pi = 1 / sigma_g^2",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.gyro_noise) },
    { "wheel_model_noise", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^1.5",
      "Robot model: q_w, the wheel model's error (spectral density on omega'): the prior's precision",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.wheel_model_noise) },
    { "shortfall_noise", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "rad/s^0.5",
      "Robot model: q_d, the drift of each side's actuation shortfall d (its random walk); 0 = d fixed at 0",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.shortfall_noise) },
    { "yaw_model_noise", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^1.5",
      "Robot model: q_theta, the yaw model's error on theta_dot'",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.yaw_model_noise) },
    { "yaw_slip_noise", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "rad/s^0.5",
      "Robot model: q_e, the drift of the yaw shortfall e (the yaw rate the wheels through b_hat do not deliver); "
      "0 = e fixed at 0",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.yaw_slip_noise) },
    { "action_gain", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "1/s",
      "Robot model: k_a, the action's loop gain (the rate of its Gauss-Newton descent of F; k_a >= action_rate "
      "reaches the minimiser each action step)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(robot.action_gain) },
    { "learn_wheel_separation", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the model's wheel separation b_hat descends the free energy of the gyro-encoder disagreement "
      "(frozen near rest, while the action saturates and while a sensor is isolated); false: b_hat fixed",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.enabled) },
    { "separation_learning_rate", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "m^2 s/rad^2",
      "Learning rate kappa_b of b_hat: db_hat/dt = -kappa_b dF_b/db_hat",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.rate) },
    { "separation_min", T::kDouble, C, "active_inference", kMinLength, false, kMaxLength, "m",
      "Lower bound of the learned wheel separation b_hat (<= separation_max)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.min) },
    { "separation_max", T::kDouble, C, "active_inference", kMinLength, false, kMaxLength, "m",
      "Upper bound of the learned wheel separation b_hat",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.max) },
    { "separation_min_yaw_rate", T::kDouble, C, "active_inference", 0.0, false, 10.0, "rad/s",
      "b_hat is frozen while the gyro's |yaw rate| is below this (near rest)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.min_yaw_rate) },
    { "separation_max_yaw_acceleration", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "rad/s^2",
      "b_hat is frozen while the gyro's |yaw acceleration| (its generalized order 1) is above this (a transient)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.max_yaw_acceleration) },
    { "separation_max_rate", T::kDouble, C, "active_inference", 0.0, false, 10.0, "1/s",
      "b_hat moves by at most this share of itself per second (slower than the fault monitor detects a "
      "sensor fault, so that learning cannot explain the fault away); 0 = unlimited",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(separation_learner.max_rate) },
    { "learn_precision", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the order-0 sensory precisions of the gyro and the wheels descend the free energy, "
      "Pi_j -> 1 / E[eps_j^2] (frozen near rest, while the action saturates and while a sensor is isolated); "
      "false: Pi_y = 1 / var_y fixed",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.enabled) },
    { "precision_learning_rate", T::kDouble, C, "active_inference", 0.0, false, kMaxGain, "1/s",
      "Learning rate kappa_pi of the log-precisions: d ln Pi_j/dt = -kappa_pi (Pi_j s_j - 1) / 2",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.rate) },
    { "precision_min_factor", T::kDouble, C, "active_inference", 0.0, true, 1.0, "-",
      "Lower bound of a learned precision, as a factor of the configured 1 / var_y",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.min_factor) },
    { "precision_max_factor", T::kDouble, C, "active_inference", 1.0, false, kMaxGain, "-",
      "Upper bound of a learned precision, as a factor of the configured 1 / var_y",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.max_factor) },
    { "precision_time_constant", T::kDouble, C, "active_inference", 0.0, true, 1000.0, "s",
      "Time constant of the low-pass of the squared prediction errors s_j the precisions learn from",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.time_constant) },
    { "precision_min_wheel_speed", T::kDouble, C, "active_inference", 0.0, false, 100.0, "rad/s",
      "The precisions are frozen while both wheels' |speed| is below this (near rest)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(precision_learner.min_wheel_speed) },
    { "learn_gyro_bias", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the gyro's offset beta_hat is learned while the wheels and their commands stand still and "
      "subtracted from every gyro sample (frozen while moving and while the gyro is flagged); false: none",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.enabled) },
    { "gyro_bias_max", T::kDouble, C, "active_inference", 0.0, true, 1.0, "rad/s",
      "Bound of the learned gyro offset |beta_hat|; a larger |reading| at rest is not learned from (the robot "
      "is turned by hand, or a fault)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.max_bias) },
    { "gyro_bias_rest_speed", T::kDouble, C, "active_inference", 0.0, true, 10.0, "rad/s",
      "At rest for the gyro offset: both wheels' and both wheel commands' |speed| below this",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.rest_speed) },
    { "gyro_bias_rest_time", T::kDouble, C, "active_inference", 0.0, false, 10.0, "s",
      "The gyro offset learns from this long after a rest began (the body's yaw settles)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.rest_time) },
    { "gyro_bias_time_constant", T::kDouble, C, "active_inference", 0.0, true, 1.0e5, "s",
      "Time constant T_beta with which the gyro offset follows a drift once the first rest is averaged",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.time_constant) },
    { "gyro_bias_min_rest", T::kDouble, C, "active_inference", 0.0, false, 600.0, "s",
      "The learned gyro offset is removed from the gyro once this much rest has been learned from (the "
      "average of a shorter rest is mostly noise); before that, none",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(gyro_bias.min_rest) },
    { "tip_guard", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the body's pitch is integrated from the gyro's y axis; when it passes tip_guard_pitch while "
      "the robot brakes (speeds up), the reference path stops braking until the body is level, and later "
      "paths stay below tip_guard_margin x the deceleration at which the wheels lifted (no effect with "
      "reference_time_constant 0)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(tip_guard.enabled) },
    { "tip_guard_pitch", T::kDouble, C, "active_inference", 0.0, true, 0.5, "rad",
      "|pitch| that trips the tip-over guard (a rigid robot on flat ground pitches only when a pair of "
      "wheels leaves it)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(tip_guard.trip_pitch) },
    { "tip_guard_margin", T::kDouble, C, "active_inference", 0.0, true, 1.0, "-",
      "The tip-over guard's learned bound is this factor of the deceleration (acceleration) at which the "
      "wheels lifted",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(tip_guard.margin) },
    { "tip_guard_min_acceleration", T::kDouble, C, "active_inference", 0.0, true, 100.0, "m/s^2",
      "Floor of the tip-over guard's learned deceleration and acceleration bounds",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(tip_guard.min_acceleration) },
    // ---- robot (Clearpath Jackal; doc/jackal.md)
    { "wheel_radius", T::kDouble, C, "robot", kMinLength, false, kMaxLength, "m",
      "Wheel radius r (thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(wheel_radius) },
    { "slip_factor", T::kDouble, C, "robot", kMinSlipFactor, false, kMaxSlipFactor, "-",
      "Slip factor alpha of the extended differential drive (thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(slip_factor) },
    { "wheel_separation", T::kDouble, C, "robot", kMinLength, false, kMaxLength, "m",
      "Virtual wheel separation b_hat (identified; the track is 0.376 m; thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(wheel_separation) },
    { "max_wheel_speed", T::kDouble, C, "robot", 0.0, true, kMaxWheelSpeedLimit, "rad/s",
      "Wheel commands are clamped to +-this (2.0 m/s / 0.098 m ~ 20.4 rad/s)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_CONTROLLER(max_wheel_speed) },
  };
  // clang-format on
}
#undef JACKAL_AIC_CONTROLLER

std::string formatNumber(double v)
{
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

/// Adds a violation if v is not finite or outside the row's range.
void checkNumber(const ParamSpec& row, const std::string& name, double v, std::vector<ParamViolation>* out)
{
  const bool ok = std::isfinite(v) && (row.min_exclusive ? v > row.min : v >= row.min) && v <= row.max;
  if (!ok)
  {
    out->push_back({ name, formatNumber(v), rangeText(row) });
  }
}

/// Size rule of a per-order list (ParamSpec::channels > 0).
void checkListSize(const ParamSpec& row, const std::vector<double>& var, int embedding_order,
                   std::vector<ParamViolation>* out)
{
  const std::string key = row.key;
  const bool order_ok = embedding_order >= 1 && embedding_order <= kMaxEmbeddingOrder;
  const int channels = row.channels;
  if (order_ok)
  {
    const std::size_t n = static_cast<std::size_t>(embedding_order + 1);
    if (var.size() != n && var.size() != n * static_cast<std::size_t>(channels))
    {
      out->push_back({ key + ".size()", std::to_string(var.size()),
                       std::to_string(n) + " (one per order) or " + std::to_string(n * channels) +
                           " (per order and channel, order-major) for embedding_order " +
                           std::to_string(embedding_order) });
    }
  }
  else if (var.empty())
  {
    out->push_back(
        { key + ".size()", "0", "embedding_order + 1 or " + std::to_string(channels) + " * (embedding_order + 1)" });
  }
}

void checkStringList(const ParamSpec& row, const std::vector<std::string>& names, std::vector<ParamViolation>* out)
{
  const std::string key = row.key;
  if (names.empty())
  {
    out->push_back({ key, "[]", "a non-empty list of joint names" });
    return;
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const std::string item = key + "[" + std::to_string(i) + "]";
    if (names[i].empty())
    {
      out->push_back({ item, "\"\"", "a non-empty joint name" });
    }
    else if (!seen.insert(names[i]).second)
    {
      out->push_back({ item, names[i], "a name not listed twice" });
    }
  }
}
}  // namespace

bool ParamSpec::numeric() const
{
  return type == ParamType::kDouble || type == ParamType::kInt || type == ParamType::kDoubleList;
}

const std::vector<ParamSpec>& controllerParamSpecs()
{
  static const std::vector<ParamSpec> rows = buildControllerRows();
  return rows;
}

void checkParamValue(const ParamSpec& row, const ParamValue& value, int embedding_order,
                     std::vector<ParamViolation>* out)
{
  switch (row.type)
  {
    case ParamType::kDouble:
      checkNumber(row, row.key, std::get<double>(value), out);
      break;
    case ParamType::kInt: {
      const int v = std::get<int>(value);
      if (v < row.min || v > row.max)
      {
        out->push_back({ row.key, std::to_string(v), rangeText(row) });
      }
      break;
    }
    case ParamType::kDoubleList: {
      const auto& list = std::get<std::vector<double>>(value);
      if (row.channels > 0)
      {
        checkListSize(row, list, embedding_order, out);
      }
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        checkNumber(row, std::string(row.key) + "[" + std::to_string(i) + "]", list[i], out);
      }
      break;
    }
    case ParamType::kString: {
      const auto& s = std::get<std::string>(value);
      if (!row.choices.empty() && std::find(row.choices.begin(), row.choices.end(), s) == row.choices.end())
      {
        out->push_back({ row.key, s, rangeText(row) });
      }
      break;
    }
    case ParamType::kStringList:
      checkStringList(row, std::get<std::vector<std::string>>(value), out);
      break;
    case ParamType::kBool:
      break;
  }
}

std::vector<ParamViolation> checkParamRanges(const AicParams& params)
{
  std::vector<ParamViolation> out;
  for (const ParamSpec& row : controllerParamSpecs())
  {
    checkParamValue(row, row.get_aic(params), params.embedding_order, &out);
  }
  return out;
}

std::string expectedText(const ParamSpec& row)
{
  switch (row.type)
  {
    case ParamType::kDouble:
      return "a number";
    case ParamType::kInt:
      return "an integer";
    case ParamType::kBool:
      return "true or false";
    case ParamType::kString: {
      std::string text = "a string";
      for (std::size_t i = 0; i < row.choices.size(); ++i)
      {
        text += (i == 0 ? ": " : " or ") + row.choices[i];
      }
      return text;
    }
    case ParamType::kDoubleList:
      return "a list of numbers";
    case ParamType::kStringList:
      return "a list of strings";
  }
  return "a value";
}

std::string rangeText(const ParamSpec& row)
{
  switch (row.type)
  {
    case ParamType::kInt:
      return "integer in [" + formatNumber(row.min) + ", " + formatNumber(row.max) + "]";
    case ParamType::kDouble:
    case ParamType::kDoubleList: {
      std::string text = (row.min_exclusive ? "> " : ">= ") + formatNumber(row.min);
      return std::isinf(row.max) ? text + " and finite" : text + " and <= " + formatNumber(row.max) + ", finite";
    }
    case ParamType::kString: {
      std::string text;
      for (const auto& c : row.choices)
      {
        text += (text.empty() ? "" : " | ") + c;
      }
      return text.empty() ? "any string" : text;
    }
    case ParamType::kBool:
      return "true | false";
    case ParamType::kStringList:
      return "a non-empty list of distinct, non-empty names";
  }
  return "";
}

std::string formatParamValue(const ParamValue& value)
{
  struct Printer
  {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(int i) const { return std::to_string(i); }
    std::string operator()(double d) const { return formatNumber(d); }
    std::string operator()(const std::string& s) const { return s; }
    std::string operator()(const std::vector<double>& v) const
    {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i)
      {
        out += (i ? ", " : "") + formatNumber(v[i]);
      }
      return out + "]";
    }
    std::string operator()(const std::vector<std::string>& v) const
    {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i)
      {
        out += (i ? ", " : "") + v[i];
      }
      return out + "]";
    }
  };
  return std::visit(Printer{}, value);
}

}  // namespace jackal_aic
