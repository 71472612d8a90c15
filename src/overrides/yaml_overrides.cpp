/**
 * \file yaml_overrides.cpp
 * \brief "KEY=VALUE" overrides on top of a YAML tree (include/jackal_aic/overrides/yaml_overrides.hpp).
 */
#include "jackal_aic/overrides/yaml_overrides.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace jackal_aic
{
namespace overrides
{
namespace
{
std::vector<std::string> keyParts(const std::string& key)
{
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string part; std::getline(ss, part, '.');)
  {
    parts.push_back(part);
  }
  if (!key.empty() && key.back() == '.')
  {
    parts.emplace_back();
  }
  return parts;
}

void flatten(const YAML::Node& node, const std::string& prefix, const std::string& source,
             std::vector<std::string>* out)
{
  for (const auto& kv : node)
  {
    const std::string key = kv.first.as<std::string>();
    if (key.empty() || key.find('=') != std::string::npos || key.find('.') != std::string::npos)
    {
      throw std::invalid_argument("overlay '" + source + "': key '" + key + "' contains '=' or '.'");
    }
    const std::string dotted = prefix.empty() ? key : prefix + "." + key;
    if (kv.second.IsMap())
    {
      flatten(kv.second, dotted, source, out);
      continue;
    }
    YAML::Emitter e;
    e << YAML::Flow << kv.second;
    out->push_back(dotted + "=" + (kv.second.IsNull() ? std::string("null") : std::string(e.c_str())));
  }
}
}  // namespace

Override parseOverride(const std::string& text)
{
  const auto eq = text.find('=');
  const std::string key = eq == std::string::npos ? std::string() : text.substr(0, eq);
  bool ok = !key.empty();
  for (const auto& part : keyParts(key))
  {
    ok = ok && !part.empty();
  }
  if (!ok)
  {
    throw std::invalid_argument("override '" + text + "' is not of the form key=value");
  }
  return { key, text.substr(eq + 1) };
}

void applyOverrides(YAML::Node root, const std::vector<std::string>& overrides)
{
  std::vector<std::pair<std::vector<std::string>, YAML::Node>> parsed;
  for (const std::string& text : overrides)
  {
    const Override o = parseOverride(text);
    YAML::Node value;
    try
    {
      value = YAML::Load(o.value);
    }
    catch (const YAML::Exception&)
    {
      throw std::invalid_argument("override '" + text + "' has a malformed value");
    }
    parsed.emplace_back(keyParts(o.key), value);
  }
  for (const auto& [parts, value] : parsed)
  {
    // Walk with fresh handles (yaml-cpp node assignment rebinds).
    std::vector<YAML::Node> chain{ root };
    for (std::size_t i = 0; i + 1 < parts.size(); ++i)
    {
      YAML::Node next = chain.back()[parts[i]];
      chain.push_back(next);
    }
    chain.back()[parts.back()] = value;
  }
}

std::vector<std::string> overlayOverrides(const YAML::Node& overlay, const std::string& source)
{
  std::vector<std::string> out;
  if (!overlay || overlay.IsNull())
  {
    return out;
  }
  if (!overlay.IsMap())
  {
    throw std::invalid_argument("overlay '" + source + "' must be a YAML map");
  }
  flatten(overlay, "", source, &out);
  return out;
}

std::vector<std::string> loadOverlayFile(const std::string& path)
{
  std::ifstream in(path);
  if (!in.good())
  {
    throw std::invalid_argument("overlay '" + path + "' does not exist or cannot be read");
  }
  std::stringstream ss;
  ss << in.rdbuf();
  YAML::Node root;
  try
  {
    root = YAML::Load(ss.str());
  }
  catch (const YAML::Exception& ex)
  {
    throw std::invalid_argument("overlay '" + path + "' is malformed YAML: " + ex.what());
  }
  return overlayOverrides(root, path);
}

}  // namespace overrides
}  // namespace jackal_aic
