/**
 * \file robot_belief.cpp
 * \brief The robot model's beliefs in their filter form (doc/active_inference.md, 'The robot model').
 */
#include "jackal_aic/aic/robot_belief.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace jackal_aic
{
namespace aic
{
namespace
{
/// One side's belief (omega, d) with covariance p carried h [s] under the command u [rad/s].
void predictSide(const WheelLoopModel& loop, const params::RobotModelParams& params, double h, double u, double rate,
                 double* omega, double d, Eigen::Matrix2d* p)
{
  double gain = 0.0;
  const double next = loop.step(*omega, u - d, rate, h, &gain);
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

RobotBelief::RobotBelief(const params::RobotModelParams& params) : params_(params)
{
  reset(base::Vector2::Zero(), 0.0);
}

void RobotBelief::setParams(const params::RobotModelParams& params)
{
  params_ = params;
}

void RobotBelief::reset(const base::Vector2& omega, double theta_dot)
{
  x_ << omega(0), 0.0, omega(1), 0.0, theta_dot, 0.0, 0.0;
  // The fast states start uncertain, the slow ones at zero and certain: they drift from there at
  // their own rate (shortfall_noise, yaw_slip_noise, gyro_offset_noise), not on the first transient.
  p_left_ << kInitialVariance, 0.0, 0.0, 0.0;
  p_right_ = p_left_;
  p_yaw_.setZero();
  p_yaw_(0, 0) = kInitialVariance;
  turn_ = std::numeric_limits<double>::quiet_NaN();  // no predict() yet
  offset_run_.clear();
  wheel_command_.setZero();
  steady_command_.setZero();
  steady_time_.setZero();
  settle_needed_.setZero();
  shortfall_runs_[0].clear();
  shortfall_runs_[1].clear();
  shortfall_jump_.setZero();
  jump_turn_.setZero();
  omega_rate_.setZero();
  yaw_rate_ = 0.0;
  f_sensory_ = 0.0;
  f_prior_ = 0.0;
  innovation_.setZero();
}

void RobotBelief::forgetSlowStates()
{
  x_(1) = 0.0;
  x_(3) = 0.0;
  x_(5) = 0.0;
  x_(6) = 0.0;
  for (Eigen::Matrix2d* p : { &p_left_, &p_right_ })
  {
    p->row(1).setZero();
    p->col(1).setZero();
  }
  p_yaw_.bottomRows<2>().setZero();
  p_yaw_.rightCols<2>().setZero();
  offset_run_.clear();
  shortfall_runs_[0].clear();
  shortfall_runs_[1].clear();
  shortfall_jump_.setZero();
}

void RobotBelief::predict(double h, const WheelLoopModel& loop, const base::Vector2& u_at_wheels,
                          const base::Vector2& rate_at_wheels, double yaw_gain, double turn)
{
  const base::Vector2 before = wheelSpeeds();
  const double yaw_before = x_(4);
  // A jump in the shortfall belongs to the turn it was taken in (a stall, a turn deficit, a wheel at
  // its limit in the turn): when the goal's turn moves on by more than kJumpTurnBand it is dropped,
  // and the drift's part of d stays.
  for (int i = 0; i < 2; ++i)
  {
    if (shortfall_jump_(i) != 0.0 && std::isfinite(turn) && !(std::abs(turn - jump_turn_(i)) <= kJumpTurnBand))
    {
      x_(2 * i + 1) -= shortfall_jump_(i);
      shortfall_jump_(i) = 0.0;
    }
  }
  // Each side's command at the wheels: steady while it stays within kSteadyBand of where it
  // settled; a change beyond restarts the wait for the wheel loop to settle.
  for (int i = 0; i < 2; ++i)
  {
    const double u = u_at_wheels(i);
    if (std::abs(u - steady_command_(i)) <= kSteadyBand)
    {
      steady_time_(i) += h;
    }
    else
    {
      settle_needed_(i) = settleTime(u - steady_command_(i));
      steady_command_(i) = u;
      steady_time_(i) = 0.0;
    }
    wheel_command_(i) = u;
  }
  predictSide(loop, params_, h, u_at_wheels(0), rate_at_wheels(0), &x_(0), x_(1), &p_left_);
  predictSide(loop, params_, h, u_at_wheels(1), rate_at_wheels(1), &x_(2), x_(3), &p_right_);
  // The yaw triple (theta_dot, s, beta): theta_dot' = ((1 - s) u - theta_dot) / T_s, u =
  // yaw_gain (omega_R - omega_L), integrated exactly with u held; s moves with the goal's turn
  // (variance sigma_s^2 |dw|), beta with time.
  const double u = yaw_gain * (x_(2) - x_(0));
  wheels_yaw_ = u;
  yaw_gain_ = yaw_gain;
  const double dw = std::isfinite(turn_) && std::isfinite(turn) ? std::abs(turn - turn_) : 0.0;
  turn_ = turn;
  const double target = (1.0 - x_(5)) * u;
  const double decay = std::exp(-h / params_.yaw_time_constant);
  x_(4) = target + (x_(4) - target) * decay;
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 0) = decay;
  f(0, 1) = -u * (1.0 - decay);
  p_yaw_ = f * p_yaw_ * f.transpose();
  p_yaw_(0, 0) += params_.yaw_model_noise * params_.yaw_model_noise * h;
  p_yaw_(1, 1) += params_.yaw_slip_noise * params_.yaw_slip_noise * dw;
  // The offset drifts where it is observed: at rest and in straight driving (the goal's turn
  // below kStraightTurn). In a turn it changes by a jump only (correct()).
  if (std::abs(turn) < kStraightTurn)
  {
    p_yaw_(2, 2) += params_.gyro_offset_noise * params_.gyro_offset_noise * h;
  }
  omega_rate_ = (wheelSpeeds() - before) / h;
  yaw_rate_ = (x_(4) - yaw_before) / h;
}

bool RobotBelief::correct(const base::Vector2& y_omega, double y_gyro, bool use_left, bool use_right, bool use_gyro,
                          bool learn, bool learn_slip)
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
  detectShortfallJump(0, y_omega(0), use_left, r_e, &x_(1), p_left_);
  detectShortfallJump(1, y_omega(1), use_right, r_e, &x_(3), p_right_);
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
    // y = theta_dot + beta: H = (1, 0, 1). Without learning the slow states take no gain.
    const double r_g = params_.gyro_noise * params_.gyro_noise;
    const Eigen::RowVector3d hrow(1.0, 0.0, 1.0);
    const Eigen::Vector3d ph = p_yaw_ * hrow.transpose();
    const double sv = hrow.dot(ph) + r_g;
    Eigen::Vector3d k = ph / sv;
    if (!learn_slip)
    {
      k(1) = 0.0;
    }
    if (!learn)
    {
      k(1) = 0.0;
      k(2) = 0.0;
      offset_run_.clear();
    }
    else
    {
      // The gyro against the model's steady yaw rate (1 - s) u + beta: kJumpSamples residuals in a
      // row beyond kJumpThreshold standard deviations (sigma_g and the slow states' uncertainty)
      // are an offset jump, taken up at once: beta moves by their mean, theta_dot back by it.
      const double r = y_gyro - ((1.0 - x_(5)) * wheels_yaw_ + x_(6));
      const double var_r = r_g + wheels_yaw_ * wheels_yaw_ * p_yaw_(1, 1) + p_yaw_(2, 2);
      const bool beyond = std::isfinite(r) && r * r > kJumpThreshold * kJumpThreshold * var_r;
      if (offset_run_.add(r, beyond, std::numeric_limits<double>::infinity(), kJumpSamples))
      {
        const double jump = offset_run_.mean();
        x_(6) += jump;
        x_(4) -= jump;
        ++offset_jumps_;
      }
    }
    const double e = y_gyro - (x_(4) + x_(6));
    x_(4) += k(0) * e;
    x_(5) += k(1) * e;
    x_(6) += k(2) * e;
    // Joseph form: valid for the gain used, optimal or held.
    const Eigen::Matrix3d a = Eigen::Matrix3d::Identity() - k * hrow;
    p_yaw_ = a * p_yaw_ * a.transpose() + r_g * k * k.transpose();
    const double corrected = e - hrow.dot(k) * e;  // y - H mu at the corrected belief
    f_sensory_ += 0.5 * corrected * corrected / r_g;
    f_prior_ += 0.5 * e * e * hrow.dot(k) * (1.0 - hrow.dot(k)) / r_g;
    innovation_(2) = e;
  }
  return true;
}

base::SampleInnovation RobotBelief::sampleInnovation(const base::Vector2& y_omega, double y_gyro) const
{
  const double r_e = params_.encoder_noise * params_.encoder_noise;
  base::SampleInnovation in;
  in.error(base::kGyroZ) = y_gyro - (x_(4) + x_(6));
  in.error(base::kOmegaLeft) = y_omega(0) - x_(0);
  in.error(base::kOmegaRight) = y_omega(1) - x_(2);
  in.variance(base::kGyroZ) =
      p_yaw_(0, 0) + 2.0 * p_yaw_(0, 2) + p_yaw_(2, 2) + params_.gyro_noise * params_.gyro_noise;
  in.variance(base::kOmegaLeft) = p_left_(0, 0) + r_e;
  in.variance(base::kOmegaRight) = p_right_(0, 0) + r_e;
  const double k = (1.0 - x_(5)) * yaw_gain_;
  in.parity = in.error(base::kGyroZ) - k * (in.error(base::kOmegaRight) - in.error(base::kOmegaLeft));
  in.parity_variance =
      in.variance(base::kGyroZ) + k * k * (in.variance(base::kOmegaLeft) + in.variance(base::kOmegaRight));
  return in;
}

void RobotBelief::detectShortfallJump(int side, double y, bool used, double r_e, double* d, const Eigen::Matrix2d& p)
{
  // The wheel against the model's steady speed u - d, once the command has held long enough for
  // the wheel loop to have settled: kShortfallJumpSamples residuals in a row beyond kJumpThreshold
  // standard deviations (sigma_e and d's uncertainty), all within kJumpThreshold sqrt(2) sigma_e of
  // the first (the wheel no longer moves: a loop still converging changes them), are a step in the
  // load; d takes their mean at once.
  ResidualRun& run = shortfall_runs_[side];
  if (!used || steady_time_(side) < settle_needed_(side))
  {
    run.clear();
    return;
  }
  const double r = y - (wheel_command_(side) - *d);
  const double limit = kJumpThreshold * std::sqrt(r_e + p(1, 1));
  if (run.add(r, std::abs(r) > limit, kJumpThreshold * std::sqrt(2.0 * r_e), kShortfallJumpSamples))
  {
    // A shortfall: the wheel delivers between nothing and the whole command (a wheel faster than
    // its command, pushed or rolling downhill, is left to the drift).
    const double u = wheel_command_(side);
    const double target = std::clamp(*d - run.mean(), std::min(0.0, u), std::max(0.0, u));
    if (std::abs(target - *d) > limit)
    {
      shortfall_jump_(side) += target - *d;
      jump_turn_(side) = turn_;
      *d = target;
      ++shortfall_jumps_;
    }
  }
}

double RobotBelief::settleTime(double du) const
{
  return std::abs(du) / params_.wheel_acceleration + kSettleLags * params_.wheel_time_constant;
}

bool RobotBelief::shiftGyroOffset(double delta)
{
  if (!std::isfinite(delta))
  {
    return false;
  }
  x_(6) += delta;
  return true;
}

bool RobotBelief::rescaleSlip(double k)
{
  if (!std::isfinite(k) || !(k > 0.0))
  {
    return false;
  }
  x_(5) = 1.0 - k * (1.0 - x_(5));
  p_yaw_.row(1) *= k;
  p_yaw_.col(1) *= k;
  return true;
}

Eigen::Matrix<double, 7, 1> RobotBelief::variances() const
{
  Eigen::Matrix<double, 7, 1> v;
  v << p_left_(0, 0), p_left_(1, 1), p_right_(0, 0), p_right_(1, 1), p_yaw_(0, 0), p_yaw_(1, 1), p_yaw_(2, 2);
  return v;
}

}  // namespace aic
}  // namespace jackal_aic
