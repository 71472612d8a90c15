#pragma once
/**
 * \file gyro_bias_estimator.hpp
 * \brief Learning the gyro's offset beta_hat at standstill (zero angular-rate update): the
 *        generative model's sensor row y_gyro = theta_dot + beta with theta_dot = 0 known while the
 *        wheels stand still. ROS-free. doc/active_inference.md, 'Learning the gyro's offset'.
 */

#include <cstdint>
#include <string>

#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Posterior mean of the gyro's offset from the readings taken while the robot stands still.
 *
 * A skid-steer robot whose wheels stand still does not turn, so at rest the gyro's reading is its
 * offset plus noise: y_gyro = beta + w. With the free energy F_beta = Pi_gyro (y_gyro - beta_hat)^2 / 2
 * summed over the rest samples and a prior of kPriorSamples samples centred on 0, its minimum is
 * the running mean
 *   beta_hat <- beta_hat + k (y_gyro - beta_hat),   k = max(1 / (n + kPriorSamples), h / T_beta),
 * n the number of rest samples learned from: the first standstill is averaged (the offset a MEMS
 * gyro has at power-on, typically 0.005-0.05 rad/s), later ones follow a slow drift (temperature)
 * with the time constant T_beta. beta_hat is clamped to +-max_bias. offset() is beta_hat once min_rest
 * seconds of rest have been learned from (before that the average of a short rest is mostly the
 * gyro's noise and the body's settling, 1e-3 rad/s after 1 s; until then it is 0). The caller subtracts
 * offset() from every gyro sample before the beliefs, the fault monitor and the separation learner
 * see it (SamplePipeline): otherwise the separation learner reads a 0.03 rad/s offset as a 6 % error of
 * the wheel separation in a 0.5 rad/s arc, of opposite sign in left and right turns.
 *
 * Rest: both wheels' measured |speed| and both wheel commands' |speed| below rest_speed, for
 * rest_time (the body's yaw settles after the wheels stop). Frozen (not moved) while moving, in
 * the first rest_time of a rest, while the gyro is flagged or the IMU is missing (gyro_ok false),
 * and while |y_gyro| > max_bias (the robot is being turned by hand, or a fault the fault monitor will
 * isolate: not an offset).
 *
 * No heap allocation, no exceptions after construction.
 */
class GyroBiasEstimator
{
public:
  /// Weight of the prior beta = 0, in samples: the first rest sample moves beta_hat by 1/(1 + this).
  static constexpr double kPriorSamples = 5.0;

  /// Why the last update() did or did not move beta_hat.
  enum class State
  {
    kLearning,     ///< beta_hat moved (or stayed at a bound)
    kMoving,       ///< frozen: a wheel or a command is above rest_speed
    kSettling,     ///< frozen: at rest for less than rest_time
    kSensorFault,  ///< frozen: the gyro is flagged or the IMU is missing
    kImplausible,  ///< frozen: |y_gyro| > max_bias at rest
    kBadInput      ///< ignored: non-finite input or h <= 0
  };

  /// \throws std::invalid_argument naming every violated rule of GyroBiasEstimatorParams.
  explicit GyroBiasEstimator(const params::GyroBiasEstimatorParams& params);

  /**
   * \brief One sensor sample.
   * \param h          time since the previous sample [s], finite and > 0
   * \param gyro_z     the gyro's raw yaw rate y_gyro (offset not removed) [rad/s]
   * \param omega_l    measured left wheel speed [rad/s]
   * \param omega_r    measured right wheel speed [rad/s]
   * \param command_l  left wheel command in force [rad/s]
   * \param command_r  right wheel command in force [rad/s]
   * \param gyro_ok    false while the fault monitor flags the gyro or the IMU is missing
   * \return the reason the sample did or did not move beta_hat.
   */
  State update(double h, double gyro_z, double omega_l, double omega_r, double command_l, double command_r,
               bool gyro_ok);

  /// The learned offset beta_hat [rad/s], within +-max_bias (0 before any rest).
  double bias() const { return bias_; }
  /// The offset to remove from the gyro [rad/s]: bias() once learnedTime() >= min_rest, else 0.
  double offset() const { return learned_time_ >= params_.min_rest ? bias_ : 0.0; }
  /// Rest time learned from so far [s].
  double learnedTime() const { return learned_time_; }
  /// The state of the last update() (kMoving before any).
  State state() const { return state_; }
  /// Number of samples learned from (n).
  std::uint64_t learningSamples() const { return samples_; }
  /// Back to beta_hat = 0, n = 0, nothing learned, not at rest.
  void reset();
  /// The settings in use.
  const params::GyroBiasEstimatorParams& params() const { return params_; }
  /// Replace the settings, keeping beta_hat (clamped to the new bound) and n.
  /// \throws std::invalid_argument as the constructor (the estimator unchanged).
  void setParams(const params::GyroBiasEstimatorParams& params);

private:
  params::GyroBiasEstimatorParams params_;
  double bias_ = 0.0;
  double rest_for_ = 0.0;      ///< time at rest so far [s]
  double learned_time_ = 0.0;  ///< rest time learned from [s]
  State state_ = State::kMoving;
  std::uint64_t samples_ = 0;
};

/// Name of an estimator state, e.g. "settling".
const char* toString(GyroBiasEstimator::State state);

/**
 * \brief The estimator's status line for diagnostics: the state's name, and until offset() is in
 *        use "; not removed yet (<learned> of <min_rest> s of rest learned)", e.g.
 *        "moving; not removed yet (1.2 of 5.0 s of rest learned)". Allocates (not for the belief loop).
 */
std::string statusText(const GyroBiasEstimator& estimator);

}  // namespace aic
}  // namespace jackal_aic
