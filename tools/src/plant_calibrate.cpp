/**
 * \file plant_calibrate.cpp
 * \brief plant_calibrate: run the stock controller on the ODE plant (faster than real
 *        time, no ROS) for velocity steps from rest and print settling and rise times
 *        beside the real Jackal's (thesis table 3-1b, doc/jackal.md).
 *
 * What is compared and how (see jackal_sim/harness/calibration.hpp): wheel-odometry body speed
 * r (omega_L + omega_R) / 2 from the 50 Hz joint states, as the robot's own estimate was;
 * metrics from jackal_aic::analysis::computeStepMetrics (rise 10-90 % of the step, settling into
 * +-5 % of the set point, from the set-point step). Ground truth is printed beside it.
 *
 * Usage: plant_calibrate [--urdf FILE] [--config FILE] [--overlay FILE]... [--set key=value]...
 *                        [--csv FILE] [--check]
 * --overlay: a plant YAML with only the keys that differ (sim/config/variants/), applied after
 * --config and before --set; repeatable, later ones win.
 * Then the steady-state checks (jackal_sim/harness/calibration.hpp): the top speed (the stock
 * controller commanding its 2.0 m/s limit, and the motor-limited speed with the wheel set
 * points at the MCU clamp) and the effective wheel separation r (wR - wL) / yaw rate in
 * steady turns in place and on an arc, beside the robot's b_hat = 0.5621 m.
 *
 * --check exits 1 unless 0.5 and 1.0 m/s are within +-25 % and 0.1 m/s within +-50 % of
 * the robot's times and the rise time grows with the step, the plant reaches 2.0 m/s with
 * a motor-limited top speed within 2.0-2.75 m/s, straight driving gives r omega within 5 %,
 * and every effective separation is within +-10 % of 0.5621 m.
 */

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_sim/harness/calibration.hpp"
#include "jackal_sim/plant/plant.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
constexpr double kSettle = 4.0;   // s from rest before the steady-state window
constexpr double kMeasure = 2.0;  // s, steady-state window

/// Top speed: the stock controller at its 2.0 m/s limit must reach it (odometry within
/// kTopSpeedTolerance, ground truth = r omega within kStraightSpeedTolerance), and the
/// motor-limited speed (wheel set points at the MCU clamp) must lie between the manual's
/// 2.0 m/s and the thesis's 2.5 m/s (+ kMotorTopSpeedTolerance).
bool printTopSpeed(const RobotDescription& desc, const PlantParams& params)
{
  std::printf("\ntop speed on flat ground, steady (means over %.0f-%.0f s from rest; odometry r*(wL+wR)/2)\n", kSettle,
              kSettle + kMeasure);
  std::printf("%-30s | %-15s | %-16s | %-19s | %-28s | %s\n", "scenario", "wheels [rad/s]", "speed [m/s]",
              "robot [m/s]", "accepted", "");
  std::printf("%-30s | %7s %7s | %7s %8s | %-19s | %-28s | %s\n", "", "left", "right", "odom", "true", "", "", "");
  bool ok = true;
  for (std::size_t i = 0; i < kTopSpeedScenarios.size(); ++i)
  {
    const SteadyScenario& sc = kTopSpeedScenarios[i];
    const SteadyDrive d = runSteadyDrive(desc, params, sc, kSettle, kMeasure);
    const bool straight = std::abs(d.v_true - d.v_odom) <= kStraightSpeedTolerance * std::abs(d.v_odom);
    bool row_ok = false;
    char robot[32];
    char band[64];
    if (sc.input == DriveInput::kStockTwist)
    {
      row_ok = d.v_odom >= (1.0 - kTopSpeedTolerance) * sc.a && straight;
      std::snprintf(robot, sizeof(robot), "%.1f (manual)", kRobotTopSpeed);
      std::snprintf(band, sizeof(band), "odom >= %.2f, |true-odom|<5%%", (1.0 - kTopSpeedTolerance) * sc.a);
    }
    else
    {
      const double hi = (1.0 + kMotorTopSpeedTolerance) * kThesisTopSpeed;
      row_ok = d.v_odom >= kRobotTopSpeed && d.v_odom <= hi && straight;
      std::snprintf(robot, sizeof(robot), "%.1f; thesis %.1f", kRobotTopSpeed, kThesisTopSpeed);
      std::snprintf(band, sizeof(band), "%.2f <= odom <= %.2f", kRobotTopSpeed, hi);
    }
    std::printf("%-30s | %7.2f %7.2f | %7.3f %8.3f | %-19s | %-28s | %s\n", sc.label, d.wheel_left, d.wheel_right,
                d.v_odom, d.v_true, robot, band, row_ok ? "ok" : "OUT");
    ok = ok && row_ok;
  }
  std::printf("acceptance (reaches 2.0 m/s; motor limit within 2.0-%.2f m/s; straight r*omega within 5 %%): %s\n",
              (1.0 + kMotorTopSpeedTolerance) * kThesisTopSpeed, ok ? "PASS" : "FAIL");
  return ok;
}

/// Effective wheel separation r (wR - wL) / yaw rate in steady turns, against the b_hat
/// identified on the robot (within kSeparationTolerance).
bool printSeparation(const RobotDescription& desc, const PlantParams& params)
{
  std::printf("\neffective wheel separation b = r*(wR-wL)/yaw rate, steady (means over %.0f-%.0f s; yaw rate: ground "
              "truth)\n",
              kSettle, kSettle + kMeasure);
  std::printf("%-30s | %-15s | %-18s | %-8s | %-27s | %s\n", "scenario", "wheels [rad/s]", "yaw rate [rad/s]", "speed",
              "separation b [m]", "");
  std::printf("%-30s | %7s %7s | %8s %9s | %8s | %8s %8s %9s | %s\n", "", "left", "right", "sim", "set pt", "[m/s]",
              "sim", "robot", "error", "");
  bool ok = true;
  for (const SteadyScenario& sc : kSeparationScenarios)
  {
    const SteadyDrive d = runSteadyDrive(desc, params, sc, kSettle, kMeasure);
    const double b = d.effectiveSeparation();
    const double err = (b - kRobotWheelSeparation) / kRobotWheelSeparation;
    const bool row_ok = std::isfinite(b) && std::abs(err) <= kSeparationTolerance;
    char set_point[16] = "-";
    if (sc.input == DriveInput::kStockTwist)
    {
      std::snprintf(set_point, sizeof(set_point), "%.3f", sc.b);
    }
    std::printf("%-30s | %7.2f %7.2f | %8.3f %9s | %8.3f | %8.3f %8.4f %+8.1f%% | %s\n", sc.label, d.wheel_left,
                d.wheel_right, d.yaw_rate, set_point, d.v_true, b, kRobotWheelSeparation, 100.0 * err,
                row_ok ? "ok" : "OUT");
    ok = ok && row_ok;
  }
  std::printf("acceptance (every b within %.0f %% of the robot's b_hat = %.4f m): %s\n", 100.0 * kSeparationTolerance,
              kRobotWheelSeparation, ok ? "PASS" : "FAIL");
  return ok;
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string csv;
  bool check = false;
  jackal_aic::CommandLine cl("plant_calibrate", "The stock controller on the ODE plant for velocity steps from rest, "
                                                "beside the real "
                                                "Jackal's settling and rise times (thesis table 3-1b), then the "
                                                "top-speed and "
                                                "wheel-separation checks.");
  plant.addTo(&cl);
  cl.option("csv", &csv, "write the step traces as CSV");
  cl.flag("check", &check, "exit 1 unless every acceptance band holds");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  RobotDescription desc;
  PlantParams params;
  try
  {
    desc = plant.description();
    params = plant.params();
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_calibrate: " << e.what() << "\n";
    return 1;
  }
  std::printf("plant_calibrate: stock controller on the ODE plant, steps from rest\n");
  std::printf("  urdf %s\n  config %s\n", plant.urdf.c_str(), plant.config.c_str());
  plant.printLayers();
  std::printf("  measured: wheel-odometry speed r*(wL+wR)/2 from 50 Hz joint states (the robot's own estimate);\n"
              "  metrics: jackal_aic::analysis::computeStepMetrics, rise 10-90 %% of the step, settling into +-5 %% of "
              "the\n"
              "  set point, times from the set-point step\n\n");
  std::printf("%-6s | %-27s | %-27s | %-9s | %-20s\n", "step", "settling 5% [s]", "rise 10-90% [s]", "overshoot",
              "ground truth");
  std::printf("%-6s | %8s %8s %9s | %8s %8s %9s | %9s | %9s %10s\n", "[m/s]", "sim", "robot", "error", "sim", "robot",
              "error", "[%]", "settl [s]", "rise [s]");
  std::ofstream csv_out;
  if (!csv.empty())
  {
    csv_out.open(csv);
    csv_out << "step,t,v_odom,v_true,cmd\n";
  }
  bool ok = true;
  double previous_rise = 0.0;
  for (const RobotStepReference& row : kRobotStepTable)
  {
    const StepRecord rec = runStockStep(desc, params, row.step);
    for (std::size_t k = 0; k < rec.time.size() && csv_out; ++k)
    {
      csv_out << row.step << "," << rec.time[k] << "," << rec.v_odom[k] << "," << rec.v_true[k] << "," << rec.command[k]
              << "\n";
    }
    const jackal_aic::analysis::StepMetrics m = stepMetricsOf(rec);
    const jackal_aic::analysis::StepMetrics g = stepMetricsOf(rec, true);
    const double es = (m.settling_time - row.settling) / row.settling;
    const double er = (m.rise_time - row.rise) / row.rise;
    std::printf("%-6.1f | %8.3f %8.2f %+8.0f%% | %8.3f %8.2f %+8.0f%% | %9.1f | %9.3f %10.3f\n", row.step,
                m.settling_time, row.settling, 100.0 * es, m.rise_time, row.rise, 100.0 * er, m.overshoot_percent,
                g.settling_time, g.rise_time);
    const bool row_ok = std::abs(es) <= row.tolerance && std::abs(er) <= row.tolerance && m.rise_time > previous_rise;
    ok = ok && row_ok;
    previous_rise = m.rise_time;
  }
  std::printf("\nacceptance (0.5, 1.0 m/s within 25 %%, 0.1 m/s within 50 %%, rise grows with step): %s\n",
              ok ? "PASS" : "FAIL");
  const bool steps_ok = ok;
  const bool top_ok = printTopSpeed(desc, params);
  const bool separation_ok = printSeparation(desc, params);
  ok = steps_ok && top_ok && separation_ok;
  std::printf("\noverall: steps %s, top speed %s, effective separation %s -> %s\n", steps_ok ? "PASS" : "FAIL",
              top_ok ? "PASS" : "FAIL", separation_ok ? "PASS" : "FAIL", ok ? "PASS" : "FAIL");
  return (check && !ok) ? 1 : 0;
}
