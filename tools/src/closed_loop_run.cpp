/**
 * \file closed_loop_run.cpp
 * \brief closed_loop_run: one set-point profile with the stock controller or the AIC on the
 *        ODE plant core, headless and faster than real time (jackal_sim/harness/closed_loop.hpp: the
 *        node's logic, ControlLoop, on simulated time). Prints one JSON object with the metrics of
 *        every transition of the profile for the measured (wheel-odometry), ground-truth,
 *        belief and drive-command speeds, and the tracking of the whole profile (RMS and max
 *        error of vx and wz, ground truth and wheel odometry, against the set point; the
 *        ground-truth path's drift from the set point's ideal path: jackal_aic/analysis/tracking_metrics.hpp);
 *        optionally the trace as CSV. The experiment engine of aic_reproduce.py (--backend core)
 *        and aic_track.py; the ROS backend runs the nodes instead.
 *
 * Usage: closed_loop_run --controller aic|stock|open|ideal|pi [--aic-config FILE] [--aic-set key=value]...
 *            [--pi-config FILE] [--pi-set key=value]...
 *            [--config PLANT.yaml] [--overlay FILE]... [--set key=value]... [--urdf FILE]
 *            (--step V [--turn W] | --square LOW HIGH | --profile FILE [--segments]) [--channel linear|angular]
 *            [--period S] [--cycles N] [--rest S] [--hold S] [--noise] [--fault LINE]... [--csv FILE]
 *            [--ideal-iterations N] [--ideal-gain G]
 *   --overlay FILE    plant YAML with only the keys that differ (e.g. a file of sim/config/variants/),
 *                     applied after --config and before --set; repeatable, later ones win
 *   --controller pi    the classical peer (jackal_aic/classical/pi_controller.hpp): PI loops on the
 *                     wheel speeds and the yaw rate around the robot model's feed-forward, its
 *                     settings from --pi-config (default config/classical/pi.yaml) and --pi-set
 *   --controller open  no controller: the set point's wheel speeds go to the MCU as they are
 *   --controller ideal the ideal controller (jackal_sim/harness/closed_loop.hpp, runIdealController): the
 *                     command sequence learned over --ideal-iterations runs from rest (iterative
 *                     learning control, the set point command_delay ahead to start with); the best
 *                     run's figures; where it misses the set point the plant decides;
 *                     --ideal-iterations N (>= 1, default kIdealIterations), --ideal-gain G (in (0, 2),
 *                     default kIdealLearningGain) set the learning
 *   --channel angular  the step / square values are yaw rates [rad/s] (linear set point 0);
 *                      metrics on the yaw rate
 *   --step V          0 until --rest, then V [m/s] for --hold seconds
 *   --turn W          with --step: a combined step, the yaw-rate set point steps to W [rad/s] at
 *                     the same time; "angular_segments" gives the yaw rate's metrics
 *   --square LOW HIGH 0 until --rest, LOW for --rest seconds (lead-in), then --cycles periods of
 *                     HIGH / LOW, each half --period / 2
 *   --profile FILE    a twist profile CSV (t, vx, wz rows, header optional, zero-order hold, the
 *                     last row's t ends it; jackal_aic/analysis/tracking_metrics.hpp), played from --rest on;
 *                     its transitions are not steps: "segments" is empty unless --segments (then the
 *                     step metrics of every transition, "segments" vx and "angular_segments" wz)
 *   --noise           keep the plant YAML's sensor noise (seeded; default: ideal sensors)
 *   --fault LINE      inject a fault from START s after the run's start (sim/README.md)
 * JSON: {"runaways", "max_abs_speed", "max_abs_pitch" (the largest |ground-truth pitch| [rad]: a
 *        pair of wheels off the ground, pi / 2 a robot tipped over), with the AIC "tip_guard":
 *        {"trips", "front", "rear"} (the tip-over guard's trips and learned bounds [m/s^2], null: none)
 *        and "fault_monitor": {"isolated", "restored", "detected"} (its events' counts: on a healthy
 *        run each is a false alarm),
 *        "command_delay" (the plant's motor.command_delay [s]),
 *        with learn_precision (goal and unbiased models) "sensory_precisions" (the AIC's Pi_y^(0)
 *        per sensor channel at the end),
 *        with the robot model's learn_latency "learned_latency" (its wheel loop's L at the end [s]),
 *        with the robot model "shortfall_jumps": {"taken", "released", "unanswered", "stalls"} (its
 *        shortfall jumps' counts over the run, both sides: doc/active_inference.md, 'The robot model'),
 *        "plant": what the plant did over the profile's span, any controller: {"torque_limited" (share
 *        of the samples x sides with the motor torque clamped to its limit), "wheel_loop": {"vx", "wz"}
 *        (RMS of the wheel loops' set point in effect minus the true wheel speeds, as body twist
 *        [m/s, rad/s]: the MCU loop's lag), "slip": {"vx", "wz"} (RMS of the true wheel speeds' twist
 *        minus the ground truth: slip and skid)}, with --controller ideal "ideal": {"runs", "best",
 *        "vx_rms": [...], "wz_rms": [...]} (every run's RMS error over the whole run),
 *        "segments": [{"t_step", "initial", "target", "measured": {...}, "truth": {...}, "belief": {...},
 *        "drive": {...}}] [, "angular_segments": [...]] ("measured": wheel odometry in "segments", the
 *        gyro in "angular_segments"), "profile",
 *        "duration", "tracking": {"truth": {"vx": {"rms", "max"}, "wz": {...}, "samples"}, "odometry": {...},
 *        "stops": {"stops", "reverse_speed_max" [m/s], "reverse_travel_max" [m], "window" [s]} (the true
 *        speed against the direction before each stop of the profile, within "window" of it:
 *        jackal_aic/analysis/stop_reversal.hpp, stopReversal),
 *        "turned_over_at" (the profile time the body first tilted past 90 degrees, on its side or back
 *        [s]: jackal_aic/analysis/steady_estimate.hpp, turnoverTime; null: it stayed upright),
 *        with the AIC "belief": {"vx": {"steady_mean_abs", "steady_max_abs", "samples", "segments"}, "wz":
 *        {...}, "unavailable"} (belief mu^(0) against the truth from "belief_settle" [s] after each change
 *        of the channel's set point to the next: jackal_aic/analysis/tracking_metrics.hpp, steadyEstimateError)
 *        and, on a run that turned the robot over, "belief_upright" (the same up to "turned_over_at")},
 *        "path": {"final_position_error", "max_position_error", "final_heading_error", "ideal_length",
 *        "samples"}} with rise, settling, overshoot, sse, settled; times from the profile's start
 *        (--rest + 10 ms into the run); tracking over the profile's span.
 * CSV (--csv): t (from the profile's start), set points, speeds, beliefs, drive commands, the
 *        ground-truth pose x, y, heading, the ideal pose x_ideal, y_ideal, heading_ideal (empty
 *        outside the analysed span) and the AIC's wheel separation b_hat [m] (learned with
 *        learn_wheel_separation; empty for the other controllers and before the AIC starts), its gyro
 *        offset gyro_offset [rad/s], the ground-truth pitch [rad] (> 0 nose down), and the AIC's
 *        fault monitor's residual fdi_residual [rad/s] and statistic fdi_statistic [-] (empty for
 *        the other controllers, before the first test and while the IMU is missing); with the AIC
 *        then its inference, units in brackets: the free energy F and its sensory and prior parts
 *        F_sensory, F_prior (thesis eq. 3-10), the action a_L, a_R, its prior a_ff_L, a_ff_R, the
 *        attractor goal mu_r as goal_{x_dot,y_dot,theta_dot} (the reference model's output), the sensory
 *        precisions in use Pi_y0_<channel> (learned with learn_precision), the robot model's slow
 *        states shortfall_{L,R}, turn_shortfall_{L,R} [rad/s], slip_ratio [-] and gyro_offset_belief
 *        [rad/s] (beta, on top of the offset removed at rest), and per order i = 0..p the beliefs
 *        mu<i>_{x_dot,y_dot,theta_dot}, the sensory prediction errors eps_y<i>_{gyro_z,omega_L,omega_R,
 *        accel_x,accel_y} (eq. 3-8) and the state prediction errors eps_mu<i>_* (eq. 3-9), empty
 *        before the controller starts and where the belief model in use has no such quantity
 *        (jackal_aic/aic/inference_sample.hpp: the robot model's states under the goal and unbiased
 *        models; a_ff, eps_mu, mu and eps_y beyond its own under the robot model).
 * Divergence: a run whose controller had a runaway reset, whose ground truth or drive command
 *        went non-finite, or whose robot never moved (no commanded channel's ground-truth speed
 *        reached kMovedShare of its largest set point) has diverged: the JSON's "diverged" holds
 *        the cause (null otherwise), one line "closed_loop_run: diverged: CAUSE" goes to stderr
 *        and the exit status is 3, unless --keep-going (then the JSON alone reports it, exit 0).
 * Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments, 3 on a diverged run
 *        (without --keep-going).
 */

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/pi_params_yaml.hpp"
#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_aic/analysis/tracking_metrics.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_tools/share_path.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
/// Steady segments of the honest-belief measure start this long after a set-point change [s]
/// (doc/experiments.md, 'Driving acceptance').
constexpr double kBeliefSettle = 0.5;
/// A robot "moved" when a commanded channel's ground-truth speed reached this share of the
/// channel's largest |set point| [-].
constexpr double kMovedShare = 0.1;
/// Exit status of a diverged run (without --keep-going).
constexpr int kExitDiverged = 3;

std::string metricsJson(const std::vector<double>& t, const std::vector<double>& y, double t_step, double t_end,
                        double initial, double target)
{
  analysis::StepMetricsOptions o;
  o.step_time = t_step;
  o.end_time = t_end;
  o.initial = initial;
  o.target = target;
  std::vector<double> tt;
  std::vector<double> yy;
  for (std::size_t i = 0; i < t.size(); ++i)
  {
    if (std::isfinite(y[i]))
    {
      tt.push_back(t[i]);
      yy.push_back(y[i]);
    }
  }
  if (tt.size() < 2)
  {
    return "null";
  }
  const analysis::StepMetrics m = analysis::computeStepMetrics(tt, yy, o);
  std::ostringstream os;
  os << "{\"rise\": " << base::jsonNumber(m.rise_time) << ", \"settling\": " << base::jsonNumber(m.settling_time)
     << ", \"overshoot\": " << base::jsonNumber(m.overshoot_percent)
     << ", \"sse\": " << base::jsonNumber(m.steady_state_error) << ", \"settled\": " << (m.settled ? "true" : "false")
     << "}";
  return os.str();
}
}  // namespace

namespace
{
/// The inference columns of the trace (AIC, --csv), units in brackets: F and its parts, the
/// action, its prior, the attractor goal, the sensory precisions Pi_y^(0), the robot model's slow
/// states (shortfalls d, turn shortfalls e, slip ratio s, gyro offset beta), then per order i the
/// beliefs mu<i>_*, the sensory errors eps_y<i>_* and the state errors eps_mu<i>_*
/// (jackal_aic/aic/inference_sample.hpp). Empty for orders = 0 (no AIC).
std::string inferenceCsvHeader(int orders)
{
  if (orders == 0)
  {
    return "";
  }
  std::ostringstream h;
  h << ",F[-],F_sensory[-],F_prior[-],a_L[rad/s],a_R[rad/s],a_ff_L[rad/s],a_ff_R[rad/s]";
  for (int c = 0; c < base::kMuDim; ++c)
  {
    h << ",goal_" << aic::kBeliefChannelNames[c] << "[" << aic::kBeliefChannelUnits[c] << "]";
  }
  for (int c = 0; c < base::kYDim; ++c)
  {
    h << ",Pi_y0_" << aic::kSensorChannelNames[c] << "[1/(" << aic::kSensorChannelUnits[c] << ")^2]";
  }
  h << ",shortfall_L[rad/s],shortfall_R[rad/s],turn_shortfall_L[rad/s],turn_shortfall_R[rad/s],slip_ratio[-],"
       "gyro_offset_belief[rad/s]";
  for (int i = 0; i < orders; ++i)
  {
    for (int c = 0; c < base::kMuDim; ++c)
    {
      h << ",mu" << i << "_" << aic::kBeliefChannelNames[c] << "[" << aic::orderUnit(aic::kBeliefChannelUnits[c], i)
        << "]";
    }
    for (int c = 0; c < base::kYDim; ++c)
    {
      h << ",eps_y" << i << "_" << aic::kSensorChannelNames[c] << "[" << aic::orderUnit(aic::kSensorChannelUnits[c], i)
        << "]";
    }
    for (int c = 0; c < base::kMuDim; ++c)
    {
      h << ",eps_mu" << i << "_" << aic::kBeliefChannelNames[c] << "["
        << aic::orderUnit(aic::kBeliefChannelUnits[c], i + 1) << "]";
    }
  }
  return h.str();
}

/// One sample's inference columns (inferenceCsvHeader's order; empty cells: NaN, an order
/// beyond the sample's).
std::string inferenceCsvRow(const aic::InferenceSample& s, int orders)
{
  auto cell = [](double v) { return std::isfinite(v) ? base::jsonNumber(v) : std::string(); };
  std::ostringstream r;
  r << "," << cell(s.free_energy) << "," << cell(s.sensory) << "," << cell(s.prior) << "," << cell(s.action(0)) << ","
    << cell(s.action(1)) << "," << cell(s.action_prior(0)) << "," << cell(s.action_prior(1));
  for (int c = 0; c < base::kMuDim; ++c)
  {
    r << "," << cell(s.goal(c));
  }
  for (int c = 0; c < base::kYDim; ++c)
  {
    r << "," << cell(s.precision_y(c));
  }
  r << "," << cell(s.shortfall(0)) << "," << cell(s.shortfall(1)) << "," << cell(s.turn_shortfall(0)) << ","
    << cell(s.turn_shortfall(1)) << "," << cell(s.slip_ratio) << "," << cell(s.gyro_offset_belief);
  const double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < orders; ++i)
  {
    const bool has = i < s.mu.cols();
    for (int c = 0; c < base::kMuDim; ++c)
    {
      r << "," << cell(has ? s.mu(c, i) : kNaN);
    }
    for (int c = 0; c < base::kYDim; ++c)
    {
      r << "," << cell(has ? s.eps_y(c, i) : kNaN);
    }
    for (int c = 0; c < base::kMuDim; ++c)
    {
      r << "," << cell(has ? s.eps_mu(c, i) : kNaN);
    }
  }
  return r.str();
}

/// Why the run ``rec`` of the profile ``profile`` (set-point segments; the analysed span starts at
/// ``t0`` [s]) diverged, or "" when it did not: runaway resets, a non-finite ground truth or drive
/// command, or a robot that never moved (every commanded channel's largest |ground truth| below
/// kMovedShare of its largest |set point|). Causes joined by "; ".
std::string divergence(const ClosedLoopRecord& rec, const std::vector<SetPointSegment>& profile, double t0)
{
  std::vector<std::string> causes;
  if (rec.runaways > 0)
  {
    causes.push_back(std::to_string(rec.runaways) + " runaway reset(s): a belief left runaway_limit or went non-finite "
                                                    "(the belief dynamics are "
                                                    "unstable at these settings; check them with aic_analyze)");
  }
  const std::vector<std::pair<const char*, const std::vector<double>*>> signals = {
    { "ground-truth speed", &rec.v_true }, { "ground-truth yaw rate", &rec.yaw_true },
    { "drive command", &rec.command },     { "drive command's yaw rate", &rec.command_yaw },
    { "ground-truth x", &rec.x_true },     { "ground-truth y", &rec.y_true },
  };
  for (const auto& s : signals)
  {
    const auto bad = std::find_if(s.second->begin(), s.second->end(), [](double v) { return !std::isfinite(v); });
    if (bad != s.second->end())
    {
      const std::size_t k = static_cast<std::size_t>(bad - s.second->begin());
      causes.push_back(std::string("non-finite ") + s.first + " at t = " + base::jsonNumber(rec.time[k] - t0) + " s");
      break;
    }
  }
  double set_lin = 0.0;
  double set_ang = 0.0;
  for (const SetPointSegment& p : profile)
  {
    set_lin = std::max(set_lin, std::abs(p.linear));
    set_ang = std::max(set_ang, std::abs(p.angular));
  }
  double max_lin = 0.0;
  double max_ang = 0.0;
  for (std::size_t k = 0; k < rec.time.size(); ++k)
  {
    if (rec.time[k] >= t0 - 1e-9)
    {
      max_lin = std::max(max_lin, std::isfinite(rec.v_true[k]) ? std::abs(rec.v_true[k]) : 0.0);
      max_ang = std::max(max_ang, std::isfinite(rec.yaw_true[k]) ? std::abs(rec.yaw_true[k]) : 0.0);
    }
  }
  const bool commanded = set_lin > 0.0 || set_ang > 0.0;
  const bool moved =
      (set_lin > 0.0 && max_lin >= kMovedShare * set_lin) || (set_ang > 0.0 && max_ang >= kMovedShare * set_ang);
  if (commanded && !moved)
  {
    std::ostringstream os;
    os << "the robot never moved: largest ground-truth |vx| " << base::jsonNumber(max_lin, 3)
       << " m/s against a set point of " << base::jsonNumber(set_lin, 3) << " m/s, |wz| "
       << base::jsonNumber(max_ang, 3) << " rad/s against " << base::jsonNumber(set_ang, 3) << " rad/s (below "
       << base::jsonNumber(100.0 * kMovedShare) << " %)";
    causes.push_back(os.str());
  }
  std::string out;
  for (const std::string& c : causes)
  {
    out += (out.empty() ? "" : "; ") + c;
  }
  return out;
}

/// ``text`` as a JSON string (quotes and backslashes escaped).
std::string jsonString(const std::string& text)
{
  std::string out = "\"";
  for (char ch : text)
  {
    if (ch == '"' || ch == '\\')
    {
      out += '\\';
    }
    out += ch;
  }
  return out + "\"";
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string aic_config = packageFile("config/thesis_equivalent.yaml");
  std::vector<std::string> aic_overrides;
  std::string pi_config = packageFile("config/classical/pi.yaml");
  std::vector<std::string> pi_overrides;
  std::string controller;
  std::string csv;
  double step = 0.0;
  double low = 0.0;
  double high = 0.0;
  double period = 4.0;
  int cycles = 2;
  double rest = 1.0;
  double hold = 3.0;
  bool noise = false;
  std::string channel = "linear";
  std::vector<double> square;
  double turn = 0.0;
  std::string profile_file;
  bool profile_segments = false;
  int ideal_iterations = kIdealIterations;
  double ideal_gain = kIdealLearningGain;
  CommandLine cl("closed_loop_run", "One set-point profile with the stock controller or the AIC on the ODE plant core, "
                                    "headless and "
                                    "faster than real time; prints one JSON object with the metrics of every "
                                    "transition.");
  cl.option("controller", &controller,
            "aic, stock, open (no controller: the set point's wheel speeds go to the MCU as they are) or ideal (the "
            "command sequence learned over repeated runs, knowing the profile and the ground truth: what the plant "
            "allows) or pi (the classical peer: PI loops on the wheel speeds and the yaw rate around the robot "
            "model's feed-forward)",
            true);
  cl.option("aic-config", &aic_config, "controller YAML (controller and node keys, as the node reads it)");
  cl.overrides("aic-set", &aic_overrides, "override a controller or node key");
  cl.option("pi-config", &pi_config, "--controller pi: its YAML (default config/classical/pi.yaml)");
  cl.overrides("pi-set", &pi_overrides, "--controller pi: override a key of its YAML (e.g. wheel.kp=0.4)");
  plant.addTo(&cl);
  cl.option("step", &step, "0 until --rest, then V [m/s] (or [rad/s]) for --hold seconds");
  cl.numbers("square", &square, 2,
             "LOW HIGH: 0 until --rest, LOW for --rest seconds (lead-in), then --cycles periods of HIGH / LOW, each "
             "half --period / 2");
  cl.option("channel", &channel,
            "linear or angular: the step / square values are yaw rates [rad/s] (linear set point 0); metrics on the "
            "yaw rate");
  cl.option("turn", &turn,
            "W [rad/s]: a combined step, --step V on the linear channel and W on the angular one at once (--channel "
            "linear); metrics for both (\"segments\": linear, \"angular_segments\": yaw rate)");
  cl.option("profile", &profile_file,
            "twist profile CSV (t,vx,wz rows, zero-order hold, the last row's t ends it), played from --rest on");
  cl.flag("segments", &profile_segments, "with --profile: step metrics of every transition of both channels");
  cl.option("ideal-iterations", &ideal_iterations, "--controller ideal: runs of the learning, >= 1");
  cl.option("ideal-gain", &ideal_gain, "--controller ideal: learning gain, in (0, 2)");
  cl.option("period", &period, "square period [s]");
  cl.option("cycles", &cycles, "square periods, 1..100");
  cl.option("rest", &rest, "rest before the profile [s], > 0.2");
  cl.option("hold", &hold, "step hold time [s]");
  cl.flag("noise", &noise, "keep the plant YAML's sensor noise (seeded; default: ideal sensors)");
  std::vector<std::string> fault_lines;
  cl.repeated("fault", &fault_lines,
              "inject a fault, \"TARGET KIND [VALUE] [START] [DURATION] [PERIOD]\" with START from the run's "
              "start (sim/README.md, 'Fault injection')");
  cl.option("csv", &csv, "write the trace as CSV");
  bool keep_going = false;
  cl.flag("keep-going", &keep_going,
          "a diverged run (runaway, non-finite values, a robot that never moved) is reported in the JSON's "
          "\"diverged\" and exits 0 (default: also one line on stderr and exit 3)");
  cl.footer("Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments, 3 on a diverged run (runaway, "
            "non-finite values, a robot that never moved) without --keep-going.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  const bool have_step = cl.given("step");
  const bool have_square = cl.given("square");
  const bool have_profile = cl.given("profile");
  if (have_square)
  {
    low = square[0];
    high = square[1];
  }
  if (controller != "aic" && controller != "stock" && controller != "open" && controller != "ideal" &&
      controller != "pi")
  {
    return cl.bad("--controller must be aic, stock, open, ideal or pi");
  }
  if (channel != "linear" && channel != "angular")
  {
    return cl.bad("--channel must be linear or angular");
  }
  const bool angular = channel == "angular";
  if (static_cast<int>(have_step) + static_cast<int>(have_square) + static_cast<int>(have_profile) != 1)
  {
    return cl.bad("give exactly one of --step, --square and --profile");
  }
  if (profile_segments && !have_profile)
  {
    return cl.bad("--segments goes with --profile");
  }
  if (!(rest > 0.2) || !(hold > 0.0) || !(period > 0.0) || cycles < 1 || cycles > 100)
  {
    return cl.bad("--rest must be > 0.2 s, --hold and --period > 0, --cycles in [1, 100]");
  }

  const bool combined = cl.given("turn");
  if (combined && (!have_step || angular))
  {
    return cl.bad("--turn needs --step and --channel linear");
  }

  ClosedLoopConfig c;
  for (const std::string& line : fault_lines)
  {
    FaultSpec f;
    std::string error;
    if (!parseFaultSpec(line, &f, &error))
    {
      return cl.bad("--fault '" + line + "': " + error);
    }
    c.faults.push_back(f);
  }
  c.controller = controller == "aic"   ? LoopController::kAic :
                 controller == "open"  ? LoopController::kOpenLoop :
                 controller == "ideal" ? LoopController::kIdeal :
                 controller == "pi"    ? LoopController::kPi :
                                         LoopController::kStock;
  // A set point on the chosen channel, 0 on the other.
  auto sp = [angular](double start, double value) -> SetPointSegment {
    return angular ? SetPointSegment{ start, 0.0, value } : SetPointSegment{ start, value, 0.0 };
  };
  c.ideal_sensors = !noise;
  // Set-point changes 10 ms after a 50 Hz tick, as the identification runs.
  const double t0 = rest + 0.01;
  if (have_step)
  {
    c.profile = { sp(0.0, 0.0), sp(t0, step) };
    if (combined)
    {
      c.profile[1].angular = turn;
    }
    c.duration = t0 + hold;
  }
  else if (have_square)
  {
    c.profile.push_back(sp(0.0, 0.0));
    c.profile.push_back(sp(t0, low));
    double t = t0 + rest;
    for (int k = 0; k < cycles; ++k)
    {
      c.profile.push_back(sp(t, high));
      c.profile.push_back(sp(t + 0.5 * period, low));
      t += period;
    }
    c.duration = t;
  }

  // The profile in profile time (0 = t0), for the tracking metrics; a CSV profile is played from t0.
  analysis::TwistProfile tracked;
  try
  {
    if (have_profile)
    {
      tracked = analysis::loadTwistProfileCsv(profile_file);
      c.profile = profileSegments(tracked, t0);
      c.duration = t0 + tracked.duration;
    }
    else
    {
      for (const SetPointSegment& s : c.profile)
      {
        if (s.start >= t0 - 1e-9)
        {
          tracked.points.push_back(analysis::TwistProfilePoint{ s.start - t0, s.linear, s.angular });
        }
      }
      tracked.duration = c.duration - t0;
      tracked.name = have_step ? "step" : "square";
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "closed_loop_run: " << e.what() << "\n";
    return 1;
  }

  RobotDescription desc;
  PlantParams params;
  try
  {
    desc = plant.description();
    params = plant.params();
    if (c.controller == LoopController::kAic)
    {
      c.node = loadNodeParamsFiles({ aic_config }, aic_overrides);  // the node's keys too (triggers, FDI, ...)
      c.aic = c.node.aic;
    }
    if (c.controller == LoopController::kPi)
    {
      c.pi = loadPiParams(pi_config, pi_overrides);
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "closed_loop_run: " << e.what() << "\n";
    return 1;
  }
  if (ideal_iterations < 1 || !(ideal_gain > 0.0 && ideal_gain < 2.0))
  {
    return cl.bad("--ideal-iterations must be >= 1 and --ideal-gain in (0, 2)");
  }
  c.record_inference = !csv.empty();  // the trace's inference columns (AIC only)
  ClosedLoopRecord rec;
  IdealRun ideal;
  try
  {
    if (c.controller == LoopController::kIdeal)
    {
      ideal = runIdealController(desc, params, c, ideal_iterations, ideal_gain);
      rec = std::move(ideal.record);
    }
    else
    {
      rec = runClosedLoop(desc, params, c);
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "closed_loop_run: " << e.what() << "\n";
    return 1;
  }

  // Tracking of the whole profile: ground truth and wheel odometry against the set point, the
  // ground-truth path against the ideal one.
  std::vector<double> t_profile;
  for (double t : rec.time)
  {
    t_profile.push_back(t - t0);
  }
  std::string tracking_json;
  analysis::PathDrift drift;
  try
  {
    tracking_json = "{\"truth\": " +
                    analysis::toJson(analysis::velocityTrackingError(tracked, t_profile, rec.v_true, rec.yaw_true)) +
                    ", \"odometry\": " +
                    analysis::toJson(analysis::velocityTrackingError(tracked, t_profile, rec.v_odom, rec.yaw_odom)) +
                    ", \"stops\": " +
                    analysis::toJson(analysis::stopReversal(tracked, t_profile, rec.v_true, analysis::kStopWindow));
    // A body turned over (on its side or its back) no longer drives: the time, or null.
    const double t_over = analysis::turnoverTime(t_profile, rec.up_true);
    tracking_json += ", \"turned_over_at\": " + (std::isfinite(t_over) ? base::jsonNumber(t_over) : "null");
    if (c.controller == LoopController::kAic)
    {
      // The honest-belief measure: belief mu^(0) against the truth where the set point holds; on a
      // run that turns the robot over also up to the turnover alone.
      tracking_json += ", \"belief\": " +
                       analysis::toJson(analysis::steadyEstimateError(tracked, t_profile, rec.belief, rec.belief_yaw,
                                                                      rec.v_true, rec.yaw_true, kBeliefSettle)) +
                       ", \"belief_settle\": " + base::jsonNumber(kBeliefSettle);
      if (std::isfinite(t_over))
      {
        tracking_json +=
            ", \"belief_upright\": " +
            analysis::toJson(analysis::steadyEstimateError(tracked, t_profile, rec.belief, rec.belief_yaw, rec.v_true,
                                                           rec.yaw_true, kBeliefSettle, t_over));
      }
    }
    tracking_json += "}";
    drift = analysis::pathDrift(tracked, t_profile, rec.x_true, rec.y_true, rec.heading_true);
  }
  catch (const std::exception& e)
  {
    std::cerr << "closed_loop_run: " << e.what() << "\n";
    return 1;
  }

  if (!csv.empty())
  {
    std::ofstream f(csv);
    const int orders = rec.inference.empty() ? 0 : static_cast<int>(rec.inference.front().mu.cols());
    f << "t,set_point,v_odom,v_true,yaw_odom,yaw_true,command,belief,angular_set_point,command_yaw,belief_yaw,"
         "x,y,heading,x_ideal,y_ideal,heading_ideal,separation,gyro_offset,pitch,fdi_residual,fdi_statistic"
      << inferenceCsvHeader(orders) << "\n";
    std::size_t ideal = 0;  // next analysed sample of the path drift
    for (std::size_t k = 0; k < rec.time.size(); ++k)
    {
      f << t_profile[k] << "," << rec.set_point[k] << "," << rec.v_odom[k] << "," << rec.v_true[k] << ","
        << rec.yaw_odom[k] << "," << rec.yaw_true[k] << "," << rec.command[k] << ","
        << (std::isfinite(rec.belief[k]) ? base::jsonNumber(rec.belief[k]) : "") << "," << rec.angular_set_point[k]
        << "," << rec.command_yaw[k] << ","
        << (std::isfinite(rec.belief_yaw[k]) ? base::jsonNumber(rec.belief_yaw[k]) : "") << ","
        << base::jsonNumber(rec.x_true[k], 9) << "," << base::jsonNumber(rec.y_true[k], 9) << ","
        << base::jsonNumber(rec.heading_true[k], 9);
      if (ideal < drift.time.size() && drift.time[ideal] == t_profile[k])
      {
        f << "," << base::jsonNumber(drift.ideal[ideal].x, 9) << "," << base::jsonNumber(drift.ideal[ideal].y, 9) << ","
          << base::jsonNumber(drift.ideal[ideal].heading, 9);
        ++ideal;
      }
      else
      {
        f << ",,,";
      }
      f << "," << (std::isfinite(rec.separation[k]) ? base::jsonNumber(rec.separation[k]) : "") << ","
        << (std::isfinite(rec.gyro_offset[k]) ? base::jsonNumber(rec.gyro_offset[k]) : "") << ","
        << base::jsonNumber(rec.pitch_true[k], 6) << ","
        << (std::isfinite(rec.fdi_residual[k]) ? base::jsonNumber(rec.fdi_residual[k]) : "") << ","
        << (std::isfinite(rec.fdi_statistic[k]) ? base::jsonNumber(rec.fdi_statistic[k]) : "");
      if (k < rec.inference.size())
      {
        f << inferenceCsvRow(rec.inference[k], orders);
      }
      f << "\n";
    }
    if (!f)
    {
      std::cerr << "closed_loop_run: cannot write " << csv << "\n";
      return 1;
    }
  }

  double max_abs = 0.0;
  for (double v : rec.v_true)
  {
    max_abs = std::max(max_abs, std::abs(v));
  }
  double max_pitch = 0.0;  // the largest |pitch| over the run: a lifted pair of wheels, or a tip-over
  for (double p : rec.pitch_true)
  {
    max_pitch = std::max(max_pitch, std::abs(p));
  }
  std::cout << "{\"controller\": \"" << controller << "\", \"channel\": \"" << channel
            << "\", \"runaways\": " << rec.runaways << ", \"max_abs_speed\": " << base::jsonNumber(max_abs)
            << ", \"max_abs_pitch\": " << base::jsonNumber(max_pitch)
            << ", \"command_delay\": " << base::jsonNumber(params.motor.command_delay)
            << ", \"t0\": " << base::jsonNumber(t0);
  if (c.controller == LoopController::kAic)
  {
    // The tip-over guard: trips and learned bounds (null: none learned).
    const auto bound = [](double b) { return std::isfinite(b) ? base::jsonNumber(b) : std::string("null"); };
    std::cout << ", \"tip_guard\": {\"trips\": " << rec.tip_trips << ", \"front\": " << bound(rec.tip_front)
              << ", \"rear\": " << bound(rec.tip_rear) << "}";
    // The fault monitor's events: on a healthy run, each is a false alarm.
    int isolated = 0, restored = 0, detected = 0;
    for (const HealthEvent& e : rec.health_events)
    {
      isolated += e.event == safety::FaultMonitor::Event::kIsolated;
      restored += e.event == safety::FaultMonitor::Event::kRestored;
      detected += e.event == safety::FaultMonitor::Event::kDetected;
    }
    std::cout << ", \"fault_monitor\": {\"isolated\": " << isolated << ", \"restored\": " << restored
              << ", \"detected\": " << detected << "}";
  }
  if (c.controller == LoopController::kAic && params::learnsLatency(c.aic))
  {
    std::cout << ", \"learned_latency\": " << base::jsonNumber(rec.latency);
  }
  if (c.controller == LoopController::kAic && c.aic.belief_model == params::BeliefModel::kRobot)
  {
    std::cout << ", \"shortfall_jumps\": {\"taken\": " << rec.shortfall_jumps
              << ", \"released\": " << rec.shortfall_releases << ", \"unanswered\": " << rec.unanswered_jumps
              << ", \"stalls\": " << rec.stalls << "}";
  }
  if (c.controller == LoopController::kAic && params::learnsPrecision(c.aic))
  {
    // The sensory precisions Pi_y^(0) at the end (learn_precision), per SensorIndex.
    std::cout << ", \"sensory_precisions\": [";
    for (std::size_t j = 0; j < rec.sensory_precisions.size(); ++j)
    {
      std::cout << (j ? ", " : "") << base::jsonNumber(rec.sensory_precisions[j]);
    }
    std::cout << "]";
  }
  std::cout << ", \"segments\": ";
  // The transitions of one channel (angular: the yaw rate) as a JSON list of metrics.
  auto segments = [&](bool yaw) {
    std::ostringstream out;
    out << "[";
    bool first = true;
    for (std::size_t s = 1; s < c.profile.size(); ++s)
    {
      const double t_step = c.profile[s].start;
      if (t_step < t0 - 1e-9)
      {
        continue;
      }
      const double t_end = s + 1 < c.profile.size() ? c.profile[s + 1].start : c.duration;
      const double initial = yaw ? c.profile[s - 1].angular : c.profile[s - 1].linear;
      const double target = yaw ? c.profile[s].angular : c.profile[s].linear;
      // "measured": what the robot's own sensors say: wheel odometry for the speed, the gyro for the
      // yaw rate (wheel odometry's yaw depends on the b_hat it assumes, which the plant's turning does not).
      const auto& measured = yaw ? rec.yaw_gyro : rec.v_odom;
      const auto& truth = yaw ? rec.yaw_true : rec.v_true;
      const auto& belief = yaw ? rec.belief_yaw : rec.belief;
      const auto& drive = yaw ? rec.command_yaw : rec.command;
      if (initial == target)
      {
        continue;
      }
      out << (first ? "" : ", ") << "{\"t_step\": " << base::jsonNumber(t_step - t0)
          << ", \"initial\": " << base::jsonNumber(initial) << ", \"target\": " << base::jsonNumber(target)
          << ", \"measured\": " << metricsJson(rec.time, measured, t_step, t_end, initial, target)
          << ", \"truth\": " << metricsJson(rec.time, truth, t_step, t_end, initial, target)
          << ", \"belief\": " << metricsJson(rec.time, belief, t_step, t_end, initial, target)
          << ", \"drive\": " << metricsJson(rec.time, drive, t_step, t_end, initial, target) << "}";
      first = false;
    }
    out << "]";
    return out.str();
  };
  if (have_profile)
  {
    std::cout << (profile_segments ? segments(false) : "[]");
    if (profile_segments)
    {
      std::cout << ", \"angular_segments\": " << segments(true);
    }
  }
  else
  {
    std::cout << segments(angular);
    if (combined)
    {
      std::cout << ", \"angular_segments\": " << segments(true);
    }
  }
  // What the plant did over the profile's span (from t0 on).
  {
    double limited = 0.0;
    double loop_v = 0.0;
    double loop_w = 0.0;
    double slip_v = 0.0;
    double slip_w = 0.0;
    std::size_t n = 0;
    for (std::size_t k = 0; k < rec.time.size(); ++k)
    {
      if (t_profile[k] < -1e-9 || t_profile[k] > tracked.duration + 1e-9)
      {
        continue;
      }
      limited += rec.torque_limited[k];
      loop_v += std::pow(rec.wheel_setpoint[k] - rec.v_wheels[k], 2);
      loop_w += std::pow(rec.wheel_setpoint_yaw[k] - rec.yaw_wheels[k], 2);
      slip_v += std::pow(rec.v_wheels[k] - rec.v_true[k], 2);
      slip_w += std::pow(rec.yaw_wheels[k] - rec.yaw_true[k], 2);
      ++n;
    }
    const double m = std::max<double>(1.0, static_cast<double>(n));
    std::cout << ", \"plant\": {\"torque_limited\": " << base::jsonNumber(limited / m)
              << ", \"wheel_loop\": {\"vx\": " << base::jsonNumber(std::sqrt(loop_v / m))
              << ", \"wz\": " << base::jsonNumber(std::sqrt(loop_w / m))
              << "}, \"slip\": {\"vx\": " << base::jsonNumber(std::sqrt(slip_v / m))
              << ", \"wz\": " << base::jsonNumber(std::sqrt(slip_w / m)) << "}}";
  }
  if (c.controller == LoopController::kIdeal)
  {
    auto list = [](const std::vector<double>& v) {
      std::string o = "[";
      for (std::size_t i = 0; i < v.size(); ++i)
      {
        o += (i ? ", " : "") + base::jsonNumber(v[i]);
      }
      return o + "]";
    };
    std::cout << ", \"ideal\": {\"runs\": " << ideal.vx_rms.size() << ", \"best\": " << ideal.best
              << ", \"vx_rms\": " << list(ideal.vx_rms) << ", \"wz_rms\": " << list(ideal.wz_rms) << "}";
  }
  const std::string diverged = divergence(rec, c.profile, t0);
  std::cout << ", \"profile\": \"" << tracked.name << "\", \"duration\": " << base::jsonNumber(tracked.duration)
            << ", \"tracking\": " << tracking_json << ", \"path\": " << analysis::toJson(drift)
            << ", \"diverged\": " << (diverged.empty() ? std::string("null") : jsonString(diverged)) << "}\n";
  if (!diverged.empty() && !keep_going)
  {
    std::cout.flush();
    std::cerr << "closed_loop_run: diverged: " << diverged << " (--keep-going: report and exit 0)\n";
    return kExitDiverged;
  }
  return 0;
}
