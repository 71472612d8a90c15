/**
 * \file plant_fit.cpp
 * \brief plant_fit: run every robot step response of sim/config/robot_steps.yaml (thesis
 *        tables 3-1b stock controller, 3-1a / 5-1 / 5-2 active inference controller) on the
 *        ODE plant, headless and faster than real time, and print the fit table: simulated
 *        settling and rise time beside the robot's, the error of each entry, each table's
 *        mean error and acceptance, and the identification cost.
 *
 * The AIC rows run the thesis-equivalent controller (config/thesis_equivalent.yaml) at each
 * row's belief and action rates, scheduled as the jackal_AIC node (jackal_sim/harness/closed_loop.hpp).
 * The plant's speed is measured from wheel odometry, as the robot's was.
 * Acceptance (doc/robot_data.md): stock entries within +-20 % (0.5, 1.0 m/s) and +-50 % (0.1 m/s);
 * each AIC table within 25 % mean |error|; the steady checks (turning in place at -10/+10 rad/s
 * the servo holds the wheel speeds; the stock controller reaches the 2.0 m/s top speed); and the
 * turning targets (jackal_sim/harness/identification.hpp: the stock controller's 1 rad/s turn in place
 * rises within 0.5 s and settles within 0.8 s, a 0.5 m/s + 0.5 rad/s arc's yaw rate settles
 * within 0.8 s), whose misses are added to the cost.
 *
 * Usage: plant_fit [--urdf FILE] [--config PLANT.yaml] [--overlay FILE]... [--set key=value]...
 *                  [--aic-config FILE] [--data FILE] [--tables ID,ID,...] [--json] [--check]
 * --overlay: a plant YAML with only the keys that differ (sim/config/variants/), applied after
 * --config and before --set; repeatable, later ones win.
 * --json prints one JSON object (entries, tables, cost) instead of the table: the interface
 * of scripts/plant_identify.py. --check exits 1 unless every table is accepted.
 * Exit 2 on bad arguments, 1 on unreadable or invalid files.
 */

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_sim/harness/identification.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
std::string fmtTime(double v)
{
  char buf[32];
  if (std::isfinite(v))
    std::snprintf(buf, sizeof(buf), "%.3f", v);
  else
    std::snprintf(buf, sizeof(buf), "   --");
  return buf;
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string aic_config = packageFile("config/thesis_equivalent.yaml");
  std::string data = packageFile("sim/config/robot_steps.yaml");
  std::set<std::string> only;
  bool json = false;
  bool check = false;
  std::vector<std::string> table_ids;
  CommandLine cl("plant_fit", "Every robot step response of the data file on the ODE plant (stock controller and the "
                              "thesis-equivalent AIC), headless: the fit table, or one JSON object with --json.");
  plant.addTo(&cl);
  cl.option("aic-config", &aic_config, "controller YAML of the AIC rows");
  cl.option("data", &data, "the robot's step tables");
  cl.list("tables", &table_ids, "table ids to run (default all)");
  cl.flag("json", &json, "print one JSON object (the interface of scripts/plant_identify.py)");
  cl.flag("check", &check, "exit 1 unless every table is accepted");
  cl.footer("Exit 2 on bad arguments, 1 on unreadable or invalid files.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  only.insert(table_ids.begin(), table_ids.end());

  RobotDescription desc;
  PlantParams params;
  params::NodeParams controller;
  std::vector<RobotStepTable> tables;
  try
  {
    desc = plant.description();
    params = plant.params();
    controller = loadNodeParamsFiles({ aic_config });  // the AIC and the node's keys (action_trigger, ...)
    for (const RobotStepTable& t : loadRobotStepTables(data))
    {
      if (only.empty() || only.count(t.id))
      {
        tables.push_back(t);
      }
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_fit: " << e.what() << "\n";
    return 1;
  }
  if (tables.empty())
  {
    std::cerr << "plant_fit: no table selected\n";
    return 2;
  }

  FitReport report;
  try
  {
    report = runFit(desc, params, controller, tables);
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_fit: " << e.what() << "\n";
    return 1;
  }
  const std::vector<FitEntry>& entries = report.entries;
  const std::vector<TableFit>& fits = report.fits;
  const SteadyChecks& steady = report.steady;
  const TurningChecks& turning = report.turning;
  const double cost = report.cost;
  const bool all_ok = report.accepted;

  if (json)
  {
    std::cout << "{\"cost\": " << base::jsonNumber(cost) << ", \"accepted\": " << (all_ok ? "true" : "false")
              << ", \"tables\": [";
    for (std::size_t i = 0; i < fits.size(); ++i)
    {
      std::cout << (i ? ", " : "") << "{\"id\": \"" << fits[i].id
                << "\", \"mean_abs_error\": " << base::jsonNumber(fits[i].mean_abs_error)
                << ", \"cost\": " << base::jsonNumber(fits[i].cost)
                << ", \"accepted\": " << (fits[i].accepted ? "true" : "false") << "}";
    }
    std::cout << "], \"steady\": {\"turn_hold_error\": " << base::jsonNumber(steady.turn_hold_error)
              << ", \"stock_turn_error\": " << base::jsonNumber(steady.stock_turn_error)
              << ", \"top_speed\": " << base::jsonNumber(steady.top_speed)
              << ", \"penalty\": " << base::jsonNumber(steady.penalty)
              << "}, \"turning\": {\"turn_rise\": " << base::jsonNumber(turning.turn.rise_time)
              << ", \"turn_settling\": " << base::jsonNumber(turning.turn.settling_time)
              << ", \"turn_truth_rise\": " << base::jsonNumber(turning.turn_truth.rise_time)
              << ", \"turn_truth_settling\": " << base::jsonNumber(turning.turn_truth.settling_time)
              << ", \"arc_settling\": " << base::jsonNumber(turning.arc.settling_time)
              << ", \"arc_truth_settling\": " << base::jsonNumber(turning.arc_truth.settling_time)
              << ", \"ok\": " << (turning.ok ? "true" : "false")
              << ", \"penalty\": " << base::jsonNumber(turning.penalty) << "}, \"entries\": [";
    for (std::size_t i = 0; i < entries.size(); ++i)
    {
      const FitEntry& e = entries[i];
      std::cout << (i ? ", " : "") << "{\"table\": \"" << e.table << "\", \"step\": " << base::jsonNumber(e.robot.step)
                << ", \"belief_rate\": " << base::jsonNumber(e.robot.belief_rate)
                << ", \"action_rate\": " << base::jsonNumber(e.robot.action_rate)
                << ", \"settling\": " << base::jsonNumber(e.sim.settling_time)
                << ", \"rise\": " << base::jsonNumber(e.sim.rise_time)
                << ", \"overshoot\": " << base::jsonNumber(e.sim.overshoot_percent)
                << ", \"robot_settling\": " << base::jsonNumber(e.robot.settling)
                << ", \"robot_rise\": " << base::jsonNumber(e.robot.rise)
                << ", \"settling_error\": " << base::jsonNumber(e.settling_error)
                << ", \"rise_error\": " << base::jsonNumber(e.rise_error) << ", \"runaways\": " << e.runaways << "}";
    }
    std::cout << "]}\n";
    return (check && !all_ok) ? 1 : 0;
  }

  std::printf("plant_fit: robot step responses on the ODE plant (wheel-odometry speed; rise 10-90 %%, settling "
              "+-5 %%)\n  urdf %s\n  plant %s\n  AIC %s\n  data %s\n",
              plant.urdf.c_str(), plant.config.c_str(), aic_config.c_str(), data.c_str());
  plant.printLayers();
  std::string current;
  for (const FitEntry& e : entries)
  {
    if (e.table != current)
    {
      current = e.table;
      for (const RobotStepTable& t : tables)
      {
        if (t.id == current)
        {
          std::printf("\n%s: %s (%s)\n", t.id.c_str(), t.title.c_str(), t.source.c_str());
        }
      }
      std::printf("%-6s %-6s %-6s | %-24s | %-24s | %s\n", "step", "belief", "action", "settling [s]", "rise [s]",
                  "overshoot");
      std::printf("%-6s %-6s %-6s | %7s %7s %8s | %7s %7s %8s | %s\n", "[m/s]", "[Hz]", "[Hz]", "sim", "robot", "error",
                  "sim", "robot", "error", "[%]");
    }
    std::printf("%-6.1f %-6.0f %-6.0f | %7s %7.2f %+7.0f%% | %7s %7.2f %+7.0f%% | %6.1f%s\n", e.robot.step,
                e.robot.belief_rate, e.robot.action_rate, fmtTime(e.sim.settling_time).c_str(), e.robot.settling,
                100.0 * e.settling_error, fmtTime(e.sim.rise_time).c_str(), e.robot.rise, 100.0 * e.rise_error,
                e.sim.overshoot_percent, e.runaways ? "  RUNAWAY" : "");
  }
  std::printf("\n%-6s | %-16s | %-9s | %s\n", "table", "mean |error| [%]", "cost", "accepted");
  for (const TableFit& f : fits)
  {
    std::printf("%-6s | %16.1f | %9.3f | %s\n", f.id.c_str(), 100.0 * f.mean_abs_error, f.cost,
                f.accepted ? "yes" : "NO");
  }
  std::printf("\nsteady checks: turning in place at 5 and 10 rad/s the servo holds the wheels within %.3f rad/s "
              "(accepted <= %.2f); the stock controller turns in place at 0.5 rad/s within %.0f %% (accepted <= "
              "10 %%): %s; stock controller at 2.0 m/s reaches %.3f m/s: %s; penalty %.3f\n",
              steady.turn_hold_error, kTurnHoldTolerance, 100.0 * steady.stock_turn_error, steady.turn_ok ? "ok" : "NO",
              steady.top_speed, steady.top_speed_ok ? "ok" : "NO", steady.penalty);
  std::printf("turning targets (stock controller, yaw rate from wheel odometry; gyro in brackets): 1 rad/s turn in "
              "place rise %s s [%s] (accepted <= %.2f), settling %s s [%s] (<= %.2f); 0.5 m/s + 0.5 rad/s arc "
              "settling %s s [%s] (<= %.2f): %s; penalty %.3f\n",
              fmtTime(turning.turn.rise_time).c_str(), fmtTime(turning.turn_truth.rise_time).c_str(), kTurnRiseTarget,
              fmtTime(turning.turn.settling_time).c_str(), fmtTime(turning.turn_truth.settling_time).c_str(),
              kTurnSettlingTarget, fmtTime(turning.arc.settling_time).c_str(),
              fmtTime(turning.arc_truth.settling_time).c_str(), kArcSettlingTarget, turning.ok ? "ok" : "NO",
              turning.penalty);
  std::printf("identification cost %.4f; acceptance (stock entries within 20 %% / 50 %% at 0.1 m/s, AIC tables "
              "within 25 %% mean, steady checks, turning targets): %s\n",
              cost, all_ok ? "PASS" : "FAIL");
  return (check && !all_ok) ? 1 : 0;
}
