/**
 * \file pi_params_yaml.cpp
 * \brief The classical peer's settings from YAML (jackal_tools/pi_params_yaml.hpp).
 */
#include "jackal_tools/pi_params_yaml.hpp"

#include <map>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "jackal_tools/params_yaml.hpp"

namespace jackal_aic
{
namespace
{
/// The number at `node`, or a runtime_error naming the file and the key.
double number(const YAML::Node& node, const std::string& file, const std::string& key)
{
  try
  {
    if (node.IsScalar())
    {
      return node.as<double>();
    }
  }
  catch (const YAML::Exception&)
  {
  }
  throw std::runtime_error(file + ": key '" + key + "' must be a number");
}
}  // namespace

classical::PiControllerParams loadPiParams(const std::string& file, const std::vector<std::string>& overrides)
{
  const YAML::Node root = readYamlMap(file, overrides);
  classical::PiControllerParams p;
  const std::map<std::string, double*> scalars = {
    { "period", &p.period },
    { "rest_linear", &p.rest_linear },
    { "rest_angular", &p.rest_angular },
    { "wheel_radius", &p.wheel_radius },
    { "wheel_separation", &p.wheel_separation },
    { "max_wheel_speed", &p.max_wheel_speed },
    { "goal_rate_hold", &p.goal_rate_hold },
    { "max_goal_rate_linear", &p.max_goal_rate_linear },
    { "max_goal_rate_angular", &p.max_goal_rate_angular },
  };
  const std::map<std::string, std::map<std::string, double*>> maps = {
    { "wheel", { { "kp", &p.wheel.kp }, { "ki", &p.wheel.ki } } },
    { "yaw", { { "kp", &p.yaw.kp }, { "ki", &p.yaw.ki } } },
    { "robot",
      { { "latency", &p.robot.latency },
        { "wheel_time_constant", &p.robot.wheel_time_constant },
        { "wheel_acceleration", &p.robot.wheel_acceleration },
        { "yaw_time_constant", &p.robot.yaw_time_constant } } },
  };
  for (const auto& kv : root)
  {
    const std::string key = kv.first.as<std::string>();
    if (const auto s = scalars.find(key); s != scalars.end())
    {
      *s->second = number(kv.second, file, key);
      continue;
    }
    const auto m = maps.find(key);
    if (m == maps.end() || !kv.second.IsMap())
    {
      throw std::runtime_error(file + ": unknown key '" + key + "'" +
                               (m == maps.end() ? std::string() : " (expected a map)"));
    }
    for (const auto& inner : kv.second)
    {
      const std::string name = inner.first.as<std::string>();
      const auto field = m->second.find(name);
      if (field == m->second.end())
      {
        throw std::runtime_error(file + ": unknown key '" + key + "." + name + "'");
      }
      *field->second = number(inner.second, file, key + "." + name);
    }
  }
  const std::vector<std::string> violations = p.validate();
  if (!violations.empty())
  {
    std::string msg = file + ": invalid parameters:";
    for (const std::string& v : violations)
    {
      msg += " " + v + ";";
    }
    throw std::runtime_error(msg);
  }
  return p;
}

}  // namespace jackal_aic
