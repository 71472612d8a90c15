/**
 * \file sensor_pairing.cpp
 * \brief Joint-state and IMU validation and pairing (include/jackal_aic/loop/sensor_pairing.hpp).
 */
#include "jackal_aic/loop/sensor_pairing.hpp"

#include <cmath>
#include <limits>

namespace jackal_aic
{
namespace loop
{
namespace
{
/// Index of `joint` in `names`, or -1.
int findJoint(const std::vector<std::string>& names, const std::string& joint)
{
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    if (names[i] == joint)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
}

std::size_t sizeOf(const std::vector<double>* v)
{
  return v == nullptr ? 0 : v->size();
}

std::string stampText(double stamp)
{
  return std::isfinite(stamp) ? std::to_string(stamp) : std::string("unset");
}
}  // namespace

const char* toString(DropReason reason)
{
  switch (reason)
  {
    case DropReason::kJointNames:
      return "joint_states: unknown or missing joint name";
    case DropReason::kJointArrays:
      return "joint_states: array length mismatch";
    case DropReason::kJointNonFinite:
      return "joint_states: non-finite value";
    case DropReason::kJointStamp:
      return "joint_states: zero or backwards stamp";
    case DropReason::kImuNonFinite:
      return "imu: non-finite value";
    case DropReason::kImuStamp:
      return "imu: zero or backwards stamp";
    case DropReason::kNoImu:
      return "sample: no imu within imu_max_skew (sample used without the imu)";
    case DropReason::kTooClose:
      return "sample: closer than min_sample_interval";
    case DropReason::kCount:
      break;
  }
  return "unknown";
}

SensorPairing::SensorPairing(const Config& config) : config_(config) {}

void SensorPairing::restartHistory()
{
  has_previous_sample_ = false;
  has_imu_stamp_ = false;
  has_joint_stamp_ = false;
  imu_count_ = 0;
  imu_next_ = 0;
}

bool SensorPairing::drop(DropReason reason, DropReason* out, std::string* why, const std::string& detail)
{
  ++drops_[static_cast<std::size_t>(reason)];
  if (out != nullptr)
  {
    *out = reason;
  }
  if (why != nullptr)
  {
    *why = detail;
  }
  return false;
}

bool SensorPairing::addImu(const ImuInput& imu, std::string* why)
{
  if (!imu.angular_velocity.allFinite() || !imu.linear_acceleration.allFinite())
  {
    return drop(DropReason::kImuNonFinite, nullptr, why, "angular_velocity or linear_acceleration is NaN/Inf");
  }
  if (!std::isfinite(imu.stamp) || (has_imu_stamp_ && imu.stamp <= last_imu_stamp_))
  {
    return drop(DropReason::kImuStamp, nullptr, why,
                "stamp " + stampText(imu.stamp) + " not after the previous " +
                    (has_imu_stamp_ ? std::to_string(last_imu_stamp_) : std::string("(none)")));
  }
  last_imu_stamp_ = imu.stamp;
  has_imu_stamp_ = true;
  imu_[imu_next_] = { imu.stamp,
                      imu.angular_velocity.z(),
                      imu.angular_velocity.y(),
                      imu.linear_acceleration.x(),
                      imu.linear_acceleration.y(),
                      imu.linear_acceleration.z() };
  imu_next_ = (imu_next_ + 1) % kImuHistory;
  imu_count_ = imu_count_ < kImuHistory ? imu_count_ + 1 : kImuHistory;
  return true;
}

bool SensorPairing::addJointState(const JointStateInput& joints, SensorSample* out, DropReason* reason,
                                  std::string* why)
{
  static const std::vector<std::string> kNoNames;
  static const std::vector<double> kNoValues;
  const std::vector<std::string>& names = joints.name ? *joints.name : kNoNames;
  const std::vector<double>& velocity = joints.velocity ? *joints.velocity : kNoValues;
  const std::size_t n = names.size();
  const std::size_t n_position = sizeOf(joints.position);
  const std::size_t n_effort = sizeOf(joints.effort);
  if (velocity.size() != n || (n_position != 0 && n_position != n) || (n_effort != 0 && n_effort != n))
  {
    return drop(DropReason::kJointArrays, reason, why,
                "name " + std::to_string(n) + ", position " + std::to_string(n_position) + ", velocity " +
                    std::to_string(velocity.size()) + ", effort " + std::to_string(n_effort));
  }
  double mean[2] = { 0.0, 0.0 };
  double travel[2] = { 0.0, 0.0 };
  const std::vector<std::string>* sides[2] = { &config_.left_joints, &config_.right_joints };
  for (int side = 0; side < 2; ++side)
  {
    for (const auto& joint : *sides[side])
    {
      const int i = findJoint(names, joint);
      if (i < 0)
      {
        return drop(DropReason::kJointNames, reason, why, "joint '" + joint + "' not in the message");
      }
      const auto k = static_cast<std::size_t>(i);
      if (!std::isfinite(velocity[k]) || (n_position != 0 && !std::isfinite((*joints.position)[k])) ||
          (n_effort != 0 && !std::isfinite((*joints.effort)[k])))
      {
        return drop(DropReason::kJointNonFinite, reason, why, "joint '" + joint + "' has a NaN/Inf");
      }
      mean[side] += velocity[k];
      travel[side] += n_position != 0 ? (*joints.position)[k] : 0.0;
    }
    mean[side] /= static_cast<double>(sides[side]->size());
    travel[side] /= static_cast<double>(sides[side]->size());
  }
  const double stamp = joints.stamp;
  if (!std::isfinite(stamp) || (has_joint_stamp_ && stamp <= last_joint_stamp_))
  {
    return drop(DropReason::kJointStamp, reason, why,
                "stamp " + stampText(stamp) + " not after the previous " +
                    (has_joint_stamp_ ? std::to_string(last_joint_stamp_) : std::string("(none)")));
  }
  last_joint_stamp_ = stamp;
  has_joint_stamp_ = true;

  // Pair with the closest IMU sample already received, within imu_max_skew.
  const ImuEntry* imu = nullptr;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < imu_count_; ++i)
  {
    const double d = std::abs(imu_[i].stamp - stamp);
    if (d <= config_.imu_max_skew && d < best)
    {
      best = d;
      imu = &imu_[i];
    }
  }
  if (imu == nullptr)
  {
    // Degraded mode: the encoders alone carry the twist; the sample goes on without the IMU.
    ++drops_[static_cast<std::size_t>(DropReason::kNoImu)];
  }

  double h = 0.0;
  bool first = !has_previous_sample_;
  if (!first)
  {
    h = stamp - previous_sample_stamp_;
    if (h < config_.min_sample_interval)
    {
      return drop(DropReason::kTooClose, reason, why, "interval " + std::to_string(h) + " s");
    }
    if (h > config_.max_gap)
    {
      first = true;  // a gap: restart the history rather than differentiate across it
      h = 0.0;
    }
  }
  previous_sample_stamp_ = stamp;
  has_previous_sample_ = true;
  ++accepted_;

  out->imu_ok = imu != nullptr;
  out->y(base::kGyroZ) = imu ? imu->gyro_z : 0.0;
  out->y(base::kOmegaLeft) = mean[0];
  out->y(base::kOmegaRight) = mean[1];
  out->y(base::kAccelX) = imu ? imu->accel_x : 0.0;
  out->y(base::kAccelY) = imu ? imu->accel_y : 0.0;
  out->pitch_rate = imu ? imu->gyro_y : 0.0;
  out->up_force = imu ? imu->accel_z : 0.0;
  out->h = h;
  out->first = first;
  out->stamp = stamp;
  out->travel = base::Vector2(travel[0], travel[1]);
  out->has_travel = n_position != 0;
  return true;
}

}  // namespace loop
}  // namespace jackal_aic
