#pragma once
/**
 * \file action_prior.hpp
 * \brief The controller's action prior a_ff: the wheel speeds the goal's path predicts, through
 *        the inverse kinematics (not in the thesis; Adams, Shipp & Friston, Brain Struct. Funct.
 *        218, 2013; doc/active_inference.md, 'Action prior'). ROS-free.
 */

#include "jackal_aic/aic/reference_model.hpp"
#include "jackal_aic/aic/skid_steer_model.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief a_ff = k_ff W (m + T_p m') with a reference model, else a_ff = k_ff W mu_hat_d.
 *
 * W is the wheel rows (omega_L, omega_R) of the model's R, the inverse kinematics G^+ of eq. 3-3,
 * so W mu is the wheel speeds of a twist; m, m' the reference path and its rate and mu_hat_d the
 * predicted goal (ReferenceModel). m + T_p m' inverts a first-order wheel loop of time constant
 * T_p along the path. The action is a = a_F + a_ff, a_F the free-energy part (eq. 3-16).
 *
 * No heap allocation, no exceptions.
 */
class ActionPrior
{
public:
  explicit ActionPrior(const params::ActionPriorParams& params = params::ActionPriorParams()) : params_(params) {}

  /// The settings in use.
  const params::ActionPriorParams& params() const { return params_; }
  /// True when the prior acts (gain > 0).
  bool enabled() const { return params_.gain > 0.0; }

  /**
   * \brief The prior a_ff = (omega_L, omega_R) [rad/s] for the goal's path.
   * \param model      the generative model whose R gives W
   * \param reference  the goal stage: its path m and rate m' if reference.enabled(), else its
   *                   predicted goal target()
   * \return zero when !enabled().
   */
  base::Vector2 wheels(const SkidSteerModel& model, const ReferenceModel& reference) const;

private:
  params::ActionPriorParams params_;
};

}  // namespace aic
}  // namespace jackal_aic
