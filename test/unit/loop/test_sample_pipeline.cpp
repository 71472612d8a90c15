/**
 * \file test_sample_pipeline.cpp
 * \brief gtest (no roscore) of SamplePipeline, the node's ROS-free sample path: parameter
 *        checks, degraded-mode fill, history restarts, refused samples, the bumpless start,
 *        fault isolation through the controller's channel mask, and parameter changes.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "jackal_aic/loop/sample_pipeline.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kTol = 1e-12;      // exact arithmetic of a few terms
constexpr double kH = 0.02;         // s, the Jackal's 50 Hz sensor interval
constexpr double kBeliefH = 0.001;  // s, 1 kHz belief steps

/// config/default.yaml's controller.
params::AicParams aicParams()
{
  return params::recommendedAicParams();
}

/// Wheels at omega [rad/s] both sides, gyro consistent (0), accelerometers 0.
base::Vector5 straight(double omega)
{
  base::Vector5 y = base::Vector5::Zero();
  y(base::kOmegaLeft) = omega;
  y(base::kOmegaRight) = omega;
  return y;
}

/// The sum of the gyro, wheel and accelerometer bits of a full mask.
constexpr std::uint8_t kAllChannels = 0x1F;
}  // namespace

TEST(SamplePipeline, RefusesInvalidParametersNamingEveryViolation)
{
  params::AicParams bad = aicParams();
  bad.tau = -1.0;
  bad.k_a = std::numeric_limits<double>::quiet_NaN();
  params::FdiParams fdi;
  fdi.threshold = 0.0;
  try
  {
    loop::SamplePipeline pipeline(bad, fdi);
    FAIL() << "invalid parameters accepted";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("tau"), std::string::npos) << what;
    EXPECT_NE(what.find("k_a"), std::string::npos) << what;
    EXPECT_NE(what.find("threshold"), std::string::npos) << what;
  }
}

TEST(SamplePipeline, FirstSampleStartsTheHistoryThenContinues)
{
  loop::SamplePipeline pipeline(aicParams(), params::FdiParams());
  base::Vector5 y = straight(1.0);
  bool restarted = false;
  EXPECT_EQ(pipeline.generalize(&y, kH, true, false, &restarted), aic::Generalizer::Status::kFirstSample);
  EXPECT_TRUE(restarted);  // an uninitialized generalizer restarts even when not asked
  y = straight(1.2);
  EXPECT_EQ(pipeline.generalize(&y, kH, true, false, &restarted), aic::Generalizer::Status::kOk);
  EXPECT_FALSE(restarted);
  EXPECT_NEAR(pipeline.generalizer().yTilde()(base::kOmegaLeft, 1), 0.2 / kH, 1e-9);  // first difference
  y = straight(1.2);
  EXPECT_EQ(pipeline.generalize(&y, kH, true, true, &restarted), aic::Generalizer::Status::kFirstSample);
  EXPECT_TRUE(restarted);
  EXPECT_EQ(pipeline.generalizer().yTilde()(base::kOmegaLeft, 1), 0.0);  // higher orders restart at zero
}

TEST(SamplePipeline, RefusedSampleLeavesTheHistory)
{
  loop::SamplePipeline pipeline(aicParams(), params::FdiParams());
  base::Vector5 y = straight(1.0);
  ASSERT_EQ(pipeline.generalize(&y, kH, true, false), aic::Generalizer::Status::kFirstSample);
  const auto before = pipeline.generalizer().yTilde();
  for (double h : { 0.0, -kH, std::numeric_limits<double>::quiet_NaN() })
  {
    base::Vector5 next = straight(3.0);
    const aic::Generalizer::Status status = pipeline.generalize(&next, h, true, false);
    EXPECT_NE(status, aic::Generalizer::Status::kOk) << "h = " << h;
    EXPECT_NE(status, aic::Generalizer::Status::kFirstSample) << "h = " << h;
    EXPECT_TRUE(pipeline.generalizer().yTilde() == before) << "h = " << h;
  }
}

TEST(SamplePipeline, WithoutTheImuTheGyroSlotCarriesTheWheelsYawRate)
{
  const params::AicParams p = aicParams();
  loop::SamplePipeline pipeline(p, params::FdiParams());
  base::Vector5 y = straight(2.0);
  y(base::kOmegaRight) = 4.0;
  y(base::kGyroZ) = 123.0;  // whatever a missing IMU left there
  pipeline.generalize(&y, kH, false, false);
  const double yaw = p.wheel_radius * p.slip_factor * (4.0 - 2.0) / p.wheel_separation;  // (r alpha / b_hat)(w_R - w_L)
  EXPECT_NEAR(y(base::kGyroZ), yaw, kTol);
  EXPECT_NEAR(pipeline.generalizer().yTilde()(base::kGyroZ, 0), yaw, kTol);
  // With the IMU the sample is left as it is.
  base::Vector5 z = straight(2.0);
  z(base::kGyroZ) = 0.5;
  pipeline.generalize(&z, kH, true, false);
  EXPECT_EQ(z(base::kGyroZ), 0.5);
}

TEST(SamplePipeline, ActivateStartsBumplessFromTheMeasuredWheels)
{
  const params::AicParams p = aicParams();
  loop::SamplePipeline pipeline(p, params::FdiParams());
  base::Vector5 y = straight(3.0);
  pipeline.generalize(&y, kH, true, false);
  pipeline.activate(base::Vector2(3.0, 3.0), base::Vector3(0.5, 0.0, 0.0));
  const aic::ActiveInferenceController& c = pipeline.controller();
  EXPECT_TRUE(c.hasMeasurement());
  EXPECT_NEAR(c.action()(0), 3.0, kTol);
  EXPECT_NEAR(c.action()(1), 3.0, kTol);
  EXPECT_NEAR(c.mu()(0, 0), p.wheel_radius * p.slip_factor * 3.0, kTol);  // mu^(0) = G omega
  EXPECT_EQ(c.mu()(2, 0), 0.0);
  EXPECT_EQ(c.mu().rightCols(p.numOrders() - 1).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(c.goal()(0), 0.5, kTol);
}

TEST(SamplePipeline, MeasureIsolatesABiasedGyroThroughTheMask)
{
  loop::SamplePipeline pipeline(aicParams(), params::FdiParams());  // isolation on, 0.2 s detection time
  const double omega = 5.0;                                         // rad/s, straight run at ~0.49 m/s
  base::Vector5 y = straight(omega);
  pipeline.generalize(&y, kH, true, false);
  pipeline.activate(base::Vector2(omega, omega), base::Vector3(0.49, 0.0, 0.0));
  bool isolated = false;
  for (int k = 0; k < 100 && !isolated; ++k)  // 2 s of samples
  {
    for (int i = 0; i < 20; ++i)
    {
      pipeline.controller().updateBeliefs(kBeliefH);
    }
    y = straight(omega);
    y(base::kGyroZ) = 1.0;  // a 1 rad/s bias on a gyro that should read 0
    ASSERT_EQ(pipeline.generalize(&y, kH, true, false), aic::Generalizer::Status::kOk);
    const loop::SamplePipeline::Measurement m = pipeline.measure(y, kH, true);
    ASSERT_TRUE(m.accepted);
    if (m.event == safety::FaultMonitor::Event::kIsolated)
    {
      EXPECT_EQ(m.event_channel, base::kGyroZ);
      isolated = true;
    }
  }
  ASSERT_TRUE(isolated) << "a 1 rad/s gyro bias was never isolated";
  EXPECT_EQ(pipeline.faultMonitor().isolatedChannel(), base::kGyroZ);
  EXPECT_EQ(pipeline.faultMonitor().sensorMask(), kAllChannels & ~(1u << base::kGyroZ));
  // After a restart of the history (sensors lost) the isolation is forgotten.
  pipeline.restartHistory();
  EXPECT_EQ(pipeline.faultMonitor().isolatedChannel(), -1);
  EXPECT_FALSE(pipeline.generalizer().initialized());
}

TEST(SamplePipeline, SetParamsRebuildsTheGeneralizerOnlyForANewOrder)
{
  params::AicParams p = aicParams();
  loop::SamplePipeline pipeline(p, params::FdiParams());
  base::Vector5 y = straight(1.0);
  pipeline.generalize(&y, kH, true, false);
  p.k_a = 5.0;
  EXPECT_FALSE(pipeline.setParams(p, params::FdiParams()));
  EXPECT_TRUE(pipeline.generalizer().initialized());
  EXPECT_EQ(pipeline.controller().params().k_a, 5.0);
  p.embedding_order = p.embedding_order == 3 ? 2 : 3;
  p.var_mu.assign(p.embedding_order + 1, 4.0);
  p.var_y.assign(p.embedding_order + 1, 2.0);
  EXPECT_TRUE(pipeline.setParams(p, params::FdiParams()));
  EXPECT_EQ(pipeline.generalizer().embeddingOrder(), p.embedding_order);
  EXPECT_FALSE(pipeline.generalizer().initialized());
  // An invalid set changes nothing.
  params::AicParams bad = p;
  bad.k_mu = -1.0;
  EXPECT_THROW(pipeline.setParams(bad, params::FdiParams()), std::invalid_argument);
  EXPECT_EQ(pipeline.controller().params().k_mu, p.k_mu);
  params::FdiParams bad_fdi;
  bad_fdi.release_ratio = 2.0;
  params::AicParams q = p;
  q.k_a = 7.0;
  EXPECT_THROW(pipeline.setParams(q, bad_fdi), std::invalid_argument);
  EXPECT_EQ(pipeline.controller().params().k_a, 5.0);  // not half-applied
}
}  // namespace jackal_aic
