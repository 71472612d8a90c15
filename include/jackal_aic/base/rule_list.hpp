#pragma once
/**
 * \file rule_list.hpp
 * \brief The violated rules of a settings struct, collected into one message (the learners'
 *        constructors: SeparationLearner, PrecisionLearner, GyroBiasEstimator). ROS-free.
 */

#include <string>

namespace jackal_aic
{
namespace base
{
/**
 * \brief Collects the rules a settings struct violates, so that one std::invalid_argument names
 *        every violation, not only the first.
 *
 * Usage: `RuleList rules; rules.require(x > 0.0, "x > 0"); ... if (!rules.ok()) throw
 * std::invalid_argument("invalid Params:" + rules.violations());`
 */
class RuleList
{
public:
  /// Record `text` (the rule, e.g. "separation_min finite and > 0") when `ok` is false.
  void require(bool ok, const std::string& text)
  {
    if (!ok)
    {
      violations_ += " " + text + ";";
    }
  }
  /// True while every rule held.
  bool ok() const { return violations_.empty(); }
  /// The violated rules, each as " <rule>;" in the order required (empty when ok()).
  const std::string& violations() const { return violations_; }

private:
  std::string violations_;
};

}  // namespace base
}  // namespace jackal_aic
