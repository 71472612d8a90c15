#pragma once
/**
 * \file param_schema.hpp
 * \brief The one table of the jackal_AIC parameters: key, member, type, default, range,
 *        unit, description, live-tunable. ROS-free.
 *
 * Everything that names a parameter comes from this table (doc/jackal_aic_node.md,
 * 'Parameters'): AicParams::validate() and NodeParams::validate() (ranges), the node's
 * rosparam loading and its unknown-key warning (src/ros/node_params.cpp), the YAML loading
 * of the tools (include/jackal_aic/params_yaml.hpp), the dynamic_reconfigure mapping
 * (include/jackal_aic/ros/node_reconfigure.hpp) and the generated cfg/AIC.cfg and parameter
 * table (include/jackal_aic/param_docs.hpp). Defaults are those of a default-constructed
 * NodeParams (the member initializers of AicParams and NodeParams), so they exist once.
 */

#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "jackal_aic/node_params.hpp"

namespace jackal_aic
{
/// Type of a parameter's value (as in the YAML file and on the parameter server).
enum class ParamType
{
  kDouble,      ///< a number (an integer in the YAML is accepted)
  kInt,         ///< an integer
  kBool,        ///< true / false
  kString,      ///< a string, optionally one of ParamSpec::choices
  kDoubleList,  ///< a list of numbers
  kStringList   ///< a list of strings
};

/// A parameter's value; the alternative matches ParamType (kDouble -> double, ...).
using ParamValue = std::variant<bool, int, double, std::string, std::vector<double>, std::vector<std::string>>;

/// Who reads a parameter.
enum class ParamScope
{
  kController,  ///< a member of AicParams: the node and the tools (aic_analyze, closed_loop_run, ...)
  kNode         ///< a node-only member of NodeParams (ignored by the tools)
};

/**
 * \brief One row of the schema.
 *
 * Range: a number (each element of a list) must be finite and lie in [min, max], or in
 * (min, max] when min_exclusive; max = +infinity means "no upper bound" (still finite).
 * kInt: an integer in [min, max]. kString with choices: one of them. kStringList: a
 * non-empty list of non-empty, distinct strings. kDoubleList with channels > 0: a list of
 * p+1 values (one per generalized order) or channels * (p+1) (per order and channel,
 * order-major), p = embedding_order (AicParams).
 */
struct ParamSpec
{
  const char* key;          ///< YAML / rosparam / reconfigure name, e.g. "tau"
  ParamType type;           ///< value type
  ParamScope scope;         ///< controller (AicParams) or node-only (NodeParams)
  const char* group;        ///< dynamic_reconfigure group: loops, active_inference, robot, safety, node
  double min;               ///< lower bound (numbers, list elements, integers); NaN for other types
  bool min_exclusive;       ///< true: value > min; false: value >= min
  double max;               ///< upper bound, inclusive; +infinity = none
  const char* unit;         ///< SI unit as in config/*.yaml comments, e.g. "Hz", "-", "SI^2 of each order"
  const char* description;  ///< one sentence, with the thesis equation where there is one
  bool live;                ///< changeable through dynamic_reconfigure (cfg/AIC.cfg)
  int level;                ///< dynamic_reconfigure level bits (1: loop rate, 2: embedding order)
  bool required;            ///< no default: the node refuses to start without it
  int channels;             ///< kDoubleList per generalized order: channels of the per-channel form (3 or 5), else 0
  std::vector<std::string> choices;  ///< kString: allowed values (empty = any)
  /// Live kDoubleList per order: reconfigure slots "<key>_<i>", i = 0..kMaxOrders-1, and their
  /// defaults (the first p+1 equal the default list; the rest are used when p grows live).
  std::vector<double> slot_defaults;
  /// The member's current value, of the alternative matching `type`.
  ParamValue (*get)(const NodeParams& params);
  /**
   * \brief Store a value in the member.
   * \return false if the value is not acceptable for the member's C++ type (wrong
   *         alternative, or a string that names no enumerator, e.g. integrator "rk4");
   *         the member is unchanged then
   */
  bool (*set)(NodeParams& params, const ParamValue& value);
  /// The node's own upper bound when below `max` (the loop rates: `max` is the core's sanity
  /// bound, 1e6 Hz, the node runs at most kMaxLoopRate); +infinity = as `max`.
  double node_max = std::numeric_limits<double>::infinity();

  /// Upper bound in the node (NodeParams::validate(), cfg/AIC.cfg): min(max, node_max).
  double nodeMax() const { return node_max < max ? node_max : max; }
  /// Number of reconfigure slots (0 unless a live per-order list).
  int slots() const { return static_cast<int>(slot_defaults.size()); }
  /// True for kDouble, kInt, kDoubleList (the range applies).
  bool numeric() const;
};

/// The schema, in the order of config/default.yaml (controller keys first, then node-only keys).
const std::vector<ParamSpec>& paramSchema();

/// The row of `key`, or nullptr if the schema has no such key.
const ParamSpec* findParam(const std::string& key);

/// The schema's default of a row (from a default-constructed NodeParams).
ParamValue defaultValue(const ParamSpec& row);

/// Keys other programs write into the node's private namespace: "diagnostic_period"
/// (diagnostic_updater) and "groups" (dynamic_reconfigure). Known, never read by us.
const std::vector<std::string>& foreignKeys();

/**
 * \brief One dynamic_reconfigure parameter (a row of cfg/AIC.cfg), derived from the schema.
 *
 * A live scalar row gives one entry named like the key; a live per-order list gives
 * kMaxOrders slots "<key>_<i>" (type kDouble) for element i (the first channel's value
 * in the per-channel form).
 */
struct ReconfigureEntry
{
  std::string name;        ///< cfg name, e.g. "tau" or "var_mu_2"
  const ParamSpec* row;    ///< the schema row
  int slot;                ///< generalized order of a list slot, -1 for a scalar
  ParamType type;          ///< kDouble, kInt, kBool or kString
  ParamValue default_value;  ///< the default shown (scalar default, or slot_defaults[slot])
  std::string description;   ///< cfg description: the row's, with the unit and the order of a slot
};

/// Every dynamic_reconfigure parameter, in schema order.
const std::vector<ReconfigureEntry>& reconfigureEntries();

/**
 * \brief True if `key` may appear in the node's private namespace: a schema key, a
 *        reconfigure slot name ("var_mu_0", ...) when with_reconfigure, or a foreign key.
 */
bool isKnownKey(const std::string& key, bool with_reconfigure);

/// What a value of a row must be, for messages: "a number", "an integer", "true or false",
/// "a string: euler or exact", "a list of numbers", "a list of strings".
std::string expectedText(const ParamSpec& row);

/// The allowed range of a row as text, e.g. "> 0 and <= 1000000, finite", ">= 0 and finite",
/// "integer in [1, 5]", "euler | exact".
std::string rangeText(const ParamSpec& row);

/// A value printed for messages and docs (numbers with up to 15 significant digits, lists as [a, b]).
std::string formatParamValue(const ParamValue& value);

/**
 * \brief Range violations of every row of `scope` in `params`, in schema order.
 *
 * Checks the table's rules only (see ParamSpec); cross-parameter rules (belief_rate >=
 * action_rate, the node's rules) are added by AicParams::validate() / NodeParams::validate().
 * A violation names the key ("tau"), a list element ("var_mu[2]") or a list size
 * ("var_mu.size()"), with the value and the allowed range.
 */
std::vector<ParamViolation> checkParamRanges(const NodeParams& params, ParamScope scope);

/**
 * \brief Where parameters are read from: rosparam (the node) or a YAML map (the tools).
 */
class ParamSource
{
public:
  /// Outcome of one read().
  enum class Status
  {
    kMissing,   ///< no such key
    kOk,        ///< *out holds the value, of the alternative matching the type
    kWrongType  ///< present, but not of the type asked for
  };
  virtual ~ParamSource() = default;
  /// Read `key` as `type` (kDouble accepts integers; kInt does not accept a fractional number).
  virtual Status read(const std::string& key, ParamType type, ParamValue* out) const = 0;
  /// The raw value of `key`, printed, for messages ("<missing>" if absent).
  virtual std::string raw(const std::string& key) const = 0;
  /// Every top-level key present (for the unknown-key check).
  virtual std::vector<std::string> keys() const = 0;
};

/// Outcome of loadParams().
struct ParamLoadReport
{
  /// Keys present with a value of the wrong type or an unknown enumerator: name, raw value,
  /// expected (expectedText()).
  std::vector<ParamViolation> errors;
  std::vector<std::string> defaulted;  ///< keys of the scope(s) read that are absent (defaults kept)
  std::vector<std::string> unknown;    ///< keys of the source that isKnownKey() does not know
};

/**
 * \brief Read every key of the schema within `scopes` from `source` into `params`.
 *
 * Absent keys keep their value in *params (the defaults, for a default-constructed
 * NodeParams). Values are not validated here (call validate()).
 * \param source           where to read
 * \param scopes           the scopes to read (the tools: {kController}; the node: both)
 * \param with_reconfigure reconfigure slot names count as known keys (the node's namespace)
 * \param params           in: values for absent keys; out: the values read
 * \return type errors, defaulted keys (required keys included) and unknown keys
 */
ParamLoadReport loadParams(const ParamSource& source, const std::vector<ParamScope>& scopes,
                           bool with_reconfigure, NodeParams* params);

}  // namespace jackal_aic
