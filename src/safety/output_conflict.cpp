/**
 * \file output_conflict.cpp
 * \brief The output topic's conflict state machine (include/jackal_aic/safety/output_conflict.hpp;
 *        doc/jackal_aic_node.md, 'One publisher per command topic'). ROS-free.
 */
#include "jackal_aic/safety/output_conflict.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

namespace jackal_aic
{
namespace safety
{
const char* toString(OutputConflict::Event event)
{
  switch (event)
  {
    case OutputConflict::Event::kNone:
      return "none";
    case OutputConflict::Event::kStarted:
      return "started";
    case OutputConflict::Event::kChanged:
      return "changed";
    case OutputConflict::Event::kEnded:
      return "ended";
  }
  return "unknown";
}

OutputConflict::OutputConflict(std::string topic, std::string self) : topic_(std::move(topic)), self_(std::move(self))
{
  if (topic_.empty() || self_.empty())
  {
    throw std::invalid_argument("OutputConflict: the topic and the node's own name must not be empty");
  }
}

OutputConflict::Event OutputConflict::update(const std::vector<std::string>& publishers, double now)
{
  std::vector<std::string> others;
  for (const std::string& name : publishers)
  {
    if (!name.empty() && name != self_)
    {
      others.push_back(name);
    }
  }
  std::sort(others.begin(), others.end());
  others.erase(std::unique(others.begin(), others.end()), others.end());

  const bool was = conflicted();
  if (others == others_)
  {
    return Event::kNone;
  }
  others_ = std::move(others);
  if (!was)
  {
    since_ = now;
    ++conflicts_;
    return Event::kStarted;
  }
  return conflicted() ? Event::kChanged : Event::kEnded;
}

std::string OutputConflict::othersText() const
{
  if (others_.empty())
  {
    return "none";
  }
  std::string text;
  for (const std::string& name : others_)
  {
    text += (text.empty() ? "" : ", ") + name;
  }
  return text;
}

double OutputConflict::since() const
{
  return conflicted() ? since_ : std::numeric_limits<double>::quiet_NaN();
}

std::string OutputConflict::message(Event event) const
{
  switch (event)
  {
    case Event::kStarted:
    case Event::kChanged:
      return "another node publishes on " + topic_ + ": " + othersText() + "; " + self_ +
             " publishes nothing there until it is the only publisher (one publisher per command topic: "
             "remap or stop the other)";
    case Event::kEnded:
      return "no other publisher on " + topic_ + " any more; " + self_ + " publishes its commands again";
    case Event::kNone:
      break;
  }
  return "";
}

}  // namespace safety
}  // namespace jackal_aic
