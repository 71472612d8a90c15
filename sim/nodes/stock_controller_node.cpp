/**
 * \file stock_controller_node.cpp
 * \brief The stock controller node's ROS wiring (stock_controller_node.hpp).
 */
#include "stock_controller_node.hpp"

#include <cmath>

#include <jackal_msgs/Drive.h>
#include <jackal_msgs/Feedback.h>
#include <jackal_msgs/Status.h>
#include <nav_msgs/Odometry.h>

namespace jackal_aic
{
namespace sim_nodes
{
namespace
{
/// jackal_msgs/Status is published at least this often [s] (the MCU's 1 Hz).
constexpr double kStatusPeriod = 1.0;
/// ~cycle_on_joint_states: the timer runs the cycle after this many periods without joint states.
constexpr double kFallbackPeriods = 1.5;

}  // namespace

StockControllerNode::StockControllerNode(ros::NodeHandle nh, ros::NodeHandle pnh)
  : controller_(readParams(pnh)), odometry_(makeOdometry())
{
  const std::string input = pnh.param<std::string>("input_topic", "jackal_AIC/set_point");
  publish_odom_ = pnh.param("publish_odom", false);
  publish_mcu_ = pnh.param("publish_mcu_state", false);
  cycle_on_joint_states_ = pnh.param("cycle_on_joint_states", false);
  stopped_ = pnh.param("stop", false);
  left_joints_ = pnh.param<std::vector<std::string>>("left_joints", { "front_left_wheel", "rear_left_wheel" });
  right_joints_ = pnh.param<std::vector<std::string>>("right_joints", { "front_right_wheel", "rear_right_wheel" });
  pub_ = nh.advertise<jackal_msgs::Drive>("cmd_drive", 10);
  sub_ = nh.subscribe(input, 10, &StockControllerNode::onCommand, this, ros::TransportHints().tcpNoDelay());
  if (publish_odom_)
  {
    odom_pub_ = nh.advertise<nav_msgs::Odometry>("jackal_velocity_controller/odom", 10);
  }
  if (publish_odom_ || cycle_on_joint_states_)
  {
    joint_sub_ =
        nh.subscribe("joint_states", 10, &StockControllerNode::onJointState, this, ros::TransportHints().tcpNoDelay());
  }
  if (publish_mcu_)
  {
    status_pub_ = nh.advertise<jackal_msgs::Status>("status", 1, true);
    feedback_pub_ = nh.advertise<jackal_msgs::Feedback>("feedback", 10);
    stop_sub_ = pnh.subscribe("set_stop", 10, &StockControllerNode::onSetStop, this);
    status_timer_ = nh.createTimer(ros::Duration(kStatusPeriod), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      publishStatus();
    });
    publishStatus();
  }
  timer_ = nh.createTimer(ros::Duration(1.0 / controller_.params().publish_rate), &StockControllerNode::onTimer, this);
  ROS_INFO("stock_controller: diff_drive mapping, separation %.5f m x %.2f, radius %.3f m, %.1f Hz%s, input %s%s%s",
           controller_.params().wheel_separation, controller_.params().wheel_separation_multiplier,
           controller_.params().wheel_radius, controller_.params().publish_rate,
           cycle_on_joint_states_ ? " (cycle on joint_states)" : "", sub_.getTopic().c_str(),
           publish_odom_ ? ", odometry" : "", publish_mcu_ ? ", /status and /feedback" : "");
}

harness::DiffDriveOdometry StockControllerNode::makeOdometry() const
{
  return harness::DiffDriveOdometry(controller_.params().wheel_separation *
                                        controller_.params().wheel_separation_multiplier,
                                    controller_.params().wheel_radius);
}

harness::StockControllerParams StockControllerNode::readParams(const ros::NodeHandle& pnh)
{
  harness::StockControllerParams p;
  pnh.param("wheel_separation", p.wheel_separation, p.wheel_separation);
  pnh.param("wheel_separation_multiplier", p.wheel_separation_multiplier, p.wheel_separation_multiplier);
  pnh.param("wheel_radius", p.wheel_radius, p.wheel_radius);
  pnh.param("max_linear_velocity", p.max_linear_velocity, p.max_linear_velocity);
  pnh.param("max_linear_acceleration", p.max_linear_acceleration, p.max_linear_acceleration);
  pnh.param("max_angular_velocity", p.max_angular_velocity, p.max_angular_velocity);
  pnh.param("max_angular_acceleration", p.max_angular_acceleration, p.max_angular_acceleration);
  pnh.param("cmd_vel_timeout", p.cmd_vel_timeout, p.cmd_vel_timeout);
  pnh.param("publish_rate", p.publish_rate, p.publish_rate);
  return p;
}

void StockControllerNode::checkClock()
{
  const ros::Time now = ros::Time::now();
  const double back = time_jump_.observe(now.toSec());
  if (back > 0.0)
  {
    controller_.restartTimeline(now.toSec());
    last_cycle_ = ros::Time(0);
    last_odom_ = ros::Time(0);
    ROS_WARN("stock_controller: ROS time moved back %.3f s; the diff drive and the odometry continue on the new "
             "timeline [%lu jump(s) back so far]",
             back, static_cast<unsigned long>(time_jump_.jumps()));
  }
}

void StockControllerNode::onCommand(const geometry_msgs::Twist::ConstPtr& msg)
{
  std::lock_guard<std::mutex> lock(mutex_);
  checkClock();
  if (!controller_.setCommand(msg->linear.x, msg->angular.z, ros::Time::now().toSec()))
  {
    ROS_WARN_THROTTLE(1.0, "stock_controller: dropped non-finite command (%f, %f)", msg->linear.x, msg->angular.z);
  }
}

void StockControllerNode::onSetStop(const std_msgs::Bool::ConstPtr& msg)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (msg->data != stopped_)
  {
    stopped_ = msg->data;
    ROS_WARN("stock_controller: stop %s", stopped_ ? "ENGAGED: motors released (MODE_NONE)" : "released");
    publishStatus();  // at once, like the MCU on a change of the run/stop loop
  }
}

bool StockControllerNode::meanField(const sensor_msgs::JointState& js, const std::vector<double>& field,
                                    const std::vector<std::string>& names, double* out)
{
  double sum = 0.0;
  for (const auto& n : names)
  {
    bool found = false;
    for (std::size_t i = 0; i < js.name.size() && i < field.size(); ++i)
    {
      if (js.name[i] == n && std::isfinite(field[i]))
      {
        sum += field[i];
        found = true;
        break;
      }
    }
    if (!found)
    {
      return false;
    }
  }
  *out = sum / static_cast<double>(names.size());
  return !names.empty();
}

void StockControllerNode::onJointState(const sensor_msgs::JointState::ConstPtr& msg)
{
  if (cycle_on_joint_states_)
  {
    cycle();  // this cycle's /cmd_drive from the commands received before these joint states
  }
  if (!publish_odom_)
  {
    return;
  }
  double pl = 0.0, pr = 0.0;
  if (!meanField(*msg, msg->position, left_joints_, &pl) || !meanField(*msg, msg->position, right_joints_, &pr))
  {
    ROS_WARN_THROTTLE(1.0, "stock_controller: joint_states without finite positions of the wheel joints");
    return;
  }
  const ros::Time stamp = msg->header.stamp;
  const bool back = !last_odom_.isZero() && stamp < last_odom_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    checkClock();
  }
  if (back)
  {
    // A new timeline: the odometry starts afresh from the pose reached (kept as the offset).
    const double c = std::cos(heading_offset_), s = std::sin(heading_offset_);
    x_offset_ += c * odometry_.x() - s * odometry_.y();
    y_offset_ += s * odometry_.x() + c * odometry_.y();
    heading_offset_ += odometry_.heading();
    odometry_ = makeOdometry();
  }
  odometry_.update(pl, pr, stamp.toSec());
  last_odom_ = stamp;
  const double c = std::cos(heading_offset_), s = std::sin(heading_offset_);
  const double heading = heading_offset_ + odometry_.heading();
  nav_msgs::Odometry odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = "odom";
  odom.child_frame_id = "base_link";
  odom.pose.pose.position.x = x_offset_ + c * odometry_.x() - s * odometry_.y();
  odom.pose.pose.position.y = y_offset_ + s * odometry_.x() + c * odometry_.y();
  odom.pose.pose.orientation.z = std::sin(heading / 2.0);
  odom.pose.pose.orientation.w = std::cos(heading / 2.0);
  odom.twist.twist.linear.x = odometry_.linear();
  odom.twist.twist.angular.z = odometry_.angular();
  odom_pub_.publish(odom);
}

void StockControllerNode::publishStatus()
{
  jackal_msgs::Status s;
  s.header.stamp = ros::Time::now();
  s.hardware_id = "jackal_aic simulated base";
  s.drivers_active = !stopped_;
  s.driver_external_stop_present = true;
  s.driver_external_stop_stopped = stopped_;
  status_pub_.publish(s);
}

void StockControllerNode::onTimer(const ros::TimerEvent& e)
{
  (void)e;
  if (cycle_on_joint_states_)
  {
    std::unique_lock<std::mutex> lock(mutex_);
    checkClock();
    if (!last_cycle_.isZero() &&
        (ros::Time::now() - last_cycle_).toSec() < kFallbackPeriods / controller_.params().publish_rate)
    {
      return;  // the joint states run the cycle
    }
  }
  cycle();
}

void StockControllerNode::cycle()
{
  jackal_msgs::Drive d;
  jackal_msgs::Feedback fb;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    checkClock();
    // The diff drive keeps running while stopped (as on the robot); the MCU ignores it.
    const auto c = controller_.update(ros::Time::now().toSec());
    d.mode = stopped_ ? jackal_msgs::Drive::MODE_NONE : jackal_msgs::Drive::MODE_VELOCITY;
    d.drivers[jackal_msgs::Drive::LEFT] = static_cast<float>(c.left);
    d.drivers[jackal_msgs::Drive::RIGHT] = static_cast<float>(c.right);
    fb.header.stamp = ros::Time::now();
    fb.commanded_mode = jackal_msgs::Drive::MODE_VELOCITY;
    fb.actual_mode = d.mode;
    last_cycle_ = ros::Time::now();
  }
  pub_.publish(d);
  if (publish_mcu_)
  {
    feedback_pub_.publish(fb);
  }
}

}  // namespace sim_nodes
}  // namespace jackal_aic
