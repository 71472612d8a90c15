#pragma once
/**
 * \file stock_controller_node.hpp
 * \brief stock_controller: the Jackal's stock velocity controller as a node (logic in
 *        jackal_aic::harness::StockController, diff_drive_controller's mapping and limits). Two roles:
 *
 * - comparison controller (default): subscribes /jackal_AIC/set_point, publishes /cmd_drive;
 * - stand-in for the stock base (launch/sim.launch base:=stock_diff_drive): with
 *   ~input_topic jackal_velocity_controller/cmd_vel it is the diff drive that jackal_node
 *   runs on the robot (jackal_robot's jackal_base), the one /cmd_drive publisher; with
 *   ~publish_odom it publishes the diff drive's wheel odometry on
 *   jackal_velocity_controller/odom; with ~publish_mcu_state it publishes a jackal_msgs/Status
 *   on /status (1 Hz and at once on a change) and a jackal_msgs/Feedback on /feedback (every
 *   update) with a settable stop: ~stop (initial) and the topic ~set_stop (std_msgs/Bool).
 *   While stopped it sends MODE_NONE on /cmd_drive (the MCU's motor enable is off: the
 *   simulated motors are released) and reports drivers_active false, external stop stopped,
 *   Feedback actual_mode MODE_NONE.
 *   With ~cycle_on_joint_states (sim.launch sets it for the stock base) the diff drive's cycle
 *   runs on each joint_states message, as jackal_node's control loop publishes the joint states
 *   and then the diff drive's /cmd_drive in the same cycle: a command that answers a cycle's
 *   joint states is used at the next cycle, a fixed one-period delay rather than the phase of
 *   two free-running 50 Hz clocks. The ~publish_rate timer then only runs the cycle when no
 *   joint states came for 1.5 periods (the MCU keeps receiving commands).
 *
 * Subscribes ~input_topic (geometry_msgs/Twist: linear.x [m/s], angular.z [rad/s]; default
 * jackal_AIC/set_point) and, with ~publish_odom or ~cycle_on_joint_states, joint_states (sensor_msgs/JointState: the
 * wheel velocities of ~left_joints, ~right_joints); publishes cmd_drive (jackal_msgs/Drive,
 * MODE_VELOCITY, [rad/s]) at ~publish_rate (50 Hz) or on each joint_states. Non-finite commands are dropped with a
 * throttled warning.
 * Private parameters (defaults = jackal_control/config/control.yaml): wheel_separation,
 * wheel_separation_multiplier, wheel_radius, max_linear_velocity, max_linear_acceleration,
 * max_angular_velocity, max_angular_acceleration, cmd_vel_timeout, publish_rate.
 * Invalid values: the node logs each one with its allowed range and exits non-zero.
 */

#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>

#include "jackal_aic/loop/time_jump.hpp"
#include "jackal_sim/harness/diff_drive_odometry.hpp"
#include "jackal_sim/harness/stock_controller.hpp"

namespace jackal_aic
{
namespace sim_nodes
{
/// The stock controller node (see file comment): ROS wiring around harness::StockController.
class StockControllerNode
{
public:
  /**
   * \brief Read the private parameters, advertise and subscribe, start the timers.
   * \param nh   the node's namespace (cmd_drive, joint_states, odometry, status, feedback)
   * \param pnh  the private namespace (parameters, ~set_stop)
   * \throws std::invalid_argument from harness::StockController on an invalid parameter
   */
  StockControllerNode(ros::NodeHandle nh, ros::NodeHandle pnh);

private:
  /// The diff drive's parameters from the private namespace (defaults: jackal_control's control.yaml).
  static harness::StockControllerParams readParams(const ros::NodeHandle& pnh);
  /// A Twist set point [m/s, rad/s]; non-finite ones are dropped with a throttled warning.
  void onCommand(const geometry_msgs::Twist::ConstPtr& msg);
  /// ~set_stop: engage (true) or release (false) the simulated MCU stop.
  void onSetStop(const std_msgs::Bool::ConstPtr& msg);
  /// Mean of one field (js.position or js.velocity) over the named joints; false if one is missing or non-finite.
  static bool meanField(const sensor_msgs::JointState& js, const std::vector<double>& field,
                        const std::vector<std::string>& names, double* out);
  /// diff_drive_controller's odometry for the parameters in force (control.yaml's s and r).
  harness::DiffDriveOdometry makeOdometry() const;
  /// Runs the cycle (~cycle_on_joint_states), then diff_drive_controller's odometry from the wheel
  /// positions at the message's stamp (harness::DiffDriveOdometry), published on jackal_velocity_controller/odom.
  void onJointState(const sensor_msgs::JointState::ConstPtr& msg);
  /// Publish jackal_msgs/Status. Call with mutex_ held.
  void publishStatus();
  /// The ~publish_rate timer (only a fallback with ~cycle_on_joint_states).
  void onTimer(const ros::TimerEvent& e);
  /// One diff-drive cycle: update the controller, publish /cmd_drive (and /feedback).
  void cycle();
  /**
   * \brief ROS time moved back (a /clock restarting, a bag's loop, a wall clock stepped back):
   *        the controller, the cycle time and the odometry's stamp move onto the new timeline
   *        (the pose is kept); one warning. Call with mutex_ held, first in every callback.
   */
  void checkClock();

  std::mutex mutex_;
  harness::StockController controller_;
  harness::DiffDriveOdometry odometry_;  ///< joint-state thread only
  bool publish_odom_ = false, publish_mcu_ = false, stopped_ = false, cycle_on_joint_states_ = false;
  ros::Time last_cycle_;  ///< time of the last cycle (mutex_)
  std::vector<std::string> left_joints_, right_joints_;
  ros::Publisher pub_, odom_pub_, status_pub_, feedback_pub_;
  ros::Subscriber sub_, joint_sub_, stop_sub_;
  ros::Timer timer_, status_timer_;
  ros::Time last_odom_;
  loop::TimeJumpDetector time_jump_{ 0.001 };  ///< ROS time (mutex_)
  /// The pose reached before the odometry last restarted (ROS time moved back) [m, m, rad].
  double x_offset_ = 0.0, y_offset_ = 0.0, heading_offset_ = 0.0;
};

}  // namespace sim_nodes
}  // namespace jackal_aic
