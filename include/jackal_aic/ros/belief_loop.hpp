#pragma once
/**
 * \file belief_loop.hpp
 * \brief What runs the jackal_AIC node's belief loop (doc/jackal_aic_node.md, 'Loops'): a
 *        real-time PeriodicThread on the wall clock, a ROS timer on simulated time.
 */
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <ros/callback_queue.h>
#include <ros/node_handle.h>
#include <ros/timer.h>

#include "jackal_aic/os/periodic_thread.hpp"

namespace jackal_aic
{
namespace node
{
/**
 * \brief Interval [s] between a ROS timer's previous and current call (wall clock of the
 *        event), or -1 on its first call (the supervisor's schedulers then take the nominal
 *        period).
 */
double timerInterval(const ros::TimerEvent& event);

/**
 * \brief Drives the belief loop at belief_rate and, on the wall clock, the sensor subscribers.
 *
 *  - Wall clock (use_sim_time false): a PeriodicThread ("aic_belief") sleeping to absolute
 *    CLOCK_MONOTONIC deadlines, SCHED_FIFO at `realtime_priority` when permitted. The thread
 *    also serves `sensor_queue` (the queue the node's subscribers were given): at periods up
 *    to 2 ms once per tick, right after the wake-up and before the tick (no wake-up per
 *    message; a sample waits at most one period), at longer periods as the messages arrive,
 *    while it waits for its deadline.
 *  - Simulated time: a ros::Timer on the node handle's queue (the spinner); a thread could not
 *    follow /clock. `sensor_queue` is then unused (the subscribers stay on the spinner).
 *
 * Each tick calls `tick(interval)`: interval [s] measured since the previous tick (-1 on the
 * first). Destroying the loop (or stop()) stops the thread
 * before anything the tick uses is gone; declare it after what the tick touches.
 */
class BeliefLoop
{
public:
  /// The tick: measured interval [s] (-1 first).
  using Tick = std::function<void(double interval)>;

  /// True if the loop will run on its own thread (the wall clock): give the subscribers
  /// `sensor_queue` before subscribing.
  static bool useThread();

  /**
   * \param nh                 node handle for the simulated-time timer
   * \param rate               belief_rate [Hz], > 0 (validated by the node's parameters)
   * \param realtime_priority  SCHED_FIFO priority 1..99 for the thread, 0 = default scheduler
   * \param sensor_queue       the subscribers' queue, served by the thread (wall clock only);
   *                           must outlive this loop
   * \param tick               the work of one tick
   */
  BeliefLoop(ros::NodeHandle& nh, double rate, int realtime_priority, ros::CallbackQueue* sensor_queue, Tick tick);
  ~BeliefLoop();
  BeliefLoop(const BeliefLoop&) = delete;
  BeliefLoop& operator=(const BeliefLoop&) = delete;

  /// True if running on the real-time thread (wall clock), false on a ROS timer.
  bool onThread() const { return thread_ != nullptr; }
  /// What runs the loop, for the log and diagnostics, e.g. "real-time thread (clock_nanosleep,
  /// SCHED_FIFO 20)" or "ROS timer (simulated time)".
  const std::string& description() const { return description_; }
  /// True if the thread asked for SCHED_FIFO and was refused (the description says why).
  bool priorityRefused() const { return refused_; }
  /// Change the rate [Hz] (> 0) from the next tick on.
  void setRate(double rate);
  /// Stop the thread (or timer); idempotent.
  void stop();

private:
  void waitServingSensors(std::int64_t deadline_ns, std::int64_t period_ns);

  Tick tick_;
  ros::CallbackQueue* sensor_queue_;
  ros::Timer timer_;
  std::string description_;
  bool refused_ = false;
  std::unique_ptr<os::PeriodicThread> thread_;
};
}  // namespace node
}  // namespace jackal_aic
