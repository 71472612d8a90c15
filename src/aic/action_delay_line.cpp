/**
 * \file action_delay_line.cpp
 * \brief The delay line of the sent action's twist (doc/active_inference.md, 'Unbiased beliefs').
 */
#include "jackal_aic/aic/action_delay_line.hpp"

#include <algorithm>
#include <cstddef>

namespace jackal_aic
{
namespace aic
{
void ActionDelayLine::restart(const base::Vector3& u)
{
  head_ = 0;
  count_ = 1;
  delayed_ = u;
  line_[0] = Sample{ time_, delayed_ };
}

void ActionDelayLine::reset(const base::Vector3& u)
{
  time_ = 0.0;
  restart(u);
}

void ActionDelayLine::record(double h, const base::Vector3& u)
{
  // The body twist G a of the action just sent, from now until the next action step.
  time_ += h;
  head_ = (head_ + 1) % kCapacity;
  count_ = std::min(count_ + 1, kCapacity);
  line_[static_cast<std::size_t>(head_)] = Sample{ time_, u };
  // Zero-order hold: the newest sample sent at or before t - d_r (the oldest if the line is shorter).
  const double t_query = time_ - delay_;
  int idx = head_;
  for (int k = 1; k < count_ && line_[static_cast<std::size_t>(idx)].t > t_query; ++k)
  {
    idx = (head_ - k + kCapacity) % kCapacity;
  }
  delayed_ = line_[static_cast<std::size_t>(idx)].u;
}

}  // namespace aic
}  // namespace jackal_aic
