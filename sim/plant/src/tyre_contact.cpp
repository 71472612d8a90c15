#include "jackal_sim/plant/tyre_contact.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace jackal_aic
{
namespace plant
{
double brushForceRatio(double slip, double stiffness, double mu)
{
  if (!(mu > 0.0))
  {
    return 0.0;
  }
  if (!(stiffness > 0.0) || !std::isfinite(stiffness))
  {
    return mu;
  }
  const double t = stiffness * std::max(0.0, slip) / (3.0 * mu);
  if (!(t < 1.0))
  {
    return mu;
  }
  return mu * t * (3.0 - 3.0 * t + t * t);
}

WheelSlip wheelSlip(double forward_speed, double rolling_speed, double sliding_speed, double min_reference)
{
  if (!(min_reference > 0.0) || !std::isfinite(min_reference) || !std::isfinite(forward_speed) ||
      !std::isfinite(rolling_speed) || !std::isfinite(sliding_speed))
  {
    throw std::invalid_argument("wheelSlip: the speeds must be finite and the minimum reference speed > 0");
  }
  WheelSlip s;
  s.reference_speed = std::max({ std::abs(forward_speed), std::abs(rolling_speed), min_reference });
  s.sliding_speed = std::abs(sliding_speed);
  s.slip = s.sliding_speed / s.reference_speed;
  return s;
}

OdeSlip odeSlip(const WheelSlip& s, double stiffness, double mu, double normal_load)
{
  if (!(stiffness > 0.0) || !std::isfinite(stiffness) || !(mu > 0.0) || !std::isfinite(mu) || !(normal_load > 0.0) ||
      !std::isfinite(normal_load))
  {
    throw std::invalid_argument("odeSlip: stiffness, mu and the normal load must be > 0 and finite");
  }
  // (F/N) / sigma, the secant of the brush curve; its limit at zero slip is the slope C.
  auto secant = [&](double slip) {
    return slip < 1e-9 * 3.0 * mu / stiffness ? stiffness : brushForceRatio(slip, stiffness, mu) / slip;
  };
  // Along the sliding: the secant at the current slip, at most the full-sliding slip 3 mu / C: below it
  // ODE's damper gives the brush force at the current sliding speed; beyond it the damper's force
  // exceeds mu N and the friction pyramid caps it (Coulomb sliding, as the brush model's).
  // Across the sliding: the law's slope at zero slip, V / (C N), its stiffest: ODE is given fdir1 from
  // the sliding at the start of the step, and this row keeps the sliding along it within the step. (The
  // isotropic law's own stiffness across a full sliding, F / |v_s|, is softer; with it the sliding
  // direction lags a step behind fdir1 and the wheels chatter.)
  const double full_sliding = 3.0 * mu / stiffness;
  OdeSlip out;
  out.along = s.reference_speed / (secant(std::min(s.slip, full_sliding)) * normal_load);
  out.across = s.reference_speed / (stiffness * normal_load);
  return out;
}

}  // namespace plant
}  // namespace jackal_aic
