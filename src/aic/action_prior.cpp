/**
 * \file action_prior.cpp
 * \brief The action prior a_ff (doc/active_inference.md, 'Action prior').
 */
#include "jackal_aic/aic/action_prior.hpp"

namespace jackal_aic
{
namespace aic
{
base::Vector2 ActionPrior::wheels(const SkidSteerModel& model, const ReferenceModel& reference) const
{
  if (params_.gain <= 0.0)
  {
    return base::Vector2::Zero();
  }
  // W = the wheel rows of R (the pseudo-inverse of G, eq. 3-3): the wheel speeds of a twist.
  base::Vector3 target = reference.target();
  if (reference.enabled())
  {
    // The reference path through the inverse of a first-order wheel loop: m + T_p m'.
    target = reference.path() + params_.time_constant * reference.rate();
  }
  const base::SensorMatrix& R = model.R();
  return params_.gain * base::Vector2(R.row(base::kOmegaLeft).dot(target), R.row(base::kOmegaRight).dot(target));
}

}  // namespace aic
}  // namespace jackal_aic
