#pragma once
/**
 * \file clock.hpp
 * \brief The loop's injected time source: the node wraps ROS time, the simulator its own
 *        simulated time, the tests a settable value (doc/jackal_aic_node.md, 'Loops'). ROS-free.
 */

namespace jackal_aic
{
namespace loop
{
/// A monotonic time source [s]; the node wraps ros::Time::now(), the tests a settable value.
class Clock
{
public:
  virtual ~Clock() = default;
  /// The current time [s] (any epoch; only differences are used).
  virtual double now() const = 0;
};
}  // namespace loop
}  // namespace jackal_aic
