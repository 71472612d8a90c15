#pragma once
/**
 * \file inline_callback_queue.hpp
 * \brief A ROS callback queue that runs each callback on the thread that receives it
 *        (doc/jackal_aic_node.md, 'Loops').
 */
#include <atomic>
#include <cstdint>

#include <ros/callback_queue.h>
#include <ros/callback_queue_interface.h>

namespace jackal_aic
{
namespace node
{
/**
 * \brief ros::CallbackQueueInterface that calls each callback as roscpp adds it: a subscriber
 *        given this queue runs its callback on roscpp's network thread (the one that read the
 *        message), not on the spinner.
 *
 * The event schedule's subscribers use it: a sample becomes a ControlLoop event without a
 * hand-over between threads (one wake-up per message fewer, and the spinner's queue latency
 * gone). Callbacks must take only their own locks and never (un)subscribe the subscription they
 * serve (roscpp holds that subscription's lock around the call).
 *
 * A callback that is not ready, or that asks to be called again (ros::CallbackInterface::
 * TryAgain, e.g. when two threads deliver to one subscription), goes to `fallback` (the spinner's
 * queue unless told), which then calls it as a queue always does; removeByID() forwards there.
 * Exceptions from a callback propagate to roscpp's caller, as from ros::spin().
 */
class InlineCallbackQueue : public ros::CallbackQueueInterface
{
public:
  /// \param fallback queue for callbacks that cannot run now; not owned, must outlive this;
  ///        nullptr: the global queue (ros::getGlobalCallbackQueue(), served by ros::spin()).
  explicit InlineCallbackQueue(ros::CallbackQueueInterface* fallback = nullptr);

  /// Calls `callback` now on the calling thread; TryAgain or not ready: to the fallback queue.
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id = 0) override;

  /// Removes `owner_id`'s callbacks waiting in the fallback queue (none wait here).
  void removeByID(uint64_t owner_id) override;

  /// Callbacks called inline, and handed to the fallback queue, since construction (counted on
  /// whichever thread added them; readable from any thread).
  std::uint64_t calledInline() const { return inline_calls_.load(std::memory_order_relaxed); }
  std::uint64_t deferred() const { return deferred_.load(std::memory_order_relaxed); }

private:
  ros::CallbackQueueInterface* fallback() const;

  ros::CallbackQueueInterface* fallback_;
  std::atomic<std::uint64_t> inline_calls_{ 0 };
  std::atomic<std::uint64_t> deferred_{ 0 };
};

}  // namespace node
}  // namespace jackal_aic
