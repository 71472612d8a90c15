#include "jackal_sim/harness/identification.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "jackal_sim/harness/calibration.hpp"

namespace jackal_aic
{
namespace harness
{
using namespace plant;  // the plant this part drives

std::vector<RobotStepTable> loadRobotStepTables(const std::string& path)
{
  YAML::Node root;
  try
  {
    root = YAML::LoadFile(path);
  }
  catch (const YAML::Exception& e)
  {
    throw std::runtime_error(path + ": " + e.what());
  }
  const YAML::Node list = root["tables"];
  if (!list || !list.IsSequence() || list.size() == 0)
  {
    throw std::runtime_error(path + ": expected a non-empty list 'tables'");
  }
  std::vector<RobotStepTable> out;
  for (std::size_t i = 0; i < list.size(); ++i)
  {
    const YAML::Node t = list[i];
    RobotStepTable table;
    const std::string where = path + ": table " + std::to_string(i);
    try
    {
      table.id = t["id"].as<std::string>();
      table.title = t["title"].as<std::string>();
      table.source = t["source"].as<std::string>();
      const std::string controller = t["controller"].as<std::string>();
      if (controller == "stock")
        table.controller = LoopController::kStock;
      else if (controller == "aic")
        table.controller = LoopController::kAic;
      else
        throw std::runtime_error(where + ": controller '" + controller + "' (allowed: stock, aic)");
      const YAML::Node rows = t["rows"];
      if (!rows || !rows.IsSequence() || rows.size() == 0)
      {
        throw std::runtime_error(where + " (" + table.id + "): expected a non-empty list 'rows'");
      }
      for (std::size_t k = 0; k < rows.size(); ++k)
      {
        const std::vector<double> v = rows[k].as<std::vector<double>>();
        bool ok = v.size() == 5;
        for (double x : v)
        {
          ok = ok && std::isfinite(x) && x > 0.0;
        }
        if (!ok)
        {
          throw std::runtime_error(where + " (" + table.id + "), row " + std::to_string(k) +
                                   ": expected 5 positive numbers [step, belief_rate, action_rate, settling, rise]");
        }
        table.rows.push_back({ v[0], v[1], v[2], v[3], v[4] });
      }
    }
    catch (const YAML::Exception& e)
    {
      throw std::runtime_error(where + ": " + e.what() + " (keys: id, title, source, controller, rows)");
    }
    out.push_back(table);
  }
  return out;
}

namespace
{
double relativeError(double sim, double robot)
{
  return std::isfinite(sim) ? (sim - robot) / robot : kUnsettledError;
}

/// One identification run with `config`'s controller: rest, then the step to (linear [m/s],
/// angular [rad/s]) kIdentStepPhase after a 50 Hz tick, recorded for kIdentRecord; ideal sensors.
/// *options gets the step metrics' options for a step of the given target.
ClosedLoopRecord runIdentStep(const RobotDescription& description, const PlantParams& params, ClosedLoopConfig config,
                              double linear, double angular, double target, analysis::StepMetricsOptions* options)
{
  const double t_step = kIdentRest + kIdentStepPhase;
  config.profile = stepProfile(t_step, linear, angular);
  config.duration = t_step + kIdentRecord;
  config.ideal_sensors = true;
  options->step_time = t_step;
  options->initial = 0.0;
  options->target = target;
  return runClosedLoop(description, params, config);
}
}  // namespace

FitEntry runFitEntry(const RobotDescription& description, const PlantParams& params,
                     const params::NodeParams& controller, const RobotStepTable& table, const RobotStepRow& row)
{
  ClosedLoopConfig config;
  config.controller = table.controller;
  config.node = controller;
  config.aic = controller.aic;
  config.aic.belief_rate = row.belief_rate;
  config.aic.action_rate = row.action_rate;
  analysis::StepMetricsOptions o;
  const ClosedLoopRecord rec = runIdentStep(description, params, config, row.step, 0.0, row.step, &o);
  FitEntry e;
  e.sim = analysis::computeStepMetrics(rec.time, rec.v_odom, o);
  e.runaways = rec.runaways;
  return rescoreFitEntry(e, table, row);
}

std::vector<FitEntry> runFitEntries(const RobotDescription& description, const PlantParams& params,
                                    const params::NodeParams& controller, const std::vector<RobotStepTable>& tables)
{
  std::vector<FitEntry> entries;
  for (const RobotStepTable& t : tables)
  {
    const bool stock = t.controller == LoopController::kStock;
    for (const RobotStepRow& row : t.rows)
    {
      const FitEntry* same = nullptr;
      for (const FitEntry& d : entries)
      {
        const bool d_stock = d.table_controller == LoopController::kStock;
        if (d_stock == stock && d.robot.step == row.step &&
            (stock || (d.robot.belief_rate == row.belief_rate && d.robot.action_rate == row.action_rate)))
        {
          same = &d;
        }
      }
      entries.push_back(same ? rescoreFitEntry(*same, t, row) : runFitEntry(description, params, controller, t, row));
    }
  }
  return entries;
}

FitEntry rescoreFitEntry(const FitEntry& run, const RobotStepTable& table, const RobotStepRow& row)
{
  FitEntry e = run;
  e.table = table.id;
  e.table_controller = table.controller;
  e.robot = row;
  e.settling_error = relativeError(e.sim.settling_time, row.settling);
  e.rise_error = relativeError(e.sim.rise_time, row.rise);
  return e;
}

double stockTolerance(double step)
{
  return step < 0.3 ? 0.5 : 0.2;
}

std::vector<TableFit> summarizeFit(const std::vector<RobotStepTable>& tables, const std::vector<FitEntry>& entries)
{
  std::vector<TableFit> out;
  for (const RobotStepTable& t : tables)
  {
    TableFit f;
    f.id = t.id;
    int n = 0;
    bool all_within = true;
    double hinge = 0.0;
    for (const FitEntry& e : entries)
    {
      if (e.table != t.id)
      {
        continue;
      }
      const double tol = t.controller == LoopController::kStock ? stockTolerance(e.robot.step) : kAicTableTolerance;
      for (double err : { e.settling_error, e.rise_error })
      {
        f.mean_abs_error += std::abs(err);
        f.cost += (err / tol) * (err / tol);
        all_within = all_within && std::abs(err) <= tol;
        const double miss = std::max(0.0, std::abs(err) / tol - 1.0);
        hinge += miss * miss;
        ++n;
      }
    }
    if (n > 0)
    {
      f.mean_abs_error /= n;
      f.cost /= n;
    }
    if (t.controller == LoopController::kStock)
    {
      f.cost += kAcceptanceWeight * hinge;  // every stock entry must be within its band
    }
    else
    {
      const double miss = std::max(0.0, f.mean_abs_error / kAicTableTolerance - 1.0);
      f.cost += kAcceptanceWeight * miss * miss;  // the table's mean must be within 25 %
    }
    f.accepted =
        n > 0 && (t.controller == LoopController::kStock ? all_within : f.mean_abs_error <= kAicTableTolerance);
    out.push_back(f);
  }
  return out;
}

SteadyChecks runSteadyChecks(const RobotDescription& description, const PlantParams& params)
{
  SteadyChecks c;
  for (int i : { 0, 1 })  // in place, wheels -5/+5 and -10/+10 rad/s
  {
    const SteadyScenario& turn = kSeparationScenarios[i];
    const SteadyDrive t = runSteadyDrive(description, params, turn);
    c.turn_hold_error =
        std::max(c.turn_hold_error, std::max(std::abs(t.wheel_left - turn.a), std::abs(t.wheel_right - turn.b)));
  }
  const SteadyScenario& stock_turn = kSeparationScenarios[2];  // stock controller, in place at 0.5 rad/s
  const SteadyDrive st = runSteadyDrive(description, params, stock_turn);
  c.stock_turn_error = std::abs(st.yaw_rate - stock_turn.b) / stock_turn.b;
  c.turn_ok = c.turn_hold_error <= kTurnHoldTolerance && c.stock_turn_error <= kSeparationTolerance;
  const SteadyDrive top = runSteadyDrive(description, params, kTopSpeedScenarios[0]);
  c.top_speed = top.v_odom;
  const double top_min = (1.0 - kTopSpeedTolerance) * kRobotTopSpeed;
  c.top_speed_ok = c.top_speed >= top_min;
  const double hold_miss = std::max(0.0, c.turn_hold_error - kTurnHoldTolerance) / kTurnHoldTolerance;
  const double stock_miss = std::max(0.0, c.stock_turn_error - kSeparationTolerance) / kSeparationTolerance;
  const double turn_miss = std::sqrt(hold_miss * hold_miss + stock_miss * stock_miss);
  const double top_miss = std::max(0.0, top_min - c.top_speed) / (kTopSpeedTolerance * kRobotTopSpeed);
  c.penalty = turn_miss * turn_miss + top_miss * top_miss + (c.turn_ok && c.top_speed_ok ? 0.0 : 1.0);
  return c;
}

TurningChecks runTurningChecks(const RobotDescription& description, const PlantParams& params)
{
  auto run = [&](double linear, double angular, analysis::StepMetrics* odom, analysis::StepMetrics* truth) {
    ClosedLoopConfig config;
    config.controller = LoopController::kStock;
    analysis::StepMetricsOptions o;
    const ClosedLoopRecord rec = runIdentStep(description, params, config, linear, angular, angular, &o);
    *odom = analysis::computeStepMetrics(rec.time, rec.yaw_odom, o);
    *truth = analysis::computeStepMetrics(rec.time, rec.yaw_true, o);
  };
  TurningChecks c;
  run(0.0, kTurnStep, &c.turn, &c.turn_truth);
  run(kArcLinear, kArcAngular, &c.arc, &c.arc_truth);
  double penalty = 0.0;
  bool ok = true;
  for (const auto& [value, target] : { std::pair<double, double>{ c.turn.rise_time, kTurnRiseTarget },
                                       { c.turn.settling_time, kTurnSettlingTarget },
                                       { c.arc.settling_time, kArcSettlingTarget } })
  {
    const double miss = std::isfinite(value) ? std::max(0.0, value / target - 1.0) : kUnsettledError;
    penalty += miss * miss;
    ok = ok && std::isfinite(value) && value <= target;
  }
  c.ok = ok;
  c.penalty = kAcceptanceWeight * penalty;
  return c;
}

double fitCost(const std::vector<TableFit>& fits)
{
  double c = 0.0;
  for (const TableFit& f : fits)
  {
    c += f.cost;
  }
  return c;
}

FitReport runFit(const RobotDescription& description, const PlantParams& params, const params::NodeParams& controller,
                 const std::vector<RobotStepTable>& tables)
{
  FitReport r;
  r.entries = runFitEntries(description, params, controller, tables);
  r.fits = summarizeFit(tables, r.entries);
  r.steady = runSteadyChecks(description, params);
  r.turning = runTurningChecks(description, params);
  r.cost = fitCost(r.fits) + r.steady.penalty + r.turning.penalty;
  r.accepted = r.steady.turn_ok && r.steady.top_speed_ok && r.turning.ok;
  for (const TableFit& f : r.fits)
  {
    r.accepted = r.accepted && f.accepted;
  }
  return r;
}

}  // namespace harness
}  // namespace jackal_aic
