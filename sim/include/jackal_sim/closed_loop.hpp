#pragma once
/**
 * \file closed_loop.hpp
 * \brief A controller in closed loop with the ODE plant, headless and faster than real
 *        time: the stock controller, or the active inference controller scheduled as the
 *        jackal_AIC node schedules it. ROS-free; used by plant_identify (the wheel-loop
 *        identification) and by the identification gtests.
 *
 * Scheduling, mirroring the node (doc/jackal_aic_node.md) on simulated time:
 * - the plant steps at physics.step (1 kHz); after each step its sensor model is polled;
 * - a joint-state sample is paired with the newest IMU sample (both 50 Hz, same instants
 *   on the plant) into y = (gyro z, omega_L, omega_R, accel x, accel y); the generalizer
 *   (thesis eq. 3-17 ... 3-22) takes it with h = the interval between the two samples;
 * - once p + 1 samples have been generalized and a set point is present, the controller
 *   starts as the node's activation does: beliefs at the measured twist, action at the
 *   measured wheel speeds (bumpless);
 * - belief and action updates run on their own periods (rounded to whole plant steps),
 *   each with its measured interval; the action is sent to the plant at every action step.
 * - the stock controller (diff_drive_controller's open-loop mapping) runs at 50 Hz.
 *
 * What is measured: the body speed from wheel odometry r (omega_L + omega_R) / 2 of the
 * 50 Hz joint-state samples (the robot's own estimate, which the thesis's tables were
 * measured with), ground truth beside it, the body speed the drive command asks for, and
 * the AIC's belief mu^(0).
 */

#include <cstdint>
#include <string>
#include <vector>

#include "jackal_aic/params.hpp"
#include "jackal_sim/plant_params.hpp"
#include "jackal_sim/robot_description.hpp"

namespace jackal_aic
{
namespace sim
{
/// Which controller closes the loop.
enum class LoopController
{
  kStock,  ///< the Jackal's stock controller (diff_drive_controller mapping, 50 Hz)
  kAic,    ///< the active inference controller (jackal_aic core), scheduled as the node
  /// No controller: every 50 Hz tick the set point's wheel speeds (inverse kinematics of the
  /// stock controller, r and its b_hat) go to the MCU as they are. The wheel loop's own
  /// response, for identifying it (aic_tune.py).
  kOpenLoop
};

/// One piece of a piecewise-constant set-point profile.
struct SetPointSegment
{
  double start = 0.0;    ///< time from the run's start at which this set point begins [s], >= 0
  double linear = 0.0;   ///< body forward speed [m/s]
  double angular = 0.0;  ///< yaw rate [rad/s]
};

/// What to run.
struct ClosedLoopConfig
{
  LoopController controller = LoopController::kStock;
  AicParams aic;  ///< used when controller == kAic (validated by runClosedLoop)
  /// Set-point profile, sorted by start; the first segment should start at 0 (before it the
  /// set point is 0). Streamed, as teleop or a planner would, so no timeout fires.
  std::vector<SetPointSegment> profile;
  double duration = 4.0;    ///< length of the run [s], > 0
  bool ideal_sensors = true;  ///< true: joint-state and IMU noise, bias and dropout off (reproducible)
};

/// Recorded run, one entry per joint-state sample (50 Hz).
struct ClosedLoopRecord
{
  std::vector<double> time;       ///< sample time from the run's start [s]
  std::vector<double> set_point;  ///< linear set point in force [m/s]
  std::vector<double> v_odom;     ///< wheel-odometry body speed r (omega_L + omega_R) / 2 [m/s]
  std::vector<double> v_true;     ///< ground-truth forward speed in base_link [m/s]
  std::vector<double> yaw_odom;   ///< wheel-odometry yaw rate r (omega_R - omega_L) / b_hat [rad/s]
  std::vector<double> yaw_true;   ///< ground-truth yaw rate [rad/s]
  std::vector<double> command;    ///< body speed of the last drive command r (a_L + a_R) / 2 [m/s]
  std::vector<double> belief;     ///< AIC belief mu^(0) x_dot [m/s] (NaN for the stock controller)
  std::vector<double> angular_set_point;  ///< yaw-rate set point in force [rad/s]
  std::vector<double> command_yaw;  ///< yaw rate of the last drive command r (a_R - a_L) / b_hat [rad/s]
  std::vector<double> belief_yaw;   ///< AIC belief mu^(0) theta_dot [rad/s] (NaN for the others)
  std::vector<double> x_true;       ///< ground-truth position x of base_link in the world [m]
  std::vector<double> y_true;       ///< ground-truth position y of base_link in the world [m]
  std::vector<double> heading_true; ///< ground-truth yaw of base_link in the world [rad], wrapped to (-pi, pi]
  std::uint64_t runaways = 0;     ///< AIC runaway resets during the run
  bool active = false;            ///< AIC: the controller started (p + 1 samples and a set point)
};

/**
 * \brief Run a controller against a fresh plant for config.duration seconds.
 * \param description robot model
 * \param params      plant parameters (sensor noise switched off if config.ideal_sensors)
 * \param config      controller, profile, duration
 * \throws std::invalid_argument on an invalid AicParams, an empty or unsorted profile, a
 *         non-finite set point, or a non-positive duration (message says which)
 */
ClosedLoopRecord runClosedLoop(const RobotDescription& description, PlantParams params,
                               const ClosedLoopConfig& config);

/// A set-point step from rest: 0 until t_step, then `linear` [m/s] (and `angular` [rad/s]).
std::vector<SetPointSegment> stepProfile(double t_step, double linear, double angular = 0.0);

}  // namespace sim
}  // namespace jackal_aic
