/// Tests of FaultMonitor and ActiveInferenceController::setSensorMask (fault detection and isolation,
/// Baioumy et al. ECC 2021, arXiv 2104.01817; doc/active_inference.md, 'Fault detection and isolation').
/// The closed-loop cases run the controller on a first-order wheel-speed plant with a fault injected
/// into one sensor channel (no ROS, no timing: simulated time only).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"
#include "jackal_aic/aic/generalizer.hpp"

using namespace jackal_aic;
using Event = safety::FaultMonitor::Event;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSamplePeriod = 0.02;      // s, sensor and action period (50 Hz)
constexpr double kBeliefPeriod = 0.001;     // s (1 kHz)
constexpr double kWheelTimeConstant = 0.1;  // s, first-order wheel loop of the test plant
constexpr double kSpeedErrorTol = 0.05;     // relative: speed error <= 5 %
constexpr double kIsolationDeadline = 0.5;  // s: isolated within 0.5 s

/// config/default.yaml's controller (the schema's defaults).
/// The recommended controller with b_hat fixed: runClosedLoop()'s plant turns by the controller's own
/// model (G_3 omega), which must not move with what the controller learns. Learning under faults is
/// checked on the simulated Jackal (test/sim/test_closed_loop_acceptance.cpp).
params::AicParams defaultParams()
{
  params::AicParams p = params::recommendedAicParams();
  p.separation_learner.enabled = false;
  return p;
}

/// A fault applied to one channel of the sensor sample from a given time on.
struct Fault
{
  enum Kind
  {
    kNone,
    kBias,   ///< y_j += value
    kFreeze  ///< y_j held at its value at `start`
  } kind = kNone;
  int channel = base::kOmegaLeft;
  double value = 0.0;
  double start = 0.0;  ///< [s]
  double end = 1e9;    ///< [s]
};

/// Result of a closed-loop run.
struct LoopRun
{
  double isolated_at = kNaN;  ///< time of the first isolation event [s]
  int isolated_channel = -1;
  int restorations = 0;
  int detections = 0;
  int suspected_channel = -1;
  base::Vector3 twist_end = base::Vector3::Zero();  ///< mean true twist over the last 0.5 s
};

/// Goal as a function of time.
using GoalFn = base::Vector3 (*)(double t);

/// Controller + FaultMonitor + first-order wheel plant; the true yaw rate is G_3 omega.
LoopRun runClosedLoop(GoalFn goal, const Fault& fault, bool isolation, double duration, double noise = 0.0,
                      const params::AicParams* controller = nullptr)
{
  const params::AicParams params = controller ? *controller : defaultParams();
  aic::ActiveInferenceController c(params);
  params::FdiParams fdi;
  fdi.enabled = isolation;
  safety::FaultMonitor monitor(fdi, params);
  aic::Generalizer gen(base::kYDim, params.embedding_order);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  base::Vector2 omega = base::Vector2::Zero();
  base::Vector5 frozen = base::Vector5::Zero();
  LoopRun run;
  base::Vector3 sum = base::Vector3::Zero();
  int count = 0;
  const int steps = static_cast<int>(std::lround(duration / kSamplePeriod));
  for (int k = 0; k < steps; ++k)
  {
    const double t = k * kSamplePeriod;
    const base::Vector3 twist = c.model().twistFromWheels(omega);
    base::Vector5 y;
    y << twist(2), omega(0), omega(1), 0.0, 0.0;
    for (int j = 0; j < 3; ++j)
    {
      y(j) += noise * n01(rng);
    }
    if (fault.kind != Fault::kNone && t >= fault.start && t < fault.end)
    {
      if (fault.kind == Fault::kBias)
      {
        y(fault.channel) += fault.value;
      }
      else
      {
        y(fault.channel) = frozen(fault.channel);
      }
    }
    else
    {
      frozen = y;
    }
    gen.update(y, k == 0 ? 0.0 : kSamplePeriod);
    c.setGoal(goal(t));
    c.setMeasurement(gen.yTilde());
    const Event e = monitor.update(y, c.mu().col(0), k == 0 ? 0.0 : kSamplePeriod);
    if (e == Event::kIsolated && std::isnan(run.isolated_at))
    {
      run.isolated_at = t;
      run.isolated_channel = monitor.isolatedChannel();
    }
    run.restorations += e == Event::kRestored ? 1 : 0;
    run.detections += e == Event::kDetected ? 1 : 0;
    c.setSensorMask(monitor.sensorMask());
    for (int i = 0; i < static_cast<int>(std::lround(kSamplePeriod / kBeliefPeriod)); ++i)
    {
      EXPECT_NE(c.updateBeliefs(kBeliefPeriod), aic::ActiveInferenceController::Status::kRunaway);
    }
    EXPECT_NE(c.updateAction(kSamplePeriod), aic::ActiveInferenceController::Status::kRunaway);
    // Exact first-order step of the wheel loop over one period with the command held.
    omega = c.action() + (omega - c.action()) * std::exp(-kSamplePeriod / kWheelTimeConstant);
    if (t >= duration - 0.5)
    {
      sum += c.model().twistFromWheels(omega);
      ++count;
    }
  }
  run.twist_end = sum / count;
  run.suspected_channel = monitor.suspectedChannel();
  return run;
}

base::Vector3 straight(double)
{
  return base::Vector3(0.5, 0.0, 0.0);
}

/// Forward steps and arcs, all healthy: the residual must stay below the threshold.
base::Vector3 manoeuvres(double t)
{
  if (t < 2.0)
  {
    return base::Vector3(0.5, 0.0, 0.0);
  }
  if (t < 4.0)
  {
    return base::Vector3(0.3, 0.0, 1.0);
  }
  if (t < 6.0)
  {
    return base::Vector3(1.0, 0.0, -0.8);
  }
  return base::Vector3(0.0, 0.0, 1.5);
}

/// A steady turn, then straight driving from 3 s (the gyro freezes at 2 s, during the turn).
base::Vector3 turnThenStraight(double t)
{
  return t < 3.0 ? base::Vector3(0.4, 0.0, 0.8) : base::Vector3(0.4, 0.0, 0.0);
}
}  // namespace

TEST(FdiParams, ValidateNamesEveryViolation)
{
  params::FdiParams p;
  EXPECT_TRUE(p.validate().empty());
  p.threshold = -1.0;
  p.release_ratio = 0.0;
  p.detect_time = kNaN;
  p.release_time = -0.5;
  const auto v = p.validate();
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[0].name, "fdi_threshold");
  EXPECT_EQ(v[1].name, "fdi_release_ratio");
  EXPECT_EQ(v[2].name, "fdi_detect_time");
  EXPECT_EQ(v[3].name, "fdi_release_time");
  EXPECT_THROW(safety::FaultMonitor(p, defaultParams()), std::invalid_argument);
}

TEST(FaultMonitor, ResidualIsTheParityOfTheThreeChannels)
{
  const params::AicParams a = defaultParams();
  safety::FaultMonitor m(params::FdiParams(), a);
  const double c = a.wheel_radius * a.slip_factor / a.wheel_separation;
  // Consistent sample: gyro = c (omega_R - omega_L).
  base::Vector5 y;
  y << c * (6.0 - 4.0), 4.0, 6.0, 0.3, -0.2;
  EXPECT_EQ(m.update(y, base::Vector3::Zero(), 0.0), Event::kNone);
  EXPECT_NEAR(m.residual(), 0.0, 1e-12);
  // Each leave-one-out twist reproduces the same twist for consistent channels.
  for (int j : safety::FaultMonitor::kChannels)
  {
    const base::Vector3 x = m.twistWithout(j, y);
    EXPECT_NEAR(x(0), 0.5 * a.wheel_radius * 10.0, 1e-12) << safety::FaultMonitor::channelName(j);
    EXPECT_NEAR(x(2), c * 2.0, 1e-12) << safety::FaultMonitor::channelName(j);
  }
  y(base::kOmegaLeft) += 1.0;
  m.update(y, base::Vector3::Zero(), kSamplePeriod);
  EXPECT_NEAR(m.residual(), c * 1.0, 1e-12);
  const double pi_r = 1.0 / (2.0 + c * c * 4.0);  // var_y order 0 = 2 for every channel
  EXPECT_NEAR(m.statistic(), pi_r * c * c, 1e-12);
}

TEST(FaultMonitor, BadInputIsIgnoredAndCounted)
{
  safety::FaultMonitor m(params::FdiParams(), defaultParams());
  base::Vector5 y = base::Vector5::Zero();
  EXPECT_EQ(m.update(y, base::Vector3::Zero(), -0.01), Event::kNone);
  EXPECT_EQ(m.update(y, base::Vector3::Zero(), kNaN), Event::kNone);
  y(base::kGyroZ) = kNaN;
  EXPECT_EQ(m.update(y, base::Vector3::Zero(), 0.02), Event::kNone);
  EXPECT_EQ(m.ignoredSamples(), 3u);
  EXPECT_EQ(m.isolatedChannel(), -1);
}

TEST(FaultMonitor, HysteresisIsolatesAfterDetectTimeAndRestoresAfterReleaseTime)
{
  params::FdiParams fdi;
  fdi.detect_time = 0.1;
  fdi.release_time = 0.5;
  safety::FaultMonitor m(fdi, defaultParams());
  base::Vector5 bad = base::Vector5::Zero();
  bad(base::kGyroZ) = 1.0;  // a yaw rate the wheels do not show; the belief says "not turning"
  int isolated_at = -1;
  for (int k = 0; k < 20 && isolated_at < 0; ++k)
  {
    if (m.update(bad, base::Vector3::Zero(), kSamplePeriod) == Event::kIsolated)
    {
      isolated_at = k;
    }
  }
  // The first sample above the threshold starts the window; 0.1 s later (5 more samples) it is confirmed.
  EXPECT_EQ(isolated_at, 5);
  EXPECT_EQ(m.isolatedChannel(), base::kGyroZ);
  EXPECT_EQ(m.sensorMask() & (1u << base::kGyroZ), 0u);
  EXPECT_NEAR(m.lastDetectionDelay(), 0.1, 1e-9);
  // Agreeing again: restored only after release_time below the release level.
  const base::Vector5 good = base::Vector5::Zero();
  int restored_at = -1;
  for (int k = 0; k < 60 && restored_at < 0; ++k)
  {
    if (m.update(good, base::Vector3::Zero(), kSamplePeriod) == Event::kRestored)
    {
      restored_at = k;
    }
  }
  EXPECT_EQ(restored_at, 24);  // 25 samples of 0.02 s = 0.5 s
  EXPECT_EQ(m.isolatedChannel(), -1);
  EXPECT_EQ(m.sensorMask(), (1u << base::kYDim) - 1u);
  EXPECT_EQ(m.isolations(), 1u);
  EXPECT_EQ(m.restorations(), 1u);
}

TEST(FaultMonitor, AFaultAwaitsConfirmationFromItsFirstSampleToItsIsolationOrDetection)
{
  // awaitingConfirmation(): above the threshold and not yet isolated or detected (the robot model
  // holds its corrections then); faultPresent() stays true after the confirmation.
  for (const bool isolation : { true, false })
  {
    SCOPED_TRACE(isolation ? "isolation on" : "isolation off");
    params::FdiParams fdi;
    fdi.detect_time = 0.1;
    fdi.enabled = isolation;
    safety::FaultMonitor m(fdi, defaultParams());
    base::Vector5 bad = base::Vector5::Zero();
    bad(base::kGyroZ) = 1.0;
    EXPECT_FALSE(m.awaitingConfirmation());
    EXPECT_EQ(m.update(bad, base::Vector3::Zero(), kSamplePeriod), Event::kNone);
    EXPECT_TRUE(m.awaitingConfirmation());
    for (int k = 0; k < 4; ++k)
    {
      EXPECT_EQ(m.update(bad, base::Vector3::Zero(), kSamplePeriod), Event::kNone);
      EXPECT_TRUE(m.awaitingConfirmation());
    }
    EXPECT_EQ(m.update(bad, base::Vector3::Zero(), kSamplePeriod), isolation ? Event::kIsolated : Event::kDetected);
    EXPECT_FALSE(m.awaitingConfirmation());
    EXPECT_TRUE(m.faultPresent());
    m.update(bad, base::Vector3::Zero(), kSamplePeriod);
    EXPECT_FALSE(m.awaitingConfirmation());
  }
}

/// A model innovation: errors `e` (gyro, omega_L, omega_R) [rad/s] with variance `var` each, and
/// their parity e_gyro - k (e_R - e_L) with its variance.
base::SampleInnovation innovation(const base::Vector3& e, double var, double k = 0.2)
{
  base::SampleInnovation in;
  in.error = e;
  in.variance = base::Vector3::Constant(var);
  in.parity = e(base::kGyroZ) - k * (e(base::kOmegaRight) - e(base::kOmegaLeft));
  in.parity_variance = var + k * k * 2.0 * var;
  return in;
}

TEST(FaultMonitor, TheModelsInnovationTestHasItsOwnThresholdAndIsolatesTheOddChannel)
{
  params::FdiParams fdi;
  fdi.detect_time = 0.1;
  fdi.threshold = 1e6;  // the thesis's models' threshold: not the innovation test's
  const double var = 0.01 * 0.01;
  const double sigma = std::sqrt(var * (1.0 + 2.0 * 0.2 * 0.2));  // the parity's standard deviation
  {
    // 4.9 standard deviations of the parity, for ever: no fault.
    safety::FaultMonitor m(fdi, defaultParams());
    for (int k = 0; k < 100; ++k)
    {
      EXPECT_EQ(m.update(innovation(base::Vector3(4.9 * sigma, 0.0, 0.0), var), kSamplePeriod), Event::kNone);
    }
    EXPECT_NEAR(m.statistic(), 4.9 * 4.9, 1e-9);
    EXPECT_EQ(m.threshold(), safety::FaultMonitor::kInnovationThreshold);
    EXPECT_FALSE(m.faultPresent());
    // The thesis's models' test on the same monitor uses fdi_threshold.
    m.update(base::Vector5::Zero(), base::Vector3::Zero(), kSamplePeriod);
    EXPECT_EQ(m.threshold(), fdi.threshold);
  }
  // 5.1 standard deviations: the channel whose exclusion leaves the other two at the model's
  // prediction is isolated after detect_time (5 more samples), whichever it is.
  for (const int channel : safety::FaultMonitor::kChannels)
  {
    SCOPED_TRACE(safety::FaultMonitor::channelName(channel));
    safety::FaultMonitor m(fdi, defaultParams());
    base::Vector3 e = base::Vector3::Zero();
    e(channel) = 1.0;
    const base::SampleInnovation one = innovation(e, var);
    base::SampleInnovation in = one;
    in.error *= 5.1 * sigma / std::abs(one.parity);
    in.parity *= 5.1 * sigma / std::abs(one.parity);
    int isolated_at = -1;
    for (int k = 0; k < 10 && isolated_at < 0; ++k)
    {
      if (m.update(in, kSamplePeriod) == Event::kIsolated)
      {
        isolated_at = k;
      }
    }
    EXPECT_EQ(isolated_at, 5);
    EXPECT_EQ(m.isolatedChannel(), channel);
    EXPECT_NEAR(m.residual(), in.parity, 1e-15);
    // Restored once the parity is back below fdi_release_ratio x the threshold for release_time.
    int restored_at = -1;
    for (int k = 0; k < 100 && restored_at < 0; ++k)
    {
      if (m.update(innovation(base::Vector3::Zero(), var), kSamplePeriod) == Event::kRestored)
      {
        restored_at = k;
      }
    }
    EXPECT_GE(restored_at, 0);
  }
}

TEST(FaultMonitor, AnIsolatedChannelIsRestoredOnlyOnEvidenceTheSensorsGive)
{
  // The robot model's parity variance carries the slip ratio's uncertainty in a turn; an isolated
  // channel whose disagreement that uncertainty could explain (statistic 1 against parity_variance)
  // is not restored while it is 10 standard deviations of release_variance (the sensors' own):
  // restored once it agrees against that too.
  params::FdiParams fdi;
  fdi.detect_time = 0.1;
  const double var = 0.01 * 0.01;
  safety::FaultMonitor m(fdi, defaultParams());
  const base::SampleInnovation bad = innovation(base::Vector3(1.0, 0.0, 0.0), var);
  for (int k = 0; k < 10; ++k)
  {
    m.update(bad, kSamplePeriod);
  }
  ASSERT_EQ(m.isolatedChannel(), base::kGyroZ);
  base::SampleInnovation turn = innovation(base::Vector3(0.05, 0.0, 0.0), var);
  turn.parity_variance = turn.parity * turn.parity;           // statistic 1
  turn.release_variance = turn.parity * turn.parity / 100.0;  // 10 sigma of the sensors
  for (int k = 0; k < 200; ++k)
  {
    EXPECT_EQ(m.update(turn, kSamplePeriod), Event::kNone);
  }
  EXPECT_EQ(m.isolatedChannel(), base::kGyroZ);
  EXPECT_NEAR(m.statistic(), 1.0, 1e-12);                            // the detection statistic, as reported
  turn.release_variance = std::numeric_limits<double>::quiet_NaN();  // none: parity_variance's
  int restored_at = -1;
  for (int k = 0; k < 200 && restored_at < 0; ++k)
  {
    if (m.update(turn, kSamplePeriod) == Event::kRestored)
    {
      restored_at = k;
    }
  }
  EXPECT_GE(restored_at, 0);
}

TEST(FaultMonitor, ABadModelInnovationIsIgnoredAndCounted)
{
  safety::FaultMonitor m(params::FdiParams(), defaultParams());
  const double var = 1e-4;
  base::SampleInnovation in = innovation(base::Vector3(1.0, 0.0, 0.0), var);
  EXPECT_EQ(m.update(in, -0.02), Event::kNone);
  in.variance(base::kOmegaLeft) = 0.0;
  EXPECT_EQ(m.update(in, kSamplePeriod), Event::kNone);
  in = innovation(base::Vector3(1.0, 0.0, 0.0), var);
  in.parity_variance = kNaN;
  EXPECT_EQ(m.update(in, kSamplePeriod), Event::kNone);
  in = innovation(base::Vector3(kNaN, 0.0, 0.0), var);
  EXPECT_EQ(m.update(in, kSamplePeriod), Event::kNone);
  EXPECT_EQ(m.ignoredSamples(), 4u);
  EXPECT_FALSE(m.faultPresent());
}

TEST(FaultMonitor, ImuMissingMasksTheImuChannelsAndPausesTheTest)
{
  safety::FaultMonitor m(params::FdiParams(), defaultParams());
  m.setImuAvailable(false);
  EXPECT_EQ(m.sensorMask(), (1u << base::kOmegaLeft) | (1u << base::kOmegaRight));
  base::Vector5 y = base::Vector5::Zero();
  y(base::kOmegaLeft) = 5.0;  // would be a fault with the gyro
  for (int k = 0; k < 50; ++k)
  {
    EXPECT_EQ(m.update(y, base::Vector3::Zero(), kSamplePeriod), Event::kNone);
  }
  EXPECT_TRUE(std::isnan(m.statistic()));
  m.setImuAvailable(true);
  EXPECT_EQ(m.sensorMask(), (1u << base::kYDim) - 1u);
}

TEST(SensorMask, MaskedChannelLeavesFreeEnergyBeliefsAndAction)
{
  for (const params::Integrator integrator : { params::Integrator::kEuler, params::Integrator::kExact })
  {
    params::AicParams p = defaultParams();
    p.integrator = integrator;
    aic::ActiveInferenceController masked(p);
    aic::ActiveInferenceController clean(p);
    base::YTilde y = base::YTilde::Zero(base::kYDim, p.numOrders());
    y(base::kGyroZ, 0) = 0.3;
    y(base::kOmegaRight, 0) = 4.0;
    base::YTilde y_bad = y;
    y_bad(base::kOmegaLeft, 0) = 50.0;  // garbage on the masked channel
    y_bad(base::kOmegaLeft, 1) = -30.0;
    const std::uint8_t mask = static_cast<std::uint8_t>(((1u << base::kYDim) - 1u) & ~(1u << base::kOmegaLeft));
    masked.setSensorMask(mask);
    clean.setSensorMask(mask);
    EXPECT_EQ(masked.sensorMask(), mask);
    EXPECT_EQ(masked.precisionY().row(base::kOmegaLeft).cwiseAbs().maxCoeff(), 0.0);
    masked.setGoal(base::Vector3(0.5, 0.0, 0.2));
    clean.setGoal(base::Vector3(0.5, 0.0, 0.2));
    ASSERT_TRUE(masked.setMeasurement(y_bad));
    ASSERT_TRUE(clean.setMeasurement(y));
    for (int k = 0; k < 40; ++k)
    {
      masked.updateBeliefs(kBeliefPeriod);
      clean.updateBeliefs(kBeliefPeriod);
    }
    masked.updateAction(kSamplePeriod);
    clean.updateAction(kSamplePeriod);
    EXPECT_NEAR((masked.mu() - clean.mu()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
    EXPECT_NEAR((masked.action() - clean.action()).cwiseAbs().maxCoeff(), 0.0, 1e-12);
    EXPECT_NEAR(masked.freeEnergy(), clean.freeEnergy(), 1e-9);
    // The mask survives a parameter change and can be lifted.
    masked.setParams(p);
    EXPECT_EQ(masked.sensorMask(), mask);
    masked.setSensorMask(0xFF);
    EXPECT_EQ(masked.sensorMask(), (1u << base::kYDim) - 1u);
    EXPECT_GT(masked.precisionY()(base::kOmegaLeft, 0), 0.0);
  }
}

TEST(ClosedLoopFdi, HealthyManoeuvresRaiseNoFault)
{
  Fault none;
  const LoopRun run = runClosedLoop(&manoeuvres, none, true, 8.0, 0.05);
  EXPECT_TRUE(std::isnan(run.isolated_at))
      << "isolated " << safety::FaultMonitor::channelName(run.isolated_channel) << " at " << run.isolated_at << " s";
}

TEST(ClosedLoopFdi, EncoderBiasIsIsolatedAndTheSpeedHeld)
{
  Fault bias;
  bias.kind = Fault::kBias;
  bias.channel = base::kOmegaLeft;
  bias.value = 2.5;  // rad/s (0.25 m/s of wheel speed) on the left encoder (below max_action_lead)
  bias.start = 3.0;
  const LoopRun isolated = runClosedLoop(&straight, bias, true, 11.0, 0.05);
  std::printf("bias: isolated after %.2f s, v_x %.4f m/s isolated, ", isolated.isolated_at - bias.start,
              isolated.twist_end(0));
  EXPECT_EQ(isolated.isolated_channel, base::kOmegaLeft);
  EXPECT_LE(isolated.isolated_at - bias.start, kIsolationDeadline);
  EXPECT_NEAR(isolated.twist_end(0), 0.5, kSpeedErrorTol * 0.5);
  EXPECT_EQ(isolated.restorations, 0);  // the bias persists, so the channel stays out
  // Without isolation the fault is found and reported, not isolated. (With the action prior the
  // speed error stays small either way: the prior, not the biased encoder, carries the speed.)
  const LoopRun unisolated = runClosedLoop(&straight, bias, false, 11.0, 0.05);
  std::printf("%.4f m/s without isolation\n", unisolated.twist_end(0));
  EXPECT_TRUE(std::isnan(unisolated.isolated_at));
  EXPECT_GE(unisolated.detections, 1);
  EXPECT_EQ(unisolated.suspected_channel, base::kOmegaLeft);  // found, reported, not isolated
}

TEST(ClosedLoopFdi, EncoderBiasMisleadsTheFreeEnergyActionUnlessIsolated)
{
  // What isolation buys the thesis's controller (no action prior, no reference model): without
  // it the free-energy action follows the biased encoder, the speed error is above 5 % and at
  // least twice the isolated run's (which, driven through the gyro's row alone, is still
  // converging at the end).
  Fault bias;
  bias.kind = Fault::kBias;
  bias.channel = base::kOmegaLeft;
  bias.value = 2.5;
  bias.start = 3.0;
  params::AicParams p = defaultParams();
  p.reference.generalized_goal = false;
  p.reference.time_constant = 0.0;
  p.action_prior.gain = 0.0;
  // The gains tuned for the free-energy action alone (straight steps, doc/experiments.md, 'Tuning').
  p.tau = 0.01721;
  p.k_mu = 0.02329;
  p.k_a = 12.59;
  p.var_y = { 2.0, 38.25, 1.0e5 };
  p.anti_windup.max_action_lead = 4.367;
  const LoopRun isolated = runClosedLoop(&straight, bias, true, 11.0, 0.05, &p);
  const LoopRun unisolated = runClosedLoop(&straight, bias, false, 11.0, 0.05, &p);
  EXPECT_EQ(isolated.isolated_channel, base::kOmegaLeft);
  EXPECT_GT(std::abs(unisolated.twist_end(0) - 0.5), kSpeedErrorTol * 0.5);
  EXPECT_GT(std::abs(unisolated.twist_end(0) - 0.5), 2.0 * std::abs(isolated.twist_end(0) - 0.5));
}

TEST(ClosedLoopFdi, BiasRemovedRestoresTheChannel)
{
  Fault bias;
  bias.kind = Fault::kBias;
  bias.channel = base::kOmegaRight;
  bias.value = -2.5;
  bias.start = 2.0;
  bias.end = 4.0;
  const LoopRun run = runClosedLoop(&straight, bias, true, 7.0);
  EXPECT_EQ(run.isolated_channel, base::kOmegaRight);
  EXPECT_EQ(run.restorations, 1);
  EXPECT_NEAR(run.twist_end(0), 0.5, kSpeedErrorTol * 0.5);
}

TEST(ClosedLoopFdi, GyroFreezeDuringATurnIsIsolated)
{
  Fault freeze;
  freeze.kind = Fault::kFreeze;
  freeze.channel = base::kGyroZ;
  freeze.start = 2.0;  // during the steady turn; the set point goes straight at 3 s
  const LoopRun isolated = runClosedLoop(&turnThenStraight, freeze, true, 6.0, 0.02);
  EXPECT_EQ(isolated.isolated_channel, base::kGyroZ);
  EXPECT_NEAR(isolated.twist_end(2), 0.0, 0.05);  // rad/s: drives straight
  EXPECT_NEAR(isolated.twist_end(0), 0.4, kSpeedErrorTol * 0.4);
  const LoopRun unisolated = runClosedLoop(&turnThenStraight, freeze, false, 6.0, 0.02);
  EXPECT_GT(std::abs(unisolated.twist_end(2)), 2.0 * std::abs(isolated.twist_end(2)) + 0.02);
}

TEST(SensorMask, LoweringTheWheelLimitClampsTheHeldAction)
{
  // Found by the fuzz target (test/fuzz/fuzz_core.cpp): setParams() kept an action beyond a lowered limit.
  params::AicParams p = defaultParams();
  aic::ActiveInferenceController c(p);
  c.setAction(base::Vector2(15.0, -15.0));
  p.max_wheel_speed = 5.0;
  c.setParams(p);
  EXPECT_DOUBLE_EQ(c.action()(0), 5.0);
  EXPECT_DOUBLE_EQ(c.action()(1), -5.0);
}
