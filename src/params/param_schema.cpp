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
#include <type_traits>
#include <utility>

namespace jackal_aic
{
namespace params
{
namespace
{

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
  // clang-format off
  return {
    // ---- node only
    ParamRow("safety", "sensor_timeout").unit("s").above(0.0)
        .describe("No accepted sensor sample for this long -> zero command, diagnostics WARN")
        .node<&NodeParams::sensor_timeout>(),
    ParamRow("safety", "set_point_timeout").unit("s").above(0.0)
        .describe("No set point on ~set_point for this long -> zero command, diagnostics WARN")
        .node<&NodeParams::set_point_timeout>(),
    ParamRow("safety", "max_linear_speed").unit("m/s").above(0.0)
        .describe("|set point linear.x| is clamped to this (Jackal top speed)")
        .node<&NodeParams::max_linear_speed>(),
    ParamRow("safety", "max_angular_speed").unit("rad/s").above(0.0)
        .describe("|set point angular.z| is clamped to this (stock controller's limit)")
        .node<&NodeParams::max_angular_speed>(),
    ParamRow("safety", "imu_max_skew").unit("s").above(0.0)
        .describe("Largest joint_states / imu stamp difference for the two to form one sample")
        .node<&NodeParams::imu_max_skew>(),
    ParamRow("node", "min_sample_interval").unit("s").atLeast(0.0)
        .describe("Samples closer (by stamp) than this to the previous one are dropped as duplicates; < "
                  "sensor_timeout")
        .notLive().node<&NodeParams::min_sample_interval>(),
    ParamRow("safety", "runaway_hold_time").unit("s").atLeast(0.0)
        .describe("After a runaway reset the command stays zero for this long")
        .node<&NodeParams::runaway_hold_time>(),
    // ---- fault detection and isolation (Baioumy et al. ECC 2021; doc/active_inference.md)
    ParamRow("safety", "fdi_enabled")
        .describe("Sensor fault isolation: a channel (gyro z, omega_L, omega_R) found faulty gets Pi_y = 0; false "
                  "= the test runs and is reported, nothing is isolated")
        .node<&NodeParams::fdi, &FdiParams::enabled>(),
    ParamRow("safety", "fdi_threshold").above(0.0)
        .describe("Fault threshold on the precision-weighted residual s = Pi_r r^2, r = gyro - (r alpha / b_hat) "
                  "(omega_R - omega_L) (goal and unbiased models; the robot model tests its innovations' parity "
                  "at 5 standard deviations, from its noises: no effect)")
        .readBy(kLinearBeliefModels).node<&NodeParams::fdi, &FdiParams::threshold>(),
    ParamRow("safety", "fdi_release_ratio").above(0.0).atMost(1.0)
        .describe("Hysteresis: an isolated channel is restored only while s < fdi_release_ratio * the threshold")
        .node<&NodeParams::fdi, &FdiParams::release_ratio>(),
    ParamRow("safety", "fdi_detect_time").unit("s").atLeast(0.0)
        .describe("s must exceed the threshold this long before a channel is isolated")
        .node<&NodeParams::fdi, &FdiParams::detect_time>(),
    ParamRow("safety", "fdi_release_time").unit("s").atLeast(0.0)
        .describe("s must stay below the release level this long before the isolated channel is restored")
        .node<&NodeParams::fdi, &FdiParams::release_time>(),
    ParamRow("node", "left_joints")
        .describe("Joints (by name in /joint_states) whose velocities are averaged into omega_L")
        .notLive().required().node<&NodeParams::left_joints>(),
    ParamRow("node", "right_joints")
        .describe("Joints (by name in /joint_states) whose velocities are averaged into omega_R; disjoint from "
                  "left_joints")
        .notLive().required().node<&NodeParams::right_joints>(),
    ParamRow("node", "debug_rate").unit("Hz").above(0.0).atMost(kMaxLoopRate)
        .describe("~belief, ~free_energy, ~eps_y and ~eps_mu are published at most this often, from the newest "
                  "belief")
        .notLive().node<&NodeParams::debug_rate>(),
    ParamRow("loops", "action_trigger")
        .describe("What starts an action step: timer (action_rate, the thesis) or sample (each accepted sensor "
                  "sample, so the command uses the newest data; the timer then only keeps /cmd_drive alive while "
                  "inactive)")
        .notLive().choices({ "timer", "sample" }).accessors(&getActionTrigger, &setActionTrigger),
    ParamRow("loops", "belief_schedule")
        .describe("How the beliefs are advanced: event (to the time of every input and timer event, in steps of at "
                  "most 1 / belief_rate, inputs held between events; no belief timer) or timer (a free-running "
                  "belief_rate timer: a real-time thread on the wall clock, a ROS timer on simulated time)")
        .notLive().choices({ "event", "timer" }).accessors(&getBeliefSchedule, &setBeliefSchedule),
    ParamRow("node", "realtime_priority").atLeast(0.0).atMost(99.0)
        .describe("Belief thread (wall-clock mode): 0 = default scheduler, 1..99 = SCHED_FIFO at this priority if "
                  "permitted")
        .notLive().node<&NodeParams::realtime_priority>(),
    ParamRow("safety", "publisher_check_period").unit("s").atLeast(0.0).atMost(10.0)
        .describe("Wall time between two polls of the ROS master for other publishers on the output topic; while "
                  "there is one the node publishes nothing there (diagnostics ERROR); 0 = no check")
        .notLive().node<&NodeParams::publisher_check_period>(),
    // ---- output (node only, read at start): cmd_drive, or cmd_vel through the stock diff drive
    ParamRow("output", "output_mode")
        .describe("cmd_drive: publish the wheel commands as jackal_msgs/Drive on /cmd_drive (simulator, modified "
                  "bases); cmd_vel: publish the twist the stock diff_drive_controller maps back onto them, as "
                  "geometry_msgs/Twist on jackal_velocity_controller/cmd_vel (an unmodified Jackal)")
        .notLive().choices({ "cmd_drive", "cmd_vel" }).node<&NodeParams::output_mode>(),
    ParamRow("node", "learned_model_file")
        .describe("YAML overlay that ~save_learned_model writes the learned generative model to "
                  "(wheel_separation; latency with the robot model's learn_latency); empty = "
                  "$ROS_HOME/jackal_aic/learned_model.yaml. Load it next time as the launch files' learned_model")
        .notLive().node<&NodeParams::learned_model_file>(),
    ParamRow("output", "cmd_vel_wheel_radius").unit("m").above(0.0)
        .describe("cmd_vel mode: the stock controller's wheel radius (jackal_control control.yaml)")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::wheel_radius>(),
    ParamRow("output", "cmd_vel_wheel_separation").unit("m").above(0.0)
        .describe("cmd_vel mode: the stock controller's wheel separation (the track, jackal_description)")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::wheel_separation>(),
    ParamRow("output", "cmd_vel_wheel_separation_multiplier").above(0.0)
        .describe("cmd_vel mode: the stock controller's wheel_separation_multiplier (control.yaml)")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::wheel_separation_multiplier>(),
    ParamRow("output", "cmd_vel_max_linear_velocity").unit("m/s").above(0.0)
        .describe("cmd_vel mode: the stock controller's linear.x max_velocity; beyond it the command is clipped "
                  "(anti-windup)")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::max_linear_velocity>(),
    ParamRow("output", "cmd_vel_max_linear_acceleration").unit("m/s^2").above(0.0)
        .describe("cmd_vel mode: the stock controller's linear.x max_acceleration")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::max_linear_acceleration>(),
    ParamRow("output", "cmd_vel_max_angular_velocity").unit("rad/s").above(0.0)
        .describe("cmd_vel mode: the stock controller's angular.z max_velocity")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::max_angular_velocity>(),
    ParamRow("output", "cmd_vel_max_angular_acceleration").unit("rad/s^2").above(0.0)
        .describe("cmd_vel mode: the stock controller's angular.z max_acceleration")
        .notLive().node<&NodeParams::cmd_vel, &DiffDriveParams::max_angular_acceleration>(),
  };
  // clang-format on
}

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

std::vector<const ParamSpec*> keysWithoutEffect(const NodeParams& params, const std::vector<std::string>& set_keys)
{
  static const NodeParams defaults;
  std::vector<const ParamSpec*> out;
  for (const ParamSpec& row : paramSchema())
  {
    if (!row.readBy(params.aic.belief_model) &&
        std::find(set_keys.begin(), set_keys.end(), std::string(row.key)) != set_keys.end() &&
        !(row.get(params) == row.get(defaults)))
    {
      out.push_back(&row);
    }
  }
  return out;
}

std::vector<const ParamSpec*> keysWithoutEffect(const NodeParams& params)
{
  static const std::vector<std::string> all = [] {
    std::vector<std::string> keys;
    for (const ParamSpec& row : paramSchema())
    {
      keys.emplace_back(row.key);
    }
    return keys;
  }();
  return keysWithoutEffect(params, all);
}

std::string withoutEffectText(const ParamSpec& row, const NodeParams& params)
{
  const bool one = (row.models & (row.models - 1u)) == 0u;
  return std::string(row.key) + " = " + formatParamValue(row.get(params)) + " has no effect with belief_model " +
         toString(params.aic.belief_model) + " (read by the " + beliefModelsText(row.models) +
         (one ? " model only)" : " models only)");
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

}  // namespace params
}  // namespace jackal_aic
