#pragma once
/**
 * \file inference_sample.hpp
 * \brief The active inference controller's inference at one instant, as one record: the free
 *        energy and its two parts, the beliefs and both prediction errors of every order, the
 *        action and the stages' outputs (action prior, attractor goal), the sensory precisions and
 *        b_hat in use, and the robot model's slow states (doc/active_inference.md, 'Prediction
 *        errors and free energy', 'The robot model'). What the belief model in use does not have is
 *        NaN. The one reading of the controller that the headless closed loop's trace
 *        (closed_loop_run --csv) and the node's ~inference topic (msg/InferenceState.msg) both
 *        carry. ROS-free.
 */

#include <string>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace aic
{
/// Belief channel names, rows of mu and eps_mu: x_dot, y_dot, theta_dot.
extern const char* const kBeliefChannelNames[base::kMuDim];
/// Units of order 0 of the belief channels: m/s, m/s, rad/s (order i: per s^i).
extern const char* const kBeliefChannelUnits[base::kMuDim];
/// Sensor channel names, rows of eps_y and of Pi_y (SensorIndex): gyro_z, omega_L, omega_R, accel_x, accel_y.
extern const char* const kSensorChannelNames[base::kYDim];
/// Units of order 0 of the sensor channels: rad/s, rad/s, rad/s, m/s^2, m/s^2 (order i: per s^i).
extern const char* const kSensorChannelUnits[base::kYDim];

/**
 * \brief The unit of order `i` of a signal whose order 0 is in `unit` (one "/s" more per order):
 *        orderUnit("m/s", 2) = "m/s^3", orderUnit("rad/s", 0) = "rad/s", orderUnit("m", 1) = "m/s".
 * \param unit  order-0 unit, "X" or "X/s" or "X/s^k"
 * \param i     order, >= 0
 */
std::string orderUnit(const std::string& unit, int i);

/**
 * \brief The controller's inference at one instant. Matrices have one row per channel and one
 *        column per generalized order 0..p of the controller's embedding order p; order i of a
 *        channel is in its unit per s^i (eps_mu^(i): per s^(i+1), the unit of mu^(i+1)).
 *
 * The goal and unbiased models fill every field but the robot model's states (NaN). The robot
 * model (RobotBelief, a filter on the wheel speeds, the yaw rate and its slow states) has no
 * generalized coordinates beyond the rates its model gives, no state prior in them and no separate
 * action prior, so under it NaN marks: mu^(i) for i >= 2; eps_y but order 0 of the three sensors it
 * reads (gyro_z: y - (theta_dot + beta), omega_s: y - omega_s, at the beliefs as they are);
 * eps_mu; action_prior. Its F is RobotBelief's: sensory (1/2) sum eps^2 / sigma^2 at the corrected
 * beliefs, prior the filter's (1/2) eps_mu^T P_-^{-1} eps_mu of the last sample.
 */
struct InferenceSample
{
  /// The belief model the controller runs: which fields are NaN (above)
  params::BeliefModel belief_model = params::BeliefModel::kGoal;
  double free_energy = 0.0;  ///< F (thesis eq. 3-10; the robot model: RobotBelief's) [-]
  double sensory = 0.0;      ///< its sensory part (1/2) sum_i eps_y^(i)T Pi_y^(i) eps_y^(i) [-]
  double prior = 0.0;        ///< its prior part (1/2) sum_i eps_mu^(i)T Pi_mu^(i) eps_mu^(i) [-]
  base::MuTilde mu;          ///< beliefs mu_tilde, 3 x (p+1) (kBeliefChannelNames rows)
  base::YTilde eps_y;        ///< sensory prediction errors eps_y, 5 x (p+1) (eq. 3-8; SensorIndex rows)
  base::MuTilde eps_mu;      ///< state prediction errors eps_mu, 3 x (p+1) (eq. 3-9)
  base::Vector2 action = base::Vector2::Zero();        ///< the action a = (omega_L, omega_R) [rad/s]
  base::Vector2 action_prior = base::Vector2::Zero();  ///< its prior part a_ff (ActionPrior; 0 when off) [rad/s]
  /// The robot model's shortfalls (d_L, d_R) [rad/s] (RobotBelief::shortfalls())
  base::Vector2 shortfall = base::Vector2::Zero();
  /// Its turn shortfalls (e_L, e_R) [rad/s] (RobotBelief::turnShortfalls())
  base::Vector2 turn_shortfall = base::Vector2::Zero();
  double slip_ratio = 0.0;          ///< its yaw slip ratio s [-] (RobotBelief::slipRatio())
  double gyro_offset_belief = 0.0;  ///< its gyro offset beta [rad/s], on top of the offset removed at rest
  /// The attractor's goal mu_r (the reference model's output, else mu_d) [m/s, m/s, rad/s]
  base::Vector3 goal = base::Vector3::Zero();
  /// The precisions Pi_y^(0) in use per sensor channel (learned with learn_precision; 0: masked) [1/unit^2]
  base::Vector5 precision_y = base::Vector5::Zero();
  double wheel_separation = 0.0;  ///< b_hat of the generative model [m] (learned with learn_wheel_separation)
};

/**
 * \brief The inference of `controller` now (ActiveInferenceController's freeEnergy(),
 *        sensoryFreeEnergy(), priorFreeEnergy(), mu(), epsY(), epsMu(), action(), actionPrior(),
 *        attractorGoal(), precisionY().col(0), model().wheelSeparation(); under the robot model
 *        its RobotBelief's states and errors, NaN where the model has none: InferenceSample).
 *        Before the first measurement the errors and F are those of a zero measurement. No heap
 *        allocation.
 */
InferenceSample inferenceSample(const ActiveInferenceController& controller);

/**
 * \brief Whether every value the sample's belief model has is finite: F and its parts, mu, the
 *        action, the goal, Pi_y^(0), b_hat, and the errors and states of its model (NaN only where
 *        the model has no such quantity, InferenceSample). False for unavailableInferenceSample().
 */
bool modelledValuesFinite(const InferenceSample& s);

/// An InferenceSample of `orders` columns with every value NaN: no controller running (yet).
InferenceSample unavailableInferenceSample(int orders);
}  // namespace aic
}  // namespace jackal_aic
