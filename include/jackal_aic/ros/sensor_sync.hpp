#pragma once
/**
 * \file sensor_sync.hpp
 * \brief Validation of /joint_states and /imu/data and their pairing into one sensor
 *        sample y = (gyro z, omega_L, omega_R, accel x, accel y) with one interval h.
 *
 * Synchronization policy (the Jackal's two streams are both 50 Hz but not
 * hardware-synchronized): /joint_states drives sampling. When a valid JointState
 * arrives, it is paired with the valid Imu message, among those already received
 * (message_filters::Cache), whose stamp is closest to the JointState's stamp, provided
 * |stamp difference| <= imu_max_skew; otherwise the sample is used without the IMU
 * (SensorSample::imu_ok false, counted as kNoImu): the wheel encoders alone carry the twist
 * (degraded mode, doc/jackal_aic_node.md, 'Degraded modes').
 * The sample's stamp is the JointState stamp and h is the difference between the stamps
 * of two consecutive accepted samples. No message is waited for, so pairing adds no
 * latency to the wheel speeds (the IMU is at most one IMU period old).
 * A gap longer than `max_gap` (the sensor timeout) starts a new sample history (the next
 * sample is a first sample and the generalizer restarts).
 */

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <message_filters/cache.h>
#include <ros/time.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "jackal_aic/node_params.hpp"
#include "jackal_aic/types.hpp"


namespace jackal_aic
{
/// One synchronized sensor sample.
struct SensorSample
{
  Vector5 y = Vector5::Zero();  ///< (gyro z [rad/s], omega_L [rad/s], omega_R [rad/s], accel x, y [m/s^2])
  double h = 0.0;               ///< interval since the previous accepted sample [s]; 0 if first
  bool first = true;            ///< true: no usable previous sample (start or after a gap)
  /// false: no valid Imu within imu_max_skew (missing or stale IMU); gyro and accel fields are then 0
  /// and must not be used (the node masks those channels: Pi_y = 0, degraded mode).
  bool imu_ok = true;
  ros::Time stamp;              ///< JointState stamp
};

/// Why an input was dropped (index into SensorSynchronizer::dropCounts()).
enum class DropReason : int
{
  kJointNames = 0,    ///< a configured joint missing from JointState.name
  kJointArrays,       ///< velocity size != name size, or position/effort neither empty nor name size
  kJointNonFinite,    ///< NaN/Inf in position, velocity or effort of a configured joint
  kJointStamp,        ///< zero stamp, or not newer than the previous valid JointState
  kImuNonFinite,      ///< NaN/Inf in angular_velocity or linear_acceleration
  kImuStamp,          ///< zero stamp, or not newer than the previous valid Imu
  kNoImu,             ///< no valid Imu within imu_max_skew of the JointState: not a drop, the sample goes on
                      ///< without the IMU (SensorSample::imu_ok false); counted here
  kTooClose,          ///< sample closer than min_sample_interval to the previous one
  kCount
};

/// Human-readable name of a drop reason, e.g. "unknown or missing joint name".
const char* toString(DropReason reason);

/**
 * \brief Validates the two sensor streams and pairs them into samples (policy above).
 *
 * Joints are looked up by name in every message (never by index); omega_L is the mean
 * velocity of `left_joints`, omega_R of `right_joints`. Every dropped message is counted
 * per reason and reported with a throttled warning. Not thread-safe (call from one thread).
 */
class SensorSynchronizer
{
public:
  /// Configuration (from NodeParams).
  struct Config
  {
    std::vector<std::string> left_joints;   ///< non-empty
    std::vector<std::string> right_joints;  ///< non-empty
    double imu_max_skew = 0.025;            ///< [s], > 0
    double min_sample_interval = 0.005;     ///< [s], >= 0
    double max_gap = 0.25;                  ///< [s], > 0: longer gaps restart the history

    /// The node's keys: left_joints, right_joints, imu_max_skew, min_sample_interval, and
    /// sensor_timeout as max_gap.
    static Config fromParams(const NodeParams& params);
  };

  /// \param config  joint names and limits; not checked here (NodeParams::validate() does that).
  explicit SensorSynchronizer(const Config& config);
  /// Replace the configuration (dynamic_reconfigure); history, IMU cache and counters are kept.
  void setConfig(const Config& config);

  /// Validate an Imu message; keep it for pairing. \return false if dropped.
  bool addImu(const sensor_msgs::Imu::ConstPtr& msg);

  /**
   * \brief Validate a JointState and pair it with an Imu into a sample.
   * \param out  filled on success
   * \return false if dropped (reason counted, warning throttled)
   */
  bool addJointState(const sensor_msgs::JointState::ConstPtr& msg, SensorSample* out);

  /**
   * \brief Forget the sample history: the next sample is a first sample, the stamp order
   *        checks start afresh and the IMU cache is emptied; counters are kept.
   *
   * Called when the sensors went stale, so that one message with a stamp far in the
   * future (which makes every later message look "backwards") blocks the streams only
   * until the sensor timeout, not for ever.
   */
  void restartHistory();

  /// Dropped inputs per DropReason since construction.
  const std::array<std::uint64_t, static_cast<int>(DropReason::kCount)>& dropCounts() const { return drops_; }
  /// Samples returned by addJointState() since construction.
  std::uint64_t acceptedSamples() const { return accepted_; }

private:
  bool drop(DropReason reason, const std::string& detail);

  Config config_;
  std::unique_ptr<message_filters::Cache<sensor_msgs::Imu>> imu_cache_;
  ros::Time last_imu_stamp_;
  ros::Time last_joint_stamp_;
  ros::Time previous_sample_stamp_;
  bool has_previous_sample_ = false;
  std::array<std::uint64_t, static_cast<int>(DropReason::kCount)> drops_{};
  std::uint64_t accepted_ = 0;
};

}  // namespace jackal_aic
