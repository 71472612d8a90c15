#pragma once
/**
 * \file loop_scheduler.hpp
 * \brief Scheduling of one timer loop: the measured interval clamped and, for the belief
 *        loop, split into catch-up steps of about one nominal period; with the loop's
 *        statistics, which belong to it (doc/jackal_aic_node.md, 'Loops'). ROS-free.
 */

#include <cstdint>

namespace jackal_aic
{
namespace loop
{
/// The largest interval the action loop integrates over, in nominal periods (longer gaps are clamped).
constexpr double kMaxActionIntervalFactor = 3.0;
/// The largest interval the belief loop integrates over, in nominal periods; it is split into
/// steps of about one nominal period each (catch-up), so a late tick never means a long Euler step.
constexpr double kMaxBeliefIntervalFactor = 10.0;
/// ... but never less than this [s]: at 10 kHz ten periods are 1 ms, shorter than a scheduler
/// preemption on a loaded machine; up to 10 ms are caught up at any rate (100 steps of ~2 us at 10 kHz).
constexpr double kMinBeliefCatchUpInterval = 0.01;

/// Statistics of one timer loop; the window_* fields are reset at every diagnostics publication.
struct LoopStats
{
  double nominal_period = 0.0;         ///< 1 / rate [s]
  double max_factor = 3.0;             ///< longer intervals are clamped to maxInterval()
  double min_max_interval = 0.0;       ///< maxInterval() is at least this [s]
  std::uint64_t ticks = 0;             ///< callbacks since start
  std::uint64_t overruns = 0;          ///< measured interval > 2 nominal periods (a tick was missed)
  std::uint64_t clamped = 0;           ///< intervals clamped to max_factor periods
  std::uint64_t catch_up_steps = 0;    ///< extra integration steps run to cover missed ticks
  double window_max_interval = 0.0;    ///< largest measured interval in the window [s]
  double window_abs_jitter_sum = 0.0;  ///< sum of |interval - nominal| in the window [s]
  std::uint64_t window_ticks = 0;      ///< callbacks in the window
  double window_max_duration = 0.0;    ///< longest callback execution in the window [s]

  /// The longest interval integrated [s]: max(max_factor * nominal_period, min_max_interval),
  /// at most params::kMaxStep (the longest step the controller takes).
  double maxInterval() const;
  /// Record one measured interval [s]; a non-finite or non-positive one (first tick) counts as
  /// nominal_period. \return the interval to integrate with [s], clamped to maxInterval().
  double record(double interval);
  /// Zero the window_* statistics (after each diagnostics publication); counters are kept.
  void resetWindow();
};

/**
 * \brief Scheduling of one timer loop: clamps the measured interval and, with catch-up,
 *        splits it into integration steps of about one nominal period.
 *
 * Catch-up (the belief loop): the interval in nominal periods is added to a step debt;
 * the tick runs round(debt) steps, at least 1 and at most max_factor, of h = interval /
 * steps each, and keeps the remainder (bounded to [-1, 1]) for the next tick, so early and
 * late ticks average out to `rate` steps per second. Without catch-up (the action loop)
 * every tick is one step over the clamped interval.
 */
class LoopScheduler
{
public:
  /// One tick's integration plan.
  struct Tick
  {
    int steps = 1;          ///< integration steps to run, >= 1
    double h = 0.0;         ///< step length [s] (interval / steps)
    double interval = 0.0;  ///< the clamped interval [s]
  };

  /**
   * \param rate        nominal rate [Hz], > 0
   * \param max_factor  longest interval integrated, in nominal periods (kMaxBeliefIntervalFactor, ...)
   * \param catch_up    split long intervals into steps of about one period (at most
   *                    maxInterval() / nominal period steps a tick)
   * \param min_max_interval  the longest interval integrated is at least this [s] (kMinBeliefCatchUpInterval)
   */
  LoopScheduler(double rate, double max_factor, bool catch_up, double min_max_interval = 0.0);

  /// Change the nominal rate [Hz], > 0 (the step debt is kept).
  void setRate(double rate);
  /// Nominal rate [Hz].
  double rate() const { return 1.0 / stats_.nominal_period; }
  /// Nominal period [s].
  double nominalPeriod() const { return stats_.nominal_period; }

  /// Plan one tick from the measured interval since the previous one [s] (<= 0 or non-finite: first tick).
  Tick tick(double measured_interval);
  /// Record how long a callback took [s] (for the window's longest callback).
  void recordDuration(double seconds);
  /// The loop's statistics.
  const LoopStats& stats() const { return stats_; }
  /// Start a new statistics window (counters are kept).
  void resetWindow() { stats_.resetWindow(); }

private:
  LoopStats stats_;
  bool catch_up_;
  double debt_ = 0.0;  ///< steps owed, in nominal periods, in [-1, 1] between ticks
};
}  // namespace loop
}  // namespace jackal_aic
