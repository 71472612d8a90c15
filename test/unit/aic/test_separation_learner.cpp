/// Tests of SeparationLearner: free-energy descent of the effective wheel separation b_hat on the
/// gyro-encoder disagreement (doc/active_inference.md, 'Learning the generative model').
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "jackal_aic/aic/separation_learner.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kR = 0.098;       // wheel radius [m]
constexpr double kTrack = 0.5621;  // nominal separation [m]
constexpr double kLive = 1e-3;     // a live gyro's rate in a steady turn [rad/s^2]: never exactly 0
constexpr double kPi = 0.5;        // Pi_b: the recommended gyro precision 1 / var_y[0]
constexpr double kH = 0.001;       // 1 kHz [s]

/// A learner of settings p on the Jackal's wheels (r = kR, alpha = 1), starting at `initial` [m].
aic::SeparationLearner learner(double initial,
                               const params::SeparationLearnerParams& p = params::SeparationLearnerParams())
{
  return aic::SeparationLearner(p, kR, 1.0, initial);
}

/// Deterministic zero-mean noise in [-a, a] (linear congruential generator).
struct Noise
{
  std::uint64_t s = 12345;
  double operator()(double a)
  {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return a * (2.0 * static_cast<double>(s >> 11) / 9007199254740992.0 - 1.0);
  }
};

/// Drive an arc (v [m/s], w [rad/s]) for `seconds` on a base whose effective separation is b_eff:
/// the wheels turn w b_eff / r apart, the gyro measures w (plus noise of amplitude `noise`).
void driveArc(aic::SeparationLearner* l, double v, double w, double b_eff, double seconds, double noise = 0.0)
{
  Noise n;
  const int steps = static_cast<int>(std::lround(seconds / kH));
  for (int k = 0; k < steps; ++k)
  {
    const double wl = (v - 0.5 * w * b_eff) / kR + n(noise);
    const double wr = (v + 0.5 * w * b_eff) / kR + n(noise);
    l->update(kH, w + n(noise), kLive, wl, wr, 0.0, 0.0, kPi, true, false);
  }
}
}  // namespace

TEST(SeparationLearner, ConvergesFromTrackAndTwiceTrack)
{
  for (const double ratio : { 1.32, 1.42 })  // the plant's arcs: 1.32 ... 1.42 x track
  {
    const double b_eff = ratio * kTrack;
    for (const double start : { 1.0, 2.0 })
    {
      aic::SeparationLearner l = learner(start * kTrack);
      driveArc(&l, 0.5, 0.5, b_eff, 10.0);
      EXPECT_NEAR(l.separation(), b_eff, 0.05 * b_eff) << "ratio " << ratio << " start " << start;
      driveArc(&l, 0.5, 0.5, b_eff, 10.0);
      EXPECT_NEAR(l.separation(), b_eff, 0.005 * b_eff) << "ratio " << ratio << " start " << start;
      EXPECT_EQ(l.state(), aic::SeparationLearner::State::kLearning);
    }
  }
}

TEST(SeparationLearner, ConvergesWithNoiseAndBothTurnDirections)
{
  const double b_eff = 1.4 * kTrack;
  aic::SeparationLearner l = learner(kTrack);
  driveArc(&l, 0.5, -0.5, b_eff, 10.0, 0.02);
  EXPECT_NEAR(l.separation(), b_eff, 0.05 * b_eff);
  driveArc(&l, 0.0, 1.0, b_eff, 10.0, 0.02);  // turning in place
  EXPECT_NEAR(l.separation(), b_eff, 0.01 * b_eff);
}

TEST(SeparationLearner, Bounded)
{
  params::SeparationLearnerParams p;
  p.min = 0.5;
  p.max = 0.7;
  aic::SeparationLearner l = learner(kTrack, p);
  // Effective separations beyond the bounds but within the plausible window [min / 2, 2 max]:
  // b_hat goes to the bound.
  driveArc(&l, 0.5, 0.5, 2.2 * kTrack, 20.0);
  EXPECT_DOUBLE_EQ(l.separation(), 0.7);
  driveArc(&l, 0.5, 0.5, 0.6 * kTrack, 20.0);
  EXPECT_DOUBLE_EQ(l.separation(), 0.5);
  // Beyond the window (2.5 x track = 1.41 m > 2 max): implausible, frozen.
  driveArc(&l, 0.5, 0.5, 2.5 * kTrack, 20.0);
  EXPECT_DOUBLE_EQ(l.separation(), 0.5);
  EXPECT_EQ(l.state(), aic::SeparationLearner::State::kImplausible);
  EXPECT_TRUE(l.setSeparation(5.0));
  EXPECT_DOUBLE_EQ(l.separation(), 0.7);
  EXPECT_FALSE(l.setSeparation(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_DOUBLE_EQ(l.separation(), 0.7);
  l.reset();
  EXPECT_DOUBLE_EQ(l.separation(), kTrack);
  EXPECT_EQ(l.learningSteps(), 0u);
}

TEST(SeparationLearner, FrozenUnderEachCondition)
{
  const double b_eff = 1.4 * kTrack;
  const double wl = (0.5 - 0.25 * b_eff) / kR;
  const double wr = (0.5 + 0.25 * b_eff) / kR;
  aic::SeparationLearner l = learner(kTrack);
  for (int k = 0; k < 1000; ++k)
  {
    EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wr, 0.0, 0.0, kPi, false, false),
              aic::SeparationLearner::State::kSensorFault);
    EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wr, 0.0, 0.0, kPi, true, true), aic::SeparationLearner::State::kSaturated);
    EXPECT_EQ(l.update(kH, 0.05, kLive, 0.1 * wl, 0.1 * wr, 0.0, 0.0, kPi, true, false),
              aic::SeparationLearner::State::kNearRest);
    EXPECT_EQ(l.update(kH, std::numeric_limits<double>::quiet_NaN(), kLive, wl, wr, 0.0, 0.0, kPi, true, false),
              aic::SeparationLearner::State::kBadInput);
    EXPECT_EQ(l.update(0.0, 0.5, kLive, wl, wr, 0.0, 0.0, kPi, true, false), aic::SeparationLearner::State::kBadInput);
    EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wr, 0.0, 0.0, -1.0, true, false), aic::SeparationLearner::State::kBadInput);
    EXPECT_EQ(l.update(kH, 0.5, 2.0, wl, wr, 0.0, 0.0, kPi, true, false), aic::SeparationLearner::State::kTransient);
    EXPECT_EQ(l.update(kH, 0.5, -2.0, wl, wr, 0.0, 0.0, kPi, true, false), aic::SeparationLearner::State::kTransient);
    // The wheels' yaw acceleration r (dw_R - dw_L) / b_hat beyond the bound (the gyro steady: frozen).
    EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wr, -3.0, 3.0, kPi, true, false), aic::SeparationLearner::State::kTransient);
    // The gyro's reading repeats bit for bit (rate exactly 0): stuck, no new information.
    EXPECT_EQ(l.update(kH, 0.5, 0.0, wl, wr, 0.0, 0.0, kPi, true, false), aic::SeparationLearner::State::kStuckGyro);
    // A frozen gyro reports 0.5 rad/s while the wheels drive straight: no b_hat explains it.
    EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wl, 0.0, 0.0, kPi, true, false),
              aic::SeparationLearner::State::kImplausible);
    // The gyro turns the other way than the wheels.
    EXPECT_EQ(l.update(kH, -0.5, kLive, wl, wr, 0.0, 0.0, kPi, true, false),
              aic::SeparationLearner::State::kImplausible);
    // The implied separation r (w_R - w_L) / y_gyro: 3.9 m, beyond 2 max (3 m).
    EXPECT_EQ(l.update(kH, 0.1, kLive, wl, wr, 0.0, 0.0, kPi, true, false),
              aic::SeparationLearner::State::kImplausible);
  }
  EXPECT_EQ(l.separation(), kTrack);  // bit for bit
  EXPECT_EQ(l.learningSteps(), 0u);
  EXPECT_EQ(l.update(kH, 0.5, kLive, wl, wr, 0.0, 0.0, kPi, true, false), aic::SeparationLearner::State::kLearning);
  EXPECT_GT(l.separation(), kTrack);
  EXPECT_EQ(l.learningSteps(), 1u);
}

TEST(SeparationLearner, MovesAtMostMaxRatePerSecond)
{
  // A disagreement that the gradient alone would follow within a fraction of a second (a gyro
  // fault before the fault monitor isolates it): b_hat moves by at most max_rate b_hat per second.
  params::SeparationLearnerParams p;
  p.max_rate = 0.05;
  aic::SeparationLearner limited = learner(kTrack, p);
  p.max_rate = 0.0;  // unlimited
  aic::SeparationLearner free = learner(kTrack, p);
  driveArc(&limited, 0.5, 1.0, 2.0 * kTrack, 0.2);
  driveArc(&free, 0.5, 1.0, 2.0 * kTrack, 0.2);
  EXPECT_GT(free.separation(), 1.1 * kTrack) << "the control: the unlimited gradient moves fast";
  EXPECT_LE(limited.separation(), kTrack * std::exp(0.05 * 0.2) * (1.0 + 1e-9));
  EXPECT_GT(limited.separation(), kTrack * (1.0 + 0.9 * 0.05 * 0.2));
}

TEST(SeparationLearner, ZeroRateOrPrecisionNeverMoves)
{
  params::SeparationLearnerParams p;
  p.rate = 0.0;
  aic::SeparationLearner l = learner(kTrack, p);
  driveArc(&l, 0.5, 0.5, 1.4 * kTrack, 2.0);
  EXPECT_EQ(l.separation(), kTrack);
}

TEST(SeparationLearner, RejectsBadParams)
{
  params::SeparationLearnerParams p;
  p.min = 0.8;  // initial below min
  EXPECT_THROW(learner(kTrack, p), std::invalid_argument);
  p = params::SeparationLearnerParams();
  p.rate = -1.0;
  EXPECT_THROW(learner(kTrack, p), std::invalid_argument);
  p = params::SeparationLearnerParams();
  p.max_yaw_acceleration = 0.0;
  EXPECT_THROW(learner(kTrack, p), std::invalid_argument);
  p = params::SeparationLearnerParams();
  p.max = std::numeric_limits<double>::infinity();
  EXPECT_THROW(learner(kTrack, p), std::invalid_argument);
  EXPECT_STREQ(aic::toString(aic::SeparationLearner::State::kSaturated), "saturated");
  EXPECT_STREQ(aic::toString(aic::SeparationLearner::State::kImplausible), "implausible disagreement");
  EXPECT_STREQ(aic::toString(aic::SeparationLearner::State::kStuckGyro), "stuck gyro");
}
