/// Tests of the action's slew limit (ActionSlewLimit, key action_slew_limit; doc/extending.md, the
/// worked example): the stage's maths and bad input, its schema row, and its place in the
/// controller's action step. The closed loop on the simulated Jackal:
/// test/sim/test_closed_loop_acceptance.cpp, StepResponse.TheSlewLimitBoundsTheWheelCommandsRate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "jackal_aic/aic/action_slew_limit.hpp"
#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/params/param_schema.hpp"

using namespace jackal_aic;
using Status = aic::ActiveInferenceController::Status;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kH = 0.02;  ///< action step [s]

aic::ActionSlewLimit limit(double max_rate)
{
  params::ActionSlewLimitParams p;
  p.max_rate = max_rate;
  return aic::ActionSlewLimit(p);
}

bool hasViolation(const params::AicParams& p, const std::string& key)
{
  for (const params::ParamViolation& v : p.validate())
  {
    if (v.name == key)
    {
      return true;
    }
  }
  return false;
}
}  // namespace

// ---- the stage

TEST(ActionSlewLimit, OffPassesEverythingOnBitForBit)
{
  const base::Vector2 previous(0.0, 0.0), command(10.0, -7.0), a_F(0.1, 0.2), candidate(9.0, -8.0);
  for (double off : { 0.0, kNaN })  // 0 = off; NaN, which the schema refuses, acts as off
  {
    const aic::ActionSlewLimit s = limit(off);
    EXPECT_FALSE(s.enabled());
    const aic::ActionSlewLimit::Result r =
        s.apply(previous, command, a_F, candidate, base::Vector2(1.0, -1.0), base::Vector2(1.0, 1.0), kH);
    EXPECT_EQ(r.command, command);
    EXPECT_EQ(r.free_energy_part, candidate);
    EXPECT_FALSE(r.limited);
  }
}

TEST(ActionSlewLimit, AChangeWithinTheLimitIsKept)
{
  const aic::ActionSlewLimit s = limit(50.0);  // 1 rad/s per 20 ms step
  const aic::ActionSlewLimit::Result r =
      s.apply(base::Vector2(2.0, 2.0), base::Vector2(3.0, 1.5), base::Vector2::Zero(), base::Vector2(3.0, 1.5),
              base::Vector2(1.0, -1.0), base::Vector2::Zero(), kH);
  EXPECT_EQ(r.command, base::Vector2(3.0, 1.5));
  EXPECT_FALSE(r.limited);
}

TEST(ActionSlewLimit, TheLargerChangeMovesByTheLimitAndTheDirectionIsKept)
{
  // A step into an arc from rest: the wheels' change (4, 8) rad/s; S h = 50 x 0.02 = 1 rad/s.
  const aic::ActionSlewLimit s = limit(50.0);
  const base::Vector2 previous(1.0, 2.0), command(5.0, 10.0);
  const aic::ActionSlewLimit::Result r =
      s.apply(previous, command, base::Vector2::Zero(), command, base::Vector2(1.0, 1.0), base::Vector2::Zero(), kH);
  EXPECT_TRUE(r.limited);
  EXPECT_NEAR(r.command(1) - previous(1), 1.0, 1e-15);
  EXPECT_NEAR(r.command(0) - previous(0), 0.5, 1e-15);  // the same fraction of its change
  // The ratio of the wheels' changes (the arc's) is kept; each stays between a_prev and the command.
  EXPECT_NEAR((r.command(1) - previous(1)) / (r.command(0) - previous(0)), 2.0, 1e-12);
  for (int i = 0; i < 2; ++i)
  {
    EXPECT_GE(r.command(i), previous(i));
    EXPECT_LE(r.command(i), command(i));
  }
  // Downwards alike.
  const aic::ActionSlewLimit::Result down =
      s.apply(command, previous, base::Vector2::Zero(), previous, base::Vector2(-1.0, -1.0), base::Vector2::Zero(), kH);
  EXPECT_NEAR(down.command(1), 9.0, 1e-12);
  EXPECT_NEAR(down.command(0), 4.5, 1e-12);
}

TEST(ActionSlewLimit, LimitGivesTheCommandApplyGives)
{
  const base::Vector2 previous(1.0, 2.0), command(2.0, 1.5);
  bool limited = false;
  const base::Vector2 a = limit(10.0).limit(previous, command, kH, &limited);
  EXPECT_TRUE(limited);
  EXPECT_TRUE(a.isApprox(base::Vector2(1.2, 1.9), 1e-12)) << a.transpose();
  const aic::ActionSlewLimit::Result r =
      limit(10.0).apply(previous, command, previous, command, base::Vector2::Zero(), base::Vector2::Zero(), kH);
  EXPECT_EQ(r.command, a);
  EXPECT_EQ(limit(0.0).limit(previous, command, kH, &limited), command);
  EXPECT_FALSE(limited);
  const base::Vector2 bad = limit(10.0).limit(previous, base::Vector2(kNaN, 1.0), kH, &limited);
  EXPECT_TRUE(std::isnan(bad(0)) && bad(1) == 1.0) << "a non-finite command passes (the divergence check runs before)";
  EXPECT_FALSE(limited);
}

TEST(ActionSlewLimit, TheFreeEnergyPartDoesNotWindUpBehindTheLimit)
{
  const aic::ActionSlewLimit s = limit(50.0);
  const base::Vector2 prior(0.5, 0.5);
  // a_F integrates upwards (a_dot > 0) into a cut: it stops at the command sent less the prior.
  aic::ActionSlewLimit::Result r = s.apply(base::Vector2(1.0, 1.0), base::Vector2(4.0, 4.0), base::Vector2(0.2, 0.2),
                                           base::Vector2(3.5, 3.5), base::Vector2(10.0, 10.0), prior, kH);
  EXPECT_TRUE(r.command.isApprox(base::Vector2(2.0, 2.0), 1e-15));
  EXPECT_TRUE(r.free_energy_part.isApprox(base::Vector2(1.5, 1.5), 1e-15));
  // ... and is never pulled back below where it was (the prior's own jump is cut, not stored).
  r = s.apply(base::Vector2(1.0, 1.0), base::Vector2(4.0, 4.0), base::Vector2(3.2, 3.2), base::Vector2(3.5, 3.5),
              base::Vector2(10.0, 10.0), prior, kH);
  EXPECT_EQ(r.free_energy_part, base::Vector2(3.2, 3.2));
  // A cut against the direction a_F integrates leaves its integration alone.
  r = s.apply(base::Vector2(1.0, 1.0), base::Vector2(4.0, 4.0), base::Vector2(0.2, 0.2), base::Vector2(0.1, 0.1),
              base::Vector2(-5.0, -5.0), base::Vector2(3.9, 3.9), kH);
  EXPECT_EQ(r.free_energy_part, base::Vector2(0.1, 0.1));
}

TEST(ActionSlewLimit, BadIntervalsAndNonFiniteCommandsPassUnchanged)
{
  const aic::ActionSlewLimit s = limit(50.0);
  const base::Vector2 previous(0.0, 0.0), command(5.0, 5.0), candidate(5.0, 5.0);
  for (double h : { 0.0, -0.02, kNaN, kInf })
  {
    const aic::ActionSlewLimit::Result r =
        s.apply(previous, command, base::Vector2::Zero(), candidate, base::Vector2(1.0, 1.0), base::Vector2::Zero(), h);
    EXPECT_EQ(r.command, command) << h;
    EXPECT_FALSE(r.limited) << h;
  }
  // The controller's divergence check catches a non-finite command before this stage; the stage
  // passes it on rather than turning it into a finite one.
  const aic::ActionSlewLimit::Result r = s.apply(previous, base::Vector2(kNaN, 1.0), base::Vector2::Zero(), candidate,
                                                 base::Vector2(1.0, 1.0), base::Vector2::Zero(), kH);
  EXPECT_TRUE(std::isnan(r.command(0)));
  EXPECT_FALSE(r.limited);
}

// ---- the schema row

TEST(ActionSlewLimitSchema, TheKeyIsTheMemberAndRefusesBadValues)
{
  const params::ParamSpec* row = params::findParam("action_slew_limit");
  ASSERT_NE(row, nullptr);
  EXPECT_EQ(row->scope, params::ParamScope::kController);
  EXPECT_EQ(std::string(row->unit), "rad/s^2");
  EXPECT_EQ(params::defaultValue(*row), params::ParamValue(0.0)) << "the stage ships off";
  EXPECT_EQ(params::recommendedAicParams().action_slew.max_rate, 0.0);
  params::NodeParams n;
  ASSERT_TRUE(row->set(n, 25.0));
  EXPECT_EQ(n.aic.action_slew.max_rate, 25.0);
  // The range (every bad value: test/unit/params/test_aic_params.cpp, SetPointDynamicsAndActionPrior):
  // a negative or NaN limit is refused by validation, so no controller is built with one.
  for (double bad : { -1.0, kNaN })
  {
    params::AicParams p;
    p.action_slew.max_rate = bad;
    EXPECT_TRUE(hasViolation(p, "action_slew_limit")) << bad;
    EXPECT_THROW(aic::ActiveInferenceController c(p), std::invalid_argument) << bad;
    aic::ActiveInferenceController c{ params::AicParams() };
    EXPECT_THROW(c.setParams(p), std::invalid_argument) << bad;
    EXPECT_EQ(c.params().action_slew.max_rate, 0.0);
  }
}

// ---- in the controller's action step

namespace
{
/// The thesis's improved controller at 1 kHz / 50 Hz, exact integrator, with the slew limit S.
params::AicParams withSlewLimit(double max_rate)
{
  params::AicParams p;
  p.integrator = params::Integrator::kExact;
  p.action_slew.max_rate = max_rate;
  return p;
}

/// A plant that follows the action exactly (wheel speeds = a, the gyro its yaw rate).
base::YTilde followingPlant(const aic::ActiveInferenceController& c)
{
  base::YTilde y = base::YTilde::Zero(base::kYDim, c.params().numOrders());
  y(base::kGyroZ, 0) = c.model().twistFromWheels(c.action())(2);
  y(base::kOmegaLeft, 0) = c.action()(0);
  y(base::kOmegaRight, 0) = c.action()(1);
  return y;
}

/// One action period: the measurement, 20 belief steps of 1 ms, the action step.
void period(aic::ActiveInferenceController& c)
{
  ASSERT_TRUE(c.setMeasurement(followingPlant(c)));
  for (int k = 0; k < 20; ++k)
  {
    ASSERT_EQ(c.updateBeliefs(0.001), Status::kOk);
  }
  ASSERT_EQ(c.updateAction(kH), Status::kOk);
}
}  // namespace

namespace
{
/// The controller of `model` with the slew limit S against the same without it, both driven to
/// (0.5 m/s, 0.3 rad/s) for 10 s: every action step of the limited one moves a wheel by at most
/// S h, the unlimited one's moves more (the limit acted), and both arrive at the same command (the
/// limited one neither wound up nor lost the step).
void expectTheRateBoundedAndTheStepArriving(params::BeliefModel model, double S)
{
  params::AicParams p = withSlewLimit(S);
  p.belief_model = model;
  params::AicParams q = p;
  q.action_slew.max_rate = 0.0;
  aic::ActiveInferenceController limited(p), unlimited(q);
  for (aic::ActiveInferenceController* c : { &limited, &unlimited })
  {
    c->setGoal(base::Vector3(0.5, 0.0, 0.3));
  }
  double largest_unlimited = 0.0;
  for (int k = 0; k < 500; ++k)  // 10 s
  {
    const base::Vector2 before = limited.action(), before_unlimited = unlimited.action();
    period(limited);
    period(unlimited);
    EXPECT_LE((limited.action() - before).cwiseAbs().maxCoeff(), S * kH * (1.0 + 1e-12)) << k;
    largest_unlimited = std::max(largest_unlimited, (unlimited.action() - before_unlimited).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest_unlimited, 2.0 * S * kH) << "the limit never acted: the test checks nothing";
  EXPECT_TRUE(limited.action().isApprox(unlimited.action(), 1e-3))
      << limited.action().transpose() << " vs " << unlimited.action().transpose();
}
}  // namespace

TEST(ActionSlewLimitController, TheCommandsRateIsBoundedAndTheStepStillArrives)
{
  // 5 rad/s^2: 0.1 rad/s per 20 ms step. a_F does not wind up behind the limit.
  expectTheRateBoundedAndTheStepArriving(params::BeliefModel::kGoal, 5.0);
}

TEST(ActionSlewLimitController, TheRobotModelsCommandIsBoundedTooAndItsModelKnowsIt)
{
  // belief_model robot: the command LatencyAction finds is limited as it is sent, and the wheel
  // loop model records the limited one, so the step still arrives.
  expectTheRateBoundedAndTheStepArriving(params::BeliefModel::kRobot, 5.0);
}

TEST(ActionSlewLimitController, ALimitThatNeverActsChangesNothing)
{
  aic::ActiveInferenceController off(withSlewLimit(0.0)), wide(withSlewLimit(1.0e5));
  for (aic::ActiveInferenceController* c : { &off, &wide })
  {
    c->setGoal(base::Vector3(0.5, 0.0, -0.4));
  }
  for (int k = 0; k < 100; ++k)
  {
    period(off);
    period(wide);
    ASSERT_EQ(off.action(), wide.action()) << k;
    ASSERT_EQ(off.mu(), wide.mu()) << k;
  }
}
