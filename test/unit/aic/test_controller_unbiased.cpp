/// Tests of ActiveInferenceController's unbiased beliefs (belief_model unbiased) and of learning the
/// wheel separation inside the controller (doc/active_inference.md, 'Unbiased beliefs',
/// 'Learning the generative model').
#include <gtest/gtest.h>

#include <cmath>

#include "jackal_aic/aic/controller.hpp"

using namespace jackal_aic;
using Status = aic::ActiveInferenceController::Status;

namespace
{
constexpr double kH = 0.001;  // belief step [s]

params::AicParams unbiased()
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kUnbiased;
  p.tau = 0.1;
  p.k_mu = 5.0;  // the beliefs follow the sensors within tens of milliseconds (exact integrator)
  p.var_mu = { 1.0e3, 1.0e3, 1.0e3 };
  return p;
}

/// y^(0) of a base turning at w [rad/s] and driving v [m/s] with effective separation b_eff.
base::YTilde arcMeasurement(const aic::ActiveInferenceController& c, double v, double w, double b_eff)
{
  base::YTilde y = base::YTilde::Zero(base::kYDim, c.params().numOrders());
  const double r = c.params().wheel_radius * c.params().slip_factor;
  y(base::kGyroZ, 0) = w;
  y(base::kOmegaLeft, 0) = (v - 0.5 * w * b_eff) / r;
  y(base::kOmegaRight, 0) = (v + 0.5 * w * b_eff) / r;
  return y;
}

void runBeliefs(aic::ActiveInferenceController* c, double seconds)
{
  const int steps = static_cast<int>(std::lround(seconds / kH));
  for (int k = 0; k < steps; ++k)
  {
    ASSERT_EQ(c->updateBeliefs(kH), Status::kOk);
  }
}
/// `y` with a live gyro: a small non-zero rate of the gyro (order 1). A reading that repeats bit
/// for bit (rate exactly 0) is a stuck gyro, which the learner does not learn from.
base::YTilde live(base::YTilde y)
{
  y(base::kGyroZ, 1) = 1e-3;
  return y;
}

}  // namespace

TEST(ControllerUnbiased, DefaultsAreTheThesisModelAndTheRecommendedLearns)
{
  const params::AicParams p;
  EXPECT_EQ(p.belief_model, params::BeliefModel::kGoal);
  EXPECT_FALSE(p.separation_learner.enabled);
  EXPECT_TRUE(params::recommendedAicParams().separation_learner.enabled);
  EXPECT_EQ(params::recommendedAicParams().belief_model, params::BeliefModel::kGoal);
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(0.5, 0.0, 0.2));
  EXPECT_EQ(c.priorGoal(), c.attractorGoal());
  params::BeliefModel m = params::BeliefModel::kGoal;
  EXPECT_TRUE(params::beliefModelFromString("unbiased", &m));
  EXPECT_EQ(m, params::BeliefModel::kUnbiased);
  EXPECT_FALSE(params::beliefModelFromString("biased", &m));
  EXPECT_EQ(params::toString(params::BeliefModel::kGoal), "goal");
}

TEST(ControllerUnbiased, BeliefFollowsTheDataNotTheGoal)
{
  // Turning in place with a stalled base: the action asks for 1 rad/s, the base turns at 0.1.
  for (const params::BeliefModel model : { params::BeliefModel::kGoal, params::BeliefModel::kUnbiased })
  {
    params::AicParams p = model == params::BeliefModel::kUnbiased ? unbiased() : params::recommendedAicParams();
    aic::ActiveInferenceController c{ p };
    c.setGoal(base::Vector3(0.0, 0.0, 1.0));
    c.startReference(base::Vector3(0.0, 0.0, 1.0));
    c.setAction(c.model().wheelsFromTwist(base::Vector3(0.0, 0.0, 1.0)));
    ASSERT_TRUE(c.setMeasurement(arcMeasurement(c, 0.0, 0.1, p.wheel_separation)));
    runBeliefs(&c, 2.0);
    if (model == params::BeliefModel::kUnbiased)
    {
      EXPECT_NEAR(c.mu()(2, 0), 0.1, 0.03);
    }
    else
    {
      EXPECT_GT(c.mu()(2, 0), 0.5);  // the goal-biased prior: the belief says the base turns
    }
  }
}

TEST(ControllerUnbiased, ActionDrivenByTheGoalThroughTheBelief)
{
  params::AicParams p = unbiased();
  p.action_prior.gain = 0.0;
  aic::ActiveInferenceController c{ p };
  c.setGoal(base::Vector3(1.0, 0.0, 0.0));
  c.startReference(base::Vector3(1.0, 0.0, 0.0));
  ASSERT_TRUE(c.setMeasurement(arcMeasurement(c, 0.5, 0.0, p.wheel_separation)));
  runBeliefs(&c, 1.0);
  EXPECT_NEAR(c.mu()(0, 0), 0.5, 0.01);
  const base::Vector2 a_dot = c.aDot();
  EXPECT_GT(a_dot(0), 0.0);  // slower than the goal: both wheels speed up
  EXPECT_NEAR(a_dot(0), a_dot(1), 1e-9);
  // At the goal the action rests.
  ASSERT_TRUE(c.setMeasurement(arcMeasurement(c, 1.0, 0.0, p.wheel_separation)));
  runBeliefs(&c, 1.0);
  // (what remains is the motion prior's pull: the action was not stepped, G a = 0)
  EXPECT_LT(c.aDot().cwiseAbs().maxCoeff(), 1e-2 * std::abs(a_dot(0)));
}

TEST(ControllerUnbiased, TheGoalPriorTargetsTheExpectedResponse)
{
  // A goal step with a reference model: 50 ms after it the reference path has moved (0 -> 0.5 m/s
  // at the acceleration limit, 0.18 m/s by then), the expected response with T_g = 0.05 s lags it,
  // so the action's goal prior asks for less; after 10 T_g they agree.
  params::AicParams p = unbiased();
  p.action_prior.gain = 0.0;
  p.reference.delay = 0.0;
  params::AicParams lagged = p;
  lagged.goal_response_time_constant = 0.05;
  aic::ActiveInferenceController c{ p };
  aic::ActiveInferenceController cl{ lagged };
  for (aic::ActiveInferenceController* x : { &c, &cl })
  {
    x->setGoal(base::Vector3(0.5, 0.0, 0.0));
    ASSERT_TRUE(x->setMeasurement(arcMeasurement(*x, 0.0, 0.0, p.wheel_separation)));
    runBeliefs(x, 0.05);
  }
  // Both beliefs at rest (the data): a belief below the goal asks both wheels to speed up.
  EXPECT_GT(cl.aDot()(0), 0.0);
  EXPECT_LT(cl.aDot()(0), 0.7 * c.aDot()(0));
  for (aic::ActiveInferenceController* x : { &c, &cl })
  {
    runBeliefs(x, 0.5);
  }
  EXPECT_NEAR(cl.aDot()(0), c.aDot()(0), 1e-3 * std::abs(c.aDot()(0)));
}

TEST(ControllerUnbiased, TheGoalResponseDoesNotChangeTheGoalModel)
{
  // belief_model goal: goal_response_time_constant has no effect, bit for bit.
  params::AicParams p = params::recommendedAicParams();
  params::AicParams lagged = p;
  lagged.goal_response_time_constant = 0.05;
  aic::ActiveInferenceController c{ p };
  aic::ActiveInferenceController cl{ lagged };
  for (aic::ActiveInferenceController* x : { &c, &cl })
  {
    x->setGoal(base::Vector3(0.5, 0.0, 0.3));
    ASSERT_TRUE(x->setMeasurement(arcMeasurement(*x, 0.2, 0.1, p.wheel_separation)));
    for (int k = 0; k < 500; ++k)
    {
      ASSERT_EQ(x->updateBeliefs(kH), Status::kOk);
      if (k % 20 == 0)
      {
        ASSERT_EQ(x->updateAction(0.02), Status::kOk);
      }
    }
  }
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_EQ(c.mu()(i, 0), cl.mu()(i, 0));
  }
  EXPECT_EQ(c.action()(0), cl.action()(0));
  EXPECT_EQ(c.action()(1), cl.action()(1));
}

TEST(ControllerUnbiased, PriorTargetIsTheDelayedAction)
{
  params::AicParams p = unbiased();
  p.reference.delay = 0.1;
  p.action_prior.gain = 0.0;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setMeasurement(arcMeasurement(c, 0.0, 0.0, p.wheel_separation)));
  c.setGoal(base::Vector3(1.0, 0.0, 0.0));
  c.startReference(base::Vector3(1.0, 0.0, 0.0));
  const double h_a = 0.02;
  for (int k = 0; k < 4; ++k)  // 0.08 s < d_r: the prior still expects the start (rest)
  {
    ASSERT_EQ(c.updateAction(h_a), Status::kOk);
  }
  EXPECT_TRUE(c.priorGoal().isZero());
  for (int k = 0; k < 3; ++k)
  {
    ASSERT_EQ(c.updateAction(h_a), Status::kOk);
  }
  EXPECT_GT(c.priorGoal()(0), 0.0);  // the first actions' response is now expected
  EXPECT_TRUE(c.priorRate().isZero());
  c.reset();
  EXPECT_TRUE(c.priorGoal().isZero());
}

TEST(ControllerUnbiased, LearnsTheEffectiveSeparationOnArcs)
{
  for (const double start : { 1.0, 2.0 })
  {
    params::AicParams p = unbiased();
    p.separation_learner.enabled = true;
    p.wheel_separation = start * 0.5621;
    aic::ActiveInferenceController c{ p };
    const double b_eff = 1.4 * 0.5621;
    ASSERT_TRUE(c.setMeasurement(live(arcMeasurement(c, 0.5, 0.5, b_eff))));
    c.setAction(base::Vector2(c.yTilde()(base::kOmegaLeft, 0), c.yTilde()(base::kOmegaRight, 0)));
    runBeliefs(&c, 10.0);
    EXPECT_NEAR(c.separationLearner().separation(), b_eff, 0.05 * b_eff) << "start " << start;
    EXPECT_NEAR(c.model().wheelSeparation(), c.separationLearner().separation(),
                aic::ActiveInferenceController::kSeparationApplyTolerance * b_eff);
    runBeliefs(&c, 10.0);
    // The wheels now tell the gyro's turn: the belief is honest.
    EXPECT_NEAR(c.mu()(2, 0), 0.5, 0.01) << "start " << start;
  }
}

TEST(ControllerUnbiased, LearningFrozenWhileASensorIsIsolatedAndResettable)
{
  params::AicParams p = unbiased();
  p.separation_learner.enabled = true;
  aic::ActiveInferenceController c{ p };
  ASSERT_TRUE(c.setMeasurement(live(arcMeasurement(c, 0.5, 0.5, 1.4 * p.wheel_separation))));
  c.setSensorMask(static_cast<std::uint8_t>(((1u << base::kYDim) - 1u) & ~(1u << base::kGyroZ)));
  runBeliefs(&c, 1.0);
  EXPECT_EQ(c.separationLearner().separation(), p.wheel_separation);
  EXPECT_EQ(c.separationLearner().state(), aic::SeparationLearner::State::kSensorFault);
  c.setSensorMask(static_cast<std::uint8_t>((1u << base::kYDim) - 1u));
  runBeliefs(&c, 1.0);
  EXPECT_GT(c.separationLearner().separation(), p.wheel_separation);
  EXPECT_TRUE(c.setLearnedSeparation(0.7));
  EXPECT_DOUBLE_EQ(c.model().wheelSeparation(), 0.7);
  EXPECT_DOUBLE_EQ(c.referenceModel().wheelSeparation(), 0.7) << "the path's wheel bound uses b_hat";
  c.resetLearning();
  EXPECT_DOUBLE_EQ(c.model().wheelSeparation(), p.wheel_separation);
  EXPECT_DOUBLE_EQ(c.referenceModel().wheelSeparation(), p.wheel_separation);
  // Learning off: b_hat never moves.
  p.separation_learner.enabled = false;
  aic::ActiveInferenceController d{ p };
  ASSERT_TRUE(d.setMeasurement(arcMeasurement(d, 0.5, 0.5, 1.4 * p.wheel_separation)));
  runBeliefs(&d, 1.0);
  EXPECT_EQ(d.model().wheelSeparation(), p.wheel_separation);
}

TEST(ControllerUnbiased, SeparationBoundsValidated)
{
  params::AicParams p;
  p.separation_learner.min = 1.0;
  p.separation_learner.max = 0.5;
  EXPECT_FALSE(p.validate().empty());
  p.separation_learner.max = 2.0;
  EXPECT_TRUE(p.validate().empty());
}
