#pragma once
/**
 * \file robot_belief.hpp
 * \brief The robot model's beliefs: the wheel speeds, the actuation shortfalls and the yaw rate,
 *        descending the free energy of the robot model in its filter form (doc/active_inference.md,
 *        'The robot model'). ROS-free.
 */

#include <Eigen/Core>

#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/robot_model_params.hpp"

namespace jackal_aic
{
/**
 * \brief Beliefs mu = (omega_L, d_L, omega_R, d_R, theta_dot, e) with their covariance, under the
 *        robot model (RobotModelParams); e is the yaw rate the wheels' r (omega_R - omega_L) / b_hat
 *        does not deliver (the slip the learned separation does not explain yet).
 *
 * A Gaussian belief N(mu, P) on a linear-Gaussian model: the free energy of a measurement y with
 * the model's prediction N(mu_-, P_-) as the prior (the Laplace form, Friston et al. 2007),
 *   F(mu) = 1/2 eps_y^T Pi_y eps_y + 1/2 eps_mu^T P_-^{-1} eps_mu,  eps_y = y - H mu,  eps_mu = mu - mu_-,
 * is quadratic, so its gradient descent dmu/dt = -k dF/dmu converges to the one minimiser
 * mu = mu_- + P_- H^T (H P_- H^T + Pi_y^{-1})^{-1} (y - H mu_-), the Kalman filter's correction, and
 * the curvature P^{-1} = P_-^{-1} + H^T Pi_y H is its covariance update. correct() takes that
 * minimiser directly (the descent run to convergence); predict() carries the belief through the
 * model's dynamics with its process noise (the prior's precision between samples).
 * Each side's pair (omega_s, d_s) and the yaw pair (theta_dot, e) are filtered on their own (their
 * covariances are not coupled: the yaw pair takes the believed wheel speeds as its input).
 *
 * No heap allocation, no exceptions.
 */
class RobotBelief
{
public:
  /// Beliefs at zero (reset()).
  explicit RobotBelief(const RobotModelParams& params = RobotModelParams());

  /// Replace the settings (beliefs kept).
  void setParams(const RobotModelParams& params);

  /// Beliefs: wheel speeds omega (rad/s), yaw rate theta_dot (rad/s) with variance kInitialVariance;
  /// the shortfalls d_L, d_R, e zero with variance zero (they drift from there at their noise rates).
  void reset(const Vector2& omega, double theta_dot);

  /**
   * \brief Carry the beliefs h [s] forward under the command u_at_wheels [rad/s] (the command in
   *        effect at the wheels, WheelLoopModel::commandAt()) through the wheel loop, and the yaw
   *        rate toward the wheels' yaw_gain (omega_R - omega_L) - e with the scrub lag T_s.
   * \param yaw_gain  r alpha / b_hat [m/m]: the wheels' yaw rate per unit of their speed difference
   */
  void predict(double h, const WheelLoopModel& loop, const Vector2& u_at_wheels, double yaw_gain);

  /**
   * \brief Take a measurement: the sides' wheel speeds y_omega [rad/s] and the gyro's yaw rate less
   *        its learned offset y_gyro [rad/s]; a channel whose flag is false is skipped (isolated or absent).
   *        Sets the free energy's parts at the new beliefs (sensoryFreeEnergy(), priorFreeEnergy()).
   * \return false (nothing changed) if a used value is not finite
   */
  bool correct(const Vector2& y_omega, double y_gyro, bool use_left, bool use_right, bool use_gyro);

  /// Believed wheel speeds (omega_L, omega_R) [rad/s].
  Vector2 wheelSpeeds() const { return Vector2(x_(0), x_(2)); }
  /// Believed shortfalls (d_L, d_R) [rad/s]: the command the sides do not deliver in steady state.
  Vector2 shortfalls() const { return Vector2(x_(1), x_(3)); }
  /// Believed yaw rate theta_dot [rad/s].
  double yawRate() const { return x_(4); }
  /// Believed yaw shortfall e [rad/s]: the wheels' yaw through b_hat less the body's, in steady state.
  double yawShortfall() const { return x_(5); }
  /// Its rate theta_dot' [rad/s^2] under the model (the last predict()).
  double yawAcceleration() const { return yaw_rate_; }
  /// Believed wheel accelerations (omega_L', omega_R') [rad/s^2] under the model (the last predict()).
  Vector2 wheelAccelerations() const { return omega_rate_; }
  /// Covariance diagonal of (omega_L, d_L, omega_R, d_R, theta_dot, e).
  Eigen::Matrix<double, 6, 1> variances() const;

  /// Sensory part of F at the last correct(): 1/2 sum eps_y^2 / sigma^2 [-].
  double sensoryFreeEnergy() const { return f_sensory_; }
  /// Prior part of F at the last correct(): 1/2 eps_mu^T P_-^{-1} eps_mu [-].
  double priorFreeEnergy() const { return f_prior_; }
  /// Sensory prediction errors of the last correct() (eps_L, eps_R, eps_gyro) at the prior beliefs [rad/s].
  const Vector3& innovation() const { return innovation_; }

  /// Variance of omega_L, omega_R and theta_dot after reset() [(rad/s)^2].
  static constexpr double kInitialVariance = 1.0;

private:
  RobotModelParams params_;
  Eigen::Matrix<double, 6, 1> x_ = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix2d p_left_ = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d p_right_ = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d p_yaw_ = Eigen::Matrix2d::Identity();
  Vector2 omega_rate_ = Vector2::Zero();
  double yaw_rate_ = 0.0;
  double f_sensory_ = 0.0;
  double f_prior_ = 0.0;
  Vector3 innovation_ = Vector3::Zero();
};

}  // namespace jackal_aic
