#pragma once
/**
 * \file latency_action.hpp
 * \brief The robot model's action: the wheel commands descend the free energy of the goal prior on
 *        the sensations they cause, predicted through the latency and the wheel loop
 *        (doc/active_inference.md, 'The robot model'). ROS-free.
 */

#include <limits>

#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/// What one action step of LatencyAction found.
struct LatencyActionResult
{
  base::Vector2 command = base::Vector2::Zero();     ///< the new action a (omega_L, omega_R) [rad/s]
  base::Vector2 minimiser = base::Vector2::Zero();   ///< u*, the minimiser of F_a [rad/s]
  base::Vector2 at_latency = base::Vector2::Zero();  ///< predicted wheel speeds at t + L [rad/s]
  base::Vector2 predicted = base::Vector2::Zero();   ///< predicted wheel speeds at t + L + h_a under `command` [rad/s]
  double free_energy = 0.0;                          ///< F_a at `command` [-]
};

/**
 * \brief One action step of the robot model.
 *
 * The command a sent now reaches the wheels at t + L and is held there for the action step h_a, so
 * the sensation it causes is the wheel speed at t + L + h_a, omega_s(t + L + h_a | a): the belief
 * omega_s(t) carried through the commands in flight (WheelLoopModel::predict()) to t + L, then
 * through the wheel loop under a_s - d_s for h_a, with the feed-forward of a's rate after the
 * newest command (WheelLoopModel::rateOf()). The goal, predicted to that time, is its prior:
 *   F_a(a) = 1/2 sum_s pi_e (omega_s(t + L + h_a | a) - g_s)^2,   pi_e = 1 / sigma_e^2.
 * Each side's prediction is monotone in a_s, so the minimiser u* is found per side by bisection (to
 * kTolerance): where g_s is beyond what the wheel loop can give within h_a (its rate bound), the
 * command nearest the previous action that gives the most it can. The action then takes the
 * Gauss-Newton step of the descent da/dt = -k_a (J^T pi_e J)^{-1} dF_a/da over h_a,
 *   a <- a + min(1, k_a h_a) (u* - a),
 * J = d omega(t + L + h_a)/da from the same model (not the static K of thesis eq. 3-16). The
 * feed-forward (the model's inverse through the latency) and the feedback (the believed state's
 * departure from the goal's path) are the same term. A side given a finite `reach` keeps its command
 * within that of its steady command g_s + d_s: on a wheel that does not answer (a stall), the model
 * would otherwise ask for one more kick of the MCU's feed-forward every latency, and ramp the command
 * to max_speed.
 *
 * No heap allocation, no exceptions.
 */
class LatencyAction
{
public:
  /// Bisection tolerance on the command [rad/s].
  static constexpr double kTolerance = 1.0e-6;

  /**
   * \param loop        the wheel loop with the commands sent so far (the clock's `now` is the newest)
   * \param omega       believed wheel speeds now [rad/s]
   * \param shortfall   believed shortfalls d [rad/s]
   * \param now         the model's clock [s]
   * \param goal        the wheels' goal g at t + L + h_a [rad/s]
   * \param previous    the action held now [rad/s]
   * \param h_a         the action step [s], > 0; the cost grows as h_a / WheelLoopModel::kSubstep
   *                    per bisection step (the controller's steps are at most params::kMaxStep)
   * \param gain        k_a [1/s], > 0
   * \param max_speed   the command's bound [rad/s], > 0
   * \param pi_e        the goal prior's precision [(rad/s)^-2], > 0 (only scales free_energy)
   * \param reach       per side, the largest |a_s - (g_s + d_s)| [rad/s] the command may take, >= 0
   *                    (a negative one is taken as 0; +inf or NaN: none): a stalled side's is
   *                    WheelLoopModel::kickRange() (the controller; RobotBelief::stalled())
   */
  static LatencyActionResult
  step(const WheelLoopModel& loop, const base::Vector2& omega, const base::Vector2& shortfall, double now,
       const base::Vector2& goal, const base::Vector2& previous, double h_a, double gain, double max_speed, double pi_e,
       const base::Vector2& reach = base::Vector2::Constant(std::numeric_limits<double>::infinity()));

  /// One side's wheel speed after h [s] from omega0 [rad/s] under the command u less d [rad/s], the
  /// command stream's rate being `rate` [rad/s^2] (WheelLoopModel::step()), in substeps of at most
  /// WheelLoopModel::kSubstep: h / kSubstep steps, so the caller bounds h.
  static double response(const WheelLoopModel& loop, double omega0, double u, double rate, double d, double h);

  /// The shortfall the action makes up (step()'s `shortfall`): each side's believed shortfall d
  /// [rad/s] bounded to +-limit [rad/s], limit = shortfall_compensation_limit e_c (0: unbounded).
  /// Beyond e_c the MCU's proportional path is saturated: the wheel answers a raised command only
  /// through the integral path, over seconds, and overshoots when that has caught up
  /// (doc/active_inference.md, 'The robot model', 'Ending a chase of jumps'). The belief keeps the
  /// whole d. A NaN d passes unchanged (the caller's runaway check sees it); limit must be >= 0.
  static base::Vector2 compensated(const base::Vector2& shortfall, double limit);

  /**
   * \brief The shortfall the action makes up in an arc: its differential part in full, its common
   *        part only as far as the wheels' mean speed falls short of the goal's.
   *
   * In an arc (both wheels' goals in one direction) the body couples the sides: a turn it resists
   * (scrub) holds the outer wheel back and the body pushes the inner one over its command, so the
   * wheels roll at the body's speed and only the outer one shows a shortfall. Made up on that side
   * alone, it raises the body's speed, not its turn. With d = (d_L, d_R), the common part
   * d_c = (d_L + d_R)/2 and the differential part d_t = (d_L - d_R)/2, the action makes up
   *   (d_c' + d_t, d_c' - d_t),   d_c' = sign(d_c) min(|d_c|, max(0, sign(g_m) (g_m - omega_m))),
   * g_m and omega_m the means of the goal's and the believed wheel speeds: the turn's part in full,
   * the speed's only where the wheels are short of the goal's speed (doc/active_inference.md, 'The
   * robot model', 'A shortfall in an arc').
   *
   * \param shortfall the shortfalls the action would make up otherwise (d_L, d_R) [rad/s]
   * \param goal      the wheels' goal g [rad/s]
   * \param omega     the believed wheel speeds [rad/s]
   * \return the shortfalls to make up [rad/s]; `shortfall` unchanged unless both goals are nonzero
   *         and of one sign (an arc; a turn in place or a stop is left alone); NaN where the goal
   *         or a wheel speed is not finite (a non-finite shortfall passes through): the caller's
   *         runaway check sees it.
   */
  static base::Vector2 inArc(const base::Vector2& shortfall, const base::Vector2& goal, const base::Vector2& omega);
};

}  // namespace aic
}  // namespace jackal_aic
