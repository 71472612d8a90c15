/**
 * \file node_reconfigure.cpp
 * \brief dynamic_reconfigure of the jackal_AIC node through the parameter schema
 *        (include/jackal_aic/ros/node_reconfigure.hpp; doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_aic/ros/node_reconfigure.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

#include <boost/bind/bind.hpp>
#include <ros/console.h>

#include "jackal_aic/ros/param_server.hpp"

namespace jackal_aic
{
namespace node
{
namespace
{
using Description = AICConfig::AbstractParamDescription;

const Description& describe(const std::string& name)
{
  static const std::map<std::string, AICConfig::AbstractParamDescriptionConstPtr> by_name = [] {
    std::map<std::string, AICConfig::AbstractParamDescriptionConstPtr> m;
    for (const auto& d : AICConfig::__getParamDescriptions__())
    {
      m[d->name] = d;
    }
    return m;
  }();
  const auto it = by_name.find(name);
  if (it == by_name.end())
  {
    throw std::out_of_range("cfg/AIC.cfg has no parameter '" + name + "'");
  }
  return *it->second;
}

/// The member of `config` that a description points to, if it is of type T.
template <class T>
const T* fieldOf(const AICConfig& config, const Description& d)
{
  const auto* typed = dynamic_cast<const AICConfig::ParamDescription<T>*>(&d);
  return typed ? &(config.*(typed->field)) : nullptr;
}

template <class T>
bool setField(AICConfig* config, const Description& d, const params::ParamValue& value)
{
  const auto* typed = dynamic_cast<const AICConfig::ParamDescription<T>*>(&d);
  const T* v = std::get_if<T>(&value);
  if (typed == nullptr || v == nullptr)
  {
    return false;
  }
  config->*(typed->field) = *v;
  return true;
}

bool perOrder(const params::AicParams& a)
{
  const auto orders = static_cast<std::size_t>(a.numOrders());
  return a.var_mu.size() == orders && a.var_y.size() == orders;
}
}  // namespace

params::ParamValue configValue(const AICConfig& config, const std::string& name)
{
  const Description& d = describe(name);
  if (const double* v = fieldOf<double>(config, d))
  {
    return *v;
  }
  if (const int* v = fieldOf<int>(config, d))
  {
    return *v;
  }
  if (const bool* v = fieldOf<bool>(config, d))
  {
    return *v;
  }
  return *fieldOf<std::string>(config, d);  // the generator's fourth and last type
}

void setConfigValue(AICConfig* config, const std::string& name, const params::ParamValue& value)
{
  const Description& d = describe(name);
  if (!setField<double>(config, d, value) && !setField<int>(config, d, value) && !setField<bool>(config, d, value) &&
      !setField<std::string>(config, d, value))
  {
    throw std::invalid_argument("cfg parameter '" + name + "' cannot take the value " +
                                params::formatParamValue(value));
  }
}

AICConfig configFromParams(const params::NodeParams& params, const AICConfig& base)
{
  AICConfig c = base;
  const int orders = params.aic.numOrders();
  for (const params::ReconfigureEntry& e : params::reconfigureEntries())
  {
    if (e.slot < 0)
    {
      setConfigValue(&c, e.name, e.row->get(params));
      continue;
    }
    // Per-order variances; with the per-channel form, the first channel of each order is shown.
    const auto list = std::get<std::vector<double>>(e.row->get(params));
    const std::size_t stride = list.size() == static_cast<std::size_t>(orders) ? 1 : e.row->channels;
    const std::size_t index = static_cast<std::size_t>(e.slot) * stride;
    if (e.slot < orders && index < list.size())
    {
      setConfigValue(&c, e.name, list[index]);
    }
  }
  return c;
}

ReconfigureOutcome paramsFromRequest(const AICConfig& request, const AICConfig& shown, const params::NodeParams& base)
{
  AICConfig reference = shown;
  reference.__clamp__();  // what the server made of the keys the request did not carry
  ReconfigureOutcome out{ base, {}, {} };
  bool lists_touched = false;
  std::vector<bool> slot_changed;
  for (const params::ReconfigureEntry& e : params::reconfigureEntries())
  {
    const params::ParamValue value = configValue(request, e.name);
    if (value == configValue(reference, e.name))
    {
      continue;
    }
    out.changed.push_back(e.name);
    if (e.slot >= 0 || e.row->key == std::string("embedding_order"))
    {
      lists_touched = true;
    }
    if (e.slot < 0 && !e.row->set(out.params, value))
    {
      out.violations.push_back({ e.name, params::formatParamValue(value), params::expectedText(*e.row) });
    }
  }
  if (lists_touched && !perOrder(base.aic))
  {
    out.violations.push_back({ "var_mu/var_y/embedding_order", "changed live",
                               "unchanged while the YAML gives per-channel variances (edit the YAML instead)" });
  }
  else if (lists_touched)
  {
    const int orders = out.params.aic.numOrders();
    const int base_orders = base.aic.numOrders();
    for (const params::ParamSpec& row : params::paramSchema())
    {
      if (row.type != params::ParamType::kDoubleList || row.slots() == 0 || orders < 1 || orders > row.slots())
      {
        continue;  // an out-of-range order is reported by validate()
      }
      const auto old_list = std::get<std::vector<double>>(row.get(base));
      std::vector<double> list(static_cast<std::size_t>(orders));
      for (int i = 0; i < orders; ++i)
      {
        const std::string slot = std::string(row.key) + "_" + std::to_string(i);
        const params::ParamValue value = configValue(request, slot);
        const bool keep = i < base_orders && value == configValue(reference, slot);
        list[static_cast<std::size_t>(i)] = keep ? old_list[static_cast<std::size_t>(i)] : std::get<double>(value);
      }
      row.set(out.params, list);
    }
  }
  for (auto& v : out.params.validate())
  {
    out.violations.push_back(std::move(v));
  }
  return out;
}

NodeReconfigure::NodeReconfigure(const ros::NodeHandle& pnh, const params::NodeParams& in_force)
  : in_force_(in_force), server_(server_mutex_, pnh)
{
  shown_ = configFromParams(in_force_, AICConfig::__getDefault__());
  server_.updateConfig(shown_);  // the validated YAML values
  server_.setCallback(boost::bind(&NodeReconfigure::callback, this, boost::placeholders::_1, boost::placeholders::_2));
}

std::unique_ptr<params::NodeParams> NodeReconfigure::takePending()
{
  std::lock_guard<std::mutex> lock(pending_mutex_);
  return std::move(pending_);
}

void NodeReconfigure::callback(AICConfig& config, std::uint32_t /*level*/)
{
  if (!initialized_)
  {
    initialized_ = true;  // setCallback's first call carries the values we already run with
    return;
  }
  params::NodeParams base = in_force_;
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    if (pending_)
    {
      base = *pending_;
    }
  }
  const ReconfigureOutcome outcome = paramsFromRequest(config, shown_, base);
  if (!outcome.violations.empty())
  {
    for (const auto& v : outcome.violations)
    {
      ROS_ERROR_STREAM("jackal_AIC: reconfigure refused: ~" << v.toString());
    }
    config = configFromParams(base, shown_);  // the server publishes the values still in force
    shown_ = config;
    return;
  }
  std::string changed;
  for (const auto& name : outcome.changed)
  {
    changed += (changed.empty() ? "" : ", ") + name;
  }
  ROS_INFO_STREAM("jackal_AIC: reconfigure accepted (" << (changed.empty() ? "no change" : changed)
                                                       << "); applied at the next tick");
  warnIfUnstable(outcome.params.aic, "reconfigure: ");
  // The changed entries' keys (a list's slots name their row's key), judged by the same rule as
  // at start (params::keysWithoutEffect(): not read by the model and not at the schema's default).
  std::vector<std::string> changed_keys;
  for (const auto& e : params::reconfigureEntries())
  {
    if (std::find(outcome.changed.begin(), outcome.changed.end(), e.name) != outcome.changed.end())
    {
      changed_keys.emplace_back(e.row->key);
    }
  }
  for (const params::ParamSpec* row : params::keysWithoutEffect(outcome.params, changed_keys))
  {
    ROS_WARN_STREAM("jackal_AIC: reconfigure: ~" << params::withoutEffectText(*row, outcome.params));
  }
  config = configFromParams(outcome.params, config);
  shown_ = config;
  std::lock_guard<std::mutex> lock(pending_mutex_);
  pending_ = std::make_unique<params::NodeParams>(outcome.params);
}

}  // namespace node
}  // namespace jackal_aic
