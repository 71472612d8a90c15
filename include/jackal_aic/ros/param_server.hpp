#pragma once
/**
 * \file param_server.hpp
 * \brief Reading NodeParams (include/jackal_aic/params/node_params.hpp) from the node's private
 *        namespace, key by key as the parameter schema lists them
 *        (include/jackal_aic/params/param_schema.hpp; doc/jackal_aic_node.md, 'Parameters').
 */

#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/params/param_schema.hpp"

namespace jackal_aic
{
namespace node
{
/**
 * \brief The parameter server under a node handle's namespace as a ParamSource.
 *
 * Types as roscpp reads them: a number accepts an XML-RPC int or double; an integer must
 * be an XML-RPC int (roscpp's getParam(int&) would round 2.5 to 3); lists through
 * getParam(std::vector<...>&).
 */
class RosParamSource : public params::ParamSource
{
public:
  /// \param nh  the namespace to read (the node's private handle ~)
  explicit RosParamSource(const ros::NodeHandle& nh) : nh_(nh) {}
  Status read(const std::string& key, params::ParamType type, params::ParamValue* out) const override;
  std::string raw(const std::string& key) const override;
  /// First path component of every parameter under the namespace.
  std::vector<std::string> keys() const override;

private:
  ros::NodeHandle nh_;
};

/**
 * \brief Read every parameter of NodeParams from `pnh` (the private namespace).
 *
 * A missing key keeps the default of NodeParams (logged at INFO: "parameter ~key not set,
 * using the default"), except `left_joints` and `right_joints`, which are required
 * (validate() reports them). A key of the wrong type (e.g. a string for `tau`, a float for
 * `embedding_order`) or an unknown `integrator` name is a violation. Keys in the namespace
 * that the schema does not know are warned about ("unknown parameter ~key ignored (typo?)").
 *
 * \param pnh         private node handle (~)
 * \param params      output; holds defaults for missing keys
 * \param violations  output; type errors found while reading (append), before validate()
 */
void loadNodeParams(const ros::NodeHandle& pnh, params::NodeParams* params,
                    std::vector<params::ParamViolation>* violations);

/**
 * \brief loadNodeParams() then NodeParams::validate(); every violation is logged at FATAL as
 *        "invalid parameter ~name = value (allowed: range)", then their count and namespace.
 * \return true if the parameters are valid (the node may start); false: exit non-zero
 */
bool loadValidNodeParams(const ros::NodeHandle& pnh, params::NodeParams* params);

/**
 * \brief Log at WARN "jackal_AIC: <what>the configuration is unstable on the linear model ...
 *        spectral radius R >= 1 ..." when stabilityWarning() (jackal_aic/analysis/configured_stability.hpp)
 *        finds the controller of `params` unstable at its rates; nothing for a stable one. The node
 *        warns and runs: the runaway reset still guards the robot (doc/jackal_aic_node.md,
 *        'Parameters'; doc/tuning.md, 'The stability check at load').
 * \param params  the controller parameters about to be used (valid)
 * \param what    prefix naming the occasion, e.g. "reconfigure: " ("" at start-up)
 * \return true if it warned
 */
bool warnIfUnstable(const params::AicParams& params, const std::string& what);

}  // namespace node
}  // namespace jackal_aic
