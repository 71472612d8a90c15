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
AicNode::AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh)
{
}

AicNode::~AicNode()
{
  if (belief_loop_)
  {
    belief_loop_->stop();
  }
}

bool AicNode::init()
{
  if (!loadValidNodeParams(pnh_, &params_))
  {
    return false;
  }
  try
  {
    pipeline_ = std::make_unique<SamplePipeline>(params_.aic, params_.fdi);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL_STREAM("jackal_AIC: cannot build the controller: " << e.what());
    return false;
  }
  sync_ = std::make_unique<SensorSynchronizer>(SensorSynchronizer::Config::fromParams(params_));
  supervisor_ = std::make_unique<Supervisor>(params_, clock_);

  outputs_ = std::make_unique<NodeOutputs>(nh_, pnh_, params_.output_mode, params_.cmd_vel, params_.debug_rate);

  // Wall clock: the belief thread serves the subscribers (BeliefLoop); simulated time: the spinner.
  belief_on_thread_ = BeliefLoop::useThread();
  ros::NodeHandle sensor_nh(nh_), sensor_pnh(pnh_);
  if (belief_on_thread_)
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
  diagnostics_->addFaultMonitor(pnh_, pipeline_->faultMonitor());

  action_timer_ = nh_.createTimer(ros::Duration(supervisor_->actionLoop().nominalPeriod()),
                                  &AicNode::actionTimerCallback, this);
  diagnostics_->start(nh_, mutex_);
  outputs_->startDebug(nh_, [this](DebugSnapshot* snapshot) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (belief_steps_ == published_steps_)
    {
      return false;  // no belief step since the last publication (belief_rate < debug_rate, or not started)
    }
    published_steps_ = belief_steps_;
    outputs_->capture(pipeline_->controller(), belief_stamp_, snapshot);
    return true;
  });
  belief_loop_ = std::make_unique<BeliefLoop>(nh_, params_.aic.belief_rate, params_.realtime_priority, &sensor_queue_,
                                              [this](double interval, const ros::Time& stamp) {
                                                beliefTick(interval, stamp);
                                              });
  if (belief_loop_->priorityRefused())
  {
    ROS_WARN_STREAM("jackal_AIC: belief loop: " << belief_loop_->description());
  }
  diagnostics_->setBeliefLoop(belief_loop_->description());

  ROS_INFO_STREAM("jackal_AIC: " << params_.aic.summary() << "; belief loop on a " << belief_loop_->description()
                                 << "; waiting for /joint_states, /imu/data and ~set_point");
  return true;
}

// ---------------------------------------------------------------------------
// Supervisor decisions.

void AicNode::carryOut(const Supervisor::Transition& t)
{
  if (t.restart_history)
  {
    // Sensors are gone: the next sample starts a new history (and a new warm-up).
    pipeline_->restartHistory();
    sync_->restartHistory();
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
  pipeline_->activate(wheels, supervisor_->goal());  // beliefs at the measured twist, action at the wheels
  outputs_->resetWheels(wheels);  // cmd_vel: the stock controller's acceleration limit starts there too
  ROS_INFO_STREAM("jackal_AIC: running (start from measured wheels " << wheels.transpose() << " rad/s, goal "
                                                                     << supervisor_->goal().transpose() << ")");
}

void AicNode::handleRunaway(const char* where)
{
  carryOut(supervisor_->runaway(where));
  ROS_ERROR_STREAM_THROTTLE(1.0, "jackal_AIC: runaway beliefs in the " << where << " (|mu| > runaway_limit "
                                     << params_.aic.runaway_limit << " or non-finite); controller reset, zero "
                                     << "command for " << params_.runaway_hold_time << " s ["
                                     << supervisor_->runaways() << " runaway(s) so far]");
}

// ---------------------------------------------------------------------------
// Timers: do the work.

void AicNode::beliefTick(double interval, const ros::Time& stamp)
{
  const ros::WallTime start = ros::WallTime::now();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!belief_on_thread_)
  {
    applyPendingParams();  // on ROS timers both loops apply; the thread leaves it to the spinner
  }
  const LoopScheduler::Tick tick = supervisor_->beliefLoop().tick(interval);
  diagnostics_->tickBelief();
  carryOut(supervisor_->update());
  for (int i = 0; i < tick.steps; ++i)
  {
    if (supervisor_->active() && pipeline_->controller().updateBeliefs(tick.h) == ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway("belief update");
    }
  }
  belief_steps_ += static_cast<std::uint64_t>(tick.steps);
  belief_stamp_ = stamp;
  supervisor_->beliefLoop().recordDuration((ros::WallTime::now() - start).toSec());
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
    else if (supervisor_->keepAliveDue())
    {
      publishCommand(pipeline_->controller().action()(0), pipeline_->controller().action()(1));
    }
    return;
  }
  actionStep(timerInterval(event));
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
  else if (pipeline_->controller().updateAction(h) == ActiveInferenceController::Status::kRunaway)
  {
    handleRunaway("action update");  // publishes the zero command
  }
  else
  {
    publishCommand(pipeline_->controller().action()(0), pipeline_->controller().action()(1));
    supervisor_->actionPublished();
    // Age of the newest sensor data in this command: the sensor-to-command latency.
    diagnostics_->commandLatency((ros::Time::now() - newest_sample_stamp_).toSec());
  }
  supervisor_->actionLoop().recordDuration((ros::WallTime::now() - start).toSec());
}

void AicNode::publishCommand(double omega_left, double omega_right)
{
  const NodeOutputs::WheelsResult r = outputs_->wheels(omega_left, omega_right, params_.aic.max_wheel_speed,
                                                       supervisor_->actionLoop().nominalPeriod());
  if (r.clipped && supervisor_->active())
  {
    pipeline_->controller().setAction(r.wheels);  // cmd_vel anti-windup: the action is what the robot gets
  }
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

ControllerReport AicNode::controllerReport() const
{
  ControllerReport r = ControllerReport::of(pipeline_->controller(), supervisor_->active());
  r.guarded_outputs = outputs_->guardedOutputs();
  r.generalizer_drops = generalizer_drops_;
  r.output_mode = params_.output_mode;
  r.output_clips = outputs_->clips();
  r.last_output_clipped = outputs_->lastClipped();
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
  bool new_history = false;
  try
  {
    new_history = pipeline_->setParams(next->aic, next->fdi);
  }
  catch (const std::exception& e)
  {
    ROS_ERROR_STREAM("jackal_AIC: reconfigure not applied: " << e.what());
    return;
  }
  if (new_history)
  {
    sync_->restartHistory();
    carryOut(supervisor_->embeddingOrderChanged());
  }
  supervisor_->setParams(*next);
  diagnostics_->setRates(next->aic.belief_rate, next->aic.action_rate);
  if (next->aic.belief_rate != params_.aic.belief_rate)
  {
    belief_loop_->setRate(next->aic.belief_rate);
  }
  if (next->aic.action_rate != params_.aic.action_rate)
  {
    action_timer_.setPeriod(ros::Duration(supervisor_->actionLoop().nominalPeriod()));
  }
  sync_->setConfig(SensorSynchronizer::Config::fromParams(*next));
  params_ = *next;
  ROS_INFO_STREAM("jackal_AIC: parameters applied (" << params_.aic.summary() << ")");
}

}  // namespace jackal_aic
