#pragma once
/**
 * \file wheel_loop_model.hpp
 * \brief The robot model's wheel loop: the commands in flight through the latency and the MCU's
 *        rate-bounded first-order response to them (doc/active_inference.md, 'The robot model').
 *        ROS-free.
 */

#include <array>

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/robot_model_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief The sent wheel commands and the model of how each side's wheel speed answers them.
 *
 * record(t, u) stores the command u = (omega_L, omega_R) [rad/s] sent at time t [s] (the model's
 * clock, advanced by the caller); the command in effect at the wheels at time t is the newest one
 * sent at or before t - L (commandAt()), zero before the first, and its rate the difference to the
 * command before it over their interval (commandRateAt(): what the MCU's acceleration feed-forward
 * differentiates). step() advances one side's wheel speed by the MCU's response,
 *   omega <- omega + clamp((u - omega) (1 - exp(-h / T_w)), -(A_w - A_ff) h, (A_w - A_ff) h)
 *                  + clamp(c u', -A_ff, A_ff) h
 * (the lag integrated exactly with u held, then its rate bound; plus the feed-forward of the rate
 * u'), and predict() runs it over the commands in flight.
 *
 * No heap allocation (fixed capacity kCapacity), no exceptions.
 */
class WheelLoopModel
{
public:
  /// Commands remembered; older ones are forgotten (the oldest kept stands in for them).
  static constexpr int kCapacity = 1024;

  /// \param params  the latency, T_w and A_w (validated by the caller)
  explicit WheelLoopModel(const params::RobotModelParams& params = params::RobotModelParams());

  /// Replace L, T_w, A_w; the history is kept.
  void setParams(const params::RobotModelParams& params);

  /// Forget every command: the history is u at time t [s].
  void reset(double t, const base::Vector2& u);
  /// Store the command u [rad/s] sent at time t [s] (t not before the newest stored; an earlier t
  /// is taken as the newest's).
  void record(double t, const base::Vector2& u);
  /// The command in effect at the wheels at time t [s]: the newest sent at or before t - L [rad/s].
  base::Vector2 commandAt(double t) const;
  /// The rate of the command in effect at time t [rad/s^2]: its difference to the command sent before
  /// it over their interval (at least kSubstep); zero for the oldest remembered.
  base::Vector2 commandRateAt(double t) const;
  /// The newest command sent [rad/s] (zero before the first).
  base::Vector2 lastCommand() const;
  /// The rate [rad/s^2] a command u sent at time t [s] would have after the newest one (as
  /// commandRateAt() will give once it is recorded).
  base::Vector2 rateOf(double t, const base::Vector2& u) const;
  /// Scalar form of rateOf() for one side s (0 left, 1 right).
  double rateOf(double t, double u, int s) const;

  /**
   * \brief One side's wheel speed after h [s] with the command u held [rad/s] and the command
   *        stream's rate `rate` [rad/s^2]: the lag integrated exactly, its change bounded by
   *        (A_w - A_ff) h, plus the feed-forward clamp(c rate, -A_ff, A_ff) h.
   * \param[out] gain  d(result)/d(omega) (exp(-h / T_w), or 1 when the lag's bound is active); may be null
   */
  double step(double omega, double u, double rate, double h, double* gain = nullptr) const;

  /**
   * \brief The wheel speeds at time t1 > t0 from omega0 at t0 [s], under the commands in flight
   *        (commandAt(), commandRateAt()) less the shortfall d [rad/s], in substeps of at most kSubstep.
   *        Its cost is (t1 - t0) / kSubstep steps, without bound: the caller bounds the span (the
   *        controller's steps are at most params::kMaxStep, the latency at most its range).
   */
  base::Vector2 predict(const base::Vector2& omega0, const base::Vector2& d, double t0, double t1) const;
  /// predict() with the commands taking effect a latency `latency` [s] after they were sent instead of L.
  base::Vector2 predictWithLatency(const base::Vector2& omega0, const base::Vector2& d, double t0, double t1,
                                   double latency) const;

  /// Substep of predict() [s].
  static constexpr double kSubstep = 1.0e-3;

  /**
   * \brief The kick range [rad/s]: how far beyond the wheel's steady command a command sent for one
   *        step h [s] still buys acceleration within that step, the lag's share reaching its bound
   *        plus the feed-forward's share reaching its clamp,
   *          (A_w - A_ff) h / (1 - exp(-h / T_w)) + A_ff h / c
   *        (the second term 0 without the feed-forward, c = 0; the first (A_w - A_ff) h with T_w = 0).
   *        A command further out gives the same response in that step (step()): on a wheel that does
   *        not answer, a further rise only winds the command up. 0 unless h is finite and > 0.
   */
  double kickRange(double h) const;
  /// L [s].
  double latency() const { return params_.latency; }
  /// Replace L [s] (a learned latency; the history is kept).
  void setLatency(double latency) { params_.latency = latency; }

private:
  struct Entry
  {
    double t;
    base::Vector2 u;
    base::Vector2 rate;  ///< (u - the previous entry's u) / the interval
  };
  /// The entry in effect at the wheels at time t under the latency L (the oldest if all are newer).
  const Entry& entryAt(double t, double latency) const;
  /// Its rate at time t under L: zero if it is the oldest standing in for older commands.
  static base::Vector2 rateIn(const Entry& e, double t, double latency);
  params::RobotModelParams params_;
  std::array<Entry, kCapacity> line_{};
  int head_ = 0;   ///< index of the newest entry
  int count_ = 1;  ///< entries in the line
};

}  // namespace aic
}  // namespace jackal_aic
