/**
 * \file belief_loop.cpp
 * \brief The jackal_AIC node's belief-loop driver (include/jackal_aic/ros/belief_loop.hpp).
 */
#include "jackal_aic/ros/belief_loop.hpp"

#include <utility>

#include <ros/ros.h>

namespace jackal_aic
{
namespace node
{
namespace
{
/// Belief periods up to this [ns] serve the subscribers once per tick (<= 2 ms of added sample
/// latency, no wake-up per message); longer periods serve them as they arrive.
constexpr std::int64_t kBatchedDispatchMaxPeriodNs = 2000000;
}  // namespace

double timerInterval(const ros::TimerEvent& event)
{
  if (event.last_real.isZero())
  {
    return -1.0;  // first call: the scheduler uses the nominal period
  }
  return (event.current_real - event.last_real).toSec();
}

bool BeliefLoop::useThread()
{
  return !ros::Time::isSimTime();
}

BeliefLoop::BeliefLoop(ros::NodeHandle& nh, double rate, int realtime_priority, ros::CallbackQueue* sensor_queue,
                       Tick tick)
  : tick_(std::move(tick)), sensor_queue_(sensor_queue)
{
  if (!useThread())
  {
    timer_ = nh.createTimer(ros::Duration(1.0 / rate),
                            [this](const ros::TimerEvent& event) { tick_(timerInterval(event)); });
    description_ = "ROS timer (simulated time)";
    return;
  }
  thread_ = std::make_unique<os::PeriodicThread>(
      [this](double interval) { tick_(interval); }, "aic_belief",
      [this](std::int64_t deadline_ns, std::int64_t period_ns) { waitServingSensors(deadline_ns, period_ns); });
  const std::string priority = thread_->start(rate, realtime_priority);
  refused_ = priority.find("refused") != std::string::npos;
  description_ =
      "real-time thread (clock_nanosleep, " + (priority.empty() ? std::string("default scheduler") : priority) + ")";
}

BeliefLoop::~BeliefLoop()
{
  stop();
}

void BeliefLoop::setRate(double rate)
{
  if (thread_)
  {
    thread_->setRate(rate);
  }
  else
  {
    timer_.setPeriod(ros::Duration(1.0 / rate));
  }
}

void BeliefLoop::stop()
{
  if (thread_)
  {
    thread_->stop();
  }
  timer_.stop();
}

void BeliefLoop::waitServingSensors(std::int64_t deadline_ns, std::int64_t period_ns)
{
  if (period_ns <= kBatchedDispatchMaxPeriodNs)
  {
    os::PeriodicThread::sleepUntil(deadline_ns);
    sensor_queue_->callAvailable(ros::WallDuration(0.0));  // what came during the period, then the step
    return;
  }
  for (std::int64_t left = deadline_ns - os::PeriodicThread::monotonicNow(); left > 0;
       left = deadline_ns - os::PeriodicThread::monotonicNow())
  {
    sensor_queue_->callAvailable(ros::WallDuration(static_cast<double>(left) * 1e-9));
  }
}
}  // namespace node
}  // namespace jackal_aic
