/**
 * \file robot_belief.cpp
 * \brief The robot model's beliefs in their filter form (doc/active_inference.md, 'The robot model').
 */
#include "jackal_aic/aic/robot_belief.hpp"

#include <cmath>

namespace jackal_aic
{
namespace
{
/// One side's belief (omega, d) with covariance p carried h [s] under the command u [rad/s].
void predictSide(const WheelLoopModel& loop, const RobotModelParams& params, double h, double u, double* omega,
                 double d, Eigen::Matrix2d* p)
{
  double gain = 0.0;
  const double next = loop.step(*omega, u - d, h, &gain);
  const bool bounded = params.wheel_time_constant > 0.0 && gain == 1.0;
  Eigen::Matrix2d f;
  f << gain, bounded ? 0.0 : -(1.0 - gain), 0.0, 1.0;
  *p = f * (*p) * f.transpose();
  (*p)(0, 0) += params.wheel_model_noise * params.wheel_model_noise * h;
  (*p)(1, 1) += params.shortfall_noise * params.shortfall_noise * h;
  *omega = next;
}

/// Scalar measurement y of the first state of (x0, x1) with covariance p and noise variance r;
/// adds the free energy's parts at the corrected belief: sensory 1/2 (e r / s)^2 / r, prior
/// 1/2 (K e)^T P_-^{-1} (K e) = 1/2 e^2 p00 / s^2 (e the innovation, s = p00 + r, K = P_- col 0 / s).
void correctPair(double y, double r, double* x0, double* x1, Eigen::Matrix2d* p, double* f_sensory, double* f_prior,
                 double* innovation)
{
  const double e = y - *x0;
  const double p00 = (*p)(0, 0);
  const double s = p00 + r;
  const Eigen::Vector2d k = p->col(0) / s;
  *x0 += k(0) * e;
  *x1 += k(1) * e;
  const Eigen::RowVector2d row = p->row(0);
  *p -= k * row;
  *f_sensory += 0.5 * e * e * r / (s * s);
  *f_prior += 0.5 * e * e * p00 / (s * s);
  *innovation = e;
}
}  // namespace

RobotBelief::RobotBelief(const RobotModelParams& params) : params_(params)
{
  reset(Vector2::Zero(), 0.0);
}

void RobotBelief::setParams(const RobotModelParams& params)
{
  params_ = params;
}

void RobotBelief::reset(const Vector2& omega, double theta_dot)
{
  x_ << omega(0), 0.0, omega(1), 0.0, theta_dot, 0.0;
  // The fast states start uncertain, the shortfalls at zero and certain: they drift from there at
  // their own rate (shortfall_noise, yaw_slip_noise), not on the first transient.
  p_left_ << kInitialVariance, 0.0, 0.0, 0.0;
  p_right_ = p_left_;
  p_yaw_ = p_left_;
  omega_rate_.setZero();
  yaw_rate_ = 0.0;
  f_sensory_ = 0.0;
  f_prior_ = 0.0;
  innovation_.setZero();
}

void RobotBelief::predict(double h, const WheelLoopModel& loop, const Vector2& u_at_wheels, double yaw_gain)
{
  const Vector2 before = wheelSpeeds();
  const double yaw_before = x_(4);
  predictSide(loop, params_, h, u_at_wheels(0), &x_(0), x_(1), &p_left_);
  predictSide(loop, params_, h, u_at_wheels(1), &x_(2), x_(3), &p_right_);
  // The yaw pair (theta_dot, e): theta_dot' = (yaw_gain (omega_R - omega_L) - e - theta_dot) / T_s,
  // integrated exactly with the wheels' yaw held; e a random walk.
  const double target = yaw_gain * (x_(2) - x_(0)) - x_(5);
  const double decay = std::exp(-h / params_.yaw_time_constant);
  x_(4) = target + (x_(4) - target) * decay;
  Eigen::Matrix2d f;
  f << decay, -(1.0 - decay), 0.0, 1.0;
  p_yaw_ = f * p_yaw_ * f.transpose();
  p_yaw_(0, 0) += params_.yaw_model_noise * params_.yaw_model_noise * h;
  p_yaw_(1, 1) += params_.yaw_slip_noise * params_.yaw_slip_noise * h;
  omega_rate_ = (wheelSpeeds() - before) / h;
  yaw_rate_ = (x_(4) - yaw_before) / h;
}

bool RobotBelief::correct(const Vector2& y_omega, double y_gyro, bool use_left, bool use_right, bool use_gyro)
{
  if ((use_left && !std::isfinite(y_omega(0))) || (use_right && !std::isfinite(y_omega(1))) ||
      (use_gyro && !std::isfinite(y_gyro)))
  {
    return false;
  }
  f_sensory_ = 0.0;
  f_prior_ = 0.0;
  innovation_.setZero();
  const double r_e = params_.encoder_noise * params_.encoder_noise;
  if (use_left)
  {
    correctPair(y_omega(0), r_e, &x_(0), &x_(1), &p_left_, &f_sensory_, &f_prior_, &innovation_(0));
  }
  if (use_right)
  {
    correctPair(y_omega(1), r_e, &x_(2), &x_(3), &p_right_, &f_sensory_, &f_prior_, &innovation_(1));
  }
  if (use_gyro)
  {
    correctPair(y_gyro, params_.gyro_noise * params_.gyro_noise, &x_(4), &x_(5), &p_yaw_, &f_sensory_, &f_prior_,
                &innovation_(2));
  }
  return true;
}

Eigen::Matrix<double, 6, 1> RobotBelief::variances() const
{
  Eigen::Matrix<double, 6, 1> v;
  v << p_left_(0, 0), p_left_(1, 1), p_right_(0, 0), p_right_(1, 1), p_yaw_(0, 0), p_yaw_(1, 1);
  return v;
}

}  // namespace jackal_aic
