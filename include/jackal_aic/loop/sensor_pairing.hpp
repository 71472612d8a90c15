#pragma once
/**
 * \file sensor_pairing.hpp
 * \brief Validation of the wheel-encoder (joint state) and IMU streams and their pairing into
 *        one sensor sample y = (gyro z, omega_L, omega_R, accel x, accel y) with one interval h.
 *        ROS-free: the node passes the fields of sensor_msgs/JointState and sensor_msgs/Imu,
 *        the simulator those of its sensor model (doc/jackal_aic_node.md, 'Sensor
 *        synchronization').
 *
 * Policy (the Jackal's two streams are both 50 Hz but not hardware-synchronized): the joint
 * state drives sampling. A valid joint state is paired with the valid IMU sample, among the
 * last kImuHistory received, whose stamp is closest to the joint state's, provided
 * |stamp difference| <= imu_max_skew; otherwise the sample goes on without the IMU
 * (SensorSample::imu_ok false, counted as kNoImu): the wheel encoders alone carry the twist
 * (degraded mode, doc/jackal_aic_node.md, 'Degraded modes'). The sample's stamp is the joint
 * state's and h is the difference between the stamps of two consecutive accepted samples.
 * Nothing waits for a later message, so pairing adds no latency to the wheel speeds. A gap
 * longer than `max_gap` (the sensor timeout) starts a new sample history.
 */

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace loop
{
/// One synchronized sensor sample.
struct SensorSample
{
  base::Vector5 y = base::Vector5::Zero();  ///< (gyro z [rad/s], omega_L [rad/s], omega_R [rad/s], accel x, y [m/s^2])
  double h = 0.0;                           ///< interval since the previous accepted sample [s]; 0 if first
  bool first = true;                        ///< true: no usable previous sample (start or after a gap)
  /// false: no valid IMU sample within imu_max_skew (missing or stale IMU); gyro and accel
  /// fields are then 0 and must not be used (the channels are masked: Pi_y = 0, degraded mode).
  bool imu_ok = true;
  double stamp = 0.0;  ///< the joint state's stamp [s] (the caller's epoch)
  /// The paired IMU's gyro y [rad/s]: the body's pitch rate q (REP 103, base_link: > 0 noses
  /// down), read by the TipGuard, not by the beliefs; 0 when imu_ok is false.
  double pitch_rate = 0.0;
  /// The paired IMU's specific force along the body's z axis (linear_acceleration.z) [m/s^2]: +g
  /// level at rest, -g on its back; read by the TipGuard (turnedOver()); 0 when imu_ok is false.
  double up_force = 0.0;
  /// The joint state's wheel travel (mean position of left_joints, of right_joints) [rad]; zero
  /// when the message has no positions (has_travel false). Read by FrozenJointStates.
  base::Vector2 travel = base::Vector2::Zero();
  bool has_travel = false;  ///< the message carried positions
};

/// One joint-state message, by reference to its arrays (sensor_msgs/JointState's fields).
struct JointStateInput
{
  /// Header stamp [s] in the caller's epoch; NaN for an unset stamp (a zero ROS stamp).
  double stamp = 0.0;
  const std::vector<std::string>* name = nullptr;  ///< joint names; required
  const std::vector<double>* position = nullptr;   ///< [rad]: empty or one per name; null = empty
  const std::vector<double>* velocity = nullptr;   ///< [rad/s]: one per name; required
  const std::vector<double>* effort = nullptr;     ///< [N m]: empty or one per name; null = empty
};

/// One IMU message (sensor_msgs/Imu's fields that the controller uses or checks).
struct ImuInput
{
  /// Header stamp [s] in the caller's epoch; NaN for an unset stamp (a zero ROS stamp).
  double stamp = 0.0;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     ///< [rad/s]
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< specific force [m/s^2]
};

/// Why an input was dropped (index into SensorPairing::dropCounts()).
enum class DropReason : int
{
  kJointNames = 0,  ///< a configured joint missing from the joint state's names
  kJointArrays,     ///< velocity size != name size, or position/effort neither empty nor name size
  kJointNonFinite,  ///< NaN/Inf in position, velocity or effort of a configured joint
  kJointStamp,      ///< unset stamp, or not newer than the previous valid joint state
  kImuNonFinite,    ///< NaN/Inf in angular_velocity or linear_acceleration
  kImuStamp,        ///< unset stamp, or not newer than the previous valid IMU sample
  kNoImu,           ///< no valid IMU sample within imu_max_skew of the joint state: not a drop, the
                    ///< sample goes on without the IMU (SensorSample::imu_ok false); counted here
  kTooClose,        ///< sample closer than min_sample_interval to the previous one
  kCount
};

/// Human-readable name of a drop reason, e.g. "joint_states: unknown or missing joint name".
const char* toString(DropReason reason);

/**
 * \brief Validates the two sensor streams and pairs them into samples (policy in the file
 *        comment). Joints are looked up by name in every message (never by index); omega_L is
 *        the mean velocity of `left_joints`, omega_R of `right_joints`. Every dropped input is
 *        counted per reason. Not thread-safe; no allocation after construction except in the
 *        text of a drop's reason.
 */
class SensorPairing
{
public:
  /// IMU samples kept for pairing (0.4 s at 50 Hz).
  static constexpr std::size_t kImuHistory = 20;

  /// Configuration (the node's keys left_joints, right_joints, imu_max_skew,
  /// min_sample_interval, and sensor_timeout as max_gap).
  struct Config
  {
    std::vector<std::string> left_joints;   ///< non-empty
    std::vector<std::string> right_joints;  ///< non-empty
    double imu_max_skew = 0.025;            ///< [s], > 0
    double min_sample_interval = 0.005;     ///< [s], >= 0
    double max_gap = 0.25;                  ///< [s], > 0: longer gaps restart the history
  };

  /// \param config  joint names and limits; not checked here (NodeParams::validate() does that).
  explicit SensorPairing(const Config& config);
  /// Replace the configuration (a parameter change); history, IMU samples and counters are kept.
  void setConfig(const Config& config) { config_ = config; }
  /// The configuration in force.
  const Config& config() const { return config_; }

  /**
   * \brief Validate an IMU sample and keep it for pairing.
   * \param why  out (may be null): on a drop, what was wrong
   * \return false if dropped (counted)
   */
  bool addImu(const ImuInput& imu, std::string* why = nullptr);

  /**
   * \brief Validate a joint state and pair it with an IMU sample into a sample.
   * \param out  filled on success (imu_ok false: no IMU within imu_max_skew, counted as kNoImu)
   * \param why  out (may be null): on a drop, what was wrong
   * \return false if dropped (counted; *reason says why)
   */
  bool addJointState(const JointStateInput& joints, SensorSample* out, DropReason* reason = nullptr,
                     std::string* why = nullptr);

  /**
   * \brief Forget the sample history: the next sample is a first sample, the stamp order
   *        checks start afresh and the IMU samples are forgotten; counters are kept.
   *
   * Called when the sensors went stale, so that one message with a stamp far in the future
   * (which makes every later message look "backwards") blocks the streams only until the
   * sensor timeout, not for ever.
   */
  void restartHistory();

  /// Dropped inputs per DropReason since construction.
  const std::array<std::uint64_t, static_cast<int>(DropReason::kCount)>& dropCounts() const { return drops_; }
  /// Dropped inputs of one reason since construction.
  std::uint64_t drops(DropReason reason) const { return drops_[static_cast<std::size_t>(reason)]; }
  /// Samples returned by addJointState() since construction.
  std::uint64_t acceptedSamples() const { return accepted_; }

private:
  struct ImuEntry
  {
    double stamp;
    double gyro_z;
    double gyro_y;
    double accel_x;
    double accel_y;
    double accel_z;
  };
  bool drop(DropReason reason, DropReason* out, std::string* why, const std::string& detail);

  Config config_;
  std::array<ImuEntry, kImuHistory> imu_{};
  std::size_t imu_count_ = 0;  ///< valid entries in imu_ (at most kImuHistory)
  std::size_t imu_next_ = 0;   ///< where the next IMU sample goes
  bool has_imu_stamp_ = false, has_joint_stamp_ = false, has_previous_sample_ = false;
  double last_imu_stamp_ = 0.0;
  double last_joint_stamp_ = 0.0;
  double previous_sample_stamp_ = 0.0;
  std::array<std::uint64_t, static_cast<int>(DropReason::kCount)> drops_{};
  std::uint64_t accepted_ = 0;
};

}  // namespace loop
}  // namespace jackal_aic
