#pragma once
/**
 * \file diff_drive_odometry.hpp
 * \brief The wheel odometry of ros_controllers' diff_drive_controller, as jackal_node runs it:
 *        body speeds from the wheel positions' differences over the controller's update step,
 *        smoothed by a rolling mean. ROS-free.
 *
 * Follows ros_controllers (noetic-devel) `diff_drive_controller/src/odometry.cpp`
 * (`Odometry::update`): each update at time t with the mean wheel positions per side [rad],
 *   d_L = r (p_L - p_L,old),  d_R = r (p_R - p_R,old)  [m],
 *   linear = (d_R + d_L) / 2,  angular = (d_R - d_L) / s,
 * the pose integrated exactly (`integrateExact`; second-order Runge-Kutta below 1e-6 rad); then if
 * dt = t - t_old < 0.0001 s the speeds are left as they were (the step's displacement is in the pose
 * only), else linear / dt and angular / dt enter rolling means over the last `window` updates,
 * which are the published twist. From `diff_drive_controller/src/diff_drive_controller.cpp`: the
 * window (velocity_rolling_window_size, default 10), s = wheel_separation_multiplier *
 * wheel_separation, r = wheel_radius_multiplier * wheel_radius (jackal_control's control.yaml:
 * 0.37559 x 1.5, 0.098 x 1), one update per control cycle with the cycle's time.
 */

#include <cstddef>
#include <deque>

namespace jackal_aic
{
namespace harness
{
/// diff_drive_controller's odometry (see file comment).
class DiffDriveOdometry
{
public:
  /**
   * \param separation effective wheel separation s [m], finite, > 0
   * \param radius     wheel radius r [m], finite, > 0
   * \param window     rolling-mean window [updates], >= 1
   * \throws std::invalid_argument naming the bad value
   */
  DiffDriveOdometry(double separation, double radius, std::size_t window = 10);

  /**
   * \brief One controller update (odometry.cpp's Odometry::update).
   * \param left_pos   mean left wheel position [rad]
   * \param right_pos  mean right wheel position [rad]
   * \param t          the update's time [s]; the first call only sets the positions and the time
   * \return true if the speeds were updated (false on the first call and when dt < 0.0001 s)
   */
  bool update(double left_pos, double right_pos, double t);

  double linear() const { return linear_; }    ///< smoothed body speed [m/s]
  double angular() const { return angular_; }  ///< smoothed yaw rate [rad/s]
  double x() const { return x_; }              ///< position in the odometry frame [m]
  double y() const { return y_; }              ///< [m]
  double heading() const { return heading_; }  ///< [rad], not wrapped

private:
  void integrate(double linear, double angular);

  double separation_;
  double radius_;
  std::size_t window_;
  bool started_ = false;
  double time_ = 0.0;
  double left_old_ = 0.0, right_old_ = 0.0;  ///< [m]
  double x_ = 0.0, y_ = 0.0, heading_ = 0.0;
  double linear_ = 0.0, angular_ = 0.0;
  std::deque<double> linear_window_, angular_window_;
};

}  // namespace harness
}  // namespace jackal_aic
