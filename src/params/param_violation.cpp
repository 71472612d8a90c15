/**
 * \file param_violation.cpp
 * \brief ParamViolation's one-line text.
 */
#include "jackal_aic/params/param_violation.hpp"

namespace jackal_aic
{
std::string ParamViolation::toString() const
{
  return name + " = " + value + " (allowed: " + allowed + ")";
}
}  // namespace jackal_aic
