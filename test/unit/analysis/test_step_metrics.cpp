/// Tests of computeStepMetrics against closed-form responses sampled with uneven stamps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "jackal_aic/analysis/step_metrics.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kTimeTol = 2e-3;    // s: interpolation on ~1 ms jittered stamps
constexpr double kPercentTol = 0.2;  // % of step
constexpr double kValueTol = 1e-3;   // signal units

/// Jittered stamps from t0 to t1, mean period dt.
std::vector<double> jitteredTimes(double t0, double t1, double dt, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.3, 1.7);
  std::vector<double> t;
  for (double x = t0; x <= t1; x += dt * u(rng))
  {
    t.push_back(x);
  }
  return t;
}
}  // namespace

TEST(StepMetrics, FirstOrderResponse)
{
  constexpr double kT = 0.2;     // s, time constant
  constexpr double kStep = 1.0;  // s
  constexpr double kY0 = 0.1;
  constexpr double kY1 = 0.5;
  const auto t = jitteredTimes(0.0, 4.0, 0.001, 1);
  std::vector<double> v;
  for (double x : t)
  {
    v.push_back(x < kStep ? kY0 : kY1 + (kY0 - kY1) * std::exp(-(x - kStep) / kT));
  }
  analysis::StepMetricsOptions o;
  o.step_time = kStep;
  o.initial = kY0;
  o.target = kY1;
  const auto m = analysis::computeStepMetrics(t, v, o);
  EXPECT_NEAR(m.rise_time, kT * std::log(9.0), kTimeTol);
  EXPECT_NEAR(m.t_rise_low, -kT * std::log(0.9), kTimeTol);
  // Band = 5 % of the final value 0.5 = 0.025 = 6.25 % of the step 0.4: e^{-t/T} * 0.4 = 0.025.
  EXPECT_NEAR(m.band, 0.025, 1e-12);
  EXPECT_NEAR(m.settling_time, kT * std::log(0.4 / 0.025), kTimeTol);
  EXPECT_TRUE(m.settled);
  EXPECT_NEAR(m.overshoot_percent, 0.0, 1e-12);
  EXPECT_NEAR(m.steady_state_error, 0.0, kValueTol);
  EXPECT_NEAR(m.steady_state_window_used, 0.5, 2e-3);
  // IAE of a first-order rise over 3 s = 15 T: step * T (1 - e^-15), less the error before the
  // first sample (the first stamp is within 1.7 ms of the step: at most 0.4 * 1.7e-3).
  EXPECT_NEAR(m.iae, 0.4 * kT, 0.4 * 1.7e-3);

  o.band_basis = analysis::SettlingBandBasis::kStepSize;
  const auto ms = analysis::computeStepMetrics(t, v, o);
  EXPECT_NEAR(ms.settling_time, kT * std::log(20.0), kTimeTol);
}

TEST(StepMetrics, IaeIntegratesTheAbsoluteErrorAcrossItsSignChanges)
{
  // Error 1 at t = 0, -1 at t = 1 (a crossing at 0.5: two triangles of 0.25), 0 from t = 2.
  analysis::StepMetricsOptions o;
  o.target = 1.0;
  const auto m = analysis::computeStepMetrics({ 0.0, 1.0, 2.0, 3.0 }, { 0.0, 2.0, 1.0, 1.0 }, o);
  EXPECT_NEAR(m.iae, 0.25 + 0.25 + 0.5, 1e-12);
  // A response lingering at the band's edge: the settling time jumps by the lingering's length,
  // the IAE by its area only.
  const std::vector<double> t{ 0.0, 0.1, 0.2, 0.3, 0.4, 0.5 };
  const auto inside = analysis::computeStepMetrics(t, { 0.0, 0.9, 0.951, 0.951, 0.951, 1.0 }, o);
  const auto edge = analysis::computeStepMetrics(t, { 0.0, 0.9, 0.949, 0.949, 0.949, 1.0 }, o);
  EXPECT_GT(edge.settling_time - inside.settling_time, 0.2);
  EXPECT_NEAR(edge.iae - inside.iae, 0.002 * 0.3, 1e-9);
}

TEST(StepMetrics, SecondOrderOvershootAndDownStep)
{
  constexpr double kZeta = 0.3;
  constexpr double kWn = 10.0;  // rad/s
  const double wd = kWn * std::sqrt(1 - kZeta * kZeta);
  const auto t = jitteredTimes(0.0, 3.0, 0.0005, 2);
  std::vector<double> v;
  // Down-step 1.0 -> 0.2 at t = 0: the metrics are direction-agnostic.
  for (double x : t)
  {
    const double s =
        1 - std::exp(-kZeta * kWn * x) * (std::cos(wd * x) + kZeta / std::sqrt(1 - kZeta * kZeta) * std::sin(wd * x));
    v.push_back(1.0 - 0.8 * s);
  }
  analysis::StepMetricsOptions o;
  o.initial = 1.0;
  o.target = 0.2;
  const auto m = analysis::computeStepMetrics(t, v, o);
  const double expected_os = 100.0 * std::exp(-kZeta * M_PI / std::sqrt(1 - kZeta * kZeta));
  EXPECT_NEAR(m.overshoot_percent, expected_os, kPercentTol);
  EXPECT_GT(m.rise_time, 0.0);
  EXPECT_LT(m.rise_time, 0.2);
  EXPECT_TRUE(m.settled);
}

TEST(StepMetrics, SteadyStateErrorAndNotSettled)
{
  const auto t = jitteredTimes(0.0, 2.0, 0.01, 3);
  std::vector<double> v(t.size(), 0.45);  // jumps to 0.45 and stays: 0.05 short of 0.5
  analysis::StepMetricsOptions o;
  o.initial = 0.0;
  o.target = 0.5;
  o.settling_band = 0.05;  // band 0.025 < 0.05: never inside
  auto m = analysis::computeStepMetrics(t, v, o);
  EXPECT_NEAR(m.steady_state_error, 0.05, 1e-12);
  EXPECT_FALSE(m.settled);
  EXPECT_TRUE(std::isnan(m.settling_time));
  EXPECT_NEAR(m.rise_time, 0.0, 1e-12);  // both thresholds crossed at the first sample
  // Response that never reaches 90 %: rise time undefined.
  std::fill(v.begin(), v.end(), 0.3);
  m = analysis::computeStepMetrics(t, v, o);
  EXPECT_TRUE(std::isnan(m.rise_time));
  EXPECT_EQ(analysis::toJson(m, o).find("\"rise_time\": null"), 1u);
}

TEST(StepMetrics, EndTimeLimitsTheWindow)
{
  // Square wave: 0 -> 1 at t = 0, 1 -> 0 at t = 1. Analysing [0, 1] sees only the first half.
  const auto t = jitteredTimes(0.0, 2.0, 0.001, 4);
  std::vector<double> v;
  for (double x : t)
  {
    v.push_back(x < 1.0 ? 1.0 - std::exp(-x / 0.05) : std::exp(-(x - 1.0) / 0.05));
  }
  analysis::StepMetricsOptions o;
  o.initial = 0.0;
  o.target = 1.0;
  o.end_time = 1.0;
  const auto m = analysis::computeStepMetrics(t, v, o);
  EXPECT_TRUE(m.settled);
  EXPECT_NEAR(m.settling_time, 0.05 * std::log(20.0), kTimeTol);
  EXPECT_NEAR(m.steady_state_error, 0.0, kValueTol);
}

TEST(StepMetrics, BadInputThrows)
{
  const std::vector<double> t{ 0.0, 0.1, 0.2 };
  const std::vector<double> v{ 0.0, 0.5, 1.0 };
  analysis::StepMetricsOptions o;
  o.target = 1.0;
  EXPECT_NO_THROW(analysis::computeStepMetrics(t, v, o));
  EXPECT_THROW(analysis::computeStepMetrics(t, { 0.0, 1.0 }, o), std::invalid_argument);                // size
  EXPECT_THROW(analysis::computeStepMetrics({ 0.0, 0.2, 0.1 }, v, o), std::invalid_argument);           // backwards
  EXPECT_THROW(analysis::computeStepMetrics({ 0.0, 0.1, 0.1 }, v, o), std::invalid_argument);           // repeated
  EXPECT_THROW(analysis::computeStepMetrics(t, { 0.0, std::nan(""), 1.0 }, o), std::invalid_argument);  // NaN value
  EXPECT_THROW(analysis::computeStepMetrics({ 0.0, INFINITY, 0.3 }, v, o), std::invalid_argument);      // Inf stamp
  auto bad = o;
  bad.target = bad.initial;
  EXPECT_THROW(analysis::computeStepMetrics(t, v, bad), std::invalid_argument);  // zero step
  bad = o;
  bad.step_time = 0.15;  // one sample left
  EXPECT_THROW(analysis::computeStepMetrics(t, v, bad), std::invalid_argument);
  bad = o;
  bad.rise_low = 0.95;
  EXPECT_THROW(analysis::computeStepMetrics(t, v, bad), std::invalid_argument);
  bad = o;
  bad.settling_band = 0.0;
  EXPECT_THROW(analysis::computeStepMetrics(t, v, bad), std::invalid_argument);
  bad = o;
  bad.steady_state_window = -1.0;
  EXPECT_THROW(analysis::computeStepMetrics(t, v, bad), std::invalid_argument);
  try
  {
    analysis::computeStepMetrics({ 0.0, 0.2, 0.1 }, v, o);
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("not strictly increasing at sample 2"), std::string::npos) << e.what();
  }
}
