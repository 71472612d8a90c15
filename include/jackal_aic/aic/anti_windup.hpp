#pragma once
/**
 * \file anti_windup.hpp
 * \brief The action's clamps and the conditional integration of its free-energy part (not in the
 *        thesis; doc/active_inference.md, 'Update rules', Anti-windup). ROS-free.
 */

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief The conditional integration of one wheel's free-energy part a_F behind a clamp of its
 *        command (AntiWindup, ActionSlewLimit): where the clamp cut the command (cut = unclamped -
 *        clamped command) in the direction a_F integrates, a_F integrates only up to the clamp and
 *        is never pulled back by it:
 *          max(a_F, min(candidate, at_clamp))   if cut > 0 and a_dot > 0,
 *          min(a_F, max(candidate, at_clamp))   if cut < 0 and a_dot < 0,
 *          candidate                            otherwise.
 * \param a_F        the wheel's a_F before the step [rad/s]
 * \param candidate  its update without the clamp [rad/s]
 * \param a_dot      da_F/dt of the wheel [rad/s^2] (its sign is the direction a_F integrates)
 * \param cut        the unclamped less the clamped command [rad/s]
 * \param at_clamp   the clamped command less the action prior, a - a_ff [rad/s]
 * \return the wheel's a_F after the step [rad/s]. No exceptions.
 */
double conditionalIntegration(double a_F, double candidate, double a_dot, double cut, double at_clamp);

/**
 * \brief The command a = clamps(a_F + h a_F' + a_ff) and the a_F it leaves.
 *
 * The clamps, in order, on the sum raw = a_F + h a_F' + a_ff (a_F' = da_F/dt of eq. 3-16, a_ff the
 * action prior), with omega the measured wheel speeds y^(0)[omega_L], y^(0)[omega_R]:
 *  1. lead (max_action_lead L > 0): a_i in [min(omega_i - L, a_ff,i), max(omega_i + L, a_ff,i)]
 *     (the prior alone is never cut), only on a wheel whose channel is trusted;
 *  2. turning lead (max_action_lead_turn L_t > 0, both wheel channels trusted): the differential
 *     part (e_R - e_L) / 2 of the lead e = a - omega within +-L_t, its common part kept;
 *  3. wheel speed: a_i in [-max_wheel_speed, max_wheel_speed] (AicParams::max_wheel_speed: the
 *     robot's, shared; always; it wins over the others).
 * Conditional integration: where a clamp cut a wheel's command (raw_i != a_i) in the direction
 * a_F' integrates,
 *   a_F,i <- max(a_F,i, min(a_F,i + h a_F,i', a_i - a_ff,i))   if cut > 0 and a_F,i' > 0,
 *   a_F,i <- min(a_F,i, max(a_F,i + h a_F,i', a_i - a_ff,i))   if cut < 0 and a_F,i' < 0,
 *   a_F,i <- a_F,i + h a_F,i'                                   otherwise,
 * so a_F never winds up against a clamp, is never pulled back by one, and a cut of the prior's
 * part is not stored in it.
 *
 * No heap allocation, no exceptions.
 */
class AntiWindup
{
public:
  /// One clamped action step.
  struct Result
  {
    base::Vector2 command;           ///< a, the clamped command (omega_L, omega_R) [rad/s]
    base::Vector2 free_energy_part;  ///< a_F after the step [rad/s]
    bool saturated;                  ///< the wheel-speed clamp (3) cut the command (the lead clamps do not count)
  };

  /// \param params           the lead limits (AicParams::anti_windup, validated)
  /// \param max_wheel_speed  the wheel-speed clamp [rad/s], > 0 (AicParams::max_wheel_speed)
  explicit AntiWindup(const params::AntiWindupParams& params = params::AntiWindupParams(),
                      double max_wheel_speed = 20.0)
    : params_(params), max_wheel_speed_(max_wheel_speed)
  {
  }

  /// The settings in use.
  const params::AntiWindupParams& params() const { return params_; }
  /// The wheel-speed clamp in use [rad/s].
  double maxWheelSpeed() const { return max_wheel_speed_; }

  /**
   * \brief Clamp one action step and integrate a_F conditionally.
   * \param a_F            free-energy part before the step [rad/s]
   * \param candidate      its unclamped update a_F + h a_F' [rad/s]
   * \param a_dot          a_F' [rad/s^2] (its sign is the direction a_F integrates)
   * \param prior          the action prior a_ff [rad/s]
   * \param omega          measured wheel speeds (omega_L, omega_R) [rad/s]
   * \param left_trusted   the left wheel channel is used (not isolated by the sensor mask)
   * \param right_trusted  the right wheel channel is used
   * \return the command, the new a_F and whether the wheel-speed clamp cut the command.
   *         Inputs are expected finite (the controller checks candidate + prior first).
   */
  Result apply(const base::Vector2& a_F, const base::Vector2& candidate, const base::Vector2& a_dot,
               const base::Vector2& prior, const base::Vector2& omega, bool left_trusted, bool right_trusted) const;

  /// a with each wheel clamped to +-max_wheel_speed [rad/s].
  base::Vector2 limitWheelSpeed(const base::Vector2& a) const
  {
    return a.cwiseMax(-max_wheel_speed_).cwiseMin(max_wheel_speed_);
  }

private:
  params::AntiWindupParams params_;
  double max_wheel_speed_;
};

}  // namespace aic
}  // namespace jackal_aic
