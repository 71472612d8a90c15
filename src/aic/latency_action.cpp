/**
 * \file latency_action.cpp
 * \brief The robot model's action through the latency (doc/active_inference.md, 'The robot model').
 */
#include "jackal_aic/aic/latency_action.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace jackal_aic
{
namespace aic
{
namespace
{
/// The command within [-max_speed, max_speed] nearest `previous` whose response from omega0 over h
/// is g (or, g out of reach, the most the loop gives toward it), by bisection; side s's command
/// sent at time now, its rate after the newest recorded (WheelLoopModel::rateOf()).
double minimiser(const WheelLoopModel& loop, int s, double now, double omega0, double d, double h, double g,
                 double previous, double max_speed)
{
  const auto response = [&](double u) {
    return LatencyAction::response(loop, omega0, u, loop.rateOf(now, u, s), d, h);
  };
  const double lo_response = response(-max_speed);
  const double hi_response = response(max_speed);
  const double target = std::clamp(g, lo_response, hi_response);
  const double at_previous = response(std::clamp(previous, -max_speed, max_speed));
  double lo = -max_speed;
  double hi = max_speed;
  // Upward: the smallest command reaching the target; downward: the largest. Either way the
  // nearest to the previous action on a plateau of the rate bound.
  const bool upward = target >= at_previous;
  const double slack = 1.0e-9;
  while (hi - lo > LatencyAction::kTolerance)
  {
    const double mid = 0.5 * (lo + hi);
    const double r = response(mid);
    const bool below = upward ? r < target - slack : r <= target + slack;
    if (below)
    {
      lo = mid;
    }
    else
    {
      hi = mid;
    }
  }
  return upward ? hi : lo;
}
}  // namespace

double LatencyAction::response(const WheelLoopModel& loop, double omega0, double u, double rate, double d, double h)
{
  double omega = omega0;
  double t = 0.0;
  while (t < h - 1.0e-12)
  {
    const double dt = std::min(WheelLoopModel::kSubstep, h - t);
    omega = loop.step(omega, u - d, rate, dt);
    t += dt;
  }
  return omega;
}

base::Vector2 LatencyAction::compensated(const base::Vector2& shortfall, double limit)
{
  if (!(limit > 0.0))
  {
    return shortfall;
  }
  base::Vector2 d = shortfall;
  for (int s = 0; s < 2; ++s)
  {
    if (std::abs(d(s)) > limit)
    {
      d(s) = std::copysign(limit, d(s));
    }
  }
  return d;
}

base::Vector2 LatencyAction::inArc(const base::Vector2& shortfall, const base::Vector2& goal,
                                   const base::Vector2& omega)
{
  if (!(goal.allFinite() && omega.allFinite()))
  {
    return base::Vector2::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  if (!(goal(0) * goal(1) > 0.0))
  {
    return shortfall;
  }
  const double g_mean = 0.5 * (goal(0) + goal(1));
  const double direction = g_mean > 0.0 ? 1.0 : -1.0;
  const double short_of_goal = std::max(0.0, (g_mean - 0.5 * (omega(0) + omega(1))) * direction);
  const double common = 0.5 * (shortfall(0) + shortfall(1));
  const double turn = 0.5 * (shortfall(0) - shortfall(1));
  const double made_up = std::copysign(std::min(std::abs(common), short_of_goal), common);
  return base::Vector2(made_up + turn, made_up - turn);
}

LatencyActionResult LatencyAction::step(const WheelLoopModel& loop, const base::Vector2& omega,
                                        const base::Vector2& shortfall, double now, const base::Vector2& goal,
                                        const base::Vector2& previous, double h_a, double gain, double max_speed,
                                        double pi_e, const base::Vector2& reach)
{
  LatencyActionResult r;
  r.at_latency = loop.predict(omega, shortfall, now, now + loop.latency());
  const double fraction = std::min(1.0, gain * h_a);
  for (int s = 0; s < 2; ++s)
  {
    r.minimiser(s) = minimiser(loop, s, now, r.at_latency(s), shortfall(s), h_a, goal(s), previous(s), max_speed);
    r.command(s) = std::clamp(previous(s) + fraction * (r.minimiser(s) - previous(s)), -max_speed, max_speed);
    if (std::isfinite(reach(s)))
    {
      // Both ends within the command's bound, so lo <= hi whatever the steady command (a negative
      // reach is taken as 0).
      const double steady = goal(s) + shortfall(s);
      const double within = std::max(reach(s), 0.0);
      const double lo = std::clamp(steady - within, -max_speed, max_speed);
      const double hi = std::clamp(steady + within, -max_speed, max_speed);
      r.command(s) = std::clamp(r.command(s), lo, hi);
    }
    r.predicted(s) =
        response(loop, r.at_latency(s), r.command(s), loop.rateOf(now, r.command(s), s), shortfall(s), h_a);
  }
  r.free_energy = 0.5 * pi_e * (r.predicted - goal).squaredNorm();
  return r;
}

}  // namespace aic
}  // namespace jackal_aic
