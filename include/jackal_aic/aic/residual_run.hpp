#pragma once
/**
 * \file residual_run.hpp
 * \brief A jump's test: n residuals in a row beyond their limit, each within a band of the run's
 *        first (the robot model's gyro-offset and shortfall jumps; doc/active_inference.md, 'The
 *        robot model'). ROS-free, header-only, no allocation.
 */
#include <cmath>

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Counts residuals r [the signal's unit] in a row that are beyond their limit and, after the
 *        first, within `band` of the first. A residual within its limit ends the run; one beyond it
 *        but outside the band starts a new run at itself. When a run reaches n residuals, add()
 *        returns true, mean() is their mean, and the count restarts.
 */
class ResidualRun
{
public:
  /**
   * \brief Add residual r.
   * \param r       the residual (finite; a non-finite one ends the run)
   * \param beyond  whether |r| is beyond its limit (the caller's test)
   * \param band    largest |r - first| of a run [r's unit]; +inf: any
   * \param n       the run's length that completes it, >= 1
   * \return true when this residual completes a run of n (then mean() holds its mean)
   */
  bool add(double r, bool beyond, double band, int n)
  {
    if (!beyond || !std::isfinite(r))
    {
      count_ = 0;
      sum_ = 0.0;
      first_ = r;
      return false;
    }
    if (count_ > 0 && !(std::abs(r - first_) <= band))
    {
      count_ = 1;
      sum_ = r;
      first_ = r;
      return false;
    }
    if (count_ == 0)
    {
      first_ = r;
    }
    sum_ += r;
    if (++count_ >= n)
    {
      mean_ = sum_ / count_;
      count_ = 0;
      sum_ = 0.0;
      return true;
    }
    return false;
  }
  /// End the run (no residual counts toward the next one).
  void clear()
  {
    count_ = 0;
    sum_ = 0.0;
  }
  /// The mean of the last completed run [r's unit]; 0 before any.
  double mean() const { return mean_; }
  /// Residuals in the run so far.
  int count() const { return count_; }

private:
  int count_ = 0;
  double sum_ = 0.0;
  double first_ = 0.0;
  double mean_ = 0.0;
};
}  // namespace aic
}  // namespace jackal_aic
