#pragma once
/**
 * \file node_reconfigure.hpp
 * \brief dynamic_reconfigure of the jackal_AIC node (cfg/AIC.cfg, generated from the
 *        parameter schema): the mapping between AICConfig and NodeParams, by name through
 *        the schema's reconfigure entries, and the server that validates and queues changes
 *        (doc/jackal_aic_node.md, 'Parameters').
 *
 * Only the keys a request changes are applied: a key counts as changed when the request's
 * value differs from the value the server showed (after the server's own clamping to the
 * cfg range), so a value the cfg range cannot show is never overwritten by a request that
 * is about another key.
 */

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <ros/node_handle.h>

#include "jackal_aic/AICConfig.h"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/params/param_schema.hpp"

namespace jackal_aic
{
namespace node
{
/**
 * \brief The value of the cfg parameter `name` in `config`, as a ParamValue (double, int,
 *        bool or std::string).
 * \throws std::out_of_range if AICConfig has no parameter of that name
 */
params::ParamValue configValue(const AICConfig& config, const std::string& name);

/**
 * \brief Set the cfg parameter `name` in `config`.
 * \throws std::out_of_range if AICConfig has no parameter of that name
 * \throws std::invalid_argument if `value` does not hold the parameter's type
 */
void setConfigValue(AICConfig* config, const std::string& name, const params::ParamValue& value);

/**
 * \brief The config that shows `params`: every reconfigure entry of the schema set from
 *        params; variance slot i from element i of the per-order list, or from the first
 *        channel of order i in the per-channel form; slots beyond p keep `base`'s values.
 * \param params  validated parameters
 * \param base    values for what params does not determine (slots beyond p)
 */
AICConfig configFromParams(const params::NodeParams& params, const AICConfig& base);

/// Outcome of paramsFromRequest().
struct ReconfigureOutcome
{
  params::NodeParams params;                       ///< base with the changed keys applied
  std::vector<std::string> changed;                ///< cfg names that changed, in schema order
  std::vector<params::ParamViolation> violations;  ///< empty: accept `params`
};

/**
 * \brief Apply the keys a reconfigure request changed to `base` and validate the result.
 *
 * A cfg parameter is changed when its value in `request` differs from its value in `shown`
 * clamped to the cfg range (what the server does to every key before the callback). Variance
 * slots and embedding_order may change only while both variance lists have one value per
 * order; the lists are then rebuilt for the (new) p from the unchanged elements of `base`
 * and the request's slots. The whole set is validated (NodeParams::validate()).
 * \param request  the config the server passes to the callback (clamped)
 * \param shown    the config the server held before the request
 * \param base     the parameters the request changes (in force, or the last accepted set)
 */
ReconfigureOutcome paramsFromRequest(const AICConfig& request, const AICConfig& shown, const params::NodeParams& base);

/**
 * \brief The node's dynamic_reconfigure server: validates each request in its callback and
 *        queues the accepted parameter set; the node applies it between two timer ticks
 *        (takePending()). A refused request is logged ("jackal_AIC: reconfigure refused:
 *        ~name = value (allowed: ...)") and the server shows the values still in force.
 */
class NodeReconfigure
{
public:
  /**
   * \param pnh        private node handle (the server's namespace)
   * \param in_force   the node's parameters in force; must outlive this object (read in the callback)
   */
  NodeReconfigure(const ros::NodeHandle& pnh, const params::NodeParams& in_force);

  /// The parameter set accepted since the last call, or null.
  std::unique_ptr<params::NodeParams> takePending();

private:
  void callback(AICConfig& config, std::uint32_t level);

  const params::NodeParams& in_force_;
  boost::recursive_mutex server_mutex_;
  dynamic_reconfigure::Server<AICConfig> server_;
  AICConfig shown_;           ///< what the server holds (the last config given to it)
  bool initialized_ = false;  ///< setCallback()'s first call carries the values already in force
  std::mutex pending_mutex_;
  std::unique_ptr<params::NodeParams> pending_;
};

}  // namespace node
}  // namespace jackal_aic
