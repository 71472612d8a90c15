#pragma once
/**
 * \file latency_learner.hpp
 * \brief The robot model's latency learned from the wheels' first motion after rest
 *        (doc/active_inference.md, 'Learning the latency'). ROS-free.
 */

#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Learns L, the time from a command to the wheels' response, where the data identify it:
 *        when the wheels start from rest.
 *
 * A start is a command leaving zero while the previous command was zero and the believed wheels
 * rest (commandSent()). The first wheel sample after it on which a side reads more than
 * `threshold` [rad/s] (kOnsetSigmas standard deviations of the encoder noise) gives that start's
 * latency: the L' under which the wheel loop's model, from rest, under the commands sent since the
 * start (WheelLoopModel::predictWithLatency()), predicts that reading at that time, found by
 * bisection in [min, max] (the prediction falls as L' grows; it moves in steps of the model's 1 ms
 * substep, WheelLoopModel::kSubstep, which is the estimate's resolution). The learned L is the mean of the
 * starts' latencies, the newest kMemory weighted alike (a running mean that forgets older starts
 * slowly). A start whose wheels have not moved by max + kWindow is dropped (a stall, a command too
 * small to move them).
 *
 * The estimate is what L is if the wheel loop's model is right: a plant whose wheels break away
 * late (friction beyond the model's) reads as a longer latency.
 *
 * No heap allocation, no exceptions.
 */
class LatencyLearner
{
public:
  /// Standard deviations of the encoder noise a reading must exceed to be the wheels' motion.
  static constexpr double kOnsetSigmas = 5.0;
  /// Starts weighted alike in the running mean.
  static constexpr int kMemory = 4;
  /// Time after max [s] to wait for the motion before a start is dropped.
  static constexpr double kWindow = 0.1;
  /// Bisection tolerance [s].
  static constexpr double kTolerance = 1.0e-5;

  /**
   * \param initial      the identified L [s], the learned value until a start is seen; in [min, max]
   * \param min, max     bounds of the learned L [s], 0 <= min <= max
   * \param encoder_noise sigma_e [rad/s], > 0 (the threshold is kOnsetSigmas sigma_e)
   */
  LatencyLearner(double initial, double min, double max, double encoder_noise);

  /// Back to `initial`, no start seen, none armed.
  void reset();

  /**
   * \brief A command u [rad/s] was sent at time t [s] (after the one before it, `previous`).
   * \param wheels_at_rest  the believed wheels are within the threshold of zero
   */
  void commandSent(double t, const base::Vector2& u, const base::Vector2& previous, bool wheels_at_rest);

  /**
   * \brief A wheel sample y [rad/s] at time t [s]; `loop` holds the commands sent (its own L unused).
   * \return true if this sample completed a start and the learned L changed
   */
  bool sample(double t, const base::Vector2& y, const WheelLoopModel& loop);

  /// Drop an armed start (a fault, a masked wheel: its samples are not the wheels' motion).
  void disarm() { armed_ = false; }
  /// A start from rest is armed: the command left zero and no wheel sample has shown its motion yet.
  bool armed() const { return armed_; }

  /// The learned L [s].
  double latency() const { return latency_; }
  /// The latency of the newest start [s] (NaN before one).
  double lastStart() const { return last_; }
  /// Starts seen.
  int starts() const { return starts_; }

private:
  double initial_;
  double min_;
  double max_;
  double threshold_;
  double latency_;
  double last_;
  bool armed_ = false;
  double start_time_ = 0.0;
  int starts_ = 0;
};

}  // namespace aic
}  // namespace jackal_aic
