/**
 * \file param_server.cpp
 * \brief NodeParams from the parameter server through the parameter schema
 *        (doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_aic/ros/param_server.hpp"

#include <algorithm>
#include <sstream>

#include <ros/console.h>
#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "jackal_aic/analysis/configured_stability.hpp"

namespace jackal_aic
{
namespace node
{
namespace
{
template <class T>
params::ParamSource::Status readAs(const ros::NodeHandle& nh, const std::string& key, params::ParamValue* out)
{
  T value{};
  if (!nh.getParam(key, value))
  {
    return params::ParamSource::Status::kWrongType;
  }
  *out = value;
  return params::ParamSource::Status::kOk;
}
}  // namespace

params::ParamSource::Status RosParamSource::read(const std::string& key, params::ParamType type,
                                                 params::ParamValue* out) const
{
  if (!nh_.hasParam(key))
  {
    return Status::kMissing;
  }
  switch (type)
  {
    case params::ParamType::kDouble:
      return readAs<double>(nh_, key, out);
    case params::ParamType::kInt: {
      // roscpp's getParam(int&) rounds a double (2.5 -> 3) instead of failing: require an XML-RPC int.
      XmlRpc::XmlRpcValue raw;
      if (!nh_.getParam(key, raw) || raw.getType() != XmlRpc::XmlRpcValue::TypeInt)
      {
        return Status::kWrongType;
      }
      *out = static_cast<int>(raw);
      return Status::kOk;
    }
    case params::ParamType::kBool:
      return readAs<bool>(nh_, key, out);
    case params::ParamType::kString:
      return readAs<std::string>(nh_, key, out);
    case params::ParamType::kDoubleList:
      return readAs<std::vector<double>>(nh_, key, out);
    case params::ParamType::kStringList:
      return readAs<std::vector<std::string>>(nh_, key, out);
  }
  return Status::kWrongType;
}

std::string RosParamSource::raw(const std::string& key) const
{
  XmlRpc::XmlRpcValue raw;
  if (!nh_.getParam(key, raw))
  {
    return "<missing>";
  }
  std::ostringstream os;
  raw.write(os);
  return os.str();
}

std::vector<std::string> RosParamSource::keys() const
{
  std::vector<std::string> names;
  std::vector<std::string> out;
  if (!ros::param::getParamNames(names))
  {
    return out;
  }
  const std::string prefix = nh_.getNamespace() + "/";
  for (const auto& full : names)
  {
    if (full.compare(0, prefix.size(), prefix) != 0)
    {
      continue;
    }
    const std::string rest = full.substr(prefix.size());
    const std::string key = rest.substr(0, rest.find('/'));
    if (std::find(out.begin(), out.end(), key) == out.end())
    {
      out.push_back(key);
    }
  }
  return out;
}

void loadNodeParams(const ros::NodeHandle& pnh, params::NodeParams* params,
                    std::vector<params::ParamViolation>* violations)
{
  const RosParamSource source(pnh);
  const params::ParamLoadReport report = params::loadParams(
      source, { params::ParamScope::kController, params::ParamScope::kNode }, /*with_reconfigure=*/true, params);
  for (const auto& key : report.defaulted)
  {
    const params::ParamSpec* row = params::findParam(key);
    if (row != nullptr && !row->required)
    {
      ROS_INFO_STREAM("jackal_AIC: parameter ~" << key << " not set, using the default");
    }
  }
  violations->insert(violations->end(), report.errors.begin(), report.errors.end());
  for (const auto& key : report.unknown)
  {
    ROS_WARN_STREAM("jackal_AIC: unknown parameter ~" << key << " ignored (typo?)");
  }
  // One line, at INFO: the namespace holds every file's keys (a base's too, config/default.yaml's
  // robot-model keys under the goal model's overlay), so a listed key may be a base's, not a mistake.
  std::string without_effect;
  for (const params::ParamSpec* row : params::keysWithoutEffect(*params, source.keys()))
  {
    without_effect += (without_effect.empty() ? "" : "; ") + params::withoutEffectText(*row, *params);
  }
  if (!without_effect.empty())
  {
    ROS_INFO_STREAM("jackal_AIC: parameters set without effect: " << without_effect);
  }
}

bool loadValidNodeParams(const ros::NodeHandle& pnh, params::NodeParams* params)
{
  std::vector<params::ParamViolation> violations;
  loadNodeParams(pnh, params, &violations);
  for (auto& v : params->validate())
  {
    violations.push_back(std::move(v));
  }
  for (const auto& v : violations)
  {
    ROS_FATAL_STREAM("jackal_AIC: invalid parameter ~" << v.toString());
  }
  if (!violations.empty())
  {
    ROS_FATAL_STREAM("jackal_AIC: " << violations.size() << " invalid parameter(s) in " << pnh.getNamespace()
                                    << "; exiting");
  }
  return violations.empty();
}

bool warnIfUnstable(const params::AicParams& params, const std::string& what)
{
  const std::string warning = analysis::stabilityWarning(params);
  if (!warning.empty())
  {
    ROS_WARN_STREAM("jackal_AIC: " << what << "the configuration is " << warning
                                   << "; running it, the runaway reset guards the robot");
  }
  return !warning.empty();
}

}  // namespace node
}  // namespace jackal_aic
