#pragma once
/**
 * \file periodic_thread.hpp
 * \brief A thread that runs a step at a fixed rate by sleeping to absolute deadlines
 *        (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)), with optional SCHED_FIFO
 *        priority, and the statistics of its wake-up intervals. ROS-free (POSIX).
 *
 * The jackal_AIC node runs its belief loop on it in wall-clock mode (doc/jackal_aic_node.md,
 * 'Loops'); aic_timing runs the same loop beside a bare one to measure both.
 *
 * Why absolute deadlines: a relative sleep of one period after each step drifts by the
 * step's duration and the wake-up latency every period; sleeping until t0 + k T does not
 * drift, so the achieved rate is the nominal one whenever the steps fit in a period. A
 * wake-up later than one whole period re-anchors the deadlines at the current time (no
 * burst of back-to-back steps); the step receives the measured interval and can cover it
 * (the node's LoopScheduler splits it into catch-up steps).
 */

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace jackal_aic
{
namespace os
{
/**
 * \brief Histogram of intervals with 1 us bins up to kMaxUs (longer ones in an overflow
 *        count, their maximum kept exactly), for period percentiles without storing samples.
 *        Fixed size (no allocation after construction). Not thread-safe.
 */
class IntervalHistogram
{
public:
  /// Largest interval with its own bin [us]; longer ones are counted as overflow.
  static constexpr int kMaxUs = 50000;

  IntervalHistogram();
  /// Add one interval [s]; non-finite or negative intervals are ignored.
  void add(double seconds);
  /// Number of intervals added.
  std::uint64_t count() const { return count_; }
  /// Largest interval added [s]; 0 if none.
  double max() const { return max_; }
  /**
   * \brief The q-quantile [s] (upper edge of the bin where the cumulative count reaches
   *        q * count, so its resolution is 1 us); the exact max() for an overflow.
   * \param q  in [0, 1]; values outside are clamped
   * \return 0 if the histogram is empty
   */
  double quantile(double q) const;
  /// Forget every interval.
  void clear();

private:
  std::vector<std::uint64_t> bins_;  ///< bins_[i]: intervals in [i, i+1) us; the last: overflow
  std::uint64_t count_ = 0;
  double max_ = 0.0;
};

/// Wake-up statistics of a PeriodicThread.
struct PeriodicStats
{
  double rate = 0.0;                       ///< nominal rate at the time of the snapshot [Hz]
  std::uint64_t wakeups = 0;               ///< steps run (one per wake-up)
  std::uint64_t overruns = 0;              ///< wake-ups more than 2 nominal periods after the previous one
  std::uint64_t reanchors = 0;             ///< deadlines re-anchored after a wake-up later than one whole period
  double elapsed = 0.0;                    ///< wall time from the first wake-up to the snapshot [s] (CLOCK_MONOTONIC)
  double cpu = 0.0;                        ///< CPU time of the thread (user + system) [s] (CLOCK_THREAD_CPUTIME_ID)
  double p50 = 0.0, p99 = 0.0, max = 0.0;  ///< wake-up interval percentiles and maximum [s]
  /// Achieved rate [Hz]: intervals per elapsed second (0 before two wake-ups).
  double achievedRate() const { return elapsed > 0.0 && wakeups > 1 ? (wakeups - 1) / elapsed : 0.0; }
  /// CPU share of one core [-] (cpu / elapsed).
  double cpuShare() const { return elapsed > 0.0 ? cpu / elapsed : 0.0; }
};

/**
 * \brief Runs `step(interval)` at a nominal rate on its own thread, sleeping to absolute
 *        CLOCK_MONOTONIC deadlines.
 *
 * The step gets the measured interval since the previous wake-up [s] (-1 on the first call,
 * as a ros::TimerEvent without last_real). Wake-up intervals go into a histogram (read by
 * stats()); the thread's CPU time is read live through pthread_getcpuclockid().
 * Threading: start(), stop(), setRate() and stats() are for one controlling thread; step
 * runs on the periodic thread and must do its own locking of shared data.
 */
class PeriodicThread
{
public:
  /// The work of one period: measured interval since the previous call [s], -1 on the first.
  using Step = std::function<void(double interval)>;
  /**
   * \brief How the thread waits for a deadline: block until CLOCK_MONOTONIC reaches
   *        `deadline_ns` [ns] (never return before it), possibly doing work meanwhile (the
   *        node serves its sensor callbacks); `period_ns`: the current period [ns].
   *        Default: sleepUntil(deadline_ns).
   */
  using Wait = std::function<void(std::int64_t deadline_ns, std::int64_t period_ns)>;

  /**
   * \param step  called once per period on the thread
   * \param name  thread name (pthread_setname_np, at most 15 characters shown in top/ps)
   * \param wait  how to wait for each deadline (empty: sleepUntil)
   * \throws std::invalid_argument for an empty step
   */
  PeriodicThread(Step step, std::string name, Wait wait = Wait());

  /// Sleep until CLOCK_MONOTONIC reaches `deadline_ns` [ns] (clock_nanosleep, TIMER_ABSTIME;
  /// resumed after a signal). Returns at once for a past deadline.
  static void sleepUntil(std::int64_t deadline_ns);
  /// CLOCK_MONOTONIC now [ns] (the clock of the deadlines).
  static std::int64_t monotonicNow();
  /// Stops the thread (joins it).
  ~PeriodicThread();
  PeriodicThread(const PeriodicThread&) = delete;
  PeriodicThread& operator=(const PeriodicThread&) = delete;

  /**
   * \brief Start the thread at `rate`.
   * \param rate      nominal rate [Hz], finite, > 0 and <= 1e6
   * \param priority  0: the default scheduler; 1..99: ask for SCHED_FIFO at that priority
   * \return a message for the log about the priority: empty when none was asked, else
   *         "SCHED_FIFO priority N" or why it was refused (e.g. EPERM without
   *         CAP_SYS_NICE / an rtprio limit); the thread runs either way
   * \throws std::invalid_argument for a bad rate or priority; std::logic_error if running
   */
  std::string start(double rate, int priority = 0);
  /// Ask the thread to finish its current step and join it; idempotent.
  void stop();
  /// True between start() and stop().
  bool running() const { return thread_.joinable(); }
  /**
   * \brief Change the nominal rate [Hz] (finite, > 0, <= 1e6); takes effect at the next deadline.
   * \throws std::invalid_argument for a bad rate
   */
  void setRate(double rate);
  /// Nominal rate [Hz].
  double rate() const { return 1e9 / static_cast<double>(period_ns_.load()); }
  /**
   * \brief Statistics so far. Counters and CPU are live; the interval percentiles are
   *        consistent while the thread runs only approximately (the histogram is read
   *        without a lock) and exactly after stop().
   */
  PeriodicStats stats() const;

private:
  void run();

  Step step_;
  std::string name_;
  Wait wait_;
  std::thread thread_;
  std::atomic<bool> stop_{ false };
  std::atomic<std::int64_t> period_ns_{ 1000000 };
  std::atomic<std::uint64_t> wakeups_{ 0 }, overruns_{ 0 }, reanchors_{ 0 };
  std::atomic<std::int64_t> first_wakeup_ns_{ -1 }, last_wakeup_ns_{ -1 };
  std::atomic<double> cpu_at_stop_{ 0.0 };
  IntervalHistogram histogram_;
};

}  // namespace os
}  // namespace jackal_aic
