/**
 * \file stock_controller_node.cpp
 * \brief stock_controller: the Jackal's stock velocity controller as a node (logic in
 *        jackal_aic::sim::StockController, diff_drive_controller's mapping and limits). Two roles:
 *
 * - comparison controller (default): subscribes /jackal_AIC/set_point, publishes /cmd_drive;
 * - stand-in for the stock base (launch/sim.launch base:=stock_diff_drive): with
 *   ~input_topic jackal_velocity_controller/cmd_vel it is the diff drive that jackal_node
 *   runs on the robot (jackal_robot's jackal_base), the one /cmd_drive publisher; with
 *   ~publish_odom it publishes the diff drive's wheel odometry on
 *   jackal_velocity_controller/odom; with ~publish_mcu_state it publishes a jackal_msgs/Status
 *   on /status (1 Hz and at once on a change) and a jackal_msgs/Feedback on /feedback (every
 *   update) with a settable stop: ~stop (initial) and the topic ~set_stop (std_msgs/Bool).
 *   While stopped it sends MODE_NONE on /cmd_drive (the MCU's motor enable is off: the
 *   simulated motors are released) and reports drivers_active false, external stop stopped,
 *   Feedback actual_mode MODE_NONE.
 *   With ~cycle_on_joint_states (sim.launch sets it for the stock base) the diff drive's cycle
 *   runs on each joint_states message, as jackal_node's control loop publishes the joint states
 *   and then the diff drive's /cmd_drive in the same cycle: a command that answers a cycle's
 *   joint states is used at the next cycle, a fixed one-period delay rather than the phase of
 *   two free-running 50 Hz clocks. The ~publish_rate timer then only runs the cycle when no
 *   joint states came for 1.5 periods (the MCU keeps receiving commands).
 *
 * Subscribes ~input_topic (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s]; default
 * jackal_AIC/set_point) and, with ~publish_odom or ~cycle_on_joint_states, joint_states (sensor_msgs/JointState: the
 * wheel velocities of ~left_joints, ~right_joints); publishes cmd_drive (jackal_msgs/Drive,
 * MODE_VELOCITY, [rad/s]) at ~publish_rate (50 Hz) or on each joint_states. Non-finite commands are dropped with a
 * throttled warning.
 * Private parameters (defaults = jackal_control/config/control.yaml): wheel_separation,
 * wheel_separation_multiplier, wheel_radius, max_linear_velocity, max_linear_acceleration,
 * max_angular_velocity, max_angular_acceleration, cmd_vel_timeout, publish_rate.
 * Invalid values: the node logs each one with its allowed range and exits non-zero.
 */
#include <cmath>
#include <exception>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <jackal_msgs/Drive.h>
#include <jackal_msgs/Feedback.h>
#include <jackal_msgs/Status.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>

#include "jackal_sim/stock_controller.hpp"

namespace
{
using jackal_aic::sim::StockController;
using jackal_aic::sim::StockControllerParams;

/// jackal_msgs/Status is published at least this often [s] (the MCU's 1 Hz).
constexpr double kStatusPeriod = 1.0;
/// ~cycle_on_joint_states: the timer runs the cycle after this many periods without joint states.
constexpr double kFallbackPeriods = 1.5;

class StockControllerNode
{
public:
  StockControllerNode(ros::NodeHandle nh, ros::NodeHandle pnh) : controller_(readParams(pnh))
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
      joint_sub_ = nh.subscribe("joint_states", 10, &StockControllerNode::onJointState, this,
                                ros::TransportHints().tcpNoDelay());
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
    timer_ = nh.createTimer(ros::Duration(1.0 / controller_.params().publish_rate), &StockControllerNode::onTimer,
                            this);
    ROS_INFO("stock_controller: diff_drive mapping, separation %.5f m x %.2f, radius %.3f m, %.1f Hz%s, input %s%s%s",
             controller_.params().wheel_separation, controller_.params().wheel_separation_multiplier,
             controller_.params().wheel_radius, controller_.params().publish_rate,
             cycle_on_joint_states_ ? " (cycle on joint_states)" : "", sub_.getTopic().c_str(),
             publish_odom_ ? ", odometry" : "", publish_mcu_ ? ", /status and /feedback" : "");
  }

private:
  static StockControllerParams readParams(const ros::NodeHandle& pnh)
  {
    StockControllerParams p;
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

  void onCommand(const geometry_msgs::Twist::ConstPtr& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!controller_.setCommand(msg->linear.x, msg->angular.z, ros::Time::now().toSec()))
    {
      ROS_WARN_THROTTLE(1.0, "stock_controller: dropped non-finite command (%f, %f)", msg->linear.x,
                        msg->angular.z);
    }
  }

  void onSetStop(const std_msgs::Bool::ConstPtr& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (msg->data != stopped_)
    {
      stopped_ = msg->data;
      ROS_WARN("stock_controller: stop %s", stopped_ ? "ENGAGED: motors released (MODE_NONE)" : "released");
      publishStatus();  // at once, like the MCU on a change of the run/stop loop
    }
  }

  /// Mean velocity of the named joints [rad/s]; false if one is missing or non-finite.
  static bool meanVelocity(const sensor_msgs::JointState& js, const std::vector<std::string>& names, double* out)
  {
    double sum = 0.0;
    for (const auto& n : names)
    {
      bool found = false;
      for (std::size_t i = 0; i < js.name.size() && i < js.velocity.size(); ++i)
      {
        if (js.name[i] == n && std::isfinite(js.velocity[i]))
        {
          sum += js.velocity[i];
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

  /// diff_drive_controller's odometry from the wheel speeds (velocity integration, as its
  /// open-loop-free mode): v = r (wL + wR) / 2, w = r (wR - wL) / s.
  void onJointState(const sensor_msgs::JointState::ConstPtr& msg)
  {
    if (cycle_on_joint_states_)
    {
      cycle();  // this cycle's /cmd_drive from the commands received before these joint states
    }
    if (!publish_odom_)
    {
      return;
    }
    double wl = 0.0, wr = 0.0;
    if (!meanVelocity(*msg, left_joints_, &wl) || !meanVelocity(*msg, right_joints_, &wr))
    {
      ROS_WARN_THROTTLE(1.0, "stock_controller: joint_states without finite velocities of the wheel joints");
      return;
    }
    const jackal_aic::BodyTwist t = jackal_aic::twistFromWheels(controller_.params(), jackal_aic::Vector2(wl, wr));
    const ros::Time stamp = msg->header.stamp;
    if (!last_odom_.isZero() && stamp > last_odom_)
    {
      const double dt = (stamp - last_odom_).toSec();
      const double heading = yaw_ + 0.5 * t.angular * dt;  // second-order Runge-Kutta, as diff_drive_controller
      x_ += t.linear * std::cos(heading) * dt;
      y_ += t.linear * std::sin(heading) * dt;
      yaw_ += t.angular * dt;
    }
    last_odom_ = stamp;
    nav_msgs::Odometry odom;
    odom.header.stamp = stamp;
    odom.header.frame_id = "odom";
    odom.child_frame_id = "base_link";
    odom.pose.pose.position.x = x_;
    odom.pose.pose.position.y = y_;
    odom.pose.pose.orientation.z = std::sin(yaw_ / 2.0);
    odom.pose.pose.orientation.w = std::cos(yaw_ / 2.0);
    odom.twist.twist.linear.x = t.linear;
    odom.twist.twist.angular.z = t.angular;
    odom_pub_.publish(odom);
  }

  /// Call with mutex_ held.
  void publishStatus()
  {
    jackal_msgs::Status s;
    s.header.stamp = ros::Time::now();
    s.hardware_id = "jackal_aic simulated base";
    s.drivers_active = !stopped_;
    s.driver_external_stop_present = true;
    s.driver_external_stop_stopped = stopped_;
    status_pub_.publish(s);
  }

  void onTimer(const ros::TimerEvent& e)
  {
    (void)e;
    if (cycle_on_joint_states_)
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!last_cycle_.isZero() &&
          (ros::Time::now() - last_cycle_).toSec() < kFallbackPeriods / controller_.params().publish_rate)
      {
        return;  // the joint states run the cycle
      }
    }
    cycle();
  }

  /// One diff-drive cycle: update the controller, publish /cmd_drive (and /feedback).
  void cycle()
  {
    jackal_msgs::Drive d;
    jackal_msgs::Feedback fb;
    {
      std::lock_guard<std::mutex> lock(mutex_);
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

  std::mutex mutex_;
  StockController controller_;
  bool publish_odom_ = false, publish_mcu_ = false, stopped_ = false, cycle_on_joint_states_ = false;
  ros::Time last_cycle_;  ///< time of the last cycle (mutex_)
  std::vector<std::string> left_joints_, right_joints_;
  ros::Publisher pub_, odom_pub_, status_pub_, feedback_pub_;
  ros::Subscriber sub_, joint_sub_, stop_sub_;
  ros::Timer timer_, status_timer_;
  ros::Time last_odom_;
  double x_ = 0.0, y_ = 0.0, yaw_ = 0.0;
};
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "stock_controller");
  try
  {
    StockControllerNode node{ ros::NodeHandle(), ros::NodeHandle("~") };
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("stock_controller: %s", e.what());
    std::cerr << "stock_controller: fatal: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
