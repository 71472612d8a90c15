#pragma once
/**
 * \file control_loop.hpp
 * \brief The jackal_AIC node's logic, ROS-free and clock-injected: one ControlLoop turns input
 *        events (a joint-state or IMU sample, a set point, the MCU's state, a parameter change,
 *        a timer tick or a plain advance of time) into outputs (the wheel command, log lines,
 *        sensor-health events) and state (supervisor, beliefs, counters). The node
 *        (src/ros/) feeds it ROS messages and timers; the headless closed loop
 *        (sim/harness/src/closed_loop.cpp) feeds it the plant core's samples on simulated time.
 *        Behaviour: doc/jackal_aic_node.md, 'Loops', 'Safety', 'Degraded modes'.
 *
 * The loop owns the sensor pairing (SensorPairing), the sample pipeline (generalizer,
 * controller, fault monitor: SamplePipeline), the Supervisor (state machine, watchdogs,
 * set-point checks, loop statistics) and the command stage (final guard, clamp, output mode
 * cmd_vel through the stock diff drive with anti-windup feedback).
 *
 * Belief schedule (NodeParams::belief_schedule):
 *  - kEvent (default): the beliefs are advanced to the time of every event, the inputs
 *    (measurement, goal, sensor mask) held since the previous one, in n = ceil(T / h_mu)
 *    equal steps of T / n <= h_mu (h_mu = 1 / belief_rate, T the time since the previous
 *    event, at most maxEventInterval()). With events on the belief grid this is the same
 *    discrete system as a belief timer at belief_rate, and no thread wakes between events.
 *  - kTimer: beliefTimer() at belief_rate integrates the measured interval (catch-up
 *    scheduling, LoopScheduler); events leave the beliefs alone.
 * Action trigger (NodeParams::action_trigger): kSample runs the action step on each accepted
 * sample (over the interval between sample stamps); kTimer on actionTimer(). With kSample,
 * actionTimer() only keeps the command alive (idle command while not running, a repeat of the
 * held command when no sample ran the action for 1.5 action periods).
 *
 * The controller's composition: every stage of the controller, in the order it runs, across its
 * three owners (ControlLoop, SamplePipeline, ActiveInferenceController; the stages' settings are
 * the structs nested in AicParams, doc/active_inference.md, 'Structure of the controller'):
 *
 *   set point (setPoint):  Supervisor's checks and clamps -> GoalRateEstimator (mu_d', with
 *       generalized_goal) -> ActiveInferenceController::setGoal -> ReferenceModel's goal
 *   sample (jointState):   TimeJumpDetector -> belief steps up to now on the held inputs
 *       (advanceBeliefs, event schedule) -> GoalRateEstimator's rate refreshed -> SensorPairing
 *       -> SamplePipeline::generalize [GyroBiasEstimator's offset off the gyro z, the wheels'
 *       yaw rate in its place without the IMU, Generalizer] -> SamplePipeline::guardTip
 *       [GyroBiasEstimator of the gyro y, TipGuard -> ReferenceModel's tip bounds] -> Supervisor
 *       (activation: SamplePipeline::activate) -> while running SamplePipeline::measure
 *       [the controller's y_tilde, FaultMonitor -> the sensor mask, GyroBiasEstimator learns]
 *       -> with action_trigger sample, the action step
 *   belief step (integrate -> ActiveInferenceController::updateBeliefs, h <= 1 / belief_rate):
 *       the beliefs integrated towards the prior's target (eq. 3-15; ReferenceModel's mu_r, or
 *       ActionDelayLine's G a(t - d_r) with belief_model unbiased) -> ReferenceModel::advance ->
 *       GoalResponse::advance -> SeparationLearner (learn_wheel_separation; the model takes
 *       b_hat) -> PrecisionLearner (learn_precision; Pi_y takes it). belief_model robot instead:
 *       RobotBelief's prediction through WheelLoopModel and its correction by a new sample ->
 *       ReferenceModel::advance -> SeparationLearner
 *   action step (actionStep -> ActiveInferenceController::updateAction -> sendCommand):
 *       Supervisor's action loop tick (idle or the runaway hold's zero instead) -> RestRelease ->
 *       da_F/dt (eq. 3-16; unbiased: the goal prior on GoalResponse's g) -> ActionPrior -> the
 *       divergence check -> AntiWindup (lead, turning lead, wheel-speed clamps) -> ActionSlewLimit
 *       (action_slew_limit) -> ActionDelayLine records the command. belief_model robot instead:
 *       ReferenceModel's path (held at the believed speed while the tip guard is tripped) ->
 *       LatencyAction through WheelLoopModel -> ActionSlewLimit::limit -> WheelLoopModel records
 *       the command. Then the command stage: the final guard, and in output mode
 *       cmd_vel the stock diff drive's limits (a clipped command becomes the action)
 *
 * Time moving backwards (a simulator's /clock restarting at 0, a `rosbag play --loop --clock`
 * loop, a wall clock stepped back): every event first reads the clock through a
 * TimeJumpDetector; a reading more than kTimeJumpTolerance before the latest one resets what
 * depends on the old timeline (resetTimeline()): one warning per jump, and driving resumes,
 * bumplessly, with the new timeline's first p+1 samples.
 *
 * Not thread-safe: the caller serializes every call (the node: one mutex). No allocation on
 * the per-sample and per-step paths except in log lines, which are throttled.
 */

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "jackal_aic/loop/diff_drive.hpp"
#include "jackal_aic/aic/goal_rate.hpp"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/loop/sample_pipeline.hpp"
#include "jackal_aic/loop/sensor_pairing.hpp"
#include "jackal_aic/loop/supervisor.hpp"
#include "jackal_aic/loop/time_jump.hpp"
#include "jackal_aic/safety/frozen_joint_states.hpp"

namespace jackal_aic
{
namespace loop
{
/// A clock reading at most this far [s] before the latest one is not a time jump (ControlLoop).
constexpr double kTimeJumpTolerance = 0.001;

/// Severity of a ControlLoop log line.
enum class LogLevel
{
  kInfo,
  kWarn,
  kError
};

/// One wheel command of the loop, after the command stage.
struct WheelCommand
{
  /// What the motors get (omega_L, omega_R) [rad/s]: finite, within +-max_wheel_speed; in output
  /// mode cmd_vel, after the stock controller's limits (wheelsFromTwist(twist)).
  base::Vector2 wheels = base::Vector2::Zero();
  /// Output mode cmd_vel: the twist to publish (linear.x [m/s], angular.z [rad/s]).
  BodyTwist twist;
  bool cmd_vel = false;  ///< output mode cmd_vel (publish twist), else cmd_drive (publish wheels)
  bool clipped = false;  ///< cmd_vel: the stock controller's limits changed the command
  /// An action step's command: age [s] of the newest accepted sensor sample (stamp to now, the
  /// sensor-to-command latency); NaN for an idle command or a keep-alive repeat.
  double latency = 0.0;
};

/**
 * \brief The node's logic (see the file comment). Construct with validated NodeParams and a
 *        clock; feed events; read outputs through Output and the accessors.
 */
class ControlLoop
{
public:
  /// Where the loop's outputs go (the node publishes and logs, the simulator applies).
  class Output
  {
  public:
    virtual ~Output() = default;
    /// A wheel command to send now.
    virtual void command(const WheelCommand& command) = 0;
    /**
     * \brief The fault monitor changed a channel (isolated, restored, detected with isolation
     *        off); `channel` is the SensorIndex concerned. Default: ignored.
     */
    virtual void healthEvent(safety::FaultMonitor::Event event, int channel);
    /// A log line (prefix-free text; throttled by the loop to one per second per kind). Default: ignored.
    virtual void log(LogLevel level, const std::string& text);
  };

  /**
   * \param params  validated parameters (NodeParams::validate() empty); joint names are used by
   *                the pairing
   * \param clock   time source [s] for every event; must outlive the loop
   * \param output  receiver of commands, log lines and health events; must outlive the loop
   * \throws std::invalid_argument if params are invalid (every violation listed)
   */
  ControlLoop(const params::NodeParams& params, const Clock& clock, Output& output);
  ~ControlLoop();
  ControlLoop(const ControlLoop&) = delete;
  ControlLoop& operator=(const ControlLoop&) = delete;

  // ---- events (each at clock.now())
  /**
   * \brief A joint-state message: pairing (with the newest IMU samples), the frozen-stream
   *        check (FrozenJointStates: while the data repeat with a wheel turning, the sample is
   *        refused and the sensors count as lost, Supervisor::jointStatesFrozen()), generalization, the
   *        supervisor's warm-up, activation when due, the measurement and fault test while
   *        running and, with action_trigger sample, the action step and its command.
   *        Event schedule: the beliefs are first advanced to now with the old inputs.
   * \return false if the message was dropped (pairing), the stream is frozen or the sample
   *         refused (generalizer, controller)
   */
  bool jointState(const JointStateInput& joints);
  /// An IMU message: validated and kept for pairing. \return false if dropped.
  bool imu(const ImuInput& imu);
  /**
   * \brief A set point (geometry_msgs/Twist fields: linear x, y, z [m/s], angular x, y, z
   *        [rad/s]): checked by the supervisor (NaN/Inf dropped, clamped to max_linear_speed /
   *        max_angular_speed) and, unless dropped, the goal mu_d = (linear.x, 0, angular.z) with,
   *        if AicParams::reference.generalized_goal, its rate mu_d' from the stream (GoalRateEstimator; the
   *        rate is refreshed at every event, so a ramp's slope expires).
   */
  SetPointResult setPoint(const double (&fields)[6]);
  /// The MCU's jackal_msgs/Status (Supervisor::mcuStatus()); the watchdogs run at once.
  void mcuStatus(bool drivers_active, bool external_stop_present, bool external_stop_stopped);
  /// The MCU's jackal_msgs/Feedback actual_mode (Supervisor::mcuFeedback()); the watchdogs run at once.
  void mcuFeedback(int actual_mode);
  /**
   * \brief Whether another node publishes on the output topic (the node's OutputConflict,
   *        Supervisor::outputBlocked()); the watchdogs run at once. While blocked the state is
   *        kBlocked, the controller is stopped and no command reaches Output::command()
   *        (counted: blockedCommands()); when released the controller restarts bumpless from
   *        the measured wheel speeds.
   * \param blocked  true while the conflict lasts
   * \param why      the reason for diagnostics (names the other publishers)
   */
  void outputBlocked(bool blocked, const std::string& why);
  /**
   * \brief The action_rate timer's tick, `interval` [s] since its previous tick (<= 0 or
   *        non-finite: first tick). action_trigger timer: the action step (a += h da/dt, thesis
   *        eq. 3-16, over the interval clamped to 3 periods) and its command; sample: the
   *        keep-alive (see the file comment).
   */
  void actionTimer(double interval);
  /**
   * \brief Belief schedule timer: the belief_rate timer's tick, `interval` [s] since its
   *        previous tick (<= 0: first); the watchdogs, then the catch-up steps the scheduler
   *        plans for the interval. Event schedule: the same as advance().
   */
  void beliefTimer(double interval);
  /// Time advances (any timer: debug, diagnostics): event schedule: the beliefs to now; the watchdogs.
  void advance();
  /**
   * \brief Apply new parameters between events (dynamic_reconfigure). The rates, gains,
   *        precisions, timeouts, limits and pairing settings take effect at once; a changed
   *        embedding order restarts the sample history (warm-up; a running controller stops
   *        until it is warm). output_mode, cmd_vel_* and belief_schedule keep their start values.
   * \throws std::invalid_argument (nothing changed) if `params` are invalid
   */
  void setParams(const params::NodeParams& params);
  /**
   * \brief Restart a running controller from the measured state, as on activation: beliefs at the
   *        measured twist, action at the measured wheel speeds (bumpless). No effect unless running.
   *        The node calls it when its output is enabled again (OutputGate, ~enable_output), so an
   *        action integrated while another controller drove the robot is not commanded.
   * \return true if the controller was restarted
   */
  bool restartFromMeasured();

  /**
   * \brief Start over on a new timeline (called by every event when the clock moved back by
   *        more than kTimeJumpTolerance; callable by a caller that knows of a jump). Resets
   *        what depends on the old timeline: the sensor pairing's stamp order, IMU samples and
   *        history, the generalizer and the fault monitor's history, the goal-rate
   *        estimator, the belief time, the log throttles; the supervisor's timers are moved
   *        onto the new timeline with their ages kept (Supervisor::resetTimeline()). A running
   *        controller stops and starts again, from the measured wheel speeds, after p+1
   *        samples of the new timeline; until its first sample nothing is commanded, then
   *        the measured wheel speeds. Parameters, counters and the set point are kept. Logs
   *        one warning.
   */
  void resetTimeline();

  /**
   * \brief Set the controller's learned wheel separation b_hat [m] (a saved overlay, a service):
   *        ActiveInferenceController::setLearnedSeparation(), clamped to [separation_min,
   *        separation_max]. \return false (unchanged) if b is not finite
   */
  bool setLearnedSeparation(double b) { return pipeline_.controller().setLearnedSeparation(b); }
  /// Forget what the controller learned (ActiveInferenceController::resetLearning()): b_hat back
  /// to wheel_separation, the gyro's offset beta_hat back to 0 (it learns again at the next rest),
  /// the robot model's shortfalls, slip ratio and gyro offset back to 0 (belief_model robot) and
  /// the tip-over guard's learned bounds forgotten (a payload removed).
  void resetLearning()
  {
    pipeline_.controller().resetLearning();
    pipeline_.resetGyroBias();
    pipeline_.resetTipGuard();
  }
  /// The gyro's offset estimator (beta_hat [rad/s], learned with learn_gyro_bias).
  const aic::GyroBiasEstimator& gyroBias() const { return pipeline_.gyroBias(); }
  /// The tip-over guard (pitch, learned bounds, trips; acts with tip_guard).
  const safety::TipGuard& tipGuard() const { return pipeline_.tipGuard(); }

  // ---- state
  /// The parameters in force.
  const params::NodeParams& params() const { return params_; }
  /// The state machine, watchdogs, counters and loop statistics.
  const Supervisor& supervisor() const { return supervisor_; }
  /// \copydoc supervisor() (the node's diagnostics reset its statistics windows).
  Supervisor& supervisor() { return supervisor_; }
  /// The sensor pairing (accepted samples, drops per reason).
  const SensorPairing& pairing() const { return pairing_; }
  /// The controller (beliefs mu_tilde, action a, goal mu_d).
  const aic::ActiveInferenceController& controller() const { return pipeline_.controller(); }
  /// The fault monitor (channel health).
  const safety::FaultMonitor& faultMonitor() const { return pipeline_.faultMonitor(); }
  /// The generalizer (y_tilde of the newest accepted sample).
  const aic::Generalizer& generalizer() const { return pipeline_.generalizer(); }
  /// True while the controller runs (Supervisor state kRunning).
  bool active() const { return supervisor_.active(); }
  /// Belief integration steps run since construction (both schedules; only while running).
  /// Event schedule: about belief_rate per second plus up to one per event (steps are at most
  /// 1 / belief_rate long).
  std::uint64_t beliefSteps() const { return belief_steps_; }
  /// Time the beliefs were integrated over since construction [s] (the sum of the step
  /// lengths): grows at 1 s per second while running, in either schedule, unless intervals
  /// were clamped (timer: kMaxBeliefIntervalFactor periods; event: maxEventInterval()).
  double beliefTimeIntegrated() const { return belief_integrated_; }
  /// Action steps run since construction.
  std::uint64_t actionSteps() const { return action_steps_; }
  /// Clock time [s] the beliefs were last advanced to (event schedule) or of the last belief tick (timer).
  double beliefTime() const { return belief_time_; }
  /// Samples the generalizer or the controller refused.
  std::uint64_t refusedSamples() const { return refused_samples_; }
  /// Non-finite wheel commands replaced by zero by the command stage.
  std::uint64_t guardedCommands() const { return guarded_commands_; }
  /// Output mode cmd_vel: commands clipped by the stock controller's limits (0 in cmd_drive mode).
  std::uint64_t outputClips() const { return cmd_vel_ ? cmd_vel_->clips() : 0; }
  /// Output mode cmd_vel: the last command was clipped.
  bool lastOutputClipped() const { return last_clipped_; }
  /// Commands withheld while blocked (kBlocked: another publisher on the output topic).
  std::uint64_t blockedCommands() const { return blocked_commands_; }
  /// Backward jumps of the clock seen (each reset the timeline).
  std::uint64_t timeJumps() const { return time_jump_.jumps(); }
  /// Size of the last backward jump of the clock [s]; 0 before the first.
  double lastTimeJump() const { return time_jump_.lastJump(); }
  /// Controller starts (entries into kRunning) since construction.
  std::uint64_t starts() const { return starts_; }
  /// The frozen joint-state check (verdict, the current run of repeats, entries into frozen).
  const safety::FrozenJointStates& frozenJointStates() const { return frozen_; }
  /// Joint-state samples refused because the stream was frozen.
  std::uint64_t frozenSamples() const { return frozen_samples_; }
  /// Stamp [s] of the newest accepted sensor sample (the clock's epoch); NaN before the first.
  double newestSampleStamp() const { return newest_sample_stamp_; }

  /**
   * \brief Event schedule: the longest interval [s] the beliefs are advanced over at one event:
   *        max(sensor_timeout, kMaxBeliefIntervalFactor / belief_rate). Longer gaps (the sensors
   *        are stale by then) lose the time beyond it, as the timer's clamp does.
   */
  double maxEventInterval() const;

private:
  /// What a log line is about (each kind is throttled on its own).
  enum Notice : int
  {
    kNoticeDrop = 0,
    kNoticeNoImu,
    kNoticeRefused,
    kNoticeSetPointDropped,
    kNoticeSetPointClamped,
    kNoticeRunaway,
    kNoticeGuard,
    kNoticeClip,
    kNoticeCount
  };
  /// True (and the throttle restarted) if a line of this kind may be logged now.
  bool due(Notice kind);
  /// Every event first: a backward jump of the clock resets the timeline. \return true if it did.
  bool checkClock();
  /// resetTimeline() with the supervisor's timers moved by `shift` [s] (the new reading minus the old timeline's latest).
  void restartTimeline(double shift);
  /// Event schedule: integrate the beliefs from beliefTime() to now (if running).
  void advanceBeliefs();
  /// Generalized goal: the controller's mu_d' to the estimator's rate now (a ramp's slope expires).
  void refreshGoalRate();
  /// Integrate `steps` belief steps of h [s]; a runaway stops and is handled.
  void integrate(int steps, double h);
  /// Watchdogs: Supervisor::update() and its transition.
  void watch();
  /// Carry out a supervisor transition: restart the history, warn, (de)activate.
  void carryOut(const Supervisor::Transition& t);
  /// Reset the controller and start it from the measured wheel speeds (bumpless); the log line
  /// says why it had stopped, on a restart.
  void activate();
  /// A runaway: the supervisor's hold (zero command), and probation for the restart after it.
  void handleRunaway(const char* where);
  /// Log a change of the tip-over guard's turned-over state (TipGuard::turnedOver(): ERROR when
  /// the robot has turned over and the command is zero, WARN when it resumes).
  void noticeTurnover();
  /// True while a restart after a runaway is on probation: the command stays zero until the
  /// restarted beliefs have integrated one action period (1 / action_rate) without a runaway.
  bool onProbation() const { return probation_left_ > kProbationTolerance; }
  /// One action step over `interval` [s] (-1: nominal); its command.
  void actionStep(double interval);
  /// The command stage: guard, clamp, output mode; emit (nothing in kBlocked). `stock_limits` false:
  /// output mode cmd_vel publishes the twist of `wheels` without the stock controller's
  /// velocity and acceleration limits (the idle zero: the diff drive ramps down itself).
  void sendCommand(const base::Vector2& wheels, double latency, bool stock_limits = true);
  /// The frozen-stream check of one paired sample; tells the supervisor and logs a change.
  /// \return true if the stream is frozen (the sample must not be used)
  bool checkFrozen(const SensorSample& sample);
  /// The command outside kRunning (Supervisor::idleCommand()): zero at once (cmd_vel: the zero
  /// twist, not ramped by our copy of the stock limits), the measured wheel speeds (kHeld,
  /// warming up), or nothing; withheld in kBlocked, as every command.
  void sendIdle();

  params::NodeParams params_;
  const Clock& clock_;
  Output& output_;
  SensorPairing pairing_;
  SamplePipeline pipeline_;
  Supervisor supervisor_;
  aic::GoalRateEstimator goal_rate_;       ///< mu_d' of the set-point stream (AicParams::reference.generalized_goal)
  std::unique_ptr<CmdVelOutput> cmd_vel_;  ///< output mode cmd_vel only
  TimeJumpDetector time_jump_{ kTimeJumpTolerance };
  safety::FrozenJointStates frozen_;  ///< a frozen MCU behind jackal_node
  std::uint64_t frozen_samples_ = 0;
  std::uint64_t starts_ = 0;
  std::string last_stop_reason_;        ///< why the controller last left kRunning (for the restart's log line)
  bool restart_after_runaway_ = false;  ///< the next start follows a runaway: it starts on probation
  double probation_left_ = 0.0;         ///< belief time [s] still to integrate before the action drives
  static constexpr double kProbationTolerance = 1e-9;  ///< [s] rounding of summed step lengths

  std::uint64_t belief_steps_ = 0;
  double belief_integrated_ = 0.0;
  std::uint64_t action_steps_ = 0;
  std::uint64_t refused_samples_ = 0;
  std::uint64_t guarded_commands_ = 0;
  std::uint64_t blocked_commands_ = 0;
  bool last_clipped_ = false;
  bool turned_over_ = false;  ///< the tip-over guard's turned-over state at the last sample (logged on change)
  double belief_time_ = 0.0;
  double newest_sample_stamp_;
  std::array<double, kNoticeCount> last_notice_;
  std::string text_;  ///< scratch for log lines
};

}  // namespace loop
}  // namespace jackal_aic
