#pragma once
/**
 * \file action_slew_limit.hpp
 * \brief The slew limit of the action: each wheel command moves by at most a rate times the action
 *        step, with the conditional integration of the free-energy part behind it (not in the
 *        thesis; doc/extending.md, the worked example). ROS-free.
 */

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief After the anti-windup clamps (AntiWindup), with a_prev the command of the previous action
 *        step, the change d = a - a_prev of one step of h seconds is bounded by
 *          s = min(1, S h / max_i |d_i|),   a <- a_prev + s d,
 *        S = action_slew_limit [rad/s^2]: the wheel with the larger change moves by at most S h, the
 *        other by the same fraction of its change, so the direction of the change (an arc's ratio of
 *        the wheel speeds, from rest) is kept while the limit acts. Where it cut a wheel's command, its
 *        free-energy part a_F integrates conditionally (conditionalIntegration(), as behind the
 *        AntiWindup's clamps): it does not wind up while the command slews.
 *
 * The limit is a bound on the rate of a; a command within the wheel-speed clamp stays within it
 * (a lies between a_prev and the clamped command). The linear analysis (ClosedLoopModel) leaves it
 * out: doc/extending.md, 'The stability model'.
 *
 * No heap allocation, no exceptions.
 */
class ActionSlewLimit
{
public:
  /// One slew-limited action step.
  struct Result
  {
    base::Vector2 command;           ///< a, the limited command (omega_L, omega_R) [rad/s]
    base::Vector2 free_energy_part;  ///< a_F after the step [rad/s]
    bool limited;                    ///< the limit cut the command
  };

  /// \param params  the limit (AicParams::action_slew, validated: max_rate finite and >= 0)
  explicit ActionSlewLimit(const params::ActionSlewLimitParams& params = params::ActionSlewLimitParams())
    : params_(params)
  {
  }

  /// The settings in use.
  const params::ActionSlewLimitParams& params() const { return params_; }
  /// True when the limit acts (max_rate > 0; a NaN, which the schema refuses, is off).
  bool enabled() const { return params_.max_rate > 0.0; }

  /**
   * \brief The command after the limit: previous + s (command - previous), s = min(1, S h / max_i
   *        |command_i - previous_i|) [rad/s] (both wheels scaled alike). command unchanged, bit for
   *        bit, when !enabled(), when h is not finite and > 0, or when the change is not finite.
   * \param[out] limited  true when the limit cut the command; may be null
   */
  base::Vector2 limit(const base::Vector2& previous, const base::Vector2& command, double h,
                      bool* limited = nullptr) const;

  /**
   * \brief Limit one action step's command and integrate a_F conditionally behind the limit.
   * \param previous   the command of the previous action step a_prev [rad/s]
   * \param command    this step's command after the AntiWindup's clamps [rad/s]
   * \param a_F        free-energy part before the step [rad/s]
   * \param candidate  free-energy part after the AntiWindup (its Result::free_energy_part) [rad/s]
   * \param a_dot      da_F/dt [rad/s^2] (its sign is the direction a_F integrates)
   * \param prior      the action prior a_ff [rad/s]
   * \param h          action step [s]
   * \return (command, candidate, false) unchanged, bit for bit, when !enabled(), when h is not finite
   *         and > 0, when previous or command is not finite (the controller's divergence check runs
   *         before), or when the change is within S h on both wheels.
   */
  Result apply(const base::Vector2& previous, const base::Vector2& command, const base::Vector2& a_F,
               const base::Vector2& candidate, const base::Vector2& a_dot, const base::Vector2& prior, double h) const;

private:
  params::ActionSlewLimitParams params_;
};

}  // namespace aic
}  // namespace jackal_aic
