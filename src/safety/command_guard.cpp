/**
 * \file command_guard.cpp
 * \brief The last guard of the wheel command (jackal_aic/safety/command_guard.hpp).
 */
#include "jackal_aic/safety/command_guard.hpp"

#include <algorithm>
#include <cmath>

namespace jackal_aic
{
namespace safety
{
GuardedWheels guardWheelCommand(const base::Vector2& wheels, double limit) noexcept
{
  GuardedWheels g;
  if (!wheels.allFinite() || !std::isfinite(limit) || !(limit > 0.0))
  {
    g.replaced = true;
    return g;
  }
  for (int i = 0; i < 2; ++i)
  {
    g.wheels(i) = std::clamp(wheels(i), -limit, limit);
    g.clamped = g.clamped || g.wheels(i) != wheels(i);
  }
  return g;
}

}  // namespace safety
}  // namespace jackal_aic
