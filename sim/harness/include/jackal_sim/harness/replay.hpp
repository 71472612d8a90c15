#pragma once
/**
 * \file replay.hpp
 * \brief Replay of a recorded /cmd_drive stream (a robot's bag) on the ODE plant, headless and
 *        faster than real time, with the sensor streams a Jackal publishes (/joint_states,
 *        /imu/data) sampled as the plant node samples them; and the stock controller's
 *        /cmd_drive stream for a twist profile. ROS-free; used by plant_replay (the engine of
 *        `plant_identify.py --bag`) and its gtest.
 *
 * The MCU gets each command at its time (the plant's wheel-speed servo then applies its own
 * transport delay, motor.command_delay): MODE_VELOCITY commands set the wheel-speed set points,
 * MODE_NONE releases the motors. Between commands the last one holds, as on the MCU (the
 * plant node's cmd_timeout is a node setting, not part of a replay).
 */

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_aic
{
namespace harness
{
/// The plant's names this interface uses (jackal_sim/plant/).
using plant::kNumWheels;
using plant::PlantParams;
using plant::RobotDescription;
/// One jackal_msgs/Drive message as the MCU receives it.
struct DriveCommand
{
  double time = 0.0;    ///< receipt time from the start of the replay [s], >= 0
  bool enabled = true;  ///< MODE_VELOCITY (true) or MODE_NONE (false: motors released)
  double left = 0.0;    ///< left wheel-speed set point [rad/s] (ignored when !enabled)
  double right = 0.0;   ///< right wheel-speed set point [rad/s]
};

/// One joint-state sample of the replay (50 Hz by default) with the newest IMU sample and the
/// ground truth at the same instant.
struct ReplaySample
{
  double time = 0.0;                          ///< joint-state stamp [s]
  std::array<double, kNumWheels> position{};  ///< wheel angles [rad], WheelIndex order
  std::array<double, kNumWheels> velocity{};  ///< wheel speeds [rad/s], WheelIndex order
  double imu_time = 0.0;                      ///< stamp of the IMU sample [s] (NaN before the first)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< IMU frame in odom
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       ///< gyro [rad/s]
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();    ///< specific force [m/s^2]
  double v_true = 0.0;                                              ///< ground-truth forward speed in base_link [m/s]
  double yaw_true = 0.0;                                            ///< ground-truth yaw rate [rad/s]
  bool command_enabled = false;                                     ///< the last command received (MODE_VELOCITY)
  double command_left = 0.0;                                        ///< its left set point [rad/s]
  double command_right = 0.0;                                       ///< its right set point [rad/s]
  double torque_left = 0.0;                                         ///< the left servo's torque in the last step [N m]
  double torque_right = 0.0;                                        ///< the right servo's torque [N m]
};

/**
 * \brief Replay a /cmd_drive stream on a fresh plant for `duration` seconds.
 * \param description   robot model
 * \param params        plant parameters (sensor noise, bias and dropout off if ideal_sensors)
 * \param commands      the stream, sorted by time
 * \param duration      length of the replay [s], > 0
 * \param ideal_sensors true: joint-state and IMU noise, bias and dropout off (reproducible)
 * \return one ReplaySample per joint-state sample
 * \throws std::invalid_argument on an empty stream, an unsorted, negative or non-finite time, a
 *         non-finite set point of an enabled command, or a non-positive or non-finite duration
 */
std::vector<ReplaySample> replayDriveCommands(const RobotDescription& description, PlantParams params,
                                              const std::vector<DriveCommand>& commands, double duration,
                                              bool ideal_sensors = true);

/**
 * \brief The /cmd_drive stream the stock controller (jackal_sim/harness/stock_controller.hpp: the
 *        Jackal's diff_drive_controller mapping and limits, 50 Hz) sends for a streamed twist
 *        profile: one command per controller period k / publish_rate, k = 0, 1, ... < duration.
 *        The stock controller is open loop, so the stream does not depend on the plant.
 * \param profile  set points (start [s], linear [m/s], angular [rad/s]), sorted by start; before
 *                 the first segment the set point is 0
 * \param duration [s], > 0
 * \throws std::invalid_argument on an empty or unsorted profile, a non-finite value or a bad duration
 */
std::vector<DriveCommand> stockDriveCommands(const std::vector<SetPointSegment>& profile, double duration);

}  // namespace harness
}  // namespace jackal_aic
