/**
 * \file test_inline_callback_queue.cpp
 * \brief gtest (no roscore): InlineCallbackQueue (include/jackal_aic/ros/inline_callback_queue.hpp)
 *        calls a ready callback on the thread that adds it, and hands one that is not ready or asks
 *        to be called again to its fallback queue, which then calls it.
 */
#include <gtest/gtest.h>

#include <thread>

#include <ros/callback_queue.h>

#include "jackal_aic/ros/inline_callback_queue.hpp"

namespace jackal_aic
{
namespace
{
/// A callback that records where it ran and answers `first` on its first call, Success after.
class FakeCallback : public ros::CallbackInterface
{
public:
  explicit FakeCallback(CallResult first = Success, bool ready = true) : first_(first), ready_(ready) {}
  CallResult call() override
  {
    thread_ = std::this_thread::get_id();
    return ++calls_ == 1 ? first_ : Success;
  }
  bool ready() override { return ready_; }
  int calls() const { return calls_; }
  std::thread::id thread() const { return thread_; }
  void makeReady() { ready_ = true; }

private:
  CallResult first_;
  bool ready_;
  int calls_ = 0;
  std::thread::id thread_;
};

TEST(InlineCallbackQueue, CallsAReadyCallbackOnTheAddingThread)
{
  ros::CallbackQueue fallback;
  node::InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<FakeCallback>();
  std::thread network([&] { queue.addCallback(cb, 1); });  // as roscpp's network thread would
  const std::thread::id network_id = network.get_id();
  network.join();
  EXPECT_EQ(cb->calls(), 1);
  EXPECT_EQ(cb->thread(), network_id);
  EXPECT_EQ(queue.calledInline(), 1u);
  EXPECT_EQ(queue.deferred(), 0u);
  EXPECT_TRUE(fallback.isEmpty());
}

TEST(InlineCallbackQueue, TryAgainGoesToTheFallbackWhichCallsItAgain)
{
  ros::CallbackQueue fallback;
  node::InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<FakeCallback>(ros::CallbackInterface::TryAgain);
  queue.addCallback(cb, 1);
  EXPECT_EQ(cb->calls(), 1);
  EXPECT_EQ(queue.calledInline(), 0u);
  EXPECT_EQ(queue.deferred(), 1u);
  ASSERT_FALSE(fallback.isEmpty());
  fallback.callAvailable();
  EXPECT_EQ(cb->calls(), 2);
  EXPECT_TRUE(fallback.isEmpty());
}

TEST(InlineCallbackQueue, ANotReadyCallbackWaitsInTheFallbackUncalled)
{
  ros::CallbackQueue fallback;
  node::InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<FakeCallback>(ros::CallbackInterface::Success, false);
  queue.addCallback(cb, 1);
  EXPECT_EQ(cb->calls(), 0);
  EXPECT_EQ(queue.deferred(), 1u);
  cb->makeReady();
  fallback.callAvailable();
  EXPECT_EQ(cb->calls(), 1);
}

TEST(InlineCallbackQueue, RemoveByIdRemovesWaitingCallbacksOfThatOwner)
{
  ros::CallbackQueue fallback;
  node::InlineCallbackQueue queue(&fallback);
  auto mine = boost::make_shared<FakeCallback>(ros::CallbackInterface::Success, false);
  auto other = boost::make_shared<FakeCallback>(ros::CallbackInterface::Success, false);
  queue.addCallback(mine, 1);
  queue.addCallback(other, 2);
  queue.removeByID(1);
  mine->makeReady();
  other->makeReady();
  fallback.callAvailable();
  EXPECT_EQ(mine->calls(), 0);
  EXPECT_EQ(other->calls(), 1);
}

}  // namespace
}  // namespace jackal_aic
