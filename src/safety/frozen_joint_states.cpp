/**
 * \file frozen_joint_states.cpp
 * \brief A frozen MCU behind jackal_node (include/jackal_aic/safety/frozen_joint_states.hpp;
 *        doc/jackal_aic_node.md, 'Frozen joint states'). ROS-free.
 */
#include "jackal_aic/safety/frozen_joint_states.hpp"

#include <cmath>
#include <stdexcept>

namespace jackal_aic
{
namespace safety
{
const char* toString(FrozenJointStates::Event event)
{
  switch (event)
  {
    case FrozenJointStates::Event::kNone:
      return "none";
    case FrozenJointStates::Event::kFrozen:
      return "frozen";
    case FrozenJointStates::Event::kThawed:
      return "thawed";
  }
  return "unknown";
}

FrozenJointStates::FrozenJointStates(double hold_time, double motion_speed)
  : hold_time_(hold_time), motion_speed_(motion_speed)
{
  if (!(std::isfinite(hold_time) && hold_time > 0.0) || !(std::isfinite(motion_speed) && motion_speed >= 0.0))
  {
    throw std::invalid_argument("FrozenJointStates: hold_time must be finite and > 0 s, motion_speed finite and "
                                ">= 0 rad/s");
  }
}

FrozenJointStates::Event FrozenJointStates::update(const Input& in)
{
  const bool was = frozen_;
  const bool same = have_last_ && in.has_travel && in.travel == last_travel_ && in.speed == last_speed_;
  if (!same)
  {
    have_last_ = in.has_travel;
    last_travel_ = in.travel;
    last_speed_ = in.speed;
    run_start_ = in.stamp;
    repeats_ = 0;
    frozen_ = false;
  }
  else
  {
    ++repeats_;
    const bool turning = in.speed.cwiseAbs().maxCoeff() > motion_speed_;  // the same for the whole run
    if (turning && !frozen_ && in.stamp - run_start_ > hold_time_)
    {
      frozen_ = true;
      ++events_;
    }
  }
  held_for_ = in.stamp - run_start_;
  if (frozen_ == was)
  {
    return Event::kNone;
  }
  return frozen_ ? Event::kFrozen : Event::kThawed;
}

void FrozenJointStates::reset()
{
  have_last_ = false;
  run_start_ = 0.0;
  held_for_ = 0.0;
  repeats_ = 0;
  frozen_ = false;
}

}  // namespace safety
}  // namespace jackal_aic
