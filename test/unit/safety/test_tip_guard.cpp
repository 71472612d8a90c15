/**
 * \file test_tip_guard.cpp
 * \brief TipGuard: trips on a pitch while braking, learns the deceleration at the lift's onset,
 *        holds the braking bound at 0 until the body is level; a slope, a pitch without braking
 *        and a missing IMU do not trip it; past the turnover pitch the body has turned over
 *        (a zero command); reset, settings and bad input
 *        (include/jackal_aic/safety/tip_guard.hpp); the reference path's tip bounds
 *        (ReferenceModel::setTipBounds); in SamplePipeline, the gyro y's offset learned at rest
 *        and removed before the guard, and the guard's bounds in the controller's path.
 */
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/aic/reference_model.hpp"
#include "jackal_aic/loop/sample_pipeline.hpp"
#include "jackal_aic/safety/tip_guard.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kH = 0.02;  // the robot's 50 Hz sensor rate [s]
constexpr double kG = safety::TipGuard::kGravity;
using State = safety::TipGuard::State;

/// `seconds` of samples at pitch rate q [rad/s] and body acceleration a [m/s^2] (the wheels'
/// speed `*v` changes by a h per sample). `theta` carries the true pitch, `v` the speed, between
/// calls. Returns the last state.
State drive(safety::TipGuard* g, double seconds, double q, double a, double* theta, double* v, double noise = 0.0,
            std::mt19937* rng = nullptr)
{
  std::normal_distribution<double> n(0.0, 1.0);
  State s = State::kLevel;
  for (int i = 0; i < static_cast<int>(std::lround(seconds / kH)); ++i)
  {
    *theta += q * kH;
    *v += a * kH;
    const double wq = rng ? noise * n(*rng) : 0.0;
    s = g->update(kH, q + wq, *v, true);
  }
  return s;
}
/// The body noses down at 0.3 rad/s while braking at `a` [m/s^2] (a < 0) until the guard trips
/// (or the pitch reaches 0.2 rad). Returns the state.
State tipNoseDown(safety::TipGuard* g, double a, double* theta, double* v)
{
  State s = g->state();
  while (s != State::kTippingFront && *theta < 0.2)
  {
    s = drive(g, kH, 0.3, a, theta, v);
  }
  return s;
}
}  // namespace

TEST(TipGuard, LevelBrakingDoesNotTrip)
{
  safety::TipGuard g{ params::TipGuardParams() };
  double theta = 0.0;
  double v = 1.5;
  std::mt19937 rng(3);
  EXPECT_EQ(drive(&g, 2.0, 0.0, -3.0, &theta, &v, 0.005, &rng), State::kLevel);
  EXPECT_EQ(g.trips(), 0u);
  EXPECT_TRUE(std::isinf(g.frontBound()));
  EXPECT_TRUE(std::isinf(g.rearBound()));
  EXPECT_NEAR(g.acceleration(), -3.0, 1e-9);
}

TEST(TipGuard, TripsWhileBrakingLearnsTheOnsetAndHoldsUntilLevel)
{
  params::TipGuardParams p;
  p.margin = 0.8;
  p.min_acceleration = 0.5;
  safety::TipGuard g{ p };
  double theta = 0.0;
  double v = 1.5;
  drive(&g, 0.5, 0.0, -2.0, &theta, &v);  // braking at 2 m/s^2, all wheels down
  // The rear wheels lift at 2.0 m/s^2 and the brake, still pressing, reaches 3.0 m/s^2 before
  // the pitch trips the guard: the bound is learned from the onset, not from the trip.
  State s = drive(&g, kH, 0.3, -2.0, &theta, &v);
  s = tipNoseDown(&g, -3.0, &theta, &v);
  ASSERT_EQ(s, State::kTippingFront);
  EXPECT_GT(g.pitch(), p.trip_pitch);
  EXPECT_EQ(g.trips(), 1u);
  EXPECT_EQ(g.frontBound(), 0.0) << "while the body is tipped, the path does not brake";
  EXPECT_TRUE(std::isinf(g.rearBound()));
  // Learned at the onset (theta through 0.1 trip_pitch), where the acceleration was 2.0 m/s^2.
  EXPECT_LT(g.acceleration(), -2.6) << "the brake pressed on to the trip";
  EXPECT_NEAR(g.learnedFront(), 0.8 * 2.0, 0.05);
  // The brake released, the body rolls back onto its wheels.
  s = drive(&g, 0.1, 0.1, -0.2, &theta, &v);
  EXPECT_EQ(s, State::kTippingFront) << "still tipped: theta " << g.pitch();
  while (theta > 0.0)
  {
    s = drive(&g, kH, -0.3, 0.0, &theta, &v);
  }
  EXPECT_EQ(s, State::kLevel);
  EXPECT_NEAR(g.pitch(), 0.0, 0.01) << "no leak while it rotates: the landing integrates back";
  EXPECT_NEAR(g.frontBound(), 0.8 * 2.0, 0.05) << "after the trip, the learned bound";
  // A second, harder trip does not raise the bound.
  drive(&g, 0.5, 0.0, -3.0, &theta, &v);
  tipNoseDown(&g, -3.0, &theta, &v);
  EXPECT_EQ(g.trips(), 2u);
  EXPECT_NEAR(g.learnedFront(), 0.8 * 2.0, 0.05);
}

TEST(TipGuard, TailDownWhileSpeedingUpLearnsTheRearBound)
{
  safety::TipGuard g{ params::TipGuardParams() };
  double theta = 0.0;
  double v = 1.5;
  drive(&g, 0.3, 0.0, 4.0, &theta, &v);
  while (g.state() != State::kTippingRear && theta > -0.2)
  {
    drive(&g, kH, -0.3, 4.0, &theta, &v);
  }
  EXPECT_EQ(g.state(), State::kTippingRear);
  EXPECT_EQ(g.rearBound(), 0.0);
  EXPECT_NEAR(g.learnedRear(), 0.6 * 4.0, 0.1);
  EXPECT_TRUE(std::isinf(g.frontBound()));
}

TEST(TipGuard, ASlopeOrAPitchWithoutBrakingIsNotLearned)
{
  safety::TipGuard g{ params::TipGuardParams() };
  double theta = 0.0;
  double v = 1.5;
  // Onto a 5 degree downhill ramp while cruising (no acceleration): pitched, not tripped.
  // (kBrakingThreshold: a pitch without braking is a slope or a bump.)
  drive(&g, 0.29, 0.3, 0.0, &theta, &v);
  EXPECT_EQ(g.state(), State::kPitched);
  EXPECT_EQ(g.trips(), 0u);
  // On the ramp the body does not rotate: the estimate fades to the ramp's plane.
  drive(&g, 5.0, 0.0, 0.0, &theta, &v);
  EXPECT_NEAR(g.pitch(), 0.0, 0.001);
  EXPECT_EQ(g.state(), State::kLevel);
  // Braking on the ramp with all wheels down does not trip it.
  drive(&g, 1.0, 0.0, -2.0, &theta, &v);
  EXPECT_EQ(g.trips(), 0u);
  EXPECT_TRUE(std::isinf(g.frontBound()));
}

TEST(TipGuard, WithoutTheImuThePitchFadesAndNothingIsLearned)
{
  safety::TipGuard g{ params::TipGuardParams() };
  double theta = 0.0;
  double v = 1.5;
  drive(&g, 0.05, 0.3, 0.0, &theta, &v);
  const double before = g.pitch();
  EXPECT_EQ(g.update(kH, 5.0, v, false), State::kNoImu) << "the gyro's reading is ignored";
  EXPECT_NEAR(g.pitch(), before * std::exp(-kH / safety::TipGuard::kPitchTimeConstant), 1e-12);
  EXPECT_EQ(g.trips(), 0u);
}

TEST(TipGuard, ResetForgetsTheBounds)
{
  safety::TipGuard g{ params::TipGuardParams() };
  double theta = 0.0;
  double v = 1.5;
  tipNoseDown(&g, -2.5, &theta, &v);
  ASSERT_TRUE(std::isfinite(g.learnedFront()));
  g.reset();
  EXPECT_TRUE(std::isinf(g.frontBound()));
  EXPECT_EQ(g.pitch(), 0.0);
  EXPECT_EQ(g.trips(), 0u);
  EXPECT_EQ(g.state(), State::kLevel);
}

TEST(TipGuard, TheFloorBoundsWhatATripTeaches)
{
  params::TipGuardParams p;
  p.min_acceleration = 1.5;
  safety::TipGuard g{ p };
  double theta = 0.0;
  double v = 1.5;
  tipNoseDown(&g, -1.0, &theta, &v);  // a lift at 1 m/s^2 (a robot much heavier in front)
  EXPECT_EQ(g.learnedFront(), 1.5);
  p.min_acceleration = 2.0;
  g.setParams(p);
  EXPECT_EQ(g.learnedFront(), 2.0) << "a new floor raises the learned bound";
}

TEST(TipGuard, PastTheTurnoverPitchTheBodyHasTurnedOverUntilThePitchFadesBelowIt)
{
  const params::TipGuardParams p;  // turnover_pitch 0.4 rad
  safety::TipGuard g{ p };
  double theta = 0.0;
  double v = 1.5;
  drive(&g, 0.5, 0.0, -2.0, &theta, &v);
  ASSERT_EQ(tipNoseDown(&g, -2.0, &theta, &v), State::kTippingFront);
  // The body goes on over its front axle at 2 rad/s, the wheels at the speed they had.
  while (g.pitch() < 0.38)
  {
    EXPECT_FALSE(g.turnedOver()) << "pitch " << g.pitch();
    drive(&g, kH, 2.0, 0.0, &theta, &v);
  }
  EXPECT_EQ(drive(&g, 0.1, 2.0, 0.0, &theta, &v), State::kTurnedOver);
  EXPECT_TRUE(g.turnedOver());
  EXPECT_EQ(g.frontBound(), 0.0) << "the trip stays under it";
  EXPECT_EQ(safety::statusText(g).rfind("turned over (wheels stopped); front ", 0), 0u) << safety::statusText(g);
  // On its back, at rest: the estimate fades with T_theta; turned over until it is below 0.4 rad.
  drive(&g, 0.5, 2.0, 0.0, &theta, &v);  // to 1.2 rad or so
  const double top = g.pitch();
  ASSERT_GT(top, 1.0);
  const double fade = std::log(top / p.turnover_pitch) * safety::TipGuard::kPitchTimeConstant;
  drive(&g, fade - 0.1, 0.0, 0.0, &theta, &v);
  EXPECT_TRUE(g.turnedOver()) << g.pitch();
  EXPECT_NE(drive(&g, 0.2, 0.0, 0.0, &theta, &v), State::kTurnedOver);
  EXPECT_FALSE(g.turnedOver()) << g.pitch();
  EXPECT_EQ(g.frontBound(), 0.0) << "tipped still: the trip ends at trip_pitch / 2";
  // Whatever turned it over: a tail-down tumble without braking (a bump) counts alike.
  safety::TipGuard tumble{ p };
  theta = 0.0;
  v = 0.5;
  EXPECT_EQ(drive(&tumble, 0.25, -2.0, 0.0, &theta, &v), State::kTurnedOver);
  EXPECT_EQ(tumble.trips(), 0u);
  EXPECT_TRUE(std::isinf(tumble.rearBound())) << "nothing learned: no acceleration tipped it";
}

TEST(TipGuard, ARobotOnItsBackStaysTurnedOverUntilItIsUprightAgain)
{
  // After a flip the pitch estimate reads about 0 (a half turn integrated, or leaked away at rest),
  // and a robot on its back would get its command back. The accelerometer's f_z = -g keeps it
  // turned over until the body is upright again.
  const params::TipGuardParams p;  // turnover_pitch 0.4 rad
  const double g0 = safety::TipGuard::kGravity;
  const auto hold = [](safety::TipGuard* g, double seconds, double f_z, bool imu_ok = true) {
    for (double t = 0.0; t < seconds; t += kH)
    {
      g->update(kH, 0.0, 0.0, imu_ok, f_z);
    }
  };
  safety::TipGuard g{ p };
  EXPECT_EQ(g.upForce(), g0);
  hold(&g, 5.0, -g0);  // five seconds on its back, at rest
  EXPECT_EQ(g.pitch(), 0.0);
  EXPECT_TRUE(g.upsideDown());
  EXPECT_TRUE(g.turnedOver());
  EXPECT_EQ(g.state(), State::kTurnedOver);
  EXPECT_LT(g.upForce(), -0.99 * g0);
  // No IMU: nothing new of the body, the state holds; reset() (a payload removed) keeps it too.
  hold(&g, 1.0, g0, false);
  g.reset();
  EXPECT_TRUE(g.turnedOver());
  // Lifted onto its side and on to 60 degrees of tilt: still turned over (the release needs the
  // body within turnover_pitch of upright).
  hold(&g, 1.0, 0.0);
  hold(&g, 1.0, g0 * std::cos(1.0));
  EXPECT_TRUE(g.turnedOver());
  hold(&g, 2.0, g0 * std::cos(0.3));
  EXPECT_FALSE(g.upsideDown());
  EXPECT_FALSE(g.turnedOver());
  EXPECT_EQ(g.state(), State::kLevel);
  // A 40 degree slope and a sample of -2 g (a bump) never read as upside down.
  safety::TipGuard slope{ p };
  hold(&slope, 2.0, g0 * std::cos(0.7));
  slope.update(kH, 0.0, 0.0, true, -2.0 * g0);
  hold(&slope, 0.1, g0 * std::cos(0.7));
  EXPECT_FALSE(slope.upsideDown());
  EXPECT_FALSE(slope.turnedOver());
}

TEST(TipGuard, BadInputIsIgnoredAndBadSettingsRefused)
{
  safety::TipGuard g{ params::TipGuardParams() };
  EXPECT_EQ(g.update(0.0, 0.1, 0.0, true), State::kBadInput);
  EXPECT_EQ(g.update(kH, std::nan(""), 0.0, true), State::kBadInput);
  EXPECT_EQ(g.update(kH, 0.0, std::numeric_limits<double>::infinity(), true), State::kBadInput);
  EXPECT_EQ(g.update(kH, 0.0, std::nan(""), false), State::kBadInput);
  EXPECT_EQ(g.update(kH, 0.0, 0.0, true, -std::numeric_limits<double>::infinity()), State::kBadInput);
  EXPECT_FALSE(g.upsideDown());
  EXPECT_EQ(g.update(kH, 0.0, 0.0, false, std::nan("")), State::kNoImu) << "without an IMU f_z is not read";
  EXPECT_EQ(g.pitch(), 0.0);
  EXPECT_EQ(g.acceleration(), 0.0);
  for (const auto& bad :
       { params::TipGuardParams{ false, 0.0, 0.8, 1.0 }, params::TipGuardParams{ false, 0.02, 0.0, 1.0 },
         params::TipGuardParams{ false, 0.02, 1.1, 1.0 }, params::TipGuardParams{ false, 0.02, 0.8, 0.0 },
         params::TipGuardParams{ false, std::nan(""), 0.8, 1.0 }, params::TipGuardParams{ false, 0.02, 0.8, 1.0, 0.02 },
         params::TipGuardParams{ false, 0.3, 0.8, 1.0, 0.2 }, params::TipGuardParams{ false, 0.02, 0.8, 1.0, 1.6 },
         params::TipGuardParams{ false, 0.02, 0.8, 1.0, std::nan("") } })
  {
    EXPECT_THROW(safety::TipGuard{ bad }, std::invalid_argument);
    EXPECT_THROW(g.setParams(bad), std::invalid_argument);
  }
  try
  {
    safety::TipGuard{ params::TipGuardParams{ false, 0.0, 0.0, 0.0, 0.0 } };
    FAIL() << "no exception";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("tip_guard_pitch"), std::string::npos) << what;
    EXPECT_NE(what.find("tip_guard_margin"), std::string::npos) << what;
    EXPECT_NE(what.find("tip_guard_min_acceleration"), std::string::npos) << what;
    EXPECT_NE(what.find("tip_guard_turnover_pitch"), std::string::npos) << what;
  }
}

TEST(TipGuard, StatusTextNamesStateBoundsAndTrips)
{
  safety::TipGuard g{ params::TipGuardParams() };
  EXPECT_EQ(safety::statusText(g), "level; front none, rear none; 0 trips");
  double theta = 0.0;
  double v = 1.5;
  drive(&g, 0.5, 0.0, -2.5, &theta, &v);
  tipNoseDown(&g, -2.5, &theta, &v);
  EXPECT_EQ(safety::statusText(g), "tipping nose-down; front 1.50 m/s^2, rear none; 1 trip");
}

TEST(ReferenceModelTipBounds, ClampThePathsRateAlongXDot)
{
  params::ReferenceModelParams p;
  p.time_constant = 0.005;
  p.max_acceleration_linear = 4.0;
  aic::ReferenceModel r{ p };
  ASSERT_TRUE(r.start(base::Vector3(1.5, 0.0, 0.0)));
  ASSERT_TRUE(r.setGoal(base::Vector3(0.0, 0.0, 0.5)));
  EXPECT_NEAR(r.rate()(0), -4.0, 1e-9);
  r.setTipBounds(1.6, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(r.rate()(0), -1.6, 1e-9) << "braking below the front bound";
  EXPECT_NEAR(r.rate()(2), 0.5 / 0.005, 1e-9) << "the yaw channel is not bounded by it";
  r.setTipBounds(0.0, std::numeric_limits<double>::infinity());
  EXPECT_EQ(r.rate()(0), 0.0) << "tipping: the path holds its speed";
  r.advance(0.1);
  EXPECT_NEAR(r.path()(0), 1.5, 1e-12);
  r.setTipBounds(std::nan(""), -1.0);
  EXPECT_EQ(r.tipBoundFront(), 0.0) << "NaN and negative bounds are ignored";
  EXPECT_TRUE(std::isinf(r.tipBoundRear()));
  r.setParams(p, 1.0e3);
  EXPECT_EQ(r.tipBoundFront(), 0.0) << "kept by setParams()";
  r.setTipBounds(std::numeric_limits<double>::infinity(), 0.5);
  ASSERT_TRUE(r.setGoal(base::Vector3(3.0, 0.0, 0.0)));
  EXPECT_NEAR(r.rate()(0), 0.5, 1e-9) << "speeding up below the rear bound";
}

TEST(ReferenceModelTipBounds, ATrippedBoundHoldsThePathAtTheSpeedGivenNotAhead)
{
  const double inf = std::numeric_limits<double>::infinity();
  params::ReferenceModelParams p;
  p.time_constant = 0.005;
  p.max_acceleration_linear = 4.0;
  aic::ReferenceModel r{ p };
  ASSERT_TRUE(r.start(base::Vector3(0.5, 0.0, 0.2)));
  EXPECT_FALSE(r.holdTipSpeed(0.9)) << "no trip: the path is left alone";
  EXPECT_FALSE(r.tipTripped());
  EXPECT_EQ(r.path()(0), 0.5);
  r.setTipBounds(1.6, inf);
  EXPECT_FALSE(r.holdTipSpeed(0.9)) << "a bound that is not tripped holds nothing";
  EXPECT_FALSE(r.tipTripped()) << "a learned bound is no trip";
  r.setTipBounds(0.0, inf);  // tipping nose-down: no more braking
  EXPECT_TRUE(r.tipTripped());
  EXPECT_FALSE(r.holdTipSpeed(0.3)) << "the path is above the speed: it stays";
  EXPECT_FALSE(r.holdTipSpeed(std::nan("")));
  EXPECT_EQ(r.path()(0), 0.5);
  EXPECT_TRUE(r.holdTipSpeed(0.9)) << "the path below the robot's speed is raised to it";
  EXPECT_EQ(r.path(), base::Vector3(0.9, 0.0, 0.2)) << "only x_dot moves";
  ASSERT_TRUE(r.setGoal(base::Vector3(0.0, 0.0, 0.2)));
  r.advance(0.1);
  EXPECT_NEAR(r.path()(0), 0.9, 1e-12) << "and held there: the trip still stops the braking";
  r.setTipBounds(inf, 0.0);  // tipping nose-up: no more acceleration
  EXPECT_TRUE(r.tipTripped());
  EXPECT_TRUE(r.holdTipSpeed(0.4)) << "a rear trip lowers the path to the speed";
  EXPECT_EQ(r.path()(0), 0.4);
  EXPECT_FALSE(r.holdTipSpeed(0.7));
}

TEST(TipGuardInThePipeline, TheGyroYOffsetIsRemovedAndTheBoundsReachThePath)
{
  params::AicParams aic = params::recommendedAicParams();  // tip_guard and learn_gyro_bias on
  params::FdiParams fdi;
  loop::SamplePipeline pipe(aic, fdi);
  pipe.activate(base::Vector2::Zero(), base::Vector3::Zero());
  // 6 s at rest with a 0.03 rad/s gyro y offset from power-on: without its removal the leaky
  // pitch would settle at offset x T_theta = 0.03 rad, above tip_guard_pitch.
  for (int i = 0; i < 300; ++i)
  {
    pipe.guardTip(base::Vector5::Zero(), 0.03, kH, true);
  }
  EXPECT_NEAR(pipe.pitchBias().offset(), 0.03, 0.002);
  for (int i = 0; i < 250; ++i)
  {
    pipe.guardTip(base::Vector5::Zero(), 0.03, kH, true);
  }
  EXPECT_NEAR(pipe.tipGuard().pitch(), 0.0, 0.003);
  EXPECT_TRUE(std::isinf(pipe.controller().referenceModel().tipBoundFront()));
  // Braking (the wheels slow by 2.5 m/s^2) while the body noses down at 0.3 rad/s: it trips.
  const double r = aic.wheel_radius;
  double v = 1.5;
  for (int i = 0; i < 10 && pipe.tipGuard().state() != safety::TipGuard::State::kTippingFront; ++i)
  {
    v -= 2.5 * kH;
    base::Vector5 y;
    y << 0.0, v / r, v / r, 0.0, 0.0;
    pipe.guardTip(y, 0.03 + 0.3, kH, true);
  }
  ASSERT_EQ(pipe.tipGuard().state(), safety::TipGuard::State::kTippingFront);
  EXPECT_EQ(pipe.controller().referenceModel().tipBoundFront(), 0.0) << "the path holds while tipped";
  EXPECT_FALSE(pipe.controller().turnedOver());
  // On over its front axle at 2 rad/s: past the turnover pitch the controller's command is zero.
  for (int i = 0; i < 25 && !pipe.tipGuard().turnedOver(); ++i)
  {
    pipe.guardTip(base::Vector5::Zero(), 0.03 + 2.0, kH, true);
  }
  ASSERT_TRUE(pipe.tipGuard().turnedOver());
  EXPECT_TRUE(pipe.controller().turnedOver());
  // Off: the controller's path is not bounded, whatever the guard saw.
  aic.tip_guard.enabled = false;
  pipe.setParams(aic, fdi);
  pipe.guardTip(base::Vector5::Zero(), 0.03, kH, true);
  EXPECT_TRUE(std::isinf(pipe.controller().referenceModel().tipBoundFront()));
  EXPECT_FALSE(pipe.controller().turnedOver());
  pipe.resetTipGuard();
  EXPECT_EQ(pipe.pitchBias().bias(), 0.0);
  EXPECT_EQ(pipe.tipGuard().trips(), 0u);
}

}  // namespace jackal_aic
