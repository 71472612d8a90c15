/**
 * \file aic_node_inputs.cpp
 * \brief The jackal_AIC node's subscribers (include/jackal_aic/ros/aic_node.hpp): each message
 *        becomes a ControlLoop event under the node's lock (stamps in the clock's seconds, a
 *        zero stamp as NaN). Wiring, timers and outputs: aic_node.cpp.
 */
#include "jackal_aic/ros/aic_node.hpp"

namespace jackal_aic
{
namespace node
{
void AicNode::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg)
{
  loop::JointStateInput joints;
  joints.stamp = clock_.seconds(msg->header.stamp);
  joints.name = &msg->name;
  joints.position = &msg->position;
  joints.velocity = &msg->velocity;
  joints.effort = &msg->effort;
  const std::lock_guard<std::mutex> lock(mutex_);
  loop_->jointState(joints);
}

void AicNode::imuCallback(const sensor_msgs::Imu::ConstPtr& msg)
{
  loop::ImuInput imu;
  imu.stamp = clock_.seconds(msg->header.stamp);
  imu.angular_velocity << msg->angular_velocity.x, msg->angular_velocity.y, msg->angular_velocity.z;
  imu.linear_acceleration << msg->linear_acceleration.x, msg->linear_acceleration.y, msg->linear_acceleration.z;
  const std::lock_guard<std::mutex> lock(mutex_);
  loop_->imu(imu);
}

void AicNode::setPointCallback(const geometry_msgs::Twist::ConstPtr& msg)
{
  const double fields[6] = {
    msg->linear.x, msg->linear.y, msg->linear.z, msg->angular.x, msg->angular.y, msg->angular.z
  };
  const std::lock_guard<std::mutex> lock(mutex_);
  loop_->setPoint(fields);
}

void AicNode::statusCallback(const jackal_msgs::Status::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  loop_->mcuStatus(msg->drivers_active, msg->driver_external_stop_present, msg->driver_external_stop_stopped);
}

void AicNode::feedbackCallback(const jackal_msgs::Feedback::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  loop_->mcuFeedback(msg->actual_mode);
}

}  // namespace node
}  // namespace jackal_aic
