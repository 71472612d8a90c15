/**
 * \file plant_turning.cpp
 * \brief plant_turning: how the simulated Jackal turns. The stock controller drives constant
 *        twists from rest (turns in place and a grid of steady arcs, speed x yaw rate) on the plant,
 *        headless and faster than real time (jackal_sim/harness/turning.hpp), for the default plant
 *        and each variant given; prints per run the steady speed and yaw rate (ground truth, the
 *        noise-free gyro), the effective wheel separation r (w_R - w_L) / yaw rate over the track,
 *        the time to reach 95 % of the command and the side torques, or the grid as Markdown tables
 *        (doc/robot_data.md, 'Turning').
 *
 * Usage: plant_turning [--config PLANT.yaml] [--overlay FILE]... [--set key=value]... [--urdf FILE]
 *            [--variant FILE]... [--speeds LIST] [--yaw-rates LIST] [--in-place LIST]
 *            [--case V,W]... [--markdown] [--check]
 *   --variant FILE   also run the plant with this overlay (after --overlay); repeatable. The plant
 *                    without a --variant is always run first, labelled "default".
 *   --case V,W       run these twists (a speed [m/s] and a yaw rate [rad/s]) instead of the grid
 *   --markdown       Markdown tables (one per plant: rows speeds, columns yaw rates; cells
 *                    "b / track" and, when the steady run misses the command by more than 5 %,
 *                    the ratio of the steady yaw rate (and speed) to the command)
 *   --check          exit 1 unless every run that turns (steady yaw rate >= 0.05 rad/s) has its
 *                    effective separation in [1.0, 1.6] x track (the Jackal's band: Clearpath's
 *                    multiplier 1.5, a J100 that tracked with ~1.0); "followed" is printed, not checked
 * Exit 0 on success, 1 on bad files or parameters (or a failed --check), 2 on bad arguments.
 * Each run: 0.5 s at rest, then the twist for 6 s; steady values are the means of its last 2.5 s
 * (jackal_sim/harness/turning.hpp).
 */

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "jackal_sim/harness/turning.hpp"
#include "jackal_tools/cli.hpp"
#include "jackal_tools/plant_cli.hpp"

using namespace jackal_aic;
using namespace jackal_aic::harness;

namespace
{
/// The separation band of a Jackal [x track]: Clearpath's multiplier 1.5 (jackal_control control.yaml,
/// b_hat = 0.5621 m identified on the robot) and a J100 that tracked with ~1.0 (clearpath_robot #280).
constexpr double kMinSeparation = 1.0;
constexpr double kMaxSeparation = 1.6;
/// A run "turns" when its steady yaw rate is at least this [rad/s] (the separation is defined).
constexpr double kTurning = 0.05;

double trackOf(const plant::RobotDescription& d)
{
  return std::abs(d.wheels[plant::kFrontLeft].origin.translation().y() -
                  d.wheels[plant::kFrontRight].origin.translation().y());
}

std::string basename(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.rfind(".yaml");
  return dot == std::string::npos ? name : name.substr(0, dot);
}

/// b / track with two decimals, "--" when undefined (the robot does not turn).
std::string number(double b)
{
  if (!std::isfinite(b))
  {
    return "--";
  }
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", b);
  return buf;
}

/// A Markdown cell: b / track, and the steady ratios when the run misses the command.
std::string cell(const TwistRun& r, double track)
{
  char buf[96];
  const double b = r.separation() / track;
  if (r.followed)
  {
    std::snprintf(buf, sizeof(buf), "%.2f", b);
  }
  else if (r.linear == 0.0)
  {
    std::snprintf(buf, sizeof(buf), "%s (yaw %.2f)", number(b).c_str(), r.yaw_rate / r.angular);
  }
  else
  {
    std::snprintf(buf, sizeof(buf), "%s (yaw %.2f, v %.2f)", number(b).c_str(), r.yaw_rate / r.angular,
                  r.v_true / r.linear);
  }
  return buf;
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant_options;
  std::vector<std::string> variants;
  TurningGrid grid;
  std::vector<std::string> cases;
  bool markdown = false;
  bool check = false;
  CommandLine cl("plant_turning", "How the simulated Jackal turns: the stock controller's turns in place and steady "
                                  "arcs from rest, "
                                  "with the steady speed and yaw rate, the effective wheel separation and the time to "
                                  "95 %.");
  plant_options.addTo(&cl);
  cl.repeated("variant", &variants, "also run the plant with this overlay (after --overlay)");
  cl.list("speeds", &grid.speeds, "forward speeds of the arcs [m/s]");
  cl.list("yaw-rates", &grid.yaw_rates, "yaw rates of the arcs [rad/s]");
  cl.list("in-place", &grid.in_place, "yaw rates of the turns in place [rad/s]");
  cl.repeated("case", &cases, "V,W: run this twist (speed [m/s], yaw rate [rad/s]) instead of the grid");
  cl.flag("markdown", &markdown, "Markdown tables of the grid, one per plant");
  cl.flag("check", &check,
          "exit 1 unless every run that turns (steady yaw rate >= 0.05 rad/s) has a separation in [1.0, 1.6] x track");
  cl.footer("Exit 0 on success, 1 on bad files or parameters (or a failed --check), 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  std::vector<std::pair<double, double>> twists;
  for (const std::string& c : cases)
  {
    double v = 0.0;
    double w = 0.0;
    char extra = 0;
    if (std::sscanf(c.c_str(), "%lf,%lf%c", &v, &w, &extra) != 2 || !std::isfinite(v) || !std::isfinite(w))
    {
      return cl.bad("--case '" + c + "': expected V,W (two finite numbers)");
    }
    twists.emplace_back(v, w);
  }
  if (markdown && !twists.empty())
  {
    return cl.bad("--markdown prints the grid: not with --case");
  }

  struct Layer
  {
    std::string label;
    std::vector<std::string> overlays;
  };
  std::vector<Layer> layers{ { "default", plant_options.overlays } };
  for (const std::string& v : variants)
  {
    Layer l{ basename(v), plant_options.overlays };
    l.overlays.push_back(v);
    layers.push_back(l);
  }

  plant::RobotDescription description;
  try
  {
    description = plant_options.description();
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_turning: " << e.what() << "\n";
    return 1;
  }
  const double track = trackOf(description);
  bool ok = true;
  for (const Layer& layer : layers)
  {
    plant::PlantParams params;
    std::vector<TwistRun> runs;
    try
    {
      params =
          plant::loadPlantParams(plant_options.config, plant::plantOverrides(layer.overlays, plant_options.overrides));
      if (twists.empty())
      {
        runs = runTurningGrid(description, params, grid);
      }
      else
      {
        for (const auto& [v, w] : twists)
        {
          runs.push_back(runStockTwist(description, params, v, w));
        }
      }
    }
    catch (const std::exception& e)
    {
      std::cerr << "plant_turning: " << layer.label << ": " << e.what() << "\n";
      return 1;
    }
    for (const TwistRun& r : runs)
    {
      const double b = r.separation() / track;
      if (std::abs(r.yaw_rate) >= kTurning && !(b >= kMinSeparation && b <= kMaxSeparation))
      {
        ok = false;
      }
    }
    if (markdown)
    {
      std::printf("\n**%s** (b / track; a run that misses the command by more than 5 %% gives the steady ratio "
                  "to the command)\n\n| turn in place [rad/s] |",
                  layer.label.c_str());
      for (double w : grid.in_place)
      {
        std::printf(" %g |", w);
      }
      std::printf("\n|---|");
      for (std::size_t j = 0; j < grid.in_place.size(); ++j)
      {
        std::printf("---|");
      }
      std::printf("\n| |");
      for (std::size_t i = 0; i < grid.in_place.size(); ++i)
      {
        std::printf(" %s |", cell(runs[i], track).c_str());
      }
      std::printf("\n\n| arc: speed [m/s] \\ yaw rate [rad/s] |");
      for (double w : grid.yaw_rates)
      {
        std::printf(" %g |", w);
      }
      std::printf("\n|---|");
      for (std::size_t j = 0; j < grid.yaw_rates.size(); ++j)
      {
        std::printf("---|");
      }
      std::printf("\n");
      std::size_t k = grid.in_place.size();
      for (double v : grid.speeds)
      {
        std::printf("| %g |", v);
        for (std::size_t j = 0; j < grid.yaw_rates.size(); ++j)
        {
          std::printf(" %s |", cell(runs[k++], track).c_str());
        }
        std::printf("\n");
      }
      continue;
    }
    std::printf("%s (track %.4f m)\n", layer.label.c_str(), track);
    std::printf("  command v [m/s] w [rad/s] | steady v [m/s]  w [rad/s] | b / track | t95 [s] | torque L / R [N m] | "
                "followed\n");
    for (const TwistRun& r : runs)
    {
      std::printf("  %15.2f %9.2f | %14.3f %10.3f | %9.3f | %7.3f | %8.2f / %5.2f | %s\n", r.linear, r.angular,
                  r.v_true, r.yaw_rate, r.separation() / track, r.reach_time, r.torque_left, r.torque_right,
                  r.followed ? "yes" : "NO");
    }
  }
  if (check)
  {
    std::printf("%scheck (every run that turns: b in [%.1f, %.1f] x track): %s\n", markdown ? "\n" : "", kMinSeparation,
                kMaxSeparation, ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
  }
  return 0;
}
