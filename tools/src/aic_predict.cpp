/**
 * \file aic_predict.cpp
 * \brief CLI: batch predictions of the dual-rate closed-loop state-space model
 *        (jackal_aic::analysis::ClosedLoopModel; thesis ch. 4, appendix A; doc/active_inference.md,
 *        'State-space model for analysis') for a tuner: one candidate per input line.
 *
 * Usage: aic_predict CONFIG.yaml [--target V] [--duration S]
 * Reads lines from stdin; each line is whitespace-separated KEY=VALUE overrides of the YAML
 * (controller keys, values parsed as YAML, e.g. `tau=0.01 var_y=[2,20,1e5,1e5]`) and plant
 * keys `plant.time_constant=S` (first-order wheel loop; absent: point mass), `plant.gain=K`,
 * `plant.delay=S`. Writes one JSON object per line, in order:
 *   {"ok": true, "spectral_radius": r, "stable": b, "rise": s, "settling": s, "overshoot": %,
 *    "sse": m/s, "peak_command": rad/s}      (metrics of v_x for a step 0 -> V at t = 0; null
 *                                             where undefined, e.g. unstable)
 *   {"ok": false, "error": "..."}           (invalid parameters or plant)
 * An empty line is answered with an empty object. Exit 0 at end of input; 1 if CONFIG cannot
 * be read; 2 on bad arguments. The tuner (scripts/aic_tune.py) keeps one process open.
 * Command line on Boost.program_options, overrides through the shared parser (tools/include/jackal_tools/cli.hpp,
 * include/jackal_aic/overrides/yaml_overrides.hpp).
 */
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/analysis/state_space.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"

using namespace jackal_aic;

namespace
{
std::string jsonEscape(const std::string& s)
{
  std::string out;
  for (char c : s)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (c == '\n')
    {
      out += "\\n";
    }
    else
    {
      out += c;
    }
  }
  return out;
}

double plantNumber(const std::string& key, const std::string& value)
{
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(v))
  {
    throw std::runtime_error(key + ": '" + value + "' is not a finite number");
  }
  return v;
}

/// One candidate: overrides -> JSON line.
std::string predictLine(const std::string& config, const std::string& line, double target, double duration)
{
  std::istringstream in(line);
  std::string tok;
  std::vector<std::string> overrides;
  analysis::PlantModel plant;
  while (in >> tok)
  {
    const overrides::Override o = overrides::parseOverride(tok);  // the shared KEY=VALUE parser
    if (o.key.rfind("plant.", 0) == 0)
    {
      const double v = plantNumber(o.key, o.value);
      if (o.key == "plant.time_constant")
      {
        plant.type = analysis::PlantModel::Type::kFirstOrder;
        plant.time_constant = v;
      }
      else if (o.key == "plant.gain")
      {
        plant.gain = v;
      }
      else if (o.key == "plant.delay")
      {
        plant.delay = v;
      }
      else
      {
        throw std::runtime_error("unknown plant key '" + o.key + "' (plant.time_constant, plant.gain, plant.delay)");
      }
    }
    else
    {
      overrides.push_back(tok);
    }
  }
  const params::AicParams p = loadAicParams(config, overrides);
  const analysis::ClosedLoopModel model(p, plant);
  const double rho = model.spectralRadius();
  std::ostringstream os;
  os << "{\"ok\": true, \"spectral_radius\": " << base::jsonNumber(rho, 8)
     << ", \"stable\": " << (rho < 1.0 ? "true" : "false");
  double rise = NAN, settling = NAN, overshoot = NAN, sse = NAN, peak = NAN;
  if (rho < 1.0)
  {
    const auto resp = model.stepResponse(base::Vector3(target, 0.0, 0.0), duration);
    std::vector<double> t, v;
    peak = 0.0;
    for (const auto& s : resp)
    {
      t.push_back(s.t);
      v.push_back(s.twist(0));
      peak = std::max(peak, s.a.cwiseAbs().maxCoeff());
    }
    analysis::StepMetricsOptions o;
    o.initial = 0.0;
    o.target = target;
    const analysis::StepMetrics m = analysis::computeStepMetrics(t, v, o);
    rise = m.rise_time;
    settling = m.settled ? m.settling_time : NAN;
    overshoot = m.overshoot_percent;
    sse = m.steady_state_error;
  }
  os << ", \"rise\": " << base::jsonNumber(rise, 8) << ", \"settling\": " << base::jsonNumber(settling, 8)
     << ", \"overshoot\": " << base::jsonNumber(overshoot, 8) << ", \"sse\": " << base::jsonNumber(sse, 8)
     << ", \"peak_command\": " << base::jsonNumber(peak, 8) << "}";
  return os.str();
}
}  // namespace

int main(int argc, char** argv)
{
  std::string config;
  double target = 0.5;
  double duration = 3.0;
  CommandLine cl("aic_predict", "Batch predictions of the dual-rate closed-loop state-space model, one candidate per "
                                "stdin line: "
                                "whitespace-separated KEY=VALUE overrides of the YAML and "
                                "plant.time_constant|gain|delay=...; one "
                                "JSON object per line.");
  cl.positional("CONFIG", &config, "controller YAML");
  cl.option("target", &target, "step of v_x from 0 [m/s], non-zero");
  cl.option("duration", &duration, "simulated time [s], > 0");
  cl.footer("Exit 0 at end of input; 1 if CONFIG cannot be read; 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (target == 0.0 || duration <= 0.0)
  {
    return cl.bad("--target must be non-zero and --duration > 0");
  }
  try
  {
    loadAicParams(config);
  }
  catch (const std::exception& e)
  {
    std::cerr << "aic_predict: " << e.what() << "\n";
    return 1;
  }
  std::string line;
  while (std::getline(std::cin, line))
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos)
    {
      std::cout << "{}" << std::endl;
      continue;
    }
    try
    {
      std::cout << predictLine(config, line, target, duration) << std::endl;
    }
    catch (const std::exception& e)
    {
      std::cout << "{\"ok\": false, \"error\": \"" << jsonEscape(e.what()) << "\"}" << std::endl;
    }
  }
  return 0;
}
