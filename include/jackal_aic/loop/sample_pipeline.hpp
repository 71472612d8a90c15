#pragma once
/**
 * \file sample_pipeline.hpp
 * \brief The ROS-free path of one synchronized sensor sample through the controller:
 *        degraded-mode fill, finite-difference generalization, the controller's measurement,
 *        fault detection and isolation (doc/jackal_aic_node.md, 'Sensors', 'Fault detection
 *        and isolation'; doc/active_inference.md).
 */
#include <memory>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"
#include "jackal_aic/aic/generalizer.hpp"
#include "jackal_aic/aic/gyro_bias_estimator.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/safety/tip_guard.hpp"
#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace loop
{
/**
 * \brief Owns the controller, the generalizer, the fault monitor, the gyro's offset estimators
 *        and the tip-over guard of the jackal_AIC node and carries a sample through them in the
 *        node's order. Not thread-safe: the node calls it under its lock. No allocation on the
 *        per-sample path.
 *
 * Per sample: generalize() (always: the history must stay continuous while the node waits;
 * with learn_gyro_bias the learned offset beta_hat is subtracted from the gyro first), then
 * guardTip() (always: the tip-over guard's pitch stays current; with tip_guard its bounds go into
 * the controller's reference path), then, only while the node runs, measure() (the controller's
 * y_tilde, then the FDI test; doc/active_inference.md, 'Fault detection and isolation', after
 * Baioumy et al., ECC 2021; the offset estimator then learns from the sample).
 */
class SamplePipeline
{
public:
  /**
   * \param aic  controller parameters (AicParams::validate() must pass)
   * \param fdi  fault detection parameters (FdiParams::validate() must pass)
   * \throws std::invalid_argument  if either is invalid (message lists every violation)
   */
  SamplePipeline(const params::AicParams& aic, const params::FdiParams& fdi);

  /**
   * \brief Generalize one sample (thesis eqs. 3-17 ... 3-22).
   * \param y        (gyro z, omega_L, omega_R, accel x, accel y) [rad/s, rad/s, rad/s, m/s^2, m/s^2];
   *                 modified: with learn_gyro_bias the gyro slot is y_gyro - beta_hat; without the
   *                 IMU (imu_ok false) it gets the wheels' yaw rate (r alpha / b_hat)(omega_R -
   *                 omega_L), so its generalized orders stay smooth for when the IMU returns (the
   *                 channel itself is masked, Pi_y = 0)
   * \param h        interval since the previous sample [s] (ignored on a first sample)
   * \param imu_ok   the sample has a paired IMU message
   * \param restart  the sample starts a new history (after a gap); so does an uninitialized
   *                 generalizer. *restarted tells the caller which happened.
   * \param restarted  out (may be null): true if the history was restarted
   * \return the generalizer's status: kOk or kFirstSample = accepted; anything else = the sample
   *         was refused and the state is unchanged
   */
  aic::Generalizer::Status generalize(base::Vector5* y, double h, bool imu_ok, bool restart, bool* restarted = nullptr);

  /// What measure() found.
  struct Measurement
  {
    bool accepted = false;                                                   ///< the controller took y_tilde
    safety::FaultMonitor::Event event = safety::FaultMonitor::Event::kNone;  ///< FDI event of this sample
    int event_channel = -1;  ///< the channel of the event (restored: the one released), else -1
  };
  /**
   * \brief Give the controller the newest generalized measurement, then run the FDI test on
   *        the sample (y as generalize() left it, its interval h [s], imu_ok) against the
   *        belief mu^(0) and set the controller's channel mask (Pi_y = 0 for isolated or
   *        missing channels), so a channel isolated now is out of the next action step. With
   *        learn_gyro_bias the offset estimator then takes the sample's raw gyro reading, the wheels
   *        and the controller's action (it learns only at standstill with a healthy gyro).
   *        wheels_repeated: the joint state repeated the previous one exactly
   *        (ActiveInferenceController::setMeasurement()).
   */
  Measurement measure(const base::Vector5& y, double h, bool imu_ok, bool wheels_repeated = false);

  /// Forget the sensor history (sensors were lost): generalizer and fault monitor restart.
  void restartHistory();

  /**
   * \brief (Re)start control bumplessly: reset the controller, set the goal mu_d [m/s, m/s,
   *        rad/s] and the newest y_tilde, the action to the measured wheel speeds [rad/s], and the
   *        beliefs to the measured twist (mu^(0) = G omega, higher orders zero).
   */
  void activate(const base::Vector2& wheels, const base::Vector3& goal);

  /**
   * \brief Apply new parameters between steps. A changed embedding order builds a new
   *        generalizer (the history restarts: returns true).
   * \throws std::invalid_argument  if either set is invalid; nothing is changed then
   */
  bool setParams(const params::AicParams& aic, const params::FdiParams& fdi);

  /// The controller (beliefs mu, action a, goal mu_d; thesis eqs. 3-15, 3-16): the node's belief
  /// and action steps run on it directly.
  aic::ActiveInferenceController& controller() { return *controller_; }
  const aic::ActiveInferenceController& controller() const { return *controller_; }
  /// The fault monitor (channel health for diagnostics; its mask is applied by measure()).
  safety::FaultMonitor& faultMonitor() { return *fault_monitor_; }
  /// \copydoc faultMonitor()
  const safety::FaultMonitor& faultMonitor() const { return *fault_monitor_; }
  /// The gyro's offset estimator (beta_hat [rad/s]; learns with learn_gyro_bias).
  const aic::GyroBiasEstimator& gyroBias() const { return gyro_bias_; }
  /// Forget the learned gyro offset (beta_hat = 0).
  void resetGyroBias() { gyro_bias_.reset(); }
  /**
   * \brief One sample into the tip-over guard (TipGuard) and, with tip_guard, its bounds into the
   *        controller's reference path (ActiveInferenceController::setTipBounds; none without) and
   *        its turned-over state into the controller's command (setTurnedOver: zero while the body
   *        has turned over). With learn_gyro_bias the gyro y's offset is learned at rest as the gyro z's is (a second
   *        GyroBiasEstimator) and removed from the pitch rate first.
   * \param y           the sample (its wheel speeds; SensorSample::y)
   * \param pitch_rate  the IMU's gyro y [rad/s] (SensorSample::pitch_rate)
   * \param h           interval since the previous sample [s]; a first sample (h <= 0) is skipped
   * \param imu_ok      false without a valid IMU sample (the guard's pitch decays)
   * \param up_force    the IMU's specific force along the body's z [m/s^2] (SensorSample::up_force;
   *                    default: level), which tells the guard a robot lies on its back
   */
  void guardTip(const base::Vector5& y, double pitch_rate, double h, bool imu_ok,
                double up_force = safety::TipGuard::kGravity);
  /// The tip-over guard (its pitch, learned bounds and trips).
  const safety::TipGuard& tipGuard() const { return tip_guard_; }
  /// Forget the tip-over guard's learned bounds and pitch, and the gyro y's offset.
  void resetTipGuard();
  /// The gyro y's offset estimator (learned with learn_gyro_bias; the tip-over guard's pitch rate).
  const aic::GyroBiasEstimator& pitchBias() const { return pitch_bias_; }
  /// The generalizer: y_tilde, 5 x (p+1), of the newest accepted sample.
  const aic::Generalizer& generalizer() const { return *generalizer_; }

private:
  std::unique_ptr<aic::ActiveInferenceController> controller_;
  std::unique_ptr<aic::Generalizer> generalizer_;
  std::unique_ptr<safety::FaultMonitor> fault_monitor_;
  aic::GyroBiasEstimator gyro_bias_;
  safety::TipGuard tip_guard_;
  aic::GyroBiasEstimator pitch_bias_;
  double raw_gyro_ = 0.0;        ///< the gyro's reading of the newest generalized sample, offset not removed [rad/s]
  double removed_offset_ = 0.0;  ///< the offset removed from the gyro's newest reading the controller got [rad/s]
};
}  // namespace loop
}  // namespace jackal_aic
