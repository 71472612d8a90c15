#pragma once
/**
 * \file action_delay_line.hpp
 * \brief The unbiased beliefs' motion prior: the body twist G a(t - d_r) of the action sent a
 *        latency d_r ago (Baioumy, Pezzato, Ferrari & Hawes, IROS 2022; doc/active_inference.md,
 *        'Unbiased beliefs'). ROS-free.
 */

#include <array>

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Delay line of the sent action's body twist u = G a, one sample per action step.
 *
 * record(h, u) advances the action clock by h and stores u as sent at the new time, held until
 * the next action step (zero-order hold); delayed() is then the newest sample sent at or before
 * t - d_r, or the oldest one if the line is shorter than the delay. With belief_model unbiased the
 * beliefs' state prior is f(mu, a) = (G a(t - d_r) - mu) / tau.
 *
 * No heap allocation (fixed capacity kCapacity), no exceptions.
 */
class ActionDelayLine
{
public:
  /// Length of the line [action steps]; a delay longer than kCapacity steps uses the oldest.
  static constexpr int kCapacity = 512;

  /// \param delay  d_r [s], >= 0 (AicParams::reference.delay)
  explicit ActionDelayLine(double delay = 0.0) : delay_(delay) {}

  /// Set d_r [s], >= 0; takes effect at the next record().
  void setDelay(double delay) { delay_ = delay; }
  /// d_r in use [s].
  double delay() const { return delay_; }

  /// Restart the line at the twist u [m/s, m/s, rad/s] held now (one sample at the current
  /// clock; delayed() = u). The clock is kept.
  void restart(const base::Vector3& u);
  /// Clock back to 0, then restart(u).
  void reset(const base::Vector3& u);
  /**
   * \brief Record the twist u [m/s, m/s, rad/s] of the action just sent, after an action step
   *        h [s] (finite and > 0), and update delayed().
   */
  void record(double h, const base::Vector3& u);

  /// G a(t - d_r) [m/s, m/s, rad/s]: the unbiased state prior's target.
  const base::Vector3& delayed() const { return delayed_; }
  /// The action clock [s]: the sum of the recorded steps since reset().
  double clock() const { return time_; }
  /// Samples in the line, 1 ... kCapacity.
  int size() const { return count_; }

private:
  /// One sample: action clock [s], twist G a.
  struct Sample
  {
    double t;
    base::Vector3 u;
  };

  double delay_;
  std::array<Sample, kCapacity> line_{};
  int head_ = 0;
  int count_ = 1;
  double time_ = 0.0;
  base::Vector3 delayed_ = base::Vector3::Zero();
};

}  // namespace aic
}  // namespace jackal_aic
