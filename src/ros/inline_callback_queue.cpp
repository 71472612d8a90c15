/**
 * \file inline_callback_queue.cpp
 * \brief InlineCallbackQueue (include/jackal_aic/ros/inline_callback_queue.hpp).
 */
#include "jackal_aic/ros/inline_callback_queue.hpp"

#include <ros/init.h>

namespace jackal_aic
{
namespace node
{
InlineCallbackQueue::InlineCallbackQueue(ros::CallbackQueueInterface* fallback) : fallback_(fallback) {}

void InlineCallbackQueue::addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id)
{
  if (callback->ready() && callback->call() != ros::CallbackInterface::TryAgain)
  {
    inline_calls_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  deferred_.fetch_add(1, std::memory_order_relaxed);
  fallback()->addCallback(callback, owner_id);
}

ros::CallbackQueueInterface* InlineCallbackQueue::fallback() const
{
  return fallback_ != nullptr ? fallback_ : ros::getGlobalCallbackQueue();
}

void InlineCallbackQueue::removeByID(uint64_t owner_id)
{
  fallback()->removeByID(owner_id);
}

}  // namespace node
}  // namespace jackal_aic
