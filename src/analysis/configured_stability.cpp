/**
 * \file configured_stability.cpp
 * \brief The stability check of a configuration at load
 *        (include/jackal_aic/analysis/configured_stability.hpp).
 */
#include "jackal_aic/analysis/configured_stability.hpp"

#include <sstream>
#include <stdexcept>

#include "jackal_aic/analysis/state_space.hpp"

namespace jackal_aic
{
namespace analysis
{
ConfiguredStability checkConfiguredStability(const params::AicParams& params)
{
  ConfiguredStability out;
  try
  {
    const ClosedLoopModel model(params, PlantModel());
    out.spectral_radius = model.spectralRadius();
    out.analysed = true;
    out.stable = out.spectral_radius < 1.0;  // NaN (a non-finite map) counts as unstable
  }
  catch (const std::exception& e)  // invalid parameters, or a model the linear one does not represent
  {
    out.reason = e.what();
  }
  return out;
}

std::string stabilityWarning(const params::AicParams& params)
{
  const ConfiguredStability s = checkConfiguredStability(params);
  if (!s.analysed || s.stable)
  {
    return "";
  }
  std::ostringstream os;
  os.precision(4);
  os << "unstable on the linear model at belief_rate " << params.belief_rate << " Hz, action_rate "
     << params.action_rate << " Hz, integrator " << params::toString(params.integrator) << ": spectral radius "
     << s.spectral_radius << " >= 1 (aic_analyze; doc/tuning.md, 'The stability check at load')";
  return os.str();
}
}  // namespace analysis
}  // namespace jackal_aic
