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
#include <stdexcept>
#include <utility>
#include <type_traits>

namespace jackal_aic
{
namespace params
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

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
  // clang-format off
  return {
    // ---- loops
    ParamRow("loops", "belief_rate").unit("Hz").atLeast(kMinRate).atMost(kMaxRate).nodeMax(kMaxLoopRate)
        .describe("Belief update rate (timer); >= action_rate; the node runs at most 10000 Hz")
        .level(1).member<&AicParams::belief_rate>(),
    ParamRow("loops", "action_rate").unit("Hz").atLeast(kMinRate).atMost(kMaxRate).nodeMax(kMaxLoopRate)
        .describe("Action update rate; /cmd_drive is published at this rate; the node runs at most 10000 Hz")
        .level(1).member<&AicParams::action_rate>(),
    ParamRow("loops", "integrator")
        .describe("Belief integrator: euler (thesis eq. 3-15, forward Euler) or exact (zero-order-hold exact step "
                  "of the linear belief dynamics)")
        .choices({ "euler", "exact" }).readBy(kLinearBeliefModels).accessors(&getIntegrator, &setIntegrator),
    // ---- active inference (thesis tables C-1 / 5-8)
    ParamRow("active_inference", "tau").unit("s").atLeast(kMinTau).atMost(kMaxTau)
        .describe("Attractor time constant tau of f(mu) = (mu_d - mu) / tau (thesis eq. 3-7)")
        .readBy(kLinearBeliefModels).member<&AicParams::tau>(),
    ParamRow("active_inference", "k_mu").above(0.0).atMost(kMaxGain)
        .describe("Belief learning rate k_mu (thesis eq. 3-15)")
        .readBy(kLinearBeliefModels).member<&AicParams::k_mu>(),
    ParamRow("active_inference", "k_a").above(0.0).atMost(kMaxGain)
        .describe("Action learning rate k_a (thesis eq. 3-16)")
        .readBy(kLinearBeliefModels).member<&AicParams::k_a>(),
    ParamRow("active_inference", "embedding_order").atLeast(1.0).atMost(static_cast<double>(base::kMaxEmbeddingOrder))
        .describe("Embedding order p: generalized orders 0..p are used (thesis eq. 3-17); var_mu and var_y need "
                  "p + 1 entries: extend them by the rule of doc/tuning.md, 'Embedding order and the variance lists'")
        .level(2).member<&AicParams::embedding_order>(),
    ParamRow("active_inference", "var_mu").unit("SI^2 of each order").atLeast(kMinVariance).atMost(kMaxVariance)
        .describe("Belief variances sigma^2_mu, one per order 0..p or one per order and channel (x_dot, y_dot, "
                  "theta_dot; order-major); precision Pi_mu = 1/sigma^2 (thesis table C-1); order i weighs the "
                  "belief's i-th rate (doc/tuning.md, 'Embedding order and the variance lists')")
        .perOrder(base::kMuDim, base::kMaxOrders).readBy(kLinearBeliefModels).member<&AicParams::var_mu>(),
    ParamRow("active_inference", "var_y").unit("SI^2 of each order").atLeast(kMinVariance).atMost(kMaxVariance)
        .describe("Sensor variances sigma^2_y, one per order 0..p or one per order and channel (gyro z, omega_L, "
                  "omega_R, accel x, accel y; order-major); precision Pi_y = 1/sigma^2 (thesis table C-1); order i "
                  "weighs the sensors' i-th finite difference (doc/tuning.md, 'Embedding order and the variance "
                  "lists')")
        .perOrder(base::kYDim, base::kMaxOrders).readBy(kLinearBeliefModels).member<&AicParams::var_y>(),
    ParamRow("active_inference", "accel_in_model")
        .describe("If true, the accelerometer-x row of the sensor model maps onto mu^(1); false is the thesis "
                  "model (accelerometer rows zero)")
        .readBy(kLinearBeliefModels).member<&AicParams::accel_in_model>(),
    ParamRow("active_inference", "runaway_limit").unit("SI").above(0.0).atMost(kMaxRunawayLimit)
        .describe("Any belief element beyond this magnitude (or non-finite) is a runaway: reset, zero command, "
                  "diagnostics ERROR")
        .member<&AicParams::runaway_limit>(),
    ParamRow("robot", "max_action_lead").unit("rad/s").atLeast(0.0).atMost(kMaxWheelSpeedLimit)
        .describe("Anti-windup, not in the thesis: each wheel command is kept within +-this of the measured wheel "
                  "speed; 0 = off")
        .readBy(kLinearBeliefModels).member<&AicParams::anti_windup, &AntiWindupParams::max_action_lead>(),
    ParamRow("robot", "max_action_lead_turn").unit("rad/s").atLeast(0.0).atMost(kMaxWheelSpeedLimit)
        .describe("Anti-windup of turning, not in the thesis: half the difference of the two wheels' leads is kept "
                  "within +-this (a turn in place winds the wheel loop up while friction holds the wheels); 0 = off")
        .readBy(kLinearBeliefModels).member<&AicParams::anti_windup, &AntiWindupParams::max_action_lead_turn>(),
    ParamRow("robot", "action_release_time").unit("s").atLeast(0.0).atMost(10.0)
        .describe("Release at rest, not in the thesis: the free-energy action's common (differential) part decays "
                  "with this time constant while the linear (yaw-rate) goal is zero, so a stop stops the wheels; 0 "
                  "= off")
        .readBy(kLinearBeliefModels).member<&AicParams::action_release_time>(),
    ParamRow("robot", "action_slew_limit").unit("rad/s^2").atLeast(0.0).atMost(kMaxGain)
        .describe("Slew limit, not in the thesis: each wheel command changes by at most this times the action "
                  "step, a larger change of the pair scaled down as a whole; 0 = off")
        .member<&AicParams::action_slew, &ActionSlewLimitParams::max_rate>(),
    // ---- set-point dynamics and the action prior (not in the thesis; doc/active_inference.md)
    ParamRow("active_inference", "generalized_goal")
        .describe("If true, the goal's rate mu_d' comes from the set-point stream by finite differences and the "
                  "goal is predicted goal_lead ahead (a generalized goal); false: every set point is a step")
        .member<&AicParams::reference, &ReferenceModelParams::generalized_goal>(),
    ParamRow("active_inference", "goal_rate_hold").unit("s").above(0.0).atMost(10.0)
        .describe("Generalized goal: a set-point change within this of the previous one continues a ramp (mu_d' = "
                  "change / interval), a later one is a step; a slope is held 1.25 change intervals, at most this "
                  "long")
        .member<&AicParams::reference, &ReferenceModelParams::goal_rate_hold>(),
    ParamRow("active_inference", "max_goal_rate_linear").unit("m/s^2").above(0.0).atMost(kMaxGain)
        .describe("Generalized goal: |mu_d'| of x_dot is clamped to this: a faster set-point change is followed, "
                  "not extrapolated (belief_model robot: also to A_w r, what the wheels can follow)")
        .member<&AicParams::reference, &ReferenceModelParams::max_goal_rate_linear>(),
    ParamRow("active_inference", "max_goal_rate_angular").unit("rad/s^2").above(0.0).atMost(kMaxGain)
        .describe("Generalized goal: |mu_d'| of theta_dot is clamped to this: a faster set-point change (a "
                  "joystick flick) is followed, not extrapolated (belief_model robot: also to 2 A_w r / "
                  "wheel_separation, what the wheels can follow)")
        .member<&AicParams::reference, &ReferenceModelParams::max_goal_rate_angular>(),
    ParamRow("active_inference", "goal_lead").unit("s").atLeast(0.0).atMost(1.0)
        .describe("Generalized goal: the linear goal (x_dot, y_dot) is predicted this far ahead, mu_d + goal_lead "
                  "mu_d'")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::goal_lead>(),
    ParamRow("active_inference", "goal_lead_angular").unit("s").atLeast(0.0).atMost(1.0)
        .describe("Generalized goal: the yaw-rate goal is predicted this far ahead, mu_d + goal_lead_angular mu_d'")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::goal_lead_angular>(),
    ParamRow("active_inference", "reference_time_constant").unit("s").atLeast(0.0).atMost(10.0)
        .describe("Reference model T_r: the beliefs are drawn to the path m' = (goal - m) / T_r delayed by "
                  "reference_delay, f(mu) = mu_r' + (mu_r - mu) / tau; 0 = off (the thesis's f(mu) = (mu_d - mu) / "
                  "tau, eq. 3-7); belief_model robot: no effect (its path is the wheel loop's, wheel_time_constant)")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::time_constant>(),
    ParamRow("active_inference", "goal_response_time_constant").unit("s").atLeast(0.0).atMost(10.0)
        .describe("Unbiased beliefs: the action's goal prior targets the goal's path as the robot follows it, g' = "
                  "(mu_r - g) / T_g; 0 = off (the reference path mu_r itself); no effect with belief_model goal")
        .readBy(beliefModelBit(BeliefModel::kUnbiased)).member<&AicParams::goal_response_time_constant>(),
    ParamRow("active_inference", "max_reference_acceleration_linear").unit("m/s^2").above(0.0).atMost(kMaxGain)
        .describe("Reference model: the path's acceleration along x_dot is clamped to this (what the wheels' "
                  "torque allows)")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::max_acceleration_linear>(),
    ParamRow("active_inference", "max_reference_acceleration_angular").unit("rad/s^2").above(0.0).atMost(kMaxGain)
        .describe("Reference model: the path's acceleration along theta_dot is clamped to this")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::max_acceleration_angular>(),
    ParamRow("active_inference", "max_reference_acceleration_wheel").unit("m/s^2").atLeast(0.0).atMost(kMaxGain)
        .describe("Reference model: each wheel's rim-speed rate along the path, |m'_x -+ m'_theta b_hat / 2|, is "
                  "clamped to this before the body channels' bounds (the wheel loops saturate per wheel: a turn "
                  "started with the forward speed waits for the inner wheel); 0 = none")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::max_acceleration_wheel>(),
    ParamRow("active_inference", "max_reference_deceleration_linear").unit("m/s^2").atLeast(0.0).atMost(kMaxGain)
        .describe("Reference model: a payload's tip-over bound along x_dot: the path's braking, forward or in "
                  "reverse, and its speeding up in reverse (which tips the robot over its front wheels as braking "
                  "forward does) are clamped to this, below the lower of the accelerations at which the robot "
                  "with its payload tips over its front or rear wheels (g d / h, plant_payload; doc/usage.md, "
                  "'Payloads'); 0 = none (the path's other bounds)")
        .member<&AicParams::reference, &ReferenceModelParams::max_deceleration_linear>(),
    ParamRow("active_inference", "reference_delay").unit("s").atLeast(0.0).atMost(kMaxReferenceDelay)
        .describe("Reference model: the latency from command to wheel response that the beliefs expect")
        .readBy(kLinearBeliefModels).member<&AicParams::reference, &ReferenceModelParams::delay>(),
    ParamRow("active_inference", "action_prior_gain").atLeast(0.0).atMost(2.0)
        .describe("Action prior k_ff: a = a_F + k_ff W (m + T_p m'), the reference path's wheel speeds (inverse "
                  "model, eq. 3-3) handed to the MCU's wheel loop, a_F the free-energy action (eq. 3-16); 0 = off "
                  "(the thesis)")
        .readBy(kLinearBeliefModels).member<&AicParams::action_prior, &ActionPriorParams::gain>(),
    ParamRow("active_inference", "action_prior_time_constant").unit("s").atLeast(0.0).atMost(10.0)
        .describe("Action prior: the wheel loop's time constant T_p that the prior inverts (with a reference model)")
        .readBy(kLinearBeliefModels).member<&AicParams::action_prior, &ActionPriorParams::time_constant>(),
    // ---- unbiased beliefs and learning the generative model (not in the thesis; doc/active_inference.md)
    ParamRow("active_inference", "belief_model")
        .describe("State prior of the beliefs: goal (the thesis, f(mu) = (mu_d - mu) / tau, eq. 3-7) or unbiased "
                  "(f = (G a(t - d_r) - mu) / tau, the robot's response to the sent action; the goal drives the "
                  "action) or robot (the identified model of the wheels, their latency and the yaw rate; the "
                  "action descends F through it)")
        .choices({ "goal", "unbiased", "robot" }).accessors(&getBeliefModel, &setBeliefModel),
    // ---- the robot model (belief_model robot; doc/active_inference.md, 'The robot model')
    ParamRow("active_inference", "latency").unit("s").atLeast(0.0).atMost(kMaxReferenceDelay)
        .describe("Robot model: L, /cmd_drive to the wheels' response (identified: plant_identify's command_delay)")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::latency>(),
    ParamRow("active_inference", "wheel_time_constant").unit("s").atLeast(0.0).atMost(1.0)
        .describe("Robot model: T_w, the MCU wheel loop's lag (identified motor keys): to a ramped command with "
                  "wheel_feedforward 0; with the feed-forward, its proportional path's (set-point lag + J_n / K_p)")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::wheel_time_constant>(),
    ParamRow("active_inference", "wheel_acceleration").unit("rad/s^2").above(0.0).atMost(kMaxGain)
        .describe("Robot model: A_w, the largest wheel acceleration the MCU's wheel loop gives (identified motor "
                  "keys)")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::wheel_acceleration>(),
    ParamRow("active_inference", "wheel_feedforward").unit("-").atLeast(0.0).atMost(2.0)
        .describe("Robot model: c, the share of the command stream's rate the MCU's acceleration feed-forward gives "
                  "the wheel (identified motor keys: J_ff / J_n); 0 = none")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::wheel_feedforward>(),
    ParamRow("active_inference", "wheel_feedforward_acceleration").unit("rad/s^2").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: A_ff, the bound of that feed-forward's wheel acceleration, < wheel_acceleration "
                  "(identified motor keys: accel_feedforward_limit / J_n); the lag's bound is the rest")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::wheel_feedforward_acceleration>(),
    ParamRow("active_inference", "yaw_time_constant").unit("s").above(0.0).atMost(10.0)
        .describe("Robot model: T_s, the scrub lag of the body's yaw rate behind the wheels'")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::yaw_time_constant>(),
    ParamRow("active_inference", "encoder_noise").unit("rad/s").above(0.0).atMost(kMaxGain)
        .describe("Robot model: sigma_e, one side's wheel-speed noise (measured on a rest segment); Pi = 1 / "
                  "sigma_e^2")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::encoder_noise>(),
    ParamRow("active_inference", "gyro_noise").unit("rad/s").above(0.0).atMost(kMaxGain)
        .describe("Robot model: sigma_g, the gyro's noise (measured on a rest segment); Pi = 1 / sigma_g^2")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::gyro_noise>(),
    ParamRow("active_inference", "wheel_model_noise").unit("rad/s^1.5").above(0.0).atMost(kMaxGain)
        .describe("Robot model: q_w, the wheel model's error (spectral density on omega'): the prior's precision")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::wheel_model_noise>(),
    ParamRow("active_inference", "shortfall_noise").unit("rad/s^0.5").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: q_d, the drift of each side's actuation shortfall d (its random walk); 0 = d fixed "
                  "at 0")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::shortfall_noise>(),
    ParamRow("active_inference", "turn_shortfall_noise").unit("rad/s^0.5").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: q_e, the drift of each side's turn shortfall e (what the side does not deliver on "
                  "top of d in a turn that loads it against its motion: the scrub load; a random walk while the "
                  "robot turns); 0 = e fixed at 0")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::turn_shortfall_noise>(),
    ParamRow("active_inference", "shortfall_compensation_limit").unit("rad/s").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: e_c, the largest shortfall per side the action makes up by raising the command "
                  "(the error at which the MCU's proportional path saturates, on a wheel loop whose integral path "
                  "takes the rest up: plant_identify.py --bag writes proportional_limit / speed_kp); 0 = no bound")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::shortfall_compensation_limit>(),
    ParamRow("active_inference", "yaw_model_noise").unit("rad/s^1.5").above(0.0).atMost(kMaxGain)
        .describe("Robot model: q_theta, the yaw model's error on theta_dot'")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::yaw_model_noise>(),
    ParamRow("active_inference", "yaw_slip_noise").unit("(rad/s)^-0.5").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: sigma_s, how far the yaw slip ratio s may move with the turn (its variance grows "
                  "by sigma_s^2 |dw| as the goal's yaw rate changes by dw); 0 = s fixed at 0")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::yaw_slip_noise>(),
    ParamRow("active_inference", "gyro_offset_noise").unit("rad/s^0.5").atLeast(0.0).atMost(kMaxGain)
        .describe("Robot model: q_beta, the drift of the gyro's offset beta at rest and in straight driving (a "
                  "random walk; in a turn it changes by a jump only); 0 = beta fixed there")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::gyro_offset_noise>(),
    ParamRow("active_inference", "action_gain").unit("1/s").above(0.0).atMost(kMaxGain)
        .describe("Robot model: k_a, the action's loop gain (the rate of its Gauss-Newton descent of F; k_a >= "
                  "action_rate reaches the minimiser each action step)")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::action_gain>(),
    ParamRow("active_inference", "learn_latency")
        .describe("Robot model: learn L from the wheels' first motion after rest (within 0.5-2 x latency); false = "
                  "L as configured")
        .readBy(kRobotBeliefModel).member<&AicParams::robot, &RobotModelParams::learn_latency>(),
    ParamRow("active_inference", "learn_wheel_separation")
        .describe("If true, the model's wheel separation b_hat descends the free energy of the gyro-encoder "
                  "disagreement (frozen near rest, while the action saturates and while a sensor is isolated); "
                  "false: b_hat fixed")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::enabled>(),
    ParamRow("active_inference", "separation_learning_rate").unit("m^2 s/rad^2").atLeast(0.0).atMost(kMaxGain)
        .describe("Learning rate kappa_b of b_hat: db_hat/dt = -kappa_b dF_b/db_hat")
        .readBy(kLinearBeliefModels).member<&AicParams::separation_learner, &SeparationLearnerParams::rate>(),
    ParamRow("active_inference", "separation_min").unit("m").atLeast(kMinLength).atMost(kMaxLength)
        .describe("Lower bound of the learned wheel separation b_hat (<= separation_max)")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::min>(),
    ParamRow("active_inference", "separation_max").unit("m").atLeast(kMinLength).atMost(kMaxLength)
        .describe("Upper bound of the learned wheel separation b_hat")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::max>(),
    ParamRow("active_inference", "separation_min_yaw_rate").unit("rad/s").atLeast(0.0).atMost(10.0)
        .describe("b_hat is frozen while the gyro's |yaw rate| is below this (near rest); with belief_model robot "
                  "while the believed wheels' |yaw rate| is (rest and straight driving)")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::min_yaw_rate>(),
    ParamRow("active_inference", "separation_max_yaw_acceleration").unit("rad/s^2").above(0.0).atMost(kMaxGain)
        .describe("b_hat is frozen while the gyro's |yaw acceleration| (its generalized order 1) is above this (a "
                  "transient); with belief_model robot also while the believed wheels' yaw acceleration or their "
                  "common acceleration counted as one side's, 2 |x_dot'| / b_hat, is")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::max_yaw_acceleration>(),
    ParamRow("active_inference", "separation_max_rate").unit("1/s").atLeast(0.0).atMost(10.0)
        .describe("b_hat moves by at most this share of itself per second (slower than the fault monitor detects a "
                  "sensor fault, so that learning cannot explain the fault away); 0 = unlimited")
        .member<&AicParams::separation_learner, &SeparationLearnerParams::max_rate>(),
    ParamRow("active_inference", "learn_precision")
        .describe("If true, the order-0 sensory precisions of the gyro and the wheels descend the free energy, "
                  "Pi_j -> 1 / E[eps_j^2] (frozen near rest, while the action saturates and while a sensor is "
                  "isolated); false: Pi_y = 1 / var_y fixed")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::enabled>(),
    ParamRow("active_inference", "precision_learning_rate").unit("1/s").atLeast(0.0).atMost(kMaxGain)
        .describe("Learning rate kappa_pi of the log-precisions: d ln Pi_j/dt = -kappa_pi (Pi_j s_j - 1) / 2")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::rate>(),
    ParamRow("active_inference", "precision_min_factor").above(0.0).atMost(1.0)
        .describe("Lower bound of a learned precision, as a factor of the configured 1 / var_y")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::min_factor>(),
    ParamRow("active_inference", "precision_max_factor").atLeast(1.0).atMost(kMaxGain)
        .describe("Upper bound of a learned precision, as a factor of the configured 1 / var_y")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::max_factor>(),
    ParamRow("active_inference", "precision_time_constant").unit("s").above(0.0).atMost(1000.0)
        .describe("Time constant of the low-pass of the squared prediction errors s_j the precisions learn from")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::time_constant>(),
    ParamRow("active_inference", "precision_min_wheel_speed").unit("rad/s").atLeast(0.0).atMost(100.0)
        .describe("The precisions are frozen while both wheels' |speed| is below this (near rest)")
        .readBy(kLinearBeliefModels).member<&AicParams::precision_learner, &PrecisionLearnerParams::min_wheel_speed>(),
    ParamRow("active_inference", "learn_gyro_bias")
        .describe("If true, the gyro's offset beta_hat is learned while the wheels and their commands stand still "
                  "and subtracted from every gyro sample (frozen while moving and while the gyro is flagged); "
                  "false: none")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::enabled>(),
    ParamRow("active_inference", "gyro_bias_max").unit("rad/s").above(0.0).atMost(1.0)
        .describe("Bound of the learned gyro offset |beta_hat|; a larger |reading| at rest is not learned from "
                  "(the robot is turned by hand, or a fault)")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::max_bias>(),
    ParamRow("active_inference", "gyro_bias_rest_speed").unit("rad/s").above(0.0).atMost(10.0)
        .describe("At rest for the gyro offset: both wheels' and both wheel commands' |speed| below this")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::rest_speed>(),
    ParamRow("active_inference", "gyro_bias_rest_time").unit("s").atLeast(0.0).atMost(10.0)
        .describe("The gyro offset learns from this long after a rest began (the body's yaw settles)")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::rest_time>(),
    ParamRow("active_inference", "gyro_bias_time_constant").unit("s").above(0.0).atMost(1.0e5)
        .describe("Time constant T_beta with which the gyro offset follows a drift once the first rest is averaged")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::time_constant>(),
    ParamRow("active_inference", "gyro_bias_min_rest").unit("s").atLeast(0.0).atMost(600.0)
        .describe("The learned gyro offset is removed from the gyro once this much rest has been learned from (the "
                  "average of a shorter rest is mostly noise); before that, none")
        .member<&AicParams::gyro_bias, &GyroBiasEstimatorParams::min_rest>(),
    ParamRow("active_inference", "tip_guard")
        .describe("If true, the body's pitch is integrated from the gyro's y axis; when it passes tip_guard_pitch "
                  "while the robot brakes (speeds up), the reference path stops braking until the body is level, "
                  "and later paths stay below tip_guard_margin x the deceleration at which the wheels lifted (no "
                  "effect with reference_time_constant 0)")
        .member<&AicParams::tip_guard, &TipGuardParams::enabled>(),
    ParamRow("active_inference", "tip_guard_pitch").unit("rad").above(0.0).atMost(0.5)
        .describe("|pitch| that trips the tip-over guard (a rigid robot on flat ground pitches only when a pair of "
                  "wheels leaves it)")
        .member<&AicParams::tip_guard, &TipGuardParams::trip_pitch>(),
    ParamRow("active_inference", "tip_guard_margin").above(0.0).atMost(1.0)
        .describe("The tip-over guard's learned bound is this factor of the deceleration (acceleration) at which "
                  "the wheels lifted")
        .member<&AicParams::tip_guard, &TipGuardParams::margin>(),
    ParamRow("active_inference", "tip_guard_min_acceleration").unit("m/s^2").above(0.0).atMost(100.0)
        .describe("Floor of the tip-over guard's learned deceleration and acceleration bounds")
        .member<&AicParams::tip_guard, &TipGuardParams::min_acceleration>(),
    ParamRow("active_inference", "tip_guard_turnover_pitch").unit("rad").above(0.0).atMost(1.5)
        .describe("|pitch| past which the body has turned over and the tip-over guard stops the wheels (zero "
                  "command until the pitch is below it again and, after the IMU's z specific force read the body "
                  "on its back, it is upright within this angle); > tip_guard_pitch. 0.4: past the tipping point "
                  "of any robot that braking at the wheels' 4.2 m/s^2 can tip")
        .member<&AicParams::tip_guard, &TipGuardParams::turnover_pitch>(),
    // ---- robot (Clearpath Jackal; doc/jackal.md)
    ParamRow("robot", "wheel_radius").unit("m").atLeast(kMinLength).atMost(kMaxLength)
        .describe("Wheel radius r (thesis eq. 3-1 to 3-4)")
        .member<&AicParams::wheel_radius>(),
    ParamRow("robot", "slip_factor").atLeast(kMinSlipFactor).atMost(kMaxSlipFactor)
        .describe("Slip factor alpha of the extended differential drive (thesis eq. 3-1 to 3-4)")
        .member<&AicParams::slip_factor>(),
    ParamRow("robot", "wheel_separation").unit("m").atLeast(kMinLength).atMost(kMaxLength)
        .describe("Virtual wheel separation b_hat (identified; the track is 0.376 m; thesis eq. 3-1 to 3-4)")
        .member<&AicParams::wheel_separation>(),
    ParamRow("robot", "max_wheel_speed").unit("rad/s").above(0.0).atMost(kMaxWheelSpeedLimit)
        .describe("Wheel commands are clamped to +-this (2.0 m/s / 0.098 m ~ 20.4 rad/s)")
        .member<&AicParams::max_wheel_speed>(),
  };
  // clang-format on
}

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
  const bool order_ok = embedding_order >= 1 && embedding_order <= base::kMaxEmbeddingOrder;
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

ParamRow::ParamRow(const char* group, const char* key)
{
  spec_.key = key;
  spec_.type = ParamType::kDouble;  // until member(), node() or accessors()
  spec_.scope = ParamScope::kController;
  spec_.group = group;
  spec_.min = kNone;
  spec_.min_exclusive = false;
  spec_.max = kNone;
  spec_.unit = "-";
  spec_.description = nullptr;
  spec_.live = true;
  spec_.level = 0;
  spec_.required = false;
  spec_.channels = 0;
  spec_.reconfigure_slots = 0;
  spec_.get_aic = nullptr;
  spec_.set_aic = nullptr;
  spec_.get_node = nullptr;
  spec_.set_node = nullptr;
}

ParamRow& ParamRow::unit(const char* unit)
{
  spec_.unit = unit;
  return *this;
}

ParamRow& ParamRow::describe(const char* description)
{
  spec_.description = description;
  return *this;
}

ParamRow& ParamRow::atLeast(double min)
{
  spec_.min = min;
  spec_.min_exclusive = false;
  return *this;
}

ParamRow& ParamRow::above(double min)
{
  spec_.min = min;
  spec_.min_exclusive = true;
  return *this;
}

ParamRow& ParamRow::atMost(double max)
{
  spec_.max = max;
  return *this;
}

ParamRow& ParamRow::nodeMax(double max)
{
  spec_.node_max = max;
  return *this;
}

ParamRow& ParamRow::notLive()
{
  spec_.live = false;
  return *this;
}

ParamRow& ParamRow::level(int bits)
{
  spec_.level = bits;
  return *this;
}

ParamRow& ParamRow::required()
{
  spec_.required = true;
  return *this;
}

ParamRow& ParamRow::perOrder(int channels, int slots)
{
  spec_.channels = channels;
  spec_.reconfigure_slots = slots;
  return *this;
}

ParamRow& ParamRow::choices(std::vector<std::string> names)
{
  spec_.choices = std::move(names);
  return *this;
}

ParamRow& ParamRow::readBy(BeliefModelSet models)
{
  spec_.models = models;
  return *this;
}

std::string beliefModelsText(BeliefModelSet models)
{
  std::vector<std::string> names;
  for (const BeliefModel m : { BeliefModel::kGoal, BeliefModel::kUnbiased, BeliefModel::kRobot })
  {
    if ((models & beliefModelBit(m)) != 0u)
    {
      names.push_back(toString(m));
    }
  }
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    out += (i == 0 ? "" : (i + 1 == names.size() ? " and " : ", ")) + names[i];
  }
  return out;
}

ParamRow& ParamRow::accessors(ParamValue (*get)(const AicParams&), bool (*set)(AicParams&, const ParamValue&))
{
  spec_.type = ParamType::kString;
  spec_.scope = ParamScope::kController;
  spec_.get_aic = get;
  spec_.set_aic = set;
  return *this;
}

ParamRow& ParamRow::accessors(ParamValue (*get)(const NodeParams&), bool (*set)(NodeParams&, const ParamValue&))
{
  spec_.type = ParamType::kString;
  spec_.scope = ParamScope::kNode;
  spec_.get_node = get;
  spec_.set_node = set;
  return *this;
}

ParamRow::operator ParamSpec() const
{
  const std::string key = spec_.key;
  const bool accessed = spec_.scope == ParamScope::kController ? spec_.get_aic != nullptr && spec_.set_aic != nullptr :
                                                                 spec_.get_node != nullptr && spec_.set_node != nullptr;
  if (!accessed)
  {
    throw std::logic_error("schema row " + key + ": no member (member<...>(), node<...>() or accessors())");
  }
  if (spec_.description == nullptr)
  {
    throw std::logic_error("schema row " + key + ": no description (describe())");
  }
  ParamSpec row = spec_;
  if (row.numeric())
  {
    if (std::isnan(row.min))
    {
      throw std::logic_error("schema row " + key + ": a number without a lower bound (atLeast() or above())");
    }
    if (std::isnan(row.max))
    {
      row.max = kInf;
    }
  }
  else
  {
    row.min = kNone;
    row.max = kNone;
  }
  return row;
}

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

}  // namespace params
}  // namespace jackal_aic
