#pragma once
/**
 * \file node_diagnostics.hpp
 * \brief /diagnostics of the jackal_AIC node (doc/jackal_aic_node.md, 'Diagnostics'): the
 *        achieved loop rates, loop timing, sensor freshness and drops, controller state.
 */

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <ros/timer.h>

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"
#include "jackal_aic/os/periodic_thread.hpp"
#include "jackal_aic/base/types.hpp"

// update_functions.h is included by node_diagnostics.cpp only: diagnostic_updater 1.10
// (Debian 11) defines TimeStampStatus::run in that header without `inline`, so a second
// translation unit including it fails to link.
namespace diagnostic_updater
{
class FrequencyStatus;
}  // namespace diagnostic_updater

namespace jackal_aic
{
namespace node
{
/// The controller's side of the diagnostics, gathered by the node when they are published.
struct ControllerReport
{
  double free_energy = 0.0;                       ///< F (thesis eq. 3-10) at the diagnostics publication
  double belief_vx = 0.0;                         ///< mu^(0) x_dot [m/s]
  double belief_wz = 0.0;                         ///< mu^(0) theta_dot [rad/s]
  base::Vector2 command = base::Vector2::Zero();  ///< wheel command (omega_L, omega_R) [rad/s], zero when inactive
  std::uint64_t guarded_outputs = 0;              ///< non-finite outputs suppressed
  std::uint64_t generalizer_drops = 0;            ///< samples the generalizer or the controller refused
  std::string output_mode = "cmd_drive";          ///< output_mode parameter
  std::uint64_t output_clips = 0;                 ///< cmd_vel mode: commands clipped to the stock controller's limits
  bool last_output_clipped = false;               ///< cmd_vel mode: the last command was clipped (anti-windup active)
  std::string output_topic;                       ///< the command topic's resolved name
  std::string other_publishers = "none";          ///< other nodes publishing on it ("unchecked" with the check off)
  std::uint64_t output_conflicts = 0;             ///< conflicts started (another publisher appeared)
  std::uint64_t blocked_commands = 0;             ///< commands withheld while another node published on the topic
  double wheel_separation = 0.0;            ///< b_hat the generative model uses [m] (learned if learn_wheel_separation)
  std::string separation_learning = "off";  ///< the learner's state (learning, near rest, transient, ...) or "off"
  std::uint64_t separation_learning_steps = 0;  ///< learning steps taken
  double gyro_bias = 0.0;                  ///< the gyro's learned offset beta_hat [rad/s] (0 without learn_gyro_bias)
  std::string gyro_bias_learning = "off";  ///< the offset estimator's state (learning, moving, settling, ...) or "off"
  /// The robot model's latency L in use [s] (NaN for the other belief models): the configured
  /// `latency`, or the learned one with learn_latency (LatencyLearner::latency()).
  double latency = std::numeric_limits<double>::quiet_NaN();
  /// With learn_latency: "<n> starts, newest <L> s" (LatencyLearner::starts(), lastStart()); "off" otherwise.
  std::string latency_learning = "off";
  /// The robot model's shortfall jumps, "<j> taken, <r> released, <u> unanswered, <s> stalls;
  /// stalled: none|left|right|both" (RobotBelief::shortfallJumps(), shortfallReleases(),
  /// unansweredJumps(), stalls(), stalled()); "off" for the other belief models.
  std::string shortfall_jumps = "off";
  /// The tip-over guard's state, learned bounds and trips (statusText(const TipGuard&)) or "off".
  std::string tip_guard = "off";
  std::string precision_learning = "off";  ///< the precision learner's state (learning, near rest, ...) or "off"
  /// The sensory precisions Pi_y^(0) in use, "gyro_z <Pi>, omega_left <Pi>, omega_right <Pi>"
  /// [1/(rad/s)^2] (learned if learn_precision); the robot model's: 1 / gyro_noise^2 and
  /// 1 / encoder_noise^2.
  std::string sensory_precisions;

  /// The controller's part: F (0 before the first measurement), mu^(0) x_dot and theta_dot,
  /// the action as the command while `active` (zero otherwise), the model's b_hat, its latency and the state
  /// of their learning; the rest stays default.
  static ControllerReport of(const aic::ActiveInferenceController& controller, bool active);
};

/**
 * \brief The node's diagnostic_updater tasks, published every ~diagnostic_period (1 s):
 *        "belief step rate" (while running: belief time integrated per second within +-10 %
 *        of 1, steps per second at least 90 % of belief_rate), "action loop rate (/cmd_drive)" (FrequencyStatus of the published
 *        commands, +-10 %), "loops", "sensors", "controller", "sensor health" (keys as in
 *        doc/jackal_aic_node.md).
 */
class NodeDiagnostics
{
public:
  /**
   * \param nh, pnh      node handles for the diagnostic_updater
   * \param loop         the node's logic: supervisor state, ages, counters and loop statistics
   *                     (the statistics windows are reset at every publication), the sensor
   *                     pairing's counters, the belief steps; must outlive this object
   * \param controller   called at every publication for the controller's side
   */
  NodeDiagnostics(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, loop::ControlLoop& loop,
                  std::function<ControllerReport()> controller);
  ~NodeDiagnostics();

  /// The parameters now in force (at construction and after a reconfigure): the expected loop
  /// rates [Hz] and the keys the belief model does not read (params::keysWithoutEffect()).
  void paramsApplied(const params::NodeParams& params);
  /// How the beliefs are advanced, e.g. "each event (belief_schedule event)".
  void setBeliefLoop(std::string description) { belief_loop_ = std::move(description); }
  /**
   * \brief A command was published (the achieved /cmd_drive rate); `latency` [s]: the age of the
   *        newest sensor sample in it (the sensor-to-command latency, a window's p50 / p99 / max
   *        shown in "loops"), NaN for an idle command or a keep-alive repeat (not counted).
   */
  void commandPublished(double latency);
  /// Poll the updater (publishes when ~diagnostic_period has passed).
  void update() { updater_->update(); }
  /**
   * \brief At kPollRate on a timer of `nh` (the spinner), under `mutex` (the node's lock): the
   *        loop's time advance (ControlLoop::advance()), update() and pollHealth(); after the
   *        loop saw ROS time move back, /diagnostics and ~sensor_health at once (their
   *        schedules were on the old timeline).
   */
  void start(ros::NodeHandle& nh, std::mutex& mutex);
  /// start()'s polling rate [Hz] (/diagnostics is published every ~diagnostic_period, default 1 s).
  static constexpr double kPollRate = 10.0;

  /**
   * \brief Report sensor health: adds the "sensor health" task to /diagnostics and advertises
   *        ~sensor_health (diagnostic_msgs/DiagnosticStatus, latched; published by publishHealth()).
   * \param pnh      private node handle
   * \param monitor  the node's fault monitor; must outlive this object
   */
  void addFaultMonitor(ros::NodeHandle& pnh, const safety::FaultMonitor& monitor);
  /**
   * \brief Publish the channel health on ~sensor_health and, for an event, log it (WARN on an
   *        isolation or a detection, INFO on a restoration). A no-op before addFaultMonitor().
   * \param event  what the last FaultMonitor::update() changed (kNone: periodic publication)
   * \param channel  the channel the event concerns (SensorIndex; -1 for none)
   */
  void publishHealth(safety::FaultMonitor::Event event, int channel);
  /**
   * \brief Periodic ~sensor_health: publishes (as publishHealth(kNone)) when the channel states
   *        (IMU available, isolated channel, fault present) changed since the last publication,
   *        or when kHealthPeriod has passed; call it often (the node: 10 Hz).
   */
  void pollHealth();
  /// ~sensor_health is republished at least this often [s] (events and changes: at once).
  static constexpr double kHealthPeriod = 1.0;
  /// Health of the five sensor channels as a status: WARN while the IMU is missing or a channel
  /// is isolated (or a fault is detected with isolation off), OK otherwise.
  void fillHealth(diagnostic_updater::DiagnosticStatusWrapper& stat) const;

private:
  ros::Timer poll_timer_;
  void loops(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void sensors(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void controller(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void beliefRate(diagnostic_updater::DiagnosticStatusWrapper& stat);

  loop::ControlLoop& loop_;
  std::function<ControllerReport()> report_;
  std::string belief_loop_ = "ROS timer";
  os::IntervalHistogram latency_;  ///< sensor-to-command latencies of the current window
  double belief_rate_ = 0.0, action_freq_min_ = 0.0, action_freq_max_ = 0.0;
  std::string without_effect_ = "none";  ///< the keys in force the belief model does not read, or "none"
  std::uint64_t rate_steps_ = 0;         ///< loop_.beliefSteps() at the last "belief step rate"
  double rate_integrated_ = 0.0;         ///< loop_.beliefTimeIntegrated() then [s]
  ros::WallTime rate_time_;              ///< its time
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> action_freq_;
  const safety::FaultMonitor* monitor_ = nullptr;
  ros::Publisher health_pub_;
  std::string last_event_ = "none";
  int published_state_ = -1;           ///< healthState() at the last publication
  ros::Time published_at_;             ///< time of the last publication
  std::uint64_t seen_time_jumps_ = 0;  ///< loop_.timeJumps() at the last poll
  /// The channel states as one number (IMU available, isolated channel, fault present).
  int healthState() const;
};

}  // namespace node
}  // namespace jackal_aic
