#pragma once
/**
 * \file fdi_params.hpp
 * \brief Parameters of the sensor fault detection and isolation (FaultMonitor,
 *        include/jackal_aic/safety/fault_monitor.hpp; doc/jackal_aic_node.md, 'Parameters'). ROS-free.
 */

#include <vector>

#include "jackal_aic/params/param_violation.hpp"

namespace jackal_aic
{
namespace params
{
/// Parameters of FaultMonitor (schema keys fdi_*; doc/jackal_aic_node.md, 'Parameters').
struct FdiParams
{
  /// Isolation switch: false = the test runs and is reported, but no channel's Pi_y is ever zeroed.
  bool enabled = true;
  /// Detection threshold gamma on the precision-weighted residual s = Pi_r r^2 [-], > 0 (see FaultMonitor).
  double threshold = 0.06;
  /// Hysteresis: a channel is restored only while s < release_ratio * threshold [-], in (0, 1].
  double release_ratio = 0.25;
  /// s must exceed the threshold for this long before a channel is isolated [s], >= 0.
  double detect_time = 0.2;
  /// s must stay below release_ratio * threshold for this long before the channel is restored [s], >= 0.
  double release_time = 1.0;

  /// Every violated rule (the schema's ranges), named by YAML key (fdi_threshold, ...).
  std::vector<ParamViolation> validate() const;
};
}  // namespace params
}  // namespace jackal_aic
