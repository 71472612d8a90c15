/**
 * \file test_gyro_bias_estimator.cpp
 * \brief GyroBiasEstimator: the gyro's offset learned at standstill, frozen while moving, settling,
 *        with a flagged gyro and on implausible readings; bounded; bad input and bad settings refused
 *        (include/jackal_aic/aic/gyro_bias_estimator.hpp).
 */
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "jackal_aic/aic/gyro_bias_estimator.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/loop/sample_pipeline.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kH = 0.02;  // the robot's 50 Hz sensor rate [s]
using State = aic::GyroBiasEstimator::State;

/// Feed `seconds` of rest samples (wheels and commands 0) reading bias + N(0, sigma).
State rest(aic::GyroBiasEstimator* e, double seconds, double bias, double sigma, std::mt19937* rng, bool gyro_ok = true)
{
  std::normal_distribution<double> noise(0.0, sigma);
  State s = State::kMoving;
  for (int i = 0; i < static_cast<int>(std::lround(seconds / kH)); ++i)
  {
    s = e->update(kH, bias + noise(*rng), 0.0, 0.0, 0.0, 0.0, gyro_ok);
  }
  return s;
}
}  // namespace

TEST(GyroBiasEstimator, AveragesTheFirstRestToTheOffset)
{
  params::GyroBiasEstimatorParams p;
  p.rest_time = 0.25;
  p.min_rest = 2.0;
  aic::GyroBiasEstimator e{ p };
  std::mt19937 rng(7);
  EXPECT_EQ(rest(&e, 1.0, 0.03, 0.005, &rng), State::kLearning);
  // About 0.75 s of learning at 50 Hz: 38 samples against a prior of 5 at 0 -> 88 % of the offset.
  const double n = static_cast<double>(e.learningSamples());
  EXPECT_NEAR(n, 38.0, 1.0);
  EXPECT_NEAR(e.bias(), 0.03 * n / (n + aic::GyroBiasEstimator::kPriorSamples), 0.002);
  EXPECT_EQ(e.offset(), 0.0) << "0.75 s of rest is less than min_rest: nothing removed yet";
  rest(&e, 4.0, 0.03, 0.005, &rng);
  EXPECT_NEAR(e.bias(), 0.03, 0.002);
  EXPECT_EQ(e.learningSamples(), static_cast<std::uint64_t>(n) + 200u);
  EXPECT_NEAR(e.learnedTime(), static_cast<double>(e.learningSamples()) * kH, 1e-9);
  EXPECT_EQ(e.offset(), e.bias());
}

TEST(GyroBiasEstimator, WaitsForTheRestTimeAfterEachStop)
{
  params::GyroBiasEstimatorParams p;
  p.rest_time = 0.25;
  aic::GyroBiasEstimator e{ p };
  std::mt19937 rng(1);
  EXPECT_EQ(rest(&e, 0.2, 0.05, 0.0, &rng), State::kSettling);
  EXPECT_EQ(e.bias(), 0.0);
  EXPECT_EQ(rest(&e, 0.1, 0.05, 0.0, &rng), State::kLearning);
  const double learned = e.bias();
  EXPECT_GT(learned, 0.0);
  // Driving: a wheel or a command above rest_speed freezes it and restarts the rest timer.
  EXPECT_EQ(e.update(kH, 0.4, 5.0, 6.0, 5.0, 6.0, true), State::kMoving);
  EXPECT_EQ(e.update(kH, 0.0, 0.0, 0.0, 0.0, 0.06, true), State::kMoving);
  EXPECT_EQ(e.update(kH, 0.0, 0.0, 0.06, 0.0, 0.0, true), State::kMoving);
  EXPECT_EQ(e.bias(), learned);
  EXPECT_EQ(rest(&e, 0.2, 0.5, 0.0, &rng), State::kSettling);  // the body still yawing as it stops
  EXPECT_EQ(e.bias(), learned);
}

TEST(GyroBiasEstimator, FrozenWithAFlaggedGyroAndOnImplausibleReadings)
{
  aic::GyroBiasEstimator e{ params::GyroBiasEstimatorParams{} };
  std::mt19937 rng(3);
  EXPECT_EQ(rest(&e, 2.0, 0.05, 0.0, &rng, false), State::kSensorFault);
  EXPECT_EQ(e.bias(), 0.0);
  // Turned by hand at rest, or a fault: 0.3 rad/s is no offset (gyro_bias_max 0.1).
  EXPECT_EQ(rest(&e, 2.0, 0.3, 0.0, &rng), State::kImplausible);
  EXPECT_EQ(e.bias(), 0.0);
  EXPECT_EQ(e.learningSamples(), 0u);
}

TEST(GyroBiasEstimator, BoundedByMaxBias)
{
  params::GyroBiasEstimatorParams p;
  p.max_bias = 0.02;
  p.rest_time = 0.0;
  aic::GyroBiasEstimator e{ p };
  EXPECT_EQ(e.update(kH, 0.019, 0.0, 0.0, 0.0, 0.0, true), State::kLearning);
  for (int i = 0; i < 100; ++i)
  {
    e.update(kH, i % 2 ? 0.02 : -0.02, 0.0, 0.0, 0.0, 0.0, true);  // within the bound, mean 0
  }
  EXPECT_LE(std::abs(e.bias()), 0.02);
  p.max_bias = 0.001;
  e.setParams(p);
  EXPECT_LE(std::abs(e.bias()), 0.001);  // a tighter bound clamps what was learned
}

TEST(GyroBiasEstimator, FollowsADriftWithItsTimeConstant)
{
  params::GyroBiasEstimatorParams p;
  p.time_constant = 2.0;
  aic::GyroBiasEstimator e{ p };
  std::mt19937 rng(5);
  rest(&e, 200.0, 0.0, 0.0, &rng);  // long averaged: the gain is h / T_beta now
  rest(&e, 2.0 + p.rest_time, 0.04, 0.0, &rng);
  // One time constant of a 0.04 rad/s step: 1 - e^-1 of it (the rest timer is kept while at rest).
  EXPECT_NEAR(e.bias(), 0.04 * (1.0 - std::exp(-1.0 - p.rest_time / 2.0)), 0.002);
}

TEST(GyroBiasEstimator, BadInputIsIgnored)
{
  aic::GyroBiasEstimator e{ params::GyroBiasEstimatorParams{} };
  std::mt19937 rng(2);
  rest(&e, 1.0, 0.02, 0.0, &rng);
  const double learned = e.bias();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(e.update(kH, nan, 0.0, 0.0, 0.0, 0.0, true), State::kBadInput);
  EXPECT_EQ(e.update(kH, 0.0, inf, 0.0, 0.0, 0.0, true), State::kBadInput);
  EXPECT_EQ(e.update(kH, 0.0, 0.0, 0.0, nan, 0.0, true), State::kBadInput);
  EXPECT_EQ(e.update(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, true), State::kBadInput);
  EXPECT_EQ(e.update(-kH, 0.0, 0.0, 0.0, 0.0, 0.0, true), State::kBadInput);
  EXPECT_EQ(e.bias(), learned);
  e.reset();
  EXPECT_EQ(e.bias(), 0.0);
  EXPECT_EQ(e.learningSamples(), 0u);
  EXPECT_STREQ(aic::toString(e.state()), "moving");
}

TEST(GyroBiasEstimator, StatusTextSaysUntilWhenTheOffsetIsNotRemoved)
{
  params::GyroBiasEstimatorParams p;
  p.rest_time = 0.0;
  p.min_rest = 1.0;
  aic::GyroBiasEstimator e{ p };
  std::mt19937 rng(4);
  rest(&e, 0.5, 0.01, 0.0, &rng);
  EXPECT_EQ(aic::statusText(e), "learning; not removed yet (0.5 of 1.0 s of rest learned)");
  rest(&e, 0.6, 0.01, 0.0, &rng);
  EXPECT_EQ(aic::statusText(e), "learning");
  EXPECT_EQ(e.update(kH, 0.2, 4.0, 4.0, 4.0, 4.0, true), State::kMoving);
  EXPECT_EQ(aic::statusText(e), "moving");
}

TEST(GyroBiasEstimator, InvalidSettingsNameEveryRule)
{
  params::GyroBiasEstimatorParams p;
  p.max_bias = 0.0;
  p.rest_speed = std::numeric_limits<double>::quiet_NaN();
  p.rest_time = -1.0;
  p.time_constant = 0.0;
  try
  {
    aic::GyroBiasEstimator e{ p };
    FAIL() << "accepted invalid settings";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string what = e.what();
    for (const char* key :
         { "gyro_bias_max", "gyro_bias_rest_speed", "gyro_bias_rest_time", "gyro_bias_time_constant" })
    {
      EXPECT_NE(what.find(key), std::string::npos) << what;
    }
  }
  aic::GyroBiasEstimator ok{ params::GyroBiasEstimatorParams{} };
  EXPECT_THROW(ok.setParams(p), std::invalid_argument);
  EXPECT_EQ(ok.params().max_bias, params::GyroBiasEstimatorParams{}.max_bias);
}

/// The pipeline subtracts beta_hat from the gyro before the controller and the fault monitor see it.
TEST(GyroBiasEstimator, ThePipelineRemovesTheOffsetBeforeTheController)
{
  params::AicParams aic = params::recommendedAicParams();
  params::FdiParams fdi;
  loop::SamplePipeline pipe(aic, fdi);
  base::Vector5 y = base::Vector5::Zero();
  bool first = true;
  auto sample = [&](double gyro) {
    y << gyro, 0.0, 0.0, 0.0, 0.0;
    base::Vector5 in = y;
    pipe.generalize(&in, kH, true, false);
    if (first)
    {
      pipe.activate(base::Vector2::Zero(), base::Vector3::Zero());
      first = false;
    }
    pipe.measure(in, kH, true);
    return in(base::kGyroZ);
  };
  for (int i = 0; i < 250; ++i)
  {
    sample(0.04);
  }
  EXPECT_NEAR(pipe.gyroBias().bias(), 0.04, 0.002);
  EXPECT_NEAR(sample(0.04), 0.04, 1e-12) << "4.5 s of rest learned: less than gyro_bias_min_rest (5 s)";
  for (int i = 0; i < 30; ++i)
  {
    sample(0.04);
  }
  EXPECT_NEAR(sample(0.04), 0.0, 0.002);  // what the controller and the monitor get
  EXPECT_NEAR(pipe.controller().yTilde()(base::kGyroZ, 0), 0.0, 0.002);
  pipe.resetGyroBias();
  EXPECT_EQ(pipe.gyroBias().bias(), 0.0);
  // Off: the gyro passes as it reads, and what was learned is forgotten.
  for (int i = 0; i < 250; ++i)
  {
    sample(0.04);
  }
  aic.gyro_bias.enabled = false;
  pipe.setParams(aic, fdi);
  EXPECT_EQ(pipe.gyroBias().bias(), 0.0);
  EXPECT_NEAR(sample(0.04), 0.04, 1e-12);
}

}  // namespace jackal_aic
