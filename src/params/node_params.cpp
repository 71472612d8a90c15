/**
 * \file node_params.cpp
 * \brief NodeParams::validate(): the schema's ranges plus the node's own rules
 *        (doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_aic/params/node_params.hpp"

#include <cmath>
#include <utility>

#include "jackal_aic/params/param_schema.hpp"

namespace jackal_aic
{
namespace params
{
bool actionTriggerFromString(const std::string& name, ActionTrigger* out)
{
  if (name == "timer")
  {
    *out = ActionTrigger::kTimer;
    return true;
  }
  if (name == "sample")
  {
    *out = ActionTrigger::kSample;
    return true;
  }
  return false;
}

std::string toString(ActionTrigger trigger)
{
  return trigger == ActionTrigger::kSample ? "sample" : "timer";
}

bool beliefScheduleFromString(const std::string& name, BeliefSchedule* out)
{
  if (name == "event")
  {
    *out = BeliefSchedule::kEvent;
    return true;
  }
  if (name == "timer")
  {
    *out = BeliefSchedule::kTimer;
    return true;
  }
  return false;
}

std::string toString(BeliefSchedule schedule)
{
  return schedule == BeliefSchedule::kTimer ? "timer" : "event";
}

std::vector<ParamViolation> NodeParams::validate() const
{
  std::vector<ParamViolation> violations = aic.validate();
  // The node's own bounds below the core's (the loop rates: ParamSpec::node_max).
  for (const ParamSpec& row : paramSchema())
  {
    if (row.type != ParamType::kDouble || !(row.node_max < row.max))
    {
      continue;
    }
    const double v = std::get<double>(row.get(*this));
    if (std::isfinite(v) && v > row.node_max)
    {
      violations.push_back({ row.key, formatParamValue(v), "<= " + formatParamValue(row.node_max) + " " + row.unit });
    }
  }
  for (auto& v : checkParamRanges(*this, ParamScope::kNode))
  {
    violations.push_back(std::move(v));
  }
  if (std::isfinite(min_sample_interval) && min_sample_interval >= 0.0 && std::isfinite(sensor_timeout) &&
      min_sample_interval >= sensor_timeout)
  {
    violations.push_back({ "min_sample_interval", formatParamValue(min_sample_interval),
                           ">= 0 and < sensor_timeout (" + formatParamValue(sensor_timeout) + ")" });
  }
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

}  // namespace params
}  // namespace jackal_aic
