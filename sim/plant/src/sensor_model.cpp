#include "jackal_sim/plant/sensor_model.hpp"

#include <algorithm>
#include <cmath>

namespace jackal_aic
{
namespace plant
{
namespace
{
std::uint64_t toSteps(double seconds, double step)
{
  return static_cast<std::uint64_t>(std::llround(seconds / step));
}
}  // namespace

SensorModel::SensorModel(const SensorParams& params, double step)
  : params_(params)
  , step_(step)
  , js_period_(std::max<std::uint64_t>(1, toSteps(1.0 / params.joint_states.rate, step)))
  , imu_period_(std::max<std::uint64_t>(1, toSteps(1.0 / params.imu.rate, step)))
  , js_delay_(toSteps(params.joint_states.delay, step))
  , imu_delay_(toSteps(params.imu.delay, step))
  , ring_(std::max(js_delay_, imu_delay_) + 1)
  , js_rng_(params.seed)
  , imu_rng_(params.seed + 1u)
{
}

void SensorModel::record(const Plant& plant)
{
  head_ = (head_ + 1) % ring_.size();
  Raw& r = ring_[head_];
  for (int i = 0; i < kNumWheels; ++i)
  {
    r.position[i] = plant.wheelPosition(i);
    r.velocity[i] = plant.wheelVelocity(i);
  }
  r.imu = plant.imuTruth();
  if (recorded_ == 0)
  {
    // Fill the delay line with the first state (the robot was there before).
    std::fill(ring_.begin(), ring_.end(), r);
  }
  ++recorded_;
  step_count_ = plant.stepCount();
  time_ = plant.time();
}

const SensorModel::Raw& SensorModel::delayed(std::uint64_t delay_steps) const
{
  const std::size_t n = ring_.size();
  return ring_[(head_ + n - static_cast<std::size_t>(delay_steps % n)) % n];
}

bool SensorModel::pollJointStates(JointStateSample* out)
{
  if (recorded_ == 0 || step_count_ == 0 || step_count_ % js_period_ != 0)
  {
    return false;
  }
  const JointStateSensorParams& p = params_.joint_states;
  const bool drop = p.dropout > 0.0 && uniform_(js_rng_) < p.dropout;
  const Raw& r = delayed(js_delay_);
  out->stamp = time_;
  for (int i = 0; i < kNumWheels; ++i)
  {
    out->position[i] = r.position[i] + p.position_noise_std * normal_(js_rng_);
    out->velocity[i] = r.velocity[i] + p.velocity_bias + p.velocity_noise_std * normal_(js_rng_);
  }
  if (drop)
  {
    ++js_dropped_;
    return false;
  }
  return true;
}

bool SensorModel::pollImu(ImuSample* out)
{
  if (recorded_ == 0 || step_count_ == 0 || step_count_ % imu_period_ != 0)
  {
    return false;
  }
  const ImuSensorParams& p = params_.imu;
  const bool drop = p.dropout > 0.0 && uniform_(imu_rng_) < p.dropout;
  const Raw& r = delayed(imu_delay_);
  out->stamp = time_;
  for (int k = 0; k < 3; ++k)
  {
    out->angular_velocity[k] = r.imu.angular_velocity[k] + p.gyro_bias[k] + p.gyro_noise_std * normal_(imu_rng_);
    out->linear_acceleration[k] =
        r.imu.linear_acceleration[k] + p.accel_bias[k] + p.accel_noise_std * normal_(imu_rng_);
  }
  Eigen::Vector3d e;
  for (int k = 0; k < 3; ++k)
  {
    e[k] = p.orientation_noise_std * normal_(imu_rng_);
  }
  out->orientation =
      (r.imu.orientation * Eigen::AngleAxisd(e.z(), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(e.y(), Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(e.x(), Eigen::Vector3d::UnitX()))
          .normalized();
  if (drop)
  {
    ++imu_dropped_;
    return false;
  }
  return true;
}

}  // namespace plant
}  // namespace jackal_aic
