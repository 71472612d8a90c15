#pragma once
/**
 * \file calibration.hpp
 * \brief Step responses of the stock controller on the plant, compared with the real
 *        Jackal's (thesis table 3-1b, doc/jackal.md). ROS-free; used by the
 *        plant_calibrate tool and by the calibration gtest.
 *
 * What is compared: the robot's table was measured from the robot's own velocity estimate,
 * which rests on wheel odometry. The plant is therefore measured the same way: body speed
 * v = r (omega_L + omega_R) / 2 from the 50 Hz joint-state samples (noise, bias and dropout
 * switched off so the numbers are reproducible). Ground truth is recorded beside it.
 * Metrics: jackal_aic::analysis::computeStepMetrics (the project's one implementation): rise time
 * 10-90 % of the step, settling time into +-5 % of the set point, both from the moment the
 * set point changes.
 */

#include <array>
#include <vector>

#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_aic
{
namespace harness
{
/// The plant's names this interface uses (jackal_sim/plant/).
using plant::PlantParams;
using plant::RobotDescription;
/// One row of the robot's table, with its acceptance band (sim/README.md, 'Calibration').
struct RobotStepReference
{
  double step;       ///< set-point step from rest [m/s]
  double settling;   ///< settling time (5 %) on the robot [s]
  double rise;       ///< rise time (10-90 %) on the robot [s]
  double tolerance;  ///< accepted relative error of the plant [-]
};

/// Thesis table 3-1b: 0.1, 0.5, 1.0 m/s (accepted within 50 %, 25 %, 25 %).
constexpr std::array<RobotStepReference, 3> kRobotStepTable{
  { { 0.1, 0.14, 0.04, 0.50 }, { 0.5, 0.54, 0.35, 0.25 }, { 1.0, 1.05, 0.62, 0.25 } }
};

/// Recorded step response; times from the set-point step [s].
struct StepRecord
{
  double step = 0.0;            ///< set point [m/s]
  std::vector<double> time;     ///< [s], 50 Hz sample times from the step
  std::vector<double> v_odom;   ///< wheel-odometry body speed [m/s]
  std::vector<double> v_true;   ///< ground-truth body speed in base_link [m/s]
  std::vector<double> command;  ///< stock controller's limited linear command [m/s]
};

/**
 * \brief Run the stock controller (50 Hz) on a fresh plant: rest for settle_before, then a
 *        set-point step (10 ms after a controller tick), recorded for `record` seconds.
 * \param description robot model
 * \param params      plant parameters (sensor noise is switched off inside)
 * \param step        set point [m/s], != 0
 * \param settle_before rest before the step [s]
 * \param record      recording after the step [s]
 */
StepRecord runStockStep(const RobotDescription& description, PlantParams params, double step,
                        double settle_before = 1.0, double record = 3.0);

/// Step metrics of a record (v_odom if ground_truth is false, else v_true).
analysis::StepMetrics stepMetricsOf(const StepRecord& record, bool ground_truth = false);

// ------------------------------------------------------------------ steady-state checks

/// The Jackal's top speed [m/s] (Clearpath's manual; the stock controller's limit too).
constexpr double kRobotTopSpeed = 2.0;
/// The top speed the thesis quotes [m/s].
constexpr double kThesisTopSpeed = 2.5;
/// Accepted shortfall of the steady speed for a kRobotTopSpeed command [-]: the plant must
/// reach the command (its wheel servo has an integrator), within numerical noise.
constexpr double kTopSpeedTolerance = 0.01;
/// Accepted excess of the motor-limited top speed over kThesisTopSpeed [-].
constexpr double kMotorTopSpeedTolerance = 0.10;
/// Virtual wheel separation b_hat identified on the robot [m] (thesis; the controllers'
/// wheel_separation). The stock controller's 1.5 x 0.37559 m = 0.5634 m agrees.
constexpr double kRobotWheelSeparation = 0.5621;
/// Accepted relative error of the plant's effective wheel separation [-].
constexpr double kSeparationTolerance = 0.10;
/// Accepted relative error of the ground-truth speed against r omega when driving
/// straight [-] (sim/README.md, 'Calibration': r omega within 5 %).
constexpr double kStraightSpeedTolerance = 0.05;

/// What drives the plant in a steady run.
enum class DriveInput
{
  kStockTwist,  ///< the stock controller (50 Hz), streamed twist set point (linear [m/s], angular [rad/s])
  kWheelSpeeds  ///< MCU wheel-speed set points directly (left, right [rad/s]), as /cmd_drive
};

/// A constant drive from rest and what it is compared with.
struct SteadyScenario
{
  const char* label;  ///< short description for the table
  DriveInput input;   ///< what a and b mean
  double a;           ///< linear [m/s] or left wheel speed [rad/s]
  double b;           ///< angular [rad/s] or right wheel speed [rad/s]
};

/// Means over the measuring window of a constant drive: 50 Hz joint-state samples (noise,
/// bias and dropout off) and the ground truth at the same instants.
struct SteadyDrive
{
  double wheel_left = 0.0;    ///< mean left wheel speed (front and rear) [rad/s]
  double wheel_right = 0.0;   ///< mean right wheel speed [rad/s]
  double v_odom = 0.0;        ///< wheel-odometry forward speed r (wL + wR) / 2 [m/s]
  double v_true = 0.0;        ///< ground-truth forward speed in base_link [m/s]
  double v_lateral = 0.0;     ///< ground-truth lateral speed in base_link [m/s]
  double yaw_rate = 0.0;      ///< ground-truth yaw rate (the noise-free gyro) [rad/s]
  double wheel_radius = 0.0;  ///< r [m]

  /// Effective (virtual) wheel separation r (wR - wL) / yaw_rate [m]: the b_hat with which
  /// an ideal differential drive would turn as the plant does. NaN if the yaw rate is ~0.
  double effectiveSeparation() const;
};

/// Top-speed scenarios: the stock controller at its 2.0 m/s limit, and the wheel set
/// points at the MCU's clamp (motor-limited speed).
constexpr std::array<SteadyScenario, 2> kTopSpeedScenarios{
  { { "stock, 2.0 m/s command", DriveInput::kStockTwist, kRobotTopSpeed, 0.0 },
    { "motor limit, wheels 25 rad/s", DriveInput::kWheelSpeeds, 25.0, 25.0 } }
};

/// Effective-separation scenarios: turning in place at two wheel speeds, the stock
/// controller turning in place and driving an arc.
constexpr std::array<SteadyScenario, 4> kSeparationScenarios{
  { { "in place, wheels -5/+5 rad/s", DriveInput::kWheelSpeeds, -5.0, 5.0 },
    { "in place, wheels -10/+10 rad/s", DriveInput::kWheelSpeeds, -10.0, 10.0 },
    { "in place, stock 0.5 rad/s", DriveInput::kStockTwist, 0.0, 0.5 },
    { "arc, stock 0.5 m/s + 0.5 rad/s", DriveInput::kStockTwist, 0.5, 0.5 } }
};

/**
 * \brief Drive a fresh plant from rest with a constant input and average the steady state.
 * \param description robot model
 * \param params      plant parameters (joint-state noise, bias and dropout switched off)
 * \param scenario    the drive
 * \param settle      time before the measuring window [s], > 0
 * \param measure     length of the measuring window [s], > 0
 * \throws std::invalid_argument on non-finite inputs or non-positive times
 */
SteadyDrive runSteadyDrive(const RobotDescription& description, PlantParams params, const SteadyScenario& scenario,
                           double settle = 4.0, double measure = 2.0);

}  // namespace harness
}  // namespace jackal_aic
