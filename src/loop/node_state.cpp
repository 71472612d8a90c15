/**
 * \file node_state.cpp
 * \brief The node states' names (doc/jackal_aic_node.md, 'Safety'). ROS-free.
 */
#include "jackal_aic/loop/node_state.hpp"

namespace jackal_aic
{
namespace loop
{
const char* toString(NodeState state)
{
  switch (state)
  {
    case NodeState::kWaiting:
      return "waiting";
    case NodeState::kRunning:
      return "running";
    case NodeState::kStale:
      return "stale";
    case NodeState::kRunaway:
      return "runaway";
    case NodeState::kHeld:
      return "held";
    case NodeState::kBlocked:
      return "blocked";
  }
  return "unknown";
}
}  // namespace loop
}  // namespace jackal_aic
