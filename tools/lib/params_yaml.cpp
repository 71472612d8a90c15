/**
 * \file params_yaml.cpp
 * \brief AicParams from a YAML file through the parameter schema (doc/jackal_aic_node.md,
 *        'Parameters').
 */
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/share_path.hpp"

#include <iostream>
#include <sstream>
#include <stdexcept>

#include "jackal_aic/analysis/configured_stability.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"

namespace jackal_aic
{
namespace
{
template <class T>
params::ParamSource::Status readAs(const YAML::Node& n, params::ParamValue* out)
{
  try
  {
    *out = n.as<T>();
    return params::ParamSource::Status::kOk;
  }
  catch (const YAML::Exception&)
  {
    return params::ParamSource::Status::kWrongType;
  }
}
}  // namespace

params::ParamSource::Status YamlParamSource::read(const std::string& key, params::ParamType type,
                                                  params::ParamValue* out) const
{
  const YAML::Node n = root_.IsMap() ? root_[key] : YAML::Node();
  if (!n)
  {
    return Status::kMissing;
  }
  switch (type)
  {
    case params::ParamType::kDouble:
      return readAs<double>(n, out);
    case params::ParamType::kInt:
      return readAs<int>(n, out);
    case params::ParamType::kBool:
      return readAs<bool>(n, out);
    case params::ParamType::kString:
      return n.IsScalar() ? readAs<std::string>(n, out) : Status::kWrongType;
    case params::ParamType::kDoubleList:
      return readAs<std::vector<double>>(n, out);
    case params::ParamType::kStringList:
      return readAs<std::vector<std::string>>(n, out);
  }
  return Status::kWrongType;
}

std::string YamlParamSource::raw(const std::string& key) const
{
  const YAML::Node n = root_.IsMap() ? root_[key] : YAML::Node();
  if (!n)
  {
    return "<missing>";
  }
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}

std::vector<std::string> YamlParamSource::keys() const
{
  std::vector<std::string> out;
  if (root_.IsMap())
  {
    for (const auto& kv : root_)
    {
      out.push_back(kv.first.as<std::string>());
    }
  }
  return out;
}

params::AicParams aicParamsFromYaml(const YAML::Node& root, const std::string& file,
                                    std::vector<std::string>* defaulted, std::vector<std::string>* unknown)
{
  params::NodeParams params;
  const params::ParamLoadReport report = params::loadParams(YamlParamSource(root), { params::ParamScope::kController },
                                                            /*with_reconfigure=*/false, &params);
  if (!report.errors.empty())
  {
    const params::ParamViolation& e = report.errors.front();
    throw std::runtime_error(file + ": key '" + e.name + "' must be " + e.allowed + " (got " + e.value + ")");
  }
  if (defaulted)
  {
    *defaulted = report.defaulted;
  }
  if (unknown)
  {
    *unknown = report.unknown;
  }
  return params.aic;
}

YAML::Node readYamlMap(const std::string& file, const std::vector<std::string>& overrides)
{
  YAML::Node root;
  try
  {
    root = YAML::LoadFile(resolveDataFile(file));
    if (root.IsNull())
    {
      throw std::runtime_error(file + ": no parameters (the file is empty or holds only comments)");
    }
    if (!root.IsMap())
    {
      throw std::runtime_error(file + ": expected a map of parameters at the top level");
    }
    overrides::applyOverrides(root, overrides);
  }
  catch (const YAML::BadFile&)
  {
    throw std::runtime_error("cannot read '" + file + "'");
  }
  catch (const YAML::Exception& e)
  {
    throw std::runtime_error(file + ": YAML error: " + e.what());
  }
  catch (const std::invalid_argument& e)
  {
    throw std::runtime_error(file + ": " + e.what());
  }
  return root;
}

namespace
{
/// What the values came from, for messages: "<what>", or "<what> with --aic-set K=V, ..." when
/// overrides were applied (so an error they cause does not read as the file's).
std::string sourceName(const std::string& what, const std::vector<std::string>& overrides)
{
  std::string name = what;
  for (std::size_t i = 0; i < overrides.size(); ++i)
  {
    name += (i == 0 ? " with --aic-set " : ", ") + overrides[i];
  }
  return name;
}

/// Throws "<file>: invalid parameters: ..." listing every violation, if any.
void requireValid(const std::vector<params::ParamViolation>& violations, const std::string& file)
{
  if (!violations.empty())
  {
    std::string msg = file + ": invalid parameters:";
    for (const auto& v : violations)
    {
      msg += " " + v.toString() + ";";
    }
    throw std::runtime_error(msg);
  }
}
}  // namespace

params::AicParams loadAicParams(const std::string& file, const std::vector<std::string>& overrides)
{
  const params::AicParams p =
      aicParamsFromYaml(readYamlMap(file, overrides), sourceName(file, overrides), nullptr, nullptr);
  requireValid(p.validate(), sourceName(file, overrides));
  return p;
}

params::NodeParams loadNodeParamsFiles(const std::vector<std::string>& files, const std::vector<std::string>& overrides,
                                       bool warn)
{
  params::NodeParams params;
  std::string names;
  std::vector<std::string> set_keys;  // the keys the last file and the overrides set: the user's layer
  for (std::size_t i = 0; i < files.size(); ++i)
  {
    const std::string& file = files[i];
    const std::vector<std::string>& applied = i + 1 == files.size() ? overrides : std::vector<std::string>();
    const YAML::Node root = readYamlMap(file, applied);
    const YamlParamSource source(root);
    if (i + 1 == files.size())
    {
      set_keys = source.keys();
    }
    const params::ParamLoadReport report = params::loadParams(
        source, { params::ParamScope::kController, params::ParamScope::kNode }, /*with_reconfigure=*/false, &params);
    if (!report.errors.empty())
    {
      const params::ParamViolation& e = report.errors.front();
      throw std::runtime_error(sourceName(file, applied) + ": key '" + e.name + "' must be " + e.allowed + " (got " +
                               e.value + ")");
    }
    names += (names.empty() ? "" : " + ") + file;
  }
  // The joint lists may be left to the caller (the simulator's wheels): check the rest.
  params::NodeParams check = params;
  if (check.left_joints.empty() && check.right_joints.empty())
  {
    check.left_joints = { "left" };
    check.right_joints = { "right" };
  }
  requireValid(check.validate(), sourceName(names, overrides));
  if (!warn)
  {
    return params;
  }
  const std::string unstable = analysis::stabilityWarning(params.aic);
  if (!unstable.empty())
  {
    std::cerr << sourceName(names, overrides) << ": warning: the configuration is " << unstable << "\n";
  }
  // The last file's keys only: a base (config/default.yaml's robot-model keys under the goal model's
  // overlay) is not the layer being written.
  for (const params::ParamSpec* row : params::keysWithoutEffect(params, set_keys))
  {
    std::cerr << sourceName(names, overrides) << ": warning: " << params::withoutEffectText(*row, params) << "\n";
  }
  return params;
}

}  // namespace jackal_aic
