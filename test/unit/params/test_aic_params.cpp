/// Tests of AicParams::validate() (one test per rule), precisions and integrator names.
#include <gtest/gtest.h>

#include <vector>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "jackal_aic/params/aic_params.hpp"

using jackal_aic::params::AicParams;
using jackal_aic::params::Integrator;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPrecisionTol = 1e-12;  // 1/variance units

bool hasViolation(const AicParams& p, const std::string& name)
{
  const auto v = p.validate();
  return std::any_of(v.begin(), v.end(), [&](const jackal_aic::params::ParamViolation& x) { return x.name == name; });
}

/// Every bounded scalar rule, checked for 0, negative, NaN, Inf and just above its upper bound.
void expectPositiveRule(double AicParams::*member, const std::string& name, double upper)
{
  for (double bad : { 0.0, -1.0, kNaN, kInf, upper * 1.01 })
  {
    AicParams p;
    p.*member = bad;
    EXPECT_TRUE(hasViolation(p, name)) << name << " = " << bad;
  }
  AicParams ok;
  EXPECT_FALSE(hasViolation(ok, name));
  ok.*member = upper;
  EXPECT_FALSE(hasViolation(ok, name)) << name << " = " << upper << " must be allowed";
}
}  // namespace

TEST(Params, DefaultsAreValid)
{
  EXPECT_TRUE(AicParams().validate().empty());
}

TEST(Params, SummaryNamesTheBeliefModelAndTheKeysThatShapeItsCommand)
{
  AicParams p = jackal_aic::params::recommendedAicParams();
  p.belief_model = jackal_aic::params::BeliefModel::kGoal;
  EXPECT_NE(p.summary().find("belief model goal, tau "), std::string::npos) << p.summary();
  p.belief_model = jackal_aic::params::BeliefModel::kRobot;
  p.robot.learn_latency = true;
  const std::string robot = p.summary();
  EXPECT_NE(robot.find("belief model robot, latency 0.1187 s (learned), action_gain 50 1/s, b_hat_0 0.5621 m"),
            std::string::npos)
      << robot;
  EXPECT_EQ(robot.find("tau"), std::string::npos) << "a key without effect in the robot model: " << robot;
}

namespace
{
/// A loop rate: positive, at most kMaxRate, and at least kMinRate, so that no period is longer
/// than the longest step the controller takes (kMaxStep).
void expectRateRule(double AicParams::*member, const std::string& name)
{
  expectPositiveRule(member, name, jackal_aic::params::kMaxRate);
  AicParams p;
  p.belief_rate = p.action_rate = jackal_aic::params::kMinRate;
  EXPECT_FALSE(hasViolation(p, name)) << name << " = kMinRate must be allowed";
  // Both below, equal: belief_rate >= action_rate holds, so only the range rule can name the key.
  p.belief_rate = p.action_rate = 0.5 * jackal_aic::params::kMinRate;
  EXPECT_TRUE(hasViolation(p, name)) << name << " = " << p.*member;
  EXPECT_LE(1.0 / jackal_aic::params::kMinRate, jackal_aic::params::kMaxStep);
}
}  // namespace

TEST(Params, BeliefRate)
{
  expectRateRule(&AicParams::belief_rate, "belief_rate");
}
TEST(Params, ActionRate)
{
  expectRateRule(&AicParams::action_rate, "action_rate");
}
TEST(Params, Tau)
{
  expectPositiveRule(&AicParams::tau, "tau", jackal_aic::params::kMaxTau);
}
TEST(Params, KMu)
{
  expectPositiveRule(&AicParams::k_mu, "k_mu", jackal_aic::params::kMaxGain);
}
TEST(Params, KA)
{
  expectPositiveRule(&AicParams::k_a, "k_a", jackal_aic::params::kMaxGain);
}
TEST(Params, WheelRadius)
{
  expectPositiveRule(&AicParams::wheel_radius, "wheel_radius", jackal_aic::params::kMaxLength);
}
TEST(Params, SlipFactor)
{
  expectPositiveRule(&AicParams::slip_factor, "slip_factor", jackal_aic::params::kMaxSlipFactor);
}
TEST(Params, WheelSeparation)
{
  expectPositiveRule(&AicParams::wheel_separation, "wheel_separation", jackal_aic::params::kMaxLength);
}
TEST(Params, MaxWheelSpeed)
{
  expectPositiveRule(&AicParams::max_wheel_speed, "max_wheel_speed", jackal_aic::params::kMaxWheelSpeedLimit);
}
TEST(Params, RunawayLimit)
{
  expectPositiveRule(&AicParams::runaway_limit, "runaway_limit", jackal_aic::params::kMaxRunawayLimit);
}

TEST(Params, MaxActionLead)
{
  for (double bad : { -1.0, kNaN, kInf, jackal_aic::params::kMaxWheelSpeedLimit * 1.01 })
  {
    AicParams p;
    p.anti_windup.max_action_lead = bad;
    EXPECT_TRUE(hasViolation(p, "max_action_lead")) << bad;
  }
  AicParams p;
  EXPECT_FALSE(hasViolation(p, "max_action_lead"));  // 0 = off
  p.anti_windup.max_action_lead = 3.0;
  EXPECT_FALSE(hasViolation(p, "max_action_lead"));
}

TEST(Params, MaxActionLeadTurn)
{
  for (double bad : { -1.0, kNaN, kInf, jackal_aic::params::kMaxWheelSpeedLimit * 1.01 })
  {
    AicParams p;
    p.anti_windup.max_action_lead_turn = bad;
    EXPECT_TRUE(hasViolation(p, "max_action_lead_turn")) << bad;
  }
  AicParams p;
  EXPECT_FALSE(hasViolation(p, "max_action_lead_turn"));  // 0 = off
  p.anti_windup.max_action_lead_turn = 1.0;
  EXPECT_FALSE(hasViolation(p, "max_action_lead_turn"));
}

// The member of AicParams at `path` (e.g. reference.delay), as a function for a table of cases.
#define JACKAL_AIC_MEMBER(path) [](AicParams& p) -> double& { return p.path; }

TEST(Params, SetPointDynamicsAndActionPrior)
{
  struct Case
  {
    const char* key;
    double& (*member)(AicParams& p);
    std::vector<double> bad;
    double good;
  };
  const std::vector<Case> cases = {
    { "goal_rate_hold", JACKAL_AIC_MEMBER(reference.goal_rate_hold), { 0.0, -0.1, 10.5, kNaN, kInf }, 0.15 },
    { "max_goal_rate_linear", JACKAL_AIC_MEMBER(reference.max_goal_rate_linear), { 0.0, -1.0, kNaN, kInf }, 4.0 },
    { "max_goal_rate_angular", JACKAL_AIC_MEMBER(reference.max_goal_rate_angular), { 0.0, -1.0, kNaN, kInf }, 8.0 },
    { "goal_lead", JACKAL_AIC_MEMBER(reference.goal_lead), { -0.01, 1.5, kNaN, kInf }, 0.0 },
    { "goal_lead_angular", JACKAL_AIC_MEMBER(reference.goal_lead_angular), { -0.01, 1.5, kNaN, kInf }, 0.0 },
    { "reference_time_constant", JACKAL_AIC_MEMBER(reference.time_constant), { -0.01, 11.0, kNaN, kInf }, 0.0 },
    { "max_reference_acceleration_wheel",
      JACKAL_AIC_MEMBER(reference.max_acceleration_wheel),
      { -0.1, 2.0e6, kNaN, kInf },
      0.0 },
    { "reference_delay",
      JACKAL_AIC_MEMBER(reference.delay),
      { -0.01, jackal_aic::params::kMaxReferenceDelay * 1.01, kNaN },
      0.1 },
    { "action_prior_gain", JACKAL_AIC_MEMBER(action_prior.gain), { -0.1, 2.5, kNaN, kInf }, 1.0 },
    { "action_prior_time_constant", JACKAL_AIC_MEMBER(action_prior.time_constant), { -0.1, 11.0, kNaN }, 0.2 },
    { "action_release_time", JACKAL_AIC_MEMBER(action_release_time), { -0.1, 10.5, kNaN, kInf }, 0.5 },
    { "action_slew_limit", JACKAL_AIC_MEMBER(action_slew.max_rate), { -0.1, 2.0e6, kNaN, kInf }, 20.0 },
    { "gyro_bias_max", JACKAL_AIC_MEMBER(gyro_bias.max_bias), { 0.0, -0.1, 1.5, kNaN, kInf }, 0.05 },
    { "gyro_bias_rest_speed", JACKAL_AIC_MEMBER(gyro_bias.rest_speed), { 0.0, -0.1, 10.5, kNaN, kInf }, 0.1 },
    { "gyro_bias_rest_time", JACKAL_AIC_MEMBER(gyro_bias.rest_time), { -0.1, 10.5, kNaN, kInf }, 0.0 },
    { "gyro_bias_time_constant", JACKAL_AIC_MEMBER(gyro_bias.time_constant), { 0.0, -1.0, 2.0e5, kNaN, kInf }, 5.0 },
    { "gyro_bias_min_rest", JACKAL_AIC_MEMBER(gyro_bias.min_rest), { -0.1, 601.0, kNaN, kInf }, 0.0 },
    { "tip_guard_pitch", JACKAL_AIC_MEMBER(tip_guard.trip_pitch), { 0.0, -0.01, 0.51, kNaN, kInf }, 0.05 },
    { "tip_guard_margin", JACKAL_AIC_MEMBER(tip_guard.margin), { 0.0, -0.1, 1.01, kNaN, kInf }, 1.0 },
    { "tip_guard_min_acceleration",
      JACKAL_AIC_MEMBER(tip_guard.min_acceleration),
      { 0.0, -1.0, 101.0, kNaN, kInf },
      0.5 },
    // 0.02: not above tip_guard_pitch's 0.02 (the cross rule).
    { "tip_guard_turnover_pitch",
      JACKAL_AIC_MEMBER(tip_guard.turnover_pitch),
      { 0.0, -0.1, 0.02, 1.51, kNaN, kInf },
      1.0 },
  };
  for (const Case& c : cases)
  {
    for (double bad : c.bad)
    {
      AicParams p;
      c.member(p) = bad;
      EXPECT_TRUE(hasViolation(p, c.key)) << c.key << " = " << bad;
    }
    AicParams p;
    c.member(p) = c.good;
    EXPECT_FALSE(hasViolation(p, c.key)) << c.key;
  }
}

TEST(Params, LowerSanityBounds)
{
  AicParams p;
  p.tau = jackal_aic::params::kMinTau * 0.99;
  p.wheel_radius = jackal_aic::params::kMinLength * 0.99;
  p.wheel_separation = jackal_aic::params::kMinLength * 0.99;
  p.slip_factor = jackal_aic::params::kMinSlipFactor * 0.99;
  EXPECT_TRUE(hasViolation(p, "tau"));
  EXPECT_TRUE(hasViolation(p, "wheel_radius"));
  EXPECT_TRUE(hasViolation(p, "wheel_separation"));
  EXPECT_TRUE(hasViolation(p, "slip_factor"));
  p.tau = jackal_aic::params::kMinTau;
  p.wheel_radius = jackal_aic::params::kMinLength;
  p.wheel_separation = jackal_aic::params::kMinLength;
  p.slip_factor = jackal_aic::params::kMinSlipFactor;
  p.belief_rate = 1000.0;  // belief_rate >= action_rate still holds
  EXPECT_TRUE(p.validate().empty());
}

TEST(Params, BeliefRateNotBelowActionRate)
{
  AicParams p;
  p.belief_rate = 20.0;
  p.action_rate = 50.0;
  EXPECT_TRUE(hasViolation(p, "belief_rate"));
  p.belief_rate = 50.0;
  EXPECT_TRUE(p.validate().empty());
}

TEST(Params, TheWheelFeedForwardsBoundIsWithinTheWheelLoops)
{
  // A_ff is part of A_w and the lag's bound is the rest: all of it would leave the lag no bound to
  // move the wheel by, so A_ff must be below A_w.
  AicParams p;
  p.robot.wheel_feedforward = 0.787;
  p.robot.wheel_feedforward_acceleration = p.robot.wheel_acceleration;
  EXPECT_TRUE(hasViolation(p, "wheel_feedforward_acceleration"));
  p.robot.wheel_feedforward_acceleration = 34.76;
  EXPECT_TRUE(p.validate().empty());
  p.robot.wheel_feedforward = 2.5;
  EXPECT_TRUE(hasViolation(p, "wheel_feedforward"));
}

TEST(Params, EmbeddingOrderRange)
{
  for (int bad : { 0, -1, 6, 100 })
  {
    AicParams p;
    p.embedding_order = bad;
    EXPECT_TRUE(hasViolation(p, "embedding_order")) << bad;
  }
  for (int ok = 1; ok <= jackal_aic::base::kMaxEmbeddingOrder; ++ok)
  {
    AicParams p;
    p.embedding_order = ok;
    p.var_mu.assign(ok + 1, 1.0);
    p.var_y.assign(ok + 1, 1.0);
    EXPECT_TRUE(p.validate().empty()) << ok;
  }
}

TEST(Params, VarianceSizes)
{
  AicParams p;  // p = 3
  p.var_mu = { 1.0, 1.0 };
  EXPECT_TRUE(hasViolation(p, "var_mu.size()"));
  p.var_mu.assign(12, 1.0);  // 3 channels x 4 orders
  EXPECT_FALSE(hasViolation(p, "var_mu.size()"));
  p.var_y.assign(12, 1.0);  // wrong: per channel needs 20
  EXPECT_TRUE(hasViolation(p, "var_y.size()"));
  p.var_y.assign(20, 1.0);
  EXPECT_TRUE(p.validate().empty());
  p.var_y.clear();
  EXPECT_TRUE(hasViolation(p, "var_y.size()"));
}

TEST(Params, VarianceValues)
{
  for (double bad :
       { 0.0, -2.0, kNaN, kInf, jackal_aic::params::kMinVariance * 0.99, jackal_aic::params::kMaxVariance * 1.01 })
  {
    AicParams p;
    p.var_mu[2] = bad;
    p.var_y[0] = bad;
    EXPECT_TRUE(hasViolation(p, "var_mu[2]")) << bad;
    EXPECT_TRUE(hasViolation(p, "var_y[0]")) << bad;
  }
}

TEST(Params, IntegratorValue)
{
  AicParams p;
  p.integrator = static_cast<Integrator>(7);
  EXPECT_TRUE(hasViolation(p, "integrator"));
}

TEST(Params, ReportsEveryViolation)
{
  AicParams p;
  p.tau = -1.0;
  p.k_mu = kNaN;
  p.wheel_radius = 0.0;
  const auto v = p.validate();
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].toString(), "tau = -1 (allowed: >= 1e-06 and <= 1000, finite)");
  EXPECT_EQ(v[1].name, "k_mu");
  EXPECT_EQ(v[2].name, "wheel_radius");
}

TEST(Params, Precisions)
{
  AicParams p;
  const auto pi_mu = p.precisionMu();
  ASSERT_EQ(pi_mu.cols(), 4);
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(pi_mu(c, 0), 1.0 / 1.5, kPrecisionTol);
    EXPECT_NEAR(pi_mu(c, 3), 1.0 / 8.0, kPrecisionTol);
  }
  p.var_y.assign(20, 1.0);
  p.var_y[2 * 5 + 4] = 4.0;  // order 2, channel 4
  const auto pi_y = p.precisionY();
  EXPECT_NEAR(pi_y(4, 2), 0.25, kPrecisionTol);
  EXPECT_NEAR(pi_y(3, 2), 1.0, kPrecisionTol);
}

TEST(Params, PrecisionsRejectMismatch)
{
  AicParams p;
  p.var_mu = { 1.0 };
  EXPECT_THROW(p.precisionMu(), std::invalid_argument);
}

TEST(Params, IntegratorNames)
{
  Integrator i = Integrator::kEuler;
  EXPECT_TRUE(jackal_aic::params::integratorFromString("exact", &i));
  EXPECT_EQ(i, Integrator::kExact);
  EXPECT_FALSE(jackal_aic::params::integratorFromString("Euler", &i));
  EXPECT_EQ(i, Integrator::kExact);
  EXPECT_TRUE(jackal_aic::params::integratorFromString("euler", &i));
  EXPECT_EQ(jackal_aic::params::toString(i), "euler");
  EXPECT_FALSE(jackal_aic::params::integratorFromString("euler", nullptr));
}

TEST(Params, OnlyTheRobotModelLearnsTheLatencyAndOnlyTheOthersThePrecisions)
{
  AicParams p = jackal_aic::params::recommendedAicParams();
  using jackal_aic::params::BeliefModel;
  for (const auto model : { BeliefModel::kGoal, BeliefModel::kUnbiased, BeliefModel::kRobot })
  {
    for (const bool learn : { true, false })
    {
      p.belief_model = model;
      p.robot.learn_latency = learn;
      p.precision_learner.enabled = learn;
      EXPECT_EQ(jackal_aic::params::learnsLatency(p), learn && model == BeliefModel::kRobot);
      EXPECT_EQ(jackal_aic::params::learnsPrecision(p), learn && model != BeliefModel::kRobot);
    }
  }
}

TEST(Params, TheRobotModelWeighsItsSensorsByTheirMeasuredNoises)
{
  AicParams p = jackal_aic::params::recommendedAicParams();
  p.belief_model = jackal_aic::params::BeliefModel::kGoal;
  EXPECT_EQ(p.modelPrecisionY(), p.precisionY());
  p.belief_model = jackal_aic::params::BeliefModel::kRobot;
  p.robot.gyro_noise = 0.005;
  p.robot.encoder_noise = 0.01;
  const jackal_aic::base::YTilde pi = p.modelPrecisionY();
  ASSERT_EQ(pi.cols(), p.numOrders());
  EXPECT_DOUBLE_EQ(pi(jackal_aic::base::kGyroZ, 0), 40000.0);
  EXPECT_DOUBLE_EQ(pi(jackal_aic::base::kOmegaLeft, 0), 10000.0);
  EXPECT_DOUBLE_EQ(pi(jackal_aic::base::kOmegaRight, 0), 10000.0);
  // The accelerometers and the higher orders: not read by the robot model.
  EXPECT_DOUBLE_EQ(pi.bottomRows(2).cwiseAbs().sum() + pi.rightCols(pi.cols() - 1).cwiseAbs().sum(), 0.0);
}

TEST(Params, TheRobotModelsGoalRateBoundsAreTheConfiguredOnesWithinItsWheelLoops)
{
  AicParams p = jackal_aic::params::recommendedAicParams();
  p.reference.max_goal_rate_linear = 1.0;
  p.reference.max_goal_rate_angular = 2.0;
  const jackal_aic::params::ReferenceModelParams goal = jackal_aic::params::goalRateParams(p);
  EXPECT_EQ(goal.max_goal_rate_linear, 1.0);
  EXPECT_EQ(goal.max_goal_rate_angular, 2.0);
  EXPECT_EQ(goal.goal_rate_hold, p.reference.goal_rate_hold);
  p.belief_model = jackal_aic::params::BeliefModel::kRobot;
  p.robot.wheel_acceleration = 40.0;
  p.wheel_radius = 0.1;
  p.slip_factor = 1.0;
  p.wheel_separation = 0.5;
  const jackal_aic::params::ReferenceModelParams robot = jackal_aic::params::goalRateParams(p);
  EXPECT_DOUBLE_EQ(robot.max_goal_rate_linear, 1.0);  // the configured bounds, below the wheels'
  EXPECT_DOUBLE_EQ(robot.max_goal_rate_angular, 2.0);
  EXPECT_EQ(robot.goal_rate_hold, p.reference.goal_rate_hold);
  p.reference.max_goal_rate_linear = 10.0;
  p.reference.max_goal_rate_angular = 30.0;
  const jackal_aic::params::ReferenceModelParams wheels = jackal_aic::params::goalRateParams(p);
  EXPECT_DOUBLE_EQ(wheels.max_goal_rate_linear, 4.0);    // A_w r alpha
  EXPECT_DOUBLE_EQ(wheels.max_goal_rate_angular, 16.0);  // 2 A_w r alpha / b_0
}
