/// Tests of ActiveInferenceController (thesis eq. 3-6 ... 3-16; doc/active_inference.md).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "jackal_aic/aic/controller.hpp"

using namespace jackal_aic;
using Status = aic::ActiveInferenceController::Status;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

params::AicParams thesisStandard()
{
  params::AicParams p;
  p.belief_rate = 50.0;
  p.action_rate = 50.0;
  p.tau = 0.03;
  p.k_mu = 0.01;
  p.k_a = 8.0;
  return p;
}

/// Generalized measurement of a plant that follows the action exactly: wheel speeds = a,
/// gyro = r alpha / b (a_R - a_L), higher orders zero (a is piecewise constant).
base::YTilde perfectMeasurement(const aic::ActiveInferenceController& c)
{
  base::YTilde y = base::YTilde::Zero(base::kYDim, c.params().numOrders());
  const base::Vector2 a = c.action();
  const base::Vector3 twist = c.model().twistFromWheels(a);
  y(base::kGyroZ, 0) = twist(2);
  y(base::kOmegaLeft, 0) = a(0);
  y(base::kOmegaRight, 0) = a(1);
  return y;
}
}  // namespace

TEST(Controller, RejectsInvalidParams)
{
  params::AicParams p;
  p.tau = -1.0;
  EXPECT_THROW(aic::ActiveInferenceController c(p), std::invalid_argument);
  aic::ActiveInferenceController c{ params::AicParams() };
  EXPECT_THROW(c.setParams(p), std::invalid_argument);
  EXPECT_EQ(c.params().tau, params::AicParams().tau);
}

TEST(Controller, DoesNotMoveBeforeFirstMeasurement)
{
  aic::ActiveInferenceController c{ thesisStandard() };
  c.setGoal(base::Vector3(0.5, 0.0, 0.0));
  EXPECT_EQ(c.updateBeliefs(0.02), Status::kNoMeasurement);
  EXPECT_EQ(c.updateAction(0.02), Status::kNoMeasurement);
  EXPECT_TRUE(c.mu().isZero());
  EXPECT_TRUE(c.action().isZero());
}

TEST(Controller, BadIntervalKeepsState)
{
  aic::ActiveInferenceController c{ thesisStandard() };
  c.setGoal(base::Vector3(0.5, 0.0, 0.2));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(5, 4)));
  ASSERT_EQ(c.updateBeliefs(0.02), Status::kOk);
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  const base::MuTilde mu = c.mu();
  const base::Vector2 a = c.action();
  for (double bad : { 0.0, -0.02, kNaN, kInf, 2.0 * params::kMaxStep })
  {
    EXPECT_EQ(c.updateBeliefs(bad), Status::kBadInterval);
    EXPECT_EQ(c.updateAction(bad), Status::kBadInterval);
    EXPECT_EQ(c.mu(), mu);
    EXPECT_EQ(c.action(), a);
  }
}

TEST(Controller, RejectsNonFiniteInputs)
{
  aic::ActiveInferenceController c{ thesisStandard() };
  EXPECT_FALSE(c.setGoal(base::Vector3(kNaN, 0.0, 0.0)));
  EXPECT_TRUE(c.goal().isZero());
  base::YTilde y = base::YTilde::Zero(5, 4);
  y(1, 2) = kInf;
  EXPECT_FALSE(c.setMeasurement(y));
  EXPECT_FALSE(c.hasMeasurement());
  EXPECT_FALSE(c.setMeasurement(base::YTilde::Zero(5, 3)));  // wrong number of orders
  y.setZero();
  y(3, 3) = 2.0 * aic::ActiveInferenceController::kMaxMeasurementMagnitude;
  EXPECT_FALSE(c.setMeasurement(y));
  EXPECT_FALSE(c.hasMeasurement());
  EXPECT_FALSE(c.setGoal(base::Vector3(0.0, 0.0, 2.0 * c.params().runaway_limit)));
  base::MuTilde mu = base::MuTilde::Zero(3, 4);
  mu(1, 1) = kNaN;
  EXPECT_FALSE(c.setBeliefs(mu));
  EXPECT_FALSE(c.setBeliefs(base::MuTilde::Zero(3, 2)));
  EXPECT_TRUE(c.mu().isZero());
  c.setAction(base::Vector2(kNaN, 1.0));
  EXPECT_TRUE(c.action().isZero());
  c.setAction(base::Vector2(100.0, -100.0));
  EXPECT_EQ(c.action()(0), 20.0);
  EXPECT_EQ(c.action()(1), -20.0);
}

TEST(Controller, ConvergesWithPerfectPlantEuler)
{
  constexpr double kVelocityTol = 0.01;  // m/s
  constexpr double kYawTol = 0.01;       // rad/s
  aic::ActiveInferenceController c{ thesisStandard() };
  const base::Vector3 goal(0.5, 0.0, 0.3);
  c.setGoal(goal);
  const double h = 1.0 / 50.0;
  for (int k = 0; k < 50 * 60; ++k)
  {
    ASSERT_TRUE(c.setMeasurement(perfectMeasurement(c)));
    ASSERT_EQ(c.updateBeliefs(h), Status::kOk);
    ASSERT_EQ(c.updateAction(h), Status::kOk);
  }
  const base::Vector3 twist = c.model().twistFromWheels(c.action());
  EXPECT_NEAR(twist(0), goal(0), kVelocityTol);
  EXPECT_NEAR(twist(2), goal(2), kYawTol);
  EXPECT_NEAR(c.mu()(0, 0), goal(0), kVelocityTol);
}

TEST(Controller, RunawayIsDetectedAndReset)
{
  params::AicParams p = thesisStandard();
  p.tau = 0.001;  // Euler-unstable at 50 Hz (doc/active_inference.md, 'Analysis notes')
  p.runaway_limit = 100.0;
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(1.0, 0.0, 0.0));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(5, 4)));
  bool runaway = false;
  for (int k = 0; k < 1000 && !runaway; ++k)
  {
    const Status s = c.updateBeliefs(0.02);
    ASSERT_TRUE(s == Status::kOk || s == Status::kRunaway);
    EXPECT_TRUE(c.mu().allFinite());
    EXPECT_LE(c.mu().cwiseAbs().maxCoeff(), p.runaway_limit);
    runaway = s == Status::kRunaway;
  }
  EXPECT_TRUE(runaway);
  EXPECT_EQ(c.runawayCount(), 1u);
  EXPECT_TRUE(c.mu().isZero());
  EXPECT_TRUE(c.action().isZero());
  c.reset();
  EXPECT_FALSE(c.hasMeasurement());
}

TEST(Controller, AnActionStepBeyondTheWheelsRangeIsResetNotClamped)
{
  // The action's own guard, reached directly: with the largest action gain the schema allows and
  // the longest step the controller takes, one step of a_F moves a wheel's command by far more
  // than 2 max_wheel_speed. The update must reset (zero action, kRunaway), not pass it on to the
  // wheel clamp, which would make it +-max_wheel_speed.
  params::AicParams p = thesisStandard();
  p.k_a = params::kMaxGain;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setGoal(base::Vector3(1.0, 0.0, 0.0)));
  base::YTilde y = base::YTilde::Zero(5, 4);
  y(base::kOmegaLeft, 0) = 3.0;
  y(base::kOmegaRight, 0) = 3.0;
  ASSERT_TRUE(c.setMeasurement(y));
  ASSERT_EQ(c.updateAction(1.0e-9), Status::kOk);
  ASSERT_FALSE(c.action().isZero()) << "no action to reset";
  EXPECT_EQ(c.updateAction(params::kMaxStep), Status::kRunaway);
  EXPECT_TRUE(c.action().isZero()) << c.action().transpose();
  EXPECT_EQ(c.runawayCount(), 1u);
}

TEST(Controller, ADivergingActionIsResetNotClamped)
{
  // The thesis's improved controller as printed (Euler, tau = 0.001 s at 1 kHz, config/
  // thesis_improved_euler_diverges.yaml) diverges: from rest its beliefs grow ~6x per belief step and the
  // belief update's runaway check (|mu| > runaway_limit) fires at the fifth. An action step that
  // reads the fourth step's beliefs (finite, below runaway_limit, hundreds of m/s) must reset and
  // send zero, not clamp that action to +-max_wheel_speed and send it.
  params::AicParams p;
  p.integrator = params::Integrator::kEuler;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.0)));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(5, 4)));
  int k = 0;
  while (c.mu().cwiseAbs().maxCoeff() <= 10.0 * p.max_wheel_speed && k < 10)
  {
    ASSERT_EQ(c.updateBeliefs(1.0 / p.belief_rate), Status::kOk) << "belief step " << k;
    ++k;
  }
  ASSERT_LE(c.mu().cwiseAbs().maxCoeff(), p.runaway_limit) << "the belief check would have caught it";
  ASSERT_GT(c.mu().cwiseAbs().maxCoeff(), 10.0 * p.max_wheel_speed) << "no diverging beliefs to act on";
  EXPECT_EQ(c.updateAction(1.0 / p.action_rate), Status::kRunaway) << "action sent: " << c.action().transpose();
  EXPECT_TRUE(c.action().isZero()) << c.action().transpose();
  EXPECT_TRUE(c.mu().isZero());
  EXPECT_EQ(c.runawayCount(), 1u);
}

TEST(Controller, ASaturatedActionIsNotADivergence)
{
  // The largest step the default gains take at the wheel limit: goal at the top speed, wheels
  // measured at the opposite limit. It is clamped, not reset.
  params::AicParams p;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setGoal(base::Vector3(p.max_wheel_speed * p.wheel_radius, 0.0, 0.0)));
  base::YTilde y = base::YTilde::Zero(5, 4);
  y(base::kOmegaLeft, 0) = -p.max_wheel_speed;
  y(base::kOmegaRight, 0) = -p.max_wheel_speed;
  ASSERT_TRUE(c.setMeasurement(y));
  for (int k = 0; k < 50; ++k)
  {
    ASSERT_EQ(c.updateAction(1.0 / p.action_rate), Status::kOk) << "action step " << k;
    EXPECT_LE(c.action().cwiseAbs().maxCoeff(), p.max_wheel_speed);
  }
  EXPECT_EQ(c.action().cwiseAbs().maxCoeff(), p.max_wheel_speed) << "not at the limit: " << c.action().transpose();
  EXPECT_EQ(c.runawayCount(), 0u);
}

TEST(Controller, ActionIsClamped)
{
  params::AicParams p = thesisStandard();
  p.max_wheel_speed = 1.0;
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(2.0, 0.0, 0.0));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(5, 4)));
  for (int k = 0; k < 500; ++k)
  {
    c.updateBeliefs(0.02);
    c.updateAction(0.02);
    EXPECT_LE(c.action().cwiseAbs().maxCoeff(), 1.0);
  }
  EXPECT_EQ(c.action()(0), 1.0);
}

TEST(Controller, MaxActionLeadBoundsTheActionAroundTheMeasuredWheels)
{
  constexpr double kLead = 2.0;          // rad/s
  constexpr double kWheelsLeft = 3.0;    // rad/s, measured
  constexpr double kWheelsRight = -1.0;  // rad/s, measured
  constexpr double kTol = 1e-12;         // rad/s
  // A plant stuck at fixed wheel speeds while the goal asks for far more: without the limit
  // the action winds up to the wheel clamp; with it, it stays within kLead of the wheels.
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  y(base::kOmegaLeft, 0) = kWheelsLeft;
  y(base::kOmegaRight, 0) = kWheelsRight;
  for (const double lead : { 0.0, kLead })
  {
    params::AicParams p = thesisStandard();
    p.anti_windup.max_action_lead = lead;
    aic::ActiveInferenceController c{ p };
    c.setGoal(base::Vector3(2.0, 0.0, 0.0));
    ASSERT_TRUE(c.setMeasurement(y));
    for (int k = 0; k < 500; ++k)
    {
      c.updateBeliefs(0.02);
      ASSERT_EQ(c.updateAction(0.02), Status::kOk);
    }
    if (lead > 0.0)
    {
      EXPECT_NEAR(c.action()(0), kWheelsLeft + kLead, kTol);
      EXPECT_NEAR(c.action()(1), kWheelsRight + kLead, kTol);
    }
    else
    {
      EXPECT_EQ(c.action()(0), p.max_wheel_speed);  // wound up to the clamp
    }
  }
}

TEST(Controller, MaxActionLeadTurnBoundsOnlyTheDifferentialLead)
{
  constexpr double kLead = 3.0;      // rad/s, per wheel
  constexpr double kTurnLead = 1.0;  // rad/s, differential
  constexpr double kTol = 1e-12;     // rad/s
  // Wheels held still by friction while the goal asks for a turn in place (and, second, for a
  // straight run): the turn lead bounds half the leads' difference; a straight goal, whose
  // leads are equal, is not touched.
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  for (const bool turn : { true, false })
  {
    for (const double turn_lead : { 0.0, kTurnLead })
    {
      params::AicParams p = thesisStandard();
      p.anti_windup.max_action_lead = kLead;
      p.anti_windup.max_action_lead_turn = turn_lead;
      aic::ActiveInferenceController c{ p };
      c.setGoal(turn ? base::Vector3(0.0, 0.0, 1.0) : base::Vector3(1.0, 0.0, 0.0));
      ASSERT_TRUE(c.setMeasurement(y));
      for (int k = 0; k < 500; ++k)
      {
        c.updateBeliefs(0.02);
        ASSERT_EQ(c.updateAction(0.02), Status::kOk);
      }
      const double common = 0.5 * (c.action()(0) + c.action()(1));
      const double differential = 0.5 * (c.action()(1) - c.action()(0));
      SCOPED_TRACE(std::string(turn ? "turn" : "straight") + ", turn lead " + std::to_string(turn_lead));
      EXPECT_LE(std::abs(c.action()(0)), kLead + kTol);
      EXPECT_LE(std::abs(c.action()(1)), kLead + kTol);
      if (turn)
      {
        EXPECT_NEAR(differential, turn_lead > 0.0 ? kTurnLead : kLead, kTol);  // wound up to the bound in force
        EXPECT_NEAR(common, 0.0, 1e-9);
      }
      else
      {
        EXPECT_NEAR(common, kLead, kTol);  // the turn lead does not touch a straight run
        EXPECT_NEAR(differential, 0.0, 1e-9);
      }
    }
  }
}

TEST(Controller, MaxActionLeadTurnIgnoresAnIsolatedWheel)
{
  // The turn lead is measured against both wheel readings: with one isolated (a biased
  // encoder), it must not bound the command, or the faulty reading would steer the robot.
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  y(base::kOmegaLeft, 0) = 8.0;  // a biased left encoder
  params::AicParams p = thesisStandard();
  p.anti_windup.max_action_lead_turn = 0.5;
  aic::ActiveInferenceController c{ p };
  c.setSensorMask(static_cast<std::uint8_t>(0x1F & ~(1u << base::kOmegaLeft)));
  c.setGoal(base::Vector3(0.0, 0.0, 1.0));
  ASSERT_TRUE(c.setMeasurement(y));
  for (int k = 0; k < 200; ++k)
  {
    c.updateBeliefs(0.02);
    ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  }
  // Against the biased reading the differential lead would be held to 0.5 rad/s; it is not.
  const double differential =
      0.5 * ((c.action()(1) - y(base::kOmegaRight, 0)) - (c.action()(0) - y(base::kOmegaLeft, 0)));
  EXPECT_GT(std::abs(differential), 0.5 + 1e-6);
}

TEST(Controller, MaxActionLeadNeverBreaksTheWheelClamp)
{
  params::AicParams p = thesisStandard();
  p.max_wheel_speed = 5.0;
  p.anti_windup.max_action_lead = 1.0;
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(0.0, 0.0, 0.0));
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  y(base::kOmegaLeft, 0) = 50.0;  // measured far beyond the clamp (e.g. pushed downhill)
  y(base::kOmegaRight, 0) = -50.0;
  ASSERT_TRUE(c.setMeasurement(y));
  for (int k = 0; k < 100; ++k)
  {
    c.updateBeliefs(0.02);
    c.updateAction(0.02);
    EXPECT_LE(c.action().cwiseAbs().maxCoeff(), 5.0);
    EXPECT_TRUE(c.action().allFinite());
  }
}

TEST(Controller, SetParamsKeepsOrResetsState)
{
  aic::ActiveInferenceController c{ thesisStandard() };
  c.setGoal(base::Vector3(0.5, 0.0, 0.0));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(5, 4)));
  c.updateBeliefs(0.02);
  const base::MuTilde mu = c.mu();
  params::AicParams p = thesisStandard();
  p.k_a = 10.0;
  c.setParams(p);
  EXPECT_EQ(c.mu(), mu);
  EXPECT_TRUE(c.hasMeasurement());
  p.embedding_order = 2;
  p.var_mu = { 1.0, 1.0, 1.0 };
  p.var_y = { 1.0, 1.0, 1.0 };
  c.setParams(p);
  EXPECT_EQ(c.mu().cols(), 3);
  EXPECT_TRUE(c.mu().isZero());
  EXPECT_FALSE(c.hasMeasurement());
}

// ---- set-point dynamics and the action prior (doc/active_inference.md, 'Set-point dynamics',
// 'Action prior')

TEST(Controller, ActionPriorIsTheGoalsWheelSpeeds)
{
  params::AicParams p = thesisStandard();
  aic::ActiveInferenceController off{ p };
  off.setGoal(base::Vector3(1.0, 0.0, 0.5));
  EXPECT_EQ(off.actionPrior(), base::Vector2::Zero());  // gain 0: the thesis controller
  p.action_prior.gain = 0.8;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setGoal(base::Vector3(1.0, 0.0, 0.5)));
  // W = the wheel rows of R: omega_L,R = (v -+ w b_hat / 2) / (r alpha).
  const double r = p.wheel_radius * p.slip_factor;
  const base::Vector2 wheels((1.0 - 0.5 * p.wheel_separation / 2.0) / r, (1.0 + 0.5 * p.wheel_separation / 2.0) / r);
  EXPECT_LT((c.actionPrior() - 0.8 * wheels).cwiseAbs().maxCoeff(), 1e-12);
  // The first action step hands the prior over at once (a_F starts at zero).
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, 4)));
  ASSERT_EQ(c.updateAction(1e-9), Status::kOk);
  EXPECT_LT((c.action() - 0.8 * wheels).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(Controller, SetActionIsBumplessWithAPrior)
{
  params::AicParams p = thesisStandard();
  p.action_prior.gain = 1.0;
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(0.5, 0.0, 0.0));
  c.setAction(base::Vector2(1.0, 1.0));  // e.g. the measured wheels at a start
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, 4)));
  ASSERT_EQ(c.updateAction(1e-9), Status::kOk);
  EXPECT_LT((c.action() - base::Vector2(1.0, 1.0)).cwiseAbs().maxCoeff(), 1e-6);  // no jump to the prior
}

TEST(Controller, ReleaseAtRestDecaysOnlyTheChannelsWhoseGoalIsZero)
{
  // a_F = (1, 2): common part 1.5 (the linear channel), differential part 0.5 (the yaw channel).
  // With y = 0 and mu = 0 the prediction errors are zero, so only the release changes a_F.
  params::AicParams p = thesisStandard();
  p.action_release_time = 0.2;
  const double h = 0.02;
  const double keep = std::exp(-10 * h / p.action_release_time);  // after 10 steps: e^-1
  struct Case
  {
    base::Vector3 goal;
    double common, differential;  // expected after the 10 steps
  };
  const std::vector<Case> cases = {
    { base::Vector3(0.3, 0.0, 0.0), 1.5, 0.5 * keep },         // driving straight: the turn's part is released
    { base::Vector3(0.0, 0.0, 0.5), 1.5 * keep, 0.5 },         // turning in place: the linear part is released
    { base::Vector3(0.0, 0.0, 0.0), 1.5 * keep, 0.5 * keep },  // a stop: both
    { base::Vector3(0.3, 0.0, 0.5), 1.5, 0.5 },                // an arc: neither
  };
  for (const Case& k : cases)
  {
    aic::ActiveInferenceController c{ p };
    ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, 4)));
    ASSERT_TRUE(c.setGoal(k.goal));
    c.setAction(base::Vector2(1.0, 2.0));
    for (int i = 0; i < 10; ++i)
    {
      ASSERT_EQ(c.updateAction(h), Status::kOk);
    }
    EXPECT_NEAR(c.action()(0), k.common - k.differential, 1e-12) << k.goal.transpose();
    EXPECT_NEAR(c.action()(1), k.common + k.differential, 1e-12) << k.goal.transpose();
  }
  p.action_release_time = 0.0;  // off: a_F is kept at a stop
  aic::ActiveInferenceController off{ p };
  ASSERT_TRUE(off.setMeasurement(base::YTilde::Zero(base::kYDim, 4)));
  off.setAction(base::Vector2(1.0, 2.0));
  for (int i = 0; i < 10; ++i)
  {
    ASSERT_EQ(off.updateAction(h), Status::kOk);
  }
  EXPECT_EQ(off.action(), base::Vector2(1.0, 2.0));
}

TEST(Controller, TheLeadNeverCutsThePriorAndNoClampIsStored)
{
  // The prior asks for 10 rad/s at once while the wheels stand: the lead (1 rad/s) does not cut
  // it (the MCU handles a stock base's step itself). The wheel clamp (6 rad/s) does; once the
  // goal is within it again the command is the prior again: the cut was not stored in a_F.
  params::AicParams p = thesisStandard();
  p.action_prior.gain = 1.0;
  p.anti_windup.max_action_lead = 1.0;
  p.max_wheel_speed = 6.0;
  p.k_a = 1e-6;  // the free-energy part does (almost) nothing
  aic::ActiveInferenceController c{ p };
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  ASSERT_TRUE(c.setMeasurement(y));
  c.setGoal(base::Vector3(5.0 * p.wheel_radius, 0.0, 0.0));
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  EXPECT_NEAR(c.action()(0), 5.0, 1e-6);  // beyond the 1 rad/s lead: the prior alone
  c.setGoal(base::Vector3(10.0 * p.wheel_radius, 0.0, 0.0));
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  EXPECT_NEAR(c.action()(0), 6.0, 1e-9);  // cut by the wheel clamp
  c.setGoal(base::Vector3(3.0 * p.wheel_radius, 0.0, 0.0));
  ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  EXPECT_NEAR(c.action()(0), 3.0, 1e-6);
  EXPECT_NEAR(c.action()(1), 3.0, 1e-6);
}

TEST(Controller, TheFreeEnergyActionDoesNotWindUpBeyondTheLead)
{
  // Wheels held still, no prior: a_F integrates up to the lead and holds there, and comes back
  // at once when the error reverses (no stored windup).
  params::AicParams p = thesisStandard();
  p.anti_windup.max_action_lead = 1.0;
  aic::ActiveInferenceController c{ p };
  base::YTilde y = base::YTilde::Zero(base::kYDim, 4);
  ASSERT_TRUE(c.setMeasurement(y));
  c.setGoal(base::Vector3(0.5, 0.0, 0.0));
  for (int k = 0; k < 200; ++k)
  {
    c.updateBeliefs(0.02);
    ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  }
  EXPECT_NEAR(c.action()(0), 1.0, 1e-9);
  c.setGoal(base::Vector3(-0.5, 0.0, 0.0));
  for (int k = 0; k < 10; ++k)
  {
    c.updateBeliefs(0.02);
    ASSERT_EQ(c.updateAction(0.02), Status::kOk);
  }
  EXPECT_LT(c.action()(0), 1.0 - 1e-3);  // already on its way down
}

TEST(Controller, GeneralizedGoalAddsTheGoalsRateToTheAttractor)
{
  params::AicParams p = thesisStandard();
  const base::Vector3 mu_d(0.5, 0.0, 0.2);
  const base::Vector3 rate(2.0, 0.0, -1.0);
  base::MuTilde mu = base::MuTilde::Zero(base::kMuDim, 4);
  mu(0, 0) = 0.3;
  mu(0, 1) = 0.7;
  for (const bool generalized : { false, true })
  {
    p.reference.generalized_goal = generalized;
    aic::ActiveInferenceController c{ p };
    ASSERT_TRUE(c.setGoal(mu_d, rate));
    ASSERT_TRUE(c.setBeliefs(mu));
    const base::Vector3 expected_rate = generalized ? rate : base::Vector3::Zero();
    EXPECT_EQ(c.goalRate(), expected_rate);
    // eps_mu^(0) = mu^(1) - mu_d' - (mu_d - mu^(0)) / tau
    const base::Vector3 expected = mu.col(1) - expected_rate - (mu_d - mu.col(0)) / p.tau;
    EXPECT_LT((c.epsMu().col(0) - expected).cwiseAbs().maxCoeff(), 1e-12);
  }
  aic::ActiveInferenceController c{ p };
  EXPECT_FALSE(c.setGoal(mu_d, base::Vector3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0)));
  EXPECT_EQ(c.goal(), base::Vector3::Zero());  // refused whole
}

TEST(Controller, ReferenceModelDelaysAndFiltersTheGoal)
{
  params::AicParams p = thesisStandard();
  p.belief_rate = 1000.0;
  p.reference.time_constant = 0.1;
  p.reference.delay = 0.05;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.startReference(base::Vector3::Zero()));
  c.setGoal(base::Vector3(1.0, 0.0, -1.0));
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, 4)));
  for (int k = 0; k < 50; ++k)
  {
    ASSERT_EQ(c.updateBeliefs(1e-3), Status::kOk);
  }
  EXPECT_NEAR(c.attractorGoal()(0), 0.0, 1e-9);  // within the delay: nothing yet
  for (int k = 0; k < 100; ++k)
  {
    ASSERT_EQ(c.updateBeliefs(1e-3), Status::kOk);
  }
  // t = 0.15 s: mu_r = m(0.1 s) = 1 - exp(-1) along x_dot, the negative along theta_dot.
  const double expected = 1.0 - std::exp(-1.0);
  EXPECT_NEAR(c.attractorGoal()(0), expected, 1e-6);
  EXPECT_NEAR(c.attractorGoal()(2), -expected, 1e-6);
  // The beliefs follow the reference path, not the goal: still well short of it.
  EXPECT_LT(c.mu()(0, 0), 0.9);
  EXPECT_FALSE(c.startReference(base::Vector3(std::numeric_limits<double>::infinity(), 0.0, 0.0)));
}

TEST(Controller, ReferencePriorInvertsTheWheelLoopLag)
{
  // a_ff = k_ff W (m + T_p m'): at the step, with m at rest, the prior leads the goal by T_p / T_r.
  params::AicParams p = thesisStandard();
  p.reference.time_constant = 0.1;
  p.action_prior.gain = 1.0;
  p.action_prior.time_constant = 0.2;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.startReference(base::Vector3::Zero()));
  const double v = p.wheel_radius;  // 1 rad/s of wheel speed
  c.setGoal(base::Vector3(v, 0.0, 0.0));
  EXPECT_NEAR(c.actionPrior()(0), 2.0, 1e-12);
  EXPECT_NEAR(c.actionPrior()(1), 2.0, 1e-12);
}
