#pragma once
/**
 * \file fault_monitor.hpp
 * \brief Sensor fault detection and isolation (FDI) from precision-weighted sensory prediction
 *        errors, after Baioumy, Pezzato, Ferrari, Hernandez Corbato & Hawes, "Fault-tolerant
 *        control of robot manipulators with sensory faults using unbiased active inference",
 *        ECC 2021 (arXiv 2104.01817): a residual built from the sensory prediction errors is
 *        compared with a threshold; a faulty sensor is isolated by setting its precision Pi_y to
 *        zero, so the beliefs (and the action, thesis eq. 3-16) come from the healthy channels.
 *        doc/active_inference.md, 'Fault detection and isolation'. ROS-free, no heap, no exceptions
 *        on the update path.
 */

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/params/fdi_params.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace safety
{
/**
 * \brief Detects and isolates one faulty channel among gyro z, omega_L, omega_R.
 *
 * The three channels observe two twist components (x_dot, theta_dot; the sensor model R of thesis
 * eq. 3-4 has no y_dot column), so they carry one redundancy. Leaving channel j out, the other two
 * give a twist x_hat_{-j} exactly, and channel j's prediction error against it,
 * e_j = y_j - R_j x_hat_{-j}, is the sensory prediction error of an unbiased belief (one not pulled
 * towards the goal, as in the paper's unbiased active inference): zero for healthy, noise-free
 * sensors whatever the goal or the transient. All three e_j are the same residual up to scale,
 *
 *     r = y_gyro - (r alpha / b_hat) (y_omega_R - y_omega_L)      [rad/s],
 *
 * and its precision-weighted square s = Pi_r r^2, with Pi_r = 1 / (sigma^2_gyro + (r alpha / b_hat)^2
 * (sigma^2_L + sigma^2_R)) from var_y of order 0, is the detection test: s > threshold for
 * detect_time declares a fault (the paper's residual-against-threshold test on precision-weighted
 * prediction errors).
 *
 * One residual detects but cannot by itself say which channel failed. The isolated channel is the
 * one under whose exclusion the remaining two agree best with the beliefs mu^(0): argmin_j of
 * (x_hat_{-j} - mu^(0))^T Pi_mu^(0) (x_hat_{-j} - mu^(0)) (the sensory-prior free energy of the
 * hypothesis "channel j is faulty", thesis eq. 3-10 with Pi_y,j = 0), accumulated over the detection
 * window. A set-point step moves all channels together (r stays ~0) and so is no fault.
 *
 * With the robot model the residual and its variance are the model's own (update(SampleInnovation,
 * h): the innovation test, kInnovationThreshold).
 *
 * Hysteresis: an isolated channel is restored once s < release_ratio * threshold for release_time
 * (it agrees with the others again). At most one channel is isolated at a time (with two channels
 * left there is no redundancy to test). While the IMU is missing (setImuAvailable(false)) the test
 * pauses and the gyro and accelerometer channels are masked.
 */
class FaultMonitor
{
public:
  /// What an update() changed.
  enum class Event
  {
    kNone,      ///< nothing changed
    kIsolated,  ///< a channel was isolated (see isolatedChannel())
    kRestored,  ///< the isolated channel was restored
    kDetected   ///< a fault was confirmed while isolation is off (params.enabled false); nothing masked
  };

  /// Monitored channels, in SensorIndex order.
  static constexpr std::array<int, 3> kChannels{ base::kGyroZ, base::kOmegaLeft, base::kOmegaRight };

  /**
   * \param fdi  detection parameters
   * \param aic  controller parameters (r, alpha, b_hat, var_y, var_mu are used)
   * \throws std::invalid_argument listing the violations if fdi or aic are invalid.
   */
  FaultMonitor(const params::FdiParams& fdi, const params::AicParams& aic);

  /// Replace the parameters (state kept). \throws std::invalid_argument (state unchanged) if invalid.
  void setParams(const params::FdiParams& fdi, const params::AicParams& aic);
  const params::FdiParams& params() const { return fdi_; }

  /**
   * \brief Test one synchronized sample.
   * \param y    sensor sample y^(0) (gyro z [rad/s], omega_L, omega_R [rad/s], accel x, y [m/s^2])
   * \param mu0  beliefs mu^(0) (x_dot [m/s], y_dot [m/s], theta_dot [rad/s])
   * \param h    time since the previous sample [s]; a non-finite or negative h (or a non-finite y or mu0)
   *             is ignored: state kept, kNone, counted in ignoredSamples()
   * \return the event this sample caused.
   */
  Event update(const base::Vector5& y, const base::Vector3& mu0, double h);

  /**
   * \brief Test one synchronized sample against a generative model's prediction of it: the
   *        innovation test of the robot model (doc/active_inference.md, 'Fault detection and
   *        isolation'). The residual r is the innovations' parity (base::SampleInnovation: the
   *        gyro's prediction error less the yaw the wheels' prediction errors imply, which a change
   *        of the body's motion or of the wheels' load moves on all three channels alike), and the
   *        statistic s = r^2 / Var(r), Var(r) from the sensors' noise and the model's own
   *        uncertainty: chi^2 with one degree of freedom for healthy sensors, tested against
   *        kInnovationThreshold (fdi_threshold is the thesis's models' threshold on their
   *        precision-weighted parity residual, Pi_r from var_y). The isolated channel is the one
   *        whose exclusion leaves the other two closest to the model's prediction, argmin_j of
   *        sum_{i != j} eps_i^2 / Var(eps_i), accumulated over the detection window; detection time,
   *        release and hysteresis as update(y, mu0, h), the release level fdi_release_ratio x
   *        kInnovationThreshold.
   * \param model  the sample's innovations (aic::RobotBelief::sampleInnovation())
   * \param h      time since the previous sample [s]; a non-finite or negative h, a non-finite error
   *               or a variance that is not finite and > 0 is ignored as in update(y, mu0, h)
   * \return the event this sample caused.
   */
  Event update(const base::SampleInnovation& model, double h);

  /// The innovation test's threshold on s = r^2 / Var(r): 5 standard deviations of the model's
  /// parity (for chi^2 with one degree of freedom a sample beyond it about once in 1.7e6; where the
  /// model is approximate, a brisk set-point change, single healthy samples exceed it, so a fault
  /// is samples beyond it for fdi_detect_time).
  static constexpr double kInnovationThreshold = 25.0;

  /**
   * \brief Use the wheel separation b_hat [m] of the controller's generative model (learned,
   *        ActiveInferenceController::separationLearner()) in the residual r = y_gyro - r alpha
   *        (omega_R - omega_L) / b_hat, its precision and the channel reconstructions, so that a
   *        model error the learning removed is not a fault. State kept; no allocation.
   * \return false (unchanged) unless b is finite and > 0.
   */
  bool setWheelSeparation(double b);

  /// The IMU (gyro and accelerometer) is present (true) or missing/stale (false): masks those channels.
  void setImuAvailable(bool available);
  bool imuAvailable() const { return imu_available_; }

  /// Forget the test's timers and the isolation (e.g. after the sensors went stale).
  void reset();

  /**
   * \brief Channel mask for ActiveInferenceController::setSensorMask(): bit j set = channel j used.
   * Cleared: the isolated channel (if isolation is enabled) and, without the IMU, gyro z, accel x, accel y.
   */
  std::uint8_t sensorMask() const;
  /// The isolated channel (SensorIndex), or -1.
  int isolatedChannel() const { return isolated_; }
  /// The channel the last confirmed detection found faulty (isolated or, with isolation off, only
  /// reported), or -1 before one.
  int suspectedChannel() const { return suspected_; }
  /// The last residual r [rad/s] and its precision-weighted square s [-] (NaN before the first test).
  double residual() const { return residual_; }
  double statistic() const { return statistic_; }
  /// The threshold the last test used [-]: fdi_threshold (update(y, mu0, h)) or kInnovationThreshold
  /// (update(model, h)); fdi_threshold before the first test.
  double threshold() const { return threshold_; }
  /// True while s is above the threshold (a fault is suspected or confirmed).
  bool faultPresent() const { return above_for_ >= 0.0; }
  /// True while s is above the threshold but the fault is not yet confirmed (no channel isolated,
  /// none detected for this excursion): the samples' channels disagree and which one is wrong is
  /// still being tested.
  bool awaitingConfirmation() const { return above_for_ >= 0.0 && !confirmed_ && isolated_ < 0; }
  /// Number of isolations, restorations and detections (with isolation off) since construction.
  std::uint64_t isolations() const { return isolations_; }
  std::uint64_t restorations() const { return restorations_; }
  std::uint64_t detections() const { return detections_; }
  std::uint64_t ignoredSamples() const { return ignored_; }
  /// Time from the first sample above the threshold to the last isolation [s] (NaN before one).
  double lastDetectionDelay() const { return last_delay_; }

  /// Twist (x_dot [m/s], 0, theta_dot [rad/s]) given by the two channels other than `excluded` (SensorIndex).
  base::Vector3 twistWithout(int excluded, const base::Vector5& y) const;

  /// "gyro_z", "omega_left", ... for a SensorIndex; "none" for -1.
  static const char* channelName(int channel);

private:
  /// The detection, isolation and restoration logic on one sample's residual [rad/s], its
  /// statistic s and threshold [-] over h [s]; cost(k) [-] is hypothesis k's (kChannels index)
  /// cost for this sample, called only while s is above the threshold; an isolated channel is
  /// restored on release_statistic [-] (NaN: s itself) below the release level (defined and used
  /// in fault_monitor.cpp only).
  template <class Cost>
  Event test(double residual, double statistic, double threshold, const Cost& cost, double h,
             double release_statistic = std::numeric_limits<double>::quiet_NaN());

  params::FdiParams fdi_;
  double c_ = 0.0;                    ///< r alpha / b_hat [-]
  double r_alpha_ = 0.0;              ///< r alpha [m]
  double half_b_ = 0.0;               ///< b_hat / 2 [m]
  double pi_r_ = 0.0;                 ///< precision of the residual [s^2/rad^2]
  double var_gyro_ = 0.0;             ///< sigma^2 of the gyro, order 0 [rad^2/s^2]
  double var_wheels_ = 0.0;           ///< sigma^2_L + sigma^2_R of the wheels, order 0 [rad^2/s^2]
  double pi_vx_ = 0.0, pi_wz_ = 0.0;  ///< Pi_mu^(0) of x_dot and theta_dot
  bool imu_available_ = true;
  int isolated_ = -1;
  int suspected_ = -1;
  double above_for_ = -1.0;                  ///< time s has been above the threshold [s]; -1 = below
  double below_for_ = 0.0;                   ///< time s has been below the release level while isolated [s]
  std::array<double, 3> hypothesis_cost_{};  ///< accumulated cost per channel over the detection window
  bool confirmed_ = false;                   ///< a detection was confirmed for the current excursion
  double residual_, statistic_;
  double threshold_ = 0.0;  ///< the last test's threshold [-]
  double last_delay_;
  std::uint64_t isolations_ = 0, restorations_ = 0, detections_ = 0, ignored_ = 0;
};

/// "none", "isolated", "restored", "detected".
const char* toString(FaultMonitor::Event event);

}  // namespace safety
}  // namespace jackal_aic
