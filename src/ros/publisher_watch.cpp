/**
 * \file publisher_watch.cpp
 * \brief The publishers of one topic from the ROS master (include/jackal_aic/ros/publisher_watch.hpp).
 */
#include "jackal_aic/ros/publisher_watch.hpp"

#include <chrono>
#include <stdexcept>
#include <utility>

#include <ros/master.h>
#include <ros/this_node.h>
#include <xmlrpcpp/XmlRpcException.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace jackal_aic
{
namespace node
{
bool PublisherWatch::publishersOf(const std::string& topic, std::vector<std::string>* out, std::string* error)
{
  return registeredNodes(topic, 0, out, error);
}

bool PublisherWatch::subscribersOf(const std::string& topic, std::vector<std::string>* out, std::string* error)
{
  return registeredNodes(topic, 1, out, error);
}

bool PublisherWatch::registeredNodes(const std::string& topic, int kind, std::vector<std::string>* out,
                                     std::string* error)
{
  auto fail = [error](const std::string& why) {
    if (error != nullptr)
    {
      *error = why;
    }
    return false;
  };
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  try
  {
    if (!ros::master::execute("getSystemState", request, response, payload, false))
    {
      return fail("the ROS master did not answer getSystemState");
    }
    // payload = [publishers, subscribers, services]; each = [[topic, [node, ...]], ...]
    if (payload.getType() != XmlRpc::XmlRpcValue::TypeArray || payload.size() <= kind ||
        payload[kind].getType() != XmlRpc::XmlRpcValue::TypeArray)
    {
      return fail("getSystemState: unexpected answer");
    }
    std::vector<std::string> names;
    XmlRpc::XmlRpcValue& registrations = payload[kind];
    for (int i = 0; i < registrations.size(); ++i)
    {
      XmlRpc::XmlRpcValue& entry = registrations[i];
      if (entry.getType() != XmlRpc::XmlRpcValue::TypeArray || entry.size() < 2 ||
          entry[0].getType() != XmlRpc::XmlRpcValue::TypeString || entry[1].getType() != XmlRpc::XmlRpcValue::TypeArray)
      {
        return fail(kind == 0 ? "getSystemState: unexpected publisher entry" :
                                "getSystemState: unexpected subscriber entry");
      }
      if (static_cast<std::string>(entry[0]) != topic)
      {
        continue;
      }
      for (int j = 0; j < entry[1].size(); ++j)
      {
        if (entry[1][j].getType() == XmlRpc::XmlRpcValue::TypeString)
        {
          names.push_back(static_cast<std::string>(entry[1][j]));
        }
      }
    }
    *out = std::move(names);
    return true;
  }
  catch (const XmlRpc::XmlRpcException& e)
  {
    return fail("getSystemState: " + e.getMessage());
  }
}

PublisherWatch::PublisherWatch(std::string topic, double period, Callback callback)
  : topic_(std::move(topic)), period_(period), callback_(std::move(callback))
{
  if (!(period_ > 0.0) || topic_.empty())
  {
    throw std::invalid_argument("PublisherWatch: the period must be > 0 s and the topic not empty");
  }
  thread_ = std::thread([this] { run(); });
}

PublisherWatch::~PublisherWatch()
{
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable())
  {
    thread_.join();
  }
}

void PublisherWatch::run()
{
  const auto period = std::chrono::duration<double>(period_);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_)
  {
    lock.unlock();
    std::vector<std::string> publishers;
    std::string error;
    const bool ok = publishersOf(topic_, &publishers, &error);
    callback_(ok, publishers, error);
    lock.lock();
    wake_.wait_for(lock, period, [this] { return stop_; });
  }
}

}  // namespace node
}  // namespace jackal_aic
