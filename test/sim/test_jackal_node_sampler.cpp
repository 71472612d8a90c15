/**
 * \file test_jackal_node_sampler.cpp
 * \brief jackal_node's measurement side (jackal_sim/plant/jackal_node_sampler.hpp) and
 *        diff_drive_controller's odometry (jackal_sim/harness/diff_drive_odometry.hpp), on simulated
 *        time with fixed seeds: repeats, ages, catch-up cycles, stamps, positions, the rolling mean,
 *        bad parameters.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "jackal_sim/harness/diff_drive_odometry.hpp"
#include "jackal_aic/safety/frozen_joint_states.hpp"
#include "jackal_sim/plant/jackal_node_sampler.hpp"

using jackal_aic::harness::DiffDriveOdometry;
using jackal_aic::plant::JackalNodeSampler;
using jackal_aic::plant::JackalNodeSamplerParams;
using jackal_aic::plant::JackalNodeSamplerStats;
using jackal_aic::plant::JointStateSample;
using jackal_aic::plant::ResampledJointState;

namespace
{
constexpr double kStep = 0.001;      // the plant's step [s]
constexpr double kMcuPeriod = 0.02;  // the MCU's feedback period [s]
constexpr double kTimeTol = 1e-9;    // [s]
constexpr double kSpeed = 10.0;      // wheel speed of the synthetic drive [rad/s]

/// Drive a sampler for `seconds` as the plant does: every 1 ms step, an MCU sample every 20 ms (at
/// 20 ms, 40 ms, ...: the sensor model's) of wheels turning at kSpeed, then advance(). Returns every
/// message.
std::vector<ResampledJointState> run(JackalNodeSampler* s, double seconds)
{
  std::vector<ResampledJointState> all;
  std::vector<ResampledJointState> out;
  const auto steps = static_cast<int>(std::lround(seconds / kStep));
  const int period = static_cast<int>(std::lround(kMcuPeriod / kStep));
  for (int k = 1; k <= steps; ++k)
  {
    const double t = k * kStep;
    if (k % period == 0)
    {
      JointStateSample m;
      m.stamp = t;
      for (std::size_t i = 0; i < m.position.size(); ++i)
      {
        m.position[i] = kSpeed * t + 1.0;  // travel from an MCU that was on before (offset 1 rad)
        m.velocity[i] = kSpeed;
      }
      s->feedback(m);
    }
    s->advance(t, &out);
    all.insert(all.end(), out.begin(), out.end());
  }
  return all;
}

JackalNodeSamplerParams exact(double phase)
{
  JackalNodeSamplerParams p;
  p.phase = phase;
  p.jitter_std = 0.0;
  return p;
}
}  // namespace

TEST(JackalNodeSampler, ExactClocksNeverRepeatAndAgeIsThePhase)
{
  for (const double phase : { 0.0005, 0.0073, 0.0199 })
  {
    JackalNodeSampler s(exact(phase));
    const auto msgs = run(&s, 4.0);
    ASSERT_GT(msgs.size(), 190u);
    EXPECT_EQ(s.stats().repeats, 0u) << "phase " << phase;
    EXPECT_EQ(s.stats().skipped, 0u) << "phase " << phase;
    EXPECT_NEAR(s.stats().min_age, phase, kTimeTol);
    EXPECT_NEAR(s.stats().max_age, phase, kTimeTol);
    for (std::size_t i = 1; i < msgs.size(); ++i)
    {
      EXPECT_NEAR(msgs[i].sample.stamp - msgs[i - 1].sample.stamp, kMcuPeriod, kTimeTol);
    }
  }
}

TEST(JackalNodeSampler, StampsAreTheLoopsTimeAndPositionsStartAtZero)
{
  JackalNodeSampler s(exact(0.004));
  const auto msgs = run(&s, 1.0);
  ASSERT_FALSE(msgs.empty());
  // The first cycle after the first MCU sample (20 ms) is due at 24 ms; its travel is 0 (offset).
  EXPECT_NEAR(msgs.front().sample.stamp, 0.024, kTimeTol);
  EXPECT_NEAR(msgs.front().source_stamp, 0.020, kTimeTol);
  EXPECT_DOUBLE_EQ(msgs.front().sample.position[0], 0.0);
  const ResampledJointState& last = msgs.back();
  EXPECT_NEAR(last.sample.position[3], kSpeed * (last.source_stamp - 0.020), 1e-9);
  EXPECT_DOUBLE_EQ(last.sample.velocity[1], kSpeed);
}

TEST(JackalNodeSampler, SidesCarryTheirMeanAsTheMcuMeasuresOneMotorPerSide)
{
  JackalNodeSampler s(exact(0.001));
  JointStateSample m;
  m.stamp = 0.02;
  m.velocity = { 1.0, 4.0, 3.0, 6.0 };  // FL, FR, RL, RR
  s.feedback(m);
  std::vector<ResampledJointState> out;
  s.advance(0.05, &out);
  ASSERT_FALSE(out.empty());
  EXPECT_DOUBLE_EQ(out.back().sample.velocity[0], 2.0);
  EXPECT_DOUBLE_EQ(out.back().sample.velocity[2], 2.0);
  EXPECT_DOUBLE_EQ(out.back().sample.velocity[1], 5.0);
  EXPECT_DOUBLE_EQ(out.back().sample.velocity[3], 5.0);
}

// Through one period of the phase, with the default wake-up latency, the share of repeated joint
// states spans the robot's 0.3-16 %: none far from the MCU's sample instants, the most where the
// loop wakes on them. Ages stay within one MCU period.
TEST(JackalNodeSampler, PhaseSweepSpansTheRobotsRepeatRates)
{
  double lowest = 1.0;
  double highest = 0.0;
  for (int p = 0; p < 20; ++p)
  {
    JackalNodeSamplerParams params;
    params.phase = p * 0.001;
    JackalNodeSampler s(params);
    run(&s, 20.0);
    const JackalNodeSamplerStats& st = s.stats();
    lowest = std::min(lowest, st.repeatRate());
    highest = std::max(highest, st.repeatRate());
    EXPECT_GE(st.min_age, 0.0);
    EXPECT_LT(st.max_age, kMcuPeriod + kTimeTol);
    // Each repeat is an MCU sample never published a cycle later (the run may end between the two).
    EXPECT_LE(std::max(st.repeats, st.skipped) - std::min(st.repeats, st.skipped), 1u) << "phase " << params.phase;
  }
  EXPECT_LT(lowest, 0.005);
  EXPECT_GE(highest, 0.15);
}

// Repeats come singly (a stall's back-to-back catch-up cycle may repeat once more), so one MCU
// sample's data stay in the messages at most one period plus the loop's lateness: over the phase,
// with the default latency, with stalls of up to 30 ms on a tenth of the cycles and with the clock
// 5000 ppm off. The frozen-stream check's time
// (kFrozenJointStateTime, include/jackal_aic/safety/frozen_joint_states.hpp) is twice the longest.
TEST(JackalNodeSampler, RepeatsHoldDataAtMostAPeriodAndTheLateness)
{
  double held = 0.0;
  for (int p = 0; p < 20; ++p)
  {
    for (const double stall : { 0.0, 0.1 })
    {
      for (const double drift : { 0.0, 5000.0, -5000.0 })
      {
        JackalNodeSamplerParams params;
        params.phase = p * 0.001;
        params.stall_probability = stall;
        params.stall_max = 0.03;
        params.drift = drift;
        JackalNodeSampler s(params);
        run(&s, 20.0);
        const JackalNodeSamplerStats& st = s.stats();
        const std::string what = "phase " + std::to_string(params.phase) + ", stall " + std::to_string(stall) +
                                 ", drift " + std::to_string(drift);
        // Singly with the robot's latency; a stall's catch-up cycles may add one more.
        EXPECT_LE(st.max_repeat_run, stall > 0.0 ? 2u : 1u) << what;
        EXPECT_LT(st.max_held, kMcuPeriod + (stall > 0.0 ? params.stall_max : 0.005) + kTimeTol) << what;
        held = std::max(held, st.max_held);
      }
    }
  }
  EXPECT_GT(held, kMcuPeriod - 0.005);  // some data do stay about a period
  EXPECT_LE(2.0 * held, jackal_aic::safety::kFrozenJointStateTime);
}

// A loop clock 5000 ppm fast gains one period every 200 cycles: one repeat each time; 5000 ppm slow
// loses one: one MCU sample never published each time.
TEST(JackalNodeSampler, DriftRepeatsOrSkipsOncePerPeriodOfPhase)
{
  JackalNodeSamplerParams fast = exact(0.01);
  fast.drift = 5000.0;
  JackalNodeSampler f(fast);
  run(&f, 40.0);  // ~2000 cycles: 10 periods of phase
  EXPECT_NEAR(static_cast<double>(f.stats().repeats), 10.0, 1.0);
  EXPECT_EQ(f.stats().skipped, 0u);

  JackalNodeSamplerParams slow = fast;
  slow.drift = -5000.0;
  JackalNodeSampler s(slow);
  run(&s, 40.0);
  EXPECT_NEAR(static_cast<double>(s.stats().skipped), 10.0, 1.0);
  EXPECT_EQ(s.stats().repeats, 0u);
}

// Stalled cycles are followed by catch-up cycles back to back (cycle_time apart), as ros::Rate runs
// them; stamps never go back.
TEST(JackalNodeSampler, StallsMakeBackToBackCatchUpCycles)
{
  JackalNodeSamplerParams p;
  p.phase = 0.01;
  p.stall_probability = 0.05;
  p.seed = 7;
  JackalNodeSampler s(p);
  const auto msgs = run(&s, 20.0);
  EXPECT_GT(s.stats().catch_up, 5u);
  double least_gap = 1.0;
  for (std::size_t i = 1; i < msgs.size(); ++i)
  {
    least_gap = std::min(least_gap, msgs[i].sample.stamp - msgs[i - 1].sample.stamp);
  }
  EXPECT_GE(least_gap, p.cycle_time - kTimeTol);
  EXPECT_LT(least_gap, 0.001);
}

TEST(JackalNodeSampler, SameSeedSameMessages)
{
  JackalNodeSamplerParams p;
  p.phase = 0.0;
  p.stall_probability = 0.02;
  JackalNodeSampler a(p);
  JackalNodeSampler b(p);
  const auto ma = run(&a, 5.0);
  const auto mb = run(&b, 5.0);
  ASSERT_EQ(ma.size(), mb.size());
  for (std::size_t i = 0; i < ma.size(); ++i)
  {
    EXPECT_EQ(ma[i].sample.stamp, mb[i].sample.stamp);
    EXPECT_EQ(ma[i].repeated, mb[i].repeated);
  }
}

TEST(JackalNodeSampler, LinkDelayAgesEverySample)
{
  JackalNodeSamplerParams p = exact(0.003);
  p.link_delay = 0.006;
  JackalNodeSampler s(p);
  run(&s, 2.0);
  // A sample taken at 20 n ms arrives at 20 n + 6 ms: the cycle at 20 n + 3 ms still has the previous.
  EXPECT_NEAR(s.stats().min_age, 0.023, kTimeTol);
  EXPECT_NEAR(s.stats().max_age, 0.023, kTimeTol);
}

TEST(JackalNodeSampler, InvalidParametersAreNamed)
{
  const auto expectBad = [](JackalNodeSamplerParams p, const std::string& key) {
    try
    {
      JackalNodeSampler s(p);
      ADD_FAILURE() << key << " accepted";
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  JackalNodeSamplerParams p;
  p.phase = 0.02;  // one period: not in [0, 1 / loop_rate)
  expectBad(p, "phase");
  p = JackalNodeSamplerParams();
  p.loop_rate = 0.0;
  expectBad(p, "loop_rate");
  p = JackalNodeSamplerParams();
  p.drift = NAN;
  expectBad(p, "drift");
  p = JackalNodeSamplerParams();
  p.jitter_std = -0.001;
  expectBad(p, "jitter_std");
  p = JackalNodeSamplerParams();
  p.stall_probability = 1.5;
  expectBad(p, "stall_probability");
  p = JackalNodeSamplerParams();
  p.stall_max = 0.05;
  expectBad(p, "stall_max");
  p = JackalNodeSamplerParams();
  p.link_delay = -1.0;
  expectBad(p, "link_delay");
  EXPECT_TRUE(JackalNodeSamplerParams().validate().empty());
}

// diff_drive_controller's odometry: exact on a steady drive, the rolling mean over `window` updates.
TEST(DiffDriveOdometry, SteadyDriveIsExact)
{
  DiffDriveOdometry o(0.5634, 0.098);
  for (int k = 0; k <= 50; ++k)
  {
    const double t = 0.02 * k;
    o.update(5.0 * t, 5.0 * t, t);
  }
  EXPECT_NEAR(o.linear(), 5.0 * 0.098, 1e-9);
  EXPECT_NEAR(o.angular(), 0.0, 1e-9);
  EXPECT_NEAR(o.x(), 5.0 * 0.098 * 1.0, 1e-9);
}

// A repeated sample (no travel) and the double step after it: the rolling mean falls by a tenth while
// only the repeat is in the window, and is exact again once both are.
TEST(DiffDriveOdometry, RepeatThenDoubleStepInTheRollingMean)
{
  DiffDriveOdometry o(0.5634, 0.098, 10);
  double pos = 0.0;
  double t = 0.0;
  o.update(pos, pos, t);
  for (int k = 0; k < 20; ++k)
  {
    t += 0.02;
    pos += 0.1;
    o.update(pos, pos, t);
  }
  const double v = 0.1 * 0.098 / 0.02;
  EXPECT_NEAR(o.linear(), v, 1e-9);
  t += 0.02;  // repeat: no new travel
  o.update(pos, pos, t);
  EXPECT_NEAR(o.linear(), 0.9 * v, 1e-9);
  t += 0.02;
  pos += 0.2;  // two MCU periods of travel at once
  o.update(pos, pos, t);
  EXPECT_NEAR(o.linear(), v, 1e-9);
}

TEST(DiffDriveOdometry, UpdatesCloserThanATenthOfAMillisecondKeepTheSpeed)
{
  DiffDriveOdometry o(0.5634, 0.098);
  o.update(0.0, 0.0, 0.0);
  EXPECT_TRUE(o.update(0.1, 0.1, 0.02));
  const double v = o.linear();
  EXPECT_FALSE(o.update(0.2, 0.2, 0.02005));
  EXPECT_DOUBLE_EQ(o.linear(), v);
  EXPECT_NEAR(o.x(), 0.2 * 0.098, 1e-12);  // the displacement is in the pose
}

TEST(DiffDriveOdometry, InvalidParametersThrow)
{
  EXPECT_THROW(DiffDriveOdometry(0.0, 0.098), std::invalid_argument);
  EXPECT_THROW(DiffDriveOdometry(0.5, NAN), std::invalid_argument);
  EXPECT_THROW(DiffDriveOdometry(0.5, 0.098, 0), std::invalid_argument);
}
