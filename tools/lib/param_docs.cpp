/**
 * \file param_docs.cpp
 * \brief cfg/AIC.cfg, the parameter table and a YAML template, generated from the schema
 *        (tools/include/jackal_tools/param_docs.hpp; doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_tools/param_docs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "jackal_aic/params/param_schema.hpp"

namespace jackal_aic
{
namespace
{
/// A Python string literal.
std::string pyString(const std::string& s)
{
  std::string out = "\"";
  for (char c : s)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
    }
    out += c;
  }
  return out + "\"";
}

/// A Python literal of a reconfigure value (floats keep a '.' or an exponent).
std::string pyValue(const params::ParamValue& v)
{
  if (const bool* b = std::get_if<bool>(&v))
  {
    return *b ? "True" : "False";
  }
  if (const int* i = std::get_if<int>(&v))
  {
    return std::to_string(*i);
  }
  if (const double* d = std::get_if<double>(&v))
  {
    std::string s = shortestDecimal(*d);
    if (s.find_first_of(".e") == std::string::npos)
    {
      s += ".0";
    }
    return s;
  }
  return pyString(std::get<std::string>(v));
}

const char* cfgType(params::ParamType t)
{
  switch (t)
  {
    case params::ParamType::kInt:
      return "int_t";
    case params::ParamType::kBool:
      return "bool_t";
    case params::ParamType::kString:
      return "str_t";
    default:
      return "double_t";
  }
}

std::string typeText(const params::ParamSpec& s)
{
  switch (s.type)
  {
    case params::ParamType::kDouble:
      return "double";
    case params::ParamType::kInt:
      return "int";
    case params::ParamType::kBool:
      return "bool";
    case params::ParamType::kString:
      return "string";
    case params::ParamType::kDoubleList:
      return "double list";
    case params::ParamType::kStringList:
      return "string list";
  }
  return "";
}

/// A value for the docs: numbers in their shortest form, lists as [a, b].
std::string docValue(const params::ParamValue& v)
{
  if (const double* d = std::get_if<double>(&v))
  {
    return shortestDecimal(*d);
  }
  if (const auto* list = std::get_if<std::vector<double>>(&v))
  {
    std::string out = "[";
    for (std::size_t i = 0; i < list->size(); ++i)
    {
      out += (i ? ", " : "") + shortestDecimal((*list)[i]);
    }
    return out + "]";
  }
  return params::formatParamValue(v);
}

/// A Markdown table cell: '|' escaped.
std::string cell(const std::string& text)
{
  std::string out;
  for (char c : text)
  {
    out += c == '|' ? std::string("\\|") : std::string(1, c);
  }
  return out;
}

std::string rangeDoc(const params::ParamSpec& s)
{
  if (s.type == params::ParamType::kDoubleList && s.channels > 0)
  {
    return "p+1 or " + std::to_string(s.channels) + "(p+1) values, each " + params::rangeText(s);
  }
  if (s.node_max < s.max)
  {
    return params::rangeText(s) + "; the node: <= " + shortestDecimal(s.node_max);
  }
  return params::rangeText(s);
}
}  // namespace

std::string shortestDecimal(double value)
{
  if (std::isnan(value))
  {
    return "nan";
  }
  if (std::isinf(value))
  {
    return value > 0 ? "inf" : "-inf";
  }
  if (value == std::floor(value) && std::abs(value) < 1e7)
  {
    return std::to_string(static_cast<long long>(value));
  }
  std::string text;
  for (int precision = 1; precision <= 17; ++precision)
  {
    std::ostringstream os;
    os.precision(precision);
    os << value;
    text = os.str();
    if (std::strtod(text.c_str(), nullptr) == value)
    {
      break;
    }
  }
  // "1e+06" -> "1e6", "1e-06" -> "1e-6" (both read back the same in C++ and Python).
  const auto e = text.find('e');
  if (e != std::string::npos)
  {
    std::string mantissa = text.substr(0, e);
    std::string exponent = text.substr(e + 1);
    const bool negative = !exponent.empty() && exponent[0] == '-';
    if (!exponent.empty() && (exponent[0] == '+' || exponent[0] == '-'))
    {
      exponent.erase(0, 1);
    }
    exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
    text = mantissa + "e" + (negative ? "-" : "") + exponent;
  }
  return text;
}

std::string reconfigureCfgScript()
{
  std::ostringstream os;
  os << "#!/usr/bin/env python3\n"
        "# Live-tunable parameters of the jackal_AIC node (dynamic_reconfigure).\n"
        "#\n"
        "# GENERATED from the parameter schema (src/params/param_schema.cpp): do not edit; run\n"
        "#   aic_params --cfg > cfg/AIC.cfg\n"
        "# test/unit/params/test_param_schema.cpp fails while this file differs from the schema, and\n"
        "# test/ros/test_reconfigure_config.cpp compares the generated AICConfig with it.\n"
        "#\n"
        "# Ranges are the schema's, so every value the node accepts can be shown and no valid\n"
        "# value is clamped. Only the keys a request changes are applied; the whole set is then\n"
        "# validated (AicParams::validate() plus the node's rules); an invalid set is refused,\n"
        "# logged, and the previous values are restored. Accepted changes are applied between\n"
        "# two timer ticks. Variances are offered per generalized order (var_mu_i, var_y_i for\n"
        "# i = 0..5; only 0..embedding_order are used); they can be changed only while the YAML\n"
        "# gives one variance per order (p+1 values), not the per-channel form. Joint names and\n"
        "# min_sample_interval are not reconfigurable.\n"
        "PACKAGE = \"jackal_aic\"\n\n"
        "from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, double_t, int_t, bool_t, "
        "str_t\n\n"
        "gen = ParameterGenerator()\n";
  std::vector<std::string> groups;
  std::string current_group;
  for (const params::ReconfigureEntry& e : params::reconfigureEntries())
  {
    const std::string group = e.row->group;
    bool known = false;
    for (const auto& g : groups)
    {
      known = known || g == group;
    }
    if (!known)
    {
      groups.push_back(group);
      os << "\n" << group << " = gen.add_group(" << pyString(group) << ")\n";
    }
    os << group << ".add(" << pyString(e.name) << ", " << cfgType(e.type) << ", " << e.row->level << ", "
       << pyString(e.description) << ", " << pyValue(e.default_value);
    if (e.type == params::ParamType::kDouble || e.type == params::ParamType::kInt)
    {
      const params::ParamValue min = e.type == params::ParamType::kInt ?
                                         params::ParamValue(static_cast<int>(e.row->min)) :
                                         params::ParamValue(e.row->min);
      os << ", " << pyValue(min);
      if (std::isfinite(e.row->nodeMax()))
      {
        const params::ParamValue max = e.type == params::ParamType::kInt ?
                                           params::ParamValue(static_cast<int>(e.row->nodeMax())) :
                                           params::ParamValue(e.row->nodeMax());
        os << ", " << pyValue(max);
      }
    }
    os << ")\n";
  }
  os << "\nexit(gen.generate(PACKAGE, \"jackal_aic_node\", \"AIC\"))\n";
  return os.str();
}

namespace
{
/// The table's "belief models" cell: "all", or the models that read the key (ParamSpec::models).
std::string modelsCell(const params::ParamSpec& s)
{
  return s.models == params::kAllBeliefModels ? std::string("all") : params::beliefModelsText(s.models);
}

/**
 * \brief The YAML comment's note on who reads a key that not every belief model reads: " Read by
 *        belief_model goal and unbiased only." and, where \p values selects another model, " No
 *        effect with belief_model robot."; "" for a key every model reads.
 */
std::string modelsNote(const params::ParamSpec& s, const params::NodeParams* values)
{
  if (s.models == params::kAllBeliefModels)
  {
    return "";
  }
  std::string note = " Read by belief_model " + params::beliefModelsText(s.models) + " only.";
  if (values != nullptr && !s.readBy(values->aic.belief_model))
  {
    note += " No effect with belief_model " + params::toString(values->aic.belief_model) + ".";
  }
  return note;
}
}  // namespace

std::string parameterTableMarkdown()
{
  std::ostringstream os;
  os << "| key | type | default | allowed | unit | live | belief models | meaning |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (const params::ParamSpec& s : params::paramSchema())
  {
    std::string live = s.live ? "yes" : "no";
    if (s.live && s.slots() > 0)
    {
      live = "per order: `" + std::string(s.key) + "_0`..`" + s.key + "_" + std::to_string(s.slots() - 1) + "`";
    }
    std::string key = std::string("`") + s.key + "`";
    if (s.scope == params::ParamScope::kNode)
    {
      key += " (node)";
    }
    const std::string range = cell(rangeDoc(s));
    os << "| " << key << " | " << typeText(s) << " | " << (s.required ? "required" : docValue(params::defaultValue(s)))
       << " | " << range << " | " << s.unit << " | " << live << " | " << modelsCell(s) << " | " << cell(s.description)
       << " |\n";
  }
  return os.str();
}

namespace
{
/// A value as YAML: docValue(), an empty string quoted.
std::string yamlValue(const params::ParamValue& v)
{
  const std::string text = docValue(v);
  return text.empty() ? std::string("\"\"") : text;
}
}  // namespace

std::string parameterYaml(const params::NodeParams* values, const std::vector<std::string>& files)
{
  std::ostringstream os;
  if (values == nullptr)
  {
    os << "# Every parameter of the jackal_AIC node with its default: what the node uses for a key that\n"
          "# no YAML sets (generated from the schema by `aic_params --yaml`; doc/jackal_aic_node.md,\n"
          "# 'Parameters'). Keys marked (node) are read by the node only; the tools (aic_analyze,\n"
          "# closed_loop_run) ignore them.\n";
  }
  else
  {
    os << "# Every parameter of the jackal_AIC node as the node reads";
    for (std::size_t i = 0; i < files.size(); ++i)
    {
      os << (i == 0 ? " " : ", then ") << files[i];
    }
    os << "\n# over the schema's defaults (`aic_params --yaml --config FILE ...`). Keys marked (node) are read\n"
          "# by the node only.\n";
  }
  std::string group;
  for (const params::ParamSpec& s : params::paramSchema())
  {
    if (s.group != group)
    {
      group = s.group;
      os << "\n# ---- " << group << " " << std::string(group.size() < 80 ? 80 - group.size() : 0, '-') << "\n";
    }
    os << "\n# [" << s.unit << "] " << s.description << (s.scope == params::ParamScope::kNode ? " (node)" : "")
       << ".\n# Allowed: " << rangeDoc(s) << ". "
       << (s.required ? std::string("Required: no default.") : "Default: " + docValue(params::defaultValue(s)))
       << modelsNote(s, values) << "\n";
    const params::ParamValue v = values != nullptr ? s.get(*values) : params::defaultValue(s);
    const auto* list = std::get_if<std::vector<std::string>>(&v);
    if (s.required && (list == nullptr || list->empty()))
    {
      os << "# " << s.key << ": [...]\n";
    }
    else
    {
      os << s.key << ": " << yamlValue(v) << "\n";
    }
  }
  return os.str();
}

std::string parameterYamlTemplate()
{
  return parameterYaml(nullptr, {});
}

}  // namespace jackal_aic
