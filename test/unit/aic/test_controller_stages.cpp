/// Tests of the controller's stages on their own: ReferenceModel, ActionDelayLine, ActionPrior,
/// RestRelease, GoalResponse, AntiWindup (doc/active_inference.md, 'Structure of the controller'); the
/// learning stage, SeparationLearner, has test_separation_learner.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "jackal_aic/aic/action_delay_line.hpp"
#include "jackal_aic/aic/action_prior.hpp"
#include "jackal_aic/aic/anti_windup.hpp"
#include "jackal_aic/aic/goal_response.hpp"
#include "jackal_aic/aic/reference_model.hpp"
#include "jackal_aic/aic/rest_release.hpp"
#include "jackal_aic/aic/skid_steer_model.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

params::ReferenceModelParams referenceOn(double t_r, double delay)
{
  params::ReferenceModelParams p;
  p.time_constant = t_r;
  p.delay = delay;
  return p;
}
}  // namespace

// ---- ReferenceModel ----

TEST(ReferenceModel, WithoutAReferenceModelTheAttractorIsTheGoal)
{
  aic::ReferenceModel r;
  EXPECT_FALSE(r.enabled());
  ASSERT_TRUE(r.setGoal(base::Vector3(0.5, 0.0, 1.0), base::Vector3(1.0, 0.0, 2.0)));
  EXPECT_EQ(r.goal(), base::Vector3(0.5, 0.0, 1.0));
  EXPECT_TRUE(r.goalRate().isZero()) << "the rate is dropped unless generalized_goal";
  r.advance(0.02);  // no effect without a reference model
  EXPECT_EQ(r.attractorGoal(), base::Vector3(0.5, 0.0, 1.0));
  EXPECT_TRUE(r.attractorRate().isZero());
  EXPECT_TRUE(r.path().isZero());
}

TEST(ReferenceModel, GeneralizedGoalPredictsTheGoalAlongItsRate)
{
  params::ReferenceModelParams p;
  p.generalized_goal = true;
  p.goal_lead = 0.1;
  p.goal_lead_angular = 0.1;
  aic::ReferenceModel r(p);
  ASSERT_TRUE(r.setGoal(base::Vector3(0.5, 0.0, 1.0), base::Vector3(1.0, 0.0, -2.0)));
  EXPECT_EQ(r.goalRate(), base::Vector3(1.0, 0.0, -2.0));
  EXPECT_TRUE(r.target().isApprox(base::Vector3(0.6, 0.0, 0.8)));
  EXPECT_EQ(r.attractorRate(), base::Vector3(1.0, 0.0, -2.0));
  // Turning generalized_goal off drops the rate held.
  p.generalized_goal = false;
  r.setParams(p, 1.0e3);
  EXPECT_TRUE(r.goalRate().isZero());
  EXPECT_EQ(r.target(), base::Vector3(0.5, 0.0, 1.0));
}

TEST(ReferenceModel, TheYawRateHasItsOwnLead)
{
  // goal_lead predicts x_dot and y_dot, goal_lead_angular theta_dot: mu_d + t_lead mu_d' per channel.
  params::ReferenceModelParams p;
  p.generalized_goal = true;
  p.goal_lead = 0.1;
  p.goal_lead_angular = 0.25;
  aic::ReferenceModel r(p);
  ASSERT_TRUE(r.setGoal(base::Vector3(0.5, 0.2, 1.0), base::Vector3(1.0, -1.0, -2.0)));
  EXPECT_TRUE(r.target().isApprox(base::Vector3(0.6, 0.1, 0.5), 1e-15));
  // No angular lead: the yaw rate's goal is not predicted, the linear one still is.
  p.goal_lead_angular = 0.0;
  r.setParams(p, 1.0e3);
  EXPECT_TRUE(r.target().isApprox(base::Vector3(0.6, 0.1, 1.0), 1e-15));
}

TEST(ReferenceModel, RejectsNonFiniteAndRunawayGoals)
{
  aic::ReferenceModel r(params::ReferenceModelParams(), 10.0);
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, 0.0)));
  EXPECT_FALSE(r.setGoal(base::Vector3(kNaN, 0.0, 0.0)));
  EXPECT_FALSE(r.setGoal(base::Vector3(11.0, 0.0, 0.0)));
  EXPECT_FALSE(r.setGoal(base::Vector3(1.0, 0.0, 0.0), base::Vector3(0.0, 0.0, kInf)));
  EXPECT_EQ(r.goal(), base::Vector3(1.0, 0.0, 0.0));
  EXPECT_FALSE(r.start(base::Vector3(0.0, kInf, 0.0)));
}

TEST(ReferenceModel, FollowsTheGoalExactlyAsAFirstOrderModel)
{
  const double t_r = 0.1;
  const double h = 0.001;
  aic::ReferenceModel r(referenceOn(t_r, 0.0));
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, -2.0)));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(h);
  }
  // m(t) = mu_d (1 - e^(-t / T_r)) at t = 0.1 s, m' = (mu_d - m) / T_r; no delay: mu_r = m.
  const double f = 1.0 - std::exp(-1.0);
  EXPECT_NEAR(r.path()(0), f, 1e-12);
  EXPECT_NEAR(r.path()(2), -2.0 * f, 1e-12);
  EXPECT_NEAR(r.rate()(0), (1.0 - f) / t_r, 1e-9);
  EXPECT_EQ(r.attractorGoal(), r.path());
  EXPECT_TRUE(r.attractorRate().isApprox(r.rate()));
  EXPECT_NEAR(r.time(), 0.1, 1e-12);
}

TEST(ReferenceModel, TheAccelerationLimitBoundsThePathsSlope)
{
  params::ReferenceModelParams p = referenceOn(0.01, 0.0);
  p.max_acceleration_linear = 2.0;
  p.max_acceleration_angular = 4.0;
  aic::ReferenceModel r(p);
  EXPECT_EQ(r.accelerationLimit(), base::Vector3(2.0, 2.0, 4.0));
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, -1.0)));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  // A ramp of 2 m/s^2 and -4 rad/s^2 for 0.1 s; the rate at its bound.
  EXPECT_NEAR(r.path()(0), 0.2, 1e-12);
  EXPECT_NEAR(r.path()(2), -0.4, 1e-12);
  EXPECT_EQ(r.rate(), base::Vector3(2.0, 0.0, -4.0));
}

TEST(ReferenceModel, ThePathAheadIsTheAdvancedPathAndNeverPassesTheTarget)
{
  // T_r 5 ms against a 20 ms look-ahead: m + h m' would pass the target fourfold near its end.
  params::ReferenceModelParams p = referenceOn(0.005, 0.0);
  p.max_acceleration_linear = 4.0;
  aic::ReferenceModel r(p);
  ASSERT_TRUE(r.setGoal(base::Vector3(0.1, 0.0, 0.0)));
  for (int k = 0; k < 22; ++k)
  {
    r.advance(0.001);
  }
  const double h = 0.02;
  const base::Vector3 ahead = r.pathAhead(h);
  EXPECT_GT(r.path()(0) + h * r.rate()(0), 0.1 + 1e-3);  // the extrapolation passes the target
  EXPECT_LE(ahead(0), 0.1);
  EXPECT_GT(ahead(0), r.path()(0));
  // It is the path advance() reaches, and it leaves the model as it was.
  const base::Vector3 before = r.path();
  aic::ReferenceModel copy = r;
  copy.advance(h);
  EXPECT_TRUE(ahead.isApprox(copy.path(), 1e-15));
  EXPECT_EQ(r.path(), before);
  // h <= 0 or non-finite: the path now; no reference model: the target.
  EXPECT_EQ(r.pathAhead(0.0), before);
  EXPECT_EQ(r.pathAhead(kNaN), before);
  aic::ReferenceModel off;
  ASSERT_TRUE(off.setGoal(base::Vector3(0.3, 0.0, 0.2)));
  EXPECT_EQ(off.pathAhead(h), base::Vector3(0.3, 0.0, 0.2));
}
TEST(ReferenceModel, TheWheelBoundMakesATurnWaitForTheInnerWheel)
{
  // Goal 0.5 m/s + 0.5 rad/s with b = 0.5 m: rim speeds 0.375 (inner) and 0.625 m/s (outer).
  params::ReferenceModelParams p = referenceOn(0.005, 0.0);
  p.max_acceleration_linear = 100.0;  // the body bounds out of the way
  p.max_acceleration_angular = 100.0;
  p.max_acceleration_wheel = 2.0;
  aic::ReferenceModel r(p);
  r.setWheelSeparation(0.5);
  aic::ReferenceModel free(referenceOn(0.005, 0.0));
  const base::Vector3 goal(0.5, 0.0, 0.5);
  ASSERT_TRUE(r.setGoal(goal));
  ASSERT_TRUE(free.setGoal(goal));
  const double h = 0.001;
  auto rims = [](const base::Vector3& v) { return base::Vector2(v(0) - 0.25 * v(2), v(0) + 0.25 * v(2)); };
  for (int k = 1; k <= 600; ++k)
  {
    const base::Vector2 before = rims(r.path());
    r.advance(h);
    free.advance(h);
    EXPECT_LE((rims(r.path()) - before).cwiseAbs().maxCoeff(), 2.0 * h + 1e-12) << "step " << k;
    EXPECT_LE(rims(r.rate()).cwiseAbs().maxCoeff(), 2.0 + 1e-9) << "step " << k;
    if (k == 150)
    {
      // Both wheels ramp at 2 m/s^2 while the inner one is short of its speed: no turn yet.
      EXPECT_NEAR(r.path()(0), 0.3, 1e-12);
      EXPECT_NEAR(r.path()(2), 0.0, 1e-12);
      EXPECT_NEAR(free.path()(2), 0.5, 1e-9) << "without the bound the turn starts with the speed";
    }
    if (k == 250)
    {
      // The inner wheel holds 0.375 m/s; the outer one goes on: the yaw rate rises.
      EXPECT_NEAR(rims(r.path())(0), 0.375, 1e-3);
      EXPECT_GT(r.path()(2), 0.2);
      EXPECT_LT(r.path()(2), goal(2));
    }
  }
  EXPECT_TRUE(r.path().isApprox(goal, 1e-9)) << r.path().transpose();
  // The learned separation moves the rim speeds' frame; a non-finite or non-positive one is ignored.
  r.setWheelSeparation(0.6);
  EXPECT_EQ(r.wheelSeparation(), 0.6);
  r.setWheelSeparation(kNaN);
  r.setWheelSeparation(0.0);
  EXPECT_EQ(r.wheelSeparation(), 0.6);
}

TEST(ReferenceModel, AStartIntoReverseIsNeverLooserThanTheAccelerationsBound)
{
  // A deceleration bound above the acceleration's (a braking bound set looser than the start's):
  // braking forward and in reverse take it, a start into reverse keeps the acceleration's 1 m/s^2.
  params::ReferenceModelParams p = referenceOn(0.001, 0.0);
  p.max_acceleration_linear = 1.0;
  p.max_acceleration_angular = 4.0;
  p.max_deceleration_linear = 3.0;
  aic::ReferenceModel r(p);
  base::Vector3 lo, hi;
  ASSERT_TRUE(r.start(base::Vector3(1.0, 0.0, 0.0)));
  r.accelerationBounds(&lo, &hi);
  EXPECT_EQ(lo(0), -3.0);  // braking forward
  EXPECT_EQ(hi(0), 1.0);   // speeding up forward
  for (const double x_dot : { 0.0, -1.0 })
  {
    ASSERT_TRUE(r.start(base::Vector3(x_dot, 0.0, 0.0)));
    r.accelerationBounds(&lo, &hi);
    EXPECT_EQ(lo(0), -1.0) << x_dot;                     // speeding up in reverse
    EXPECT_EQ(hi(0), x_dot < 0.0 ? 3.0 : 1.0) << x_dot;  // braking in reverse; at rest a forward start
  }
  // From rest toward -1 m/s: 0.1 s at 1 m/s^2.
  ASSERT_TRUE(r.start(base::Vector3::Zero()));
  ASSERT_TRUE(r.setGoal(base::Vector3(-1.0, 0.0, 0.0)));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(r.path()(0), -0.1, 1e-9);
}

TEST(ReferenceModel, ThePayloadsTipBoundHoldsBrakingAndTheStartInReverse)
{
  params::ReferenceModelParams p = referenceOn(0.001, 0.0);
  p.max_acceleration_linear = 4.0;
  p.max_acceleration_angular = 4.0;
  p.max_deceleration_linear = 1.0;
  aic::ReferenceModel r(p);
  base::Vector3 lo, hi;
  // Forward and at rest: braking (and a start into reverse) at 1, speeding up forward at 4.
  for (const double x_dot : { 1.0, 0.0 })
  {
    ASSERT_TRUE(r.start(base::Vector3(x_dot, -1.0, 1.0)));
    r.accelerationBounds(&lo, &hi);
    EXPECT_EQ(lo, base::Vector3(-1.0, -4.0, -4.0)) << x_dot;  // x_dot only: y_dot and theta_dot keep theirs
    EXPECT_EQ(hi, base::Vector3(4.0, 4.0, 4.0)) << x_dot;
  }
  // In reverse: speeding up (nose-down, as braking forward) and braking, both at 1.
  ASSERT_TRUE(r.start(base::Vector3(-1.0, 1.0, 1.0)));
  r.accelerationBounds(&lo, &hi);
  EXPECT_EQ(lo, base::Vector3(-1.0, -4.0, -4.0));
  EXPECT_EQ(hi, base::Vector3(1.0, 4.0, 4.0));
  // Speeding up forward keeps the acceleration's bound: from 1 m/s toward 2 m/s at 4 m/s^2.
  ASSERT_TRUE(r.start(base::Vector3(1.0, -1.0, 1.0)));
  ASSERT_TRUE(r.setGoal(base::Vector3(2.0, -1.0, 1.0)));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(r.path()(0), 1.4, 1e-12);
  // Braking: to 0 at 1 m/s^2, then on into reverse at 1 m/s^2 as well.
  ASSERT_TRUE(r.setGoal(base::Vector3(-1.0, -1.0, 1.0)));
  for (int k = 0; k < 1000; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(r.path()(0), 0.4, 1e-9);
  EXPECT_NEAR(r.rate()(0), -1.0, 1e-12);
  int steps = 0;
  for (; steps < 410 && r.path()(0) > 0.0; ++steps)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(steps, 400, 1);
  EXPECT_EQ(r.path()(0), 0.0) << "a slowing path stops at 0 within the step it would cross it";
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(r.path()(0), -0.1, 1e-9) << "a start into reverse pitches the robot nose-down too";
  // Braking in reverse: from -1 m/s toward 0 at 1 m/s^2.
  ASSERT_TRUE(r.start(base::Vector3(-1.0, 0.0, 0.0)));
  ASSERT_TRUE(r.setGoal(base::Vector3::Zero()));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_NEAR(r.path()(0), -0.9, 1e-9);
  // 0 = the acceleration's bound both ways (the default, the thesis configurations unchanged).
  p.max_deceleration_linear = 0.0;
  r.setParams(p, 1.0e3);
  r.accelerationBounds(&lo, &hi);
  EXPECT_EQ(lo, -r.accelerationLimit());
  EXPECT_EQ(hi, r.accelerationLimit());
}

TEST(ReferenceModel, TheDelayLineShiftsThePathByTheDelay)
{
  const double delay = 0.05;
  aic::ReferenceModel delayed(referenceOn(0.1, delay));
  aic::ReferenceModel prompt(referenceOn(0.1, 0.0));
  ASSERT_TRUE(delayed.setGoal(base::Vector3(1.0, 0.0, 0.0)));
  ASSERT_TRUE(prompt.setGoal(base::Vector3(1.0, 0.0, 0.0)));
  const double h = 0.001;  // twice the line's spacing kMaxReferenceDelay / 800
  base::Vector3 path_at_150 = base::Vector3::Zero();
  for (int k = 1; k <= 200; ++k)
  {
    delayed.advance(h);
    prompt.advance(h);
    if (k <= 50)
    {
      EXPECT_TRUE(delayed.attractorGoal().isZero()) << "before the delay the path's start holds, k " << k;
    }
    if (k == 150)
    {
      path_at_150 = prompt.path();
    }
  }
  EXPECT_TRUE(delayed.attractorGoal().isApprox(path_at_150, 1e-12));
  EXPECT_EQ(delayed.path(), prompt.path()) << "the undelayed path does not depend on the delay";
  EXPECT_EQ(delayed.lineSize(), 201);
}

TEST(ReferenceModel, TheLineHasAFixedCapacity)
{
  aic::ReferenceModel r(referenceOn(0.1, params::kMaxReferenceDelay));
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, 0.0)));
  for (int k = 0; k < 3 * aic::ReferenceModel::kLine; ++k)
  {
    r.advance(0.001);
  }
  EXPECT_EQ(r.lineSize(), aic::ReferenceModel::kLine);
  EXPECT_TRUE(r.attractorGoal().allFinite());
}

TEST(ReferenceModel, StartRestartsThePathAndItsLineButKeepsTheGoal)
{
  aic::ReferenceModel r(referenceOn(0.1, 0.05));
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, 0.5)));
  for (int k = 0; k < 100; ++k)
  {
    r.advance(0.001);
  }
  ASSERT_TRUE(r.start(base::Vector3(0.3, 0.0, -0.2)));
  EXPECT_EQ(r.path(), base::Vector3(0.3, 0.0, -0.2));
  EXPECT_EQ(r.attractorGoal(), base::Vector3(0.3, 0.0, -0.2));
  EXPECT_TRUE(r.attractorRate().isZero());
  EXPECT_EQ(r.time(), 0.0);
  EXPECT_EQ(r.lineSize(), 1);
  EXPECT_EQ(r.goal(), base::Vector3(1.0, 0.0, 0.5));
}

// ---- ActionDelayLine ----

TEST(ActionDelayLine, HoldsTheTwistSentTheDelayAgo)
{
  aic::ActionDelayLine line(0.05);
  line.restart(base::Vector3::Zero());
  EXPECT_TRUE(line.delayed().isZero());
  const double h = 0.02;
  for (int k = 1; k <= 10; ++k)
  {
    line.record(h, base::Vector3(k, 0.0, -k));
    // The newest sample sent at or before t - 0.05: sent at step k - 3 (t = 0.02 (k - 3)),
    // before the line's start the start.
    const double expected = k >= 3 ? k - 3 : 0.0;
    EXPECT_EQ(line.delayed(), base::Vector3(expected, 0.0, -expected)) << "k " << k;
  }
  EXPECT_NEAR(line.clock(), 0.2, 1e-12);
  EXPECT_EQ(line.size(), 11);
}

TEST(ActionDelayLine, WithoutADelayTheLatestActionAndALongDelayTheOldest)
{
  aic::ActionDelayLine prompt(0.0);
  prompt.restart(base::Vector3::Zero());
  prompt.record(0.02, base::Vector3(1.0, 0.0, 0.0));
  EXPECT_EQ(prompt.delayed(), base::Vector3(1.0, 0.0, 0.0));

  aic::ActionDelayLine line(1.0e3);
  line.restart(base::Vector3(7.0, 0.0, 0.0));
  for (int k = 0; k < 2 * aic::ActionDelayLine::kCapacity; ++k)
  {
    line.record(0.02, base::Vector3(k, 0.0, 0.0));
  }
  EXPECT_EQ(line.size(), aic::ActionDelayLine::kCapacity);
  // The oldest sample kept: kCapacity samples back from the newest (2 kCapacity - 1).
  EXPECT_EQ(line.delayed()(0), static_cast<double>(aic::ActionDelayLine::kCapacity));
}

TEST(ActionDelayLine, RestartKeepsTheClockResetZeroesIt)
{
  aic::ActionDelayLine line(0.1);
  line.restart(base::Vector3::Zero());
  line.record(0.02, base::Vector3(1.0, 0.0, 0.0));
  line.record(0.02, base::Vector3(2.0, 0.0, 0.0));
  line.restart(base::Vector3(5.0, 0.0, 0.0));
  EXPECT_EQ(line.delayed(), base::Vector3(5.0, 0.0, 0.0));
  EXPECT_EQ(line.size(), 1);
  EXPECT_NEAR(line.clock(), 0.04, 1e-15);
  line.reset(base::Vector3(3.0, 0.0, 0.0));
  EXPECT_EQ(line.clock(), 0.0);
  EXPECT_EQ(line.delayed(), base::Vector3(3.0, 0.0, 0.0));
}

// ---- ActionPrior ----

TEST(ActionPrior, OffIsZero)
{
  const aic::SkidSteerModel model(0.098, 1.0, 0.5621);
  aic::ReferenceModel r;
  ASSERT_TRUE(r.setGoal(base::Vector3(0.5, 0.0, 1.0)));
  const aic::ActionPrior prior;
  EXPECT_FALSE(prior.enabled());
  EXPECT_TRUE(prior.wheels(model, r).isZero());
}

TEST(ActionPrior, WithoutAReferenceModelTheGoalsWheelSpeedsScaled)
{
  const aic::SkidSteerModel model(0.098, 1.0, 0.5621);
  params::ReferenceModelParams rp;
  rp.generalized_goal = true;
  rp.goal_lead = 0.1;
  aic::ReferenceModel r(rp);
  ASSERT_TRUE(r.setGoal(base::Vector3(0.5, 0.0, 1.0), base::Vector3(1.0, 0.0, 0.0)));
  params::ActionPriorParams ap;
  ap.gain = 0.8;
  ap.time_constant = 1.0;  // used with a reference model only
  const aic::ActionPrior prior(ap);
  const base::Vector2 expected = 0.8 * model.wheelsFromTwist(base::Vector3(0.6, 0.0, 1.0));
  EXPECT_TRUE(prior.wheels(model, r).isApprox(expected, 1e-12));
}

TEST(ActionPrior, WithAReferenceModelInvertsTheWheelLoopAlongThePath)
{
  const aic::SkidSteerModel model(0.098, 1.0, 0.5621);
  aic::ReferenceModel r(referenceOn(0.1, 0.05));
  ASSERT_TRUE(r.setGoal(base::Vector3(1.0, 0.0, -0.5)));
  for (int k = 0; k < 30; ++k)
  {
    r.advance(0.001);
  }
  params::ActionPriorParams ap;
  ap.gain = 1.0;
  ap.time_constant = 0.06;
  const aic::ActionPrior prior(ap);
  // k_ff W (m + T_p m'): the undelayed path, not the delayed attractor.
  const base::Vector2 expected = model.wheelsFromTwist(r.path() + 0.06 * r.rate());
  EXPECT_TRUE(prior.wheels(model, r).isApprox(expected, 1e-12));
}

// ---- GoalResponse ----

TEST(GoalResponse, OffPassesTheReferencePathOnBitForBit)
{
  aic::GoalResponse response(0.0);
  EXPECT_FALSE(response.enabled());
  const base::Vector3 mu_r(0.3, 0.0, -0.7);
  const base::Vector3 mu_r_dot(1.5, 0.0, 2.5);
  response.advance(0.001, mu_r, mu_r_dot);
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_EQ(response.goal()(i), mu_r(i));
    EXPECT_EQ(response.rate()(i), mu_r_dot(i));
  }
}

TEST(GoalResponse, FollowsAStepExactlyAsAFirstOrderLag)
{
  const double t_g = 0.05;
  aic::GoalResponse response(t_g);
  response.start(base::Vector3(0.1, 0.0, 0.0));
  const base::Vector3 step(0.5, 0.0, 1.0);
  // The exact discretization: any split of the time gives the same g (up to rounding).
  double t = 0.0;
  for (int k = 0; k < 37; ++k)
  {
    const double h = k % 2 == 0 ? 0.001 : 0.0025;
    response.advance(h, step, base::Vector3::Zero());
    t += h;
  }
  const double decay = std::exp(-t / t_g);
  EXPECT_NEAR(response.goal()(0), 0.5 + (0.1 - 0.5) * decay, 1e-12);
  EXPECT_NEAR(response.goal()(2), 1.0 * (1.0 - decay), 1e-12);
  EXPECT_NEAR(response.rate()(2), (1.0 - response.goal()(2)) / t_g, 1e-9);
  EXPECT_EQ(response.goal()(1), 0.0);
}

TEST(GoalResponse, BadStepsAndInputsLeaveItUnchanged)
{
  aic::GoalResponse response(0.1);
  response.start(base::Vector3(0.2, 0.0, 0.3));
  response.advance(0.0, base::Vector3::Ones(), base::Vector3::Zero());
  response.advance(-0.01, base::Vector3::Ones(), base::Vector3::Zero());
  response.advance(kNaN, base::Vector3::Ones(), base::Vector3::Zero());
  response.advance(0.01, base::Vector3(kInf, 0.0, 0.0), base::Vector3::Zero());
  response.advance(0.01, base::Vector3::Ones(), base::Vector3(0.0, kNaN, 0.0));
  response.start(base::Vector3(kNaN, 0.0, 0.0));
  EXPECT_EQ(response.goal(), base::Vector3(0.2, 0.0, 0.3));
  EXPECT_EQ(response.rate(), base::Vector3::Zero());
}

// ---- RestRelease ----

TEST(RestRelease, OffLeavesTheActionBitForBit)
{
  const aic::RestRelease release(0.0);
  EXPECT_FALSE(release.enabled());
  const base::Vector2 a_F(0.1, 0.3);
  const base::Vector2 out = release.apply(a_F, base::Vector3::Zero(), 0.02);
  EXPECT_EQ(out(0), a_F(0));
  EXPECT_EQ(out(1), a_F(1));
}

TEST(RestRelease, DecaysOnlyTheChannelsWhoseGoalIsZero)
{
  const double t_rel = 0.5;
  const double h = 0.02;
  const double keep = std::exp(-h / t_rel);
  const aic::RestRelease release(t_rel);
  const base::Vector2 a_F(1.0, 3.0);  // common part 2, differential part 1
  // Both goals zero: both parts decay.
  base::Vector2 out = release.apply(a_F, base::Vector3::Zero(), h);
  EXPECT_TRUE(aic::commonDifferential(out).isApprox(base::Vector2(2.0 * keep, keep), 1e-15));
  // Moving straight: only the differential part decays.
  out = release.apply(a_F, base::Vector3(0.5, 0.0, 0.0), h);
  EXPECT_TRUE(aic::commonDifferential(out).isApprox(base::Vector2(2.0, keep), 1e-15));
  // Turning in place: only the common part decays.
  out = release.apply(a_F, base::Vector3(0.0, 0.0, 1.0), h);
  EXPECT_TRUE(aic::commonDifferential(out).isApprox(base::Vector2(2.0 * keep, 1.0), 1e-15));
  // An arc keeps both.
  out = release.apply(a_F, base::Vector3(0.5, 0.0, 1.0), h);
  EXPECT_TRUE(out.isApprox(a_F, 1e-15));
}

// ---- AntiWindup ----

TEST(AntiWindup, AnUnclampedStepIntegratesFreely)
{
  const aic::AntiWindup aw;  // leads off, 20 rad/s
  const base::Vector2 a_F(1.0, 2.0);
  const base::Vector2 candidate(1.5, 2.5);
  const base::Vector2 prior(0.5, -0.5);
  const aic::AntiWindup::Result r =
      aw.apply(a_F, candidate, base::Vector2(25.0, 25.0), prior, base::Vector2::Zero(), true, true);
  EXPECT_EQ(r.command, candidate + prior);
  EXPECT_EQ(r.free_energy_part, candidate);
  EXPECT_FALSE(r.saturated);
}

TEST(AntiWindup, TheWheelClampSaturatesAndStopsTheIntegration)
{
  params::AntiWindupParams p;
  const aic::AntiWindup aw(p, 5.0);
  const base::Vector2 a_F(4.0, -4.0);
  const base::Vector2 candidate(6.0, -6.0);  // a_dot > 0 on the left, < 0 on the right
  const base::Vector2 prior(0.5, -0.5);
  const aic::AntiWindup::Result r =
      aw.apply(a_F, candidate, base::Vector2(100.0, -100.0), prior, base::Vector2::Zero(), true, true);
  EXPECT_EQ(r.command, base::Vector2(5.0, -5.0));
  EXPECT_TRUE(r.saturated);
  // a_F integrates only up to the clamp minus the prior.
  EXPECT_EQ(r.free_energy_part, base::Vector2(4.5, -4.5));
  // Already beyond the clamp: never pulled back.
  const aic::AntiWindup::Result r2 = aw.apply(base::Vector2(7.0, -7.0), base::Vector2(8.0, -8.0),
                                              base::Vector2(50.0, -50.0), prior, base::Vector2::Zero(), true, true);
  EXPECT_EQ(r2.free_energy_part, base::Vector2(7.0, -7.0));
  EXPECT_EQ(aw.limitWheelSpeed(base::Vector2(9.0, -9.0)), base::Vector2(5.0, -5.0));
}

TEST(AntiWindup, TheLeadBoundsTheCommandButNeverThePrior)
{
  params::AntiWindupParams p;
  p.max_action_lead = 1.0;
  const aic::AntiWindup aw(p);
  const base::Vector2 omega(2.0, 2.0);
  // Free-energy lead beyond the bound: cut to omega + 1, not saturation.
  aic::AntiWindup::Result r = aw.apply(base::Vector2::Zero(), base::Vector2(5.0, 0.5), base::Vector2(10.0, 10.0),
                                       base::Vector2::Zero(), omega, true, true);
  // Bounds [min(omega - 1, a_ff), max(omega + 1, a_ff)] = [0, 3].
  EXPECT_EQ(r.command, base::Vector2(3.0, 0.5));
  EXPECT_FALSE(r.saturated);
  EXPECT_EQ(r.free_energy_part, base::Vector2(3.0, 0.5));
  // The prior alone beyond the lead is not cut, and its cut is not stored in a_F.
  r = aw.apply(base::Vector2::Zero(), base::Vector2::Zero(), base::Vector2::Zero(), base::Vector2(6.0, 6.0), omega,
               true, true);
  EXPECT_EQ(r.command, base::Vector2(6.0, 6.0));
  EXPECT_TRUE(r.free_energy_part.isZero());
  // An untrusted (isolated) wheel is not bounded by its reading.
  r = aw.apply(base::Vector2::Zero(), base::Vector2(5.0, 5.0), base::Vector2(10.0, 10.0), base::Vector2::Zero(), omega,
               false, true);
  EXPECT_EQ(r.command, base::Vector2(5.0, 3.0));
}

TEST(AntiWindup, TheTurningLeadBoundsOnlyTheDifferentialLead)
{
  params::AntiWindupParams p;
  p.max_action_lead_turn = 0.5;
  const aic::AntiWindup aw(p);
  const base::Vector2 omega(1.0, 1.0);
  const aic::AntiWindup::Result r = aw.apply(base::Vector2::Zero(), base::Vector2(0.0, 4.0), base::Vector2(0.0, 10.0),
                                             base::Vector2::Zero(), omega, true, true);
  // Lead (-1, 3): common 1, differential 2 -> 0.5: lead (0.5, 1.5).
  EXPECT_TRUE(r.command.isApprox(base::Vector2(1.5, 2.5), 1e-15));
  EXPECT_TRUE(aic::commonDifferential(r.command - omega).isApprox(base::Vector2(1.0, 0.5), 1e-15));
  // With a wheel untrusted the turning lead is not bounded.
  const aic::AntiWindup::Result u = aw.apply(base::Vector2::Zero(), base::Vector2(0.0, 4.0), base::Vector2(0.0, 10.0),
                                             base::Vector2::Zero(), omega, true, false);
  EXPECT_EQ(u.command, base::Vector2(0.0, 4.0));
}

TEST(WheelPair, CommonDifferentialRoundTrips)
{
  const base::Vector2 w(1.0, 3.0);
  EXPECT_EQ(aic::commonDifferential(w), base::Vector2(2.0, 1.0));
  EXPECT_EQ(aic::wheelPair(aic::commonDifferential(w)), w);
}
