#pragma once
/**
 * \file supervisor.hpp
 * \brief What the jackal_AIC node decides, without ROS: the node's state machine and
 *        watchdogs, set-point checks, the loops' catch-up scheduling and statistics. The
 *        clock is injected (Clock), so every transition is testable without roscore.
 *        Behaviour: doc/jackal_aic_node.md, 'Loops' and 'Safety'.
 *
 * The node (src/ros/aic_node.cpp) is wiring: it reports inputs (sampleAccepted(),
 * setPoint(), ...), asks update() at every timer tick and carries out the Transition
 * (activate the controller, publish a zero command, restart the sample history, log).
 */

#include <cstdint>
#include <string>

#include "jackal_aic/loop/clock.hpp"
#include "jackal_aic/loop/loop_scheduler.hpp"
#include "jackal_aic/loop/node_state.hpp"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace loop
{
/// A stop reported by jackal_msgs/Feedback (actual_mode MODE_NONE) counts for this long after
/// the message [s]: the MCU publishes Feedback at 50 Hz, so a silent bridge does not hold forever.
constexpr double kMcuFeedbackExpiry = 0.5;
/// jackal_msgs/Drive MODE_NONE: the motors do not follow commands (Feedback actual_mode).
constexpr int kMcuModeNone = -1;

/// What the loop commands while the controller is not running (Supervisor::idleCommand()).
enum class IdleCommand
{
  kNone,     ///< nothing: no measurement of the robot yet (start, or a new timeline's first sample)
  kZero,     ///< zero wheel speeds
  kMeasured  ///< the measured wheel speeds of the newest sample (bumpless)
};

/// Outcome of a set-point check (Supervisor::setPoint()).
enum class SetPointResult
{
  kAccepted,  ///< finite and within the limits
  kClamped,   ///< finite; linear.x or angular.z clamped to max_linear_speed / max_angular_speed
  kDropped    ///< a NaN/Inf in some field: ignored
};

/**
 * \brief The jackal_AIC node's state machine, watchdogs and loop scheduling
 *        (doc/jackal_aic_node.md, 'Safety' and 'Loops').
 *
 * States and transitions, evaluated by update() at the clock's time:
 * - kBlocked while the output is blocked (outputBlocked(true): another node publishes on the
 *   output topic, OutputConflict): the node publishes nothing, so the controller is stopped;
 * - else kRunaway while a runaway hold is on (runaway() starts one of runaway_hold_time);
 * - else kWaiting with no sensor sample yet, or with fresh sensors and no set point yet,
 *   or with fresh sensors and set point while fewer than p+1 samples have reached the
 *   generalizer since its (re)start (warm-up);
 * - else kStale if the last accepted sample is older than sensor_timeout, the joint states
 *   are frozen (jointStatesFrozen(true): the same data repeat while the wheels turn,
 *   FrozenJointStates) or the last set point is older than set_point_timeout;
 * - else kHeld while the MCU reports a stop (mcuStopped(): jackal_msgs/Status with
 *   drivers_active false or an external stop present and stopped, or a jackal_msgs/Feedback
 *   with actual_mode MODE_NONE within kMcuFeedbackExpiry): the node commands the measured
 *   wheel speeds, so the action does not wind up against motors that do not move;
 * - else kRunning.
 * Entering kRunning activates the controller (reset, started from the measured wheel speeds:
 * bumpless, also on leaving kHeld or kBlocked); leaving it deactivates it (the idle command at once,
 * idleCommand(): zero, or the measured wheel speeds in kHeld and while warming up). Losing the sensors also restarts the sample history (the generalizer warms up
 * again). The controller is active exactly in kRunning.
 * Not thread-safe: call from the node's one spinner thread.
 */
class Supervisor
{
public:
  /// What update(), runaway() or historyRestarted() asks the node to do.
  struct Transition
  {
    bool changed = false;                  ///< the state changed
    NodeState from = NodeState::kWaiting;  ///< state before
    NodeState to = NodeState::kWaiting;    ///< state after
    bool restart_history = false;          ///< sensors lost: reset the generalizer and the pairing history
    /// Entered kRunning: reset the controller, start it from the measured wheel speeds.
    bool activate() const { return changed && to == NodeState::kRunning; }
    /// Left kRunning: stop the controller and publish the idle command now (zero; measured wheels in kHeld).
    bool deactivate() const { return changed && from == NodeState::kRunning; }
    /// Entered kStale or kHeld: log a warning with reason().
    bool warn() const { return changed && (to == NodeState::kStale || to == NodeState::kHeld); }
  };

  /**
   * \param params  timeouts, hold time, set-point limits, embedding order (warm-up length),
   *                loop rates; validated (NodeParams::validate())
   * \param clock   time source; must outlive the supervisor
   */
  Supervisor(const params::NodeParams& params, const Clock& clock);

  /// Take new validated parameters (timeouts, limits, warm-up length, loop rates); the state is kept.
  void setParams(const params::NodeParams& params);

  // ---- inputs
  /// The generalizer (re)started its history (first sample after a gap): the warm-up starts over.
  void historyRestarted() { warm_samples_ = 0; }
  /// A sample reached the generalizer (fresh sensors; one more warm-up sample).
  void sampleAccepted(const base::Vector2& measured_wheels);
  /// A valid Imu message arrived (for diagnostics only).
  void imuAccepted();
  /**
   * \brief Check a set point (geometry_msgs/Twist fields) and, unless dropped, take it as the goal.
   * \param fields  linear x, y, z [m/s], angular x, y, z [rad/s]
   * \return kDropped (any NaN/Inf: ignored, counted), kClamped (|linear.x| > max_linear_speed or
   *         |angular.z| > max_angular_speed: clamped, counted) or kAccepted; the goal is
   *         (linear.x, 0, angular.z) after clamping
   */
  SetPointResult setPoint(const double (&fields)[6]);

  /**
   * \brief The MCU's jackal_msgs/Status (1 Hz, and at once when the run/stop loop changes):
   *        the MCU stops the motors when drivers_active is false or an external stop is
   *        present and stopped. Kept until the next Status.
   */
  void mcuStatus(bool drivers_active, bool external_stop_present, bool external_stop_stopped);
  /**
   * \brief The MCU's jackal_msgs/Feedback (50 Hz): actual_mode == kMcuModeNone (MODE_NONE)
   *        means the motors do not follow commands; counts for kMcuFeedbackExpiry.
   */
  void mcuFeedback(int actual_mode);
  /**
   * \brief Whether another node publishes on the output topic (the node's OutputConflict):
   *        while blocked the state is kBlocked and nothing is published; kept until the next call.
   * \param blocked  true while the conflict lasts
   * \param why      the reason shown in diagnostics, e.g. "another node publishes on /cmd_drive: /jackal_node"
   */
  void outputBlocked(bool blocked, const std::string& why = "");
  /**
   * \brief Whether the joint states are frozen (FrozenJointStates: a stream that keeps coming
   *        with the same data while the wheels turn): while frozen the sensors count as lost, as
   *        after sensor_timeout (kStale, zero command, the sample history restarts); kept until
   *        the next call.
   * \param frozen  true while the stream is frozen
   * \param why     the reason shown in diagnostics and the log, e.g. "joint states frozen: ..."
   */
  void jointStatesFrozen(bool frozen, const std::string& why = "");
  /// The joint states are frozen now (jointStatesFrozen(true)).
  bool jointStatesFrozen() const { return joints_frozen_; }

  // ---- decisions
  /// Watchdogs at the clock's time (every timer tick). See the class comment.
  Transition update();
  /**
   * \brief The controller reported a runaway: hold a zero command for runaway_hold_time.
   * \param where  "belief update" or "action update", for the reason
   * \return the transition (to kRunaway; deactivate() is true when it was running)
   */
  Transition runaway(const std::string& where);
  /**
   * \brief The embedding order changed live: the warm-up starts over; if running, go to
   *        kWaiting ("embedding order changed; warming up") and deactivate.
   */
  Transition embeddingOrderChanged();
  /**
   * \brief The clock moved backwards (TimeJumpDetector): move every stored time by `shift`
   *        [s] (new reading - the old timeline's latest, < 0), so the ages of the last sample,
   *        IMU message, set point, MCU feedback and action, and the rest of a runaway hold,
   *        are kept; the warm-up starts over and, until the first sample of the new timeline,
   *        idleCommand() is kNone. Counters, the goal and the MCU state are kept. If running,
   *        go to kWaiting ("ROS time moved back ...; warming up on the new timeline").
   * \return the transition (deactivate() when it was running); a non-finite shift moves nothing
   */
  Transition resetTimeline(double shift);

  // ---- state
  /// The current state (reported in diagnostics as toString(state())).
  NodeState state() const { return state_; }
  /// Why the node is in its state, e.g. "no set point yet on ~set_point".
  const std::string& reason() const { return reason_; }
  /// True exactly in kRunning.
  bool active() const { return state_ == NodeState::kRunning; }
  /// The goal mu_d = (linear.x [m/s], 0, angular.z [rad/s]) of the last accepted set point.
  const base::Vector3& goal() const { return goal_; }
  /// Wheel speeds (omega_L, omega_R) [rad/s] of the last accepted sample.
  const base::Vector2& measuredWheels() const { return measured_wheels_; }
  /// Samples accepted since the last history restart (at most kMaxOrders + 1).
  int warmSamples() const { return warm_samples_; }
  /**
   * \brief What to command while the controller is not running:
   *  - kHeld: kMeasured (no windup against stopped motors);
   *  - kWaiting before any sample, or after resetTimeline() before the new timeline's first
   *    sample: kNone (nothing measured to start from; the base keeps its last command for its
   *    own timeout, and sensor_timeout still leads to kStale and zero);
   *  - kWaiting with fresh samples while the set point is fresh, or, before the first set
   *    point, within set_point_timeout of the first sample: kMeasured (warming up: the
   *    controller then starts from the same wheel speeds, so a restart of the node, of the
   *    sensors or of the timeline commands no jump);
   *  - otherwise (kStale, kRunaway, kWaiting without a set point for longer): kZero.
   */
  IdleCommand idleCommand() const;

  /// The MCU reports a stop now (see mcuStatus(), mcuFeedback()); *why (optional) says which.
  bool mcuStopped(std::string* why = nullptr) const;
  /// MCU stops seen (entries into kHeld).
  std::uint64_t mcuStops() const { return mcu_stops_; }
  /// The output is blocked now (outputBlocked(true)).
  bool blocked() const { return output_blocked_; }
  /// Entries into kBlocked.
  std::uint64_t blockedEvents() const { return blocked_events_; }

  /// Age of the last accepted sample [s] at the clock's time; -1 if there was none.
  double sampleAge() const;
  /// Age of the last valid Imu message [s]; -1 if there was none.
  double imuAge() const;
  /// Age of the last accepted set point [s]; -1 if there was none.
  double setPointAge() const;
  /// A sample was accepted within sensor_timeout and the joint states are not frozen.
  bool sensorsFresh() const;
  /// A set point was accepted within set_point_timeout.
  bool setPointFresh() const;

  /// An action step published a command now (action_trigger sample: see keepAliveDue()).
  void actionPublished() { last_action_ = clock_.now(); }
  /**
   * \brief action_trigger sample: true while running when no action step has published for
   *        kKeepAlivePeriods action periods (samples late, not yet stale): the action timer
   *        then repeats the held command, so the MCU keeps receiving commands at about
   *        action_rate.
   */
  bool keepAliveDue() const
  {
    return active() && clock_.now() - last_action_ > kKeepAlivePeriods * action_loop_.nominalPeriod();
  }
  /// keepAliveDue()'s threshold [action periods].
  static constexpr double kKeepAlivePeriods = 1.5;

  // ---- counters (since start; shown in diagnostics)
  /// Runaway resets (runaway() calls).
  std::uint64_t runaways() const { return runaways_; }
  /// Entries into kStale.
  std::uint64_t staleEvents() const { return stale_events_; }
  /// Set points dropped for a NaN/Inf field.
  std::uint64_t setPointDrops() const { return set_point_drops_; }
  /// Set points clamped to max_linear_speed / max_angular_speed.
  std::uint64_t setPointClamps() const { return set_point_clamps_; }

  // ---- loops
  /// The belief loop: belief_rate, intervals clamped to kMaxBeliefIntervalFactor periods, catch-up.
  LoopScheduler& beliefLoop() { return belief_loop_; }
  /// The action loop: action_rate, intervals clamped to kMaxActionIntervalFactor periods, one step a tick.
  LoopScheduler& actionLoop() { return action_loop_; }
  /// \copydoc beliefLoop()
  const LoopScheduler& beliefLoop() const { return belief_loop_; }
  /// \copydoc actionLoop()
  const LoopScheduler& actionLoop() const { return action_loop_; }

private:
  Transition enter(NodeState next, std::string reason);

  const Clock& clock_;
  double sensor_timeout_;
  double set_point_timeout_;
  double runaway_hold_time_;
  double max_linear_speed_;
  double max_angular_speed_;
  int num_orders_;
  LoopScheduler belief_loop_;
  LoopScheduler action_loop_;

  NodeState state_ = NodeState::kWaiting;
  std::string reason_ = "no sensor sample yet";
  bool has_sample_ = false, has_imu_ = false, has_set_point_ = false;
  double last_sample_ = 0.0, last_imu_ = 0.0, last_set_point_ = 0.0;  ///< receipt times [s]
  double runaway_until_;                                              ///< end of the runaway hold [s]; -inf: none
  double first_sample_ = 0.0;  ///< receipt time of the first sample since start [s]
  bool new_timeline_ = false;  ///< resetTimeline() and no sample of the new timeline yet
  int warm_samples_ = 0;
  base::Vector2 measured_wheels_ = base::Vector2::Zero();
  double last_action_ = 0.0;  ///< clock time of the last published action step [s]
  base::Vector3 goal_ = base::Vector3::Zero();
  std::uint64_t runaways_ = 0, stale_events_ = 0, set_point_drops_ = 0, set_point_clamps_ = 0;
  bool mcu_drivers_active_ = true, mcu_external_stop_ = false;  ///< last Status: true / false = OK to move
  bool has_mcu_mode_ = false;
  int mcu_mode_ = 0;            ///< last Feedback actual_mode
  double last_mcu_mode_ = 0.0;  ///< receipt time of the last Feedback [s]
  std::uint64_t mcu_stops_ = 0;
  bool output_blocked_ = false;  ///< outputBlocked(): another publisher on the output topic
  std::string blocked_why_;      ///< its reason
  std::uint64_t blocked_events_ = 0;
  bool joints_frozen_ = false;  ///< jointStatesFrozen(): the joint states repeat while the wheels turn
  std::string frozen_why_;      ///< its reason
};

}  // namespace loop
}  // namespace jackal_aic
