/**
 * \file test_ros_clock.cpp
 * \brief gtest (no roscore): the node's RosClock (include/jackal_aic/ros/aic_node.hpp) takes
 *        any message stamp, up to the largest ROS time (uint32 seconds), without throwing, and
 *        maps clock readings back to ROS time exactly, clamped to [0, the largest ROS time].
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "jackal_aic/ros/aic_node.hpp"

namespace jackal_aic
{
namespace
{
const ros::Time kMaxTime(std::numeric_limits<std::uint32_t>::max(), 999999999);

TEST(RosClock, AnyStampIsFiniteSecondsWithoutThrowing)
{
  node::RosClock clock;
  clock.start();
  const double now = ros::Time::now().toSec();
  double far = 0.0;
  ASSERT_NO_THROW(far = clock.seconds(kMaxTime));  // > 2^31 s after the epoch: beyond ros::Duration
  EXPECT_TRUE(std::isfinite(far));
  EXPECT_NEAR(far, 4294967296.0 - now, 1.0);
  EXPECT_TRUE(std::isnan(clock.seconds(ros::Time(0))));  // unset
  EXPECT_NEAR(clock.seconds(ros::Time(0, 1)), -now, 1.0);
  EXPECT_TRUE(std::isfinite(clock.now()));
}

TEST(RosClock, TimeIsTheInverseOfSecondsAndClamped)
{
  node::RosClock clock;
  clock.start();
  const ros::Time later = ros::Time::now() + ros::Duration(1, 234567891);
  EXPECT_EQ(clock.time(clock.seconds(later)), later);  // to the nanosecond
  // ~1.8e9 s before the epoch: a double's resolution there is 2^-22 s (~0.24 us)
  EXPECT_NEAR((clock.time(clock.seconds(ros::Time(5, 0))) - ros::Time(5, 0)).toSec(), 0.0, 1e-6);
  ros::Time t;
  ASSERT_NO_THROW(t = clock.time(clock.seconds(kMaxTime)));
  EXPECT_LE(t, kMaxTime);
  EXPECT_NEAR((kMaxTime - t).toSec(), 0.0, 1e-6);  // a double's resolution at ~2.5e9 s: 2^-21 s
  EXPECT_EQ(clock.time(1.0e12), kMaxTime);
  EXPECT_EQ(clock.time(std::numeric_limits<double>::infinity()), kMaxTime);
  EXPECT_EQ(clock.time(-1.0e12), ros::Time(0));
  EXPECT_EQ(clock.time(std::numeric_limits<double>::quiet_NaN()), ros::Time(0));
  EXPECT_EQ(clock.time(-std::numeric_limits<double>::infinity()), ros::Time(0));
}

}  // namespace
}  // namespace jackal_aic

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::Time::init();  // wall time, no roscore
  return RUN_ALL_TESTS();
}
