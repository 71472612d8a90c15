/**
 * \file fdi_params.cpp
 * \brief FdiParams::validate(): the ranges of the fdi_* keys (doc/jackal_aic_node.md, 'Parameters').
 */
#include "jackal_aic/params/fdi_params.hpp"

#include <cmath>
#include <sstream>
#include <string>

namespace jackal_aic
{
namespace params
{
namespace
{
std::string number(double v)
{
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}
}  // namespace

std::vector<ParamViolation> FdiParams::validate() const
{
  std::vector<ParamViolation> out;
  if (!(std::isfinite(threshold) && threshold > 0.0))
  {
    out.push_back({ "fdi_threshold", number(threshold), "> 0 and finite" });
  }
  if (!(std::isfinite(release_ratio) && release_ratio > 0.0 && release_ratio <= 1.0))
  {
    out.push_back({ "fdi_release_ratio", number(release_ratio), "in (0, 1]" });
  }
  if (!(std::isfinite(detect_time) && detect_time >= 0.0))
  {
    out.push_back({ "fdi_detect_time", number(detect_time), ">= 0 and finite" });
  }
  if (!(std::isfinite(release_time) && release_time >= 0.0))
  {
    out.push_back({ "fdi_release_time", number(release_time), ">= 0 and finite" });
  }
  return out;
}
}  // namespace params
}  // namespace jackal_aic
