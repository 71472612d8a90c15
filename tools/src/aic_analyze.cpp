/**
 * \file aic_analyze.cpp
 * \brief CLI: linear analysis of an active inference controller configuration (thesis ch. 4,
 *        appendix A; doc/active_inference.md, 'State-space model for analysis') on top of
 *        jackal_aic::analysis::ClosedLoopModel.
 *
 * Reads the same YAML parameter files as the jackal_AIC node (node-only keys are ignored,
 * unknown keys are warned about) and prints, per belief rate and integrator: the spectral radius
 * of the dual-rate closed loop, stable or not, the predicted step metrics of v_x, and the
 * stability limits (smallest stable tau, largest stable k_mu and k_a, the others fixed).
 * Keys are those of the parameter schema (include/jackal_aic/params/param_schema.hpp); --set uses the
 * shared override parser (include/jackal_aic/overrides/yaml_overrides.hpp). Run with --help for the
 * options (Boost.program_options). Exit 0 on success, 1 on a bad file or invalid parameters, 2 on bad arguments.
 */
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <yaml-cpp/yaml.h>

#include "jackal_tools/cli.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/analysis/state_space.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"

using namespace jackal_aic;

namespace
{
[[noreturn]] void fail(int code, const std::string& msg)
{
  std::cerr << "aic_analyze: error: " << msg << "\n";
  std::exit(code);
}

std::string fmt(double v, int precision = 4)
{
  if (std::isnan(v))
  {
    return "-";
  }
  std::ostringstream os;
  os << std::setprecision(precision) << v;
  return os.str();
}

std::string limitText(const analysis::StabilityLimit& l, bool lower_is_better, bool csv)
{
  if (std::isnan(l.value))
  {
    return csv ? "nan" : "none";
  }
  if (!l.stable_at_range_end)
  {
    // A stable band that does not reach the normally stable end of the range: "low..high".
    const double a = lower_is_better ? l.value : l.band_start;
    const double b = lower_is_better ? l.band_start : l.value;
    return fmt(a, 4) + ".." + fmt(b, 4);
  }
  if (l.unbounded)
  {
    return (lower_is_better ? "<=" : ">=") + fmt(l.value, 3);
  }
  return fmt(l.value, 4);
}

struct Row
{
  double belief_rate;
  double action_rate;
  params::Integrator integrator;
  analysis::PredictedStep pred;
  analysis::StabilityLimit tau, k_mu, k_a;
  bool scanned;
};
}  // namespace

int main(int argc, char** argv)
{
  std::string file;
  std::vector<double> rates{ 50.0, 100.0, 1000.0 };
  std::vector<std::string> integrator_names{ "euler", "exact" };
  std::string plant_name = "point";
  analysis::PlantModel plant;
  double target = 0.5;
  double duration = 20.0;
  bool csv = false;
  bool no_scan = false;
  std::vector<std::string> overrides;

  CommandLine cl("aic_analyze", "Linear analysis of an active inference controller configuration: spectral radius of "
                                "the dual-rate "
                                "closed loop, predicted step response of v_x and stability limits per belief rate and "
                                "integrator "
                                "(thesis ch. 4; doc/active_inference.md).");
  cl.positional("CONFIG", &file, "controller YAML (config/*.yaml)");
  cl.list("rates", &rates,
          "belief rates to analyse [Hz] (default 50,100,1000); the action rate is the file's action_rate (or the "
          "belief rate if that is lower)");
  cl.list("integrators", &integrator_names, "euler,exact (default both)");
  cl.option("plant", &plant_name, "plant in the loop: point (wheels follow the command, thesis ch. 4) or first-order");
  cl.option("plant-time-constant", &plant.time_constant,
            "first-order wheel-speed time constant [s] (implies first-order)");
  cl.option("target", &target, "step of the goal v_x from 0 [m/s]");
  cl.option("duration", &duration, "simulated time of the predicted step [s]");
  cl.overrides("set", &overrides, "override a YAML key, e.g. --set tau=0.01");
  cl.flag("no-scan", &no_scan, "skip the stability-limit scans");
  cl.flag("csv", &csv, "machine-readable CSV instead of the table");
  cl.footer("Scan ranges: tau [1e-5, 10] s, k_mu and k_a [1e-4, 1e4]. Exit 0 on success, 1 on a bad file or "
            "invalid parameters, 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  const bool scan = !no_scan;
  for (double r : rates)
  {
    if (r <= 0.0)
    {
      return cl.bad("--rates: '" + fmt(r) + "' is not a positive number");
    }
  }
  if (rates.empty())
  {
    return cl.bad("--rates: empty list");
  }
  std::vector<params::Integrator> integrators;
  for (const auto& name : integrator_names)
  {
    params::Integrator integ;
    if (!params::integratorFromString(name, &integ))
    {
      return cl.bad("--integrators: '" + name + "' (allowed: euler, exact)");
    }
    integrators.push_back(integ);
  }
  if (integrators.empty())
  {
    return cl.bad("--integrators: empty list");
  }
  if (plant_name == "point")
  {
    plant.type = analysis::PlantModel::Type::kPointMass;
  }
  else if (plant_name == "first-order")
  {
    plant.type = analysis::PlantModel::Type::kFirstOrder;
  }
  else
  {
    return cl.bad("--plant '" + plant_name + "' (allowed: point, first-order)");
  }
  if (cl.given("plant-time-constant"))
  {
    if (plant.time_constant <= 0.0)
    {
      return cl.bad("--plant-time-constant '" + fmt(plant.time_constant) + "' must be > 0");
    }
    plant.type = analysis::PlantModel::Type::kFirstOrder;
  }
  if (target == 0.0)
  {
    return cl.bad("--target must be a non-zero number");
  }
  if (duration <= 1.0)
  {
    return cl.bad("--duration '" + fmt(duration) + "' must be > 1 s");
  }
  for (const auto& o : overrides)
  {
    try
    {
      overrides::parseOverride(o);
    }
    catch (const std::invalid_argument& e)
    {
      return cl.bad(std::string("--set: ") + e.what());
    }
  }

  params::AicParams params;
  std::vector<std::string> defaulted;
  try
  {
    YAML::Node root = YAML::LoadFile(file);
    if (!root.IsMap())
    {
      fail(1, file + ": expected a map of parameters at the top level");
    }
    overrides::applyOverrides(root, overrides);  // the shared KEY=VALUE parser
    std::vector<std::string> unknown;
    params = aicParamsFromYaml(root, file, &defaulted, &unknown);
    for (const auto& key : unknown)
    {
      std::cerr << "aic_analyze: warning: " << file << ": unknown key '" << key << "' ignored\n";
    }
  }
  catch (const YAML::BadFile&)
  {
    fail(1, "cannot read '" + file + "'");
  }
  catch (const YAML::Exception& e)
  {
    fail(1, file + ": YAML error: " + e.what());
  }
  catch (const std::invalid_argument& e)
  {
    fail(2, std::string("--set: ") + e.what());
  }
  catch (const std::runtime_error& e)
  {
    fail(1, e.what());
  }
  const auto violations = params.validate();
  if (!violations.empty())
  {
    for (const auto& v : violations)
    {
      std::cerr << "aic_analyze: error: " << file << ": " << v.toString() << "\n";
    }
    return 1;
  }

  std::vector<Row> rows;
  try
  {
    for (double br : rates)
    {
      for (params::Integrator integ : integrators)
      {
        params::AicParams p = params;
        p.belief_rate = br;
        p.action_rate = std::min(params.action_rate, br);
        p.integrator = integ;
        if (std::abs(br / p.action_rate - std::round(br / p.action_rate)) > 1e-9 * br / p.action_rate)
        {
          fail(2, "belief rate " + fmt(br) + " Hz is not a multiple of the action rate " + fmt(p.action_rate) + " Hz");
        }
        Row r{ br, p.action_rate, integ, analysis::predictStep(p, plant, target, duration), {}, {}, {}, scan };
        if (scan)
        {
          r.tau = analysis::scanStabilityLimit(p, plant, analysis::ScanParameter::kTau, 1e-5, 10.0);
          r.k_mu = analysis::scanStabilityLimit(p, plant, analysis::ScanParameter::kKMu, 1e-4, 1e4);
          r.k_a = analysis::scanStabilityLimit(p, plant, analysis::ScanParameter::kKA, 1e-4, 1e4);
        }
        rows.push_back(r);
      }
    }
  }
  catch (const std::invalid_argument& e)
  {
    fail(1, e.what());
  }

  const std::string plant_text = plant.type == analysis::PlantModel::Type::kPointMass ?
                                     "point (wheels follow the command)" :
                                     "first-order, time constant " + fmt(plant.time_constant) + " s";
  if (csv)
  {
    std::cout << "belief_rate_hz,action_rate_hz,integrator,spectral_radius,stable,rise_time_s,settling_time_s,"
                 "overshoot_percent,steady_state_error_mps,min_stable_tau_s,max_stable_k_mu,max_stable_k_a\n";
    for (const auto& r : rows)
    {
      const bool m = r.pred.stable && r.pred.velocity_valid;
      std::cout << r.belief_rate << "," << r.action_rate << "," << params::toString(r.integrator) << ","
                << fmt(r.pred.spectral_radius, 8) << "," << (r.pred.stable ? "true" : "false") << ","
                << (m ? fmt(r.pred.velocity.rise_time, 6) : "nan") << ","
                << (m ? fmt(r.pred.velocity.settling_time, 6) : "nan") << ","
                << (m ? fmt(r.pred.velocity.overshoot_percent, 6) : "nan") << ","
                << (m ? fmt(r.pred.velocity.steady_state_error, 6) : "nan") << ","
                << (r.scanned ? limitText(r.tau, true, true) : "nan") << ","
                << (r.scanned ? limitText(r.k_mu, false, true) : "nan") << ","
                << (r.scanned ? limitText(r.k_a, false, true) : "nan") << "\n";
    }
    return 0;
  }
  std::cout << "config: " << file << "\n"
            << "  tau = " << params.tau << " s, k_mu = " << params.k_mu << ", k_a = " << params.k_a
            << ", p = " << params.embedding_order << ", file rates " << params.belief_rate << " / "
            << params.action_rate << " Hz, file integrator " << params::toString(params.integrator) << "\n"
            << "  plant: " << plant_text << "; step of v_x 0 -> " << target << " m/s over " << duration << " s\n";
  {
    // Belief stiffness (doc/active_inference.md, 'Analysis notes'): Euler is stable only while
    // h * |lambda| < 2 for the fastest (real) mode of the continuous belief dynamics.
    const analysis::ClosedLoopModel m(params, plant);
    const Eigen::EigenSolver<Eigen::MatrixXd> es(m.M(), false);
    const double lambda_max = es.eigenvalues().cwiseAbs().maxCoeff();
    const double pi_mu0 = params.precisionMu().col(0).maxCoeff();
    std::cout << "  belief stiffness: order-0 gain k_mu * Pi_mu0 / tau^2 = "
              << fmt(params.k_mu * pi_mu0 / (params.tau * params.tau))
              << " 1/s; fastest mode of dmu/dt |lambda|max = " << fmt(lambda_max)
              << " 1/s -> Euler needs belief_rate > " << fmt(lambda_max / 2.0) << " Hz\n";
  }
  if (!defaulted.empty())
  {
    std::cout << "  keys not in the file (defaults used):";
    for (const auto& k : defaulted)
    {
      std::cout << " " << k;
    }
    std::cout << "\n";
  }
  std::cout << "\n";
  std::printf("%9s %9s %-7s %12s %-8s %9s %9s %9s %10s | %16s %16s %16s\n", "belief_Hz", "action_Hz", "integ",
              "spec_radius", "stable", "rise_s", "settle_s", "overshoot%", "ss_error", "min_tau", "max_k_mu",
              "max_k_a");
  for (const auto& r : rows)
  {
    const bool m = r.pred.stable && r.pred.velocity_valid;
    std::printf("%9g %9g %-7s %12s %-8s %9s %9s %9s %10s | %16s %16s %16s\n", r.belief_rate, r.action_rate,
                params::toString(r.integrator).c_str(), fmt(r.pred.spectral_radius, 6).c_str(),
                r.pred.stable ? "yes" : "NO", m ? fmt(r.pred.velocity.rise_time).c_str() : "-",
                m ? fmt(r.pred.velocity.settling_time).c_str() : "-",
                m ? fmt(r.pred.velocity.overshoot_percent).c_str() : "-",
                m ? fmt(r.pred.velocity.steady_state_error).c_str() : "-",
                r.scanned ? limitText(r.tau, true, false).c_str() : "-",
                r.scanned ? limitText(r.k_mu, false, false).c_str() : "-",
                r.scanned ? limitText(r.k_a, false, false).c_str() : "-");
  }
  std::cout << "\nspec_radius: per action period (stable < 1). rise 10-90 %, settling +-5 % of the set point, "
               "from the linear model (no clamp).\n"
               "min_tau / max_k_mu / max_k_a: stability limits with the other parameters as in the file "
               "(none = unstable over the whole scan range; A..B = stable only between A and B).\n";
  if (plant.type == analysis::PlantModel::Type::kPointMass)
  {
    std::cout << "note: with the point plant, y^(1) (finite differences of the wheel speeds = of a) feeds back into\n"
                 "      da/dt as a sampled derivative; it is unstable once k_a / var_y[1] exceeds ~1. A lagging wheel\n"
                 "      loop changes that: try --plant-time-constant 0.05 (the Jackal's small-step response, "
                 "doc/jackal.md).\n";
  }
  return 0;
}
