/**
 * \file aic_node.cpp
 * \brief The jackal_AIC node's wiring (include/jackal_aic/ros/aic_node.hpp; doc/jackal_aic_node.md).
 */
#include "jackal_aic/ros/aic_node.hpp"

#include "jackal_aic/ros/node_params.hpp"

namespace jackal_aic
{
namespace
{
/// Diagnostics updater is polled at this rate (it publishes every ~diagnostic_period, default 1 s) [Hz].
constexpr double kDiagnosticsPollRate = 10.0;

double intervalOf(const ros::TimerEvent& event)
{
  if (event.last_real.isZero())
  {
    return -1.0;  // first tick: the scheduler uses the nominal period
  }
  return (event.current_real - event.last_real).toSec();
}

SensorSynchronizer::Config syncConfig(const NodeParams& params)
{
  SensorSynchronizer::Config c;
  c.left_joints = params.left_joints;
  c.right_joints = params.right_joints;
  c.imu_max_skew = params.imu_max_skew;
  c.min_sample_interval = params.min_sample_interval;
  c.max_gap = params.sensor_timeout;
  return c;
}
}  // namespace

AicNode::AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh)
{
}

bool AicNode::init()
{
  std::vector<ParamViolation> violations;
  loadNodeParams(pnh_, &params_, &violations);
  for (auto& v : params_.validate())
  {
    violations.push_back(std::move(v));
  }
  if (!violations.empty())
  {
    for (const auto& v : violations)
    {
      ROS_FATAL_STREAM("jackal_AIC: invalid parameter ~" << v.toString());
    }
    ROS_FATAL_STREAM("jackal_AIC: " << violations.size() << " invalid parameter(s) in " << pnh_.getNamespace()
                                    << "; exiting");
    return false;
  }
  try
  {
    controller_ = std::make_unique<ActiveInferenceController>(params_.aic);
    generalizer_ = std::make_unique<Generalizer>(kYDim, params_.aic.embedding_order);
    fault_monitor_ = std::make_unique<FaultMonitor>(params_.fdi, params_.aic);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL_STREAM("jackal_AIC: cannot build the controller: " << e.what());
    return false;
  }
  sync_ = std::make_unique<SensorSynchronizer>(syncConfig(params_));
  supervisor_ = std::make_unique<Supervisor>(params_, clock_);

  outputs_ = std::make_unique<NodeOutputs>(nh_, pnh_);

  const auto hints = ros::TransportHints().tcpNoDelay();
  joint_sub_ = nh_.subscribe("joint_states", 10, &AicNode::jointStateCallback, this, hints);
  imu_sub_ = nh_.subscribe("imu/data", 10, &AicNode::imuCallback, this, hints);
  set_point_sub_ = pnh_.subscribe("set_point", 10, &AicNode::setPointCallback, this, hints);

  reconfigure_ = std::make_unique<NodeReconfigure>(pnh_, params_);
  diagnostics_ = std::make_unique<NodeDiagnostics>(nh_, pnh_, *supervisor_, *sync_,
                                                   [this] { return controllerReport(); });
  diagnostics_->addFaultMonitor(pnh_, *fault_monitor_);

  belief_timer_ = nh_.createTimer(ros::Duration(supervisor_->beliefLoop().nominalPeriod()),
                                  &AicNode::beliefTimerCallback, this);
  action_timer_ = nh_.createTimer(ros::Duration(supervisor_->actionLoop().nominalPeriod()),
                                  &AicNode::actionTimerCallback, this);
  diagnostics_timer_ = nh_.createTimer(ros::Duration(1.0 / kDiagnosticsPollRate),
                                       [this](const ros::TimerEvent&) {
                                         diagnostics_->update();
                                         diagnostics_->publishHealth(FaultMonitor::Event::kNone, -1);
                                       });

  ROS_INFO_STREAM("jackal_AIC: belief " << params_.aic.belief_rate << " Hz, action " << params_.aic.action_rate
                                        << " Hz, tau " << params_.aic.tau << " s, k_mu " << params_.aic.k_mu
                                        << ", k_a " << params_.aic.k_a << ", p " << params_.aic.embedding_order
                                        << ", integrator " << toString(params_.aic.integrator)
                                        << "; waiting for /joint_states, /imu/data and ~set_point");
  return true;
}

// ---------------------------------------------------------------------------
// Subscribers: validate and store.

void AicNode::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg)
{
  SensorSample sample;
  if (!sync_->addJointState(msg, &sample))
  {
    return;
  }
  if (!sample.imu_ok)
  {
    // Degraded mode (IMU missing or stale): the gyro channel is masked (Pi_y = 0); give it the
    // wheels' yaw rate so that its generalized orders stay smooth when the IMU returns.
    sample.y(kGyroZ) = controller_->model().twistFromWheels(Vector2(sample.y(kOmegaLeft), sample.y(kOmegaRight)))(2);
  }
  if (sample.first || !generalizer_->initialized())
  {
    generalizer_->reset();
    supervisor_->historyRestarted();
  }
  const Generalizer::Status status = generalizer_->update(sample.y, sample.h);
  if (status != Generalizer::Status::kOk && status != Generalizer::Status::kFirstSample)
  {
    ++generalizer_drops_;
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: generalizer rejected a sample: " << toString(status));
    return;
  }
  supervisor_->sampleAccepted(Vector2(sample.y(kOmegaLeft), sample.y(kOmegaRight)));
  if (supervisor_->active() && !controller_->setMeasurement(generalizer_->yTilde()))
  {
    ++generalizer_drops_;
    ROS_WARN_THROTTLE(1.0, "jackal_AIC: controller refused a generalized measurement");
  }
  checkSensorFaults(sample);
}

void AicNode::checkSensorFaults(const SensorSample& sample)
{
  fault_monitor_->setImuAvailable(sample.imu_ok);
  const int isolated_before = fault_monitor_->isolatedChannel();
  const FaultMonitor::Event event = fault_monitor_->update(sample.y, controller_->mu().col(0), sample.h);
  controller_->setSensorMask(fault_monitor_->sensorMask());
  if (event != FaultMonitor::Event::kNone)
  {
    diagnostics_->publishHealth(event, event == FaultMonitor::Event::kRestored ? isolated_before
                                                                                : fault_monitor_->suspectedChannel());
  }
}

void AicNode::imuCallback(const sensor_msgs::Imu::ConstPtr& msg)
{
  if (sync_->addImu(msg))
  {
    supervisor_->imuAccepted();
  }
}

void AicNode::setPointCallback(const geometry_msgs::Twist::ConstPtr& msg)
{
  const double fields[6] = { msg->linear.x,  msg->linear.y,  msg->linear.z,
                             msg->angular.x, msg->angular.y, msg->angular.z };
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
  controller_->setGoal(supervisor_->goal());
}

// ---------------------------------------------------------------------------
// Supervisor decisions.

void AicNode::carryOut(const Supervisor::Transition& t)
{
  if (t.restart_history)
  {
    // Sensors are gone: the next sample starts a new history (and a new warm-up).
    generalizer_->reset();
    sync_->restartHistory();
    fault_monitor_->reset();
  }
  if (t.warn())
  {
    ROS_WARN_STREAM("jackal_AIC: " << supervisor_->reason() << "; commanding zero");
  }
  if (t.activate())
  {
    activate();
  }
  else if (t.deactivate())
  {
    publishCommand(0.0, 0.0);  // at once, not at the next action tick
  }
}

void AicNode::activate()
{
  const Vector2& wheels = supervisor_->measuredWheels();
  controller_->reset();
  controller_->setGoal(supervisor_->goal());
  controller_->setMeasurement(generalizer_->yTilde());
  controller_->setAction(wheels);  // bumpless start from the measured wheel speeds
  // Beliefs start at the measured twist (mu^(0) = G omega), higher orders zero.
  MuTilde mu = MuTilde::Zero(kMuDim, params_.aic.numOrders());
  mu.col(0) = controller_->model().twistFromWheels(wheels);
  controller_->setBeliefs(mu);
  ROS_INFO_STREAM("jackal_AIC: running (start from measured wheels " << wheels.transpose() << " rad/s, goal "
                                                                     << supervisor_->goal().transpose() << ")");
}

void AicNode::handleRunaway(const char* where)
{
  carryOut(supervisor_->runaway(where));
  ROS_ERROR_STREAM_THROTTLE(1.0, "jackal_AIC: runaway beliefs in the "
                                     << where << " (|mu| > runaway_limit " << params_.aic.runaway_limit
                                     << " or non-finite); controller reset, zero command for "
                                     << params_.runaway_hold_time << " s [" << supervisor_->runaways()
                                     << " runaway(s) so far]");
}

// ---------------------------------------------------------------------------
// Timers: do the work.

void AicNode::beliefTimerCallback(const ros::TimerEvent& event)
{
  const ros::WallTime start = ros::WallTime::now();
  applyPendingParams();
  const LoopScheduler::Tick tick = supervisor_->beliefLoop().tick(intervalOf(event));
  diagnostics_->tickBelief();
  carryOut(supervisor_->update());
  for (int i = 0; i < tick.steps; ++i)
  {
    if (supervisor_->active() && controller_->updateBeliefs(tick.h) == ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway("belief update");
    }
    outputs_->belief(event.current_real - ros::Duration(tick.h * (tick.steps - 1 - i)), controller_->mu());
  }
  supervisor_->beliefLoop().recordDuration((ros::WallTime::now() - start).toSec());
}

void AicNode::actionTimerCallback(const ros::TimerEvent& event)
{
  const ros::WallTime start = ros::WallTime::now();
  applyPendingParams();
  const double h = supervisor_->actionLoop().tick(intervalOf(event)).h;
  diagnostics_->tickAction();
  carryOut(supervisor_->update());
  if (!supervisor_->active())
  {
    publishCommand(0.0, 0.0);
  }
  else if (controller_->updateAction(h) == ActiveInferenceController::Status::kRunaway)
  {
    handleRunaway("action update");  // publishes the zero command
  }
  else
  {
    publishCommand(controller_->action()(0), controller_->action()(1));
  }
  outputs_->debug(*controller_);
  supervisor_->actionLoop().recordDuration((ros::WallTime::now() - start).toSec());
}

ControllerReport AicNode::controllerReport() const
{
  ControllerReport r;
  r.free_energy = outputs_->lastFreeEnergy();
  r.belief_vx = controller_->mu()(0, 0);
  r.belief_wz = controller_->mu()(2, 0);
  r.command = supervisor_->active() ? controller_->action() : Vector2::Zero();
  r.guarded_outputs = outputs_->guardedOutputs();
  r.generalizer_drops = generalizer_drops_;
  return r;
}

// ---------------------------------------------------------------------------
// dynamic_reconfigure: NodeReconfigure validates and queues; applied here, between ticks.

void AicNode::applyPendingParams()
{
  const std::unique_ptr<NodeParams> next = reconfigure_->takePending();
  if (!next)
  {
    return;
  }
  try
  {
    controller_->setParams(next->aic);
    fault_monitor_->setParams(next->fdi, next->aic);
  }
  catch (const std::exception& e)
  {
    ROS_ERROR_STREAM("jackal_AIC: reconfigure not applied: " << e.what());
    return;
  }
  if (next->aic.embedding_order != params_.aic.embedding_order)
  {
    generalizer_ = std::make_unique<Generalizer>(kYDim, next->aic.embedding_order);
    sync_->restartHistory();
    carryOut(supervisor_->embeddingOrderChanged());
  }
  supervisor_->setParams(*next);
  diagnostics_->setRates(next->aic.belief_rate, next->aic.action_rate);
  if (next->aic.belief_rate != params_.aic.belief_rate)
  {
    belief_timer_.setPeriod(ros::Duration(supervisor_->beliefLoop().nominalPeriod()));
  }
  if (next->aic.action_rate != params_.aic.action_rate)
  {
    action_timer_.setPeriod(ros::Duration(supervisor_->actionLoop().nominalPeriod()));
  }
  sync_->setConfig(syncConfig(*next));
  params_ = *next;
  ROS_INFO_STREAM("jackal_AIC: parameters applied (belief " << params_.aic.belief_rate << " Hz, action "
                                                            << params_.aic.action_rate << " Hz, tau "
                                                            << params_.aic.tau << ", k_mu " << params_.aic.k_mu
                                                            << ", k_a " << params_.aic.k_a << ", integrator "
                                                            << toString(params_.aic.integrator) << ")");
}

}  // namespace jackal_aic
