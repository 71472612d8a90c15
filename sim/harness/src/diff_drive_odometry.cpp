#include "jackal_sim/harness/diff_drive_odometry.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace harness
{
namespace
{
/// dt below which odometry.cpp leaves the speeds [s].
constexpr double kMinInterval = 0.0001;
/// Yaw increment below which odometry.cpp integrates with Runge-Kutta 2 [rad].
constexpr double kExactThreshold = 1e-6;

double mean(const std::deque<double>& d)
{
  return std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
}
}  // namespace

DiffDriveOdometry::DiffDriveOdometry(double separation, double radius, std::size_t window)
  : separation_(separation), radius_(radius), window_(window)
{
  if (!std::isfinite(separation) || !(separation > 0.0))
  {
    throw std::invalid_argument("DiffDriveOdometry: separation = " + std::to_string(separation) + " (> 0 m)");
  }
  if (!std::isfinite(radius) || !(radius > 0.0))
  {
    throw std::invalid_argument("DiffDriveOdometry: radius = " + std::to_string(radius) + " (> 0 m)");
  }
  if (window < 1)
  {
    throw std::invalid_argument("DiffDriveOdometry: window = 0 (>= 1 updates)");
  }
}

void DiffDriveOdometry::integrate(double linear, double angular)
{
  if (std::abs(angular) < kExactThreshold)
  {
    const double direction = heading_ + 0.5 * angular;
    x_ += linear * std::cos(direction);
    y_ += linear * std::sin(direction);
    heading_ += angular;
    return;
  }
  const double old = heading_;
  const double r = linear / angular;
  heading_ += angular;
  x_ += r * (std::sin(heading_) - std::sin(old));
  y_ += -r * (std::cos(heading_) - std::cos(old));
}

bool DiffDriveOdometry::update(double left_pos, double right_pos, double t)
{
  const double left = left_pos * radius_;
  const double right = right_pos * radius_;
  if (!started_)
  {
    started_ = true;
    left_old_ = left;
    right_old_ = right;
    time_ = t;
    return false;
  }
  const double dl = left - left_old_;
  const double dr = right - right_old_;
  left_old_ = left;
  right_old_ = right;
  const double linear = 0.5 * (dr + dl);
  const double angular = (dr - dl) / separation_;
  integrate(linear, angular);
  const double dt = t - time_;
  if (dt < kMinInterval)
  {
    return false;
  }
  time_ = t;
  linear_window_.push_back(linear / dt);
  angular_window_.push_back(angular / dt);
  if (linear_window_.size() > window_)
  {
    linear_window_.pop_front();
    angular_window_.pop_front();
  }
  linear_ = mean(linear_window_);
  angular_ = mean(angular_window_);
  return true;
}

}  // namespace harness
}  // namespace jackal_aic
