#pragma once
/**
 * \file aic_node.hpp
 * \brief The jackal_AIC node: runs the ActiveInferenceController, its belief loop on a
 *        real-time thread (wall clock) or a ROS timer (use_sim_time), its action on a ROS timer.
 *
 * Topics (see doc/jackal_aic_node.md, "Topics"):
 *   in:  /joint_states (sensor_msgs/JointState), /imu/data (sensor_msgs/Imu),
 *        ~set_point (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s])
 *        /status (jackal_msgs/Status), /feedback (jackal_msgs/Feedback): the MCU's stop state
 *   out: /cmd_drive (jackal_msgs/Drive, MODE_VELOCITY, drivers [rad/s]) every action tick, or in
 *        output mode cmd_vel jackal_velocity_controller/cmd_vel (geometry_msgs/Twist, the
 *        inverse of the stock diff drive: CmdVelOutput, include/jackal_aic/diff_drive.hpp);
 *        ~belief (geometry_msgs/TwistStamped, mu^(0)), ~free_energy (std_msgs/Float64),
 *        ~eps_y, ~eps_mu (std_msgs/Float64MultiArray, rows = channels, cols = orders) at
 *        debug_rate (100 Hz) from the newest belief, when there is a new one, while any
 *        of them has a subscriber (no debug timer wake-ups otherwise);
 *        ~sensor_health (diagnostic_msgs/DiagnosticStatus, latched) on every fault event and channel-state change, and at 1 Hz;
 *        /diagnostics (NodeDiagnostics). Publishers and the finiteness guard: NodeOutputs.
 *
 * The node is wiring. The decisions are the ROS-free Supervisor's
 * (include/jackal_aic/supervisor.hpp: state machine, watchdogs, catch-up scheduling, loop
 * statistics); the parameters come from the schema (include/jackal_aic/param_schema.hpp)
 * through loadNodeParams() and NodeReconfigure; diagnostics are NodeDiagnostics.
 *
 * Threading (doc/jackal_aic_node.md, 'Loops'). The subscribers validate and store (with
 * action_trigger sample each accepted sample also runs the action step). The spinner thread
 * (ros::spin) runs the action timer (action_rate: the action step and the command; with
 * action_trigger sample a keep-alive), the debug timer (debug_rate), the diagnostics and
 * dynamic_reconfigure. The belief loop (belief_rate) integrates the beliefs in the steps the
 * supervisor plans (a late tick is caught up):
 *  - wall clock (use_sim_time false): on its own PeriodicThread, sleeping to absolute
 *    CLOCK_MONOTONIC deadlines, optionally SCHED_FIFO (realtime_priority); a ROS timer
 *    costs a wake-up of the spinner and a callback-queue round trip per period. The
 *    subscribers run on this thread too, from their own callback queue: at belief periods
 *    up to kBatchedDispatchMaxPeriod the queue is served once per tick, right after the
 *    wake-up and before the belief step (no wake-up per message; a sample waits at most one
 *    period), at longer periods as the messages arrive, while the thread waits for its
 *    deadline;
 *  - simulated time: on a ROS timer (the thread could not follow /clock), the subscribers
 *    on the spinner.
 * One mutex guards the controller, the generalizer, the sensor pairing and the supervisor;
 * each holder keeps it for one short step (a belief step is a few microseconds), and the
 * debug timer copies a DebugSnapshot under it and publishes outside it. dynamic_reconfigure
 * queues a validated parameter set; the action timer (and, on ROS timers, the belief timer)
 * applies it at the start of its next tick.
 *
 * Safety: the controller runs only in the supervisor's kRunning state; otherwise the
 * command is zero, published at once on leaving kRunning. On (re)activation the controller
 * is reset, given the latest generalized measurement and started from the measured wheel
 * speeds (bumpless start). A runaway (reported by the controller) resets it and holds a
 * zero command for runaway_hold_time with diagnostics ERROR. Every published number passes
 * a final finiteness guard.
 */

#include <cstdint>
#include <memory>
#include <mutex>

#include <geometry_msgs/Twist.h>
#include <jackal_msgs/Feedback.h>
#include <jackal_msgs/Status.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "jackal_aic/sample_pipeline.hpp"
#include "jackal_aic/node_params.hpp"
#include "jackal_aic/ros/belief_loop.hpp"
#include "jackal_aic/ros/node_diagnostics.hpp"
#include "jackal_aic/ros/node_outputs.hpp"
#include "jackal_aic/ros/node_reconfigure.hpp"
#include "jackal_aic/ros/sensor_sync.hpp"
#include "jackal_aic/supervisor.hpp"

namespace jackal_aic
{
/// ros::Time::now() as a Clock [s] (wall or simulated time, as the node runs).
class RosClock : public Clock
{
public:
  double now() const override { return ros::Time::now().toSec(); }
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
  /// Stops the belief thread before anything it uses is destroyed.
  ~AicNode();
  AicNode(const AicNode&) = delete;
  AicNode& operator=(const AicNode&) = delete;

  /**
   * \brief Read and validate the parameters, then create subscribers, publishers, timers,
   *        the dynamic_reconfigure server and the diagnostics.
   * \return false after logging (ROS_FATAL) every violation as "name = value (allowed: range)".
   */
  bool init();

private:
  void jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg);
  void imuCallback(const sensor_msgs::Imu::ConstPtr& msg);
  void setPointCallback(const geometry_msgs::Twist::ConstPtr& msg);
  void statusCallback(const jackal_msgs::Status::ConstPtr& msg);
  void feedbackCallback(const jackal_msgs::Feedback::ConstPtr& msg);
  void actionTimerCallback(const ros::TimerEvent& event);
  /**
   * \brief One action step (call with the lock held): watchdogs, a += h da/dt (thesis eq.
   *        3-16) over the interval [s] (-1: nominal; clamped to 3 periods), the command.
   *        From the action timer (action_trigger timer) or each accepted sample (sample).
   */
  void actionStep(double interval);
  /**
   * \brief One belief-loop tick (either thread; takes the lock): plan the steps for the
   *        measured interval [s] (-1: first tick), run the watchdogs, integrate the beliefs.
   * \param stamp  the tick's time (ROS time), for the ~belief stamp
   */
  void beliefTick(double interval, const ros::Time& stamp);

  /// Apply a parameter set queued by dynamic_reconfigure (between ticks; call with the lock held).
  void applyPendingParams();
  /// Carry out a supervisor transition: restart the history, warn, (de)activate.
  void carryOut(const Supervisor::Transition& t);
  /// Reset the controller and start it from the measured wheel speeds (bumpless).
  void activate();
  void handleRunaway(const char* where);
  /**
   * \brief Publish a wheel command [rad/s] (NodeOutputs::wheels(): clamped to
   *        +-max_wheel_speed, final guard, /cmd_drive or cmd_vel); a command clipped by the stock
   *        controller's limits is fed back as the controller's action while it runs (anti-windup).
   */
  void publishCommand(double omega_left, double omega_right);
  /// The command outside kRunning: the measured wheel speeds in kHeld (MCU stop), else zero.
  void publishIdle();
  ControllerReport controllerReport() const;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  NodeParams params_;
  RosClock clock_;

  /// Controller, generalizer and fault monitor (FDI: doc/active_inference.md), ROS-free.
  std::unique_ptr<SamplePipeline> pipeline_;
  std::unique_ptr<SensorSynchronizer> sync_;
  std::unique_ptr<Supervisor> supervisor_;
  std::unique_ptr<NodeReconfigure> reconfigure_;
  std::unique_ptr<NodeDiagnostics> diagnostics_;
  std::unique_ptr<NodeOutputs> outputs_;

  /// The subscribers' queue while the belief thread runs (served by it); declared before the
  /// subscribers, so it outlives them.
  ros::CallbackQueue sensor_queue_;
  ros::Subscriber joint_sub_, imu_sub_, set_point_sub_, status_sub_, feedback_sub_;
  ros::Timer action_timer_;

  /// Guards pipeline_, sync_, supervisor_, params_ and the belief bookkeeping below.
  mutable std::mutex mutex_;
  std::uint64_t generalizer_drops_ = 0;  ///< samples the generalizer or the controller refused
  std::uint64_t belief_steps_ = 0;       ///< belief integration steps since start (catch-up included)
  std::uint64_t published_steps_ = 0;    ///< belief_steps_ at the last debug publication
  ros::Time belief_stamp_;               ///< time of the newest belief step
  ros::Time newest_sample_stamp_;        ///< stamp of the newest accepted sensor sample

  bool belief_on_thread_ = false;  ///< the belief loop runs on its own thread (wall clock)
  /// The belief loop (thread or timer). Declared last: destroyed (stopped) first.
  std::unique_ptr<BeliefLoop> belief_loop_;
};

}  // namespace jackal_aic
