/**
 * \file rosout_link.cpp
 * \brief Waiting for the rosout node's connection (include/jackal_aic/ros/rosout_link.hpp).
 */
#include "jackal_aic/ros/rosout_link.hpp"

#include <string>
#include <vector>

#include <chrono>
#include <thread>

#include <ros/names.h>
#include <ros/ros.h>
#include <ros/topic_manager.h>

#include "jackal_aic/ros/publisher_watch.hpp"

namespace jackal_aic
{
namespace node
{
bool waitForRosout(double timeout)
{
  const std::string topic = ros::names::resolve("/rosout");
  std::vector<std::string> subscribers;
  if (!PublisherWatch::subscribersOf(topic, &subscribers) || subscribers.empty())
  {
    return true;  // nothing to wait for
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  while (ros::ok())
  {
    if (ros::TopicManager::instance()->getNumSubscribers(topic) > 0)
    {
      return true;
    }
    if (std::chrono::steady_clock::now() >= deadline)
    {
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}
}  // namespace node
}  // namespace jackal_aic
