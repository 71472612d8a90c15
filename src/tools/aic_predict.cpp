/**
 * \file aic_predict.cpp
 * \brief CLI: batch predictions of the dual-rate closed-loop state-space model
 *        (jackal_aic::ClosedLoopModel; thesis ch. 4, appendix A; doc/active_inference.md,
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
 */
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_aic/params_yaml.hpp"
#include "jackal_aic/state_space.hpp"

using namespace jackal_aic;

namespace
{
std::string num(double v)
{
  if (!std::isfinite(v))
  {
    return "null";
  }
  std::ostringstream os;
  os.precision(8);
  os << v;
  return os.str();
}

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
  PlantModel plant;
  while (in >> tok)
  {
    const auto eq = tok.find('=');
    const std::string key = tok.substr(0, eq);
    if (key.rfind("plant.", 0) == 0)
    {
      if (eq == std::string::npos)
      {
        throw std::runtime_error("'" + tok + "' is not KEY=VALUE");
      }
      const double v = plantNumber(key, tok.substr(eq + 1));
      if (key == "plant.time_constant")
      {
        plant.type = PlantModel::Type::kFirstOrder;
        plant.time_constant = v;
      }
      else if (key == "plant.gain")
      {
        plant.gain = v;
      }
      else if (key == "plant.delay")
      {
        plant.delay = v;
      }
      else
      {
        throw std::runtime_error("unknown plant key '" + key + "' (plant.time_constant, plant.gain, plant.delay)");
      }
    }
    else
    {
      overrides.push_back(tok);
    }
  }
  const AicParams p = loadAicParams(config, overrides);
  const ClosedLoopModel model(p, plant);
  const double rho = model.spectralRadius();
  std::ostringstream os;
  os << "{\"ok\": true, \"spectral_radius\": " << num(rho) << ", \"stable\": " << (rho < 1.0 ? "true" : "false");
  double rise = NAN, settling = NAN, overshoot = NAN, sse = NAN, peak = NAN;
  if (rho < 1.0)
  {
    const auto resp = model.stepResponse(Vector3(target, 0.0, 0.0), duration);
    std::vector<double> t, v;
    peak = 0.0;
    for (const auto& s : resp)
    {
      t.push_back(s.t);
      v.push_back(s.twist(0));
      peak = std::max(peak, s.a.cwiseAbs().maxCoeff());
    }
    StepMetricsOptions o;
    o.initial = 0.0;
    o.target = target;
    const StepMetrics m = computeStepMetrics(t, v, o);
    rise = m.rise_time;
    settling = m.settled ? m.settling_time : NAN;
    overshoot = m.overshoot_percent;
    sse = m.steady_state_error;
  }
  os << ", \"rise\": " << num(rise) << ", \"settling\": " << num(settling) << ", \"overshoot\": " << num(overshoot)
     << ", \"sse\": " << num(sse) << ", \"peak_command\": " << num(peak) << "}";
  return os.str();
}
}  // namespace

int main(int argc, char** argv)
{
  const char* usage = "usage: aic_predict CONFIG.yaml [--target V (m/s, default 0.5)] [--duration S (default 3)]\n"
                      "  stdin: one candidate per line, KEY=VALUE overrides and plant.time_constant|gain|delay=...\n";
  std::string config;
  double target = 0.5;
  double duration = 3.0;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if ((a == "--target" || a == "--duration") && i + 1 < argc)
    {
      char* end = nullptr;
      const double v = std::strtod(argv[++i], &end);
      if (*end != '\0' || !std::isfinite(v) || (a == "--duration" && v <= 0.0) || (a == "--target" && v == 0.0))
      {
        std::cerr << "aic_predict: bad value for " << a << "\n" << usage;
        return 2;
      }
      (a == "--target" ? target : duration) = v;
    }
    else if (a == "--help" || a == "-h")
    {
      std::cout << usage;
      return 0;
    }
    else if (config.empty() && a.rfind("--", 0) != 0)
    {
      config = a;
    }
    else
    {
      std::cerr << "aic_predict: unexpected argument '" << a << "'\n" << usage;
      return 2;
    }
  }
  if (config.empty())
  {
    std::cerr << usage;
    return 2;
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
