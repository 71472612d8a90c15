#pragma once
/**
 * \file types.hpp
 * \brief Sizes and fixed-capacity Eigen types shared by the jackal_aic core.
 *
 * Generalized quantities are stored as matrices with one row per channel and one
 * column per generalized order: column i holds the i-th time derivative
 * (y_tilde.col(0) = y^(0), y_tilde.col(1) = y^(1), ...). The number of columns is
 * embedding_order + 1 at run time, bounded by kMaxOrders at compile time, so
 * resizing never touches the heap.
 *
 * ROS-free: this header depends on Eigen only.
 */

#include <limits>

#include <Eigen/Core>

namespace jackal_aic
{
namespace base
{
/// Largest embedding order p supported (orders 0..p, so at most kMaxOrders columns).
constexpr int kMaxEmbeddingOrder = 5;
/// Largest number of generalized orders (p + 1).
constexpr int kMaxOrders = kMaxEmbeddingOrder + 1;

/// Belief dimension: body twist (x_dot [m/s], y_dot [m/s], theta_dot [rad/s]).
constexpr int kMuDim = 3;
/// Sensor dimension: (gyro z [rad/s], omega_L [rad/s], omega_R [rad/s], accel x [m/s^2], accel y [m/s^2]).
constexpr int kYDim = 5;
/// Action dimension: wheel speed commands (omega_L, omega_R) [rad/s].
constexpr int kADim = 2;

/// Indices into the sensor vector y (rows of y_tilde, eps_y, Pi_y and of R;
/// doc/active_inference.md, 'Signals and units').
enum SensorIndex : int
{
  kGyroZ = 0,       ///< IMU yaw rate [rad/s]
  kOmegaLeft = 1,   ///< mean left wheel speed omega_L [rad/s]
  kOmegaRight = 2,  ///< mean right wheel speed omega_R [rad/s]
  kAccelX = 3,      ///< IMU specific force along x [m/s^2]
  kAccelY = 4       ///< IMU specific force along y [m/s^2]
};

/// Generalized beliefs mu_tilde: 3 x (p+1), column i = mu^(i).
using MuTilde = Eigen::Matrix<double, kMuDim, Eigen::Dynamic, Eigen::ColMajor, kMuDim, kMaxOrders>;
/// Generalized measurements y_tilde: 5 x (p+1), column i = y^(i).
using YTilde = Eigen::Matrix<double, kYDim, Eigen::Dynamic, Eigen::ColMajor, kYDim, kMaxOrders>;
/// Generalized signal with a run-time number of channels (used by the Generalizer).
using GeneralizedSignal =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, Eigen::Dynamic, kMaxOrders>;

/// Action-sized vector, e.g. the wheel speed commands a = (omega_L, omega_R) [rad/s].
using Vector2 = Eigen::Matrix<double, kADim, 1>;
/// Belief-sized vector, e.g. mu^(0) or the goal mu_d = (x_dot [m/s], y_dot [m/s], theta_dot [rad/s]).
using Vector3 = Eigen::Matrix<double, kMuDim, 1>;
/// Sensor-sized vector: one sample y, indexed by SensorIndex [channel units].
using Vector5 = Eigen::Matrix<double, kYDim, 1>;

/// Sensor model R (5 x 3): y = R mu.
using SensorMatrix = Eigen::Matrix<double, kYDim, kMuDim>;
/// Kinematic map G (3 x 2): mu = G (omega_L, omega_R).
using KinematicMatrix = Eigen::Matrix<double, kMuDim, kADim>;
/// Forward model K = dy/da (2 x 5), one row per action.
using ForwardMatrix = Eigen::Matrix<double, kADim, kYDim>;

/**
 * \brief One sample's sensory prediction errors under a generative model, before the beliefs take
 *        it (the innovations of the model's filter form), with their variances under the model: the
 *        input of the fault monitor's innovation test (safety::FaultMonitor, doc/active_inference.md,
 *        'Fault detection and isolation').
 */
struct SampleInnovation
{
  /// eps_y = y - H mu_- of gyro z, omega_L, omega_R, in SensorIndex order [rad/s].
  Vector3 error = Vector3::Zero();
  /// Their variances H P_- H^T + sigma^2 [(rad/s)^2].
  Vector3 variance = Vector3::Ones();
  /// The parity of the three: the gyro's error less the yaw the wheels' errors imply,
  /// eps_gyro - k (eps_R - eps_L), k the wheels' yaw rate per unit speed difference [rad/s];
  /// zero in expectation whatever the wheels and the body do, as long as the sensors are healthy.
  double parity = 0.0;
  /// Its variance, variance(gyro) + k^2 (variance(L) + variance(R)) [(rad/s)^2].
  double parity_variance = 1.0;
  /// The part of parity_variance that does not come from the model's unknown slow states (the slip
  /// ratio's uncertainty in a turn) [(rad/s)^2]: the variance against which an isolated channel's
  /// agreement is evidence that it is healthy again; <= parity_variance. NaN (or not > 0): none,
  /// parity_variance is used.
  double release_variance = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace base
}  // namespace jackal_aic
