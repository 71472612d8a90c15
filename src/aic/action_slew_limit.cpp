/**
 * \file action_slew_limit.cpp
 * \brief The slew limit of the action (doc/extending.md, the worked example).
 */
#include "jackal_aic/aic/action_slew_limit.hpp"

#include <cmath>

#include "jackal_aic/aic/anti_windup.hpp"

namespace jackal_aic
{
namespace aic
{
base::Vector2 ActionSlewLimit::limit(const base::Vector2& previous, const base::Vector2& command, double h,
                                     bool* limited) const
{
  if (limited != nullptr)
  {
    *limited = false;
  }
  const base::Vector2 change = command - previous;
  if (!enabled() || !(h > 0.0 && std::isfinite(h)) || !change.allFinite())
  {
    return command;
  }
  const double largest = change.cwiseAbs().maxCoeff();
  const double bound = params_.max_rate * h;
  if (!(largest > bound))
  {
    return command;
  }
  if (limited != nullptr)
  {
    *limited = true;
  }
  // The pair's change scaled as a whole: the wheel that changes most moves by the bound.
  return previous + (bound / largest) * change;
}

ActionSlewLimit::Result ActionSlewLimit::apply(const base::Vector2& previous, const base::Vector2& command,
                                               const base::Vector2& a_F, const base::Vector2& candidate,
                                               const base::Vector2& a_dot, const base::Vector2& prior, double h) const
{
  Result result{ command, candidate, false };
  result.command = limit(previous, command, h, &result.limited);
  if (!result.limited)
  {
    return result;
  }
  for (int i = 0; i < 2; ++i)
  {
    result.free_energy_part(i) = conditionalIntegration(a_F(i), candidate(i), a_dot(i), command(i) - result.command(i),
                                                        result.command(i) - prior(i));
  }
  return result;
}

}  // namespace aic
}  // namespace jackal_aic
