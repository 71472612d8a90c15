/**
 * \file jackal_node_sweep.cpp
 * \brief jackal_node_sweep: jackal_node's re-sampled joint states (jackal_sim/plant/jackal_node_sampler.hpp)
 *        swept through one period of the phase between its loop and the MCU's samples, on the
 *        headless closed loop (simulated time, seeded): what the re-sampling does to the joint
 *        states and to the stock odometry, and what it costs the AIC.
 *
 * Usage: jackal_node_sweep [--part resample|aic|all] [--phases N] [--drift PPM] [--jitter S]
 *            [--stall-probability P] [--seed N] [--case NAME] [--verbose] [--aic-config FILE] [--aic-set key=value]...
 *            [--config PLANT.yaml] [--overlay FILE]... [--set key=value]... [--urdf FILE]
 * --part resample: per phase, the stock controller's 0.5 m/s step from rest: share of repeated
 *   joint states [%], the longest run of consecutive repeats (run) and the longest time one MCU
 *   sample's data stayed in the messages (held_ms: what include/jackal_aic/safety/frozen_joint_states.hpp
 *   must tolerate), their ages (min, max [ms]), MCU samples never published, catch-up cycles, and
 *   diff_drive_controller's odometry (jackal_sim/harness/diff_drive_odometry.hpp) on that step:
 *   overshoot [%] and settling (5 %) [s], beside the same odometry on the clean samples.
 * --part aic: the AIC on clean samples, then at every phase: the steps of the scorecard (0.1, 0.5,
 *   1.0 m/s from rest; the 1 rad/s turn; the 0.5 m/s + 0.5 rad/s arc, speed and yaw): settling of the
 *   ground truth [s]; the six profiles of sim/profiles: RMS error of the ground truth's vx [m/s] and
 *   wz [rad/s]; each phase's figure as a ratio to the clean one, and over the sweep the worst ratio,
 *   runaways, fault-monitor events, dropped inputs by reason and joint states paired without an IMU.
 * Each phase p of N is phase = p / N / 50 s. Exit 0 on success, 1 on bad files or parameters, 2 on
 * bad arguments.
 */

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_aic/analysis/tracking_error.hpp"
#include "jackal_aic/analysis/twist_profile.hpp"
#include "jackal_aic/safety/frozen_joint_states.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_tools/share_path.hpp"

using namespace jackal_aic;
using namespace jackal_aic::harness;

namespace
{
constexpr double kRest = 1.0;      ///< rest before a step or profile [s]
constexpr double kHold = 5.0;      ///< a step's hold [s]
constexpr double kMcuRate = 50.0;  ///< the MCU's feedback rate [Hz] (the sensor model's)

/// Step metrics of y against a step at kRest + 10 ms (the set point's first sample) from 0 to target.
analysis::StepMetrics stepOf(const ClosedLoopRecord& r, const std::vector<double>& y, double target)
{
  analysis::StepMetricsOptions o;
  o.step_time = kRest;
  o.initial = 0.0;
  o.target = target;
  return analysis::computeStepMetrics(r.time, y, o);
}

/// One case of the AIC's sweep: a step (channel 0 speed, 1 yaw) or a profile.
struct Case
{
  std::string name;
  std::vector<SetPointSegment> segments;
  double duration = 0.0;
  int channel = 0;       ///< step: 0 speed, 1 yaw
  double target = 0.0;   ///< step: the channel's set point
  bool profile = false;  ///< true: RMS tracking of `tracked`
  analysis::TwistProfile tracked;
};

/// The case's figures of a run: settling [s] for a step; RMS vx [m/s], RMS wz [rad/s] for a profile.
std::vector<double> figures(const Case& c, const ClosedLoopRecord& r)
{
  if (!c.profile)
  {
    const analysis::StepMetrics m = stepOf(r, c.channel == 0 ? r.v_true : r.yaw_true, c.target);
    return { m.settling_time };
  }
  std::vector<double> t;
  for (double x : r.time)
  {
    t.push_back(x - kRest);
  }
  const analysis::VelocityTrackingError e = analysis::velocityTrackingError(c.tracked, t, r.v_true, r.yaw_true);
  return { e.vx.rms, e.wz.rms };
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string part = "all";
  int phases = 20;
  double drift = 0.0;
  double jitter = plant::JackalNodeSamplerParams().jitter_std;
  double stall = 0.0;
  int seed = 1;
  std::string aic_config = packageFile("config/default.yaml");
  std::vector<std::string> aic_overrides;
  std::string only;
  bool verbose = false;
  CommandLine cl("jackal_node_sweep", "jackal_node's re-sampled joint states through one period of the phase against "
                                      "the MCU, on the "
                                      "headless closed loop: repeats, ages, the stock odometry, and the AIC against "
                                      "clean samples.");
  plant.addTo(&cl);
  cl.option("part", &part, "resample | aic | all");
  cl.option("phases", &phases, "phases through one 20 ms period, 1..100");
  cl.option("drift", &drift, "the loop clock's rate error against the MCU's [ppm], |drift| <= 1e4");
  cl.option("jitter", &jitter, "the loop's wake-up latency |N(0, S)| [s], in [0, 0.005]");
  cl.option("stall-probability", &stall, "share of cycles that stall up to 30 ms (catch-up cycles), in [0, 1]");
  cl.option("seed", &seed, "seed of the latency draws, >= 0");
  cl.option("case", &only, "--part aic: only the case of this name (e.g. \"step 0.1 m/s\", creep)");
  cl.flag("verbose", &verbose, "--part aic: every phase's figures, repeats and ages too");
  cl.option("aic-config", &aic_config, "controller YAML (controller and node keys)");
  cl.overrides("aic-set", &aic_overrides, "override a controller or node key");
  cl.footer("Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (part != "resample" && part != "aic" && part != "all")
  {
    return cl.bad("--part must be resample, aic or all");
  }
  if (phases < 1 || phases > 100 || seed < 0)
  {
    return cl.bad("--phases must be in [1, 100] and --seed >= 0");
  }
  plant::JackalNodeSamplerParams sp;
  sp.drift = drift;
  sp.jitter_std = jitter;
  sp.stall_probability = stall;
  sp.seed = static_cast<std::uint32_t>(seed);
  if (const auto v = sp.validate(); !v.empty())
  {
    return cl.bad("invalid re-sampler: " + v.front());
  }

  RobotDescription desc;
  PlantParams params;
  params::NodeParams node;
  try
  {
    desc = plant.description();
    params = plant.params();
    node = loadNodeParamsFiles({ aic_config }, aic_overrides);
  }
  catch (const std::exception& e)
  {
    std::cerr << "jackal_node_sweep: " << e.what() << "\n";
    return 1;
  }
  auto phaseOf = [&](int p) { return static_cast<double>(p) / static_cast<double>(phases) / kMcuRate; };

  try
  {
    if (part != "aic")
    {
      ClosedLoopConfig c;
      c.controller = LoopController::kStock;
      c.profile = stepProfile(kRest, 0.5);
      c.duration = kRest + kHold;
      const ClosedLoopRecord clean = runClosedLoop(desc, params, c);
      const analysis::StepMetrics mc = stepOf(clean, clean.v_diff_drive, 0.5);
      std::printf("Re-sampled joint states, stock controller, 0.5 m/s step (drift %g ppm, jitter %g ms, stall %g)\n",
                  drift, 1e3 * jitter, stall);
      std::printf("clean samples: diff-drive odometry overshoot %.1f %%, settling %.3f s\n", mc.overshoot_percent,
                  mc.settling_time);
      std::printf("%9s %9s %6s %8s %8s %8s %7s %8s %10s %9s\n", "phase_ms", "repeat_%", "run", "held_ms", "age_min",
                  "age_max", "skipped", "catch_up", "odom_os_%", "odom_ts");
      std::uint64_t run = 0;
      double held = 0.0;
      for (int p = 0; p < phases; ++p)
      {
        c.jackal_node = true;
        c.jackal_node_sampler = sp;
        c.jackal_node_sampler.phase = phaseOf(p);
        const ClosedLoopRecord r = runClosedLoop(desc, params, c);
        const analysis::StepMetrics m = stepOf(r, r.v_diff_drive, 0.5);
        const auto& s = r.jackal_node_stats;
        std::printf("%9.1f %9.2f %6lu %8.1f %8.1f %8.1f %7lu %8lu %10.1f %9.3f\n", 1e3 * phaseOf(p),
                    100.0 * s.repeatRate(), static_cast<unsigned long>(s.max_repeat_run), 1e3 * s.max_held,
                    1e3 * s.min_age, 1e3 * s.max_age, static_cast<unsigned long>(s.skipped),
                    static_cast<unsigned long>(s.catch_up), m.overshoot_percent, m.settling_time);
        run = std::max(run, s.max_repeat_run);
        held = std::max(held, s.max_held);
      }
      std::printf("over the sweep: the longest run of repeats %lu, the longest any data stayed %.1f ms (a frozen MCU "
                  "reads as frozen after %.0f ms)\n",
                  static_cast<unsigned long>(run), 1e3 * held, 1e3 * safety::kFrozenJointStateTime);
    }
    if (part != "resample")
    {
      std::vector<Case> cases;
      for (double v : { 0.1, 0.5, 1.0 })
      {
        Case k;
        k.name = "step " + std::to_string(v).substr(0, 3) + " m/s";
        k.segments = stepProfile(kRest, v);
        k.duration = kRest + kHold;
        k.target = v;
        cases.push_back(k);
      }
      {
        Case k;
        k.name = "turn 1 rad/s";
        k.segments = stepProfile(kRest, 0.0, 1.0);
        k.duration = kRest + kHold;
        k.channel = 1;
        k.target = 1.0;
        cases.push_back(k);
        k.name = "arc, speed";
        k.segments = stepProfile(kRest, 0.5, 0.5);
        k.channel = 0;
        k.target = 0.5;
        cases.push_back(k);
        k.name = "arc, yaw";
        k.channel = 1;
        cases.push_back(k);
      }
      for (const char* name : { "creep", "fast", "planner_10hz", "s_curves", "stop_and_go", "teleop_joystick" })
      {
        Case k;
        k.name = name;
        k.profile = true;
        k.tracked = analysis::loadTwistProfileCsv(packageFile(std::string("sim/profiles/") + name + ".csv"));
        k.segments = profileSegments(k.tracked, kRest);
        k.duration = kRest + k.tracked.duration + 1.0;
        cases.push_back(k);
      }
      std::printf("\nThe AIC on re-sampled joint states (%s; drift %g ppm, jitter %g ms, stall %g; %d phases)\n",
                  aic_config.c_str(), drift, 1e3 * jitter, stall, phases);
      std::printf("%-16s %-8s %9s %9s %9s %6s %6s %s\n", "case", "figure", "clean", "worst", "ratio", "runaw", "health",
                  "drops (clean | sweep), imu_missing (clean | sweep)");
      for (const Case& k : cases)
      {
        if (!only.empty() && k.name != only)
        {
          continue;
        }
        ClosedLoopConfig c;
        c.controller = LoopController::kAic;
        c.node = node;
        c.aic = node.aic;
        c.profile = k.segments;
        c.duration = k.duration;
        const ClosedLoopRecord clean = runClosedLoop(desc, params, c);
        const std::vector<double> f0 = figures(k, clean);
        std::vector<double> worst(f0.size(), 0.0);
        std::vector<double> worst_ratio(f0.size(), 0.0);
        std::uint64_t runaways = 0;
        std::size_t health = 0;
        std::size_t imu_missing = 0;
        std::map<std::string, std::uint64_t> drops;
        for (int p = 0; p < phases; ++p)
        {
          c.jackal_node = true;
          c.jackal_node_sampler = sp;
          c.jackal_node_sampler.phase = phaseOf(p);
          const ClosedLoopRecord r = runClosedLoop(desc, params, c);
          const std::vector<double> f = figures(k, r);
          if (verbose)
          {
            std::printf("  %-16s phase %5.1f ms: repeats %5.2f %%, ages %4.1f..%4.1f ms, figures", k.name.c_str(),
                        1e3 * phaseOf(p), 100.0 * r.jackal_node_stats.repeatRate(), 1e3 * r.jackal_node_stats.min_age,
                        1e3 * r.jackal_node_stats.max_age);
            for (double x : f)
            {
              std::printf(" %.4f", x);
            }
            std::printf("\n");
          }
          for (std::size_t i = 0; i < f.size(); ++i)
          {
            const double ratio = f[i] / f0[i];
            if (!(ratio <= worst_ratio[i]))
            {
              worst_ratio[i] = ratio;
              worst[i] = f[i];
            }
          }
          runaways += r.runaways;
          health += r.health_events.size();
          imu_missing += r.imu_missing.size();
          for (const auto& d : r.drops)
          {
            drops[d.first] += d.second;
          }
        }
        std::string clean_drops;
        for (const auto& d : clean.drops)
        {
          clean_drops += d.first + " " + std::to_string(d.second) + "; ";
        }
        std::string sweep_drops;
        for (const auto& d : drops)
        {
          sweep_drops += d.first + " " + std::to_string(d.second) + "; ";
        }
        const char* names[2] = { k.profile ? "rms_vx" : "settling", "rms_wz" };
        for (std::size_t i = 0; i < f0.size(); ++i)
        {
          std::printf("%-16s %-8s %9.4f %9.4f %9.3f %6lu %6zu %s| %s; imu_missing %zu | %zu\n", k.name.c_str(),
                      names[i], f0[i], worst[i], worst_ratio[i], static_cast<unsigned long>(runaways), health,
                      clean_drops.c_str(), sweep_drops.c_str(), clean.imu_missing.size(), imu_missing);
        }
        std::fflush(stdout);
      }
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "jackal_node_sweep: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
