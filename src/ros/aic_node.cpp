/**
 * \file aic_node.cpp
 * \brief The jackal_AIC node's wiring (include/jackal_aic/ros/aic_node.hpp; doc/jackal_aic_node.md):
 *        construction, timers, the ControlLoop's outputs as messages, applying a reconfigure.
 *        Subscribers: aic_node_inputs.cpp.
 */
#include "jackal_aic/ros/aic_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "jackal_aic/ros/param_server.hpp"

namespace jackal_aic
{
namespace node
{
double RosClock::sinceEpoch(const ros::Time& stamp) const
{
  // Not ros::Duration: a stamp more than 2^31 s after the epoch (any uint32 second is valid in a
  // message) is out of its range, which throws.
  return static_cast<double>(static_cast<std::int64_t>(stamp.toNSec()) - static_cast<std::int64_t>(epoch_.toNSec())) *
         1e-9;
}

double RosClock::seconds(const ros::Time& stamp) const
{
  return stamp.isZero() ? std::numeric_limits<double>::quiet_NaN() : sinceEpoch(stamp);
}

ros::Time RosClock::time(double seconds) const
{
  // Before ROS time 0 (a reading of an earlier timeline after ROS time moved back) or NaN:
  // time 0. Beyond the largest ROS time (a far-future stamp was read): the largest ROS time.
  // In signed 64-bit nanoseconds (exact; ros::Duration would throw beyond 2^31 s).
  constexpr std::int64_t kMaxNs = 4294967295LL * 1000000000LL + 999999999LL;  // uint32 s, 1e9 - 1 ns
  constexpr double kBound = 5.0e9;  // [s], beyond any ROS time on either side of the epoch
  if (!(seconds > -kBound))
  {
    return ros::Time(0);
  }
  const std::int64_t offset = std::llround(std::min(seconds, kBound) * 1e9);
  const std::int64_t ns =
      std::min(std::max(static_cast<std::int64_t>(epoch_.toNSec()) + offset, std::int64_t{ 0 }), kMaxNs);
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(ns));
  return t;
}

AicNode::AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh) {}

AicNode::~AicNode()
{
  // On the event schedule the subscribers' callbacks run on roscpp's network thread, not on
  // this one: shut them down first (roscpp waits for a callback in flight), before the members
  // they use go.
  for (ros::Subscriber* sub : { &joint_sub_, &imu_sub_, &set_point_sub_, &status_sub_, &feedback_sub_ })
  {
    sub->shutdown();
  }
  if (belief_loop_)
  {
    belief_loop_->stop();
  }
  publisher_watch_.reset();  // joins its thread before the loop it reports to goes
}

bool AicNode::init()
{
  if (!loadValidNodeParams(pnh_, &params_))
  {
    return false;
  }
  warnIfUnstable(params_.aic, "");
  clock_.start();
  outputs_ = std::make_unique<NodeOutputs>(nh_, pnh_, params_.output_mode, params_.debug_rate);
  try
  {
    loop::ControlLoop::Output& output = *this;
    loop_ = std::make_unique<loop::ControlLoop>(params_, clock_, output);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL_STREAM("jackal_AIC: cannot build the controller: " << e.what());
    return false;
  }

  // Timer schedule on the wall clock: the belief thread serves the subscribers (BeliefLoop);
  // on the simulated clock the spinner does. Event schedule: each message's callback runs on
  // roscpp's network thread as it arrives (InlineCallbackQueue): no hand-over to the spinner.
  const bool timer_schedule = params_.belief_schedule == params::BeliefSchedule::kTimer;
  belief_on_thread_ = timer_schedule && BeliefLoop::useThread();
  ros::NodeHandle sensor_nh(nh_), sensor_pnh(pnh_);
  if (belief_on_thread_)
  {
    sensor_nh.setCallbackQueue(&sensor_queue_);
    sensor_pnh.setCallbackQueue(&sensor_queue_);
  }
  else if (!timer_schedule)
  {
    sensor_nh.setCallbackQueue(&inline_queue_);
    sensor_pnh.setCallbackQueue(&inline_queue_);
  }

  reconfigure_ = std::make_unique<NodeReconfigure>(pnh_, params_);
  diagnostics_ = std::make_unique<NodeDiagnostics>(nh_, pnh_, *loop_, [this] { return controllerReport(); });
  diagnostics_->addFaultMonitor(pnh_, loop_->faultMonitor());

  // One publisher per command topic: checked now, before the first command, then on a thread.
  conflict_ = std::make_unique<safety::OutputConflict>(outputs_->commandTopic(), ros::this_node::getName());
  if (params_.publisher_check_period > 0.0)
  {
    std::vector<std::string> publishers;
    std::string error;
    const bool ok = PublisherWatch::publishersOf(outputs_->commandTopic(), &publishers, &error);
    publishersPolled(ok, publishers, error);
    publisher_watch_ =
        std::make_unique<PublisherWatch>(outputs_->commandTopic(), params_.publisher_check_period,
                                         [this](bool ok, const std::vector<std::string>& pubs, const std::string& why) {
                                           publishersPolled(ok, pubs, why);
                                         });
  }
  else
  {
    ROS_WARN_STREAM("jackal_AIC: publisher_check_period 0: another publisher on " << outputs_->commandTopic()
                                                                                  << " would go unnoticed");
  }

  action_timer_ = nh_.createTimer(ros::Duration(loop_->supervisor().actionLoop().nominalPeriod()),
                                  &AicNode::actionTimerCallback, this);
  diagnostics_->start(nh_, mutex_);
  startOutputGate();
  learned_model_ = std::make_unique<LearnedModelService>(pnh_, mutex_, *loop_, params_.learned_model_file);
  outputs_->startDebug(nh_, [this](DebugSnapshot* snapshot) {
    const std::lock_guard<std::mutex> lock(mutex_);
    loop_->advance();  // event schedule: the beliefs to now
    if (loop_->beliefSteps() == published_steps_)
    {
      return false;  // no belief step since the last publication (not running, or belief_rate < debug_rate)
    }
    published_steps_ = loop_->beliefSteps();
    const double sample = loop_->newestSampleStamp();  // NaN before the first: ROS time 0, no ~inference
    outputs_->capture(loop_->controller(), loop_->gyroBias().offset(), clock_.time(loop_->beliefTime()),
                      clock_.time(sample), snapshot);
    return true;
  });
  std::string schedule = "each event (belief_schedule event; messages on the network thread)";
  if (timer_schedule)
  {
    belief_loop_ = std::make_unique<BeliefLoop>(nh_, params_.aic.belief_rate, params_.realtime_priority, &sensor_queue_,
                                                [this](double interval) { beliefTick(interval); });
    if (belief_loop_->priorityRefused())
    {
      ROS_WARN_STREAM("jackal_AIC: belief loop: " << belief_loop_->description());
    }
    schedule = "a " + belief_loop_->description();
  }
  diagnostics_->setBeliefLoop(schedule);

  // The subscriptions last: with the event schedule a message's callback runs on roscpp's network
  // thread as soon as a publisher connects, and it uses everything built above (diagnostics, the
  // output gate, the conflict check).
  const auto hints = ros::TransportHints().tcpNoDelay();
  joint_sub_ = sensor_nh.subscribe("joint_states", 10, &AicNode::jointStateCallback, this, hints);
  imu_sub_ = sensor_nh.subscribe("imu/data", 10, &AicNode::imuCallback, this, hints);
  set_point_sub_ = sensor_pnh.subscribe("set_point", 10, &AicNode::setPointCallback, this, hints);
  status_sub_ = sensor_nh.subscribe("status", 10, &AicNode::statusCallback, this, hints);
  feedback_sub_ = sensor_nh.subscribe("feedback", 10, &AicNode::feedbackCallback, this, hints);
  ROS_INFO_STREAM("jackal_AIC: " << params_.aic.summary() << "; beliefs advanced on " << schedule
                                 << "; waiting for /joint_states, /imu/data and ~set_point");
  return true;
}

// ---------------------------------------------------------------------------
// Timers: ControlLoop events.

void AicNode::beliefTick(double interval)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!belief_on_thread_)
  {
    applyPendingParams();  // on ROS timers both loops apply; the thread leaves it to the spinner
  }
  loop_->beliefTimer(interval);
}

void AicNode::actionTimerCallback(const ros::TimerEvent& event)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  applyPendingParams();
  loop_->actionTimer(timerInterval(event));
}

// ---------------------------------------------------------------------------
// ControlLoop outputs (called with the lock held).

void AicNode::command(const loop::WheelCommand& command)
{
  if (!gate_.admit())
  {
    return;  // ~enable_output false: another controller drives (output_enable.cpp)
  }
  outputs_->publish(command);
  diagnostics_->commandPublished(command.latency);
}

void AicNode::startOutputGate()
{
  const std::string topic =
      nh_.resolveName(params_.output_mode == "cmd_vel" ? "jackal_velocity_controller/cmd_vel" : "cmd_drive");
  output_enable_ = std::make_unique<OutputEnable>(
      nh_, pnh_, mutex_, gate_,
      [this] {
        return loop_->restartFromMeasured() ? std::string("controller restarted from the measured state") :
                                              std::string("controller not running; it starts from the measured "
                                                          "state when it does");
      },
      topic);
}

void AicNode::healthEvent(safety::FaultMonitor::Event event, int channel)
{
  diagnostics_->publishHealth(event, channel);
}

void AicNode::log(loop::LogLevel level, const std::string& text)
{
  switch (level)
  {
    case loop::LogLevel::kInfo:
      ROS_INFO_STREAM("jackal_AIC: " << text);
      break;
    case loop::LogLevel::kWarn:
      ROS_WARN_STREAM("jackal_AIC: " << text);
      break;
    case loop::LogLevel::kError:
      ROS_ERROR_STREAM("jackal_AIC: " << text);
      break;
  }
}

void AicNode::publishersPolled(bool ok, const std::vector<std::string>& publishers, const std::string& error)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!ok)
  {
    conflict_->queryFailed();
    ROS_WARN_STREAM_THROTTLE(10.0, "jackal_AIC: cannot list the publishers of " << conflict_->topic() << ": " << error
                                                                                << " (keeping the last answer)");
    return;
  }
  // While ~enable_output holds the output closed this node publishes nothing there: another
  // publisher is then the one meant to drive (a field trial's stock runs), not a conflict.
  static const std::vector<std::string> kNone;
  const safety::OutputConflict::Event event = conflict_->update(gate_.enabled() ? publishers : kNone, clock_.now());
  switch (event)
  {
    case safety::OutputConflict::Event::kNone:
      return;
    case safety::OutputConflict::Event::kStarted:
    case safety::OutputConflict::Event::kChanged:
      ROS_ERROR_STREAM("jackal_AIC: " << conflict_->message(event));
      break;
    case safety::OutputConflict::Event::kEnded:
      ROS_INFO_STREAM("jackal_AIC: " << conflict_->message(event));
      break;
  }
  loop_->outputBlocked(conflict_->conflicted(), "another node publishes on " + conflict_->topic() + ": " +
                                                    conflict_->othersText() + "; publishing nothing there");
}

ControllerReport AicNode::controllerReport() const
{
  ControllerReport r = ControllerReport::of(loop_->controller(), loop_->active());
  r.guarded_outputs = outputs_->guardedOutputs() + loop_->guardedCommands();
  r.generalizer_drops = loop_->refusedSamples();
  if (loop_->controller().params().gyro_bias.enabled)
  {
    r.gyro_bias = loop_->gyroBias().bias();
    r.gyro_bias_learning = aic::statusText(loop_->gyroBias());
  }
  if (loop_->controller().params().tip_guard.enabled)
  {
    r.tip_guard = safety::statusText(loop_->tipGuard());
  }
  r.output_mode = params_.output_mode;
  r.output_clips = loop_->outputClips();
  r.last_output_clipped = loop_->lastOutputClipped();
  r.output_topic = conflict_->topic();
  r.other_publishers = publisher_watch_ ? conflict_->othersText() : "unchecked (publisher_check_period 0)";
  r.output_conflicts = conflict_->conflicts();
  r.blocked_commands = loop_->blockedCommands();
  return r;
}

// ---------------------------------------------------------------------------
// dynamic_reconfigure: NodeReconfigure validates and queues; applied here, between ticks.

void AicNode::applyPendingParams()
{
  const std::unique_ptr<params::NodeParams> next = reconfigure_->takePending();
  if (!next)
  {
    return;
  }
  try
  {
    loop_->setParams(*next);
  }
  catch (const std::exception& e)
  {
    ROS_ERROR_STREAM("jackal_AIC: reconfigure not applied: " << e.what());
    return;
  }
  diagnostics_->paramsApplied(*next);
  if (belief_loop_ && next->aic.belief_rate != params_.aic.belief_rate)
  {
    belief_loop_->setRate(next->aic.belief_rate);
  }
  if (next->aic.action_rate != params_.aic.action_rate)
  {
    action_timer_.setPeriod(ros::Duration(loop_->supervisor().actionLoop().nominalPeriod()));
  }
  params_ = loop_->params();
}

}  // namespace node
}  // namespace jackal_aic
