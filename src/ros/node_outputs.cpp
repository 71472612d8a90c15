/**
 * \file node_outputs.cpp
 * \brief The jackal_AIC node's publishers with the final finiteness guard
 *        (include/jackal_aic/ros/node_outputs.hpp; doc/jackal_aic_node.md, 'Topics').
 */
#include "jackal_aic/ros/node_outputs.hpp"

#include <cmath>

#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <jackal_msgs/Drive.h>
#include <ros/console.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

namespace jackal_aic
{
namespace
{
/// A matrix as Float64MultiArray: dim 0 "channel" (rows), dim 1 "order" (cols), row-major data.
std_msgs::Float64MultiArray toMultiArray(const Eigen::Ref<const Eigen::MatrixXd>& m)
{
  std_msgs::Float64MultiArray msg;
  msg.layout.dim.resize(2);
  msg.layout.dim[0].label = "channel";
  msg.layout.dim[0].size = static_cast<unsigned int>(m.rows());
  msg.layout.dim[0].stride = static_cast<unsigned int>(m.rows() * m.cols());
  msg.layout.dim[1].label = "order";
  msg.layout.dim[1].size = static_cast<unsigned int>(m.cols());
  msg.layout.dim[1].stride = static_cast<unsigned int>(m.cols());
  msg.data.resize(static_cast<std::size_t>(m.rows() * m.cols()));
  for (int r = 0; r < m.rows(); ++r)
  {
    for (int c = 0; c < m.cols(); ++c)
    {
      msg.data[static_cast<std::size_t>(r * m.cols() + c)] = m(r, c);
    }
  }
  return msg;
}
}  // namespace

NodeOutputs::NodeOutputs(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& output_mode, double debug_rate)
  : cmd_vel_mode_(output_mode == "cmd_vel"), debug_rate_(debug_rate)
{
  // Only the command topic of the mode: on the robot, jackal_node is the one /cmd_drive publisher.
  if (cmd_vel_mode_)
  {
    cmd_pub_ = nh.advertise<geometry_msgs::Twist>("jackal_velocity_controller/cmd_vel", 1);
  }
  else
  {
    cmd_pub_ = nh.advertise<jackal_msgs::Drive>("cmd_drive", 1);
  }
  const ros::SubscriberStatusCallback changed = [this](const ros::SingleSubscriberPublisher&) {
    debugSubscribersChanged();
  };
  belief_pub_ = pnh.advertise<geometry_msgs::TwistStamped>("belief", 50, changed, changed);
  free_energy_pub_ = pnh.advertise<std_msgs::Float64>("free_energy", 10, changed, changed);
  eps_y_pub_ = pnh.advertise<std_msgs::Float64MultiArray>("eps_y", 10, changed, changed);
  eps_mu_pub_ = pnh.advertise<std_msgs::Float64MultiArray>("eps_mu", 10, changed, changed);
  wheel_separation_pub_ = pnh.advertise<std_msgs::Float64>("wheel_separation", 10, changed, changed);
  gyro_offset_pub_ = pnh.advertise<std_msgs::Float64>("gyro_offset", 10, changed, changed);
}

void NodeOutputs::startDebug(ros::NodeHandle& nh, Capture capture)
{
  const std::lock_guard<std::mutex> lock(debug_mutex_);
  capture_ = std::move(capture);
  debug_timer_ = nh.createTimer(
      ros::Duration(1.0 / debug_rate_),
      [this](const ros::TimerEvent&) {
        if (capture_(&snapshot_))
        {
          debug(snapshot_);  // outside the node's lock: publishing serializes messages
        }
      },
      false, debugWanted());
}

void NodeOutputs::debugSubscribersChanged()
{
  const std::lock_guard<std::mutex> lock(debug_mutex_);
  if (!debug_timer_.isValid())
  {
    return;  // not started yet; startDebug() looks at the subscribers itself
  }
  if (debugWanted())
  {
    debug_timer_.start();
  }
  else
  {
    debug_timer_.stop();
  }
}

bool NodeOutputs::debugWanted() const
{
  return belief_pub_.getNumSubscribers() + free_energy_pub_.getNumSubscribers() + eps_y_pub_.getNumSubscribers() +
             eps_mu_pub_.getNumSubscribers() + wheel_separation_pub_.getNumSubscribers() +
             gyro_offset_pub_.getNumSubscribers() >
         0;
}

void NodeOutputs::publish(const WheelCommand& command)
{
  if (cmd_vel_mode_)
  {
    double linear = command.twist.linear;
    double angular = command.twist.angular;
    if (!std::isfinite(linear) || !std::isfinite(angular))
    {
      ++guarded_outputs_;
      ROS_ERROR_THROTTLE(1.0, "jackal_AIC: non-finite twist command replaced by zero");
      linear = 0.0;
      angular = 0.0;
    }
    geometry_msgs::Twist cmd;
    cmd.linear.x = linear;
    cmd.angular.z = angular;
    cmd_pub_.publish(cmd);
    return;
  }
  Vector2 wheels = command.wheels;
  if (!wheels.allFinite())
  {
    ++guarded_outputs_;
    ROS_ERROR_THROTTLE(1.0, "jackal_AIC: non-finite wheel command replaced by zero");
    wheels.setZero();
  }
  jackal_msgs::Drive cmd;
  cmd.mode = jackal_msgs::Drive::MODE_VELOCITY;
  cmd.drivers[jackal_msgs::Drive::LEFT] = static_cast<float>(wheels(0));
  cmd.drivers[jackal_msgs::Drive::RIGHT] = static_cast<float>(wheels(1));
  cmd_pub_.publish(cmd);
}

void NodeOutputs::belief(const ros::Time& stamp, const MuTilde& mu)
{
  geometry_msgs::TwistStamped belief;
  belief.header.stamp = stamp;
  belief.header.frame_id = "base_link";
  const auto mu0 = mu.col(0);
  if (mu0.allFinite())
  {
    belief.twist.linear.x = mu0(0);
    belief.twist.linear.y = mu0(1);
    belief.twist.angular.z = mu0(2);
  }
  else
  {
    ++guarded_outputs_;  // never publish a non-finite number (the controller resets on runaway)
  }
  belief_pub_.publish(belief);
}

void NodeOutputs::capture(const ActiveInferenceController& controller, double gyro_offset, const ros::Time& stamp,
                          DebugSnapshot* snapshot) const
{
  snapshot->gyro_offset = gyro_offset;
  snapshot->stamp = stamp;
  snapshot->mu = controller.mu();
  snapshot->free_energy = controller.hasMeasurement() ? controller.freeEnergy() : 0.0;
  snapshot->wheel_separation = controller.model().wheelSeparation();
  if (eps_y_pub_.getNumSubscribers() > 0)
  {
    snapshot->eps_y = controller.epsY();
  }
  else
  {
    snapshot->eps_y.resize(kYDim, 0);
  }
  if (eps_mu_pub_.getNumSubscribers() > 0)
  {
    snapshot->eps_mu = controller.epsMu();
  }
  else
  {
    snapshot->eps_mu.resize(kMuDim, 0);
  }
}

void NodeOutputs::debug(const DebugSnapshot& snapshot)
{
  if (belief_pub_.getNumSubscribers() > 0)
  {
    belief(snapshot.stamp, snapshot.mu);
  }
  if (free_energy_pub_.getNumSubscribers() > 0)
  {
    if (std::isfinite(snapshot.free_energy))
    {
      std_msgs::Float64 f;
      f.data = snapshot.free_energy;
      free_energy_pub_.publish(f);
    }
    else
    {
      ++guarded_outputs_;
    }
  }
  if (wheel_separation_pub_.getNumSubscribers() > 0)
  {
    std_msgs::Float64 b;
    b.data = snapshot.wheel_separation;
    wheel_separation_pub_.publish(b);
  }
  if (gyro_offset_pub_.getNumSubscribers() > 0)
  {
    std_msgs::Float64 g;
    g.data = snapshot.gyro_offset;
    gyro_offset_pub_.publish(g);
  }
  // eps_y, eps_mu: captured only for a subscriber, never published non-finite.
  auto publishErrors = [this](const ros::Publisher& pub, const auto& errors) {
    if (errors.cols() == 0 || pub.getNumSubscribers() == 0)
    {
      return;
    }
    if (errors.allFinite())
    {
      pub.publish(toMultiArray(errors));
    }
    else
    {
      ++guarded_outputs_;
    }
  };
  publishErrors(eps_y_pub_, snapshot.eps_y);
  publishErrors(eps_mu_pub_, snapshot.eps_mu);
}

}  // namespace jackal_aic
