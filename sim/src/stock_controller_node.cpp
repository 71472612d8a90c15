/**
 * \file stock_controller_node.cpp
 * \brief stock_controller: the Jackal's stock velocity controller as a node, for
 *        comparison with the AIC (logic in jackal_aic::sim::StockController).
 *
 * Subscribes /jackal_AIC/set_point (geometry_msgs/Twist: linear.x [m/s], angular.z
 * [rad/s]); publishes /cmd_drive (jackal_msgs/Drive, MODE_VELOCITY, [rad/s]) at
 * ~publish_rate (50 Hz). Non-finite set points are dropped with a throttled warning.
 * Private parameters (defaults = jackal_control/config/control.yaml): wheel_separation,
 * wheel_separation_multiplier, wheel_radius, max_linear_velocity, max_linear_acceleration,
 * max_angular_velocity, max_angular_acceleration, cmd_vel_timeout, publish_rate.
 * Invalid values: the node logs each one with its allowed range and exits non-zero.
 */
#include <cmath>
#include <exception>
#include <iostream>
#include <mutex>

#include <geometry_msgs/Twist.h>
#include <jackal_msgs/Drive.h>
#include <ros/ros.h>

#include "jackal_sim/stock_controller.hpp"

namespace
{
using jackal_aic::sim::StockController;
using jackal_aic::sim::StockControllerParams;

class StockControllerNode
{
public:
  StockControllerNode(ros::NodeHandle nh, ros::NodeHandle pnh) : controller_(readParams(pnh))
  {
    pub_ = nh.advertise<jackal_msgs::Drive>("cmd_drive", 10);
    sub_ = nh.subscribe("jackal_AIC/set_point", 10, &StockControllerNode::onSetPoint, this,
                        ros::TransportHints().tcpNoDelay());
    timer_ = nh.createTimer(ros::Duration(1.0 / controller_.params().publish_rate), &StockControllerNode::onTimer,
                            this);
    ROS_INFO("stock_controller: diff_drive mapping, separation %.5f m x %.2f, radius %.3f m, %.1f Hz",
             controller_.params().wheel_separation, controller_.params().wheel_separation_multiplier,
             controller_.params().wheel_radius, controller_.params().publish_rate);
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

  void onSetPoint(const geometry_msgs::Twist::ConstPtr& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!controller_.setCommand(msg->linear.x, msg->angular.z, ros::Time::now().toSec()))
    {
      ROS_WARN_THROTTLE(1.0, "stock_controller: dropped non-finite set point (%f, %f)", msg->linear.x,
                        msg->angular.z);
    }
  }

  void onTimer(const ros::TimerEvent& e)
  {
    jackal_msgs::Drive d;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      (void)e;
      const auto c = controller_.update(ros::Time::now().toSec());
      d.mode = jackal_msgs::Drive::MODE_VELOCITY;
      d.drivers[jackal_msgs::Drive::LEFT] = static_cast<float>(c.left);
      d.drivers[jackal_msgs::Drive::RIGHT] = static_cast<float>(c.right);
    }
    pub_.publish(d);
  }

  std::mutex mutex_;
  StockController controller_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
  ros::Timer timer_;
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
