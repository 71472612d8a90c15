/**
 * \file params.cpp
 * \brief AicParams validation and precisions (thesis tables C-1 and 5-8; doc/active_inference.md,
 *        'Prediction errors and free energy' and 'Parameter sets of the thesis').
 */
#include "jackal_aic/params/aic_params.hpp"

#include "jackal_aic/params/param_spec.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace params
{
bool integratorFromString(const std::string& name, Integrator* out)
{
  if (out == nullptr)
  {
    return false;
  }
  if (name == "euler")
  {
    *out = Integrator::kEuler;
    return true;
  }
  if (name == "exact")
  {
    *out = Integrator::kExact;
    return true;
  }
  return false;
}

std::string toString(Integrator integrator)
{
  switch (integrator)
  {
    case Integrator::kEuler:
      return "euler";
    case Integrator::kExact:
      return "exact";
  }
  return "unknown";
}

bool beliefModelFromString(const std::string& name, BeliefModel* out)
{
  if (out == nullptr)
  {
    return false;
  }
  if (name == "goal")
  {
    *out = BeliefModel::kGoal;
    return true;
  }
  if (name == "unbiased")
  {
    *out = BeliefModel::kUnbiased;
    return true;
  }
  if (name == "robot")
  {
    *out = BeliefModel::kRobot;
    return true;
  }
  return false;
}

std::string toString(BeliefModel model)
{
  switch (model)
  {
    case BeliefModel::kGoal:
      return "goal";
    case BeliefModel::kUnbiased:
      return "unbiased";
    case BeliefModel::kRobot:
      return "robot";
  }
  return "unknown";
}

AicParams recommendedAicParams()
{
  AicParams p;  // rates 1000 / 50 Hz, robot geometry, runaway_limit: as table 5-8
  p.integrator = Integrator::kExact;
  p.tau = 0.01232;
  p.k_mu = 0.008264;
  p.k_a = 3.193;
  p.embedding_order = 2;
  p.var_mu = { 0.5, 0.6667, 1.333 };
  p.var_y = { 2.0, 61.83, 1.0e5 };
  p.anti_windup.max_action_lead = 1.606;
  p.anti_windup.max_action_lead_turn = 0.0;
  p.action_release_time = 0.5;
  p.reference.generalized_goal = true;
  p.reference.goal_rate_hold = 0.15;
  p.reference.max_goal_rate_linear = 4.0;
  p.reference.max_goal_rate_angular = 8.0;
  p.reference.goal_lead = 0.08095;
  p.reference.goal_lead_angular = 0.125;
  p.reference.time_constant = 0.005;
  p.reference.max_acceleration_linear = 3.689;
  p.reference.max_acceleration_angular = 10.95;
  p.reference.max_acceleration_wheel = 4.5;
  p.reference.delay = 0.085;
  p.action_prior.gain = 0.9715;
  p.action_prior.time_constant = 0.00834;
  p.separation_learner.enabled = true;  // b_hat learned from the gyro-encoder disagreement
  p.gyro_bias.enabled = true;           // the gyro's offset learned at standstill
  p.tip_guard.enabled = true;           // braking eased when the body pitches over its wheels
  return p;
}

std::string AicParams::summary() const
{
  std::ostringstream out;
  out << "belief " << belief_rate << " Hz, action " << action_rate << " Hz, belief model " << toString(belief_model)
      << ", ";
  if (belief_model == BeliefModel::kRobot)
  {
    out << "latency " << robot.latency << " s (" << (robot.learn_latency ? "learned" : "fixed") << "), action_gain "
        << robot.action_gain << " 1/s, b_hat_0 " << wheel_separation << " m";
    return out.str();
  }
  out << "tau " << tau << " s, k_mu " << k_mu << ", k_a " << k_a << ", p " << embedding_order << ", integrator "
      << toString(integrator);
  return out.str();
}

std::vector<ParamViolation> AicParams::validate() const
{
  // The ranges are the controller's rows (include/jackal_aic/params/param_spec.hpp); the cross rules are here.
  std::vector<ParamViolation> v = checkParamRanges(*this);
  if (std::isfinite(belief_rate) && std::isfinite(action_rate) && belief_rate > 0.0 && action_rate > 0.0 &&
      belief_rate < action_rate)
  {
    v.push_back(
        { "belief_rate", formatParamValue(belief_rate), ">= action_rate (" + formatParamValue(action_rate) + ")" });
  }
  const double a_ff = robot.wheel_feedforward_acceleration;
  if (std::isfinite(a_ff) && std::isfinite(robot.wheel_acceleration) && a_ff >= robot.wheel_acceleration)
  {
    v.push_back({ "wheel_feedforward_acceleration", formatParamValue(a_ff),
                  "< wheel_acceleration (" + formatParamValue(robot.wheel_acceleration) + ")" });
  }
  if (std::isfinite(tip_guard.turnover_pitch) && std::isfinite(tip_guard.trip_pitch) &&
      tip_guard.turnover_pitch <= tip_guard.trip_pitch)
  {
    v.push_back({ "tip_guard_turnover_pitch", formatParamValue(tip_guard.turnover_pitch),
                  "> tip_guard_pitch (" + formatParamValue(tip_guard.trip_pitch) + ")" });
  }
  const SeparationLearnerParams& learner = separation_learner;
  if (std::isfinite(learner.min) && std::isfinite(learner.max) && learner.min > learner.max)
  {
    v.push_back({ "separation_min", formatParamValue(learner.min),
                  "<= separation_max (" + formatParamValue(learner.max) + ")" });
  }
  return v;
}

namespace
{
template <int Rows>
Eigen::Matrix<double, Rows, Eigen::Dynamic, Eigen::ColMajor, Rows, base::kMaxOrders>
precisionFrom(const std::vector<double>& var, int orders)
{
  if (orders < 1 || orders > base::kMaxOrders ||
      (var.size() != static_cast<std::size_t>(orders) && var.size() != static_cast<std::size_t>(Rows * orders)))
  {
    throw std::invalid_argument("AicParams: variances of size " + std::to_string(var.size()) +
                                " do not fit embedding_order " + std::to_string(orders - 1) +
                                " (call validate() first)");
  }
  Eigen::Matrix<double, Rows, Eigen::Dynamic, Eigen::ColMajor, Rows, base::kMaxOrders> pi(Rows, orders);
  const bool per_channel = var.size() == static_cast<std::size_t>(Rows * orders);
  for (int i = 0; i < orders; ++i)
  {
    for (int c = 0; c < Rows; ++c)
    {
      const double s2 = per_channel ? var[static_cast<std::size_t>(i * Rows + c)] : var[static_cast<std::size_t>(i)];
      pi(c, i) = 1.0 / s2;
    }
  }
  return pi;
}
}  // namespace

base::MuTilde AicParams::precisionMu() const
{
  return precisionFrom<base::kMuDim>(var_mu, numOrders());
}

base::YTilde AicParams::precisionY() const
{
  return precisionFrom<base::kYDim>(var_y, numOrders());
}

base::YTilde AicParams::modelPrecisionY() const
{
  if (belief_model != BeliefModel::kRobot)
  {
    return precisionY();
  }
  base::YTilde pi = base::YTilde::Zero(base::kYDim, numOrders());
  pi(base::kGyroZ, 0) = 1.0 / (robot.gyro_noise * robot.gyro_noise);
  pi(base::kOmegaLeft, 0) = 1.0 / (robot.encoder_noise * robot.encoder_noise);
  pi(base::kOmegaRight, 0) = pi(base::kOmegaLeft, 0);
  return pi;
}

bool learnsLatency(const AicParams& params)
{
  return params.belief_model == BeliefModel::kRobot && params.robot.learn_latency;
}

bool learnsPrecision(const AicParams& params)
{
  return params.belief_model != BeliefModel::kRobot && params.precision_learner.enabled;
}

double robotWheelAcceleration(const AicParams& params)
{
  return params.robot.wheel_acceleration * params.wheel_radius * params.slip_factor;
}

ReferenceModelParams goalRateParams(const AicParams& params)
{
  ReferenceModelParams rp = params.reference;
  if (params.belief_model == BeliefModel::kRobot)
  {
    // The configured bound (the set-point stream's), within what the wheels can follow.
    const double wheel = robotWheelAcceleration(params);
    rp.max_goal_rate_linear = std::min(params.reference.max_goal_rate_linear, wheel);
    rp.max_goal_rate_angular = std::min(params.reference.max_goal_rate_angular, 2.0 * wheel / params.wheel_separation);
  }
  return rp;
}

}  // namespace params
}  // namespace jackal_aic
