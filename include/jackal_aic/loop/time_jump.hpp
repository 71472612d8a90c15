#pragma once
/**
 * \file time_jump.hpp
 * \brief Detection of a clock moving backwards: ROS time after a simulator restarts its
 *        /clock from 0, at each loop of `rosbag play --loop --clock`, or a wall clock stepped
 *        back. ROS-free; used by the ControlLoop (the jackal_AIC node and the headless closed
 *        loop), the plant node and the stock controller node (doc/jackal_aic_node.md,
 *        'Time moving backwards and restarts').
 */

#include <cmath>
#include <cstdint>

namespace jackal_aic
{
namespace loop
{
/**
 * \brief Watches the readings of one clock and reports each backward step larger than a
 *        tolerance. Not thread-safe; no allocation.
 *
 * Usage: call observe() with the clock's reading at every event; a positive return is the
 * size of a backward jump [s], after which the new reading is the clock's latest (the new
 * timeline). A forward jump is not a jump here (the callers' timeouts handle it).
 */
class TimeJumpDetector
{
public:
  /**
   * \param tolerance  [s], >= 0 (a negative or non-finite value counts as 0): a reading at
   *                   most this far before the latest one is not a jump (and does not move
   *                   the latest reading back)
   */
  explicit TimeJumpDetector(double tolerance = 0.0)
    : tolerance_(std::isfinite(tolerance) && tolerance > 0.0 ? tolerance : 0.0)
  {
  }

  /**
   * \brief One clock reading.
   * \param now  [s], any epoch; a non-finite reading is ignored
   * \return the size of the backward jump [s], > 0, if `now` is more than the tolerance
   *         before the latest reading (counted; `now` becomes the latest reading); else 0
   */
  double observe(double now)
  {
    if (!std::isfinite(now))
    {
      return 0.0;
    }
    if (!has_latest_)
    {
      has_latest_ = true;
      latest_ = now;
      return 0.0;
    }
    if (now >= latest_)
    {
      latest_ = now;
      return 0.0;
    }
    const double back = latest_ - now;
    if (back <= tolerance_)
    {
      return 0.0;
    }
    ++jumps_;
    last_jump_ = back;
    latest_ = now;
    return back;
  }

  /// The latest reading [s] (the largest since the last jump); NaN before the first.
  double latest() const { return has_latest_ ? latest_ : std::nan(""); }
  /// Backward jumps seen since construction.
  std::uint64_t jumps() const { return jumps_; }
  /// Size of the last backward jump [s]; 0 before the first.
  double lastJump() const { return last_jump_; }
  /// The tolerance in force [s].
  double tolerance() const { return tolerance_; }

private:
  double tolerance_;
  bool has_latest_ = false;
  double latest_ = 0.0;
  std::uint64_t jumps_ = 0;
  double last_jump_ = 0.0;
};

}  // namespace loop
}  // namespace jackal_aic
