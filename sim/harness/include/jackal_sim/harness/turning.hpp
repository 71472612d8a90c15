#pragma once
/**
 * \file turning.hpp
 * \brief Turning on the plant: the stock controller driving a constant twist (a turn in place or a
 *        steady arc) from rest, with how soon it gets there, what it settles to and the effective
 *        wheel separation it turns with; a grid of arcs. ROS-free; the engine of the plant_turning
 *        tool and of the turning gtests (test/sim/test_turning.cpp).
 *
 * The stock controller (diff_drive_controller's mapping, 50 Hz, jackal_control's limits) maps a
 * twist to wheel speeds open loop, with the separation 1.5 x track = 0.5634 m: what the robot does
 * is the plant's answer to that command, so the stock controller is the plant's own judge. Its
 * 4.0 rad/s and 2.0 m/s limits are those of the twist, not of the plant.
 *
 * Measured: ground-truth body speed and yaw rate (the noise-free gyro: sensor noise does not
 * enter the open-loop stock controller), the side wheel speeds and motor torques, and the
 * effective (virtual) separation b = r (omega_R - omega_L) / yaw rate (J.L. Mandow et al.,
 * "Experimental kinematics for wheeled skid-steer mobile robots", IROS 2007).
 */

#include <string>
#include <vector>

#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_aic
{
namespace harness
{
using plant::PlantParams;
using plant::RobotDescription;

/// What to measure of one constant twist.
struct TwistRunOptions
{
  double settle = 0.5;      ///< rest before the command [s], >= 0 (the plant settles on its wheels)
  double duration = 6.0;    ///< the command's length [s], > window
  double window = 2.5;      ///< steady means over the last `window` seconds [s], > 0
  double reach = 0.95;      ///< "reached": |yaw rate| >= reach |command| (and the same for the speed) [-], (0, 1]
  double tolerance = 0.05;  ///< "followed": steady speed and yaw rate within this fraction of the command [-], > 0
};

/// One constant twist of the stock controller from rest, measured.
struct TwistRun
{
  double linear = 0.0;        ///< commanded body speed [m/s]
  double angular = 0.0;       ///< commanded yaw rate [rad/s]
  double v_true = 0.0;        ///< steady ground-truth forward speed [m/s]
  double yaw_rate = 0.0;      ///< steady ground-truth yaw rate (the noise-free gyro) [rad/s]
  double wheel_left = 0.0;    ///< steady mean left wheel speed [rad/s]
  double wheel_right = 0.0;   ///< steady mean right wheel speed [rad/s]
  double torque_left = 0.0;   ///< steady mean left motor torque (at the wheels) [N m]
  double torque_right = 0.0;  ///< steady mean right motor torque [N m]
  double wheel_radius = 0.0;  ///< r [m]
  /// Seconds from the command until the yaw rate (and, on an arc or straight, the speed) first reach
  /// `reach` times the command; NaN if never within the run.
  double reach_time = 0.0;
  /// Steady speed within tolerance |linear| (0.02 m/s when the command is 0) and yaw rate within
  /// tolerance |angular| (0.02 rad/s when 0) of the command.
  bool followed = false;

  /// Effective separation r (wR - wL) / yaw_rate [m]; NaN when the yaw rate is ~0.
  double separation() const;
};

/**
 * \brief Run the stock controller with a constant twist from rest on a fresh plant.
 * \param description robot model
 * \param params      plant parameters (sensor noise is irrelevant: the stock controller is open loop)
 * \param linear      body speed [m/s], finite
 * \param angular     yaw rate [rad/s], finite
 * \param options     timing and thresholds
 * \throws std::invalid_argument on non-finite commands or invalid options (message says which)
 */
TwistRun runStockTwist(const RobotDescription& description, const PlantParams& params, double linear, double angular,
                       const TwistRunOptions& options = {});

/// The arcs of the turning grid: forward speeds [m/s] and yaw rates [rad/s].
struct TurningGrid
{
  std::vector<double> speeds{ 0.2, 0.5, 1.0, 1.5 };     ///< [m/s]
  std::vector<double> yaw_rates{ 0.2, 0.5, 1.0, 1.5 };  ///< [rad/s]
  std::vector<double> in_place{ 0.3, 1.0, 1.57 };       ///< turns in place [rad/s]
};

/// Every run of a grid: turns in place first (in_place order), then the arcs, speed-major.
std::vector<TwistRun> runTurningGrid(const RobotDescription& description, const PlantParams& params,
                                     const TurningGrid& grid, const TwistRunOptions& options = {});

}  // namespace harness
}  // namespace jackal_aic
