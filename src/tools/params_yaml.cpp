#include "jackal_aic/params_yaml.hpp"

#include <set>
#include <stdexcept>
#include <type_traits>

namespace jackal_aic
{
AicParams aicParamsFromYaml(const YAML::Node& root, const std::string& file, std::vector<std::string>* defaulted,
                            std::vector<std::string>* unknown)
{
  // Keys of the node's private namespace that are not controller parameters (NodeParams; diagnostic_updater).
  static const std::set<std::string> kNodeOnly{ "sensor_timeout",    "set_point_timeout", "imu_max_skew",
                                                "min_sample_interval", "max_linear_speed",  "max_angular_speed",
                                                "runaway_hold_time", "left_joints",       "right_joints",
                                                "diagnostic_period" };
  AicParams p;
  std::set<std::string> seen;
  // Reads `key` into *out if present (otherwise the key is recorded as defaulted and false returned);
  // a value that is not a T throws "<file>: key '<key>' must be <expected>".
  auto get = [&](const char* key, auto* out, const char* expected) {
    seen.insert(key);
    const YAML::Node n = root[key];
    if (!n)
    {
      if (defaulted)
      {
        defaulted->push_back(key);
      }
      return false;
    }
    try
    {
      *out = n.as<std::remove_pointer_t<decltype(out)>>();
    }
    catch (const YAML::Exception&)
    {
      throw std::runtime_error(file + ": key '" + key + "' must be " + expected);
    }
    return true;
  };
  const char* const number = "a number";
  get("belief_rate", &p.belief_rate, number);
  get("action_rate", &p.action_rate, number);
  get("tau", &p.tau, number);
  get("k_mu", &p.k_mu, number);
  get("k_a", &p.k_a, number);
  get("embedding_order", &p.embedding_order, "an integer");
  get("var_mu", &p.var_mu, "a list of numbers");
  get("var_y", &p.var_y, "a list of numbers");
  get("wheel_radius", &p.wheel_radius, number);
  get("slip_factor", &p.slip_factor, number);
  get("wheel_separation", &p.wheel_separation, number);
  get("max_wheel_speed", &p.max_wheel_speed, number);
  get("runaway_limit", &p.runaway_limit, number);
  get("max_action_lead", &p.max_action_lead, number);
  get("accel_in_model", &p.accel_in_model, "true or false");
  std::string name;
  if (get("integrator", &name, "a string") && !integratorFromString(name, &p.integrator))
  {
    throw std::runtime_error(file + ": integrator '" + name + "' (allowed: euler, exact)");
  }
  for (const auto& kv : root)
  {
    const std::string key = kv.first.as<std::string>();
    if (!seen.count(key) && !kNodeOnly.count(key) && unknown)
    {
      unknown->push_back(key);
    }
  }
  return p;
}

AicParams loadAicParams(const std::string& file, const std::vector<std::string>& overrides)
{
  YAML::Node root;
  try
  {
    root = YAML::LoadFile(file);
    if (!root.IsMap())
    {
      throw std::runtime_error(file + ": expected a map of parameters at the top level");
    }
    for (const std::string& o : overrides)
    {
      const auto eq = o.find('=');
      if (eq == std::string::npos || eq == 0)
      {
        throw std::runtime_error("override '" + o + "' is not key=value");
      }
      root[o.substr(0, eq)] = YAML::Load(o.substr(eq + 1));
    }
  }
  catch (const YAML::BadFile&)
  {
    throw std::runtime_error("cannot read '" + file + "'");
  }
  catch (const YAML::Exception& e)
  {
    throw std::runtime_error(file + ": YAML error: " + e.what());
  }
  AicParams p = aicParamsFromYaml(root, file, nullptr, nullptr);
  const auto violations = p.validate();
  if (!violations.empty())
  {
    std::string msg = file + ": invalid parameters:";
    for (const auto& v : violations)
    {
      msg += " " + v.toString() + ";";
    }
    throw std::runtime_error(msg);
  }
  return p;
}

}  // namespace jackal_aic
