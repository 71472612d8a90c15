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
/// One side's belief x = (omega, d, e) with covariance p carried h [s] under the command u [rad/s]:
/// the wheel loop under u - d - sigma e (sigma the side's RobotBelief::turnSigns() at the goal's
/// turn); d drifts in time (q_d), e only while the robot turns (q_e |sigma|: where it is observed).
void predictSide(const WheelLoopModel& loop, const params::RobotModelParams& params, double h, double u, double rate,
                 double sigma, Eigen::Vector3d* x, Eigen::Matrix3d* p)
{
  double gain = 0.0;
  const double shortfall = (*x)(1) + sigma * (*x)(2);
  const double next = loop.step((*x)(0), u - shortfall, rate, h, &gain);
  const bool bounded = params.wheel_time_constant > 0.0 && gain == 1.0;
  const double pull = bounded ? 0.0 : -(1.0 - gain);
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 0) = gain;
  f(0, 1) = pull;
  f(0, 2) = pull * sigma;
  *p = f * (*p) * f.transpose();
  const double q_e = params.turn_shortfall_noise * params.turn_shortfall_noise * h;
  (*p)(0, 0) += params.wheel_model_noise * params.wheel_model_noise * h;
  (*p)(1, 1) += params.shortfall_noise * params.shortfall_noise * h;
  (*p)(2, 2) += q_e * std::abs(sigma);
  (*x)(0) = next;
}

/// Scalar measurement y of the first state of x = (omega, d, e) with covariance p and noise variance
/// r; with hold_turn, e takes no gain (held: the Joseph form keeps p its covariance under the gain
/// used). Adds the free energy's parts at the corrected belief: sensory 1/2 (y - omega)^2 / r, prior
/// 1/2 (K e)^T P_-^{-1} (K e) = 1/2 e^2 k0 / s (e the innovation, s = p00 + r, k0 = K's omega part).
void correctSide(double y, double r, bool hold_turn, Eigen::Vector3d* x, Eigen::Matrix3d* p, double* f_sensory,
                 double* f_prior, double* innovation)
{
  const double e = y - (*x)(0);
  const double s = (*p)(0, 0) + r;
  Eigen::Vector3d k = p->col(0) / s;
  if (hold_turn)
  {
    k(2) = 0.0;
  }
  *x += k * e;
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
  a.col(0) -= k;
  *p = a * (*p) * a.transpose() + r * k * k.transpose();
  const double corrected = (1.0 - k(0)) * e;
  *f_sensory += 0.5 * corrected * corrected / r;
  *f_prior += 0.5 * e * e * k(0) / s;
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
  side_[0] << omega(0), 0.0, 0.0;
  side_[1] << omega(1), 0.0, 0.0;
  yaw_ << theta_dot, 0.0, 0.0;
  // The fast states start uncertain, the slow ones at zero and certain: they drift from there at
  // their own rate (shortfall_noise, yaw_slip_noise, gyro_offset_noise), not on the first transient.
  p_side_[0].setZero();
  p_side_[0](0, 0) = kInitialVariance;
  p_side_[1] = p_side_[0];
  turn_signs_.setZero();
  last_reading_.setConstant(std::numeric_limits<double>::quiet_NaN());
  frozen_ = Eigen::Matrix<bool, 2, 1>::Constant(false);
  sample_command_.setZero();
  p_yaw_.setZero();
  p_yaw_(0, 0) = kInitialVariance;
  turn_ = std::numeric_limits<double>::quiet_NaN();  // no predict() yet
  offset_run_.clear();
  wheel_command_.setZero();
  steady_command_.setZero();
  steady_time_.setZero();
  settle_needed_.setZero();
  for (int i = 0; i < 2; ++i)
  {
    shortfall_runs_[i].clear();
    release_runs_[i].clear();
  }
  shortfall_jump_.setZero();
  jump_turn_.setZero();
  jump_wheel_.setZero();
  jump_command_.setZero();
  for (int i = 0; i < 2; ++i)
  {
    stall_runs_[i].clear();
    stalled_[i] = false;
    saturated_[i] = false;
  }
  omega_rate_.setZero();
  yaw_rate_ = 0.0;
  f_sensory_ = 0.0;
  f_prior_ = 0.0;
  innovation_.setZero();
}

void RobotBelief::forgetSlowStates()
{
  side_[0](1) = 0.0;
  side_[1](1) = 0.0;
  yaw_(1) = 0.0;
  yaw_(2) = 0.0;
  for (int i = 0; i < 2; ++i)
  {
    side_[i].tail<2>().setZero();
    p_side_[i].bottomRows<2>().setZero();
    p_side_[i].rightCols<2>().setZero();
  }
  p_yaw_.bottomRows<2>().setZero();
  p_yaw_.rightCols<2>().setZero();
  offset_run_.clear();
  for (int i = 0; i < 2; ++i)
  {
    shortfall_runs_[i].clear();
    release_runs_[i].clear();
  }
  shortfall_jump_.setZero();
  saturated_[0] = false;
  saturated_[1] = false;
}

void RobotBelief::predict(double h, const WheelLoopModel& loop, const base::Vector2& u_at_wheels,
                          const base::Vector2& rate_at_wheels, double yaw_gain, double turn, bool slip_observed)
{
  const base::Vector2 before = wheelSpeeds();
  const double yaw_before = yaw_(0);
  // A jump in the shortfall belongs to the turn it was taken in (a stall, a turn deficit, a wheel at
  // its limit in the turn): when the goal's turn moves on by more than kJumpTurnBand it is dropped,
  // and the drift's part of d stays.
  for (int i = 0; i < 2; ++i)
  {
    if (shortfall_jump_(i) != 0.0 && std::isfinite(turn) && !(std::abs(turn - jump_turn_(i)) <= kJumpTurnBand))
    {
      dropJumps(i);
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
  // A turn's load (its scrub torque) acts against the turn: it holds the right side back in a left
  // turn and pushes the left side on, and the other way in a right turn (turnSigns()).
  turn_signs_ = turnSigns(turn);
  // A saturated side's wheel holds the speed its last jump found whatever the command: d follows
  // the command at the wheels, so the model's steady speed u - d - sigma e stays that speed (the
  // jumps' part takes the change, so dropping them leaves the drift's part).
  for (int i = 0; i < 2; ++i)
  {
    if (saturated_[i])
    {
      const double d = u_at_wheels(i) - turn_signs_(i) * side_[i](2) - jump_wheel_(i);
      shortfall_jump_(i) += d - side_[i](1);
      side_[i](1) = d;
    }
  }
  predictSide(loop, params_, h, u_at_wheels(0), rate_at_wheels(0), turn_signs_(0), &side_[0], &p_side_[0]);
  predictSide(loop, params_, h, u_at_wheels(1), rate_at_wheels(1), turn_signs_(1), &side_[1], &p_side_[1]);
  // The yaw triple (theta_dot, s, beta): theta_dot' = ((1 - s) u - theta_dot) / T_s, u =
  // yaw_gain (omega_R - omega_L), integrated exactly with u held; s moves with the goal's turn
  // (variance sigma_s^2 |dw|), beta with time.
  const double u = yaw_gain * (side_[1](0) - side_[0](0));
  wheels_yaw_ = u;
  yaw_gain_ = yaw_gain;
  const double dw = std::isfinite(turn_) && std::isfinite(turn) ? std::abs(turn - turn_) : 0.0;
  turn_ = turn;
  const double target = (1.0 - yaw_(1)) * u;
  const double decay = std::exp(-h / params_.yaw_time_constant);
  yaw_(0) = target + (yaw_(0) - target) * decay;
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 0) = decay;
  f(0, 1) = -u * (1.0 - decay);
  p_yaw_ = f * p_yaw_ * f.transpose();
  p_yaw_(0, 0) += params_.yaw_model_noise * params_.yaw_model_noise * h;
  if (slip_observed)
  {
    p_yaw_(1, 1) += params_.yaw_slip_noise * params_.yaw_slip_noise * dw;
  }
  // The offset drifts where it is observed: at rest and in straight driving (the goal's turn
  // below kStraightTurn). In a turn it changes by a jump only (correct()).
  if (std::abs(turn) < kStraightTurn)
  {
    p_yaw_(2, 2) += params_.gyro_offset_noise * params_.gyro_offset_noise * h;
  }
  omega_rate_ = (wheelSpeeds() - before) / h;
  yaw_rate_ = (yaw_(0) - yaw_before) / h;
}

bool RobotBelief::correct(const base::Vector2& y_omega, double y_gyro, const SampleUse& use)
{
  bool use_left = use.left;
  bool use_right = use.right;
  const bool use_gyro = use.gyro;
  if ((use_left && !std::isfinite(y_omega(0))) || (use_right && !std::isfinite(y_omega(1))) ||
      (use_gyro && !std::isfinite(y_gyro)))
  {
    return false;
  }
  f_sensory_ = 0.0;
  f_prior_ = 0.0;
  innovation_.setZero();
  const double r_e = params_.encoder_noise * params_.encoder_noise;
  // A frozen encoder: a nonzero reading that repeats bit for bit while the side's command at the
  // wheels moves is not the wheel (a noisy encoder's reading of a moving wheel does not repeat, a
  // stalled wheel reads zero). The side is skipped, so the belief is not pulled to the frozen value
  // and the fault monitor's innovation test sees the wheel's prediction error
  // (frozenEncoderSamples()).
  const bool frozen_left = frozenReading(0, y_omega(0));
  const bool frozen_right = frozenReading(1, y_omega(1));
  frozen_samples_ += (use_left && frozen_left ? 1u : 0u) + (use_right && frozen_right ? 1u : 0u);
  use_left = use_left && !frozen_left;
  use_right = use_right && !frozen_right;
  detectShortfallJump(0, y_omega(0), use_left, r_e, &side_[0](1), p_side_[0]);
  detectShortfallJump(1, y_omega(1), use_right, r_e, &side_[1](1), p_side_[1]);
  if (use_left)
  {
    correctSide(y_omega(0), r_e, !use.learn_turn, &side_[0], &p_side_[0], &f_sensory_, &f_prior_, &innovation_(0));
  }
  if (use_right)
  {
    correctSide(y_omega(1), r_e, !use.learn_turn, &side_[1], &p_side_[1], &f_sensory_, &f_prior_, &innovation_(1));
  }
  if (use_gyro)
  {
    // y = theta_dot + beta: H = (1, 0, 1). Without learning the slow states take no gain.
    const double r_g = params_.gyro_noise * params_.gyro_noise;
    const Eigen::RowVector3d hrow(1.0, 0.0, 1.0);
    const Eigen::Vector3d ph = p_yaw_ * hrow.transpose();
    const double sv = hrow.dot(ph) + r_g;
    Eigen::Vector3d k = ph / sv;
    if (!use.learn_slip)
    {
      k(1) = 0.0;
    }
    if (!use.learn)
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
      const double r = y_gyro - ((1.0 - yaw_(1)) * wheels_yaw_ + yaw_(2));
      const double var_r = r_g + wheels_yaw_ * wheels_yaw_ * p_yaw_(1, 1) + p_yaw_(2, 2);
      const bool beyond = std::isfinite(r) && r * r > kJumpThreshold * kJumpThreshold * var_r;
      if (offset_run_.add(r, beyond, std::numeric_limits<double>::infinity(), kJumpSamples))
      {
        const double jump = offset_run_.mean();
        yaw_(2) += jump;
        yaw_(0) -= jump;
        ++offset_jumps_;
      }
    }
    const double e = y_gyro - (yaw_(0) + yaw_(2));
    yaw_(0) += k(0) * e;
    yaw_(1) += k(1) * e;
    yaw_(2) += k(2) * e;
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
  in.error(base::kGyroZ) = y_gyro - (yaw_(0) + yaw_(2));
  in.error(base::kOmegaLeft) = y_omega(0) - side_[0](0);
  in.error(base::kOmegaRight) = y_omega(1) - side_[1](0);
  in.variance(base::kGyroZ) =
      p_yaw_(0, 0) + 2.0 * p_yaw_(0, 2) + p_yaw_(2, 2) + params_.gyro_noise * params_.gyro_noise;
  in.variance(base::kOmegaLeft) = p_side_[0](0, 0) + r_e;
  in.variance(base::kOmegaRight) = p_side_[1](0, 0) + r_e;
  const double k = (1.0 - yaw_(1)) * yaw_gain_;
  in.parity = in.error(base::kGyroZ) - k * (in.error(base::kOmegaRight) - in.error(base::kOmegaLeft));
  in.parity_variance =
      in.variance(base::kGyroZ) + k * k * (in.variance(base::kOmegaLeft) + in.variance(base::kOmegaRight));
  // In a turn the slip ratio's uncertainty (the yaw rate's share u^2 P_s) lets the parity take a
  // sensor's disagreement as slip; it is no evidence that an isolated channel agrees again. At
  // least what the sensors' own noise gives.
  const double sensors = params_.gyro_noise * params_.gyro_noise + 2.0 * k * k * r_e;
  in.release_variance = std::max(in.parity_variance - wheels_yaw_ * wheels_yaw_ * p_yaw_(1, 1), sensors);
  return in;
}

void RobotBelief::detectShortfallJump(int side, double y, bool used, double r_e, double* d, const Eigen::Matrix3d& p)
{
  // The wheel against the model's steady speed u - d, once the command has held long enough for
  // the wheel loop to have settled: kShortfallJumpSamples residuals in a row beyond kJumpThreshold
  // standard deviations (sigma_e and d's uncertainty), all within kJumpThreshold sqrt(2) sigma_e of
  // the first (the wheel no longer moves: a loop still converging changes them), are a step in the
  // load; d takes their mean at once.
  // The jump test's limit on a residual, its band of a wheel that does not move, and the turn
  // shortfall's part of the model's steady speed: shared by the stall, release and jump tests.
  const double limit = kJumpThreshold * std::sqrt(r_e + p(1, 1));
  const double band = kJumpThreshold * std::sqrt(2.0 * r_e);
  const double turn_part = turn_signs_(side) * side_[side](2);
  detectStall(side, y, used, *d + turn_part, limit, band);
  ResidualRun& run = shortfall_runs_[side];
  if (!used || steady_time_(side) < settle_needed_(side))
  {
    run.clear();
    release_runs_[side].clear();
    return;
  }
  const double r = y - (wheel_command_(side) - *d - turn_part);
  // The load the jumps took is gone (a stall that frees): the wheel runs faster than the model's
  // steady speed, toward its command, kShortfallJumpSamples samples in a row beyond the same limit,
  // still moving or not. The jumps are dropped, as at a turn's change; a shortfall that remains is
  // taken again once the wheel has stopped moving.
  const bool releases =
      shortfall_jump_(side) * wheel_command_(side) > 0.0 && r * wheel_command_(side) > 0.0 && std::abs(r) > limit;
  if (release_runs_[side].add(r, releases, std::numeric_limits<double>::infinity(), kShortfallJumpSamples))
  {
    dropJumps(side);
    ++shortfall_releases_;
    run.clear();
    return;
  }
  if (run.add(r, std::abs(r) > limit, band, kShortfallJumpSamples))
  {
    // A shortfall: the wheel delivers between nothing and the whole command (a wheel faster than
    // its command, pushed or rolling downhill, is left to the drift).
    const double u = wheel_command_(side);
    const double target = std::clamp(*d + turn_part - run.mean(), std::min(0.0, u), std::max(0.0, u)) - turn_part;
    if (std::abs(target - *d) > limit)
    {
      // A second jump: unanswered if the last went the same way and the raised command left the wheel
      // where it found it (saturateIfUnanswered()).
      const double wheel = run.mean() + (u - *d - turn_part);
      saturateIfUnanswered(side, target - *d > 0.0 ? 1.0 : -1.0, wheel, band);
      jump_wheel_(side) = wheel;
      jump_command_(side) = u;
      shortfall_jump_(side) += target - *d;
      jump_turn_(side) = turn_;
      *d = target;
      ++shortfall_jumps_;
    }
  }
}

void RobotBelief::detectStall(int side, double y, bool used, double shortfall, double limit, double band)
{
  if (!used || !std::isfinite(y))
  {
    return;
  }
  const double u = wheel_command_(side);
  const double direction = u >= 0.0 ? 1.0 : -1.0;
  // How far the model's steady speed u - d - sigma e is beyond the wheel, toward the command.
  const double steady = u - shortfall;
  const double gap = (steady - y) * direction;
  if (stalled_[side])
  {
    // Answered (the wheel gives the model's steady speed) or asked for no more than it gives (the
    // command came back to it). Not on motion alone: a wheel that sticks and slips moves while it
    // is held.
    if (gap <= limit || std::abs(u - y) <= limit)
    {
      stalled_[side] = false;
      stall_runs_[side].clear();
    }
    return;
  }
  // Held, not short: the wheel gives less than kHeldFraction of the model's steady speed.
  const bool held = gap > limit && std::abs(y) <= kHeldFraction * std::abs(steady);
  if (stall_runs_[side].add(y, held, band, kShortfallJumpSamples))
  {
    stalled_[side] = true;
    ++stalls_;
    // Held again after its jump was made up: unanswered, as a second jump would show once the
    // command held still.
    saturateIfUnanswered(side, direction, stall_runs_[side].mean(), band);
  }
}

void RobotBelief::saturateIfUnanswered(int side, double direction, double wheel, double band)
{
  // The side's last jump was in `direction`, the command has since been raised that way by more
  // than the band (an answer would show), and the wheel is within the band of where that jump
  // found it: the side is saturated, its speed no longer depends on its command.
  if (!saturated_[side] && shortfall_jump_(side) * direction > 0.0 &&
      (wheel_command_(side) - jump_command_(side)) * direction > band && std::abs(wheel - jump_wheel_(side)) <= band)
  {
    saturated_[side] = true;
    ++unanswered_jumps_;
  }
}

void RobotBelief::dropJumps(int side)
{
  side_[side](1) -= shortfall_jump_(side);
  shortfall_jump_(side) = 0.0;
  saturated_[side] = false;
}

base::Vector2 RobotBelief::compensableShortfallsAt(double turn) const
{
  base::Vector2 d = shortfallsAt(turn);
  for (int s = 0; s < 2; ++s)
  {
    if (saturated_[s] || stalled_[s])
    {
      d(s) = 0.0;
    }
  }
  return d;
}

base::Vector2 RobotBelief::turnSigns(double turn)
{
  if (!std::isfinite(turn))
  {
    return base::Vector2::Zero();
  }
  const double c = std::clamp(turn / kStraightTurn, -1.0, 1.0);
  return base::Vector2(-c, c);
}

base::Vector2 RobotBelief::shortfallsAt(double turn) const
{
  const base::Vector2 sigma = turnSigns(turn);
  return base::Vector2(side_[0](1) + sigma(0) * side_[0](2), side_[1](1) + sigma(1) * side_[1](2));
}

bool RobotBelief::frozenReading(int side, double y)
{
  if (!std::isfinite(y))
  {
    return false;
  }
  const bool repeated = y == last_reading_(side) && y != 0.0;
  const bool command_moved = std::abs(wheel_command_(side) - sample_command_(side)) > kSteadyBand;
  last_reading_(side) = y;
  sample_command_(side) = wheel_command_(side);
  // Frozen from the first repeat across a change of the side's command at the wheels, for as long
  // as the reading keeps repeating.
  frozen_(side) = repeated && (frozen_(side) || command_moved);
  return frozen_(side);
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
  yaw_(2) += delta;
  return true;
}

bool RobotBelief::rescaleSlip(double k)
{
  if (!std::isfinite(k) || !(k > 0.0))
  {
    return false;
  }
  yaw_(1) = 1.0 - k * (1.0 - yaw_(1));
  p_yaw_.row(1) *= k;
  p_yaw_.col(1) *= k;
  return true;
}

Eigen::Matrix<double, 7, 1> RobotBelief::variances() const
{
  Eigen::Matrix<double, 7, 1> v;
  v << p_side_[0](0, 0), p_side_[0](1, 1), p_side_[1](0, 0), p_side_[1](1, 1), p_yaw_(0, 0), p_yaw_(1, 1), p_yaw_(2, 2);
  return v;
}

}  // namespace aic
}  // namespace jackal_aic
