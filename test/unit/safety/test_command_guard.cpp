/**
 * \file test_command_guard.cpp
 * \brief gtests of the last guard of the wheel command (jackal_aic/safety/command_guard.hpp), reached
 *        directly: the controller clamps its own action first, so through the controller this
 *        guard is never exercised.
 */
#include <gtest/gtest.h>

#include <limits>

#include "jackal_aic/safety/command_guard.hpp"

namespace jackal_aic
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(CommandGuard, FiniteCommandsWithinTheLimitPassUnchanged)
{
  const safety::GuardedWheels g = safety::guardWheelCommand(base::Vector2(3.0, -19.9), 20.0);
  EXPECT_EQ(g.wheels, base::Vector2(3.0, -19.9));
  EXPECT_FALSE(g.replaced);
  EXPECT_FALSE(g.clamped);
}

TEST(CommandGuard, CommandsBeyondTheLimitAreClampedPerWheel)
{
  const safety::GuardedWheels g = safety::guardWheelCommand(base::Vector2(1.0e9, -25.0), 20.0);
  EXPECT_EQ(g.wheels, base::Vector2(20.0, -20.0));
  EXPECT_TRUE(g.clamped);
  EXPECT_FALSE(g.replaced);
  const safety::GuardedWheels one = safety::guardWheelCommand(base::Vector2(5.0, 21.0), 20.0);
  EXPECT_EQ(one.wheels, base::Vector2(5.0, 20.0));  // only the wheel beyond the limit changes
}

TEST(CommandGuard, NonFiniteCommandsBecomeZeroOnBothWheels)
{
  for (const base::Vector2& bad :
       { base::Vector2(kNaN, 1.0), base::Vector2(1.0, kNaN), base::Vector2(kInf, 0.0), base::Vector2(0.0, -kInf) })
  {
    const safety::GuardedWheels g = safety::guardWheelCommand(bad, 20.0);
    EXPECT_EQ(g.wheels, base::Vector2::Zero()) << bad.transpose();
    EXPECT_TRUE(g.replaced);
  }
}

TEST(CommandGuard, AnInvalidLimitNeverLetsACommandThrough)
{
  for (const double limit : { kNaN, kInf, 0.0, -1.0 })
  {
    const safety::GuardedWheels g = safety::guardWheelCommand(base::Vector2(1.0, -1.0), limit);
    EXPECT_EQ(g.wheels, base::Vector2::Zero()) << limit;
    EXPECT_TRUE(g.replaced);
  }
}

}  // namespace
}  // namespace jackal_aic
