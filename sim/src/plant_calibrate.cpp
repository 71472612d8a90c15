/**
 * \file plant_calibrate.cpp
 * \brief plant_calibrate: run the stock controller on the ODE plant (faster than real
 *        time, no ROS) for velocity steps from rest and print settling and rise times
 *        beside the real Jackal's (thesis table 3-1b, shared/spec/jackal.md).
 *
 * What is compared and how (see jackal_sim/calibration.hpp): wheel-odometry body speed
 * r (omega_L + omega_R) / 2 from the 50 Hz joint states, as the robot's own estimate was;
 * metrics from jackal_aic::computeStepMetrics (rise 10-90 % of the step, settling into
 * +-5 % of the set point, from the set-point step). Ground truth is printed beside it.
 *
 * Usage: plant_calibrate [--urdf FILE] [--config FILE] [--set key=value]... [--csv FILE]
 *                        [--check]
 * --check exits 1 unless 0.5 and 1.0 m/s are within +-25 % and 0.1 m/s within +-50 % of
 * the robot's times and the rise time grows with the step.
 */

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "jackal_sim/calibration.hpp"
#include "jackal_sim/plant.hpp"
#include "jackal_sim/plant_params.hpp"
#include "jackal_sim/robot_description.hpp"

#ifndef JACKAL_SIM_SOURCE_DIR
#define JACKAL_SIM_SOURCE_DIR "."
#endif

using namespace jackal_aic::sim;

namespace
{
void usage()
{
  std::cerr << "usage: plant_calibrate [--urdf FILE] [--config FILE] [--set key=value]... [--csv FILE] [--check]\n";
}
}  // namespace

int main(int argc, char** argv)
{
  std::string urdf = std::string(JACKAL_SIM_SOURCE_DIR) + "/sim/urdf/jackal.urdf";
  std::string config = std::string(JACKAL_SIM_SOURCE_DIR) + "/sim/config/plant.yaml";
  std::string csv;
  std::vector<std::string> overrides;
  bool check = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc)
      {
        usage();
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--urdf")
      urdf = next();
    else if (a == "--config")
      config = next();
    else if (a == "--set")
      overrides.push_back(next());
    else if (a == "--csv")
      csv = next();
    else if (a == "--check")
      check = true;
    else
    {
      usage();
      return 2;
    }
  }
  RobotDescription desc;
  PlantParams params;
  try
  {
    desc = loadRobotDescription(urdf);
    params = loadPlantParams(config, overrides);
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_calibrate: " << e.what() << "\n";
    return 1;
  }
  std::printf("plant_calibrate: stock controller on the ODE plant, steps from rest\n");
  std::printf("  urdf %s\n  config %s\n", urdf.c_str(), config.c_str());
  for (const auto& o : overrides)
  {
    std::printf("  override %s\n", o.c_str());
  }
  std::printf("  measured: wheel-odometry speed r*(wL+wR)/2 from 50 Hz joint states (the robot's own estimate);\n"
              "  metrics: jackal_aic::computeStepMetrics, rise 10-90 %% of the step, settling into +-5 %% of the\n"
              "  set point, times from the set-point step\n\n");
  std::printf("%-6s | %-27s | %-27s | %-9s | %-20s\n", "step", "settling 5% [s]", "rise 10-90% [s]", "overshoot",
              "ground truth");
  std::printf("%-6s | %8s %8s %9s | %8s %8s %9s | %9s | %9s %10s\n", "[m/s]", "sim", "robot", "error", "sim",
              "robot", "error", "[%]", "settl [s]", "rise [s]");
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
      csv_out << row.step << "," << rec.time[k] << "," << rec.v_odom[k] << "," << rec.v_true[k] << ","
              << rec.command[k] << "\n";
    }
    const jackal_aic::StepMetrics m = stepMetricsOf(rec);
    const jackal_aic::StepMetrics g = stepMetricsOf(rec, true);
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
  return (check && !ok) ? 1 : 0;
}
