#pragma once
/**
 * \file param_violation.hpp
 * \brief One violated parameter rule, as the validate() of every settings struct reports it. ROS-free.
 */

#include <string>

namespace jackal_aic
{
namespace params
{
/// One violated rule of AicParams::validate().
struct ParamViolation
{
  std::string name;     ///< parameter name as in the YAML file, e.g. "tau" or "var_mu[2]"
  std::string value;    ///< offending value, printed
  std::string allowed;  ///< allowed range, e.g. "> 0 and finite"
  /// "tau = -1 (allowed: > 0 and finite)".
  std::string toString() const;
};
}  // namespace params
}  // namespace jackal_aic
