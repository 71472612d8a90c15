/**
 * \file param_violation.cpp
 * \brief ParamViolation's one-line text.
 */
#include "jackal_aic/params/param_violation.hpp"

namespace jackal_aic
{
namespace params
{
std::string ParamViolation::toString() const
{
  return name + " = " + value + " (allowed: " + allowed + ")";
}
}  // namespace params
}  // namespace jackal_aic
