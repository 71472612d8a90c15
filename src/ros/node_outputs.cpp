/**
 * \file node_outputs.cpp
 * \brief The jackal_AIC node's publishers with the final finiteness guard
 *        (include/jackal_aic/ros/node_outputs.hpp; doc/jackal_aic_node.md, 'Topics').
 */
#include "jackal_aic/ros/node_outputs.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <geometry_msgs/TwistStamped.h>
#include <jackal_msgs/Drive.h>
#include <jackal_aic/InferenceState.h>
#include <ros/console.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

namespace jackal_aic
{
namespace node
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
  inference_pub_ = pnh.advertise<jackal_aic::InferenceState>("inference", 50, changed, changed);
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
             gyro_offset_pub_.getNumSubscribers() + inference_pub_.getNumSubscribers() >
         0;
}

void NodeOutputs::publish(const loop::WheelCommand& command)
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
  base::Vector2 wheels = command.wheels;
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

void NodeOutputs::belief(const ros::Time& stamp, const base::MuTilde& mu)
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

void NodeOutputs::capture(const aic::ActiveInferenceController& controller, double gyro_offset, const ros::Time& stamp,
                          const ros::Time& sample_stamp, DebugSnapshot* snapshot) const
{
  snapshot->gyro_offset = gyro_offset;
  snapshot->stamp = stamp;
  snapshot->sample_stamp = sample_stamp;
  snapshot->has_measurement = controller.hasMeasurement();
  snapshot->inference = aic::inferenceSample(controller);
}

void NodeOutputs::debug(const DebugSnapshot& snapshot)
{
  const aic::InferenceSample& inf = snapshot.inference;
  if (belief_pub_.getNumSubscribers() > 0)
  {
    belief(snapshot.stamp, inf.mu);
  }
  if (free_energy_pub_.getNumSubscribers() > 0)
  {
    const double f = snapshot.has_measurement ? inf.free_energy : 0.0;
    if (std::isfinite(f))
    {
      std_msgs::Float64 msg;
      msg.data = f;
      free_energy_pub_.publish(msg);
    }
    else
    {
      ++guarded_outputs_;
    }
  }
  if (wheel_separation_pub_.getNumSubscribers() > 0)
  {
    std_msgs::Float64 b;
    b.data = inf.wheel_separation;
    wheel_separation_pub_.publish(b);
  }
  if (gyro_offset_pub_.getNumSubscribers() > 0)
  {
    std_msgs::Float64 g;
    g.data = snapshot.gyro_offset;
    gyro_offset_pub_.publish(g);
  }
  // eps_y, eps_mu: only for a subscriber, never published non-finite; the goal and unbiased
  // models' (the robot model's errors are in ~inference, with NaN where it has none).
  auto publishErrors = [this, &inf](const ros::Publisher& pub, const auto& errors) {
    if (errors.cols() == 0 || pub.getNumSubscribers() == 0 || inf.belief_model == params::BeliefModel::kRobot)
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
  publishErrors(eps_y_pub_, inf.eps_y);
  publishErrors(eps_mu_pub_, inf.eps_mu);
  inference(snapshot);
}

bool NodeOutputs::inference(const DebugSnapshot& snapshot)
{
  if (inference_pub_.getNumSubscribers() == 0 || !snapshot.has_measurement || snapshot.sample_stamp.isZero() ||
      snapshot.sample_stamp == last_inference_stamp_)
  {
    return false;
  }
  const aic::InferenceSample& inf = snapshot.inference;
  // NaN only where the belief model has no such quantity (msg/InferenceState.msg).
  if (!aic::modelledValuesFinite(inf) || !std::isfinite(snapshot.gyro_offset))
  {
    ++guarded_outputs_;
    return false;
  }
  jackal_aic::InferenceState msg;
  msg.header.stamp = snapshot.sample_stamp;
  msg.header.frame_id = "base_link";
  const int orders = static_cast<int>(inf.mu.cols());
  msg.belief_model = params::toString(inf.belief_model);
  msg.orders = static_cast<std::uint8_t>(orders);
  msg.free_energy = inf.free_energy;
  msg.free_energy_sensory = inf.sensory;
  msg.free_energy_prior = inf.prior;
  // Channel-major: element (c, i) at c * orders + i (msg/InferenceState.msg).
  auto flatten = [orders](const auto& m, std::vector<double>* out) {
    out->resize(static_cast<std::size_t>(m.rows() * orders));
    for (int c = 0; c < m.rows(); ++c)
    {
      for (int i = 0; i < orders; ++i)
      {
        (*out)[static_cast<std::size_t>(c * orders + i)] = m(c, i);
      }
    }
  };
  flatten(inf.mu, &msg.mu);
  flatten(inf.eps_y, &msg.eps_y);
  flatten(inf.eps_mu, &msg.eps_mu);
  for (int k = 0; k < base::kADim; ++k)
  {
    msg.action[static_cast<std::size_t>(k)] = inf.action(k);
    msg.action_prior[static_cast<std::size_t>(k)] = inf.action_prior(k);
  }
  for (int c = 0; c < base::kMuDim; ++c)
  {
    msg.goal[static_cast<std::size_t>(c)] = inf.goal(c);
  }
  for (int c = 0; c < base::kYDim; ++c)
  {
    msg.precision_y[static_cast<std::size_t>(c)] = inf.precision_y(c);
  }
  msg.wheel_separation = inf.wheel_separation;
  msg.gyro_offset = snapshot.gyro_offset;
  for (int k = 0; k < 2; ++k)
  {
    msg.shortfall[static_cast<std::size_t>(k)] = inf.shortfall(k);
    msg.turn_shortfall[static_cast<std::size_t>(k)] = inf.turn_shortfall(k);
  }
  msg.slip_ratio = inf.slip_ratio;
  msg.gyro_offset_belief = inf.gyro_offset_belief;
  inference_pub_.publish(msg);
  last_inference_stamp_ = snapshot.sample_stamp;
  return true;
}

}  // namespace node
}  // namespace jackal_aic
