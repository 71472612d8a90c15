#pragma once
/**
 * \file aic_node.hpp
 * \brief The jackal_AIC node: runs the ActiveInferenceController on ROS timers.
 *
 * Topics (see doc/jackal_aic_node.md, "Topics"):
 *   in:  /joint_states (sensor_msgs/JointState), /imu/data (sensor_msgs/Imu),
 *        ~set_point (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s])
 *   out: /cmd_drive (jackal_msgs/Drive, MODE_VELOCITY, drivers [rad/s]) every action tick;
 *        ~belief (geometry_msgs/TwistStamped, mu^(0)) every belief step;
 *        ~sensor_health (diagnostic_msgs/DiagnosticStatus, latched) on every fault event and at 10 Hz;
 *        ~free_energy (std_msgs/Float64), ~eps_y, ~eps_mu (std_msgs/Float64MultiArray,
 *        rows = channels, cols = orders) every action tick (decimated from the belief rate);
 *        /diagnostics (NodeDiagnostics). Publishers and the finiteness guard: NodeOutputs.
 *
 * The node is wiring. The decisions are the ROS-free Supervisor's
 * (include/jackal_aic/supervisor.hpp: state machine, watchdogs, catch-up scheduling, loop
 * statistics); the parameters come from the schema (include/jackal_aic/param_schema.hpp)
 * through loadNodeParams() and NodeReconfigure; diagnostics are NodeDiagnostics.
 *
 * Threading: one thread (ros::spin). Subscribers validate and store; the belief timer
 * (belief_rate) integrates the beliefs in the steps the supervisor plans (a late tick is
 * caught up, one ~belief message per step, stamped with the time its belief refers to),
 * the action timer (action_rate) the action, and publishes the command. dynamic_reconfigure
 * queues a validated parameter set; the timers apply it at the start of their next tick.
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

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "jackal_aic/controller.hpp"
#include "jackal_aic/fault_monitor.hpp"
#include "jackal_aic/generalizer.hpp"
#include "jackal_aic/node_params.hpp"
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
  void beliefTimerCallback(const ros::TimerEvent& event);
  void actionTimerCallback(const ros::TimerEvent& event);

  /// Apply a parameter set queued by dynamic_reconfigure (between ticks).
  void applyPendingParams();
  /// Carry out a supervisor transition: restart the history, warn, (de)activate.
  void carryOut(const Supervisor::Transition& t);
  /// Reset the controller and start it from the measured wheel speeds (bumpless).
  void activate();
  void handleRunaway(const char* where);
  /// Publish a wheel command through the final guard (NodeOutputs::command, +-max_wheel_speed).
  void publishCommand(double omega_left, double omega_right)
  {
    outputs_->command(omega_left, omega_right, params_.aic.max_wheel_speed);
  }
  ControllerReport controllerReport() const;
  /// Fault detection and isolation on one accepted sample: IMU availability, the residual test,
  /// the controller's channel mask (Pi_y = 0 for isolated or missing channels), events to diagnostics.
  void checkSensorFaults(const SensorSample& sample);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  NodeParams params_;
  RosClock clock_;

  std::unique_ptr<ActiveInferenceController> controller_;
  std::unique_ptr<Generalizer> generalizer_;
  std::unique_ptr<FaultMonitor> fault_monitor_;  ///< sensor FDI (doc/active_inference.md)
  std::unique_ptr<SensorSynchronizer> sync_;
  std::unique_ptr<Supervisor> supervisor_;
  std::unique_ptr<NodeReconfigure> reconfigure_;
  std::unique_ptr<NodeDiagnostics> diagnostics_;
  std::unique_ptr<NodeOutputs> outputs_;

  ros::Subscriber joint_sub_, imu_sub_, set_point_sub_;
  ros::Timer belief_timer_, action_timer_, diagnostics_timer_;

  std::uint64_t generalizer_drops_ = 0;  ///< samples the generalizer or the controller refused
};

}  // namespace jackal_aic
