#include "jackal_aic/ros/node_params.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <type_traits>

#include <ros/console.h>
#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace jackal_aic
{
namespace
{
std::string num(double v)
{
  std::ostringstream os;
  os << v;
  return os.str();
}

/// The raw value of a parameter, printed, for a violation message.
std::string rawValue(const ros::NodeHandle& pnh, const std::string& key)
{
  XmlRpc::XmlRpcValue raw;
  if (!pnh.getParam(key, raw))
  {
    return "<missing>";
  }
  std::ostringstream os;
  raw.write(os);
  return os.str();
}

/// Read `key` into `value` if present; a present key of the wrong type is a violation.
template <class T>
void read(const ros::NodeHandle& pnh, const std::string& key, T* value, const std::string& expected,
          std::vector<ParamViolation>* violations)
{
  if (!pnh.hasParam(key))
  {
    ROS_INFO_STREAM("jackal_AIC: parameter ~" << key << " not set, using the default");
    return;
  }
  if constexpr (std::is_same_v<T, int>)
  {
    // roscpp's getParam(int&) rounds a double (2.5 -> 3) instead of failing: require an XML-RPC int.
    XmlRpc::XmlRpcValue raw;
    if (!pnh.getParam(key, raw) || raw.getType() != XmlRpc::XmlRpcValue::TypeInt)
    {
      violations->push_back({ key, rawValue(pnh, key), expected });
      return;
    }
    *value = static_cast<int>(raw);
  }
  else if (!pnh.getParam(key, *value))
  {
    violations->push_back({ key, rawValue(pnh, key), expected });
  }
}

void requirePositive(const std::string& name, double value, std::vector<ParamViolation>* violations)
{
  if (!std::isfinite(value) || value <= 0.0)
  {
    violations->push_back({ name, num(value), "> 0 and finite" });
  }
}

void checkJointList(const std::string& name, const std::vector<std::string>& joints,
                    std::vector<ParamViolation>* violations)
{
  if (joints.empty())
  {
    violations->push_back({ name, "[]", "a non-empty list of joint names" });
    return;
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < joints.size(); ++i)
  {
    const std::string item = name + "[" + std::to_string(i) + "]";
    if (joints[i].empty())
    {
      violations->push_back({ item, "\"\"", "a non-empty joint name" });
    }
    else if (!seen.insert(joints[i]).second)
    {
      violations->push_back({ item, joints[i], "a name not listed twice" });
    }
  }
}

/// Keys the node reads (or that dynamic_reconfigure and diagnostic_updater write) in ~.
const std::set<std::string>& knownKeys()
{
  static const std::set<std::string> keys = {
    "belief_rate", "action_rate", "tau", "k_mu", "k_a", "embedding_order", "var_mu", "var_y",
    "wheel_radius", "slip_factor", "wheel_separation", "max_wheel_speed", "runaway_limit", "max_action_lead",
    "accel_in_model", "integrator", "sensor_timeout", "set_point_timeout", "imu_max_skew",
    "min_sample_interval", "max_linear_speed", "max_angular_speed", "runaway_hold_time",
    "left_joints", "right_joints", "diagnostic_period",
    // written by the dynamic_reconfigure server (cfg/AIC.cfg)
    "var_mu_0", "var_mu_1", "var_mu_2", "var_mu_3", "var_mu_4", "var_mu_5",
    "var_y_0", "var_y_1", "var_y_2", "var_y_3", "var_y_4", "var_y_5",
  };
  return keys;
}

void warnUnknownKeys(const ros::NodeHandle& pnh)
{
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names))
  {
    return;
  }
  const std::string prefix = pnh.getNamespace() + "/";
  for (const auto& full : names)
  {
    if (full.compare(0, prefix.size(), prefix) != 0)
    {
      continue;
    }
    std::string key = full.substr(prefix.size());
    key = key.substr(0, key.find('/'));
    if (knownKeys().count(key) == 0 && key.compare(0, 8, "groups") != 0)
    {
      ROS_WARN_STREAM("jackal_AIC: unknown parameter ~" << key << " ignored (typo?)");
    }
  }
}
}  // namespace

std::vector<ParamViolation> NodeParams::validate() const
{
  std::vector<ParamViolation> violations = aic.validate();
  if (std::isfinite(aic.belief_rate) && aic.belief_rate > kMaxLoopRate)
  {
    violations.push_back({ "belief_rate", num(aic.belief_rate), "<= " + num(kMaxLoopRate) + " Hz" });
  }
  if (std::isfinite(aic.action_rate) && aic.action_rate > kMaxLoopRate)
  {
    violations.push_back({ "action_rate", num(aic.action_rate), "<= " + num(kMaxLoopRate) + " Hz" });
  }
  requirePositive("sensor_timeout", sensor_timeout, &violations);
  requirePositive("set_point_timeout", set_point_timeout, &violations);
  requirePositive("imu_max_skew", imu_max_skew, &violations);
  requirePositive("max_linear_speed", max_linear_speed, &violations);
  requirePositive("max_angular_speed", max_angular_speed, &violations);
  if (!std::isfinite(min_sample_interval) || min_sample_interval < 0.0 ||
      (std::isfinite(sensor_timeout) && min_sample_interval >= sensor_timeout))
  {
    violations.push_back({ "min_sample_interval", num(min_sample_interval), ">= 0 and < sensor_timeout" });
  }
  if (!std::isfinite(runaway_hold_time) || runaway_hold_time < 0.0)
  {
    violations.push_back({ "runaway_hold_time", num(runaway_hold_time), ">= 0 and finite" });
  }
  checkJointList("left_joints", left_joints, &violations);
  checkJointList("right_joints", right_joints, &violations);
  for (const auto& name : left_joints)
  {
    for (const auto& other : right_joints)
    {
      if (!name.empty() && name == other)
      {
        violations.push_back({ "right_joints", name, "a joint not also in left_joints" });
      }
    }
  }
  return violations;
}

void loadNodeParams(const ros::NodeHandle& pnh, NodeParams* params, std::vector<ParamViolation>* violations)
{
  AicParams& aic = params->aic;
  const std::string number = "a number";
  read(pnh, "belief_rate", &aic.belief_rate, number, violations);
  read(pnh, "action_rate", &aic.action_rate, number, violations);
  read(pnh, "tau", &aic.tau, number, violations);
  read(pnh, "k_mu", &aic.k_mu, number, violations);
  read(pnh, "k_a", &aic.k_a, number, violations);
  read(pnh, "embedding_order", &aic.embedding_order, "an integer", violations);
  read(pnh, "var_mu", &aic.var_mu, "a list of numbers", violations);
  read(pnh, "var_y", &aic.var_y, "a list of numbers", violations);
  read(pnh, "wheel_radius", &aic.wheel_radius, number, violations);
  read(pnh, "slip_factor", &aic.slip_factor, number, violations);
  read(pnh, "wheel_separation", &aic.wheel_separation, number, violations);
  read(pnh, "max_wheel_speed", &aic.max_wheel_speed, number, violations);
  read(pnh, "runaway_limit", &aic.runaway_limit, number, violations);
  read(pnh, "max_action_lead", &aic.max_action_lead, number, violations);
  read(pnh, "accel_in_model", &aic.accel_in_model, "true or false", violations);
  std::string integrator = toString(aic.integrator);
  read(pnh, "integrator", &integrator, "euler or exact", violations);
  if (!integratorFromString(integrator, &aic.integrator))
  {
    violations->push_back({ "integrator", integrator, "euler or exact" });
  }

  read(pnh, "sensor_timeout", &params->sensor_timeout, number, violations);
  read(pnh, "set_point_timeout", &params->set_point_timeout, number, violations);
  read(pnh, "imu_max_skew", &params->imu_max_skew, number, violations);
  read(pnh, "min_sample_interval", &params->min_sample_interval, number, violations);
  read(pnh, "max_linear_speed", &params->max_linear_speed, number, violations);
  read(pnh, "max_angular_speed", &params->max_angular_speed, number, violations);
  read(pnh, "runaway_hold_time", &params->runaway_hold_time, number, violations);

  const std::string names = "a non-empty list of joint names";
  for (const auto& key : { std::string("left_joints"), std::string("right_joints") })
  {
    auto* list = key == "left_joints" ? &params->left_joints : &params->right_joints;
    // A missing key leaves the list empty, which validate() reports as a violation.
    if (pnh.hasParam(key) && !pnh.getParam(key, *list))
    {
      violations->push_back({ key, rawValue(pnh, key), names });
    }
  }
  warnUnknownKeys(pnh);
}

}  // namespace jackal_aic
