#pragma once
/**
 * \file node_state.hpp
 * \brief What the jackal_AIC node is doing: the Supervisor's states, as reported in
 *        diagnostics (doc/jackal_aic_node.md, 'Safety'). ROS-free.
 */

namespace jackal_aic
{
namespace loop
{
/// What the node is doing (reported in diagnostics as toString(state)).
enum class NodeState
{
  kWaiting,  ///< no sensor sample or no set point yet, or warming up the generalizer: zero command
  kRunning,  ///< controller active
  kStale,    ///< sensors or set point timed out: zero command, diagnostics WARN
  kRunaway,  ///< runaway reset, holding zero command: diagnostics ERROR
  kHeld,     ///< the MCU reports a stop (mcuStatus(), mcuFeedback()): command = measured wheel speeds, diagnostics WARN
  kBlocked   ///< another node publishes on the output topic (outputBlocked()): nothing is published, diagnostics ERROR
};

/// "waiting", "running", "stale", "runaway", "held", "blocked".
const char* toString(NodeState state);
}  // namespace loop
}  // namespace jackal_aic
