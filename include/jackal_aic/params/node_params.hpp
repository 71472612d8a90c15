#pragma once
/**
 * \file node_params.hpp
 * \brief Parameters of the jackal_AIC node as plain data: the controller's AicParams plus
 *        the node-only settings (timeouts, joint names, sensor pairing, set-point limits),
 *        with their validation. ROS-free; the node reads them from its private namespace
 *        (include/jackal_aic/ros/param_server.hpp), the keys and ranges are those of the
 *        parameter schema (include/jackal_aic/params/param_schema.hpp; doc/jackal_aic_node.md,
 *        'Parameters').
 */

#include <string>
#include <vector>

#include "jackal_aic/params/diff_drive_params.hpp"
#include "jackal_aic/params/fdi_params.hpp"
#include "jackal_aic/params/param_spec.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace params
{

/// What starts an action step (doc/jackal_aic_node.md, 'Loops').
enum class ActionTrigger
{
  kTimer,  ///< a free-running timer at action_rate (the thesis)
  kSample  ///< each accepted sensor sample (the command uses the newest order-0 data); the
           ///< timer then only keeps /cmd_drive alive with zeros while the controller is inactive
};

/// How the beliefs are advanced (doc/jackal_aic_node.md, 'Loops'; include/jackal_aic/loop/control_loop.hpp).
enum class BeliefSchedule
{
  kEvent,  ///< to the time of every event, in steps of at most 1 / belief_rate (no belief timer)
  kTimer   ///< on a free-running timer at belief_rate (a thread on the wall clock, a ROS timer on simulated time)
};

/// "event" / "timer" -> BeliefSchedule; false (out unchanged) for any other text.
bool beliefScheduleFromString(const std::string& name, BeliefSchedule* out);
/// BeliefSchedule -> "event" / "timer".
std::string toString(BeliefSchedule schedule);

/// "timer" / "sample" -> ActionTrigger; false (out unchanged) for any other text.
bool actionTriggerFromString(const std::string& name, ActionTrigger* out);
/// ActionTrigger -> "timer" / "sample".
std::string toString(ActionTrigger trigger);

/**
 * \brief Everything the node reads from its private namespace.
 *
 * Keys are the member names (YAML keys of config/\*.yaml). Controller parameters live in
 * `aic` and keep the names of AicParams. The member initializers are the schema's defaults
 * (defaultValue()), the one place the node's defaults are written; config/default.yaml
 * adds only what has none (the joint names).
 */
struct NodeParams
{
  /// Controller parameters; defaults: the recommended set (recommendedAicParams());
  /// validated by AicParams::validate().
  AicParams aic = recommendedAicParams();

  double sensor_timeout = 0.25;    ///< no accepted sensor sample for this long -> zero command [s], > 0
  double set_point_timeout = 0.5;  ///< no set point for this long -> zero command [s], > 0
  /// Largest |stamp(imu) - stamp(joint_states)| for the two to form one sample [s], > 0.
  double imu_max_skew = 0.025;
  /// Samples closer than this to the previous one (by stamp) are dropped as duplicates [s], >= 0, < sensor_timeout.
  double min_sample_interval = 0.005;
  double max_linear_speed = 2.0;   ///< |set point linear.x| is clamped to this [m/s], > 0 (Jackal top speed)
  double max_angular_speed = 4.0;  ///< |set point angular.z| is clamped to this [rad/s], > 0 (stock controller limit)
  double runaway_hold_time = 1.0;  ///< after a runaway reset, zero command for this long [s], >= 0
  std::vector<std::string> left_joints;   ///< joints averaged into omega_L; required, non-empty
  std::vector<std::string> right_joints;  ///< joints averaged into omega_R; required, non-empty
  /// "cmd_drive" (jackal_msgs/Drive on /cmd_drive) or "cmd_vel" (geometry_msgs/Twist on
  /// jackal_velocity_controller/cmd_vel, inverted through the stock diff drive); read at start.
  std::string output_mode = "cmd_drive";
  /// Where ~save_learned_model writes the learned model as a YAML overlay (aic::learnedModelOverlay());
  /// empty = $ROS_HOME/jackal_aic/learned_model.yaml (resolved by the node); read at start.
  std::string learned_model_file;
  /// cmd_vel mode: the stock diff_drive_controller's kinematics and limits (keys cmd_vel_<member>;
  /// defaults: the Jackal's jackal_control/config/control.yaml), each > 0.
  DiffDriveParams cmd_vel;
  /// ~belief, ~free_energy, ~eps_y, ~eps_mu are published at most this often, from the newest state [Hz], > 0.
  double debug_rate = 100.0;
  /// Wall-clock belief thread: 0 = default scheduler, 1..99 = ask for SCHED_FIFO at this priority.
  int realtime_priority = 0;
  /// Wall time between two polls of the ROS master for other publishers on the output topic
  /// (OutputConflict) [s], >= 0, <= 10; 0 = no check.
  double publisher_check_period = 0.25;
  /// What starts an action step: the action_rate timer or each accepted sensor sample.
  ActionTrigger action_trigger = ActionTrigger::kSample;
  /// How the beliefs are advanced: to each event's time, or on a belief_rate timer; read at start.
  BeliefSchedule belief_schedule = BeliefSchedule::kEvent;
  /// Sensor fault detection and isolation (keys fdi_*; doc/active_inference.md, 'Fault detection and isolation').
  FdiParams fdi;

  /**
   * \brief Every violated rule: the AicParams rules (AicParams::validate()), the ranges of
   *        the node-only keys in the parameter schema (positive timeouts and limits,
   *        non-empty joint lists without empty or duplicate names), and the node's own
   *        rules: rates <= kMaxLoopRate, min_sample_interval < sensor_timeout, left and
   *        right joints disjoint.
   * \return one ParamViolation per violated rule, named by YAML key; empty = valid
   */
  std::vector<ParamViolation> validate() const;
};

}  // namespace params
}  // namespace jackal_aic
