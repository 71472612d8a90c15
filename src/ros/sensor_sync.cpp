#include "jackal_aic/ros/sensor_sync.hpp"

#include <cmath>
#include <limits>

#include <ros/console.h>

namespace jackal_aic
{
namespace
{
/// IMU messages kept for pairing (0.4 s at 50 Hz).
constexpr unsigned int kImuCacheSize = 20;

bool finite3(const geometry_msgs::Vector3& v)
{
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Index of `name` in msg.name, or -1.
int findJoint(const sensor_msgs::JointState& msg, const std::string& name)
{
  for (std::size_t i = 0; i < msg.name.size(); ++i)
  {
    if (msg.name[i] == name)
    {
      return static_cast<int>(i);
    }
  }
  return -1;
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

SensorSynchronizer::Config SensorSynchronizer::Config::fromParams(const NodeParams& params)
{
  Config c;
  c.left_joints = params.left_joints;
  c.right_joints = params.right_joints;
  c.imu_max_skew = params.imu_max_skew;
  c.min_sample_interval = params.min_sample_interval;
  c.max_gap = params.sensor_timeout;
  return c;
}

SensorSynchronizer::SensorSynchronizer(const Config& config)
  : config_(config), imu_cache_(std::make_unique<message_filters::Cache<sensor_msgs::Imu>>(kImuCacheSize))
{
}

void SensorSynchronizer::restartHistory()
{
  has_previous_sample_ = false;
  last_imu_stamp_ = ros::Time();
  last_joint_stamp_ = ros::Time();
  imu_cache_ = std::make_unique<message_filters::Cache<sensor_msgs::Imu>>(kImuCacheSize);
}

void SensorSynchronizer::setConfig(const Config& config)
{
  config_ = config;
}

bool SensorSynchronizer::drop(DropReason reason, const std::string& detail)
{
  ++drops_[static_cast<int>(reason)];
  ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: dropped input (" << toString(reason) << "): " << detail << " ["
                                                               << drops_[static_cast<int>(reason)]
                                                               << " dropped for this reason so far]");
  return false;
}

bool SensorSynchronizer::addImu(const sensor_msgs::Imu::ConstPtr& msg)
{
  if (!finite3(msg->angular_velocity) || !finite3(msg->linear_acceleration))
  {
    return drop(DropReason::kImuNonFinite, "angular_velocity or linear_acceleration is NaN/Inf");
  }
  if (msg->header.stamp.isZero() || msg->header.stamp <= last_imu_stamp_)
  {
    return drop(DropReason::kImuStamp, "stamp " + std::to_string(msg->header.stamp.toSec()) +
                                           " not after the previous " + std::to_string(last_imu_stamp_.toSec()));
  }
  last_imu_stamp_ = msg->header.stamp;
  imu_cache_->add(msg);
  return true;
}

bool SensorSynchronizer::addJointState(const sensor_msgs::JointState::ConstPtr& msg, SensorSample* out)
{
  const std::size_t n = msg->name.size();
  if (msg->velocity.size() != n || (!msg->position.empty() && msg->position.size() != n) ||
      (!msg->effort.empty() && msg->effort.size() != n))
  {
    return drop(DropReason::kJointArrays, "name " + std::to_string(n) + ", position " +
                                              std::to_string(msg->position.size()) + ", velocity " +
                                              std::to_string(msg->velocity.size()) + ", effort " +
                                              std::to_string(msg->effort.size()));
  }
  double mean[2] = { 0.0, 0.0 };
  const std::vector<std::string>* sides[2] = { &config_.left_joints, &config_.right_joints };
  for (int side = 0; side < 2; ++side)
  {
    for (const auto& joint : *sides[side])
    {
      const int i = findJoint(*msg, joint);
      if (i < 0)
      {
        return drop(DropReason::kJointNames, "joint '" + joint + "' not in the message");
      }
      if (!std::isfinite(msg->velocity[i]) || (!msg->position.empty() && !std::isfinite(msg->position[i])) ||
          (!msg->effort.empty() && !std::isfinite(msg->effort[i])))
      {
        return drop(DropReason::kJointNonFinite, "joint '" + joint + "' has a NaN/Inf");
      }
      mean[side] += msg->velocity[i];
    }
    mean[side] /= static_cast<double>(sides[side]->size());
  }
  const ros::Time stamp = msg->header.stamp;
  if (stamp.isZero() || stamp <= last_joint_stamp_)
  {
    return drop(DropReason::kJointStamp, "stamp " + std::to_string(stamp.toSec()) + " not after the previous " +
                                             std::to_string(last_joint_stamp_.toSec()));
  }
  last_joint_stamp_ = stamp;

  // Pair with the closest IMU already received, within imu_max_skew.
  const ros::Duration skew(config_.imu_max_skew);
  const ros::Time from = stamp > ros::Time(0) + skew ? stamp - skew : ros::Time(0);
  sensor_msgs::Imu::ConstPtr imu;
  double best = std::numeric_limits<double>::infinity();
  for (const auto& candidate : imu_cache_->getInterval(from, stamp + skew))
  {
    const double d = std::abs((candidate->header.stamp - stamp).toSec());
    if (d < best)
    {
      best = d;
      imu = candidate;
    }
  }
  if (!imu)
  {
    // Degraded mode: the encoders alone carry the twist; the sample goes on without the IMU
    // (imu_ok false, IMU fields zero) and the node masks the IMU channels (Pi_y = 0).
    ++drops_[static_cast<int>(DropReason::kNoImu)];
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: no imu message within "
                                      << config_.imu_max_skew << " s of joint_states stamp " << stamp.toSec()
                                      << ": controlling on the wheel encoders alone ["
                                      << drops_[static_cast<int>(DropReason::kNoImu)] << " such samples so far]");
  }

  double h = 0.0;
  bool first = !has_previous_sample_;
  if (!first)
  {
    h = (stamp - previous_sample_stamp_).toSec();
    if (h < config_.min_sample_interval)
    {
      return drop(DropReason::kTooClose, "interval " + std::to_string(h) + " s");
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

  out->imu_ok = static_cast<bool>(imu);
  out->y(kGyroZ) = imu ? imu->angular_velocity.z : 0.0;
  out->y(kOmegaLeft) = mean[0];
  out->y(kOmegaRight) = mean[1];
  out->y(kAccelX) = imu ? imu->linear_acceleration.x : 0.0;
  out->y(kAccelY) = imu ? imu->linear_acceleration.y : 0.0;
  out->h = h;
  out->first = first;
  out->stamp = stamp;
  return true;
}

}  // namespace jackal_aic
