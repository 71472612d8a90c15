/**
 * \file test_inference_sample.cpp
 * \brief The controller's inference as one record (include/jackal_aic/aic/inference_sample.hpp):
 *        every field is the controller's own reading, F is its two parts, the robot model's record
 *        is its belief's with NaN where it has no such quantity, the unavailable record is NaN of
 *        the configured orders, and the order units.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "jackal_aic/aic/inference_sample.hpp"

using namespace jackal_aic;

TEST(InferenceSample, IsTheControllersReading)
{
  params::AicParams p;  // the schema's recommendation: p = 2, reference model and action prior on
  aic::ActiveInferenceController c(p);
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.3)));
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  y(base::kOmegaLeft, 0) = 2.0;
  y(base::kOmegaRight, 0) = 3.0;
  ASSERT_TRUE(c.setMeasurement(y));
  for (int k = 0; k < 40; ++k)
  {
    c.updateBeliefs(1e-3);
    if (k % 20 == 19)
    {
      c.updateAction(0.02);
    }
  }
  const aic::InferenceSample s = aic::inferenceSample(c);
  EXPECT_EQ(s.free_energy, c.freeEnergy());
  EXPECT_NEAR(s.free_energy, s.sensory + s.prior, 1e-12 * std::max(1.0, s.free_energy));
  EXPECT_GT(s.sensory, 0.0);
  EXPECT_GT(s.prior, 0.0);
  EXPECT_EQ(s.mu, c.mu());
  EXPECT_EQ(s.eps_y, c.epsY());
  EXPECT_EQ(s.eps_mu, c.epsMu());
  EXPECT_EQ(s.mu.cols(), p.numOrders());
  EXPECT_EQ(s.action, c.action());
  EXPECT_EQ(s.action_prior, c.actionPrior());
  EXPECT_EQ(s.goal, c.attractorGoal());
  EXPECT_EQ(s.precision_y, c.precisionY().col(0));
  EXPECT_EQ(s.wheel_separation, c.model().wheelSeparation());
}

TEST(InferenceSample, TheGoalModelHasNoRobotStates)
{
  aic::ActiveInferenceController c{ params::AicParams() };
  ASSERT_TRUE(c.setMeasurement(base::YTilde::Zero(base::kYDim, c.params().numOrders())));
  c.updateBeliefs(1e-3);
  aic::InferenceSample s = aic::inferenceSample(c);
  EXPECT_EQ(s.belief_model, params::BeliefModel::kGoal);
  EXPECT_TRUE(s.shortfall.array().isNaN().all() && s.turn_shortfall.array().isNaN().all() && std::isnan(s.slip_ratio) &&
              std::isnan(s.gyro_offset_belief));
  EXPECT_TRUE(aic::modelledValuesFinite(s));
  s.eps_mu(0, 1) = std::nan("");  // the goal model has eps_mu
  EXPECT_FALSE(aic::modelledValuesFinite(s));
}

TEST(InferenceSample, TheRobotModelsRecordIsItsBeliefWithNaNWhereItHasNone)
{
  params::AicParams p = params::recommendedAicParams();
  p.belief_model = params::BeliefModel::kRobot;
  ASSERT_EQ(p.numOrders(), 3);
  aic::ActiveInferenceController c(p);
  ASSERT_TRUE(c.setGoal(base::Vector3(0.5, 0.0, 0.3)));
  base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
  y(base::kGyroZ, 0) = 0.25;
  y(base::kOmegaLeft, 0) = 4.0;
  y(base::kOmegaRight, 0) = 6.0;
  for (int k = 0; k < 400; ++k)
  {
    // A fresh sample every 20 ms (the MCU's rate), the encoders' readings not repeating bit for bit.
    if (k % 20 == 0)
    {
      y(base::kOmegaLeft, 0) += (k % 40 == 0 ? 1e-4 : -1e-4);
      ASSERT_TRUE(c.setMeasurement(y));
      c.updateAction(0.02);
    }
    c.updateBeliefs(1e-3);
  }
  const aic::InferenceSample s = aic::inferenceSample(c);
  const aic::RobotBelief& b = c.robotBelief();
  EXPECT_EQ(s.belief_model, params::BeliefModel::kRobot);
  EXPECT_EQ(s.free_energy, c.freeEnergy());
  EXPECT_EQ(s.prior, b.priorFreeEnergy());
  EXPECT_EQ(s.mu.leftCols(2), c.mu().leftCols(2));
  EXPECT_TRUE(s.mu.col(2).array().isNaN().all());
  EXPECT_EQ(s.eps_y(base::kGyroZ, 0), y(base::kGyroZ, 0) - (b.yawRate() + b.gyroOffset()));
  EXPECT_EQ(s.eps_y(base::kOmegaLeft, 0), y(base::kOmegaLeft, 0) - b.wheelSpeeds()(0));
  EXPECT_EQ(s.eps_y(base::kOmegaRight, 0), y(base::kOmegaRight, 0) - b.wheelSpeeds()(1));
  EXPECT_TRUE(s.eps_y.bottomRows(2).array().isNaN().all());  // the accelerometers: not read
  EXPECT_TRUE(s.eps_y.rightCols(2).array().isNaN().all());   // no generalized sensations
  EXPECT_TRUE(s.eps_mu.array().isNaN().all());
  EXPECT_TRUE(s.action_prior.array().isNaN().all());
  EXPECT_EQ(s.action, c.action());
  EXPECT_TRUE(s.action.allFinite());
  EXPECT_EQ(s.shortfall, b.shortfalls());
  EXPECT_EQ(s.turn_shortfall, b.turnShortfalls());
  EXPECT_EQ(s.slip_ratio, b.slipRatio());
  EXPECT_EQ(s.gyro_offset_belief, b.gyroOffset());
  EXPECT_TRUE(aic::modelledValuesFinite(s));
  aic::InferenceSample bad = s;
  bad.slip_ratio = std::nan("");  // the robot model has s
  EXPECT_FALSE(aic::modelledValuesFinite(bad));
  bad = s;
  bad.eps_y(base::kOmegaRight, 0) = std::nan("");
  EXPECT_FALSE(aic::modelledValuesFinite(bad));
  EXPECT_FALSE(aic::modelledValuesFinite(aic::unavailableInferenceSample(3)));
}

TEST(InferenceSample, UnavailableIsNaNOfTheOrders)
{
  const aic::InferenceSample s = aic::unavailableInferenceSample(4);
  EXPECT_EQ(s.mu.cols(), 4);
  EXPECT_EQ(s.eps_y.cols(), 4);
  EXPECT_TRUE(std::isnan(s.free_energy) && std::isnan(s.sensory) && std::isnan(s.prior));
  EXPECT_TRUE(s.mu.array().isNaN().all() && s.eps_y.array().isNaN().all() && s.eps_mu.array().isNaN().all());
  EXPECT_TRUE(s.action.array().isNaN().all() && s.goal.array().isNaN().all() && s.precision_y.array().isNaN().all() &&
              std::isnan(s.wheel_separation));
  EXPECT_TRUE(s.shortfall.array().isNaN().all() && std::isnan(s.slip_ratio));
}

TEST(InferenceSample, OrderUnits)
{
  EXPECT_EQ(aic::orderUnit("m/s", 0), "m/s");
  EXPECT_EQ(aic::orderUnit("m/s", 1), "m/s^2");
  EXPECT_EQ(aic::orderUnit("rad/s", 2), "rad/s^3");
  EXPECT_EQ(aic::orderUnit("m/s^2", 1), "m/s^3");
  EXPECT_EQ(aic::orderUnit("m", 1), "m/s");
  EXPECT_EQ(aic::orderUnit("m", 2), "m/s^2");
  EXPECT_EQ(std::string(aic::kSensorChannelNames[base::kAccelX]), "accel_x");
  EXPECT_EQ(std::string(aic::kBeliefChannelUnits[2]), "rad/s");
}
