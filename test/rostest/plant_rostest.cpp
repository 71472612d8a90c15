/**
 * \file plant_rostest.cpp
 * \brief rostest scenarios for jackal_plant_node (one .test file per scenario selects one
 *        test with --gtest_filter; expectations come in as private <param>s).
 *
 * Shared fixture: subscribes /joint_states, /imu/data, /odom; publishes /cmd_drive at
 * 50 Hz from a background timer. Assertions use message stamps (plant time), never
 * sleeps alone; waits are bounded by generous wall-clock limits.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <jackal_msgs/Drive.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sys/wait.h>
#include <unistd.h>

namespace
{
struct OdomSample
{
  double t, vx, vy, wz, x, y;
};

class PlantRosTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    pnh_ = ros::NodeHandle("~");
    odom_sub_ = nh_.subscribe("odom", 1000, &PlantRosTest::onOdom, this);
    js_sub_ = nh_.subscribe("joint_states", 1000, &PlantRosTest::onJointStates, this);
    imu_sub_ = nh_.subscribe("imu/data", 5000, &PlantRosTest::onImu, this);
    drive_pub_ = nh_.advertise<jackal_msgs::Drive>("cmd_drive", 10);
    timer_ = nh_.createWallTimer(ros::WallDuration(0.02), &PlantRosTest::onTimer, this);
  }

  double param(const std::string& name)
  {
    double v = NAN;
    EXPECT_TRUE(pnh_.getParam(name, v)) << "missing test parameter ~" << name;
    return v;
  }

  void command(int mode, double left, double right)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    mode_ = mode;
    left_ = left;
    right_ = right;
  }

  /// Wait (wall clock, bounded) until pred() is true; returns pred().
  template <typename Pred>
  bool waitFor(Pred pred, double wall_limit)
  {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(wall_limit);
    while (ros::ok() && ros::WallTime::now() < end)
    {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (pred())
        {
          return true;
        }
      }
      ros::WallDuration(0.01).sleep();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    return pred();
  }

  /// Latest odom stamp [s] (0 if none yet); caller holds no lock.
  double lastOdomStamp()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return odom_.empty() ? 0.0 : odom_.back().t;
  }

  /// Wait until /odom stamps reach t_end [s].
  bool waitUntilStamp(double t_end, double wall_limit)
  {
    return waitFor([&] { return !odom_.empty() && odom_.back().t >= t_end; }, wall_limit);
  }

  /// Odom samples with stamp in [t0, t1].
  std::vector<OdomSample> odomBetween(double t0, double t1)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<OdomSample> out;
    for (const auto& s : odom_)
    {
      if (s.t >= t0 && s.t <= t1)
      {
        out.push_back(s);
      }
    }
    return out;
  }

  void onOdom(const nav_msgs::Odometry::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    odom_.push_back({ m->header.stamp.toSec(), m->twist.twist.linear.x, m->twist.twist.linear.y,
                      m->twist.twist.angular.z, m->pose.pose.position.x, m->pose.pose.position.y });
  }
  void onJointStates(const sensor_msgs::JointState::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    js_stamps_.push_back(m->header.stamp.toSec());
    js_wall_.push_back(ros::WallTime::now().toSec());
    js_names_ = m->name;
  }
  void onImu(const sensor_msgs::Imu::ConstPtr& m)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    imu_.push_back(*m);
    imu_wall_.push_back(ros::WallTime::now().toSec());
  }
  void onTimer(const ros::WallTimerEvent&)
  {
    jackal_msgs::Drive d;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (mode_ == kSilent)
      {
        return;
      }
      d.mode = static_cast<int8_t>(mode_);
      d.drivers[0] = static_cast<float>(left_);
      d.drivers[1] = static_cast<float>(right_);
    }
    drive_pub_.publish(d);
  }

  void TearDown() override
  {
    // Stop callbacks before the data they write is destroyed.
    timer_.stop();
    odom_sub_.shutdown();
    js_sub_.shutdown();
    imu_sub_.shutdown();
    ros::WallDuration(0.1).sleep();
  }

  static constexpr int kSilent = 100;
  // Data first: members are destroyed in reverse order, so the ROS handles go first.
  std::mutex mutex_;
  int mode_ = kSilent;
  double left_ = 0.0, right_ = 0.0;
  std::vector<OdomSample> odom_;
  std::vector<double> js_stamps_, js_wall_, imu_wall_;
  std::vector<std::string> js_names_;
  std::vector<sensor_msgs::Imu> imu_;
  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  ros::Subscriber odom_sub_, js_sub_, imu_sub_;
  ros::Publisher drive_pub_;
  ros::WallTimer timer_;
};

constexpr double kStartupWall = 30.0;  // s of wall time allowed for the plant to come up

double mean(const std::vector<double>& v)
{
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

double stddev(const std::vector<double>& v)
{
  const double m = mean(v);
  double s = 0.0;
  for (double x : v)
  {
    s += (x - m) * (x - m);
  }
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

/// Constant drive omega on both sides -> steady body speed r omega within tolerance.
TEST_F(PlantRosTest, ConstantDrive)
{
  const double omega = param("omega");             // rad/s
  const double r = param("wheel_radius");          // m
  const double tol = param("relative_tolerance");  // -
  const double settle = param("settle_time");      // s of plant time
  const double window = param("measure_time");     // s of plant time
  ASSERT_TRUE(waitFor([&] { return !odom_.empty(); }, kStartupWall)) << "no /odom from the plant";
  command(jackal_msgs::Drive::MODE_VELOCITY, omega, omega);
  const double t0 = lastOdomStamp();
  ASSERT_TRUE(waitUntilStamp(t0 + settle + window, 4.0 * (settle + window) + 10.0));
  const auto s = odomBetween(t0 + settle, t0 + settle + window);
  ASSERT_GT(s.size(), 10u);
  std::vector<double> v;
  for (const auto& o : s)
  {
    v.push_back(o.vx);
  }
  const double expected = r * omega;
  EXPECT_NEAR(mean(v), expected, tol * std::abs(expected)) << "steady body speed vs r*omega";
  EXPECT_LT(std::abs(s.back().wz), 0.05) << "a straight drive should not turn [rad/s]";
}

/// Opposite drives -> turns in place: yaw rate with the sign of (right - left), little
/// translation.
TEST_F(PlantRosTest, TurnInPlace)
{
  const double omega = param("omega");
  const double min_yaw_rate = param("min_yaw_rate");    // rad/s
  const double max_linear = param("max_linear_speed");  // m/s
  const double max_drift = param("max_drift");          // m
  const double settle = param("settle_time");
  const double window = param("measure_time");
  ASSERT_TRUE(waitFor([&] { return !odom_.empty(); }, kStartupWall));
  command(jackal_msgs::Drive::MODE_VELOCITY, -omega, omega);  // right forward: counter-clockwise
  const double t0 = lastOdomStamp();
  ASSERT_TRUE(waitUntilStamp(t0 + settle + window, 4.0 * (settle + window) + 10.0));
  const auto s = odomBetween(t0 + settle, t0 + settle + window);
  ASSERT_GT(s.size(), 10u);
  std::vector<double> wz, speed;
  for (const auto& o : s)
  {
    wz.push_back(o.wz);
    speed.push_back(std::hypot(o.vx, o.vy));
  }
  EXPECT_GT(mean(wz), min_yaw_rate);
  EXPECT_LT(mean(speed), max_linear);
  EXPECT_LT(std::hypot(s.back().x - s.front().x, s.back().y - s.front().y), max_drift);
}

/// /joint_states and /imu/data at the expected rate (stamps, and arrival over wall time).
TEST_F(PlantRosTest, SensorRates)
{
  const double rate = param("expected_rate");  // Hz
  const double tol = param("relative_tolerance");
  const double duration = param("measure_time");  // s of plant time
  // The plant's node.real_time_factor (plant seconds per wall second): arrivals on the wall clock
  // come at rate x rtf, and plant time advances rtf per wall second.
  double rtf = 1.0;
  pnh_.param("real_time_factor", rtf, rtf);
  ASSERT_GT(rtf, 0.0);
  ASSERT_TRUE(waitFor([&] { return js_stamps_.size() > 5 && imu_.size() > 5; }, kStartupWall + 6.0 / (rate * rtf)));
  std::size_t js0, imu0;
  double js_wall0, imu_wall0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    js0 = js_stamps_.size() - 1;
    imu0 = imu_.size() - 1;
    js_wall0 = js_wall_.back();
    imu_wall0 = imu_wall_.back();
  }
  ASSERT_TRUE(waitFor([&] { return js_stamps_.back() - js_stamps_[js0] >= duration; }, 3.0 * duration / rtf + 10.0));
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t js_n = js_stamps_.size() - 1 - js0;
  const double js_span = js_stamps_.back() - js_stamps_[js0];
  EXPECT_NEAR(js_n / js_span, rate, tol * rate) << "joint_states rate from stamps";
  EXPECT_NEAR(js_n / (js_wall_.back() - js_wall0), rate * rtf, tol * rate * rtf) << "joint_states arrival rate (wall)";
  for (std::size_t k = js0 + 1; k < js_stamps_.size(); ++k)
  {
    ASSERT_GT(js_stamps_[k], js_stamps_[k - 1]) << "joint_states stamps must increase";
  }
  const std::size_t imu_n = imu_.size() - 1 - imu0;
  const double imu_span = imu_.back().header.stamp.toSec() - imu_[imu0].header.stamp.toSec();
  EXPECT_NEAR(imu_n / imu_span, rate, tol * rate) << "imu rate from stamps";
  EXPECT_NEAR(imu_n / (imu_wall_.back() - imu_wall0), rate * rtf, tol * rate * rtf) << "imu arrival rate (wall)";
  // Plant time keeps pace with wall time, scaled by the real-time factor.
  EXPECT_NEAR(js_span / (js_wall_.back() - js_wall0), rtf, tol * rtf) << "plant time vs wall time";
  ASSERT_EQ(js_names_.size(), 4u);
  EXPECT_EQ(js_names_[0], "front_left_wheel");
  EXPECT_EQ(js_names_[1], "front_right_wheel");
  EXPECT_EQ(js_names_[2], "rear_left_wheel");
  EXPECT_EQ(js_names_[3], "rear_right_wheel");
}

/// IMU noise standard deviation within tolerance of the configured one, at rest.
TEST_F(PlantRosTest, ImuNoise)
{
  const double gyro_std = param("gyro_noise_std");    // rad/s, as configured
  const double accel_std = param("accel_noise_std");  // m/s^2, as configured
  const double tol = param("relative_tolerance");
  const int samples = static_cast<int>(param("samples"));
  const double gravity = param("gravity");
  ASSERT_TRUE(waitFor([&] { return imu_.size() > 50; }, kStartupWall));
  std::size_t first;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    first = imu_.size();
  }
  ASSERT_TRUE(waitFor([&] { return imu_.size() >= first + samples; }, 60.0));
  std::lock_guard<std::mutex> lock(mutex_);
  std::array<std::vector<double>, 3> g, a;
  for (std::size_t k = first; k < first + samples; ++k)
  {
    g[0].push_back(imu_[k].angular_velocity.x);
    g[1].push_back(imu_[k].angular_velocity.y);
    g[2].push_back(imu_[k].angular_velocity.z);
    a[0].push_back(imu_[k].linear_acceleration.x);
    a[1].push_back(imu_[k].linear_acceleration.y);
    a[2].push_back(imu_[k].linear_acceleration.z);
  }
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_NEAR(stddev(g[i]), gyro_std, tol * gyro_std) << "gyro axis " << i;
    EXPECT_NEAR(stddev(a[i]), accel_std, tol * accel_std) << "accel axis " << i;
  }
  EXPECT_NEAR(mean(a[2]), gravity, 5.0 * accel_std / std::sqrt(samples) + 0.01) << "specific force at rest";
}

/// MODE_NONE after driving: the robot coasts to rest and stays there.
TEST_F(PlantRosTest, ModeNoneCoasts)
{
  const double omega = param("omega");
  const double drive_time = param("drive_time");  // s
  const double coast_time = param("coast_time");  // s allowed to come to rest
  const double rest_speed = param("rest_speed");  // m/s
  ASSERT_TRUE(waitFor([&] { return !odom_.empty(); }, kStartupWall));
  command(jackal_msgs::Drive::MODE_VELOCITY, omega, omega);
  const double t0 = lastOdomStamp();
  ASSERT_TRUE(waitUntilStamp(t0 + drive_time, 4.0 * drive_time + 10.0));
  const double moving = odomBetween(t0 + drive_time - 0.1, t0 + drive_time).back().vx;
  EXPECT_GT(moving, 0.5 * 0.098 * omega) << "the robot should be moving before the release";
  command(jackal_msgs::Drive::MODE_NONE, omega, omega);  // drivers must be ignored
  const double t1 = lastOdomStamp();
  ASSERT_TRUE(waitUntilStamp(t1 + coast_time + 1.0, 4.0 * (coast_time + 1.0) + 10.0));
  const auto s = odomBetween(t1, t1 + coast_time + 1.0);
  ASSERT_GT(s.size(), 10u);
  // Decelerates right after the release (no drive), then rests.
  EXPECT_LT(odomBetween(t1 + 0.2, t1 + 0.3).front().vx, moving);
  for (const auto& o : odomBetween(t1 + coast_time, t1 + coast_time + 1.0))
  {
    EXPECT_LT(std::abs(o.vx), rest_speed) << "at t = " << o.t - t1 << " s after the release";
  }
  // It coasted (travelled some distance), it was not braked to a stop at once.
  EXPECT_GT(s.back().x - s.front().x, 0.01);
}

/// stock_controller_node on the plant: a linear set point gives that body speed (open loop,
/// the plant has little longitudinal slip) and cmd_drive streams at 50 Hz.
TEST_F(PlantRosTest, StockControllerTracksSetPoint)
{
  const double v = param("set_point");  // m/s
  const double tol = param("relative_tolerance");
  const double settle = param("settle_time");   // s of plant time
  const double window = param("measure_time");  // s of plant time
  ros::Publisher sp = nh_.advertise<geometry_msgs::Twist>("jackal_AIC/set_point", 10);
  std::vector<double> drive_wall;
  std::mutex drive_mutex;
  ros::Subscriber drive_sub =
      nh_.subscribe<jackal_msgs::Drive>("cmd_drive", 100, [&](const jackal_msgs::Drive::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(drive_mutex);
        if (m->mode == jackal_msgs::Drive::MODE_VELOCITY)
        {
          drive_wall.push_back(ros::WallTime::now().toSec());
        }
      });
  ASSERT_TRUE(waitFor([&] { return !odom_.empty(); }, kStartupWall));
  const double t0 = lastOdomStamp();
  geometry_msgs::Twist twist;
  twist.linear.x = v;
  // Stream the set point at 20 Hz (the stock controller times out after 0.25 s).
  while (ros::ok() && lastOdomStamp() < t0 + settle + window)
  {
    sp.publish(twist);
    ros::WallDuration(0.05).sleep();
  }
  const auto s = odomBetween(t0 + settle, t0 + settle + window);
  ASSERT_GT(s.size(), 10u);
  std::vector<double> vx;
  for (const auto& o : s)
  {
    vx.push_back(o.vx);
  }
  EXPECT_NEAR(mean(vx), v, tol * v);
  drive_sub.shutdown();
  std::lock_guard<std::mutex> lock(drive_mutex);
  ASSERT_GT(drive_wall.size(), 20u);
  // A rate check on the wall clock (as rostest's hztest): arrivals over the run.
  const double expected_rate = param("expected_rate");  // Hz
  const double rate = (drive_wall.size() - 1) / (drive_wall.back() - drive_wall.front());
  EXPECT_NEAR(rate, expected_rate, param("rate_tolerance") * expected_rate) << "cmd_drive rate [Hz]";
}

/// A bad URDF path: the node exits non-zero and names the path.
TEST_F(PlantRosTest, BadUrdfExitsNonZero)
{
  std::string bad, config;
  ASSERT_TRUE(pnh_.getParam("bad_urdf", bad));
  ASSERT_TRUE(pnh_.getParam("plant_config", config));
  // The plant node is built next to this test executable (devel/lib/jackal_aic).
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  ASSERT_GT(n, 0);
  self[n] = '\0';
  std::string dir(self);
  dir = dir.substr(0, dir.rfind('/'));
  const std::string cmd =
      dir + "/jackal_plant_node __name:=jackal_plant_bad_urdf _urdf:=" + bad + " _plant_config:=" + config + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string output;
  char buf[512];
  while (fgets(buf, sizeof(buf), p))
  {
    output += buf;
  }
  const int status = pclose(p);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_NE(WEXITSTATUS(status), 0) << output;
  EXPECT_NE(output.find(bad), std::string::npos) << "the log must name the path; got:\n" << output;
}
}  // namespace

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "plant_rostest");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int r = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return r;
}
