/**
 * \file supervisor.cpp
 * \brief The jackal_AIC node's state machine, watchdogs and loop scheduling
 *        (doc/jackal_aic_node.md, 'Loops' and 'Safety'). ROS-free.
 */
#include "jackal_aic/loop/supervisor.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <utility>

namespace jackal_aic
{
namespace loop
{
Supervisor::Supervisor(const params::NodeParams& params, const Clock& clock)
  : clock_(clock)
  , sensor_timeout_(params.sensor_timeout)
  , set_point_timeout_(params.set_point_timeout)
  , runaway_hold_time_(params.runaway_hold_time)
  , max_linear_speed_(params.max_linear_speed)
  , max_angular_speed_(params.max_angular_speed)
  , num_orders_(params.aic.numOrders())
  , belief_loop_(params.aic.belief_rate, kMaxBeliefIntervalFactor, true, kMinBeliefCatchUpInterval)
  , action_loop_(params.aic.action_rate, kMaxActionIntervalFactor, false)
  , runaway_until_(-std::numeric_limits<double>::infinity())
{
}

void Supervisor::setParams(const params::NodeParams& params)
{
  sensor_timeout_ = params.sensor_timeout;
  set_point_timeout_ = params.set_point_timeout;
  runaway_hold_time_ = params.runaway_hold_time;
  max_linear_speed_ = params.max_linear_speed;
  max_angular_speed_ = params.max_angular_speed;
  num_orders_ = params.aic.numOrders();
  belief_loop_.setRate(params.aic.belief_rate);
  action_loop_.setRate(params.aic.action_rate);
}

void Supervisor::sampleAccepted(const base::Vector2& measured_wheels)
{
  warm_samples_ = std::min(warm_samples_ + 1, base::kMaxOrders + 1);
  measured_wheels_ = measured_wheels;
  if (!has_sample_)
  {
    first_sample_ = clock_.now();
  }
  has_sample_ = true;
  new_timeline_ = false;
  last_sample_ = clock_.now();
}

void Supervisor::imuAccepted()
{
  has_imu_ = true;
  last_imu_ = clock_.now();
}

void Supervisor::mcuStatus(bool drivers_active, bool external_stop_present, bool external_stop_stopped)
{
  mcu_drivers_active_ = drivers_active;
  mcu_external_stop_ = external_stop_present && external_stop_stopped;
}

void Supervisor::mcuFeedback(int actual_mode)
{
  has_mcu_mode_ = true;
  mcu_mode_ = actual_mode;
  last_mcu_mode_ = clock_.now();
}

void Supervisor::outputBlocked(bool blocked, const std::string& why)
{
  output_blocked_ = blocked;
  blocked_why_ = blocked ? why : std::string();
}

void Supervisor::jointStatesFrozen(bool frozen, const std::string& why)
{
  joints_frozen_ = frozen;
  frozen_why_ = frozen ? why : std::string();
}

bool Supervisor::mcuStopped(std::string* why) const
{
  std::string reason;
  if (!mcu_drivers_active_)
  {
    reason = "the MCU reports the motor drivers inactive (/status drivers_active false)";
  }
  else if (mcu_external_stop_)
  {
    reason = "the MCU reports an external stop engaged (/status driver_external_stop_stopped)";
  }
  else if (has_mcu_mode_ && mcu_mode_ == kMcuModeNone && clock_.now() - last_mcu_mode_ <= kMcuFeedbackExpiry)
  {
    reason = "the MCU reports actual_mode MODE_NONE (/feedback): the motors do not follow commands";
  }
  if (why != nullptr)
  {
    *why = reason;
  }
  return !reason.empty();
}

SetPointResult Supervisor::setPoint(const double (&fields)[6])
{
  for (double v : fields)
  {
    if (!std::isfinite(v))
    {
      ++set_point_drops_;
      return SetPointResult::kDropped;
    }
  }
  double vx = fields[0];
  double wz = fields[5];
  SetPointResult result = SetPointResult::kAccepted;
  // Validated limits are > 0 (NodeParams::validate()), so clamp's bounds are ordered.
  const double vx_max = max_linear_speed_;
  const double wz_max = max_angular_speed_;
  if (std::abs(vx) > vx_max || std::abs(wz) > wz_max)
  {
    ++set_point_clamps_;
    vx = std::clamp(vx, -vx_max, vx_max);
    wz = std::clamp(wz, -wz_max, wz_max);
    result = SetPointResult::kClamped;
  }
  goal_ << vx, 0.0, wz;
  has_set_point_ = true;
  last_set_point_ = clock_.now();
  return result;
}

Supervisor::Transition Supervisor::update()
{
  const double now = clock_.now();
  const bool sensors_fresh = has_sample_ && now - last_sample_ <= sensor_timeout_ && !joints_frozen_;
  const bool set_point_fresh = has_set_point_ && now - last_set_point_ <= set_point_timeout_;
  const bool warm = warm_samples_ >= num_orders_;

  NodeState next = NodeState::kRunning;
  if (output_blocked_)
  {
    next = NodeState::kBlocked;
  }
  else if (now < runaway_until_)
  {
    next = NodeState::kRunaway;
  }
  else if (!has_sample_ || (sensors_fresh && (!has_set_point_ || (set_point_fresh && !warm))))
  {
    next = NodeState::kWaiting;
  }
  else if (!sensors_fresh || !set_point_fresh)
  {
    next = NodeState::kStale;
  }
  else if (mcuStopped())
  {
    next = NodeState::kHeld;
  }

  bool restart = false;
  if (has_sample_ && !sensors_fresh && warm_samples_ > 0)
  {
    // Sensors are gone: the next sample starts a new history (and a new warm-up).
    warm_samples_ = 0;
    restart = true;
  }
  if (next == state_ && !(next == NodeState::kBlocked && reason_ != blocked_why_))
  {
    Transition t;
    t.from = t.to = state_;
    t.restart_history = restart;
    return t;
  }
  // Only on a change of state: this runs every belief tick.
  std::ostringstream reason;
  switch (next)
  {
    case NodeState::kRunaway:
      reason << "runaway reset; zero command until the hold time ends";
      break;
    case NodeState::kWaiting:
      reason << (!has_sample_    ? "no sensor sample yet" :
                 !has_set_point_ ? "no set point yet on ~set_point" :
                                   "warming up the generalizer");
      break;
    case NodeState::kStale:
      if (joints_frozen_)
      {
        reason << frozen_why_;
      }
      else if (!sensors_fresh)
      {
        reason << "no sensor sample for " << (now - last_sample_) << " s (sensor_timeout " << sensor_timeout_ << " s)";
      }
      else
      {
        reason << "no set point for " << (now - last_set_point_) << " s (set_point_timeout " << set_point_timeout_
               << " s)";
      }
      ++stale_events_;
      break;
    case NodeState::kHeld: {
      std::string why;
      mcuStopped(&why);
      reason << why << "; holding the command at the measured wheel speeds";
      ++mcu_stops_;
      break;
    }
    case NodeState::kBlocked:
      reason << blocked_why_;
      if (state_ != NodeState::kBlocked)
      {
        ++blocked_events_;
      }
      break;
    case NodeState::kRunning:
      reason << "controlling";
      break;
  }
  Transition t = enter(next, reason.str());
  t.restart_history = restart;
  return t;
}

Supervisor::Transition Supervisor::runaway(const std::string& where)
{
  ++runaways_;
  runaway_until_ = clock_.now() + runaway_hold_time_;
  return enter(NodeState::kRunaway, "runaway in the " + where);
}

Supervisor::Transition Supervisor::embeddingOrderChanged()
{
  warm_samples_ = 0;
  if (!active())
  {
    Transition t;
    t.from = t.to = state_;
    return t;
  }
  return enter(NodeState::kWaiting, "embedding order changed; warming up");
}

Supervisor::Transition Supervisor::resetTimeline(double shift)
{
  if (std::isfinite(shift))
  {
    for (double* t : { &last_sample_, &last_imu_, &last_set_point_, &last_mcu_mode_, &last_action_, &first_sample_,
                       &runaway_until_ })
    {
      *t += shift;  // -inf (no runaway hold) stays -inf
    }
  }
  warm_samples_ = 0;
  new_timeline_ = true;
  if (!active())
  {
    Transition t;
    t.from = t.to = state_;
    t.restart_history = true;
    return t;
  }
  std::ostringstream reason;
  reason << "ROS time moved back " << -shift << " s; warming up on the new timeline";
  Transition t = enter(NodeState::kWaiting, reason.str());
  t.restart_history = true;
  return t;
}

IdleCommand Supervisor::idleCommand() const
{
  switch (state_)
  {
    case NodeState::kHeld:
      return IdleCommand::kMeasured;
    case NodeState::kWaiting: {
      if (!has_sample_ || new_timeline_)
      {
        return IdleCommand::kNone;
      }
      const double now = clock_.now();
      const bool sensors_fresh = now - last_sample_ <= sensor_timeout_ && !joints_frozen_;
      const bool set_point_ok =
          has_set_point_ ? now - last_set_point_ <= set_point_timeout_ : now - first_sample_ <= set_point_timeout_;
      return sensors_fresh && set_point_ok ? IdleCommand::kMeasured : IdleCommand::kZero;
    }
    case NodeState::kRunning:
    case NodeState::kStale:
    case NodeState::kRunaway:
    case NodeState::kBlocked:  // nothing is published while blocked; zero if it were
      break;
  }
  return IdleCommand::kZero;
}

Supervisor::Transition Supervisor::enter(NodeState next, std::string reason)
{
  Transition t;
  t.from = state_;
  t.to = next;
  t.changed = next != state_;
  state_ = next;
  reason_ = std::move(reason);
  return t;
}

double Supervisor::sampleAge() const
{
  return has_sample_ ? clock_.now() - last_sample_ : -1.0;
}

double Supervisor::imuAge() const
{
  return has_imu_ ? clock_.now() - last_imu_ : -1.0;
}

double Supervisor::setPointAge() const
{
  return has_set_point_ ? clock_.now() - last_set_point_ : -1.0;
}

bool Supervisor::sensorsFresh() const
{
  return has_sample_ && clock_.now() - last_sample_ <= sensor_timeout_ && !joints_frozen_;
}

bool Supervisor::setPointFresh() const
{
  return has_set_point_ && clock_.now() - last_set_point_ <= set_point_timeout_;
}

}  // namespace loop
}  // namespace jackal_aic
