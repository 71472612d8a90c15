#pragma once
/**
 * \file configured_stability.hpp
 * \brief The stability check of a configuration at load: the spectral radius of the linear
 *        closed loop (ClosedLoopModel, thesis ch. 4 and appendix A; aic_analyze's check) at the
 *        configuration's own belief rate, action rate and integrator, with the point-mass plant.
 *        The node (at start-up and on each accepted reconfigure) and the tools' configuration
 *        loading call it and warn; they do not refuse (doc/tuning.md, 'The stability check at
 *        load'). ROS-free.
 */

#include <string>

#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace analysis
{
/// The outcome of checkConfiguredStability().
struct ConfiguredStability
{
  bool analysed = false;         ///< false: the linear model cannot represent the configuration (see reason)
  double spectral_radius = 0.0;  ///< of the period map at the configured rates [-]; 0 when !analysed
  bool stable = true;            ///< spectral_radius < 1 (true when !analysed: nothing is claimed)
  std::string reason;            ///< why it was not analysed ("" when analysed)
};

/**
 * \brief Spectral radius of the linear closed loop of `params` at its belief_rate, action_rate
 *        and integrator, the plant a point mass (the wheels follow the command: thesis ch. 4; the
 *        default plant of aic_analyze, whose rows at the file's rates give the same figure).
 *
 * The linear model leaves out the wheel-speed clamp, the anti-windup lead, the slew limit, the
 * runaway reset, the set-point dynamics and the action prior (ClosedLoopModel): a radius >= 1 says the thesis's
 * controller with these gains diverges at these rates, or is held only by the clamps (the
 * thesis's table C-1, config/thesis_standard.yaml: 4.63, an oscillation bounded by the wheel
 * speed limit on the simulated Jackal).
 *
 * \param params  controller parameters; invalid ones give analysed = false with the violations
 *                in reason (the loaders refuse them before this check)
 * \return the radius, or analysed = false with the reason the model refused (e.g. a belief rate
 *         that is not a multiple of the action rate, or a belief_model other than goal). Never throws.
 */
ConfiguredStability checkConfiguredStability(const params::AicParams& params);

/**
 * \brief The warning of an unstable configuration, "" for a stable (or unanalysed) one:
 *        "unstable on the linear model at belief_rate B Hz, action_rate A Hz, integrator I:
 *        spectral radius R >= 1 (aic_analyze; doc/tuning.md, 'The stability check at load')".
 * \param params  controller parameters (as checkConfiguredStability())
 */
std::string stabilityWarning(const params::AicParams& params);
}  // namespace analysis
}  // namespace jackal_aic
