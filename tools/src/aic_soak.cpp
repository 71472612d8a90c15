/**
 * \file aic_soak.cpp
 * \brief aic_soak: hours of driving, headless and faster than real time: the AIC through the
 *        node's logic (ControlLoop) in closed loop with the ODE plant core
 *        (jackal_sim/harness/closed_loop.hpp), driven by seeded random planner and joystick
 *        streams (twist profile CSVs, e.g. from `aic_track.py --write-random-profiles DIR`) played
 *        in a seeded random order, with every fault scenario (the plant's fault lines) and every
 *        ordinary operation around the node (the clock stepping back, the simulator restarting,
 *        the sensor driver pausing, the node respawning) injected at seeded random times.
 *        Reports memory, belief and command bounds, recoveries after each operation and the
 *        learned wheel separation b_hat (its spread from 120 s after each node start: median,
 *        p1 .. p99, min .. max), and checks them (doc/tools.md, 'Soak').
 *
 * Usage: aic_soak [--hours H] [--seed N] [--profile FILE]... [--profile-dir DIR]
 *            [--aic-config FILE] [--aic-set key=value]... [plant options] [--noise]
 *            [--fault-every S] [--operation-every S] [--output FILE.md]
 * Checks (exit 3 if one fails): no non-finite command, belief or measurement; every command
 * within +-max_wheel_speed; every belief finite and within runaway_limit, no runaway; the
 * process's resident memory grows by less than 1 MiB from the first simulated 10 minutes to
 * the end (a tenth of a shorter run); after every operation the controller runs again; the
 * learned b_hat always finite and within [separation_min, separation_max].
 * Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments, 3 if a check fails.
 */

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <dirent.h>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "jackal_aic/analysis/tracking_metrics.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_tools/share_path.hpp"

using namespace jackal_aic;
using namespace jackal_aic::harness;

namespace
{
/// The fault scenarios, as the plant node's ~faults lines with START 0 (the soak adds its time)
/// and a DURATION: the fault table of doc/jackal_aic_node.md, 'Degraded modes and sensor faults'.
const char* const kFaultLines[] = {
  "imu dropout 0 8",
  "left_encoder bias 2.5 0 10",
  "right_encoder bias -2.5 0 10",
  "gyro freeze 0 6",
  "gyro bias 0.5 0 8",
  "payload set 10 0 30",
  "friction_left set 0.2 0 8",
  "friction_right set 0.2 0 8",
  "gyro spikes 3 0 1 0.1",
  "joint_states delay 0.06 0 0.5",
  "joint_states dropout 0 0.15",
  "left_encoder spikes 5 0 0.5 0.1",
  "left_encoder freeze 0 4",
  "imu delay 0.05 0 2",
};

/// Resident memory of this process [bytes] (/proc/self/statm); 0 if unreadable.
double residentBytes()
{
  std::ifstream in("/proc/self/statm");
  double pages_total = 0.0, pages_resident = 0.0;
  if (!(in >> pages_total >> pages_resident))
  {
    return 0.0;
  }
  return pages_resident * static_cast<double>(sysconf(_SC_PAGESIZE));
}

/// The *.csv files of a directory, sorted. \throws std::invalid_argument if it cannot be read.
std::vector<std::string> csvFiles(const std::string& dir)
{
  std::vector<std::string> out;
  DIR* d = opendir(dir.c_str());
  if (d == nullptr)
  {
    throw std::invalid_argument("cannot read the directory " + dir);
  }
  while (const dirent* e = readdir(d))
  {
    const std::string name = e->d_name;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".csv") == 0)
    {
      out.push_back(dir + "/" + name);
    }
  }
  closedir(d);
  std::sort(out.begin(), out.end());
  return out;
}

/// Running statistics of the soak (the observer).
struct SoakStats
{
  std::uint64_t samples = 0;
  std::uint64_t non_finite = 0;
  std::uint64_t commands_beyond_limit = 0;
  std::uint64_t beliefs_beyond_limit = 0;
  double max_abs_command = 0.0;               // [rad/s]
  double max_command_rise = 0.0;              // [rad/s] |command| rise between consecutive samples
  double max_abs_mu0[3] = { 0.0, 0.0, 0.0 };  // [m/s, m/s, rad/s]
  double max_abs_mu = 0.0;                    // any order [SI]
  double max_abs_v_true = 0.0;                // [m/s]
  std::uint64_t runaways = 0;                 // summed over the node's lives
  std::uint64_t time_jumps = 0;
  std::uint64_t starts = 0;
  double rss_baseline = 0.0, rss_max_after = 0.0, rss_end = 0.0;  // [bytes]
  double rss_first = 0.0;
};

/**
 * \brief Drift of a learned value, part 1: its means over consecutive windows of simulated time,
 *        from the samples given (a soak's b_hat after the learner's warm-up).
 *
 * The window of a sample is floor(t / window); a window counts only if it holds at least half as
 * many samples as the fullest one (a window cut by a node start or the run's end is left out).
 * Units are the value's own ([m] for b_hat) and seconds.
 */
class WindowMeans
{
public:
  /// \param window length of a window [s], > 0 (not checked: the soak's constants).
  explicit WindowMeans(double window) : window_(window) {}

  /// Add the value b at time t [s]; non-finite values are ignored.
  void add(double t, double b)
  {
    if (!std::isfinite(t) || !std::isfinite(b))
    {
      return;
    }
    const auto k = static_cast<long>(std::floor(t / window_));
    if (sums_.empty() || k != index_.back())
    {
      index_.push_back(k);
      sums_.push_back(0.0);
      counts_.push_back(0);
    }
    sums_.back() += b;
    ++counts_.back();
  }

  /// The means of the windows that count (see the class), in time order; empty if none.
  std::vector<double> means() const
  {
    std::uint64_t fullest = 0;
    for (std::uint64_t c : counts_)
    {
      fullest = std::max(fullest, c);
    }
    std::vector<double> out;
    for (std::size_t i = 0; i < sums_.size(); ++i)
    {
      if (2 * counts_[i] >= fullest && counts_[i] > 0)
      {
        out.push_back(sums_[i] / static_cast<double>(counts_[i]));
      }
    }
    return out;
  }

  /// The window's length [s].
  double window() const { return window_; }

private:
  double window_;
  std::vector<long> index_;
  std::vector<double> sums_;
  std::vector<std::uint64_t> counts_;
};

/**
 * \brief Drift of a learned value, part 2: the least-squares slope of its samples b against time
 *        t [value / s], the sums taken about the first sample's time (well conditioned over hours).
 */
class LeastSquaresTrend
{
public:
  /// Add the value b at time t [s]; non-finite values are ignored.
  void add(double t, double b)
  {
    if (!std::isfinite(t) || !std::isfinite(b))
    {
      return;
    }
    if (n_ == 0)
    {
      t0_ = t;
    }
    const double u = t - t0_;
    ++n_;
    su_ += u;
    sb_ += b;
    suu_ += u * u;
    sub_ += u * b;
  }

  /// The slope [value / s]; NaN with fewer than two distinct times.
  double slope() const
  {
    const double n = static_cast<double>(n_);
    const double den = n * suu_ - su_ * su_;
    return n_ >= 2 && den > 0.0 ? (n * sub_ - su_ * sb_) / den : std::nan("");
  }

private:
  std::uint64_t n_ = 0;
  double t0_ = 0.0, su_ = 0.0, sb_ = 0.0, suu_ = 0.0, sub_ = 0.0;
};
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string aic_config = packageFile("config/default.yaml");
  std::vector<std::string> aic_overrides;
  double hours = 8.0;
  int seed = 1;
  std::vector<std::string> profile_files;
  std::string profile_dir;
  bool noise = false;
  double fault_every = 120.0;
  double operation_every = 300.0;
  std::string output;
  CommandLine cl("aic_soak", "Hours of driving, headless and faster than real time: the AIC (the node's logic) on the "
                             "ODE plant "
                             "core, seeded random planner and joystick streams, every fault scenario and every "
                             "operation around "
                             "the node (clock steps back, simulator restarts, driver pauses, node respawns) at seeded "
                             "random "
                             "times; reports and checks memory, belief and command bounds and the recoveries.");
  cl.option("hours", &hours, "simulated time [h], > 0");
  cl.option("seed", &seed, "seed of the order of the profiles, the faults and the operations");
  cl.repeated("profile", &profile_files, "a twist profile CSV (t,vx,wz); repeatable");
  cl.option("profile-dir", &profile_dir,
            "every *.csv of this folder as a profile (default without --profile: the package's "
            "test/data/soak_profiles, written by aic_track.py --write-random-profiles)");
  cl.option("aic-config", &aic_config, "controller YAML (controller and node keys, as the node reads it)");
  cl.overrides("aic-set", &aic_overrides, "override a controller or node key");
  plant.addTo(&cl);
  cl.flag("noise", &noise, "keep the plant YAML's sensor noise (seeded; default: ideal sensors)");
  cl.option("fault-every", &fault_every, "mean interval between fault scenarios [s], > 0; 0 = none");
  cl.option("operation-every", &operation_every, "mean interval between operations around the node [s], > 0; 0 = none");
  cl.option("output", &output, "write the report (markdown) to this file as well");
  cl.footer("Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments, 3 if a check fails.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (!(hours > 0.0) || !std::isfinite(hours) || !(fault_every >= 0.0) || !(operation_every >= 0.0))
  {
    return cl.bad("--hours must be > 0, --fault-every and --operation-every >= 0 (0 = none)");
  }
  std::string profile_label = profile_dir;
  if (profile_files.empty() && profile_dir.empty())
  {
    profile_dir = packageFile("test/data/soak_profiles");
    profile_label = "test/data/soak_profiles";
  }

  ClosedLoopConfig c;
  plant::RobotDescription description;
  plant::PlantParams params;
  std::vector<analysis::TwistProfile> profiles;
  try
  {
    if (!profile_dir.empty())
    {
      for (const std::string& f : csvFiles(profile_dir))
      {
        profile_files.push_back(f);
      }
    }
    if (profile_files.empty())
    {
      throw std::invalid_argument("no profile CSV given or found");
    }
    for (const std::string& f : profile_files)
    {
      profiles.push_back(analysis::loadTwistProfileCsv(f));
    }
    description = plant.description();
    params = plant.params();
    c.node = loadNodeParamsFiles({ aic_config }, aic_overrides);
    c.aic = c.node.aic;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "aic_soak: %s\n", e.what());
    return 1;
  }
  c.controller = LoopController::kAic;
  c.duration = hours * 3600.0;
  c.ideal_sensors = !noise;
  c.record = false;

  // The schedule, seeded: profiles in random order with rests between, faults and operations
  // at exponentially distributed intervals.
  std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
  std::uniform_int_distribution<std::size_t> pick_profile(0, profiles.size() - 1);
  std::uniform_real_distribution<double> rest(0.5, 5.0);
  c.profile.push_back({ 0.0, 0.0, 0.0 });
  std::vector<int> profile_plays(profiles.size(), 0);
  for (double t0 = 1.0; t0 < c.duration;)
  {
    const std::size_t i = pick_profile(rng);
    ++profile_plays[i];
    const std::vector<SetPointSegment> segs = profileSegments(profiles[i], t0);
    c.profile.insert(c.profile.end(), segs.begin() + 1, segs.end());  // without its leading rest at 0
    t0 += profiles[i].duration + rest(rng);
    c.profile.push_back({ t0 - 0.5, 0.0, 0.0 });  // a rest between streams (the last row's t ends a profile)
  }
  const std::size_t n_fault_lines = sizeof(kFaultLines) / sizeof(kFaultLines[0]);
  std::uniform_int_distribution<std::size_t> pick_fault(0, n_fault_lines - 1);
  std::exponential_distribution<double> next_fault(fault_every > 0.0 ? 1.0 / fault_every : 1.0);
  std::vector<int> fault_counts(n_fault_lines, 0);
  for (double t = next_fault(rng); fault_every > 0.0 && t < c.duration; t += next_fault(rng))
  {
    const std::size_t i = pick_fault(rng);
    plant::FaultSpec f;
    std::string error;
    if (!plant::parseFaultSpec(kFaultLines[i], &f, &error))
    {
      std::fprintf(stderr, "aic_soak: fault line '%s': %s\n", kFaultLines[i], error.c_str());
      return 1;
    }
    f.start = t;
    c.faults.push_back(f);
    ++fault_counts[i];
  }
  std::exponential_distribution<double> next_operation(operation_every > 0.0 ? 1.0 / operation_every : 1.0);
  std::uniform_int_distribution<int> pick_operation(0, 3);
  std::uniform_real_distribution<double> clock_back(0.5, 60.0);  // [s]
  std::uniform_real_distribution<double> pause(1.0, 8.0);        // [s]
  std::uniform_real_distribution<double> down(0.05, 0.4);        // [s]
  for (double t = next_operation(rng); operation_every > 0.0 && t < c.duration - 10.0; t += next_operation(rng))
  {
    Operation o;
    o.kind = static_cast<Operation::Kind>(pick_operation(rng));
    o.start = t;
    o.size = o.kind == Operation::Kind::kClockBack   ? clock_back(rng) :
             o.kind == Operation::Kind::kDriverPause ? pause(rng) :
             o.kind == Operation::Kind::kNodeRestart ? down(rng) :
                                                       0.0;
    c.operations.push_back(o);
  }

  // The observer: bounds, memory, and for each operation the time until the controller runs again.
  SoakStats s;
  const double limit = c.aic.max_wheel_speed;
  const double runaway_limit = c.aic.runaway_limit;
  const loop::ControlLoop* seen_loop = nullptr;
  std::uint64_t loop_runaways = 0, loop_jumps = 0, loop_starts = 0;
  base::Vector2 last_command = base::Vector2::Zero();
  std::size_t op_index = 0;
  double op_ready_at = -1.0;  // run time from which the operation's recovery is measured [s]
  std::vector<std::vector<double>> recoveries(4);
  std::uint64_t unrecovered = 0;  // the controller never ran again after the last operation
  std::uint64_t superseded = 0;   // operations followed by the next before the controller ran again
  // Resident memory: the baseline after the first 10 simulated minutes (a tenth of a shorter run).
  const double rss_start = std::min(600.0, 0.1 * c.duration);
  double next_rss = rss_start;
  // The learned wheel separation: a histogram over [separation_min, separation_max] of b_hat from
  // kLearnWarmup after each node start (a respawn starts learning again from wheel_separation).
  constexpr double kLearnWarmup = 120.0;  // [s]
  constexpr std::size_t kBins = 4000;
  const double b_lo = c.aic.separation_learner.min;
  const double b_hi = c.aic.separation_learner.max;
  std::vector<std::uint64_t> b_hist(kBins, 0);
  std::uint64_t b_count = 0, b_outside = 0;
  double b_min = std::numeric_limits<double>::infinity(), b_max = -b_min, b_last = std::nan("");
  // Drift of b_hat: its 1-minute and 5-minute means and its trend (the spread above includes
  // b_hat following the operating point, whose effective separation differs; doc/tools.md, 'Soak').
  WindowMeans drift_1min(60.0), drift_5min(300.0);
  LeastSquaresTrend trend;
  double loop_since = 0.0;
  c.observer = [&](const ClosedLoopSample& x) {
    ++s.samples;
    const loop::ControlLoop* loop = x.loop;
    if (loop != seen_loop)
    {
      s.runaways += loop_runaways;
      s.time_jumps += loop_jumps;
      s.starts += loop_starts;
      loop_runaways = loop_jumps = loop_starts = 0;
      seen_loop = loop;
      loop_since = x.time;
    }
    if (loop != nullptr && loop->controller().params().separation_learner.enabled)
    {
      const double b = loop->controller().model().wheelSeparation();
      b_outside += (std::isfinite(b) && b >= b_lo && b <= b_hi) ? 0 : 1;
      if (x.time - loop_since >= kLearnWarmup && std::isfinite(b))
      {
        const double u = (b - b_lo) / (b_hi - b_lo);
        ++b_hist[std::min(kBins - 1, static_cast<std::size_t>(std::max(0.0, u) * static_cast<double>(kBins)))];
        ++b_count;
        b_min = std::min(b_min, b);
        b_max = std::max(b_max, b);
        b_last = b;
        drift_1min.add(x.time, b);
        drift_5min.add(x.time, b);
        trend.add(x.time, b);
      }
    }
    const bool finite = x.wheels_command.allFinite() && x.wheels_measured.allFinite() && std::isfinite(x.v_true);
    s.non_finite += finite ? 0 : 1;
    const double cmd = x.wheels_command.cwiseAbs().maxCoeff();
    s.max_abs_command = std::max(s.max_abs_command, cmd);
    s.commands_beyond_limit += cmd <= limit ? 0 : 1;
    for (int w = 0; w < 2; ++w)
    {
      s.max_command_rise = std::max(s.max_command_rise, std::abs(x.wheels_command(w)) - std::abs(last_command(w)));
    }
    last_command = x.wheels_command;
    s.max_abs_v_true = std::max(s.max_abs_v_true, std::abs(x.v_true));
    if (loop != nullptr)
    {
      const auto& mu = loop->controller().mu();
      if (!mu.allFinite())
      {
        ++s.non_finite;
      }
      const double m = mu.cwiseAbs().maxCoeff();
      s.max_abs_mu = std::max(s.max_abs_mu, m);
      s.beliefs_beyond_limit += m <= runaway_limit ? 0 : 1;
      if (loop->active())
      {
        for (int ch = 0; ch < 3; ++ch)
        {
          s.max_abs_mu0[ch] = std::max(s.max_abs_mu0[ch], std::abs(mu(ch, 0)));
        }
      }
      loop_runaways = loop->supervisor().runaways();
      loop_jumps = loop->timeJumps();
      loop_starts = loop->starts();
    }
    // Recovery: from the operation's end (clock step, restart: its start; pause, respawn: +size)
    // to the first sample with the controller running while the set point is fresh.
    while (op_index < c.operations.size() && c.operations[op_index].start <= x.time)
    {
      if (op_ready_at >= 0.0)
      {
        ++superseded;  // the next came before the controller ran again: judged with the next
      }
      const Operation& o = c.operations[op_index];
      op_ready_at =
          o.start + (o.kind == Operation::Kind::kDriverPause || o.kind == Operation::Kind::kNodeRestart ? o.size : 0.0);
      ++op_index;
    }
    if (op_ready_at >= 0.0 && x.time >= op_ready_at && loop != nullptr && loop->active())
    {
      recoveries[static_cast<std::size_t>(c.operations[op_index - 1].kind)].push_back(x.time - op_ready_at);
      op_ready_at = -1.0;
    }
    if (x.time >= next_rss)
    {
      const double rss = residentBytes();
      if (s.rss_baseline == 0.0)
      {
        s.rss_baseline = rss;
      }
      s.rss_max_after = std::max(s.rss_max_after, rss);
      next_rss += rss_start;
    }
  };

  s.rss_first = residentBytes();
  const auto wall_start = std::chrono::steady_clock::now();
  try
  {
    runClosedLoop(description, params, c);
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "aic_soak: %s\n", e.what());
    return 1;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  s.runaways += loop_runaways;
  s.time_jumps += loop_jumps;
  s.starts += loop_starts;
  s.rss_end = residentBytes();
  if (s.rss_baseline == 0.0)
  {
    s.rss_baseline = s.rss_first;
  }
  s.rss_max_after = std::max(s.rss_max_after, s.rss_end);
  const double growth = s.rss_max_after - s.rss_baseline;
  if (op_ready_at >= 0.0 && c.duration - op_ready_at > 5.0)
  {
    ++unrecovered;
  }

  // Report.
  double b_drift = 0.0;  // largest deviation of b_hat's p1 / p99 from its median (relative)
  std::ostringstream r;
  r.setf(std::ios::fixed);
  r.precision(3);
  r << "| figure | value |\n|---|---|\n";
  r << "| simulated time | " << hours << " h (" << c.duration << " s) |\n";
  r << "| wall time | " << wall << " s (" << c.duration / wall << " x real time) |\n";
  r << "| joint-state samples | " << s.samples << " |\n";
  r << "| profiles played | " << std::count_if(profile_plays.begin(), profile_plays.end(), [](int n) { return n > 0; })
    << " of " << profiles.size() << " files, " <<
      [&] {
        int n = 0;
        for (int p : profile_plays)
          n += p;
        return n;
      }()
    << " plays |\n";
  r << "| fault scenarios injected | " << c.faults.size() << " (" << n_fault_lines << " kinds) |\n";
  r << "| operations | " << c.operations.size() << " |\n";
  r << "| non-finite values | " << s.non_finite << " |\n";
  r << "| max abs wheel command | " << s.max_abs_command << " rad/s (limit " << limit
    << "; beyond: " << s.commands_beyond_limit << ") |\n";
  r << "| max rise of abs wheel command between samples | " << s.max_command_rise << " rad/s |\n";
  r << "| max abs belief mu^(0) while running | x_dot " << s.max_abs_mu0[0] << " m/s, y_dot " << s.max_abs_mu0[1]
    << " m/s, theta_dot " << s.max_abs_mu0[2] << " rad/s |\n";
  r << "| max abs belief, any order | " << s.max_abs_mu << " (runaway_limit " << runaway_limit
    << "; beyond: " << s.beliefs_beyond_limit << ") |\n";
  r << "| max abs true speed | " << s.max_abs_v_true << " m/s |\n";
  r << "| runaway resets | " << s.runaways << " |\n";
  r << "| ROS time jumps back seen by the loop | " << s.time_jumps << " |\n";
  r << "| controller starts | " << s.starts << " |\n";
  r << "| resident memory | " << s.rss_first / 1048576.0 << " MiB at start, " << s.rss_baseline / 1048576.0
    << " MiB after " << rss_start / 60.0 << " simulated minutes, " << s.rss_end / 1048576.0
    << " MiB at the end; growth " << growth / 1024.0 << " KiB |\n";
  if (!c.aic.separation_learner.enabled)
  {
    r << "| learned parameters | none (learn_wheel_separation off): the controller adapts only its beliefs and its "
         "action (bounds above) |\n";
  }
  else if (b_count == 0)
  {
    r << "| learned wheel separation b_hat | no sample " << kLearnWarmup << " s after a node start |\n";
  }
  else
  {
    // Percentiles from the histogram (bin centres).
    auto quantile = [&](double q) {
      const auto target = static_cast<std::uint64_t>(q * static_cast<double>(b_count - 1));
      std::uint64_t seen = 0;
      for (std::size_t i = 0; i < kBins; ++i)
      {
        seen += b_hist[i];
        if (seen > target)
        {
          return b_lo + (static_cast<double>(i) + 0.5) * (b_hi - b_lo) / static_cast<double>(kBins);
        }
      }
      return b_hi;
    };
    const double median = quantile(0.5), p1 = quantile(0.01), p99 = quantile(0.99);
    b_drift = std::max(median - p1, p99 - median) / median;
    r << "| learned wheel separation b_hat (from " << kLearnWarmup << " s after each node start; " << b_count
      << " samples) | median " << median << " m, p1 .. p99 " << p1 << " .. " << p99 << " m ("
      << 100.0 * (p1 - median) / median << " % .. +" << 100.0 * (p99 - median) / median << " %), min .. max " << b_min
      << " .. " << b_max << " m, at the end " << b_last << " m; bounds " << b_lo << " .. " << b_hi
      << " m (samples outside: " << b_outside
      << "); p1 and p99 within 2 % of the median: " << (b_drift <= 0.02 ? "yes" : "no") << " |\n";
    for (const WindowMeans* d : { &drift_1min, &drift_5min })
    {
      const std::vector<double> m = d->means();
      r << "| b_hat's means over " << static_cast<int>(d->window() / 60.0) << "-minute windows (" << m.size() << ") | ";
      if (m.empty())
      {
        r << "no full window |\n";
        continue;
      }
      const auto [lo, hi] = std::minmax_element(m.begin(), m.end());
      const double dev = std::max(median - *lo, *hi - median) / median;
      r << "min .. max " << *lo << " .. " << *hi << " m (" << 100.0 * (*lo - median) / median << " % .. +"
        << 100.0 * (*hi - median) / median
        << " % of the median); within 2 % of the median: " << (dev <= 0.02 ? "yes" : "no") << " |\n";
    }
    r << "| b_hat's trend (least squares over its samples) | " << 100.0 * trend.slope() * 3600.0 / median
      << " % of the median per hour |\n";
  }
  r << "\n| operation | count | recovery p50 [s] | recovery max [s] |\n|---|---|---|---|\n";
  for (int k = 0; k < 4; ++k)
  {
    std::vector<double> v = recoveries[static_cast<std::size_t>(k)];
    std::sort(v.begin(), v.end());
    r << "| " << toString(static_cast<Operation::Kind>(k)) << " | " << v.size() << " | "
      << (v.empty() ? std::nan("") : v[v.size() / 2]) << " | " << (v.empty() ? std::nan("") : v.back()) << " |\n";
  }
  r << "\nRecovery: from the first sample after the operation (a clock step or a restart: at once; a driver pause "
       "or a respawn: after its length) to the first sample with the controller running; an operation followed by the "
       "next before that is "
       "judged with the next ("
    << superseded << " such). Operations after which the controller never ran again: " << unrecovered
    << ".\n\n| fault line | injected |\n|---|---|\n";
  for (std::size_t i = 0; i < n_fault_lines; ++i)
  {
    r << "| `" << kFaultLines[i] << "` | " << fault_counts[i] << " |\n";
  }
  std::vector<std::string> failures;
  if (s.non_finite > 0)
    failures.push_back("non-finite values");
  if (s.commands_beyond_limit > 0)
    failures.push_back("commands beyond max_wheel_speed");
  if (s.beliefs_beyond_limit > 0 || s.runaways > 0)
    failures.push_back("beliefs beyond runaway_limit / runaway resets");
  if (growth >= 1048576.0)
    failures.push_back("resident memory grew by 1 MiB or more");
  if (unrecovered > 0)
    failures.push_back("an operation after which the controller did not run again");
  if (b_outside > 0)
    failures.push_back("learned b_hat outside [separation_min, separation_max] or non-finite");
  r << "\nVerdict: " << (failures.empty() ? "PASS" : "FAIL");
  for (const auto& f : failures)
  {
    r << "; " << f;
  }
  r << "\n";
  std::cout << r.str();
  if (!output.empty())
  {
    std::ofstream out(output);
    std::ostringstream cmd;
    cmd << "aic_soak";
    for (int i = 1; i < argc; ++i)
    {
      cmd << " " << argv[i];
    }
    auto every = [](double mean, const char* what) {
      std::ostringstream o;
      if (mean > 0.0)
      {
        o << "a" << (what[0] == 'o' ? "n " : " ") << what << " every " << mean << " s on average";
      }
      else
      {
        o << "no " << what << "s";
      }
      return o.str();
    };
    out << "# Soak: "
        << (fault_every > 0.0 || operation_every > 0.0 ? "hours of driving with faults and operations around the node" :
                                                         "random driving, no faults and no operations")
        << "\n\n"
        << "Written by `" << cmd.str() << "` (tools/src/aic_soak.cpp; doc/tools.md, 'Soak'): the AIC through the "
        << "node's logic on the ODE plant core, faster than real time, seed " << seed << ", profiles "
        << (profile_label.empty() ? std::string("given on the command line") : "of " + profile_label) << ", "
        << every(fault_every, "fault") << ", " << every(operation_every, "operation") << ".\n\n"
        << r.str();
    if (!out)
    {
      std::fprintf(stderr, "aic_soak: cannot write %s\n", output.c_str());
      return 1;
    }
  }
  return failures.empty() ? 0 : 3;
}
