#pragma once
/**
 * \file plant_node.hpp
 * \brief jackal_plant: a thin ROS node over the ODE plant core, standing in for the Jackal.
 *
 * Subscribes /cmd_drive (jackal_msgs/Drive): MODE_VELOCITY -> per-side wheel-speed set
 * points [rad/s]; MODE_NONE -> motors released; any other mode -> throttled warning and
 * treated as MODE_NONE; non-finite values -> dropped with a throttled warning. If no
 * command arrives for node.cmd_timeout [s] of plant time the set points become zero (the
 * stock stack streams zeros after its own 0.25 s timeout; the MCU's timeout is not
 * documented, so this is a safety net, 0 disables it).
 *
 * Publishes /joint_states and /imu/data (rates, noise, bias, delay, dropout from the
 * plant YAML), ground-truth /odom (nav_msgs/Odometry, frame odom, child base_link, twist
 * in base_link) and tf odom -> base_link, all stamped with plant time: in real-time mode
 * stamp = ROS time at start + plant time; with /use_sim_time the node publishes /clock
 * (= plant time) itself, starting it once the /joint_states subscribers the master lists are
 * connected (at most 2 s of wall time: waitForSubscribers()). In real-time mode a backward step of the wall clock moves the origin
 * with it (checkClock()).
 *
 * The physics steps in fixed increments (physics.step, 1 ms). Pacing: each wake-up runs
 * every step due by the wall clock (so the plant catches up after a late wake-up), then
 * sleeps until the next step is due; node.real_time_factor scales plant time per wall
 * time (0 = as fast as possible). A lag of more than kWallClockCatchUp (0.5 s) on the wall
 * clock, kSimTimeCatchUp (one 50 Hz period) on simulated time, and never less than one step, is
 * dropped (logged) instead of being caught up: on simulated time a host stall then pauses the
 * whole system.
 *
 * ~joint_states_source: who publishes /joint_states. "direct" (default): the sensor model's
 * samples as they are (fresh, distinct, stamped when taken). "jackal_node": as a Jackal's
 * jackal_node does (plant::JackalNodeSampler: the samples are the MCU's feedback, re-sampled by a
 * free-running 50 Hz loop with ~jackal_node/phase [s], ~jackal_node/drift [ppm],
 * ~jackal_node/jitter_std [s], ~jackal_node/stall_probability, ~jackal_node/stall_max [s],
 * ~jackal_node/link_delay [s], ~jackal_node/seed; stamped with the loop's time; both joints of a
 * side carry the side's measurement; effort 0). "none": nothing (the real jackal_node publishes them
 * from /feedback).
 *
 * ~publish_mcu (default false): the MCU's interface, as jackal_node expects it over rosserial:
 * jackal_msgs/Feedback on /feedback with every joint-state sample of the sensor model (50 Hz; per side:
 * measured_velocity [rad/s] and measured_travel [rad] (the mean of the side's wheels, travel from
 * the plant's start), current [A] = |side torque| / ~mcu/torque_constant, duty_cycle = side torque /
 * motor.stall_torque + speed / motor.no_load_speed in [-1, 1] (the plant's DC-motor voltage
 * model), temperatures a constant ~mcu/temperature [deg C], driver_fault false; commanded_mode and
 * actual_mode MODE_VELOCITY while velocity commands arrive, else MODE_NONE) and jackal_msgs/Status on
 * /status at 1 Hz (drivers active, no external stop, nominal rails 26 / 12 / 5 V, uptimes = plant
 * time). The rosserial link itself is not simulated.
 *
 * Private parameters: ~urdf (URDF path, required), ~plant_config (plant YAML path,
 * required), ~overlay (a plant YAML with only the keys that differ, e.g.
 * sim/config/variants/turn_deficit.yaml, or a list of them applied in order; "" or absent =
 * none), ~overrides (list of "key=value" strings applied on top of the YAML and the overlays).
 */

#include <atomic>
#include <memory>
#include <mutex>
#include <string>

#include <jackal_msgs/Drive.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_broadcaster.h>

#include <deque>
#include <vector>

#include "jackal_aic/loop/time_jump.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_sim/plant/jackal_node_sampler.hpp"
#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_sim/plant/sensor_model.hpp"

namespace jackal_aic
{
namespace sim_nodes
{
/// The plant's names this interface uses (jackal_sim/plant/).
using plant::FaultedSensors;
using plant::ImuSample;
using plant::JointStateSample;
using plant::Plant;
using plant::PlantParams;
using plant::RobotDescription;
/// The plant node (see file comment).
class PlantNode
{
public:
  /**
   * \brief Read parameters, load the URDF and plant YAML, build the plant, advertise.
   * \throws std::runtime_error (RobotDescriptionError, PlantParamsError) with a message
   *         naming the file and what is wrong; main() logs it and exits non-zero.
   */
  PlantNode(ros::NodeHandle nh, ros::NodeHandle pnh);

  /// Step and publish until ROS shuts down. Returns the process exit code.
  int run();

private:
  /// Latest /cmd_drive, written by the subscriber thread.
  struct Command
  {
    std::uint64_t seq = 0;  ///< increments with every accepted message
    bool velocity = false;  ///< MODE_VELOCITY (else released)
    double left = 0.0;      ///< [rad/s]
    double right = 0.0;     ///< [rad/s]
  };

  void onDrive(const jackal_msgs::Drive::ConstPtr& msg);
  void stepOnce();
  void applyCommand();
  ros::Time stamp(double plant_time) const;
  void publishJointStates(const JointStateSample& s);
  void publishImu(const ImuSample& s);
  /// joint_msg_ from a sample (stamp, positions, velocities, efforts).
  void fillJointStates(const JointStateSample& s);
  /// The Imu message of a sample.
  sensor_msgs::Imu imuMessage(const ImuSample& s) const;
  void publishOdom();
  /// /feedback of one MCU sample (~publish_mcu).
  void publishFeedback(const JointStateSample& s);
  /// /status (~publish_mcu), at 1 Hz of plant time.
  void publishStatus();
  /// The re-sampler's parameters from ~jackal_node/* (defaults: JackalNodeSamplerParams).
  plant::JackalNodeSamplerParams samplerParams() const;
  /// Re-read ~faults (a list of fault lines, sim/plant/include/jackal_sim/plant/fault_injection.hpp) if it changed.
  void pollFaults();
  /**
   * \brief Real-time mode: if ROS time (the wall clock) moved back, the stamps' origin moves
   *        with it (stamps = ROS time again, so they jump back as the clock did); one warning.
   *        With /use_sim_time the plant is the clock (a restarted plant node starts its
   *        timeline at 0): nothing to do.
   */
  void checkClock();
  /**
   * \brief Simulated time, before the first step: wait (wall clock, at most kSubscriberWait)
   *        until every node the master lists as a /joint_states subscriber is connected, so a
   *        plant restarted under running nodes does not start its timeline before they can
   *        receive it (the clock stands still meanwhile).
   */
  void waitForSubscribers();
  static constexpr double kSubscriberWait = 2.0;  ///< [s] of wall time
  /// Plant time [s] run() catches up in a burst when it falls behind the wall clock on the wall
  /// clock; beyond it the lag is dropped (the stamps stay within it of the wall clock).
  static constexpr double kWallClockCatchUp = 0.5;
  /// The same on simulated time: one 50 Hz control period. Beyond it the lag is dropped and
  /// simulated time pauses with the host (every node waits for /clock), so a stall of the host
  /// never runs the plant open loop for longer than a control period.
  static constexpr double kSimTimeCatchUp = 0.02;

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  RobotDescription description_;
  PlantParams params_;
  std::unique_ptr<Plant> plant_;
  /// The sensor model with the injected faults (physical faults, delays, dropouts, ...).
  std::unique_ptr<FaultedSensors> sensors_;
  std::vector<JointStateSample> joint_samples_;  ///< published this step (FaultedSensors::afterStep())
  std::vector<ImuSample> imu_samples_;
  bool use_sim_time_ = false;
  ros::Time origin_;
  loop::TimeJumpDetector time_jump_{ 0.001 };  ///< ROS time in real-time mode
  std::uint64_t odom_period_ = 20;
  std::uint64_t clock_period_ = 1;

  std::mutex command_mutex_;
  Command command_;
  std::uint64_t applied_seq_ = 0;
  double last_command_time_ = 0.0;  ///< plant time the last command was applied [s]
  bool timed_out_ = false;

  ros::Subscriber drive_sub_;
  ros::Publisher joint_pub_;
  ros::Publisher imu_pub_;
  ros::Publisher odom_pub_;
  ros::Publisher clock_pub_;
  ros::Publisher feedback_pub_;
  ros::Publisher status_pub_;
  /// ~joint_states_source
  enum class JointSource
  {
    kDirect,
    kJackalNode,
    kNone
  } joint_source_ = JointSource::kDirect;
  std::unique_ptr<plant::JackalNodeSampler> sampler_;  ///< with kJackalNode
  std::vector<plant::ResampledJointState> resampled_;
  bool publish_mcu_ = false;
  double torque_constant_ = 1.0;        ///< [N m / A], ~mcu/torque_constant
  double mcu_temperature_ = 30.0;       ///< [deg C], ~mcu/temperature
  std::uint64_t status_period_ = 1000;  ///< steps between /status messages
  tf2_ros::TransformBroadcaster tf_;
  sensor_msgs::JointState joint_msg_;
  std::vector<std::string> fault_lines_;
  std::uint64_t fault_poll_period_ = 200;  ///< steps between reads of ~faults
};

}  // namespace sim_nodes
}  // namespace jackal_aic
