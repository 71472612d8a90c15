/**
 * \file fault_monitor.cpp
 * \brief Sensor fault detection and isolation (Baioumy et al., ECC 2021, arXiv 2104.01817;
 *        doc/active_inference.md, 'Fault detection and isolation').
 */
#include "jackal_aic/safety/fault_monitor.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace safety
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

constexpr std::array<int, 3> FaultMonitor::kChannels;

FaultMonitor::FaultMonitor(const params::FdiParams& fdi, const params::AicParams& aic)
  : residual_(kNaN), statistic_(kNaN), last_delay_(kNaN)
{
  setParams(fdi, aic);
}

void FaultMonitor::setParams(const params::FdiParams& fdi, const params::AicParams& aic)
{
  auto violations = fdi.validate();
  for (auto& v : aic.validate())
  {
    violations.push_back(std::move(v));
  }
  if (!violations.empty())
  {
    std::string msg = "invalid fault detection parameters:";
    for (const auto& v : violations)
    {
      msg += " " + v.toString() + ";";
    }
    throw std::invalid_argument(msg);
  }
  fdi_ = fdi;
  if (std::isnan(statistic_))
  {
    threshold_ = fdi.threshold;  // no test yet
  }
  r_alpha_ = aic.wheel_radius * aic.slip_factor;
  half_b_ = 0.5 * aic.wheel_separation;
  c_ = r_alpha_ / aic.wheel_separation;
  const base::YTilde pi_y = aic.precisionY();
  const base::MuTilde pi_mu = aic.precisionMu();
  // Var(r) = sigma^2_gyro + c^2 (sigma^2_L + sigma^2_R) for independent channel noise.
  var_gyro_ = 1.0 / pi_y(base::kGyroZ, 0);
  var_wheels_ = 1.0 / pi_y(base::kOmegaLeft, 0) + 1.0 / pi_y(base::kOmegaRight, 0);
  const double var_r = var_gyro_ + c_ * c_ * var_wheels_;
  pi_r_ = 1.0 / var_r;
  pi_vx_ = pi_mu(0, 0);
  pi_wz_ = pi_mu(2, 0);
}

bool FaultMonitor::setWheelSeparation(double b)
{
  if (!(std::isfinite(b) && b > 0.0))
  {
    return false;
  }
  half_b_ = 0.5 * b;
  c_ = r_alpha_ / b;
  pi_r_ = 1.0 / (var_gyro_ + c_ * c_ * var_wheels_);
  return true;
}

base::Vector3 FaultMonitor::twistWithout(int excluded, const base::Vector5& y) const
{
  double vx = 0.0;
  double wz = 0.0;
  switch (excluded)
  {
    case base::kGyroZ:  // wheels only: mu = G omega (thesis eq. 3-1)
      vx = 0.5 * r_alpha_ * (y(base::kOmegaLeft) + y(base::kOmegaRight));
      wz = c_ * (y(base::kOmegaRight) - y(base::kOmegaLeft));
      break;
    case base::kOmegaLeft:  // gyro + right wheel: omega_R = (x_dot + theta_dot b/2) / (r alpha)
      wz = y(base::kGyroZ);
      vx = r_alpha_ * y(base::kOmegaRight) - wz * half_b_;
      break;
    default:  // kOmegaRight: gyro + left wheel: omega_L = (x_dot - theta_dot b/2) / (r alpha)
      wz = y(base::kGyroZ);
      vx = r_alpha_ * y(base::kOmegaLeft) + wz * half_b_;
      break;
  }
  return base::Vector3(vx, 0.0, wz);
}

FaultMonitor::Event FaultMonitor::update(const base::Vector5& y, const base::Vector3& mu0, double h)
{
  if (!(std::isfinite(h) && h >= 0.0) || !y.allFinite() || !mu0.allFinite())
  {
    ++ignored_;
    return Event::kNone;
  }
  const double residual = y(base::kGyroZ) - c_ * (y(base::kOmegaRight) - y(base::kOmegaLeft));
  // Which exclusion makes the remaining channels agree with the beliefs.
  const auto cost = [&](std::size_t k) {
    const base::Vector3 x = twistWithout(kChannels[k], y);
    const double dvx = x(0) - mu0(0);
    const double dwz = x(2) - mu0(2);
    return pi_vx_ * dvx * dvx + pi_wz_ * dwz * dwz;
  };
  return test(residual, pi_r_ * residual * residual, fdi_.threshold, cost, h);
}

FaultMonitor::Event FaultMonitor::update(const base::SampleInnovation& model, double h)
{
  if (!(std::isfinite(h) && h >= 0.0) || !model.error.allFinite() || !std::isfinite(model.parity) ||
      !(model.variance.minCoeff() > 0.0) || !(model.parity_variance > 0.0) || !model.variance.allFinite() ||
      !std::isfinite(model.parity_variance))
  {
    ++ignored_;
    return Event::kNone;
  }
  // Which exclusion leaves the other two channels closest to the model's prediction.
  const auto cost = [&](std::size_t k) {
    double c = 0.0;
    for (std::size_t i = 0; i < kChannels.size(); ++i)
    {
      if (i != k)
      {
        const double e = model.error(kChannels[i]);
        c += e * e / model.variance(kChannels[i]);
      }
    }
    return c;
  };
  // Restoration is judged on the release variance where the model gives one (test(): NaN = s).
  const double release = std::isfinite(model.release_variance) && model.release_variance > 0.0 ?
                             model.parity * model.parity / model.release_variance :
                             kNaN;
  return test(model.parity, model.parity * model.parity / model.parity_variance, kInnovationThreshold, cost, h,
              release);
}

template <class Cost>
FaultMonitor::Event FaultMonitor::test(double residual, double statistic, double threshold, const Cost& cost, double h,
                                       double release_statistic)
{
  if (!imu_available_)
  {
    residual_ = kNaN;
    statistic_ = kNaN;
    above_for_ = -1.0;
    return Event::kNone;
  }
  residual_ = residual;
  statistic_ = statistic;
  threshold_ = threshold;
  const double release_level = fdi_.release_ratio * threshold;

  if (isolated_ >= 0)
  {
    // Restoration: the isolated channel agrees with the other two again.
    const double agreement = std::isnan(release_statistic) ? statistic_ : release_statistic;
    below_for_ = agreement < release_level ? below_for_ + h : 0.0;
    if (below_for_ >= fdi_.release_time && agreement < release_level)
    {
      isolated_ = -1;
      below_for_ = 0.0;
      above_for_ = -1.0;
      confirmed_ = false;
      ++restorations_;
      return Event::kRestored;
    }
    return Event::kNone;
  }

  if (statistic_ <= threshold)
  {
    // Below the threshold; with isolation off, a confirmed detection ends at the release level.
    if (statistic_ < release_level || !confirmed_)
    {
      above_for_ = -1.0;
      confirmed_ = false;
      hypothesis_cost_.fill(0.0);
    }
    return Event::kNone;
  }
  if (above_for_ < 0.0)
  {
    above_for_ = 0.0;
    hypothesis_cost_.fill(0.0);
  }
  else
  {
    above_for_ += h;
  }
  // The hypotheses' costs, accumulated over the window (computed only above the threshold).
  for (std::size_t k = 0; k < kChannels.size(); ++k)
  {
    hypothesis_cost_[k] += cost(k);
  }
  if (confirmed_ || above_for_ < fdi_.detect_time)
  {
    return Event::kNone;
  }
  confirmed_ = true;
  last_delay_ = above_for_;
  std::size_t best = 0;
  for (std::size_t k = 1; k < kChannels.size(); ++k)
  {
    if (hypothesis_cost_[k] < hypothesis_cost_[best])
    {
      best = k;
    }
  }
  suspected_ = kChannels[best];
  if (!fdi_.enabled)
  {
    ++detections_;
    return Event::kDetected;
  }
  isolated_ = kChannels[best];
  below_for_ = 0.0;
  ++isolations_;
  return Event::kIsolated;
}

void FaultMonitor::setImuAvailable(bool available)
{
  imu_available_ = available;
  if (!available)
  {
    above_for_ = -1.0;
    confirmed_ = false;
  }
}

void FaultMonitor::reset()
{
  isolated_ = -1;
  above_for_ = -1.0;
  below_for_ = 0.0;
  confirmed_ = false;
  hypothesis_cost_.fill(0.0);
  residual_ = kNaN;
  statistic_ = kNaN;
}

std::uint8_t FaultMonitor::sensorMask() const
{
  std::uint8_t mask = (1u << base::kYDim) - 1u;
  if (!imu_available_)
  {
    mask &= static_cast<std::uint8_t>(~((1u << base::kGyroZ) | (1u << base::kAccelX) | (1u << base::kAccelY)));
  }
  if (isolated_ >= 0 && fdi_.enabled)
  {
    mask &= static_cast<std::uint8_t>(~(1u << isolated_));
  }
  return mask;
}

const char* FaultMonitor::channelName(int channel)
{
  switch (channel)
  {
    case base::kGyroZ:
      return "gyro_z";
    case base::kOmegaLeft:
      return "omega_left";
    case base::kOmegaRight:
      return "omega_right";
    case base::kAccelX:
      return "accel_x";
    case base::kAccelY:
      return "accel_y";
    default:
      return "none";
  }
}

const char* toString(FaultMonitor::Event event)
{
  switch (event)
  {
    case FaultMonitor::Event::kNone:
      return "none";
    case FaultMonitor::Event::kIsolated:
      return "isolated";
    case FaultMonitor::Event::kRestored:
      return "restored";
    case FaultMonitor::Event::kDetected:
      return "detected";
  }
  return "unknown";
}

}  // namespace safety
}  // namespace jackal_aic
