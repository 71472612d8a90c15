/**
 * \file aic_node.cpp
 * \brief The jackal_AIC node's wiring (include/jackal_aic/ros/aic_node.hpp; doc/jackal_aic_node.md).
 */
#include "jackal_aic/ros/aic_node.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "jackal_aic/ros/node_params.hpp"

namespace jackal_aic
{
namespace
{
/// Diagnostics updater is polled at this rate (it publishes every ~diagnostic_period, default 1 s) [Hz].
constexpr double kDiagnosticsPollRate = 10.0;
/// action_trigger sample: with no action step for this many action periods while running,
/// the action timer repeats the held command.
constexpr double kKeepAlivePeriods = 1.5;
/// Belief periods up to this [ns] serve the subscribers once per tick (<= 2 ms of added sample
/// latency, no wake-up per message); longer periods serve them as they arrive.
constexpr std::int64_t kBatchedDispatchMaxPeriodNs = 2000000;

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

AicNode::~AicNode()
{
  if (belief_thread_)
  {
    belief_thread_->stop();
  }
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

  outputs_ = std::make_unique<NodeOutputs>(nh_, pnh_, [this] { debugSubscribersChanged(); }, params_.output_mode);
  if (outputs_->cmdVelMode())
  {
    cmd_vel_ = std::make_unique<CmdVelOutput>(params_.cmd_vel);  // validated above
  }

  // Wall clock: the belief thread serves the subscribers (waitServingSensors); simulated time:
  // the spinner.
  const bool belief_thread = !ros::Time::isSimTime();
  ros::NodeHandle sensor_nh(nh_), sensor_pnh(pnh_);
  if (belief_thread)
  {
    sensor_nh.setCallbackQueue(&sensor_queue_);
    sensor_pnh.setCallbackQueue(&sensor_queue_);
  }
  const auto hints = ros::TransportHints().tcpNoDelay();
  joint_sub_ = sensor_nh.subscribe("joint_states", 10, &AicNode::jointStateCallback, this, hints);
  imu_sub_ = sensor_nh.subscribe("imu/data", 10, &AicNode::imuCallback, this, hints);
  set_point_sub_ = sensor_pnh.subscribe("set_point", 10, &AicNode::setPointCallback, this, hints);
  status_sub_ = sensor_nh.subscribe("status", 10, &AicNode::statusCallback, this, hints);
  feedback_sub_ = sensor_nh.subscribe("feedback", 10, &AicNode::feedbackCallback, this, hints);

  reconfigure_ = std::make_unique<NodeReconfigure>(pnh_, params_);
  diagnostics_ = std::make_unique<NodeDiagnostics>(nh_, pnh_, *supervisor_, *sync_,
                                                   [this] { return controllerReport(); });
  diagnostics_->addFaultMonitor(pnh_, *fault_monitor_);

  action_timer_ = nh_.createTimer(ros::Duration(supervisor_->actionLoop().nominalPeriod()),
                                  &AicNode::actionTimerCallback, this);
  // Started and stopped by debugSubscribersChanged(): no wake-ups while nobody listens.
  debug_timer_ = nh_.createTimer(ros::Duration(1.0 / params_.debug_rate), &AicNode::debugTimerCallback, this,
                                 false, false);
  diagnostics_timer_ = nh_.createTimer(ros::Duration(1.0 / kDiagnosticsPollRate), [this](const ros::TimerEvent&) {
    const std::lock_guard<std::mutex> lock(mutex_);
    diagnostics_->update();
    diagnostics_->pollHealth();
  });

  std::string loop = "ROS timer (simulated time)";
  if (!belief_thread)
  {
    belief_timer_ = nh_.createTimer(ros::Duration(supervisor_->beliefLoop().nominalPeriod()),
                                    &AicNode::beliefTimerCallback, this);
  }
  else
  {
    belief_thread_ = std::make_unique<PeriodicThread>(
        [this](double interval) { beliefTick(interval, ros::Time::now()); }, "aic_belief",
        [this](std::int64_t deadline_ns, std::int64_t period_ns) { waitServingSensors(deadline_ns, period_ns); });
    const std::string priority = belief_thread_->start(params_.aic.belief_rate, params_.realtime_priority);
    loop = "real-time thread (clock_nanosleep, " + (priority.empty() ? std::string("default scheduler") : priority) + ")";
    if (priority.find("refused") != std::string::npos)
    {
      ROS_WARN_STREAM("jackal_AIC: belief thread: " << priority);
    }
  }
  diagnostics_->setBeliefLoop(loop);

  ROS_INFO_STREAM("jackal_AIC: belief " << params_.aic.belief_rate << " Hz on a " << loop << ", action "
                                        << params_.aic.action_rate
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
  const std::lock_guard<std::mutex> lock(mutex_);
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
  newest_sample_stamp_ = sample.stamp;
  if (!supervisor_->active())
  {
    return;
  }
  if (!controller_->setMeasurement(generalizer_->yTilde()))
  {
    ++generalizer_drops_;
    ROS_WARN_THROTTLE(1.0, "jackal_AIC: controller refused a generalized measurement");
    return;
  }
  checkSensorFaults(sample);  // before the action: a channel isolated now is out of this step
  if (params_.action_trigger == ActionTrigger::kSample)
  {
    actionStep(sample.first ? -1.0 : sample.h);  // over the sensor interval (stamps), clamped to 3 periods
  }
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
  controller_->setGoal(supervisor_->goal());
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
    // kStale: zero command; kHeld: the reason says the command holds the measured wheel speeds.
    ROS_WARN_STREAM("jackal_AIC: " << supervisor_->reason()
                                   << (supervisor_->state() == NodeState::kHeld ? "" : "; commanding zero"));
  }
  if (t.activate())
  {
    activate();
  }
  else if (t.deactivate())
  {
    publishIdle();  // at once, not at the next action tick
  }
}

void AicNode::activate()
{
  const Vector2& wheels = supervisor_->measuredWheels();
  controller_->reset();
  controller_->setGoal(supervisor_->goal());
  controller_->setMeasurement(generalizer_->yTilde());
  controller_->setAction(wheels);  // bumpless start from the measured wheel speeds
  if (cmd_vel_)
  {
    cmd_vel_->reset(wheels);  // the stock controller's acceleration limit starts from the wheels too
  }
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
  beliefTick(intervalOf(event), event.current_real);
}

void AicNode::beliefTick(double interval, const ros::Time& stamp)
{
  const ros::WallTime start = ros::WallTime::now();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!belief_thread_)
  {
    applyPendingParams();  // on ROS timers both loops apply; the thread leaves it to the spinner
  }
  const LoopScheduler::Tick tick = supervisor_->beliefLoop().tick(interval);
  diagnostics_->tickBelief();
  carryOut(supervisor_->update());
  for (int i = 0; i < tick.steps; ++i)
  {
    if (supervisor_->active() && controller_->updateBeliefs(tick.h) == ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway("belief update");
    }
  }
  belief_steps_ += static_cast<std::uint64_t>(tick.steps);
  belief_stamp_ = stamp;
  supervisor_->beliefLoop().recordDuration((ros::WallTime::now() - start).toSec());
}

void AicNode::waitServingSensors(std::int64_t deadline_ns, std::int64_t period_ns)
{
  if (period_ns <= kBatchedDispatchMaxPeriodNs)
  {
    PeriodicThread::sleepUntil(deadline_ns);
    sensor_queue_.callAvailable(ros::WallDuration(0.0));  // what came during the period, then the step
    return;
  }
  for (std::int64_t left = deadline_ns - PeriodicThread::monotonicNow(); left > 0;
       left = deadline_ns - PeriodicThread::monotonicNow())
  {
    sensor_queue_.callAvailable(ros::WallDuration(static_cast<double>(left) * 1e-9));
  }
}

void AicNode::actionTimerCallback(const ros::TimerEvent& event)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  applyPendingParams();
  if (params_.action_trigger == ActionTrigger::kSample)
  {
    // The samples run the action; the timer keeps the command alive (zeros, or the measured
    // wheel speeds while the MCU holds) while inactive.
    carryOut(supervisor_->update());
    if (!supervisor_->active())
    {
      diagnostics_->tickAction();
      publishIdle();
    }
    else if (clock_.now() - last_action_time_ > kKeepAlivePeriods * supervisor_->actionLoop().nominalPeriod())
    {
      // Samples late (not yet stale): repeat the held action, no integration, so the MCU
      // keeps receiving commands at about action_rate.
      publishCommand(controller_->action()(0), controller_->action()(1));
    }
    return;
  }
  actionStep(intervalOf(event));
}

void AicNode::actionStep(double interval)
{
  const ros::WallTime start = ros::WallTime::now();
  const double h = supervisor_->actionLoop().tick(interval).h;
  diagnostics_->tickAction();
  carryOut(supervisor_->update());
  if (!supervisor_->active())
  {
    publishIdle();
  }
  else if (controller_->updateAction(h) == ActiveInferenceController::Status::kRunaway)
  {
    handleRunaway("action update");  // publishes the zero command
  }
  else
  {
    publishCommand(controller_->action()(0), controller_->action()(1));
    last_action_time_ = clock_.now();
    // Age of the newest sensor data in this command: the sensor-to-command latency.
    diagnostics_->commandLatency((ros::Time::now() - newest_sample_stamp_).toSec());
  }
  supervisor_->actionLoop().recordDuration((ros::WallTime::now() - start).toSec());
}

void AicNode::publishCommand(double omega_left, double omega_right)
{
  const double limit = params_.aic.max_wheel_speed;
  if (!cmd_vel_)
  {
    outputs_->command(omega_left, omega_right, limit);
    return;
  }
  if (!std::isfinite(omega_left) || !std::isfinite(omega_right))
  {
    ROS_ERROR_THROTTLE(1.0, "jackal_AIC: non-finite wheel command replaced by zero");
  }
  const Vector2 wheels(std::isfinite(omega_left) ? std::clamp(omega_left, -limit, limit) : 0.0,
                       std::isfinite(omega_right) ? std::clamp(omega_right, -limit, limit) : 0.0);
  // The stock controller limits over its own 50 Hz period; ours is the action period.
  const CmdVelOutput::Result r = cmd_vel_->convert(wheels, supervisor_->actionLoop().nominalPeriod());
  last_clipped_ = r.clipped;
  if (r.clipped)
  {
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: wheel command " << wheels.transpose()
                                                                << " rad/s exceeds the stock controller's limits; "
                                                                   "clipped to "
                                                                << r.wheels.transpose() << " rad/s ["
                                                                << cmd_vel_->clips() << " so far]");
    if (supervisor_->active())
    {
      controller_->setAction(r.wheels);  // anti-windup: the action is what the robot gets
    }
  }
  outputs_->twist(r.twist.linear, r.twist.angular);
}

void AicNode::publishIdle()
{
  if (supervisor_->state() == NodeState::kHeld)
  {
    const Vector2& wheels = supervisor_->measuredWheels();  // no windup against stopped motors
    publishCommand(wheels(0), wheels(1));
  }
  else
  {
    publishCommand(0.0, 0.0);
  }
}

void AicNode::debugSubscribersChanged()
{
  if (outputs_->debugWanted())
  {
    debug_timer_.start();
  }
  else
  {
    debug_timer_.stop();
  }
}

void AicNode::debugTimerCallback(const ros::TimerEvent&)
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (belief_steps_ == published_steps_)
    {
      return;  // no belief step since the last publication (belief_rate < debug_rate, or not started)
    }
    published_steps_ = belief_steps_;
    outputs_->capture(*controller_, belief_stamp_, &snapshot_);
  }
  outputs_->debug(snapshot_);  // outside the lock: publishing serializes messages
}

ControllerReport AicNode::controllerReport() const
{
  ControllerReport r;
  r.free_energy = controller_->hasMeasurement() ? controller_->freeEnergy() : 0.0;
  r.belief_vx = controller_->mu()(0, 0);
  r.belief_wz = controller_->mu()(2, 0);
  r.command = supervisor_->active() ? controller_->action() : Vector2::Zero();
  r.guarded_outputs = outputs_->guardedOutputs();
  r.generalizer_drops = generalizer_drops_;
  r.output_mode = params_.output_mode;
  r.output_clips = cmd_vel_ ? cmd_vel_->clips() : 0;
  r.last_output_clipped = last_clipped_;
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
    if (belief_thread_)
    {
      belief_thread_->setRate(next->aic.belief_rate);
    }
    else
    {
      belief_timer_.setPeriod(ros::Duration(supervisor_->beliefLoop().nominalPeriod()));
    }
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
