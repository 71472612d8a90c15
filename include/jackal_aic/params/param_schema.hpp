#pragma once
/**
 * \file param_schema.hpp
 * \brief The one table of the jackal_AIC parameters: key, member, type, default, range,
 *        unit, description, live-tunable: the controller's rows (include/jackal_aic/params/param_spec.hpp,
 *        AicParams) followed by the node's (NodeParams). ROS-free.
 *
 * Everything that names a parameter comes from this table (doc/jackal_aic_node.md,
 * 'Parameters'): AicParams::validate() and NodeParams::validate() (ranges), the node's
 * rosparam loading and its unknown-key warning (src/ros/param_server.cpp), the YAML loading
 * of the tools (tools/include/jackal_tools/params_yaml.hpp), the dynamic_reconfigure mapping
 * (include/jackal_aic/ros/node_reconfigure.hpp) and the generated cfg/AIC.cfg and parameter
 * table (tools/include/jackal_tools/param_docs.hpp). Defaults are those of a default-constructed
 * NodeParams (its member initializers; its `aic` is recommendedAicParams()), so they exist once.
 */

#include <string>
#include <vector>

#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/params/param_spec.hpp"

namespace jackal_aic
{
namespace params
{
/// The schema, in the order of `aic_params --yaml` (controller keys first, then node-only keys).
const std::vector<ParamSpec>& paramSchema();

/// The row of `key`, or nullptr if the schema has no such key.
const ParamSpec* findParam(const std::string& key);

/// The schema's default of a row (from a default-constructed NodeParams).
ParamValue defaultValue(const ParamSpec& row);

/**
 * \brief The default of reconfigure slot `slot` of a live per-order list: element `slot` of the
 *        row's default list (defaultValue()), or its last element for the orders beyond the
 *        default embedding order (used when p grows live).
 */
double slotDefault(const ParamSpec& row, int slot);

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
  std::string name;          ///< cfg name, e.g. "tau" or "var_mu_2"
  const ParamSpec* row;      ///< the schema row
  int slot;                  ///< generalized order of a list slot, -1 for a scalar
  ParamType type;            ///< kDouble, kInt, kBool or kString
  ParamValue default_value;  ///< the default shown (scalar default, or slotDefault())
  std::string description;   ///< cfg description: the row's, with the unit and the order of a slot
};

/// Every dynamic_reconfigure parameter, in schema order.
const std::vector<ReconfigureEntry>& reconfigureEntries();

/**
 * \brief True if `key` may appear in the node's private namespace: a schema key, a
 *        reconfigure slot name ("var_mu_0", ...) when with_reconfigure, or a foreign key.
 */
bool isKnownKey(const std::string& key, bool with_reconfigure);

/**
 * \brief The keys among `set_keys` (those a source sets: a YAML file's, the node's namespace's)
 *        whose value in `params` has no effect: the loaded belief model (params.aic.belief_model)
 *        does not read them (ParamSpec::models) and the value differs from the schema's default.
 *        A key at its default is left out (dynamic_reconfigure writes every live key back into
 *        the node's namespace, so a restarted node sees them all set), as are keys the schema
 *        does not have (reported as unknown by loadParams()).
 * \return the rows, in schema order, each once
 */
std::vector<const ParamSpec*> keysWithoutEffect(const NodeParams& params, const std::vector<std::string>& set_keys);

/**
 * \brief keysWithoutEffect() over every key of the schema: the keys whose value in `params` (the
 *        values in force, however they were set) differs from the schema's default while the
 *        loaded belief model does not read them.
 * \return the rows, in schema order, each once
 */
std::vector<const ParamSpec*> keysWithoutEffect(const NodeParams& params);

/**
 * \brief One line naming a key of keysWithoutEffect() for a log: "tau = 0.02 has no effect with
 *        belief_model robot (read by the goal and unbiased models only)".
 */
std::string withoutEffectText(const ParamSpec& row, const NodeParams& params);

/**
 * \brief Range violations of every row of `scope` in `params`, in schema order.
 *
 * Checks the table's rules only (see ParamSpec); cross-parameter rules (belief_rate >=
 * action_rate, the node's rules) are added by AicParams::validate() / NodeParams::validate().
 * The controller scope is checkParamRanges(params.aic).
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
ParamLoadReport loadParams(const ParamSource& source, const std::vector<ParamScope>& scopes, bool with_reconfigure,
                           NodeParams* params);

}  // namespace params
}  // namespace jackal_aic
