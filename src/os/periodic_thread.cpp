/**
 * \file periodic_thread.cpp
 * \brief PeriodicThread and IntervalHistogram (include/jackal_aic/os/periodic_thread.hpp).
 */
#include "jackal_aic/os/periodic_thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace jackal_aic
{
namespace os
{
namespace
{
constexpr std::int64_t kNsPerS = 1000000000;
constexpr double kMaxRate = 1e6;

std::int64_t toNs(const timespec& t)
{
  return static_cast<std::int64_t>(t.tv_sec) * kNsPerS + t.tv_nsec;
}

timespec fromNs(std::int64_t ns)
{
  timespec t;
  t.tv_sec = static_cast<time_t>(ns / kNsPerS);
  t.tv_nsec = static_cast<long>(ns % kNsPerS);
  return t;
}

std::int64_t monotonicNs()
{
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return toNs(t);
}

double cpuSeconds(clockid_t clock)
{
  timespec t;
  if (clock_gettime(clock, &t) != 0)
  {
    return 0.0;
  }
  return static_cast<double>(toNs(t)) * 1e-9;
}

std::int64_t periodNs(double rate)
{
  if (!std::isfinite(rate) || rate <= 0.0 || rate > kMaxRate)
  {
    throw std::invalid_argument("PeriodicThread: rate must be finite, > 0 and <= 1e6 Hz, got " + std::to_string(rate));
  }
  return std::max<std::int64_t>(1, std::llround(1e9 / rate));
}
}  // namespace

// ---------------------------------------------------------------------------

IntervalHistogram::IntervalHistogram() : bins_(static_cast<std::size_t>(kMaxUs) + 1, 0) {}

void IntervalHistogram::add(double seconds)
{
  if (!std::isfinite(seconds) || seconds < 0.0)
  {
    return;
  }
  const double us = seconds * 1e6;
  const std::size_t bin = us >= kMaxUs ? static_cast<std::size_t>(kMaxUs) : static_cast<std::size_t>(us);
  ++bins_[bin];
  ++count_;
  max_ = std::max(max_, seconds);
}

double IntervalHistogram::quantile(double q) const
{
  if (count_ == 0)
  {
    return 0.0;
  }
  q = std::clamp(std::isfinite(q) ? q : 1.0, 0.0, 1.0);
  const auto needed = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < bins_.size(); ++i)
  {
    cumulative += bins_[i];
    if (cumulative >= std::max<std::uint64_t>(needed, 1))
    {
      // Upper edge of bin i, but never above the largest interval seen.
      return i == static_cast<std::size_t>(kMaxUs) ? max_ : std::min(max_, (static_cast<double>(i) + 1.0) * 1e-6);
    }
  }
  return max_;
}

void IntervalHistogram::clear()
{
  std::fill(bins_.begin(), bins_.end(), 0);
  count_ = 0;
  max_ = 0.0;
}

// ---------------------------------------------------------------------------

PeriodicThread::PeriodicThread(Step step, std::string name, Wait wait)
  : step_(std::move(step)), name_(std::move(name)), wait_(std::move(wait))
{
  if (!step_)
  {
    throw std::invalid_argument("PeriodicThread: empty step");
  }
}

PeriodicThread::~PeriodicThread()
{
  stop();
}

std::string PeriodicThread::start(double rate, int priority)
{
  if (thread_.joinable())
  {
    throw std::logic_error("PeriodicThread " + name_ + ": already running");
  }
  if (priority < 0 || priority > 99)
  {
    throw std::invalid_argument("PeriodicThread: priority must be 0 (default scheduler) or 1..99 (SCHED_FIFO), got " +
                                std::to_string(priority));
  }
  period_ns_ = periodNs(rate);
  stop_ = false;
  wakeups_ = 0;
  overruns_ = 0;
  reanchors_ = 0;
  first_wakeup_ns_ = -1;
  last_wakeup_ns_ = -1;
  cpu_at_stop_ = 0.0;
  histogram_.clear();
  thread_ = std::thread(&PeriodicThread::run, this);
  pthread_setname_np(thread_.native_handle(), name_.substr(0, 15).c_str());
  if (priority == 0)
  {
    return "";
  }
  sched_param param{};
  param.sched_priority = priority;
  const int err = pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &param);
  if (err != 0)
  {
    return "SCHED_FIFO priority " + std::to_string(priority) + " refused (" + std::strerror(err) +
           "; needs CAP_SYS_NICE or an rtprio limit in /etc/security/limits.conf): default scheduler";
  }
  return "SCHED_FIFO priority " + std::to_string(priority);
}

void PeriodicThread::stop()
{
  if (!thread_.joinable())
  {
    return;
  }
  stop_ = true;
  thread_.join();
}

void PeriodicThread::setRate(double rate)
{
  period_ns_ = periodNs(rate);
}

PeriodicStats PeriodicThread::stats() const
{
  PeriodicStats s;
  s.rate = rate();
  s.wakeups = wakeups_;
  s.overruns = overruns_;
  s.reanchors = reanchors_;
  const std::int64_t first = first_wakeup_ns_;
  const std::int64_t last = last_wakeup_ns_;
  s.elapsed = first >= 0 && last >= first ? static_cast<double>(last - first) * 1e-9 : 0.0;
  if (thread_.joinable())
  {
    clockid_t clock;
    if (pthread_getcpuclockid(const_cast<std::thread&>(thread_).native_handle(), &clock) == 0)
    {
      s.cpu = cpuSeconds(clock);
    }
  }
  else
  {
    s.cpu = cpu_at_stop_;
  }
  s.p50 = histogram_.quantile(0.5);
  s.p99 = histogram_.quantile(0.99);
  s.max = histogram_.max();
  return s;
}

void PeriodicThread::sleepUntil(std::int64_t deadline_ns)
{
  const timespec wake = fromNs(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr) == EINTR)
  {
  }
}

std::int64_t PeriodicThread::monotonicNow()
{
  return monotonicNs();
}

void PeriodicThread::run()
{
  std::int64_t deadline = monotonicNs();
  std::int64_t previous = -1;
  while (!stop_.load(std::memory_order_relaxed))
  {
    const std::int64_t period = period_ns_.load(std::memory_order_relaxed);
    deadline += period;
    if (wait_)
    {
      wait_(deadline, period);
    }
    else
    {
      sleepUntil(deadline);
    }
    const std::int64_t now = monotonicNs();
    if (now - deadline > period)
    {
      deadline = now;  // a whole period late: re-anchor instead of running back-to-back steps
      reanchors_.fetch_add(1, std::memory_order_relaxed);
    }
    double interval = -1.0;
    if (previous >= 0)
    {
      const std::int64_t dt = now - previous;
      interval = static_cast<double>(dt) * 1e-9;
      histogram_.add(interval);
      if (dt > 2 * period)
      {
        overruns_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    else
    {
      first_wakeup_ns_.store(now, std::memory_order_relaxed);
    }
    previous = now;
    last_wakeup_ns_.store(now, std::memory_order_relaxed);
    wakeups_.fetch_add(1, std::memory_order_relaxed);
    step_(interval);
  }
  cpu_at_stop_ = cpuSeconds(CLOCK_THREAD_CPUTIME_ID);
}

}  // namespace os
}  // namespace jackal_aic
