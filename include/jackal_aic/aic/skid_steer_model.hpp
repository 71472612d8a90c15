#pragma once
/**
 * \file skid_steer_model.hpp
 * \brief Generative model of the sensory data of a skid-steer base (thesis eq. 3-1 ... 3-4;
 *        extended differential drive, Mandow et al. 2007; doc/active_inference.md). ROS-free.
 */

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief The matrices G (3x2), R (5x3) and K (2x5) of the skid-steer generative model.
 *
 * G = r alpha [[1/2, 1/2], [0, 0], [-1/b, 1/b]]  so that mu = G (omega_L, omega_R);
 * R: gyro row (0,0,1), wheel rows = pinv(G) (Eigen's complete orthogonal decomposition),
 *    accelerometer rows zero (thesis model);
 * K = dy/da = [[-r alpha/b, 1, 0, 0, 0], [r alpha/b, 0, 1, 0, 0]].
 */
class SkidSteerModel
{
public:
  /**
   * \param wheel_radius      r [m], finite and > 0
   * \param slip_factor       alpha [-], finite and > 0
   * \param wheel_separation  b_hat [m], finite and > 0
   * \throws std::invalid_argument otherwise
   */
  SkidSteerModel(double wheel_radius, double slip_factor, double wheel_separation);

  /// Kinematic map G, 3 x 2: mu = G (omega_L, omega_R) (eq. 3-1 ... 3-4); rows x_dot and y_dot in [m/rad],
  /// row theta_dot in [-] (r alpha / b_hat).
  const base::KinematicMatrix& G() const { return G_; }
  /// Sensor model R, 5 x 3: g(mu) = R mu (eq. 3-1 ... 3-4): gyro row (0, 0, 1), wheel rows pinv(G), accelerometer rows zero.
  const base::SensorMatrix& R() const { return R_; }
  /// Forward model K = dy/da, 2 x 5, one row per action (eq. 3-4; used by the action update, eq. 3-16).
  const base::ForwardMatrix& K() const { return K_; }

  /// Body twist (x_dot, y_dot, theta_dot) from wheel speeds (omega_L, omega_R) [rad/s] (eq. 3-1).
  base::Vector3 twistFromWheels(const base::Vector2& omega) const { return G_ * omega; }
  /**
   * \brief Replace b_hat [m] (learning, doc/active_inference.md 'Learning the generative model'):
   *        G, K as in the constructor; the wheel rows of R by the closed form of pinv(G) for a
   *        full-column-rank G, omega_L,R = (x_dot -+ b_hat theta_dot / 2) / (r alpha). No heap
   *        allocation, no exceptions (the constructor's decomposition is not used).
   * \return false (model unchanged) unless b is finite and > 0.
   */
  bool setWheelSeparation(double b);
  /// b_hat in use [m].
  double wheelSeparation() const { return b_; }

  /// Wheel speeds (omega_L, omega_R) [rad/s] realizing a twist (v_x [m/s], ., omega_z [rad/s]) (pinv(G));
  /// the y_dot element is ignored (G cannot produce it). No checks: a non-finite twist gives non-finite speeds.
  base::Vector2 wheelsFromTwist(const base::Vector3& mu) const;

private:
  base::KinematicMatrix G_;
  base::SensorMatrix R_;
  base::ForwardMatrix K_;
  Eigen::Matrix<double, base::kADim, base::kMuDim> G_pinv_;
  double ra_;  ///< r alpha [m]
  double b_;   ///< b_hat [m]
};

/// Wheel pair (omega_L, omega_R) [rad/s] -> its (common, differential) parts
/// ((omega_L + omega_R) / 2, (omega_R - omega_L) / 2) [rad/s]: the parts of the wheel speeds that
/// drive x_dot and theta_dot (eq. 3-1).
inline base::Vector2 commonDifferential(const base::Vector2& wheels)
{
  return base::Vector2(0.5 * (wheels(0) + wheels(1)), 0.5 * (wheels(1) - wheels(0)));
}

/// Inverse of commonDifferential(): (c, d) [rad/s] -> the wheel pair (c - d, c + d) [rad/s].
inline base::Vector2 wheelPair(const base::Vector2& cd)
{
  return base::Vector2(cd(0) - cd(1), cd(0) + cd(1));
}

}  // namespace aic
}  // namespace jackal_aic
