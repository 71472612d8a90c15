/**
 * \file aic_node_inputs.cpp
 * \brief The jackal_AIC node's subscribers (include/jackal_aic/ros/aic_node.hpp): each validates
 *        and stores under the node's lock; an accepted joint-state sample also goes through the
 *        SamplePipeline (generalizer, measurement, fault detection) and, with action_trigger
 *        sample, runs the action step. Wiring, loops and outputs: aic_node.cpp.
 */
#include "jackal_aic/ros/aic_node.hpp"

namespace jackal_aic
{
// ---------------------------------------------------------------------------
// Subscribers: validate and store.

void AicNode::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  SensorSample sample;
  if (!sync_->addJointState(msg, &sample))
  {
    return;
  }
  bool restarted = false;
  const Generalizer::Status status = pipeline_->generalize(&sample.y, sample.h, sample.imu_ok, sample.first, &restarted);
  if (restarted)
  {
    supervisor_->historyRestarted();
  }
  if (status != Generalizer::Status::kOk && status != Generalizer::Status::kFirstSample)
  {
    ++generalizer_drops_;
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: generalizer rejected a sample: " << toString(status));
    return;
  }
  supervisor_->sampleAccepted(Vector2(sample.y(kOmegaLeft), sample.y(kOmegaRight)));
  newest_sample_stamp_ = sample.stamp;
  if (!supervisor_->active())
  {
    return;
  }
  const SamplePipeline::Measurement m = pipeline_->measure(sample.y, sample.h, sample.imu_ok);
  if (!m.accepted)
  {
    ++generalizer_drops_;
    ROS_WARN_THROTTLE(1.0, "jackal_AIC: controller refused a generalized measurement");
    return;
  }
  if (m.event != FaultMonitor::Event::kNone)
  {
    diagnostics_->publishHealth(m.event, m.event_channel);
  }
  if (params_.action_trigger == ActionTrigger::kSample)
  {
    actionStep(sample.first ? -1.0 : sample.h);  // over the sensor interval (stamps), clamped to 3 periods
  }
}

void AicNode::imuCallback(const sensor_msgs::Imu::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (sync_->addImu(msg))
  {
    supervisor_->imuAccepted();
  }
}

void AicNode::setPointCallback(const geometry_msgs::Twist::ConstPtr& msg)
{
  const double fields[6] = { msg->linear.x,  msg->linear.y,  msg->linear.z,
                             msg->angular.x, msg->angular.y, msg->angular.z };
  const std::lock_guard<std::mutex> lock(mutex_);
  switch (supervisor_->setPoint(fields))
  {
    case SetPointResult::kDropped:
      ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: dropped a set point with a NaN/Inf field ["
                                        << supervisor_->setPointDrops() << " so far]");
      return;
    case SetPointResult::kClamped:
      ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: set point (" << msg->linear.x << " m/s, " << msg->angular.z
                                                              << " rad/s) clamped to (" << supervisor_->goal()(0)
                                                              << ", " << supervisor_->goal()(2)
                                                              << ") by max_linear_speed / max_angular_speed");
      break;
    case SetPointResult::kAccepted:
      break;
  }
  pipeline_->controller().setGoal(supervisor_->goal());
}

void AicNode::statusCallback(const jackal_msgs::Status::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  supervisor_->mcuStatus(msg->drivers_active, msg->driver_external_stop_present, msg->driver_external_stop_stopped);
}

void AicNode::feedbackCallback(const jackal_msgs::Feedback::ConstPtr& msg)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  supervisor_->mcuFeedback(msg->actual_mode);
}

}  // namespace jackal_aic
