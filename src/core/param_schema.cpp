/**
 * \file param_schema.cpp
 * \brief The parameter table of the jackal_AIC node and the tools, and what is derived from
 *        it: range checks, loading from a ParamSource, reconfigure entries
 *        (doc/jackal_aic_node.md, 'Parameters'; thesis tables C-1 and 5-8 for the defaults).
 */
#include "jackal_aic/param_schema.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <type_traits>

namespace jackal_aic
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

/// Store v in *member if v holds a T (a double member also takes an int).
template <class T>
bool assign(T* member, const ParamValue& v)
{
  if (const T* x = std::get_if<T>(&v))
  {
    *member = *x;
    return true;
  }
  if constexpr (std::is_same_v<T, double>)
  {
    if (const int* i = std::get_if<int>(&v))
    {
      *member = *i;
      return true;
    }
  }
  return false;
}

// Accessors of a member of AicParams (p.aic.m) or of NodeParams (p.m).
#define JACKAL_AIC_MEMBER(expr)                                                                                      \
  [](const NodeParams& p) -> ParamValue { return p.expr; },                                                          \
      [](NodeParams& p, const ParamValue& v) { return assign(&p.expr, v); }

ParamValue getIntegrator(const NodeParams& p)
{
  return toString(p.aic.integrator);
}

bool setIntegrator(NodeParams& p, const ParamValue& v)
{
  const std::string* name = std::get_if<std::string>(&v);
  return name != nullptr && integratorFromString(*name, &p.aic.integrator);
}

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

std::vector<ParamSpec> buildSchema()
{
  using T = ParamType;
  const ParamScope C = ParamScope::kController;
  const ParamScope N = ParamScope::kNode;
  // clang-format off
  return {
    // ---- loops
    { "belief_rate", T::kDouble, C, "loops", 0.0, true, kMaxRate, "Hz",
      "Belief update rate (timer); >= action_rate; the node runs at most 10000 Hz",
      true, 1, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.belief_rate), kMaxLoopRate },
    { "action_rate", T::kDouble, C, "loops", 0.0, true, kMaxRate, "Hz",
      "Action update rate; /cmd_drive is published at this rate; the node runs at most 10000 Hz",
      true, 1, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.action_rate), kMaxLoopRate },
    { "integrator", T::kString, C, "loops", kNone, false, kNone, "-",
      "Belief integrator: euler (thesis eq. 3-15, forward Euler) or exact (zero-order-hold exact step of the "
      "linear belief dynamics)",
      true, 0, false, 0, { "euler", "exact" }, {}, &getIntegrator, &setIntegrator },
    // ---- active inference (thesis tables C-1 / 5-8)
    { "tau", T::kDouble, C, "active_inference", kMinTau, false, kMaxTau, "s",
      "Attractor time constant tau of f(mu) = (mu_d - mu) / tau (thesis eq. 3-7)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.tau) },
    { "k_mu", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "-",
      "Belief learning rate k_mu (thesis eq. 3-15)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.k_mu) },
    { "k_a", T::kDouble, C, "active_inference", 0.0, true, kMaxGain, "-",
      "Action learning rate k_a (thesis eq. 3-16)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.k_a) },
    { "embedding_order", T::kInt, C, "active_inference", 1.0, false, static_cast<double>(kMaxEmbeddingOrder), "-",
      "Embedding order p: generalized orders 0..p are used (thesis eq. 3-17)",
      true, 2, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.embedding_order) },
    { "var_mu", T::kDoubleList, C, "active_inference", kMinVariance, false, kMaxVariance, "SI^2 of each order",
      "Belief variances sigma^2_mu, one per order 0..p or one per order and channel (x_dot, y_dot, theta_dot; "
      "order-major); precision Pi_mu = 1/sigma^2 (thesis table C-1)",
      true, 0, false, kMuDim, {}, { 0.5, 0.6667, 1.333, 2.667, 5.333, 10.67 }, JACKAL_AIC_MEMBER(aic.var_mu) },
    { "var_y", T::kDoubleList, C, "active_inference", kMinVariance, false, kMaxVariance, "SI^2 of each order",
      "Sensor variances sigma^2_y, one per order 0..p or one per order and channel (gyro z, omega_L, omega_R, "
      "accel x, accel y; order-major); precision Pi_y = 1/sigma^2 (thesis table C-1)",
      true, 0, false, kYDim, {}, { 2.0, 38.25, 1.0e5, 1.0e5, 1.0e5, 1.0e5 }, JACKAL_AIC_MEMBER(aic.var_y) },
    { "accel_in_model", T::kBool, C, "active_inference", kNone, false, kNone, "-",
      "If true, the accelerometer-x row of the sensor model maps onto mu^(1); false is the thesis model "
      "(accelerometer rows zero)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.accel_in_model) },
    { "runaway_limit", T::kDouble, C, "active_inference", 0.0, true, kMaxRunawayLimit, "SI",
      "Any belief element beyond this magnitude (or non-finite) is a runaway: reset, zero command, diagnostics "
      "ERROR",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.runaway_limit) },
    { "max_action_lead", T::kDouble, C, "robot", 0.0, false, kMaxWheelSpeedLimit, "rad/s",
      "Anti-windup, not in the thesis: each wheel command is kept within +-this of the measured wheel speed; "
      "0 = off",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.max_action_lead) },
    { "max_action_lead_turn", T::kDouble, C, "robot", 0.0, false, kMaxWheelSpeedLimit, "rad/s",
      "Anti-windup of turning, not in the thesis: half the difference of the two wheels' leads is kept within "
      "+-this (a turn in place winds the wheel loop up while friction holds the wheels); 0 = off",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.max_action_lead_turn) },
    // ---- robot (Clearpath Jackal; doc/jackal.md)
    { "wheel_radius", T::kDouble, C, "robot", kMinLength, false, kMaxLength, "m",
      "Wheel radius r (thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.wheel_radius) },
    { "slip_factor", T::kDouble, C, "robot", kMinSlipFactor, false, kMaxSlipFactor, "-",
      "Slip factor alpha of the extended differential drive (thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.slip_factor) },
    { "wheel_separation", T::kDouble, C, "robot", kMinLength, false, kMaxLength, "m",
      "Virtual wheel separation b_hat (identified; the track is 0.376 m; thesis eq. 3-1 to 3-4)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.wheel_separation) },
    { "max_wheel_speed", T::kDouble, C, "robot", 0.0, true, kMaxWheelSpeedLimit, "rad/s",
      "Wheel commands are clamped to +-this (2.0 m/s / 0.098 m ~ 20.4 rad/s)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(aic.max_wheel_speed) },
    // ---- node only
    { "sensor_timeout", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "No accepted sensor sample for this long -> zero command, diagnostics WARN",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(sensor_timeout) },
    { "set_point_timeout", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "No set point on ~set_point for this long -> zero command, diagnostics WARN",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(set_point_timeout) },
    { "max_linear_speed", T::kDouble, N, "safety", 0.0, true, kInf, "m/s",
      "|set point linear.x| is clamped to this (Jackal top speed)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(max_linear_speed) },
    { "max_angular_speed", T::kDouble, N, "safety", 0.0, true, kInf, "rad/s",
      "|set point angular.z| is clamped to this (stock controller's limit)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(max_angular_speed) },
    { "imu_max_skew", T::kDouble, N, "safety", 0.0, true, kInf, "s",
      "Largest joint_states / imu stamp difference for the two to form one sample",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(imu_max_skew) },
    { "min_sample_interval", T::kDouble, N, "node", 0.0, false, kInf, "s",
      "Samples closer (by stamp) than this to the previous one are dropped as duplicates; < sensor_timeout",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(min_sample_interval) },
    { "runaway_hold_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "After a runaway reset the command stays zero for this long",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(runaway_hold_time) },
    // ---- fault detection and isolation (Baioumy et al. ECC 2021; doc/active_inference.md)
    { "fdi_enabled", T::kBool, N, "safety", kNone, false, kNone, "-",
      "Sensor fault isolation: a channel (gyro z, omega_L, omega_R) found faulty gets Pi_y = 0; false = the test "
      "runs and is reported, nothing is isolated",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(fdi.enabled) },
    { "fdi_threshold", T::kDouble, N, "safety", 0.0, true, kInf, "-",
      "Fault threshold on the precision-weighted residual s = Pi_r r^2, r = gyro - (r alpha / b_hat) "
      "(omega_R - omega_L)",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(fdi.threshold) },
    { "fdi_release_ratio", T::kDouble, N, "safety", 0.0, true, 1.0, "-",
      "Hysteresis: an isolated channel is restored only while s < fdi_release_ratio * fdi_threshold",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(fdi.release_ratio) },
    { "fdi_detect_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "s must exceed fdi_threshold this long before a channel is isolated",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(fdi.detect_time) },
    { "fdi_release_time", T::kDouble, N, "safety", 0.0, false, kInf, "s",
      "s must stay below the release level this long before the isolated channel is restored",
      true, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(fdi.release_time) },
    { "left_joints", T::kStringList, N, "node", kNone, false, kNone, "-",
      "Joints (by name in /joint_states) whose velocities are averaged into omega_L",
      false, 0, true, 0, {}, {}, JACKAL_AIC_MEMBER(left_joints) },
    { "right_joints", T::kStringList, N, "node", kNone, false, kNone, "-",
      "Joints (by name in /joint_states) whose velocities are averaged into omega_R; disjoint from left_joints",
      false, 0, true, 0, {}, {}, JACKAL_AIC_MEMBER(right_joints) },
    { "debug_rate", T::kDouble, N, "node", 0.0, true, kMaxLoopRate, "Hz",
      "~belief, ~free_energy, ~eps_y and ~eps_mu are published at most this often, from the newest belief",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(debug_rate) },
    { "action_trigger", T::kString, N, "loops", kNone, false, kNone, "-",
      "What starts an action step: timer (action_rate, the thesis) or sample (each accepted sensor sample, "
      "so the command uses the newest data; the timer then only keeps /cmd_drive alive while inactive)",
      false, 0, false, 0, { "timer", "sample" }, {}, &getActionTrigger, &setActionTrigger },
    { "belief_schedule", T::kString, N, "loops", kNone, false, kNone, "-",
      "How the beliefs are advanced: event (to the time of every input and timer event, in steps of at most "
      "1 / belief_rate, inputs held between events; no belief timer) or timer (a free-running belief_rate timer: "
      "a real-time thread on the wall clock, a ROS timer on simulated time)",
      false, 0, false, 0, { "event", "timer" }, {}, &getBeliefSchedule, &setBeliefSchedule },
    { "realtime_priority", T::kInt, N, "node", 0.0, false, 99.0, "-",
      "Belief thread (wall-clock mode): 0 = default scheduler, 1..99 = SCHED_FIFO at this priority if permitted",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(realtime_priority) },
    // ---- output (node only, read at start): cmd_drive, or cmd_vel through the stock diff drive
    { "output_mode", T::kString, N, "output", kNone, false, kNone, "-",
      "cmd_drive: publish the wheel commands as jackal_msgs/Drive on /cmd_drive (simulator, modified bases); "
      "cmd_vel: publish the twist the stock diff_drive_controller maps back onto them, as geometry_msgs/Twist "
      "on jackal_velocity_controller/cmd_vel (an unmodified Jackal)",
      false, 0, false, 0, { "cmd_drive", "cmd_vel" }, {}, JACKAL_AIC_MEMBER(output_mode) },
    { "cmd_vel_wheel_radius", T::kDouble, N, "output", 0.0, true, kInf, "m",
      "cmd_vel mode: the stock controller's wheel radius (jackal_control control.yaml)",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.wheel_radius) },
    { "cmd_vel_wheel_separation", T::kDouble, N, "output", 0.0, true, kInf, "m",
      "cmd_vel mode: the stock controller's wheel separation (the track, jackal_description)",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.wheel_separation) },
    { "cmd_vel_wheel_separation_multiplier", T::kDouble, N, "output", 0.0, true, kInf, "-",
      "cmd_vel mode: the stock controller's wheel_separation_multiplier (control.yaml)",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.wheel_separation_multiplier) },
    { "cmd_vel_max_linear_velocity", T::kDouble, N, "output", 0.0, true, kInf, "m/s",
      "cmd_vel mode: the stock controller's linear.x max_velocity; beyond it the command is clipped (anti-windup)",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.max_linear_velocity) },
    { "cmd_vel_max_linear_acceleration", T::kDouble, N, "output", 0.0, true, kInf, "m/s^2",
      "cmd_vel mode: the stock controller's linear.x max_acceleration",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.max_linear_acceleration) },
    { "cmd_vel_max_angular_velocity", T::kDouble, N, "output", 0.0, true, kInf, "rad/s",
      "cmd_vel mode: the stock controller's angular.z max_velocity",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.max_angular_velocity) },
    { "cmd_vel_max_angular_acceleration", T::kDouble, N, "output", 0.0, true, kInf, "rad/s^2",
      "cmd_vel mode: the stock controller's angular.z max_acceleration",
      false, 0, false, 0, {}, {}, JACKAL_AIC_MEMBER(cmd_vel.max_angular_acceleration) },
  };
  // clang-format on
}
#undef JACKAL_AIC_MEMBER

std::string formatNumber(double v)
{
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

/// Adds a violation if v is not finite or outside the row's range.
void checkNumber(const ParamSpec& row, const std::string& name, double v, std::vector<ParamViolation>* out)
{
  const bool ok = std::isfinite(v) && (row.min_exclusive ? v > row.min : v >= row.min) && v <= row.max;
  if (!ok)
  {
    out->push_back({ name, formatNumber(v), rangeText(row) });
  }
}

/// Size rule of a per-order list (ParamSpec::channels > 0).
void checkListSize(const ParamSpec& row, const std::vector<double>& var, int embedding_order,
                   std::vector<ParamViolation>* out)
{
  const std::string key = row.key;
  const bool order_ok = embedding_order >= 1 && embedding_order <= kMaxEmbeddingOrder;
  const int channels = row.channels;
  if (order_ok)
  {
    const std::size_t n = static_cast<std::size_t>(embedding_order + 1);
    if (var.size() != n && var.size() != n * static_cast<std::size_t>(channels))
    {
      out->push_back({ key + ".size()", std::to_string(var.size()),
                       std::to_string(n) + " (one per order) or " + std::to_string(n * channels) +
                           " (per order and channel, order-major) for embedding_order " +
                           std::to_string(embedding_order) });
    }
  }
  else if (var.empty())
  {
    out->push_back({ key + ".size()", "0",
                     "embedding_order + 1 or " + std::to_string(channels) + " * (embedding_order + 1)" });
  }
}

void checkStringList(const ParamSpec& row, const std::vector<std::string>& names, std::vector<ParamViolation>* out)
{
  const std::string key = row.key;
  if (names.empty())
  {
    out->push_back({ key, "[]", "a non-empty list of joint names" });
    return;
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    const std::string item = key + "[" + std::to_string(i) + "]";
    if (names[i].empty())
    {
      out->push_back({ item, "\"\"", "a non-empty joint name" });
    }
    else if (!seen.insert(names[i]).second)
    {
      out->push_back({ item, names[i], "a name not listed twice" });
    }
  }
}
}  // namespace

bool ParamSpec::numeric() const
{
  return type == ParamType::kDouble || type == ParamType::kInt || type == ParamType::kDoubleList;
}

const std::vector<ParamSpec>& paramSchema()
{
  static const std::vector<ParamSpec> schema = buildSchema();
  return schema;
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
          out.push_back({ std::string(s.key) + "_" + std::to_string(i), &s, i, ParamType::kDouble,
                          s.slot_defaults[static_cast<std::size_t>(i)],
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

std::string expectedText(const ParamSpec& row)
{
  switch (row.type)
  {
    case ParamType::kDouble:
      return "a number";
    case ParamType::kInt:
      return "an integer";
    case ParamType::kBool:
      return "true or false";
    case ParamType::kString:
    {
      std::string text = "a string";
      for (std::size_t i = 0; i < row.choices.size(); ++i)
      {
        text += (i == 0 ? ": " : " or ") + row.choices[i];
      }
      return text;
    }
    case ParamType::kDoubleList:
      return "a list of numbers";
    case ParamType::kStringList:
      return "a list of strings";
  }
  return "a value";
}

std::string rangeText(const ParamSpec& row)
{
  switch (row.type)
  {
    case ParamType::kInt:
      return "integer in [" + formatNumber(row.min) + ", " + formatNumber(row.max) + "]";
    case ParamType::kDouble:
    case ParamType::kDoubleList:
    {
      std::string text = (row.min_exclusive ? "> " : ">= ") + formatNumber(row.min);
      return std::isinf(row.max) ? text + " and finite" : text + " and <= " + formatNumber(row.max) + ", finite";
    }
    case ParamType::kString:
    {
      std::string text;
      for (const auto& c : row.choices)
      {
        text += (text.empty() ? "" : " | ") + c;
      }
      return text.empty() ? "any string" : text;
    }
    case ParamType::kBool:
      return "true | false";
    case ParamType::kStringList:
      return "a non-empty list of distinct, non-empty names";
  }
  return "";
}

std::string formatParamValue(const ParamValue& value)
{
  struct Printer
  {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(int i) const { return std::to_string(i); }
    std::string operator()(double d) const { return formatNumber(d); }
    std::string operator()(const std::string& s) const { return s; }
    std::string operator()(const std::vector<double>& v) const
    {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i)
      {
        out += (i ? ", " : "") + formatNumber(v[i]);
      }
      return out + "]";
    }
    std::string operator()(const std::vector<std::string>& v) const
    {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i)
      {
        out += (i ? ", " : "") + v[i];
      }
      return out + "]";
    }
  };
  return std::visit(Printer{}, value);
}

std::vector<ParamViolation> checkParamRanges(const NodeParams& params, ParamScope scope)
{
  std::vector<ParamViolation> out;
  for (const ParamSpec& row : paramSchema())
  {
    if (row.scope != scope)
    {
      continue;
    }
    const ParamValue value = row.get(params);
    switch (row.type)
    {
      case ParamType::kDouble:
        checkNumber(row, row.key, std::get<double>(value), &out);
        break;
      case ParamType::kInt:
      {
        const int v = std::get<int>(value);
        if (v < row.min || v > row.max)
        {
          out.push_back({ row.key, std::to_string(v), rangeText(row) });
        }
        break;
      }
      case ParamType::kDoubleList:
      {
        const auto& list = std::get<std::vector<double>>(value);
        if (row.channels > 0)
        {
          checkListSize(row, list, params.aic.embedding_order, &out);
        }
        for (std::size_t i = 0; i < list.size(); ++i)
        {
          checkNumber(row, std::string(row.key) + "[" + std::to_string(i) + "]", list[i], &out);
        }
        break;
      }
      case ParamType::kString:
      {
        const auto& s = std::get<std::string>(value);
        if (!row.choices.empty() && std::find(row.choices.begin(), row.choices.end(), s) == row.choices.end())
        {
          out.push_back({ row.key, s, rangeText(row) });
        }
        break;
      }
      case ParamType::kStringList:
        checkStringList(row, std::get<std::vector<std::string>>(value), &out);
        break;
      case ParamType::kBool:
        break;
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
