/**
 * \file test_frozen_joint_states.cpp
 * \brief gtest (no roscore) of the frozen joint-state check (include/jackal_aic/safety/frozen_joint_states.hpp;
 *        doc/jackal_aic_node.md, 'Frozen joint states'): single repeats of a healthy re-sampled
 *        stream never count, repeats while the wheels read as standing never count (at rest, or
 *        held by friction against a command), data that repeat with a wheel turning are frozen
 *        after kFrozenJointStateTime, and the verdict ends with new data. The ControlLoop's side (stale, zero command, the
 *        restart) is in test_control_loop.cpp; the closed loop behind jackal_node in
 *        test/sim/test_jackal_node_closed_loop.cpp.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "jackal_aic/safety/frozen_joint_states.hpp"

namespace jackal_aic
{
namespace
{
using Event = safety::FrozenJointStates::Event;
constexpr double kPeriod = 0.02;  // jackal_node's loop [s]

/// A sample stamped t of a robot driving at `speed` rad/s on both wheels, its data measured at travel_time.
safety::FrozenJointStates::Input driving(double t, double speed, double travel_time)
{
  safety::FrozenJointStates::Input in;
  in.stamp = t;
  in.travel = base::Vector2(speed * travel_time, speed * travel_time);
  in.has_travel = true;
  in.speed = base::Vector2(speed, speed);
  return in;
}

TEST(FrozenJointStates, RefusesBadSettings)
{
  EXPECT_THROW(safety::FrozenJointStates(0.0), std::invalid_argument);
  EXPECT_THROW(safety::FrozenJointStates(-0.1), std::invalid_argument);
  EXPECT_THROW(safety::FrozenJointStates(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(safety::FrozenJointStates(0.1, -1.0), std::invalid_argument);
  EXPECT_THROW(safety::FrozenJointStates(0.1, std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_NO_THROW(safety::FrozenJointStates(0.1, 0.0));
}

TEST(FrozenJointStates, NamedTimeIsAFewMcuPeriods)
{
  EXPECT_DOUBLE_EQ(safety::kFrozenJointStateTime, 0.1);
  EXPECT_GE(safety::kFrozenJointStateTime, 3.0 * kPeriod);
  EXPECT_DOUBLE_EQ(safety::FrozenJointStates().holdTime(), safety::kFrozenJointStateTime);
}

// A healthy re-sampled stream: every fourth cycle repeats the previous one (25 %, above the
// sampler's highest rate), for a minute of driving: never frozen.
TEST(FrozenJointStates, SingleRepeatsWhileDrivingNeverCount)
{
  safety::FrozenJointStates f;
  double source = 0.0;
  for (int k = 0; k < 3000; ++k)
  {
    const double t = k * kPeriod;
    if (k % 4 != 3)
    {
      source = t;  // a new MCU sample; else the same data again
    }
    EXPECT_EQ(f.update(driving(t, 10.0, source)), Event::kNone) << k;
    EXPECT_FALSE(f.frozen());
    EXPECT_LE(f.repeats(), 1u);
    EXPECT_LE(f.heldFor(), kPeriod + 1e-12);
  }
  EXPECT_EQ(f.events(), 0u);
}

// Even a run of four repeats (0.08 s of the same data) stays below the limit.
TEST(FrozenJointStates, RepeatsUpToTheLimitDoNotCount)
{
  safety::FrozenJointStates f;
  f.update(driving(0.0, 5.0, 0.0));
  for (int k = 1; k <= 5; ++k)
  {
    EXPECT_EQ(f.update(driving(k * kPeriod, 5.0, 0.0)), Event::kNone) << k;  // held for k periods <= 0.1 s
  }
  EXPECT_FALSE(f.frozen());
  EXPECT_NEAR(f.heldFor(), 0.1, 1e-12);
}

// The MCU freezes while driving: the same data with fresh stamps; frozen with the first sample
// more than kFrozenJointStateTime after the data's first, and for as long as they repeat.
TEST(FrozenJointStates, FreezeWhileDrivingIsFrozenAfterTheHoldTime)
{
  safety::FrozenJointStates f;
  for (int k = 0; k < 50; ++k)
  {
    f.update(driving(k * kPeriod, 8.0, k * kPeriod));
  }
  const double t_last = 49 * kPeriod;  // the last MCU sample
  int k = 50;
  Event e = Event::kNone;
  for (; e == Event::kNone && k < 100; ++k)
  {
    e = f.update(driving(k * kPeriod, 8.0, t_last));
  }
  EXPECT_EQ(e, Event::kFrozen);
  const double t_frozen = (k - 1) * kPeriod;
  EXPECT_GT(t_frozen - t_last, safety::kFrozenJointStateTime);
  EXPECT_LE(t_frozen - t_last, safety::kFrozenJointStateTime + kPeriod + 1e-12);
  EXPECT_TRUE(f.frozen());
  EXPECT_EQ(f.events(), 1u);
  for (int j = 0; j < 100; ++j, ++k)
  {
    EXPECT_EQ(f.update(driving(k * kPeriod, 8.0, t_last)), Event::kNone);  // still frozen
  }
  EXPECT_TRUE(f.frozen());
  // The MCU is back: new data end the verdict.
  EXPECT_EQ(f.update(driving(k * kPeriod, 7.9, k * kPeriod)), Event::kThawed);
  EXPECT_FALSE(f.frozen());
  EXPECT_EQ(f.events(), 1u);
}

// One wheel turning is enough; so is a wheel turning backwards.
TEST(FrozenJointStates, OneWheelTurningCounts)
{
  for (const double speed : { 0.06, -3.0 })
  {
    safety::FrozenJointStates f;
    safety::FrozenJointStates::Input in;
    in.has_travel = true;
    in.travel = base::Vector2(2.0, 1.0);
    in.speed = base::Vector2(0.0, speed);
    int k = 0;
    Event e = Event::kNone;
    for (; e == Event::kNone && k < 20; ++k)
    {
      in.stamp = k * kPeriod;
      e = f.update(in);
    }
    EXPECT_EQ(e, Event::kFrozen) << speed;
    EXPECT_EQ(k - 1, 6) << speed;  // 0.12 s > 0.1 s after the first
  }
}

// While the wheels read as standing (below kFrozenMotionSpeed) the data may repeat for ever: at
// rest, and also against a command (friction holding the wheels reads the same as feedback that
// froze at rest: not counted).
TEST(FrozenJointStates, StandingNeverCounts)
{
  safety::FrozenJointStates f;
  safety::FrozenJointStates::Input in;
  in.has_travel = true;
  in.travel = base::Vector2(3.0, -2.0);
  for (int k = 0; k < 5000; ++k)
  {
    in.stamp = k * kPeriod;
    in.speed = k < 2500 ? base::Vector2(0.0, 0.0) : base::Vector2(0.04, -0.05);
    const Event e = f.update(in);
    EXPECT_EQ(e, Event::kNone) << k;
  }
  EXPECT_FALSE(f.frozen());
  EXPECT_EQ(f.events(), 0u);
}

// Only exact repeats of both travel and speeds count: a change in the last bit of one wheel's
// travel or speed is new data.
TEST(FrozenJointStates, AnyChangeIsNewData)
{
  for (int which = 0; which < 4; ++which)
  {
    safety::FrozenJointStates f;
    safety::FrozenJointStates::Input in = driving(0.0, 6.0, 1.0);
    for (int k = 0; k < 100; ++k)
    {
      in.stamp = k * kPeriod;
      double* field = which == 0 ? &in.travel(0) :
                      which == 1 ? &in.travel(1) :
                      which == 2 ? &in.speed(0) :
                                   &in.speed(1);
      *field = std::nextafter(*field, 1e9);
      EXPECT_EQ(f.update(in), Event::kNone) << which << " " << k;
    }
    EXPECT_FALSE(f.frozen());
  }
}

// Without positions the speeds alone cannot tell a frozen MCU from a constant speed: no verdict.
TEST(FrozenJointStates, WithoutPositionsNoVerdict)
{
  safety::FrozenJointStates f;
  safety::FrozenJointStates::Input in = driving(0.0, 6.0, 1.0);
  in.has_travel = false;
  in.travel = base::Vector2::Zero();
  for (int k = 0; k < 100; ++k)
  {
    in.stamp = k * kPeriod;
    EXPECT_EQ(f.update(in), Event::kNone);
  }
  EXPECT_FALSE(f.frozen());
}

TEST(FrozenJointStates, ResetForgetsTheDataAndTheVerdict)
{
  safety::FrozenJointStates f;
  for (int k = 0; k < 10; ++k)
  {
    f.update(driving(k * kPeriod, 8.0, 0.0));
  }
  ASSERT_TRUE(f.frozen());
  f.reset();
  EXPECT_FALSE(f.frozen());
  EXPECT_EQ(f.repeats(), 0u);
  EXPECT_EQ(f.events(), 1u);                                  // counters kept
  EXPECT_EQ(f.update(driving(0.0, 8.0, 0.0)), Event::kNone);  // a first sample again
  EXPECT_FALSE(f.frozen());
}

TEST(FrozenJointStates, EventNames)
{
  EXPECT_STREQ(safety::toString(Event::kNone), "none");
  EXPECT_STREQ(safety::toString(Event::kFrozen), "frozen");
  EXPECT_STREQ(safety::toString(Event::kThawed), "thawed");
}

}  // namespace
}  // namespace jackal_aic
