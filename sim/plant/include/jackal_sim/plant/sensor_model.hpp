#pragma once
/**
 * \file sensor_model.hpp
 * \brief Wheel-encoder and IMU models of the simulated Jackal: sampling at a configured
 *        rate, Gaussian noise, constant bias, delay and dropout, all seeded.
 *
 * ROS-free. Call record() after every plant step; when a stream is due at that step,
 * pollJointStates() / pollImu() return its sample (unless dropped). A sample published at
 * time t carries the plant state of time t - delay (rounded to whole steps), so its stamp
 * (t) is later than the physics it describes, as with a real driver stamping on receipt.
 */

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/plant_params.hpp"

namespace jackal_aic
{
namespace plant
{
/// One wheel-encoder sample (WheelIndex order).
struct JointStateSample
{
  double stamp = 0.0;                         ///< plant time of publication [s]
  std::array<double, kNumWheels> position{};  ///< [rad]
  std::array<double, kNumWheels> velocity{};  ///< [rad/s]
};

/// One IMU sample in the IMU frame.
struct ImuSample
{
  double stamp = 0.0;                                               ///< plant time of publication [s]
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< IMU frame in odom
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       ///< [rad/s]
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();    ///< specific force [m/s^2]
};

/// Samples the plant's sensors (see file comment).
class SensorModel
{
public:
  /// \param params validated sensor parameters
  /// \param step   plant step [s], > 0; periods and delays are rounded to whole steps
  SensorModel(const SensorParams& params, double step);

  /// Record the plant's state after a step (needed every step for the delay line).
  void record(const Plant& plant);

  /// True and *out filled if a joint-state sample is published at the last recorded step.
  bool pollJointStates(JointStateSample* out);
  /// True and *out filled if an IMU sample is published at the last recorded step.
  bool pollImu(ImuSample* out);

  /// Joint-state period in steps.
  std::uint64_t jointStatePeriodSteps() const { return js_period_; }
  /// IMU period in steps.
  std::uint64_t imuPeriodSteps() const { return imu_period_; }
  /// Samples dropped so far (joint states, IMU).
  std::uint64_t droppedJointStates() const { return js_dropped_; }
  std::uint64_t droppedImu() const { return imu_dropped_; }

private:
  struct Raw
  {
    std::array<double, kNumWheels> position{};
    std::array<double, kNumWheels> velocity{};
    ImuTruth imu;
  };
  const Raw& delayed(std::uint64_t delay_steps) const;

  SensorParams params_;
  double step_;
  std::uint64_t js_period_;
  std::uint64_t imu_period_;
  std::uint64_t js_delay_;
  std::uint64_t imu_delay_;
  std::vector<Raw> ring_;
  std::size_t head_ = 0;
  std::uint64_t recorded_ = 0;
  std::uint64_t step_count_ = 0;
  double time_ = 0.0;
  std::mt19937 js_rng_;
  std::mt19937 imu_rng_;
  std::normal_distribution<double> normal_{ 0.0, 1.0 };
  std::uniform_real_distribution<double> uniform_{ 0.0, 1.0 };
  std::uint64_t js_dropped_ = 0;
  std::uint64_t imu_dropped_ = 0;
};

}  // namespace plant
}  // namespace jackal_aic
