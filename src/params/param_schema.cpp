/**
 * \file param_schema.cpp
 * \brief The parameter table of the jackal_AIC node and the tools (the controller's rows from
 *        param_spec.cpp, then the node's), and what is derived from it: range checks, loading
 *        from a ParamSource, reconfigure entries
 *        (doc/jackal_aic_node.md, 'Parameters'; thesis tables C-1 and 5-8 for the defaults).
 */
#include "jackal_aic/params/param_schema.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

namespace jackal_aic
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// Accessors of a member of NodeParams (p.m); no AicParams accessors.
#define JACKAL_AIC_NODE(expr)                                                 \
  nullptr, nullptr, [](const NodeParams& p) -> ParamValue { return p.expr; }, \
      [](NodeParams& p, const ParamValue& v) { return assignParamValue(&p.expr, v); }

ParamValue getActionTrigger(const NodeParams& p)
{
  return toString(p.action_trigger);
}

bool setActionTrigger(NodeParams& p, const ParamValue& v)
{
  const std::string* name = std::get_if<std::string>(&v);
  return name != nullptr && actionTriggerFromString(*name, &p.action_trigger);
}

ParamValue getBeliefSchedule(const NodeParams& p)
{
  return toString(p.belief_schedule);
}

bool setBeliefSchedule(NodeParams& p, const ParamValue& v)
{
  const std::string* name = std::get_if<std::string>(&v);
  return name != nullptr && beliefScheduleFromString(*name, &p.belief_schedule);
}

/// The node's rows (the controller's come first: controllerParamSpecs()).
std::vector<ParamSpec> buildNodeRows()
{
  using T = ParamType;
  const ParamScope N = ParamScope::kNode;
  // clang-format off
  return {
    // ---- node only
    { "sensor_timeout", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "No accepted sensor sample for this long -> zero command, diagnostics WARN",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(sensor_timeout) },
    { "set_point_timeout", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "No set point on ~set_point for this long -> zero command, diagnostics WARN",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(set_point_timeout) },
    { "max_linear_speed", T::kDouble, N, "safety", 0.0, true, kInf, "m/s",
      "|set point linear.x| is clamped to this (Jackal top speed)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(max_linear_speed) },
    { "max_angular_speed", T::kDouble, N, "safety", 0.0, true, kInf, "rad/s",
      "|set point angular.z| is clamped to this (stock controller's limit)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(max_angular_speed) },
    { "imu_max_skew", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "Largest joint_states / imu stamp difference for the two to form one sample",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(imu_max_skew) },
    { "min_sample_interval", T::kDouble, N, "node", 0.0, false, kInf, "s",
      "Samples closer (by stamp) than this to the previous one are dropped as duplicates; < sensor_timeout",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(min_sample_interval) },
    { "runaway_hold_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "After a runaway reset the command stays zero for this long",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(runaway_hold_time) },
    // ---- fault detection and isolation (Baioumy et al. ECC 2021; doc/active_inference.md)
    { "fdi_enabled", T::kBool, N, "safety", kNone, false, kNone, "-",
      "Sensor fault isolation: a channel (gyro z, omega_L, omega_R) found faulty gets Pi_y = 0; false = the test "
      "runs and is reported, nothing is isolated",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(fdi.enabled) },
    { "fdi_threshold", T::kDouble, N, "safety", 0.0, true, kInf, "-",
      "Fault threshold on the precision-weighted residual s = Pi_r r^2, r = gyro - (r alpha / b_hat) "
      "(omega_R - omega_L)",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(fdi.threshold) },
    { "fdi_release_ratio", T::kDouble, N, "safety", 0.0, true, 1.0, "-",
      "Hysteresis: an isolated channel is restored only while s < fdi_release_ratio * fdi_threshold",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(fdi.release_ratio) },
    { "fdi_detect_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "s must exceed fdi_threshold this long before a channel is isolated",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(fdi.detect_time) },
    { "fdi_release_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "s must stay below the release level this long before the isolated channel is restored",
      true, 0, false, 0, {}, 0, JACKAL_AIC_NODE(fdi.release_time) },
    { "left_joints", T::kStringList, N, "node", kNone, false, kNone, "-",
      "Joints (by name in /joint_states) whose velocities are averaged into omega_L",
      false, 0, true, 0, {}, 0, JACKAL_AIC_NODE(left_joints) },
    { "right_joints", T::kStringList, N, "node", kNone, false, kNone, "-",
      "Joints (by name in /joint_states) whose velocities are averaged into omega_R; disjoint from left_joints",
      false, 0, true, 0, {}, 0, JACKAL_AIC_NODE(right_joints) },
    { "debug_rate", T::kDouble, N, "node", 0.0, true, kMaxLoopRate, "Hz",
      "~belief, ~free_energy, ~eps_y and ~eps_mu are published at most this often, from the newest belief",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(debug_rate) },
    { "action_trigger", T::kString, N, "loops", kNone, false, kNone, "-",
      "What starts an action step: timer (action_rate, the thesis) or sample (each accepted sensor sample, "
      "so the command uses the newest data; the timer then only keeps /cmd_drive alive while inactive)",
      false, 0, false, 0, { "timer", "sample" }, 0, nullptr, nullptr, &getActionTrigger, &setActionTrigger },
    { "belief_schedule", T::kString, N, "loops", kNone, false, kNone, "-",
      "How the beliefs are advanced: event (to the time of every input and timer event, in steps of at most "
      "1 / belief_rate, inputs held between events; no belief timer) or timer (a free-running belief_rate timer: "
      "a real-time thread on the wall clock, a ROS timer on simulated time)",
      false, 0, false, 0, { "event", "timer" }, 0, nullptr, nullptr, &getBeliefSchedule, &setBeliefSchedule },
    { "realtime_priority", T::kInt, N, "node", 0.0, false, 99.0, "-",
      "Belief thread (wall-clock mode): 0 = default scheduler, 1..99 = SCHED_FIFO at this priority if permitted",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(realtime_priority) },
    { "publisher_check_period", T::kDouble, N, "safety", 0.0, false, 10.0, "s",
      "Wall time between two polls of the ROS master for other publishers on the output topic; while there is "
      "one the node publishes nothing there (diagnostics ERROR); 0 = no check",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(publisher_check_period) },
    // ---- output (node only, read at start): cmd_drive, or cmd_vel through the stock diff drive
    { "output_mode", T::kString, N, "output", kNone, false, kNone, "-",
      "cmd_drive: publish the wheel commands as jackal_msgs/Drive on /cmd_drive (simulator, modified bases); "
      "cmd_vel: publish the twist the stock diff_drive_controller maps back onto them, as geometry_msgs/Twist "
      "on jackal_velocity_controller/cmd_vel (an unmodified Jackal)",
      false, 0, false, 0, { "cmd_drive", "cmd_vel" }, 0, JACKAL_AIC_NODE(output_mode) },
    { "learned_model_file", T::kString, N, "node", kNone, false, kNone, "-",
      "YAML overlay that ~save_learned_model writes the learned generative model to (wheel_separation); "
      "empty = $ROS_HOME/jackal_aic/learned_model.yaml. Load it next time as the launch files' learned_model",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(learned_model_file) },
    { "cmd_vel_wheel_radius", T::kDouble, N, "output", 0.0, true, kInf, "m",
      "cmd_vel mode: the stock controller's wheel radius (jackal_control control.yaml)",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.wheel_radius) },
    { "cmd_vel_wheel_separation", T::kDouble, N, "output", 0.0, true, kInf, "m",
      "cmd_vel mode: the stock controller's wheel separation (the track, jackal_description)",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.wheel_separation) },
    { "cmd_vel_wheel_separation_multiplier", T::kDouble, N, "output", 0.0, true, kInf, "-",
      "cmd_vel mode: the stock controller's wheel_separation_multiplier (control.yaml)",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.wheel_separation_multiplier) },
    { "cmd_vel_max_linear_velocity", T::kDouble, N, "output", 0.0, true, kInf, "m/s",
      "cmd_vel mode: the stock controller's linear.x max_velocity; beyond it the command is clipped (anti-windup)",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.max_linear_velocity) },
    { "cmd_vel_max_linear_acceleration", T::kDouble, N, "output", 0.0, true, kInf, "m/s^2",
      "cmd_vel mode: the stock controller's linear.x max_acceleration",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.max_linear_acceleration) },
    { "cmd_vel_max_angular_velocity", T::kDouble, N, "output", 0.0, true, kInf, "rad/s",
      "cmd_vel mode: the stock controller's angular.z max_velocity",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.max_angular_velocity) },
    { "cmd_vel_max_angular_acceleration", T::kDouble, N, "output", 0.0, true, kInf, "rad/s^2",
      "cmd_vel mode: the stock controller's angular.z max_acceleration",
      false, 0, false, 0, {}, 0, JACKAL_AIC_NODE(cmd_vel.max_angular_acceleration) },
  };
  // clang-format on
}
#undef JACKAL_AIC_NODE

}  // namespace

const std::vector<ParamSpec>& paramSchema()
{
  static const std::vector<ParamSpec> schema = [] {
    std::vector<ParamSpec> all = controllerParamSpecs();
    for (ParamSpec& row : buildNodeRows())
    {
      all.push_back(std::move(row));
    }
    return all;
  }();
  return schema;
}

ParamValue ParamSpec::get(const NodeParams& params) const
{
  return get_aic != nullptr ? get_aic(params.aic) : get_node(params);
}

bool ParamSpec::set(NodeParams& params, const ParamValue& value) const
{
  return set_aic != nullptr ? set_aic(params.aic, value) : set_node(params, value);
}

const ParamSpec* findParam(const std::string& key)
{
  for (const ParamSpec& s : paramSchema())
  {
    if (key == s.key)
    {
      return &s;
    }
  }
  return nullptr;
}

ParamValue defaultValue(const ParamSpec& row)
{
  return row.get(NodeParams());
}

double slotDefault(const ParamSpec& row, int slot)
{
  const auto list = std::get<std::vector<double>>(defaultValue(row));
  return list.empty() ? 0.0 : list[std::min(static_cast<std::size_t>(slot), list.size() - 1)];
}

const std::vector<std::string>& foreignKeys()
{
  static const std::vector<std::string> keys{ "diagnostic_period", "groups" };
  return keys;
}

const std::vector<ReconfigureEntry>& reconfigureEntries()
{
  static const std::vector<ReconfigureEntry> entries = [] {
    std::vector<ReconfigureEntry> out;
    for (const ParamSpec& s : paramSchema())
    {
      if (!s.live)
      {
        continue;
      }
      const std::string unit = std::string(" [") + s.unit + "]";
      if (s.type == ParamType::kDoubleList)
      {
        for (int i = 0; i < s.slots(); ++i)
        {
          out.push_back({ std::string(s.key) + "_" + std::to_string(i), &s, i, ParamType::kDouble, slotDefault(s, i),
                          std::string(s.key) + " of order " + std::to_string(i) + unit +
                              " (live only while the YAML gives one value per order)" });
        }
      }
      else
      {
        out.push_back({ s.key, &s, -1, s.type, defaultValue(s), std::string(s.description) + unit });
      }
    }
    return out;
  }();
  return entries;
}

bool isKnownKey(const std::string& key, bool with_reconfigure)
{
  if (findParam(key) != nullptr)
  {
    return true;
  }
  const auto& foreign = foreignKeys();
  if (std::find(foreign.begin(), foreign.end(), key) != foreign.end())
  {
    return true;
  }
  if (with_reconfigure)
  {
    for (const ReconfigureEntry& e : reconfigureEntries())
    {
      if (e.name == key)
      {
        return true;
      }
    }
  }
  return false;
}

std::vector<ParamViolation> checkParamRanges(const NodeParams& params, ParamScope scope)
{
  if (scope == ParamScope::kController)
  {
    return checkParamRanges(params.aic);
  }
  std::vector<ParamViolation> out;
  for (const ParamSpec& row : paramSchema())
  {
    if (row.scope == scope)
    {
      checkParamValue(row, row.get(params), params.aic.embedding_order, &out);
    }
  }
  return out;
}

ParamLoadReport loadParams(const ParamSource& source, const std::vector<ParamScope>& scopes, bool with_reconfigure,
                           NodeParams* params)
{
  ParamLoadReport report;
  for (const ParamSpec& row : paramSchema())
  {
    if (std::find(scopes.begin(), scopes.end(), row.scope) == scopes.end())
    {
      continue;
    }
    ParamValue value;
    switch (source.read(row.key, row.type, &value))
    {
      case ParamSource::Status::kMissing:
        report.defaulted.push_back(row.key);
        break;
      case ParamSource::Status::kWrongType:
        report.errors.push_back({ row.key, source.raw(row.key), expectedText(row) });
        break;
      case ParamSource::Status::kOk:
        if (!row.set(*params, value))
        {
          report.errors.push_back({ row.key, source.raw(row.key), expectedText(row) });
        }
        break;
    }
  }
  for (const std::string& key : source.keys())
  {
    if (!isKnownKey(key, with_reconfigure))
    {
      report.unknown.push_back(key);
    }
  }
  return report;
}

}  // namespace jackal_aic
