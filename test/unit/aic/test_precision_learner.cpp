/// Tests of PrecisionLearner: free-energy descent of the log sensory precisions ln Pi_y^(0) on the
/// prediction errors seen (doc/active_inference.md, 'Learning the sensory precisions'), its
/// parameters' validation and its hook in ActiveInferenceController.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/aic/precision_learner.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kH = 0.001;    // 1 kHz [s]
constexpr double kWheel = 5.0;  // a driving wheel speed [rad/s] (0.49 m/s)
constexpr std::uint8_t kAll = (1u << base::kYDim) - 1u;

/// The default settings.
params::PrecisionLearnerParams learnerParams()
{
  return params::PrecisionLearnerParams();
}

/// Configured precision 20 (var_y 0.05) on every channel; gyro and wheels learned.
aic::PrecisionChannels channels()
{
  aic::PrecisionChannels c;
  c.configured = { { 20.0, 20.0, 20.0, 20.0, 20.0 } };
  return c;
}

/// Feed `seconds` of zero-mean Gaussian errors with standard deviation sigma[j] per channel while
/// driving; returns the smallest and largest precision of channel j seen.
struct Range
{
  double lo = std::numeric_limits<double>::infinity();
  double hi = 0.0;
};

Range feed(aic::PrecisionLearner* l, const std::array<double, base::kYDim>& sigma, double seconds,
           int watch = base::kGyroZ, std::uint32_t seed = 7)
{
  std::mt19937 gen(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Range r;
  const int steps = static_cast<int>(std::lround(seconds / kH));
  for (int k = 0; k < steps; ++k)
  {
    base::Vector5 eps;
    for (int j = 0; j < base::kYDim; ++j)
    {
      eps(j) = sigma[static_cast<std::size_t>(j)] * n(gen);
    }
    EXPECT_EQ(l->update(kH, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kLearning);
    r.lo = std::min(r.lo, l->precision(watch));
    r.hi = std::max(r.hi, l->precision(watch));
  }
  return r;
}
}  // namespace

TEST(PrecisionLearner, StartsAtTheConfiguredPrecisions)
{
  aic::PrecisionLearner l(learnerParams(), channels());
  for (int j = 0; j < base::kYDim; ++j)
  {
    EXPECT_EQ(l.precision(j), 20.0);
    EXPECT_DOUBLE_EQ(l.meanSquaredError(j), 1.0 / 20.0);
  }
  EXPECT_TRUE(std::isnan(l.precision(base::kYDim)));
  EXPECT_TRUE(std::isnan(l.precision(-1)));
  EXPECT_EQ(l.state(), aic::PrecisionLearner::State::kNearRest);
  EXPECT_EQ(l.learningSteps(), 0u);
}

TEST(PrecisionLearner, ConvergesToTheInverseVarianceOfWhiteNoise)
{
  // sigma 0.1 on the gyro: Pi -> 1 / 0.01 = 100 (5 x configured, inside [2, 200]); sigma 0.3 on the
  // left wheel: 1 / 0.09 = 11.1 (below configured); the right wheel without error goes to the bound.
  aic::PrecisionLearner l(learnerParams(), channels());
  feed(&l, { { 0.1, 0.3, 0.0, 0.1, 0.1 } }, 60.0);  // 6 time constants 2 / kappa_pi = 10 s
  EXPECT_NEAR(l.precision(base::kGyroZ), 100.0, 5.0);
  EXPECT_NEAR(l.precision(base::kOmegaLeft), 1.0 / 0.09, 0.05 / 0.09);
  EXPECT_DOUBLE_EQ(l.precision(base::kOmegaRight), 10.0 * 20.0);
  EXPECT_EQ(l.precision(base::kAccelX), 20.0);  // not learned
  EXPECT_EQ(l.precision(base::kAccelY), 20.0);
  EXPECT_NEAR(l.meanSquaredError(base::kGyroZ), 0.01, 0.002);
  // Held there: the estimate's scatter over a further minute stays within 5 %.
  const Range r = feed(&l, { { 0.1, 0.3, 0.0, 0.1, 0.1 } }, 60.0, base::kGyroZ, 8);
  EXPECT_GT(r.lo, 95.0);
  EXPECT_LT(r.hi, 105.0);
  EXPECT_EQ(l.learningSteps(), 120000u);
}

TEST(PrecisionLearner, FollowsBothWaysAtTheStatedTimeConstant)
{
  // From the configured 20 to 1 / 0.01 = 100. Upwards ln Pi rises at most kappa_pi / 2 = 0.1 per
  // second (d ln Pi/dt = -kappa_pi (Pi s - 1) / 2 with s -> 0.01), near the optimum it relaxes with
  // 2 / kappa_pi = 10 s: after 10 s less than 1 / ln 5 = 62 % of the way in ln Pi, within 5 % after 60 s.
  aic::PrecisionLearner l(learnerParams(), channels());
  feed(&l, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 10.0);
  const double share = std::log(l.precision(base::kGyroZ) / 20.0) / std::log(100.0 / 20.0);
  EXPECT_GT(share, 0.35);
  EXPECT_LT(share, 0.62);
  feed(&l, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 50.0);
  EXPECT_NEAR(l.precision(base::kGyroZ), 100.0, 5.0);
  // Downwards it is faster (up to kappa_pi (kOutlierClip^2 - 1) / 2 per second): noise up tenfold
  // (sigma 1, Pi -> 1, below the bound 2) reaches the bound within 20 s.
  feed(&l, { { 1.0, 1.0, 1.0, 0.0, 0.0 } }, 20.0);
  EXPECT_NEAR(l.precision(base::kGyroZ), 2.0, 1e-9);
}

TEST(PrecisionLearner, StaysWithinItsBounds)
{
  params::PrecisionLearnerParams p = learnerParams();
  p.min_factor = 0.5;
  p.max_factor = 2.0;
  p.rate = 5.0;  // fast, to hit the bounds hard
  aic::PrecisionLearner l(p, channels());
  Range r = feed(&l, { { 100.0, 0.0, 100.0, 0.0, 0.0 } }, 20.0, base::kGyroZ);
  EXPECT_GE(r.lo, 10.0 * (1.0 - 1e-12));
  EXPECT_DOUBLE_EQ(l.precision(base::kGyroZ), 10.0);
  EXPECT_DOUBLE_EQ(l.precision(base::kOmegaLeft), 40.0);
  r = feed(&l, { { 0.0, 0.0, 0.0, 0.0, 0.0 } }, 20.0, base::kGyroZ);
  EXPECT_LE(r.hi, 40.0 * (1.0 + 1e-12));
  EXPECT_DOUBLE_EQ(l.precision(base::kGyroZ), 40.0);
}

TEST(PrecisionLearner, FrozenWhileMaskedNearRestOrSaturated)
{
  aic::PrecisionLearner l(learnerParams(), channels());
  feed(&l, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 5.0);
  const auto before = l.precisions();
  const double s_before = l.meanSquaredError(base::kGyroZ);
  const std::uint64_t steps = l.learningSteps();
  base::Vector5 big = base::Vector5::Constant(3.0);
  for (int k = 0; k < 5000; ++k)
  {
    // A learned channel masked (the left wheel; the accelerometers are not learned: no effect).
    EXPECT_EQ(l.update(kH, big, kWheel, kWheel, kAll & ~(1u << base::kOmegaLeft), false),
              aic::PrecisionLearner::State::kSensorFault);
    EXPECT_EQ(l.update(kH, big, kWheel, kWheel, kAll, true), aic::PrecisionLearner::State::kSaturated);
    EXPECT_EQ(l.update(kH, big, 0.4, -0.4, kAll, false), aic::PrecisionLearner::State::kNearRest);
    EXPECT_EQ(l.update(kH, big, 0.0, 0.0, kAll, false), aic::PrecisionLearner::State::kNearRest);
  }
  EXPECT_EQ(l.precisions(), before);
  EXPECT_EQ(l.meanSquaredError(base::kGyroZ), s_before);
  EXPECT_EQ(l.learningSteps(), steps);
  // An unlearned channel masked does not freeze; one wheel at speed is not rest (turning in place
  // with one side stalled still drives).
  EXPECT_EQ(l.update(kH, big, kWheel, kWheel, kAll & ~(1u << base::kAccelY), false),
            aic::PrecisionLearner::State::kLearning);
  EXPECT_EQ(l.update(kH, big, 0.0, -kWheel, kAll, false), aic::PrecisionLearner::State::kLearning);
}

TEST(PrecisionLearner, ASingleOutlierMovesItByAtMostTheStatedAmount)
{
  // Two learners fed the same noise; one sees one sample of a 1e6 error on every channel. The
  // stated bound on its total effect: |d ln Pi| <= kOutlierClip^2 kappa_pi h / 2 = 2.5e-3.
  aic::PrecisionLearner a(learnerParams(), channels());
  aic::PrecisionLearner b(learnerParams(), channels());
  feed(&a, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 20.0);
  feed(&b, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 20.0);
  ASSERT_EQ(a.precisions(), b.precisions());
  b.update(kH, base::Vector5::Constant(1.0e6), kWheel, kWheel, kAll, false);
  a.update(kH, base::Vector5::Zero(), kWheel, kWheel, kAll, false);
  const double bound = 0.5 * aic::PrecisionLearner::kOutlierClip * aic::PrecisionLearner::kOutlierClip * 0.2 * kH;
  double worst = 0.0;
  std::mt19937 gen(11);
  std::normal_distribution<double> n(0.0, 0.1);
  for (int k = 0; k < 20000; ++k)  // 20 low-pass time constants: the outlier's share has gone
  {
    base::Vector5 eps = base::Vector5::Zero();
    for (int j = 0; j < 3; ++j)
    {
      eps(j) = n(gen);
    }
    a.update(kH, eps, kWheel, kWheel, kAll, false);
    b.update(kH, eps, kWheel, kWheel, kAll, false);
    for (int j = 0; j < 3; ++j)
    {
      worst = std::max(worst, std::abs(std::log(b.precision(j) / a.precision(j))));
    }
  }
  EXPECT_GT(worst, 0.2 * bound);  // it did move it
  EXPECT_LE(worst, 1.1 * bound) << "bound " << bound;
}

TEST(PrecisionLearner, IgnoresBadInput)
{
  aic::PrecisionLearner l(learnerParams(), channels());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  base::Vector5 eps = base::Vector5::Constant(0.1);
  EXPECT_EQ(l.update(0.0, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kBadInput);
  EXPECT_EQ(l.update(-kH, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kBadInput);
  EXPECT_EQ(l.update(nan, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kBadInput);
  EXPECT_EQ(l.update(kH, eps, nan, kWheel, kAll, false), aic::PrecisionLearner::State::kBadInput);
  eps(base::kOmegaRight) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(l.update(kH, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kBadInput);
  EXPECT_EQ(l.precision(base::kOmegaRight), 20.0);
  eps(base::kOmegaRight) = 0.1;
  eps(base::kAccelY) = nan;  // not learned: not read
  EXPECT_EQ(l.update(kH, eps, kWheel, kWheel, kAll, false), aic::PrecisionLearner::State::kLearning);
  EXPECT_EQ(l.precision(base::kAccelY), 20.0);
}

TEST(PrecisionLearner, RejectsInvalidParamsNamingEachRule)
{
  params::PrecisionLearnerParams p = learnerParams();
  p.rate = -1.0;
  p.min_factor = 0.0;
  p.max_factor = 0.5;
  p.time_constant = 0.0;
  p.min_wheel_speed = std::numeric_limits<double>::quiet_NaN();
  aic::PrecisionChannels c = channels();
  c.configured[base::kAccelX] = 0.0;
  try
  {
    aic::PrecisionLearner l(p, c);
    FAIL() << "no exception";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string what = e.what();
    for (const char* key : { "precision_learning_rate", "precision_min_factor", "precision_max_factor",
                             "precision_time_constant", "precision_min_wheel_speed", "channel 3" })
    {
      EXPECT_NE(what.find(key), std::string::npos) << key << " missing from: " << what;
    }
  }
  aic::PrecisionLearner l(learnerParams(), channels());
  EXPECT_THROW(l.setParams(p, channels()), std::invalid_argument);
  EXPECT_EQ(l.params().rate, learnerParams().rate);
}

TEST(PrecisionLearner, SetParamsKeepsWhatWasLearnedUnlessTheConfigurationChanged)
{
  aic::PrecisionLearner l(learnerParams(), channels());
  feed(&l, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 30.0);
  const double learned = l.precision(base::kGyroZ);
  ASSERT_GT(learned, 60.0);
  params::PrecisionLearnerParams p = learnerParams();
  aic::PrecisionChannels c = channels();
  p.rate = 0.5;
  l.setParams(p, c);
  EXPECT_EQ(l.precision(base::kGyroZ), learned);
  p.max_factor = 2.0;  // the new bound clamps it
  l.setParams(p, c);
  EXPECT_DOUBLE_EQ(l.precision(base::kGyroZ), 40.0);
  c.configured[base::kGyroZ] = 10.0;  // another configuration: start again
  l.setParams(p, c);
  EXPECT_EQ(l.precision(base::kGyroZ), 10.0);
  EXPECT_EQ(l.learningSteps(), 0u);
}

TEST(PrecisionLearner, ApplyToWritesOrderZeroOfTheLearnedChannels)
{
  aic::PrecisionLearner l(learnerParams(), channels());
  base::YTilde pi_y = base::YTilde::Constant(base::kYDim, 3, 7.0);
  feed(&l, { { 0.1, 0.1, 0.1, 0.0, 0.0 } }, 1.0);
  EXPECT_TRUE(l.changedSince(aic::PrecisionLearner::kApplyTolerance));
  l.applyTo(&pi_y);
  EXPECT_FALSE(l.changedSince(aic::PrecisionLearner::kApplyTolerance));
  for (int j = 0; j < base::kYDim; ++j)
  {
    EXPECT_EQ(pi_y(j, 0), j < 3 ? l.precision(j) : 7.0) << j;
    EXPECT_EQ(pi_y(j, 1), 7.0);
    EXPECT_EQ(pi_y(j, 2), 7.0);
  }
}

TEST(PrecisionLearner, ParamsFromTheController)
{
  params::AicParams a = params::recommendedAicParams();
  a.precision_learner.rate = 0.3;
  a.precision_learner.min_factor = 0.2;
  a.precision_learner.max_factor = 5.0;
  a.precision_learner.time_constant = 2.0;
  a.precision_learner.min_wheel_speed = 1.0;
  const aic::PrecisionChannels c = aic::precisionChannels(a);
  EXPECT_EQ(c.configured[base::kGyroZ], 1.0 / a.var_y[0]);
  EXPECT_EQ(c.learned, (1u << base::kGyroZ) | (1u << base::kOmegaLeft) | (1u << base::kOmegaRight));
  // The controller's learner takes AicParams::precision_learner as it is.
  const aic::ActiveInferenceController ctl(a);
  const params::PrecisionLearnerParams& p = ctl.precisionLearner().params();
  EXPECT_EQ(p.rate, 0.3);
  EXPECT_EQ(p.min_factor, 0.2);
  EXPECT_EQ(p.max_factor, 5.0);
  EXPECT_EQ(p.time_constant, 2.0);
  EXPECT_EQ(p.min_wheel_speed, 1.0);
  EXPECT_EQ(ctl.precisionLearner().channels().configured, c.configured);
  a.accel_in_model = true;
  EXPECT_EQ(aic::precisionChannels(a).learned,
            (1u << base::kGyroZ) | (1u << base::kOmegaLeft) | (1u << base::kOmegaRight) | (1u << base::kAccelX));
}

TEST(PrecisionLearnerParams, ValidationNamesTheKey)
{
  // AicParams::validate() (the schema's ranges): an invalid value is a clear error naming the key,
  // and the controller refuses it.
  struct Case
  {
    double params::PrecisionLearnerParams::*member;
    const char* key;
    double bad;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Case& c : { Case{ &params::PrecisionLearnerParams::rate, "precision_learning_rate", -0.1 },
                         Case{ &params::PrecisionLearnerParams::rate, "precision_learning_rate", nan },
                         Case{ &params::PrecisionLearnerParams::min_factor, "precision_min_factor", 0.0 },
                         Case{ &params::PrecisionLearnerParams::min_factor, "precision_min_factor", 1.5 },
                         Case{ &params::PrecisionLearnerParams::max_factor, "precision_max_factor", 0.5 },
                         Case{ &params::PrecisionLearnerParams::max_factor, "precision_max_factor", 2.0e6 },
                         Case{ &params::PrecisionLearnerParams::time_constant, "precision_time_constant", 0.0 },
                         Case{ &params::PrecisionLearnerParams::time_constant, "precision_time_constant", -1.0 },
                         Case{ &params::PrecisionLearnerParams::min_wheel_speed, "precision_min_wheel_speed", -0.1 },
                         Case{ &params::PrecisionLearnerParams::min_wheel_speed, "precision_min_wheel_speed", nan } })
  {
    params::AicParams p = params::recommendedAicParams();
    p.precision_learner.enabled = true;
    p.precision_learner.*(c.member) = c.bad;
    const auto v = p.validate();
    ASSERT_EQ(v.size(), 1u) << c.key << " = " << c.bad;
    EXPECT_EQ(v[0].name, c.key);
    EXPECT_NE(v[0].toString().find("allowed"), std::string::npos) << v[0].toString();
    try
    {
      aic::ActiveInferenceController ctl(p);
      FAIL() << c.key << " = " << c.bad << " accepted";
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(c.key), std::string::npos) << e.what();
    }
  }
  params::AicParams edge = params::recommendedAicParams();
  edge.precision_learner.min_factor = 1.0;
  edge.precision_learner.max_factor = 1.0;
  edge.precision_learner.rate = 0.0;
  edge.precision_learner.min_wheel_speed = 0.0;
  EXPECT_TRUE(edge.validate().empty());
}

namespace
{
/// A noisy measurement of a base driving v [m/s] and turning w [rad/s] with the model's geometry.
base::YTilde noisyMeasurement(const aic::ActiveInferenceController& c, double v, double w, double sigma_gyro,
                              double sigma_wheel, std::mt19937* gen)
{
  std::normal_distribution<double> n(0.0, 1.0);
  const int orders = c.params().numOrders();
  base::YTilde y = base::YTilde::Zero(base::kYDim, orders);
  const double r = c.params().wheel_radius * c.params().slip_factor;
  const double b = c.model().wheelSeparation();
  y(base::kGyroZ, 0) = w + sigma_gyro * n(*gen);
  y(base::kOmegaLeft, 0) = (v - 0.5 * w * b) / r + sigma_wheel * n(*gen);
  y(base::kOmegaRight, 0) = (v + 0.5 * w * b) / r + sigma_wheel * n(*gen);
  return y;
}

/// Run a controller for `seconds` at 1 kHz beliefs, 50 Hz action, a new noisy sample every 10 ms.
void drive(aic::ActiveInferenceController* c, double seconds, std::uint32_t seed = 3)
{
  std::mt19937 gen(seed);
  c->setGoal(base::Vector3(0.5, 0.0, 0.2));
  const int steps = static_cast<int>(std::lround(seconds / kH));
  for (int k = 0; k < steps; ++k)
  {
    if (k % 10 == 0)
    {
      ASSERT_TRUE(c->setMeasurement(noisyMeasurement(*c, 0.5, 0.2, 0.05, 0.1, &gen)));
    }
    c->updateBeliefs(kH);
    if (k % 20 == 0)
    {
      c->updateAction(0.02);
    }
  }
}
}  // namespace

TEST(ControllerPrecisionLearning, OffLeavesTheControllerUnchanged)
{
  // learning off: the precision_* settings change nothing, bit for bit.
  params::AicParams p = params::recommendedAicParams();
  aic::ActiveInferenceController a(p);
  p.precision_learner.rate = 5.0;
  p.precision_learner.min_factor = 0.9;
  p.precision_learner.max_factor = 1.1;
  p.precision_learner.time_constant = 0.01;
  aic::ActiveInferenceController b(p);
  drive(&a, 5.0);
  drive(&b, 5.0);
  EXPECT_EQ(a.mu(), b.mu());
  EXPECT_EQ(a.action(), b.action());
  EXPECT_EQ(a.precisionY(), params::recommendedAicParams().precisionY());
  EXPECT_EQ(a.precisionLearner().learningSteps(), 0u);
}

TEST(ControllerPrecisionLearning, TheLearnedPrecisionsReplaceTheConfiguredOnes)
{
  params::AicParams p = params::recommendedAicParams();
  p.precision_learner.enabled = true;
  aic::ActiveInferenceController c(p);
  drive(&c, 30.0);
  const aic::PrecisionLearner& l = c.precisionLearner();
  EXPECT_GT(l.learningSteps(), 25000u);
  const base::YTilde configured = p.precisionY();
  for (int j = 0; j < base::kYDim; ++j)
  {
    const bool learned = j == base::kGyroZ || j == base::kOmegaLeft || j == base::kOmegaRight;
    if (learned)
    {
      EXPECT_NE(l.precision(j), configured(j, 0)) << j;
      EXPECT_NEAR(c.precisionY()(j, 0), l.precision(j), aic::PrecisionLearner::kApplyTolerance * l.precision(j)) << j;
      EXPECT_GE(l.precision(j), p.precision_learner.min_factor * configured(j, 0)) << j;
      EXPECT_LE(l.precision(j), p.precision_learner.max_factor * configured(j, 0)) << j;
    }
    else
    {
      EXPECT_EQ(c.precisionY()(j, 0), configured(j, 0)) << j;
    }
    for (int i = 1; i < p.numOrders(); ++i)
    {
      EXPECT_EQ(c.precisionY()(j, i), configured(j, i)) << j << ", order " << i;
    }
  }
  // A masked channel's row is zero, its learned value kept for when it comes back; learning frozen.
  const double wheel = l.precision(base::kOmegaLeft);
  c.setSensorMask(kAll & ~(1u << base::kOmegaLeft));
  EXPECT_EQ(c.precisionY()(base::kOmegaLeft, 0), 0.0);
  drive(&c, 1.0);
  EXPECT_EQ(l.state(), aic::PrecisionLearner::State::kSensorFault);
  EXPECT_EQ(l.precision(base::kOmegaLeft), wheel);
  c.setSensorMask(kAll);
  EXPECT_NEAR(c.precisionY()(base::kOmegaLeft, 0), wheel, 1e-12);
}
