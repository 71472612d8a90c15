#pragma once
/**
 * \file json_number.hpp
 * \brief A number as JSON text, for the machine-readable output of the core and the tools.
 *        Header-only, standard library only (ROS-free).
 */

#include <cmath>
#include <sstream>
#include <string>

namespace jackal_aic
{
namespace base
{
/**
 * \brief A number as JSON text, the tools' machine-readable output: `precision` significant
 *        digits, and `null` for NaN or +-Inf (JSON has no such numbers; a metric that is
 *        undefined, such as the settling time of a response that never settles, is NaN).
 */
inline std::string jsonNumber(double v, int precision = 6)
{
  if (!std::isfinite(v))
  {
    return "null";
  }
  std::ostringstream os;
  os.precision(precision);
  os << v;
  return os.str();
}

}  // namespace base
}  // namespace jackal_aic
