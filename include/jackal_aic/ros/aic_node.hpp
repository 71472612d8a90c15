#pragma once
/**
 * \file aic_node.hpp
 * \brief The jackal_AIC node: runs the ActiveInferenceController on ROS timers.
 *
 * Topics (see doc/jackal_aic_node.md, "Topics"):
 *   in:  /joint_states (sensor_msgs/JointState), /imu/data (sensor_msgs/Imu),
 *        ~set_point (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s])
 *   out: /cmd_drive (jackal_msgs/Drive, MODE_VELOCITY, drivers [rad/s]) every action tick;
 *        ~belief (geometry_msgs/TwistStamped, mu^(0)) every belief tick;
 *        ~free_energy (std_msgs/Float64), ~eps_y, ~eps_mu (std_msgs/Float64MultiArray,
 *        rows = channels, cols = orders) every action tick (decimated from the belief rate);
 *        /diagnostics (diagnostic_updater).
 *
 * Threading: one thread (ros::spin). Subscribers validate and store; the belief timer
 * (belief_rate) integrates the beliefs, the action timer (action_rate) the action and
 * publishes the command. Both integrate over the measured interval between their
 * callbacks (ros::TimerEvent current_real - last_real), clamped: the action loop to 3
 * periods; the belief loop to 10 periods, split into steps of about one nominal period
 * (a late tick is caught up with the steps it missed, one ~belief message per step, each
 * stamped with the time its belief refers to), so the belief topic carries belief_rate
 * updates per second even when the OS delays the timer. dynamic_reconfigure writes a validated copy of the parameters
 * under a mutex; the timers apply it at the start of their next tick.
 *
 * Safety: the controller runs only while sensor samples are fresh (sensor_timeout),
 * the set point is fresh (set_point_timeout), the generalizer is warm (p+1 samples since
 * it started) and no runaway hold is active; otherwise the command is zero. Losing any
 * of these publishes a zero command at once (within one belief tick), not at the next
 * action tick. On (re)activation the controller is reset, given the latest generalized
 * measurement and started from the measured wheel speeds (bumpless start). A runaway
 * (reported by the controller) resets it and holds a zero command for runaway_hold_time
 * with diagnostics ERROR. Every published number passes a final finiteness guard.
 */

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include <boost/thread/recursive_mutex.hpp>
#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "jackal_aic/AICConfig.h"
#include "jackal_aic/controller.hpp"
#include "jackal_aic/generalizer.hpp"
#include "jackal_aic/ros/node_params.hpp"
#include "jackal_aic/ros/sensor_sync.hpp"

namespace jackal_aic
{
/// What the node is doing (reported in diagnostics).
enum class NodeState
{
  kWaiting,   ///< no sensor sample or no set point yet, or warming up the generalizer: zero command
  kRunning,   ///< controller active
  kStale,     ///< sensors or set point timed out: zero command, diagnostics WARN
  kRunaway    ///< runaway reset, holding zero command: diagnostics ERROR
};

/// "waiting", "running", "stale", "runaway".
const char* toString(NodeState state);

/// Statistics of one timer loop, reset at every diagnostics publication (except counters).
struct LoopStats
{
  double nominal_period = 0.0;    ///< 1 / rate [s]
  double max_factor = 3.0;        ///< longer intervals are clamped to max_factor * nominal_period
  std::uint64_t ticks = 0;        ///< callbacks since start
  std::uint64_t overruns = 0;     ///< measured interval > 2 nominal periods (a tick was missed)
  std::uint64_t clamped = 0;      ///< intervals clamped to max_factor periods
  std::uint64_t catch_up_steps = 0;  ///< extra integration steps run to cover missed ticks
  double window_max_interval = 0.0;   ///< largest measured interval in the window [s]
  double window_abs_jitter_sum = 0.0; ///< sum of |interval - nominal| in the window [s]
  std::uint64_t window_ticks = 0;     ///< callbacks in the window
  double window_max_duration = 0.0;   ///< longest callback execution in the window [s]

  /// Record one measured interval [s]; a non-finite or non-positive one (first tick) counts as
  /// nominal_period. \return the interval to integrate with [s], clamped to max_factor * nominal_period.
  double record(double interval);
  /// Zero the window_* statistics (after each diagnostics publication); counters are kept.
  void resetWindow();
};

/**
 * \brief The node. Construct, call init(); if it returns false, exit non-zero.
 */
class AicNode
{
public:
  /**
   * \param nh   public node handle (sensor and command topics)
   * \param pnh  private node handle (~: parameters, set point, debug topics)
   */
  AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

  /**
   * \brief Read and validate the parameters, then create subscribers, publishers, timers,
   *        the dynamic_reconfigure server and the diagnostics.
   * \return false after logging (ROS_FATAL) every violation as "name = value (allowed: range)".
   */
  bool init();

  /// The largest interval the action loop integrates over, in nominal periods (longer gaps are clamped).
  static constexpr double kMaxActionIntervalFactor = 3.0;
  /// The largest interval the belief loop integrates over, in nominal periods; it is split into
  /// steps of about one nominal period each (catch-up), so a late tick never means a long Euler step.
  static constexpr double kMaxBeliefIntervalFactor = 10.0;

private:
  void jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg);
  void imuCallback(const sensor_msgs::Imu::ConstPtr& msg);
  void setPointCallback(const geometry_msgs::Twist::ConstPtr& msg);
  void beliefTimerCallback(const ros::TimerEvent& event);
  void actionTimerCallback(const ros::TimerEvent& event);
  void diagnosticsTimerCallback(const ros::TimerEvent& event);
  void reconfigureCallback(AICConfig& config, std::uint32_t level);

  /// Apply a parameter set queued by dynamic_reconfigure (between ticks).
  void applyPendingParams();
  /// Watchdogs: decide the state, (de)activate the controller; publishes a zero command on deactivation.
  void updateState(const ros::Time& now);
  void activate();
  /// Stop the controller and publish a zero command at once.
  void deactivate();
  void handleRunaway(const ros::Time& now, const char* where);
  /// Final guard: clamp to +-max_wheel_speed, zero if non-finite, publish MODE_VELOCITY.
  void publishCommand(double omega_left, double omega_right);
  void publishDebug();
  void publishBelief(const ros::Time& stamp);

  AICConfig configFromParams(const NodeParams& params) const;
  SensorSynchronizer::Config syncConfig(const NodeParams& params) const;

  void loopDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void sensorDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void controllerDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  NodeParams params_;

  std::unique_ptr<ActiveInferenceController> controller_;
  std::unique_ptr<Generalizer> generalizer_;
  std::unique_ptr<SensorSynchronizer> sync_;

  ros::Subscriber joint_sub_, imu_sub_, set_point_sub_;
  ros::Publisher cmd_pub_, belief_pub_, free_energy_pub_, eps_y_pub_, eps_mu_pub_;
  ros::Timer belief_timer_, action_timer_, diagnostics_timer_;

  // dynamic_reconfigure: the callback validates and queues; the timers apply.
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<AICConfig>> reconfigure_server_;
  bool reconfigure_initialized_ = false;
  std::mutex pending_mutex_;
  std::unique_ptr<NodeParams> pending_params_;

  // Diagnostics.
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  double belief_freq_min_ = 0.0, belief_freq_max_ = 0.0, action_freq_min_ = 0.0, action_freq_max_ = 0.0;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> belief_freq_, action_freq_;
  LoopStats belief_stats_, action_stats_;
  double belief_step_debt_ = 0.0;  ///< belief steps owed (in nominal periods), carried between ticks, in [-1, 1]

  // State.
  NodeState state_ = NodeState::kWaiting;
  std::string state_reason_ = "no sensor sample yet";
  bool active_ = false;
  bool has_sample_ = false, has_set_point_ = false, has_joint_ = false, has_imu_ = false;
  ros::Time last_sample_receipt_, last_set_point_receipt_, last_joint_receipt_, last_imu_receipt_;
  int warm_samples_ = 0;  ///< samples accepted by the generalizer since it (re)started
  Vector2 measured_wheels_ = Vector2::Zero();
  Vector3 mu_d_ = Vector3::Zero();
  ros::Time runaway_until_;
  std::uint64_t runaways_ = 0, set_point_drops_ = 0, set_point_clamps_ = 0, generalizer_drops_ = 0;
  std::uint64_t guarded_outputs_ = 0, stale_events_ = 0;
  double last_free_energy_ = 0.0;
};

}  // namespace jackal_aic
