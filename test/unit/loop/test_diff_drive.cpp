/**
 * \file test_diff_drive.cpp
 * \brief diff_drive_controller's mapping, its inverse, its limits and the node's cmd_vel
 *        output (include/jackal_aic/loop/diff_drive.hpp; doc/jackal.md, 'The stock velocity controller').
 */
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "jackal_aic/loop/diff_drive.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kWheelTol = 1e-9;  // rad/s: the round trip is exact up to rounding
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

TEST(DiffDrive, JackalDefaults)
{
  const params::DiffDriveParams p;
  EXPECT_EQ(p.wheel_radius, 0.098);
  EXPECT_NEAR(p.effectiveSeparation(), 1.5 * 0.37559, 1e-15);
  EXPECT_TRUE(p.validate().empty());
  // 1 m/s straight: both wheels 1 / 0.098 rad/s; 1 rad/s in place: +-s / (2 r).
  EXPECT_NEAR(loop::wheelsFromTwist(p, { 1.0, 0.0 })(0), 1.0 / 0.098, 1e-12);
  const base::Vector2 turn = loop::wheelsFromTwist(p, { 0.0, 1.0 });
  EXPECT_NEAR(turn(1), 1.5 * 0.37559 / 2.0 / 0.098, 1e-12);
  EXPECT_NEAR(turn(0), -turn(1), 1e-12);
}

TEST(DiffDrive, InverseRoundTripsThroughTheStockMappingWithinTheLimits)
{
  // 10 000 random twists within the velocity limits; a limiter with the stock acceleration
  // limits over one 50 Hz period, started at the previous twist, must leave each unchanged.
  const params::DiffDriveParams p;
  std::mt19937 rng(20221);
  std::uniform_real_distribution<double> v(-p.max_linear_velocity, p.max_linear_velocity);
  std::uniform_real_distribution<double> w(-p.max_angular_velocity, p.max_angular_velocity);
  loop::CmdVelOutput out(p);
  loop::DiffDriveLimiter stock(p);
  double worst = 0.0;
  for (int i = 0; i < 10000; ++i)
  {
    const loop::BodyTwist twist{ v(rng), w(rng) };
    const base::Vector2 wheels = loop::wheelsFromTwist(p, twist);  // an AIC command the stock controller can produce
    // Far apart random twists exceed the acceleration limits: start both at the previous state.
    out.reset(wheels);
    stock.reset(loop::twistFromWheels(p, wheels));
    const loop::CmdVelOutput::Result r = out.convert(wheels, 0.02);
    ASSERT_FALSE(r.clipped) << i;
    const base::Vector2 back = loop::wheelsFromTwist(p, stock.limit(r.twist, 0.02));
    worst = std::max(worst, (back - wheels).cwiseAbs().maxCoeff());
    EXPECT_EQ(r.wheels, wheels);
  }
  EXPECT_LT(worst, kWheelTol) << "largest |wheel error| " << worst << " rad/s";
  // A sequence of commands that change within the acceleration limits (a random walk at
  // 50 Hz) is never reported clipped: rounding is no limit acting.
  loop::CmdVelOutput walk(p);
  walk.reset(base::Vector2::Zero());
  stock.reset(loop::BodyTwist{});
  loop::BodyTwist t{ 0.0, 0.0 };
  std::uniform_real_distribution<double> dv(-0.3, 0.3), dw(-0.4, 0.4);  // < 0.4 m/s, 0.5 rad/s per 20 ms
  for (int i = 0; i < 10000; ++i)
  {
    t.linear = std::clamp(t.linear + dv(rng), -p.max_linear_velocity, p.max_linear_velocity);
    t.angular = std::clamp(t.angular + dw(rng), -p.max_angular_velocity, p.max_angular_velocity);
    const base::Vector2 wheels = loop::wheelsFromTwist(p, t);
    const loop::CmdVelOutput::Result r = walk.convert(wheels, 0.02);
    ASSERT_FALSE(r.clipped) << i;
    const base::Vector2 back = loop::wheelsFromTwist(p, stock.limit(r.twist, 0.02));
    ASSERT_LT((back - wheels).cwiseAbs().maxCoeff(), kWheelTol) << i;
  }
  EXPECT_EQ(walk.clips(), 0u);
  // The inverse alone, without limits: exact for any twist.
  for (int i = 0; i < 1000; ++i)
  {
    const loop::BodyTwist t{ 10.0 * v(rng), 10.0 * w(rng) };
    const loop::BodyTwist back = loop::twistFromWheels(p, loop::wheelsFromTwist(p, t));
    EXPECT_NEAR(back.linear, t.linear, 1e-12);
    EXPECT_NEAR(back.angular, t.angular, 1e-12);
  }
}

TEST(DiffDrive, VelocityLimitClipsAndReportsTheStockControllersCommand)
{
  const params::DiffDriveParams p;
  loop::CmdVelOutput out(p);
  out.reset(base::Vector2(2.0 / 0.098, 2.0 / 0.098));  // at the limit, so only the velocity limit acts
  // 25 rad/s = 2.45 m/s > 2.0 m/s: clipped to 2.0 m/s, the wheel command fed back is 2.0 / r.
  const loop::CmdVelOutput::Result r = out.convert(base::Vector2(25.0, 25.0), 0.02);
  EXPECT_TRUE(r.clipped);
  EXPECT_DOUBLE_EQ(r.twist.linear, 2.0);
  EXPECT_NEAR(r.wheels(0), 2.0 / 0.098, 1e-12);
  EXPECT_NEAR(r.wheels(1), 2.0 / 0.098, 1e-12);
  EXPECT_EQ(out.clips(), 1u);
}

TEST(DiffDrive, AccelerationLimitClips)
{
  const params::DiffDriveParams p;
  loop::CmdVelOutput out(p);
  out.reset(base::Vector2::Zero());
  // From rest to 1 m/s in one 20 ms period: at most 20 m/s^2 * 0.02 s = 0.4 m/s.
  const loop::CmdVelOutput::Result r = out.convert(loop::wheelsFromTwist(p, { 1.0, 0.0 }), 0.02);
  EXPECT_TRUE(r.clipped);
  EXPECT_NEAR(r.twist.linear, 0.4, 1e-12);
  EXPECT_NEAR(r.wheels(0), 0.4 / 0.098, 1e-12);
  // In place, 25 rad/s^2 * 0.02 s = 0.5 rad/s.
  out.reset(base::Vector2::Zero());
  EXPECT_NEAR(out.convert(loop::wheelsFromTwist(p, { 0.0, 2.0 }), 0.02).twist.angular, 0.5, 1e-12);
}

TEST(DiffDrive, NonFiniteInputGivesAFiniteBoundedCommand)
{
  loop::CmdVelOutput out;
  const loop::CmdVelOutput::Result r = out.convert(base::Vector2(kNan, std::numeric_limits<double>::infinity()), 0.02);
  EXPECT_TRUE(r.non_finite);
  EXPECT_TRUE(std::isfinite(r.twist.linear) && std::isfinite(r.twist.angular));
  EXPECT_TRUE(r.wheels.allFinite());
  EXPECT_EQ(r.twist.linear, 0.0);
  EXPECT_EQ(r.twist.angular, 0.0);
  // A non-finite dt is taken as 0: no change allowed.
  loop::DiffDriveLimiter l;
  EXPECT_EQ(l.limit({ 1.0, 1.0 }, kNan).linear, 0.0);
}

TEST(DiffDrive, TheLimiterTakesANonFiniteTargetAsZero)
{
  // The limiter's own guard, reached directly (CmdVelOutput guards its wheel speeds before it):
  // from a finite state, a non-finite target moves toward zero within the acceleration limit and
  // leaves a finite state behind.
  loop::DiffDriveLimiter l;
  const double inf = std::numeric_limits<double>::infinity();
  for (const loop::BodyTwist& target :
       { loop::BodyTwist{ kNan, 0.2 }, loop::BodyTwist{ 0.5, inf }, loop::BodyTwist{ -inf, kNan } })
  {
    l.reset({ 0.5, 0.2 });
    const loop::BodyTwist out = l.limit(target, 1.0);  // 1 s: every limit allows the full step to zero
    EXPECT_TRUE(std::isfinite(out.linear) && std::isfinite(out.angular));
    EXPECT_EQ(out.linear, std::isfinite(target.linear) ? target.linear : 0.0);
    EXPECT_EQ(out.angular, std::isfinite(target.angular) ? target.angular : 0.0);
    EXPECT_TRUE(std::isfinite(l.limit({ 0.0, 0.0 }, 0.02).linear)) << "the state stayed finite";
  }
}

TEST(DiffDrive, InvalidParametersAreNamed)
{
  params::DiffDriveParams p;
  p.wheel_radius = 0.0;
  p.max_angular_acceleration = kNan;
  const auto e = p.validate();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0], "wheel_radius = 0 (allowed: > 0, finite)");
  EXPECT_EQ(e[1], "max_angular_acceleration = nan (allowed: > 0, finite)");
  EXPECT_THROW(loop::CmdVelOutput{ p }, std::invalid_argument);
}
}  // namespace
}  // namespace jackal_aic
