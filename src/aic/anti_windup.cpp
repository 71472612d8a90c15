/**
 * \file anti_windup.cpp
 * \brief The action's clamps and conditional integration (doc/active_inference.md, 'Update rules', Anti-windup).
 */
#include "jackal_aic/aic/anti_windup.hpp"

#include <algorithm>

#include "jackal_aic/aic/skid_steer_model.hpp"

namespace jackal_aic
{
namespace aic
{
double conditionalIntegration(double a_F, double candidate, double a_dot, double cut, double at_clamp)
{
  if (cut > 0.0 && a_dot > 0.0)
  {
    return std::max(a_F, std::min(candidate, at_clamp));
  }
  if (cut < 0.0 && a_dot < 0.0)
  {
    return std::min(a_F, std::max(candidate, at_clamp));
  }
  return candidate;
}

AntiWindup::Result AntiWindup::apply(const base::Vector2& a_F, const base::Vector2& candidate,
                                     const base::Vector2& a_dot, const base::Vector2& prior, const base::Vector2& omega,
                                     bool left_trusted, bool right_trusted) const
{
  const base::Vector2 raw = candidate + prior;
  base::Vector2 a = raw;
  if (params_.max_action_lead > 0.0)
  {
    // The action may lead the measured wheel speeds by at most max_action_lead (what the wheel
    // loop can use before it saturates), or as far as the prior alone asks (the command a stock
    // base would send: the MCU's own loop handles it, and nothing integrates it). A masked
    // (isolated) wheel channel is not trusted, so it does not bound its command.
    const base::Vector2 lead = base::Vector2::Constant(params_.max_action_lead);
    const base::Vector2 lower = (omega - lead).cwiseMin(prior);
    const base::Vector2 upper = (omega + lead).cwiseMax(prior);
    const base::Vector2 bounded = a.cwiseMax(lower).cwiseMin(upper);
    if (left_trusted)
    {
      a(0) = bounded(0);
    }
    if (right_trusted)
    {
      a(1) = bounded(1);
    }
  }
  if (params_.max_action_lead_turn > 0.0 && left_trusted && right_trusted)
  {
    // Differential (turning) lead bounded, common lead kept: e_L = c - d, e_R = c + d.
    // Both wheel channels must be trusted: the lead is measured against them.
    base::Vector2 lead = commonDifferential(a - omega);
    lead(1) = std::clamp(lead(1), -params_.max_action_lead_turn, params_.max_action_lead_turn);
    a = omega + wheelPair(lead);
  }
  const base::Vector2 unsaturated = a;
  a = limitWheelSpeed(a);  // applied last: the wheel clamp always wins
  // Where a clamp cut a wheel's command in the direction a_F integrates, a_F integrates only up
  // to the clamp (a - a_ff) and is never pulled back by it, so it cannot wind up against a limit,
  // and a cut of the prior's part is not stored in a_F (it comes back once the wheels catch up).
  Result result{ a, a_F, a != unsaturated };
  for (int i = 0; i < 2; ++i)
  {
    result.free_energy_part(i) = conditionalIntegration(a_F(i), candidate(i), a_dot(i), raw(i) - a(i), a(i) - prior(i));
  }
  return result;
}

}  // namespace aic
}  // namespace jackal_aic
