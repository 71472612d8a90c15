#pragma once
/**
 * \file controller.hpp
 * \brief The active inference controller for a skid-steer robot's body velocity
 *        (van der Meer 2022, thesis eq. 3-6 ... 3-16; Pezzato et al. 2020). ROS-free.
 */

#include <cstdint>

#include "jackal_aic/params.hpp"
#include "jackal_aic/skid_steer_model.hpp"
#include "jackal_aic/types.hpp"

namespace jackal_aic
{
/**
 * \brief Active inference controller: beliefs mu_tilde (3 x (p+1)), action a (2) [rad/s].
 *
 * Usage (double loop, spec section 5): setGoal(mu_d); whenever a generalized
 * sensor sample arrives, setMeasurement(y_tilde); at the belief rate
 * updateBeliefs(h_mu); at the action rate updateAction(h_a); send action().
 * Neither update moves before the first setMeasurement().
 *
 * Not thread-safe; no heap allocation and no exceptions in setGoal,
 * setMeasurement, updateBeliefs, updateAction (the matrix exponential of the exact
 * integrator is recomputed only when h or the parameters change).
 */
class ActiveInferenceController
{
public:
  /// Result of an update.
  enum class Status
  {
    kOk,           ///< state advanced
    kNoMeasurement,///< no measurement yet: state not moved
    kBadInterval,  ///< h <= 0 or non-finite: state not moved
    kRunaway       ///< beliefs or action became non-finite or exceeded runaway_limit: state reset to zero
  };

  /// \throws std::invalid_argument listing every violation if params.validate() is not empty.
  explicit ActiveInferenceController(const AicParams& params);

  /**
   * \brief Replace the parameters. If the embedding order changes the state is reset,
   *        otherwise beliefs and action are kept.
   * \throws std::invalid_argument (state unchanged) if params.validate() is not empty.
   */
  void setParams(const AicParams& params);
  const AicParams& params() const { return params_; }
  const SkidSteerModel& model() const { return model_; }

  /// Desired twist mu_d = (v_x [m/s], 0, omega_z [rad/s]). Non-finite input is ignored, returns false.
  bool setGoal(const Vector3& mu_d);
  const Vector3& goal() const { return mu_d_; }

  /**
   * \brief Latest generalized measurement y_tilde (5 x (p+1)), held until the next one.
   * \return false (and ignored) if it has the wrong number of columns or a non-finite entry.
   */
  bool setMeasurement(const YTilde& y_tilde);
  bool hasMeasurement() const { return has_measurement_; }

  /**
   * \brief One belief step: mu_tilde += h * (D mu_tilde - k_mu dF/dmu_tilde) (eq. 3-15, Euler)
   *        or the exact zero-order-hold step.
   * \param h  belief step [s], finite and > 0
   */
  Status updateBeliefs(double h);

  /**
   * \brief One action step: a += h * (-k_a sum_i K Pi_y^(i) eps_y^(i)) (eq. 3-16), then clamp to
   *        +-max_wheel_speed.
   * \param h  action step [s], finite and > 0
   */
  Status updateAction(double h);

  /// Zero beliefs and action, forget the measurement (goal kept).
  void reset();
  /// Set the action (e.g. to the measured wheel speeds for a bumpless start); clamped; non-finite ignored.
  void setAction(const Vector2& a);

  const MuTilde& mu() const { return mu_; }          ///< beliefs, 3 x (p+1)
  const Vector2& action() const { return a_; }       ///< wheel speed commands (omega_L, omega_R) [rad/s]
  const YTilde& yTilde() const { return y_tilde_; }  ///< held measurement, 5 x (p+1)

  /// Sensory prediction errors eps_y^(i) = y^(i) - R mu^(i), 5 x (p+1) (eq. 3-8).
  YTilde epsY() const;
  /// State prediction errors eps_mu^(i), 3 x (p+1) (eq. 3-9).
  MuTilde epsMu() const;
  /// Variational free energy F (eq. 3-10) at the current state [-].
  double freeEnergy() const;
  /// Gradient dF/dmu_tilde, 3 x (p+1) (eq. 3-13).
  MuTilde dFdMu() const;
  /// Belief rate of change dmu_tilde/dt = D mu_tilde - k_mu dF/dmu_tilde, 3 x (p+1) (eq. 3-15).
  MuTilde muDot() const;
  /// Action rate of change da/dt = -k_a sum_i K Pi_y^(i) eps_y^(i) [rad/s^2] (eq. 3-16).
  Vector2 aDot() const;

  /// Number of runaway resets since construction.
  std::uint64_t runawayCount() const { return runaway_count_; }

private:
  // Implementation-defined members (state, cached precisions, exact-integrator matrices).
  AicParams params_;
  SkidSteerModel model_;
  MuTilde mu_;
  YTilde y_tilde_;
  Vector3 mu_d_ = Vector3::Zero();
  Vector2 a_ = Vector2::Zero();
  bool has_measurement_ = false;
  std::uint64_t runaway_count_ = 0;
};

/// Human-readable name of a status, e.g. "runaway".
const char* toString(ActiveInferenceController::Status status);

}  // namespace jackal_aic
