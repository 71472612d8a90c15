#pragma once
/**
 * \file calibration.hpp
 * \brief Step responses of the stock controller on the plant, compared with the real
 *        Jackal's (thesis table 3-1b, shared/spec/jackal.md). ROS-free; used by the
 *        plant_calibrate tool and by the calibration gtest.
 *
 * What is compared: the robot's table was measured from the robot's own velocity estimate,
 * which rests on wheel odometry. The plant is therefore measured the same way: body speed
 * v = r (omega_L + omega_R) / 2 from the 50 Hz joint-state samples (noise, bias and dropout
 * switched off so the numbers are reproducible). Ground truth is recorded beside it.
 * Metrics: jackal_aic::computeStepMetrics (the project's one implementation): rise time
 * 10-90 % of the step, settling time into +-5 % of the set point, both from the moment the
 * set point changes.
 */

#include <array>
#include <vector>

#include "jackal_aic/step_metrics.hpp"
#include "jackal_sim/plant_params.hpp"
#include "jackal_sim/robot_description.hpp"

namespace jackal_aic
{
namespace sim
{
/// One row of the robot's table, with the acceptance band of issue 4.
struct RobotStepReference
{
  double step;       ///< set-point step from rest [m/s]
  double settling;   ///< settling time (5 %) on the robot [s]
  double rise;       ///< rise time (10-90 %) on the robot [s]
  double tolerance;  ///< accepted relative error of the plant [-]
};

/// Thesis table 3-1b: 0.1, 0.5, 1.0 m/s (accepted within 50 %, 25 %, 25 %).
constexpr std::array<RobotStepReference, 3> kRobotStepTable{ { { 0.1, 0.14, 0.04, 0.50 },
                                                                { 0.5, 0.54, 0.35, 0.25 },
                                                                { 1.0, 1.05, 0.62, 0.25 } } };

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
StepMetrics stepMetricsOf(const StepRecord& record, bool ground_truth = false);

}  // namespace sim
}  // namespace jackal_aic
