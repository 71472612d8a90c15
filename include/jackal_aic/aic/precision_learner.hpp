#pragma once
/**
 * \file precision_learner.hpp
 * \brief Learning the sensory precisions Pi_y^(0) of the generative model from the sensory
 *        prediction errors the controller sees: d ln Pi_j / dt = -kappa_pi dF / d ln Pi_j
 *        (precision learning as free-energy descent: Baioumy, Duckworth, Lacerda & Hawes,
 *        arXiv 2005.05894; doc/active_inference.md, 'Learning the sensory precisions').
 *        ROS-free.
 */

#include <array>
#include <cstdint>

#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace params
{
struct AicParams;
}

namespace aic
{

/// What a PrecisionLearner learns: the configured precisions it starts from and the channels it
/// learns (the controller's: precisionChannels()).
struct PrecisionChannels
{
  /// Configured precisions Pi_y^(0) per channel (SensorIndex) [1/(channel unit)^2], each finite and > 0;
  /// the learning starts from them and the bounds are factors of them.
  std::array<double, base::kYDim> configured{ { 1.0, 1.0, 1.0, 1.0, 1.0 } };
  /// Bit j (SensorIndex) set = channel j learned; the others keep their configured precision.
  std::uint8_t learned = (1u << base::kGyroZ) | (1u << base::kOmegaLeft) | (1u << base::kOmegaRight);
};

/**
 * \brief Gradient descent of the log-precisions ln Pi_j of the order-0 sensory channels on the
 *        free energy.
 *
 * The free energy of eq. 3-10 with the normalisation term of the Gaussians the precisions belong
 * to (dropped in the thesis because Pi_y is fixed there; the Laplace-encoded free energy and the
 * precision learning of Baioumy et al., arXiv 2005.05894, its section on learning the model's
 * parameters and precisions), per channel j of order 0:
 *   F_j = 1/2 (Pi_j eps_j^2 - ln Pi_j) + const,
 *   dF_j / dPi_j = 1/2 (eps_j^2 - 1 / Pi_j),
 * zero at Pi_j = 1 / E[eps_j^2]: the precision is the inverse variance of the prediction error.
 * The descent runs on lambda_j = ln Pi_j (the precision stays positive and a step is a relative
 * change), dF_j / d lambda_j = Pi_j dF_j / dPi_j = 1/2 (Pi_j eps_j^2 - 1), with eps_j^2 replaced by
 * its low-pass s_j (time constant T_w = time_constant) so that one sample does not move it:
 *   s_j      <- s_j + (1 - exp(-h / T_w)) (min(eps_j^2, c^2 / Pi_j) - s_j),
 *   lambda_j <- clamp(lambda_j - h kappa_pi / 2 (Pi_j s_j - 1), ln Pi_min,j, ln Pi_max,j),
 * c = kOutlierClip: one sample counts as at most a c-sigma error of the current precision. Near
 * the optimum lambda_j relaxes with the time constant 2 / kappa_pi (the slow timescale of
 * parameters, against the beliefs' milliseconds); far below it lambda_j rises at most kappa_pi / 2
 * per second (a tenfold rise takes at least 4.6 / kappa_pi), above it it falls at up to
 * kappa_pi (c^2 - 1) / 2 per second. Bounds: Pi_min,j = min_factor Pi_cfg,j,
 * Pi_max,j = max_factor Pi_cfg,j (Pi_cfg: the configured 1 / var_y of order 0).
 *
 * One outlier (any size) moves lambda_j by at most about c^2 kappa_pi h / 2 in all (its share of
 * s_j, at most (h / T_w) c^2 / Pi_j, decays with T_w while it drives lambda_j at kappa_pi Pi_j / 2
 * times it): 2.5e-3 (0.25 %) with the defaults at h = 1 ms.
 *
 * Frozen (nothing moves, s_j included) while the fault monitor masks a learned channel (the
 * others then explain the twist alone and their errors shrink: their precisions would run to the
 * bound), near rest (both |omega_L|, |omega_R| < min_wheel_speed: a still encoder reads exactly
 * zero and the prediction errors at rest are not those of driving), and while the action
 * saturates (the wheels cannot follow their commands: the goal-biased beliefs' errors are then
 * the saturation's, not the sensors'). The order 1 ... p precisions are not learned: their
 * errors are finite differences whose variance the configured var_y^(i) deliberately overstate
 * (the derivative damping of eq. 3-16, doc/active_inference.md, 'Analysis notes').
 *
 * No heap allocation, no exceptions after construction.
 */
class PrecisionLearner
{
public:
  /// One sample contributes at most (kOutlierClip sigma)^2 of the current precision to s_j.
  static constexpr double kOutlierClip = 5.0;
  /// Relative change of a learned precision that makes the controller take it (rebuilding its
  /// belief dynamics and, for the exact integrator, the matrix exponential) [-].
  static constexpr double kApplyTolerance = 0.01;

  /// Why the last update() did or did not move the precisions.
  enum class State
  {
    kLearning,     ///< the precisions moved (or stayed at a bound)
    kSensorFault,  ///< frozen: a learned channel is masked
    kNearRest,     ///< frozen: both wheel speeds below min_wheel_speed
    kSaturated,    ///< frozen: the action saturates
    kBadInput      ///< ignored: non-finite input or h <= 0
  };

  /// Default settings and channels (configured precisions 1).
  PrecisionLearner();
  /**
   * \param params    the learning's settings (AicParams::precision_learner; `enabled` is the
   *                  caller's): rate finite and >= 0, min_factor in (0, 1], max_factor >= 1,
   *                  time_constant > 0, min_wheel_speed >= 0, each finite
   * \param channels  the configured precisions (each finite and > 0) and the learned channels
   * \throws std::invalid_argument naming every violated rule.
   */
  PrecisionLearner(const params::PrecisionLearnerParams& params, const PrecisionChannels& channels);

  /**
   * \brief New settings. What was learned is kept (clamped to the new bounds) if the learned
   *        channels and the configured precisions are unchanged, else the learning restarts.
   * \throws std::invalid_argument (state unchanged) naming every violated rule.
   */
  void setParams(const params::PrecisionLearnerParams& params, const PrecisionChannels& channels);

  /**
   * \brief One learning step.
   * \param h            step [s], finite and > 0
   * \param eps          order-0 sensory prediction errors eps_y^(0) = y^(0) - R mu^(0) per channel
   *                     (SensorIndex) [channel unit], finite for the learned channels
   * \param omega_l      measured left wheel speed y^(0) [rad/s]
   * \param omega_r      measured right wheel speed y^(0) [rad/s]
   * \param sensor_mask  the controller's mask (bit j set = channel j used)
   * \param saturated    true while the action is clamped to max_wheel_speed
   * \return the reason the step did or did not learn; nothing changes unless kLearning.
   */
  State update(double h, const base::Vector5& eps, double omega_l, double omega_r, std::uint8_t sensor_mask,
               bool saturated);

  /// Learned precision Pi_j of channel j [1/(channel unit)^2] (the configured one for a channel
  /// not learned or j out of range: NaN).
  double precision(int j) const;
  /// The learned precisions of every channel, Pi_y^(0) per SensorIndex.
  const std::array<double, base::kYDim>& precisions() const { return pi_; }
  /// Low-passed squared prediction error s_j of channel j [(channel unit)^2] (NaN out of range).
  double meanSquaredError(int j) const;
  /// Write the learned precisions of the learned channels into column 0 of pi_y (5 x (p+1)) and
  /// remember them as the ones in use (changedSince()).
  void applyTo(base::YTilde* pi_y);
  /// True if a learned precision moved by more than `tolerance` (relative) from the one applyTo() wrote.
  bool changedSince(double tolerance) const;
  /// The state of the last update() (kNearRest before any).
  State state() const { return state_; }
  /// Number of update() calls that learned.
  std::uint64_t learningSteps() const { return steps_; }
  /// Back to the configured precisions; the step count cleared.
  void reset();
  /// The settings in use.
  const params::PrecisionLearnerParams& params() const { return params_; }
  /// The configured precisions and learned channels in use.
  const PrecisionChannels& channels() const { return channels_; }

private:
  /// True if channel j is learned.
  bool learned(int j) const { return (channels_.learned & (1u << j)) != 0; }

  params::PrecisionLearnerParams params_;
  PrecisionChannels channels_;
  std::array<double, base::kYDim> lambda_{};   ///< ln Pi_j
  std::array<double, base::kYDim> pi_{};       ///< exp(lambda_j)
  std::array<double, base::kYDim> s_{};        ///< low-pass of eps_j^2
  std::array<double, base::kYDim> applied_{};  ///< the precisions applyTo() last wrote
  State state_ = State::kNearRest;
  std::uint64_t steps_ = 0;
};

/// The controller's precision learner's channels from AicParams: configured = 1 / var_y of
/// order 0 (column 0 of precisionY()); learned = the gyro, both wheels, and accelerometer x with
/// accel_in_model. Requires a valid AicParams.
PrecisionChannels precisionChannels(const params::AicParams& params);

/// Name of a learner state, e.g. "near rest".
const char* toString(PrecisionLearner::State state);

}  // namespace aic
}  // namespace jackal_aic
