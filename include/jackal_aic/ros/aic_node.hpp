#pragma once
/**
 * \file aic_node.hpp
 * \brief The jackal_AIC node: the ROS side of the ControlLoop (the active inference
 *        controller with its sensor pairing, supervisor and scheduling).
 *
 * Topics (see doc/jackal_aic_node.md, "Topics"):
 *   in:  /joint_states (sensor_msgs/JointState), /imu/data (sensor_msgs/Imu),
 *        ~set_point (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s])
 *        /status (jackal_msgs/Status), /feedback (jackal_msgs/Feedback): the MCU's stop state
 *   out: /cmd_drive (jackal_msgs/Drive, MODE_VELOCITY, drivers [rad/s]) every action tick, or in
 *        output mode cmd_vel jackal_velocity_controller/cmd_vel (geometry_msgs/Twist, the
 *        inverse of the stock diff drive: CmdVelOutput, include/jackal_aic/loop/diff_drive.hpp);
 *        ~belief (geometry_msgs/TwistStamped, mu^(0)), ~free_energy (std_msgs/Float64),
 *        ~eps_y, ~eps_mu (std_msgs/Float64MultiArray, rows = channels, cols = orders) at
 *        debug_rate (100 Hz) from the newest belief, when there is a new one, while any
 *        of them has a subscriber (no debug timer wake-ups otherwise);
 *        ~sensor_health (diagnostic_msgs/DiagnosticStatus, latched) on every fault event and channel-state change, and at 1 Hz;
 *        /diagnostics (NodeDiagnostics). Publishers and the finiteness guard: NodeOutputs.
 *
 * The node is wiring: the node's logic is the ROS-free ControlLoop
 * (include/jackal_aic/loop/control_loop.hpp: sensor pairing, sample pipeline, supervisor,
 * scheduling, command stage). The node turns messages and timers into its events and its
 * outputs into messages; the parameters come from the schema
 * (include/jackal_aic/params/param_schema.hpp) through loadNodeParams() and NodeReconfigure;
 * diagnostics are NodeDiagnostics.
 *
 * Threading (doc/jackal_aic_node.md, 'Loops'). belief_schedule event (default): the
 * subscribers' callbacks run on roscpp's network thread as each message is read
 * (InlineCallbackQueue); the action timer (action_rate: with action_trigger sample a
 * keep-alive), the debug timer (debug_rate, only while a debug topic has a subscriber), the
 * diagnostics and dynamic_reconfigure on the spinner (ros::spin); each event advances the
 * beliefs to its time, so nothing wakes at belief_rate. belief_schedule timer: the belief loop
 * (BeliefLoop) runs at belief_rate on its own PeriodicThread on the wall clock (which then
 * also serves the subscribers' queue) or on a ROS timer on simulated time.
 * One mutex guards the ControlLoop; each holder keeps it for one event (microseconds), and
 * the debug timer copies a DebugSnapshot under it and publishes outside it. dynamic_reconfigure
 * queues a validated parameter set; the action timer (and the belief timer) applies it at
 * the start of its next tick.
 *
 * One publisher per command topic: with publisher_check_period > 0 the node asks the master
 * which nodes publish on its command topic at start and every publisher_check_period
 * (PublisherWatch, its own thread); while another one does (OutputConflict) it logs one ERROR
 * naming it, publishes nothing on the topic (ControlLoop::outputBlocked(), state kBlocked,
 * diagnostics ERROR) and restarts bumpless once it is gone.
 *
 * Safety (ControlLoop, Supervisor): the controller runs only in the supervisor's kRunning
 * state; otherwise the command is zero (the measured wheel speeds while the MCU holds),
 * published at once on leaving kRunning. Every published number passes a final finiteness
 * guard.
 */

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <jackal_msgs/Feedback.h>
#include <jackal_msgs/Status.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/safety/output_conflict.hpp"
#include "jackal_aic/safety/output_gate.hpp"
#include "jackal_aic/ros/belief_loop.hpp"
#include "jackal_aic/ros/inline_callback_queue.hpp"
#include "jackal_aic/ros/node_diagnostics.hpp"
#include "jackal_aic/ros/node_outputs.hpp"
#include "jackal_aic/ros/node_reconfigure.hpp"
#include "jackal_aic/ros/publisher_watch.hpp"
#include "jackal_aic/ros/learned_model.hpp"
#include "jackal_aic/ros/output_enable.hpp"

namespace jackal_aic
{
// The node's folder ros/ is namespace node: a jackal_aic::ros would hide ::ros inside jackal_aic.
namespace node
{
/**
 * \brief ros::Time::now() (wall or simulated time, as the node runs) as a Clock: seconds since
 *        an epoch taken at start(), so stamps keep nanosecond resolution as doubles.
 */
class RosClock : public loop::Clock
{
public:
  /// Take the epoch: the current ROS time (0 on simulated time before the first /clock).
  void start() { epoch_ = ros::Time::now(); }
  double now() const override { return sinceEpoch(ros::Time::now()); }
  /// A message stamp in the clock's seconds; NaN for a zero (unset) stamp. Any stamp, up to the
  /// largest ROS time, is finite (never throws).
  double seconds(const ros::Time& stamp) const;
  /// The ROS time of a clock reading [s]; ROS time 0 for a reading before it (ROS time
  /// moved back after start() and the reading is of the new timeline) or NaN, the largest ROS
  /// time for a reading beyond it (never throws).
  ros::Time time(double seconds) const;

private:
  /// stamp - epoch [s], in signed 64-bit nanoseconds (ros::Duration throws beyond 2^31 s).
  double sinceEpoch(const ros::Time& stamp) const;

  ros::Time epoch_;
};

/**
 * \brief The node. Construct, call init(); if it returns false, exit non-zero.
 */
class AicNode : private loop::ControlLoop::Output
{
public:
  /**
   * \param nh   public node handle (sensor and command topics)
   * \param pnh  private node handle (~: parameters, set point, debug topics)
   */
  AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);
  /// Stops the belief thread (timer schedule) before anything it uses is destroyed.
  ~AicNode() override;
  AicNode(const AicNode&) = delete;
  AicNode& operator=(const AicNode&) = delete;

  /**
   * \brief Read and validate the parameters, then create subscribers, publishers, timers,
   *        the dynamic_reconfigure server and the diagnostics.
   * \return false after logging (ROS_FATAL) every violation as "name = value (allowed: range)".
   */
  bool init();

private:
  // Subscribers: each message becomes a ControlLoop event (aic_node_inputs.cpp).
  void jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg);
  void imuCallback(const sensor_msgs::Imu::ConstPtr& msg);
  void setPointCallback(const geometry_msgs::Twist::ConstPtr& msg);
  void statusCallback(const jackal_msgs::Status::ConstPtr& msg);
  void feedbackCallback(const jackal_msgs::Feedback::ConstPtr& msg);
  void actionTimerCallback(const ros::TimerEvent& event);
  /// The belief timer's tick (belief_schedule timer): interval [s] since the previous one (-1 first).
  void beliefTick(double interval);
  /// Apply a parameter set queued by dynamic_reconfigure (between ticks; call with the lock held).
  void applyPendingParams();
  /// One poll of the command topic's publishers (PublisherWatch's thread, or init()): the
  /// conflict's transitions logged and handed to the ControlLoop. Takes the lock.
  void publishersPolled(bool ok, const std::vector<std::string>& publishers, const std::string& error);
  ControllerReport controllerReport() const;
  /// ~enable_output (output_enable.cpp): the service over gate_.
  void startOutputGate();

  // ControlLoop::Output: publish, report, log.
  void command(const loop::WheelCommand& command) override;
  void healthEvent(safety::FaultMonitor::Event event, int channel) override;
  void log(loop::LogLevel level, const std::string& text) override;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  params::NodeParams params_;
  RosClock clock_;

  std::unique_ptr<NodeOutputs> outputs_;
  std::unique_ptr<loop::ControlLoop> loop_;
  std::unique_ptr<NodeReconfigure> reconfigure_;
  std::unique_ptr<NodeDiagnostics> diagnostics_;
  /// Whether commands leave the node (~enable_output; a field trial's A/B switch). Under mutex_.
  safety::OutputGate gate_;
  std::unique_ptr<OutputEnable> output_enable_;
  std::unique_ptr<LearnedModelService> learned_model_;  ///< ~save_learned_model, ~reset_learned_model

  /// The subscribers' queue while the belief thread runs (served by it); declared before the
  /// subscribers, so it outlives them.
  ros::CallbackQueue sensor_queue_;
  /// The subscribers' queue on the event schedule: callbacks run on roscpp's network thread.
  InlineCallbackQueue inline_queue_;
  ros::Subscriber joint_sub_, imu_sub_, set_point_sub_, status_sub_, feedback_sub_;
  ros::Timer action_timer_;

  /// Guards loop_, params_ and published_steps_.
  mutable std::mutex mutex_;
  std::uint64_t published_steps_ = 0;  ///< loop_->beliefSteps() at the last debug publication

  /// The command topic's conflict state (guarded by mutex_).
  std::unique_ptr<safety::OutputConflict> conflict_;
  /// Polls the master for the command topic's publishers (publisher_check_period > 0); destroyed
  /// (its thread joined) before everything its callback uses.
  std::unique_ptr<PublisherWatch> publisher_watch_;

  bool belief_on_thread_ = false;  ///< the belief loop runs on its own thread (timer schedule, wall clock)
  /// The belief loop (timer schedule only). Declared last: destroyed (stopped) first.
  std::unique_ptr<BeliefLoop> belief_loop_;
};

}  // namespace node
}  // namespace jackal_aic
