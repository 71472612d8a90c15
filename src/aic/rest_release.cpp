/**
 * \file rest_release.cpp
 * \brief Release of the free-energy action at rest (doc/active_inference.md, 'Update rules', Release at rest).
 */
#include "jackal_aic/aic/rest_release.hpp"

#include <cmath>

#include "jackal_aic/aic/skid_steer_model.hpp"

namespace jackal_aic
{
namespace aic
{
base::Vector2 RestRelease::apply(const base::Vector2& a_F, const base::Vector3& goal, double h) const
{
  if (release_time_ <= 0.0)
  {
    return a_F;
  }
  // a_F's part along a channel whose goal is zero decays (common part: the linear goal,
  // differential part: the yaw-rate goal).
  const double keep = std::exp(-h / release_time_);
  base::Vector2 cd = commonDifferential(a_F);
  if (goal(0) == 0.0 && goal(1) == 0.0)
  {
    cd(0) *= keep;
  }
  if (goal(2) == 0.0)
  {
    cd(1) *= keep;
  }
  return wheelPair(cd);
}

}  // namespace aic
}  // namespace jackal_aic
