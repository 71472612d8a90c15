/// \file test_goal_rate.cpp  GoalRateEstimator: mu_d' of a zero-order-hold set-point stream.
#include <gtest/gtest.h>

#include <limits>

#include "jackal_aic/aic/goal_rate.hpp"

using namespace jackal_aic;

namespace
{
params::ReferenceModelParams limits()
{
  params::ReferenceModelParams p;
  p.goal_rate_hold = 0.15;
  p.max_goal_rate_linear = 4.0;
  p.max_goal_rate_angular = 8.0;
  return p;
}

TEST(GoalRate, RampAtTenHertzStreamedAtFifty)
{
  // At rest for 0.5 s, then a planner ramps 0 -> 0.8 m/s at 2 m/s^2 in 10 Hz steps (0.5 ... 0.8 s);
  // the set point is repeated at 50 Hz.
  aic::GoalRateEstimator g(limits());
  double value = 0.0;
  for (int k = 0; k <= 50; ++k)  // t = 0 ... 1 s
  {
    const double t = 0.02 * k;
    if (k >= 25 && k % 5 == 0 && value < 0.8 - 1e-9)
    {
      value += 0.2;
    }
    ASSERT_TRUE(g.update(t, base::Vector3(value, 0.0, 0.0)));
    if (k == 25)
    {
      EXPECT_EQ(g.rate(t), base::Vector3::Zero());  // the first change after a hold is a step
    }
    if (k >= 30 && k <= 40)
    {
      EXPECT_NEAR(g.rate(t)(0), 2.0, 1e-9) << t;  // the ramp continues
    }
  }
  // The last change was at 0.8 s; 1.25 intervals (0.125 s) later the ramp has ended.
  EXPECT_NEAR(g.rate(0.92)(0), 2.0, 1e-9);
  EXPECT_EQ(g.rate(0.93), base::Vector3::Zero());
}

TEST(GoalRate, StepAfterHoldIsNotARamp)
{
  aic::GoalRateEstimator g(limits());
  ASSERT_TRUE(g.update(0.0, base::Vector3::Zero()));
  ASSERT_TRUE(g.update(2.0, base::Vector3(0.5, 0.0, 1.0)));
  EXPECT_EQ(g.rate(2.0), base::Vector3::Zero());
}

TEST(GoalRate, ClampedToTheLimits)
{
  aic::GoalRateEstimator g(limits());
  ASSERT_TRUE(g.update(0.0, base::Vector3::Zero()));
  ASSERT_TRUE(g.update(0.05, base::Vector3(0.1, 0.0, 0.1)));
  ASSERT_TRUE(g.update(0.10, base::Vector3(1.1, 0.0, -1.0)));  // 20 m/s^2, -22 rad/s^2
  EXPECT_NEAR(g.rate(0.1)(0), 4.0, 1e-12);
  EXPECT_NEAR(g.rate(0.1)(2), -8.0, 1e-12);
}

TEST(GoalRate, BadInputIsRefused)
{
  aic::GoalRateEstimator g(limits());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(g.update(nan, base::Vector3::Zero()));
  EXPECT_FALSE(g.update(0.0, base::Vector3(nan, 0.0, 0.0)));
  ASSERT_TRUE(g.update(1.0, base::Vector3::Zero()));
  ASSERT_TRUE(g.update(1.05, base::Vector3(0.1, 0.0, 0.0)));
  ASSERT_TRUE(g.update(1.10, base::Vector3(0.2, 0.0, 0.0)));
  EXPECT_FALSE(g.update(1.0, base::Vector3(5.0, 0.0, 0.0)));  // before the last change: out of order
  EXPECT_NEAR(g.rate(1.1)(0), 2.0, 1e-9);                     // state kept
  g.reset();
  EXPECT_EQ(g.rate(1.1), base::Vector3::Zero());
}

TEST(PredictGoal, ARampIntoAStopIsNotPredictedThroughIt)
{
  // A 10 Hz ramp 0.4 -> 0 m/s at -2 m/s^2, predicted 0.12 s ahead: 0.4 - 0.24 = 0.16 while the
  // goal is well ahead of the stop; from 0.2 m/s the extrapolation would cross 0 (0.2 - 0.24 < 0)
  // and at the stop (goal 0, slope still held) it would ask for -0.24 m/s: both give 0.
  const base::Vector3 lead = base::Vector3::Constant(0.12);
  const base::Vector3 slope(-2.0, 0.0, 0.0);
  EXPECT_NEAR(aic::predictGoal(base::Vector3(0.4, 0.0, 0.0), slope, lead)(0), 0.16, 1e-12);
  EXPECT_EQ(aic::predictGoal(base::Vector3(0.2, 0.0, 0.0), slope, lead)(0), 0.0);
  EXPECT_EQ(aic::predictGoal(base::Vector3(0.0, 0.0, 0.0), slope, lead)(0), 0.0);
  // The same in reverse, and on y_dot.
  EXPECT_EQ(aic::predictGoal(base::Vector3(-0.2, 0.0, 0.0), -slope, lead)(0), 0.0);
  EXPECT_EQ(aic::predictGoal(base::Vector3(0.0, 0.1, 0.0), base::Vector3(0.0, -2.0, 0.0), lead)(1), 0.0);
}

TEST(PredictGoal, ARampAwayFromAStopOrAYawRateIsPredicted)
{
  const base::Vector3 lead(0.12, 0.12, 0.1);
  // Speeding up and slowing down short of 0: mu_d + t_lead mu_d' on each channel.
  const base::Vector3 up = aic::predictGoal(base::Vector3(0.2, -0.3, 0.5), base::Vector3(2.0, -1.0, 1.0), lead);
  EXPECT_NEAR(up(0), 0.44, 1e-12);
  EXPECT_NEAR(up(1), -0.42, 1e-12);
  EXPECT_NEAR(up(2), 0.6, 1e-12);
  EXPECT_NEAR(aic::predictGoal(base::Vector3(-0.5, 0.0, 0.0), base::Vector3(2.0, 0.0, 0.0), lead)(0), -0.26, 1e-12);
  // The yaw rate sweeps through 0 inside an S-curve: predicted through it, and from 0.
  EXPECT_NEAR(aic::predictGoal(base::Vector3(0.0, 0.0, 0.05), base::Vector3(0.0, 0.0, -1.0), lead)(2), -0.05, 1e-12);
  EXPECT_NEAR(aic::predictGoal(base::Vector3::Zero(), base::Vector3(0.0, 0.0, 1.0), lead)(2), 0.1, 1e-12);
  // No rate: the goal itself.
  EXPECT_EQ(aic::predictGoal(base::Vector3(0.3, 0.0, -0.2), base::Vector3::Zero(), lead),
            base::Vector3(0.3, 0.0, -0.2));
}

TEST(PredictGoal, NonFiniteInGivesNonFiniteOut)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const base::Vector3 out =
      aic::predictGoal(base::Vector3(0.5, 0.0, nan), base::Vector3(1.0, 0.0, 0.0), base::Vector3::Constant(0.1));
  EXPECT_FALSE(out.allFinite());
}
}  // namespace
