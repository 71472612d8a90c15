/**
 * \file control_loop.cpp
 * \brief The jackal_AIC node's logic, ROS-free (include/jackal_aic/loop/control_loop.hpp;
 *        doc/jackal_aic_node.md, 'Loops', 'Safety').
 */
#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/safety/command_guard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace loop
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Log lines of one kind are emitted at most once per this many seconds [s].
constexpr double kNoticePeriod = 1.0;

/// Throws std::invalid_argument listing every violation, if any.
const params::NodeParams& requireValid(const params::NodeParams& params)
{
  std::string message;
  for (const auto& v : params.validate())
  {
    message += (message.empty() ? "" : "; ") + v.toString();
  }
  if (!message.empty())
  {
    throw std::invalid_argument("invalid parameters: " + message);
  }
  return params;
}

SensorPairing::Config pairingConfig(const params::NodeParams& p)
{
  SensorPairing::Config c;
  c.left_joints = p.left_joints;
  c.right_joints = p.right_joints;
  c.imu_max_skew = p.imu_max_skew;
  c.min_sample_interval = p.min_sample_interval;
  c.max_gap = p.sensor_timeout;
  return c;
}

/// Seconds since an arbitrary origin on the monotonic clock (callback durations only).
double monotonicSeconds()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

void ControlLoop::Output::healthEvent(safety::FaultMonitor::Event /*event*/, int /*channel*/) {}

void ControlLoop::Output::log(LogLevel /*level*/, const std::string& /*text*/) {}

ControlLoop::ControlLoop(const params::NodeParams& params, const Clock& clock, Output& output)
  : params_(requireValid(params))
  , clock_(clock)
  , output_(output)
  , pairing_(pairingConfig(params))
  , pipeline_(params.aic, params.fdi)
  , supervisor_(params, clock)
  , goal_rate_(params::goalRateParams(params.aic))
  , newest_sample_stamp_(kNaN)
{
  if (params.output_mode == "cmd_vel")
  {
    cmd_vel_ = std::make_unique<CmdVelOutput>(params.cmd_vel);
  }
  last_notice_.fill(-std::numeric_limits<double>::infinity());
  belief_time_ = clock_.now();
}

ControlLoop::~ControlLoop() = default;

double ControlLoop::maxEventInterval() const
{
  return std::max(params_.sensor_timeout, kMaxBeliefIntervalFactor / params_.aic.belief_rate);
}

bool ControlLoop::due(Notice kind)
{
  const double now = clock_.now();
  double& last = last_notice_[static_cast<std::size_t>(kind)];
  if (now - last < kNoticePeriod)
  {
    return false;
  }
  last = now;
  return true;
}

// ---------------------------------------------------------------------------
// Events

bool ControlLoop::jointState(const JointStateInput& joints)
{
  checkClock();
  advanceBeliefs();   // with the inputs held until now
  refreshGoalRate();  // an expired ramp of the set point ends here
  SensorSample sample;
  DropReason reason = DropReason::kCount;
  if (!pairing_.addJointState(joints, &sample, &reason, &text_))
  {
    if (due(kNoticeDrop))
    {
      output_.log(LogLevel::kWarn, std::string("dropped input (") + toString(reason) + "): " + text_ + " [" +
                                       std::to_string(pairing_.drops(reason)) + " dropped for this reason so far]");
    }
    watch();
    return false;
  }
  if (checkFrozen(sample))
  {
    ++frozen_samples_;
    watch();  // stale: zero command, the sample history restarts
    return false;
  }
  if (!sample.imu_ok && due(kNoticeNoImu))
  {
    std::ostringstream os;
    os << "no imu message within " << params_.imu_max_skew << " s of joint_states stamp " << sample.stamp
       << ": controlling on the wheel encoders alone [" << pairing_.drops(DropReason::kNoImu)
       << " such samples so far]";
    output_.log(LogLevel::kWarn, os.str());
  }
  bool restarted = false;
  const aic::Generalizer::Status status =
      pipeline_.generalize(&sample.y, sample.h, sample.imu_ok, sample.first, &restarted);
  if (restarted)
  {
    supervisor_.historyRestarted();
  }
  if (status != aic::Generalizer::Status::kOk && status != aic::Generalizer::Status::kFirstSample)
  {
    ++refused_samples_;
    if (due(kNoticeRefused))
    {
      output_.log(LogLevel::kWarn, std::string("generalizer rejected a sample: ") + aic::toString(status));
    }
    watch();
    return false;
  }
  supervisor_.sampleAccepted(base::Vector2(sample.y(base::kOmegaLeft), sample.y(base::kOmegaRight)));
  pipeline_.guardTip(sample.y, sample.pitch_rate, sample.first ? 0.0 : sample.h, sample.imu_ok, sample.up_force);
  noticeTurnover();
  newest_sample_stamp_ = sample.stamp;
  watch();  // a warm history and a set point: the controller starts here, from this sample
  if (!supervisor_.active())
  {
    return true;
  }
  // FrozenJointStates compares travel and speeds exactly: a repeat is jackal_node's re-publication.
  const SamplePipeline::Measurement m = pipeline_.measure(sample.y, sample.h, sample.imu_ok, frozen_.repeats() > 0);
  if (!m.accepted)
  {
    ++refused_samples_;
    if (due(kNoticeRefused))
    {
      output_.log(LogLevel::kWarn, "controller refused a generalized measurement");
    }
    return false;
  }
  if (m.event != safety::FaultMonitor::Event::kNone)
  {
    output_.healthEvent(m.event, m.event_channel);
  }
  if (params_.action_trigger == params::ActionTrigger::kSample)
  {
    actionStep(sample.first ? -1.0 : sample.h);  // over the sensor interval (stamps), clamped to 3 periods
  }
  return true;
}

bool ControlLoop::imu(const ImuInput& imu)
{
  checkClock();
  if (!pairing_.addImu(imu, &text_))
  {
    if (due(kNoticeDrop))
    {
      const DropReason reason = imu.angular_velocity.allFinite() && imu.linear_acceleration.allFinite() ?
                                    DropReason::kImuStamp :
                                    DropReason::kImuNonFinite;
      output_.log(LogLevel::kWarn, std::string("dropped input (") + toString(reason) + "): " + text_ + " [" +
                                       std::to_string(pairing_.drops(reason)) + " dropped for this reason so far]");
    }
    return false;
  }
  supervisor_.imuAccepted();
  return true;
}

SetPointResult ControlLoop::setPoint(const double (&fields)[6])
{
  checkClock();
  advanceBeliefs();   // the old goal holds until now
  refreshGoalRate();  // an expired ramp of the set point ends here
  const SetPointResult result = supervisor_.setPoint(fields);
  switch (result)
  {
    case SetPointResult::kDropped:
      if (due(kNoticeSetPointDropped))
      {
        output_.log(LogLevel::kWarn, "dropped a set point with a NaN/Inf field [" +
                                         std::to_string(supervisor_.setPointDrops()) + " so far]");
      }
      return result;
    case SetPointResult::kClamped:
      if (due(kNoticeSetPointClamped))
      {
        std::ostringstream os;
        os << "set point (" << fields[0] << " m/s, " << fields[5] << " rad/s) clamped to (" << supervisor_.goal()(0)
           << ", " << supervisor_.goal()(2) << ") by max_linear_speed / max_angular_speed";
        output_.log(LogLevel::kWarn, os.str());
      }
      break;
    case SetPointResult::kAccepted:
      break;
  }
  goal_rate_.update(clock_.now(), supervisor_.goal());
  pipeline_.controller().setGoal(supervisor_.goal(), goal_rate_.rate(clock_.now()));
  watch();
  return result;
}

void ControlLoop::mcuStatus(bool drivers_active, bool external_stop_present, bool external_stop_stopped)
{
  checkClock();
  advanceBeliefs();
  refreshGoalRate();  // an expired ramp of the set point ends here
  supervisor_.mcuStatus(drivers_active, external_stop_present, external_stop_stopped);
  watch();
}

void ControlLoop::mcuFeedback(int actual_mode)
{
  checkClock();
  advanceBeliefs();
  refreshGoalRate();  // an expired ramp of the set point ends here
  supervisor_.mcuFeedback(actual_mode);
  watch();
}

void ControlLoop::outputBlocked(bool blocked, const std::string& why)
{
  advanceBeliefs();
  refreshGoalRate();  // an expired ramp of the set point ends here
  supervisor_.outputBlocked(blocked, why);
  watch();
}

void ControlLoop::advance()
{
  checkClock();
  advanceBeliefs();
  refreshGoalRate();  // an expired ramp of the set point ends here
  watch();
}

void ControlLoop::actionTimer(double interval)
{
  checkClock();
  advanceBeliefs();
  refreshGoalRate();  // an expired ramp of the set point ends here
  if (params_.action_trigger == params::ActionTrigger::kTimer)
  {
    actionStep(interval);
    return;
  }
  // The samples run the action; the timer keeps the command alive (the idle command, or a
  // repeat of the held command while samples are late) at about action_rate.
  watch();
  if (!supervisor_.active())
  {
    sendIdle();
  }
  else if (supervisor_.keepAliveDue())
  {
    if (onProbation())
    {
      sendCommand(base::Vector2::Zero(), kNaN, false);
    }
    else
    {
      sendCommand(pipeline_.controller().action(), kNaN);
    }
  }
}

void ControlLoop::beliefTimer(double interval)
{
  if (params_.belief_schedule == params::BeliefSchedule::kEvent)
  {
    advance();
    return;
  }
  checkClock();
  const double start = monotonicSeconds();
  const LoopScheduler::Tick tick = supervisor_.beliefLoop().tick(interval);
  watch();
  if (supervisor_.active())
  {
    integrate(tick.steps, tick.h);
  }
  belief_time_ = clock_.now();
  supervisor_.beliefLoop().recordDuration(monotonicSeconds() - start);
}

void ControlLoop::setParams(const params::NodeParams& next)
{
  requireValid(next);
  checkClock();
  advanceBeliefs();   // the old parameters hold until now
  refreshGoalRate();  // an expired ramp of the set point ends here
  const bool new_history = pipeline_.setParams(next.aic, next.fdi);
  pairing_.setConfig(pairingConfig(next));
  if (new_history)
  {
    pairing_.restartHistory();
    carryOut(supervisor_.embeddingOrderChanged());
  }
  supervisor_.setParams(next);
  goal_rate_.setParams(params::goalRateParams(next.aic));
  // Read at start only: the output stage and the belief schedule.
  const std::string output_mode = params_.output_mode;
  const params::DiffDriveParams cmd_vel = params_.cmd_vel;
  const params::BeliefSchedule schedule = params_.belief_schedule;
  params_ = next;
  params_.output_mode = output_mode;
  params_.cmd_vel = cmd_vel;
  params_.belief_schedule = schedule;
  output_.log(LogLevel::kInfo, "parameters applied (" + params_.aic.summary() + ")");
}

bool ControlLoop::checkFrozen(const SensorSample& sample)
{
  safety::FrozenJointStates::Input in;
  in.stamp = sample.stamp;
  in.travel = sample.travel;
  in.has_travel = sample.has_travel;
  in.speed = base::Vector2(sample.y(base::kOmegaLeft), sample.y(base::kOmegaRight));
  const safety::FrozenJointStates::Event event = frozen_.update(in);
  if (event == safety::FrozenJointStates::Event::kFrozen)
  {
    std::ostringstream os;
    os << "joint states frozen: travel and speeds (" << in.speed.transpose() << " rad/s) repeat exactly for "
       << frozen_.heldFor() << " s (" << frozen_.repeats() << " repeats) with the wheels turning (longer than "
       << frozen_.holdTime() << " s): the MCU's feedback has stopped behind jackal_node; treated as sensor loss ["
       << frozen_.events() << " frozen stream(s) so far]";
    supervisor_.jointStatesFrozen(true, os.str());
  }
  else if (event == safety::FrozenJointStates::Event::kThawed)
  {
    supervisor_.jointStatesFrozen(false);
    output_.log(LogLevel::kInfo, "joint states no longer frozen (new data): the sensors are used again");
  }
  return frozen_.frozen();
}

// ---------------------------------------------------------------------------
// Time moving backwards

bool ControlLoop::checkClock()
{
  const double back = time_jump_.observe(clock_.now());
  if (!(back > 0.0))
  {
    return false;
  }
  restartTimeline(-back);
  return true;
}

void ControlLoop::resetTimeline()
{
  if (!checkClock())
  {
    restartTimeline(0.0);
  }
}

void ControlLoop::restartTimeline(double shift)
{
  const double now = clock_.now();
  const bool was_running = supervisor_.active();
  goal_rate_.reset();
  refreshGoalRate();  // no slope from the old timeline
  frozen_.reset();    // its stamps were on the old timeline
  supervisor_.jointStatesFrozen(false);
  belief_time_ = now;
  newest_sample_stamp_ = kNaN;
  last_notice_.fill(-std::numeric_limits<double>::infinity());  // the throttles' times were on the old timeline
  // Restarts the pairing and the generalizer's history; a running controller stops (nothing is
  // commanded until the new timeline's first sample: the idle command is then the measured wheels).
  carryOut(supervisor_.resetTimeline(shift));
  std::ostringstream os;
  os << "ROS time moved back " << -shift << " s (to " << now
     << " s): sensor pairing, sample history, beliefs, goal rate and timeouts restart on the new timeline";
  if (was_running)
  {
    os << "; the controller restarts from the measured wheel speeds after " << params_.aic.numOrders()
       << " samples of it";
  }
  os << " [" << time_jump_.jumps() << " jump(s) back so far]";
  output_.log(LogLevel::kWarn, os.str());
}

// ---------------------------------------------------------------------------
// Beliefs, watchdogs, transitions

void ControlLoop::advanceBeliefs()
{
  if (params_.belief_schedule != params::BeliefSchedule::kEvent)
  {
    return;
  }
  const double now = clock_.now();
  if (!supervisor_.active())
  {
    belief_time_ = now;
    return;
  }
  const double interval = std::min(now - belief_time_, maxEventInterval());
  if (!(interval > 0.0))
  {
    return;  // the same instant (or the clock stepped back): nothing to integrate
  }
  // n equal steps of at most h_mu; on the belief grid (interval = k h_mu) exactly k steps of h_mu.
  const double h_mu = 1.0 / params_.aic.belief_rate;
  const int steps = std::max(1, static_cast<int>(std::ceil(interval / h_mu - 1e-9)));
  belief_time_ = now;
  integrate(steps, interval / steps);
}

void ControlLoop::refreshGoalRate()
{
  if (params_.aic.reference.generalized_goal)
  {
    pipeline_.controller().setGoal(supervisor_.goal(), goal_rate_.rate(clock_.now()));
  }
}

void ControlLoop::integrate(int steps, double h)
{
  for (int i = 0; i < steps; ++i)
  {
    ++belief_steps_;
    if (pipeline_.controller().updateBeliefs(h) == aic::ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway("belief update");
      return;
    }
    belief_integrated_ += h;
    probation_left_ -= h;
  }
}

void ControlLoop::watch()
{
  carryOut(supervisor_.update());
}

void ControlLoop::carryOut(const Supervisor::Transition& t)
{
  if (t.restart_history)
  {
    // Sensors are gone: the next sample starts a new history (and a new warm-up).
    pipeline_.restartHistory();
    pairing_.restartHistory();
  }
  if (t.warn())
  {
    // kStale: zero command; kHeld: the reason says the command holds the measured wheel speeds.
    output_.log(LogLevel::kWarn,
                supervisor_.reason() + (supervisor_.state() == NodeState::kHeld ? "" : "; commanding zero"));
  }
  if (t.activate())
  {
    activate();
  }
  else if (t.deactivate())
  {
    last_stop_reason_ = supervisor_.reason();
    sendIdle();  // at once, not at the next action tick
  }
}

void ControlLoop::activate()
{
  ++starts_;
  const base::Vector2& wheels = supervisor_.measuredWheels();
  pipeline_.activate(wheels, supervisor_.goal());  // beliefs at the measured twist, action at the wheels
  refreshGoalRate();
  if (cmd_vel_)
  {
    cmd_vel_->reset(wheels);  // the stock controller's acceleration limit starts there too
  }
  belief_time_ = clock_.now();
  // After a runaway the beliefs must first show they no longer diverge: an Euler-unstable belief
  // update re-diverges within a few belief steps of every restart, faster than the runaway limit
  // can stop an action step from reading a belief part-way there (and the wheel clamp would turn
  // that into +-max_wheel_speed). The hold's zero command goes on for one action period.
  probation_left_ = restart_after_runaway_ ? 1.0 / params_.aic.action_rate : 0.0;
  restart_after_runaway_ = false;
  std::ostringstream os;
  os << "running (start from measured wheels " << wheels.transpose() << " rad/s, goal "
     << supervisor_.goal().transpose() << ")";
  if (starts_ > 1)
  {
    os << "; resumed after: " << last_stop_reason_ << " [start " << starts_ << "]";
  }
  if (onProbation())
  {
    os << "; zero command until the beliefs run " << probation_left_ << " s without a runaway";
  }
  output_.log(LogLevel::kInfo, os.str());
}

bool ControlLoop::restartFromMeasured()
{
  if (!supervisor_.active())
  {
    return false;
  }
  activate();
  return true;
}

void ControlLoop::noticeTurnover()
{
  const bool turned_over = pipeline_.controller().turnedOver();
  if (turned_over == turned_over_)
  {
    return;
  }
  turned_over_ = turned_over;
  const safety::TipGuard& guard = pipeline_.tipGuard();
  std::ostringstream os;
  os << (turned_over ? "the robot has turned over; zero command until it is upright" :
                       "the body is upright again: the command resumes")
     << " (the tip-over guard's pitch estimate " << guard.pitch() << " rad, tip_guard_turnover_pitch "
     << guard.params().turnover_pitch << " rad; the IMU's z specific force " << guard.upForce()
     << " m/s^2, below 0 on its back" << (guard.upsideDown() ? ": upside down)" : ")");
  output_.log(turned_over ? LogLevel::kError : LogLevel::kWarn, os.str());
}

void ControlLoop::handleRunaway(const char* where)
{
  restart_after_runaway_ = true;
  probation_left_ = 0.0;
  carryOut(supervisor_.runaway(where));
  if (due(kNoticeRunaway))
  {
    std::ostringstream os;
    if (std::strcmp(where, "action update") == 0)
    {
      os << "runaway action in the action update (non-finite, or a step beyond 2 max_wheel_speed "
         << 2.0 * params_.aic.max_wheel_speed << " rad/s)";
    }
    else
    {
      os << "runaway beliefs in the " << where << " (|mu| > runaway_limit " << params_.aic.runaway_limit
         << " or non-finite)";
    }
    os << "; controller reset, zero command for " << params_.runaway_hold_time << " s [" << supervisor_.runaways()
       << " runaway(s) so far]";
    output_.log(LogLevel::kError, os.str());
  }
}

void ControlLoop::actionStep(double interval)
{
  const double start = monotonicSeconds();
  const double h = supervisor_.actionLoop().tick(interval).h;
  watch();
  if (!supervisor_.active())
  {
    sendIdle();
  }
  else if (onProbation())
  {
    sendCommand(base::Vector2::Zero(), kNaN, false);  // the runaway hold's zero command goes on
  }
  else if (pipeline_.controller().updateAction(h) == aic::ActiveInferenceController::Status::kRunaway)
  {
    handleRunaway("action update");  // sends the zero command
  }
  else
  {
    ++action_steps_;
    supervisor_.actionPublished();
    sendCommand(pipeline_.controller().action(), clock_.now() - newest_sample_stamp_);
  }
  supervisor_.actionLoop().recordDuration(monotonicSeconds() - start);
}

// ---------------------------------------------------------------------------
// Command stage

void ControlLoop::sendCommand(const base::Vector2& wheels, double latency, bool stock_limits)
{
  if (supervisor_.state() == NodeState::kBlocked)
  {
    ++blocked_commands_;  // another node publishes on the output topic: publish nothing
    return;
  }
  WheelCommand c;
  c.latency = latency;
  const safety::GuardedWheels guarded = safety::guardWheelCommand(wheels, params_.aic.max_wheel_speed);
  c.wheels = guarded.wheels;
  if (guarded.replaced)
  {
    ++guarded_commands_;
    if (due(kNoticeGuard))
    {
      output_.log(LogLevel::kError, "non-finite wheel command replaced by zero");
    }
  }
  if (cmd_vel_ && !stock_limits)
  {
    // The idle zero: published as it is, so the stock diff drive starts its own deceleration
    // ramp (the same limits) at its next cycle instead of following ours one cycle behind.
    c.cmd_vel = true;
    c.twist = twistFromWheels(cmd_vel_->limiter().params(), c.wheels);
    last_clipped_ = false;
    cmd_vel_->reset(supervisor_.measuredWheels());  // where the diff drive's ramp starts, roughly
  }
  else if (cmd_vel_)
  {
    // The stock controller limits over its own 50 Hz period; ours is the action period.
    const CmdVelOutput::Result r = cmd_vel_->convert(c.wheels, supervisor_.actionLoop().nominalPeriod());
    c.cmd_vel = true;
    c.twist = r.twist;
    c.clipped = r.clipped;
    last_clipped_ = r.clipped;
    if (r.clipped)
    {
      if (due(kNoticeClip))
      {
        std::ostringstream os;
        os << "wheel command " << c.wheels.transpose() << " rad/s exceeds the stock controller's limits; clipped to "
           << r.wheels.transpose() << " rad/s [" << cmd_vel_->clips() << " so far]";
        output_.log(LogLevel::kWarn, os.str());
      }
      c.wheels = r.wheels;
      if (supervisor_.active())
      {
        pipeline_.controller().setAction(r.wheels);  // anti-windup: the action is what the robot gets
      }
    }
  }
  output_.command(c);
}

void ControlLoop::sendIdle()
{
  switch (supervisor_.idleCommand())
  {
    case IdleCommand::kNone:
      return;  // nothing measured yet to command from
    case IdleCommand::kMeasured:
      // kHeld: no windup against stopped motors; warming up: the controller starts from these.
      sendCommand(supervisor_.measuredWheels(), kNaN);
      return;
    case IdleCommand::kZero:
      break;
  }
  sendCommand(base::Vector2::Zero(), kNaN, false);  // at once: the diff drive ramps down itself
}

}  // namespace loop
}  // namespace jackal_aic
