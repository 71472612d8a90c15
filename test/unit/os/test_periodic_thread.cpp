/**
 * \file test_periodic_thread.cpp
 * \brief IntervalHistogram quantiles (exact, deterministic) and PeriodicThread behaviour:
 *        steps run on their own thread at about the rate asked, receive the measured
 *        interval, stop promptly, change rate live, refuse bad arguments. Timing is checked
 *        with tolerances a loaded 2-core machine meets; the figures are aic_timing's job.
 */
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include "jackal_aic/os/periodic_thread.hpp"

using jackal_aic::os::IntervalHistogram;
using jackal_aic::os::PeriodicStats;
using jackal_aic::os::PeriodicThread;

TEST(IntervalHistogram, QuantilesOfKnownIntervals)
{
  IntervalHistogram h;
  EXPECT_EQ(h.quantile(0.5), 0.0);
  for (int i = 1; i <= 100; ++i)
  {
    h.add(i * 1e-4 + 0.5e-6);  // 100.5 us, 200.5 us, ... 10000.5 us
  }
  EXPECT_EQ(h.count(), 100u);
  EXPECT_NEAR(h.quantile(0.5), 50 * 1e-4 + 1e-6, 1e-12);  // 50th value's bin, upper edge
  EXPECT_NEAR(h.quantile(0.99), 99 * 1e-4 + 1e-6, 1e-12);
  EXPECT_NEAR(h.quantile(1.0), h.max(), 1e-12);
  EXPECT_NEAR(h.max(), 100 * 1e-4 + 0.5e-6, 1e-15);
  EXPECT_NEAR(h.quantile(0.0), 1e-4 + 1e-6, 1e-12);  // the first non-empty bin's upper edge
}

TEST(IntervalHistogram, OverflowKeepsTheExactMaximumAndIgnoresGarbage)
{
  IntervalHistogram h;
  h.add(0.001);
  h.add(0.2);  // beyond kMaxUs
  h.add(std::nan(""));
  h.add(-1.0);
  h.add(INFINITY);
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.max(), 0.2);
  EXPECT_EQ(h.quantile(1.0), 0.2);
  h.clear();
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.max(), 0.0);
}

TEST(PeriodicThread, RunsTheStepAtAboutTheRateWithMeasuredIntervals)
{
  std::mutex m;
  std::vector<double> intervals;
  const auto caller = std::this_thread::get_id();
  std::atomic<bool> other_thread{ true };
  PeriodicThread t(
      [&](double interval) {
        if (std::this_thread::get_id() == caller)
        {
          other_thread = false;
        }
        std::lock_guard<std::mutex> lock(m);
        intervals.push_back(interval);
      },
      "test_loop");
  EXPECT_EQ(t.start(500.0), "");
  EXPECT_TRUE(t.running());
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  t.stop();
  EXPECT_FALSE(t.running());
  const PeriodicStats s = t.stats();
  std::lock_guard<std::mutex> lock(m);
  ASSERT_GE(intervals.size(), 10u);  // 200 expected; a starved machine still runs some
  EXPECT_TRUE(other_thread);
  EXPECT_EQ(intervals.front(), -1.0);  // first call: no interval yet
  double sum = 0.0;
  for (std::size_t i = 1; i < intervals.size(); ++i)
  {
    EXPECT_GT(intervals[i], 0.0);
    sum += intervals[i];
  }
  EXPECT_EQ(s.wakeups, intervals.size());
  EXPECT_NEAR(s.elapsed, sum, 1e-6);  // the intervals tile the elapsed time
  EXPECT_EQ(s.rate, 500.0);
  // Absolute deadlines: the mean interval is the period unless the machine starves us (a
  // shared VM has been seen to lose half its CPU to its host for seconds: only a floor that
  // tells "runs periodically" from "stuck").
  EXPECT_GT(s.achievedRate(), 100.0);
  EXPECT_LT(s.achievedRate(), 510.0);
  EXPECT_GE(s.p99, s.p50);
  EXPECT_GE(s.max, s.p99);
  EXPECT_GE(s.cpu, 0.0);
  EXPECT_LT(s.cpuShare(), 1.0);
}

TEST(PeriodicThread, SetRateTakesEffectAndStopIsIdempotent)
{
  std::atomic<int> calls{ 0 };
  PeriodicThread t([&](double) { ++calls; }, "test_rate");
  t.start(1000.0);
  t.setRate(50.0);
  EXPECT_EQ(t.rate(), 50.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  t.stop();
  t.stop();
  // At 50 Hz for ~0.3 s: ~15 steps (+1 at the old rate); far fewer than 1 kHz would give.
  EXPECT_GE(calls.load(), 3);
  EXPECT_LE(calls.load(), 40);
  // Restartable.
  const int before = calls.load();
  t.start(200.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  t.stop();
  EXPECT_GT(calls.load(), before);
}

TEST(PeriodicThread, ACustomWaitGetsEachDeadlineAndItsPeriod)
{
  // The node's wait serves its subscribers until the deadline: the thread hands it each
  // absolute deadline, one period apart, and runs the step after it returns.
  std::mutex m;
  std::vector<std::int64_t> deadlines, periods, step_times;
  PeriodicThread t(
      [&](double) {
        const std::lock_guard<std::mutex> lock(m);
        step_times.push_back(PeriodicThread::monotonicNow());
      },
      "test_wait",
      [&](std::int64_t deadline, std::int64_t period) {
        {
          const std::lock_guard<std::mutex> lock(m);
          deadlines.push_back(deadline);
          periods.push_back(period);
        }
        PeriodicThread::sleepUntil(deadline);
      });
  t.start(200.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  t.stop();
  const std::lock_guard<std::mutex> lock(m);
  ASSERT_GE(deadlines.size(), 5u);
  ASSERT_GE(step_times.size(), deadlines.size() - 1);  // a wait may be cut short by stop()
  for (std::size_t k = 0; k < step_times.size(); ++k)
  {
    EXPECT_EQ(periods[k], 5000000);
    EXPECT_GE(step_times[k], deadlines[k]) << "step before its deadline";
    if (k > 0)
    {
      // One period apart unless a late wake-up re-anchored the deadlines (loaded machine).
      EXPECT_GE(deadlines[k] - deadlines[k - 1], 5000000);
    }
  }
  // sleepUntil a past deadline returns at once.
  const std::int64_t before = PeriodicThread::monotonicNow();
  PeriodicThread::sleepUntil(before - 1000000);
  EXPECT_LT(PeriodicThread::monotonicNow() - before, 50000000);
}

TEST(PeriodicThread, RefusesBadArguments)
{
  EXPECT_THROW(PeriodicThread(nullptr, "x"), std::invalid_argument);
  PeriodicThread t([](double) {}, "test_bad");
  for (double rate : { 0.0, -1.0, std::nan(""), static_cast<double>(INFINITY), 2e6 })
  {
    EXPECT_THROW(t.start(rate), std::invalid_argument) << rate;
    EXPECT_FALSE(t.running());
  }
  EXPECT_THROW(t.start(100.0, -1), std::invalid_argument);
  EXPECT_THROW(t.start(100.0, 100), std::invalid_argument);
  t.start(100.0);
  EXPECT_THROW(t.start(100.0), std::logic_error);
  EXPECT_THROW(t.setRate(0.0), std::invalid_argument);
  EXPECT_EQ(t.rate(), 100.0);
  t.stop();
}

/// Whether this process may give a thread SCHED_FIFO at `priority`: a probe thread asks for it.
/// \return 0 if granted, else the error pthread_setschedparam returned.
int fifoPermission(int priority)
{
  int err = -1;
  std::thread probe([&err, priority] {
    sched_param param{};
    param.sched_priority = priority;
    err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  });
  probe.join();
  return err;
}

TEST(PeriodicThread, RealtimePriorityIsGrantedOrRefusedWithAReason)
{
  // What this process is allowed decides which: granted where a probe thread gets SCHED_FIFO,
  // else refused with the probe's error and what would grant it. The loop runs in both cases.
  const int permission = fifoPermission(10);
  PeriodicThread t([](double) {}, "test_fifo");
  const std::string message = t.start(100.0, 10);
  if (permission == 0)
  {
    EXPECT_EQ(message, "SCHED_FIFO priority 10") << "granted to the probe thread";
  }
  else
  {
    EXPECT_EQ(message.rfind("SCHED_FIFO priority 10 refused (" + std::string(std::strerror(permission)), 0), 0u)
        << message;
    EXPECT_NE(message.find("CAP_SYS_NICE"), std::string::npos) << message;
    EXPECT_NE(message.find(": default scheduler"), std::string::npos) << message;
  }
  EXPECT_TRUE(t.running());
  t.stop();
}
