/**
 * \file diff_drive_params.cpp
 * \brief DiffDriveParams::validate() (ros_controllers' diff_drive_controller parameters).
 */
#include "jackal_aic/params/diff_drive_params.hpp"

#include <cmath>
#include <sstream>

namespace jackal_aic
{
namespace params
{
namespace
{
void checkPositive(std::vector<std::string>* e, double v, const char* key)
{
  if (!(v > 0.0) || !std::isfinite(v))
  {
    std::ostringstream s;
    s << key << " = " << v << " (allowed: > 0, finite)";
    e->push_back(s.str());
  }
}
}  // namespace

std::vector<std::string> DiffDriveParams::validate() const
{
  std::vector<std::string> e;
  checkPositive(&e, wheel_radius, "wheel_radius");
  checkPositive(&e, wheel_separation, "wheel_separation");
  checkPositive(&e, wheel_separation_multiplier, "wheel_separation_multiplier");
  checkPositive(&e, max_linear_velocity, "max_linear_velocity");
  checkPositive(&e, max_linear_acceleration, "max_linear_acceleration");
  checkPositive(&e, max_angular_velocity, "max_angular_velocity");
  checkPositive(&e, max_angular_acceleration, "max_angular_acceleration");
  return e;
}
}  // namespace params
}  // namespace jackal_aic
