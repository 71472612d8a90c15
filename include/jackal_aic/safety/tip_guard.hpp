#pragma once
/**
 * \file tip_guard.hpp
 * \brief The tip-over guard: the body's pitch from the IMU's gyro y, and the deceleration at which
 *        the rear (front) wheels left the ground, learned when they do and held as a bound of the
 *        reference path's acceleration. ROS-free. doc/active_inference.md, 'The tip-over guard'.
 */

#include <cstdint>
#include <string>

#include "jackal_aic/params/stage_params.hpp"

namespace jackal_aic
{
namespace safety
{
/**
 * \brief Watches the body's pitch while the robot brakes and learns the acceleration at which it
 *        starts to tip over.
 *
 * A rigid skid-steer robot without suspension does not pitch on flat ground unless a pair of
 * wheels leaves it: braking harder than g d / h (d the horizontal distance of the centre of mass
 * behind the front axle, h its height) lifts the rear wheels and the body turns nose-down about
 * the front axle (doc/usage.md, 'Payloads'). The guard integrates the IMU's pitch rate q (gyro y,
 * REP 103: > 0 noses down; the caller removes its offset) into the pitch against the ground's
 * plane, with a leak while the body does not rotate (|q| < kStillRate) so that a slope driven onto
 * fades,
 *   theta_hat <- theta_hat e^(-h/T_theta) [|q| < kStillRate] + q h,   T_theta = kPitchTimeConstant
 * (no leak while it rotates: a tip and its landing integrate back to 0),
 * and low-passes the body's longitudinal acceleration from the wheels' speed v = r (omega_L +
 * omega_R) / 2 (not from the accelerometer, which on a slope also reads gravity's share),
 *   a_hat <- a_hat + (h / T_a)((v - v_prev) / h - a_hat),   T_a = kAccelTimeConstant.
 * It trips nose-down when theta_hat > trip_pitch while a_hat < -kBrakingThreshold (the body slows
 * going forward or speeds up in reverse: the pitch is the brake's doing, not a slope's or a
 * bump's); tail-down the same with the signs turned. While tripped (until |theta_hat| < trip_pitch / 2) the bound in that direction
 * is 0: the path stops braking and the wheels roll the body back onto all four. The trip also
 * learns the acceleration that tips the robot: the rear wheels left the ground where theta_hat last
 * rose through kOnsetFraction x trip_pitch (the body rotates only while |a| > g d / h), so
 *   A_front <- min(A_front, max(min_acceleration, margin |a_hat(onset)|))
 * (A_rear tail-down). After the trip the bound is the learned A: the controller clamps the
 * reference path's rate along x_dot to [-frontBound(), rearBound()] (ReferenceModel::setTipBounds),
 * so every later stop is planned below the learned limit.
 *
 * Past turnover_pitch (|theta_hat| > turnover_pitch, whatever the acceleration) the body has turned
 * over: its centre of mass has passed over the axle it rotates about, and no wheel command rolls it
 * back. turnedOver() then asks the controller for a zero command (the wheels of a robot on its back
 * spin free, and a path held at the speed its wheels believe would hold them spinning) until the
 * pitch estimate is below turnover_pitch again. The pitch estimate alone forgets a robot lying on
 * its back (after a flip theta_hat leaks away at rest), so the guard also watches the IMU's
 * specific force along the body's z axis, f_z (+g level at rest, -g on its back), low-passed
 *   f_hat <- f_hat + (h / T_f)(f_z - f_hat),   T_f = kUpForceTimeConstant
 * (lying on its back is a lasting state: a bump's or a landing's spike of a few g for a sample
 * moves f_hat by a fraction of g);
 * the body is upside down from f_hat < 0 (its z axis below the horizon) until f_hat > g
 * cos(turnover_pitch) (upright within the turnover pitch again), and turnedOver() holds while it
 * is. A slope or a braking robot never reads f_z < 0.
 *
 * Frozen (theta_hat decays, nothing learned) without a valid IMU sample. The bounds are +inf until
 * a trip; reset() forgets them (a payload removed). No heap allocation, no exceptions after
 * construction.
 */
class TipGuard
{
public:
  /// Leak time constant T_theta of the pitch estimate [s].
  static constexpr double kPitchTimeConstant = 1.0;
  /// Time constant T_a of the longitudinal acceleration's low-pass [s].
  static constexpr double kAccelTimeConstant = 0.05;
  /// |q| below which the body counts as not rotating in pitch and theta_hat fades [rad/s].
  static constexpr double kStillRate = 0.05;
  /// The tipping acceleration a trip needs [m/s^2]: a pitch without it is a slope or a bump.
  static constexpr double kBrakingThreshold = 0.3;
  /// The lift's onset: theta_hat rising through this fraction of trip_pitch [-] (the learned bound
  /// is margin x the tipping acceleration there; a noisy gyro crosses it earlier, at a lower
  /// acceleration: the error is on the safe side).
  static constexpr double kOnsetFraction = 0.1;
  /// Time constant T_f of the low-pass of the body's z specific force f_z [s].
  static constexpr double kUpForceTimeConstant = 0.5;
  /// Standard gravity [m/s^2].
  static constexpr double kGravity = 9.80665;

  /// What the last update() saw.
  enum class State
  {
    kLevel,         ///< |theta_hat| <= trip_pitch (or tripped and back below trip_pitch / 2)
    kTippingFront,  ///< tripped nose-down: braking bound 0 until theta_hat < trip_pitch / 2
    kTippingRear,   ///< tripped tail-down: accelerating bound 0 until theta_hat > -trip_pitch / 2
    kPitched,       ///< |theta_hat| > trip_pitch without the acceleration that tips (a slope, a bump): not learned
    kTurnedOver,    ///< turnedOver(): turned over (pitch or upside down), the wheels are stopped
    kNoImu,         ///< no valid IMU sample: theta_hat decays, nothing learned
    kBadInput       ///< ignored: non-finite input or h <= 0
  };

  /// \throws std::invalid_argument naming every violated rule of TipGuardParams.
  explicit TipGuard(const params::TipGuardParams& params);

  /**
   * \brief One sensor sample.
   * \param h           time since the previous sample [s], finite and > 0
   * \param pitch_rate  the IMU's gyro y, q [rad/s] (> 0 noses down)
   * \param speed       the wheels' forward speed v = r (omega_L + omega_R) / 2 [m/s]
   * \param imu_ok      false without a valid IMU sample (pitch_rate and up_force are then ignored)
   * \param up_force    the IMU's specific force along the body's z axis, f_z (linear_acceleration.z)
   *                    [m/s^2]: +g level at rest, -g on its back; finite when imu_ok (default: level)
   * \return the state after the sample.
   */
  State update(double h, double pitch_rate, double speed, bool imu_ok, double up_force = kGravity);

  /// True while |theta_hat| > turnover_pitch or the body is upside down (upsideDown()): it has
  /// turned over and the command is zero (ActiveInferenceController::setTurnedOver()).
  bool turnedOver() const;

  /// True from the low-passed f_z below 0 (on its back) until it is above g cos(turnover_pitch).
  bool upsideDown() const { return upside_down_; }

  /// The low-passed specific force along the body's z axis, f_hat [m/s^2] (g before any IMU sample).
  double upForce() const { return up_; }
  /// The bound of the path's deceleration along x_dot (m' >= -frontBound()) [m/s^2], >= 0: 0 while
  /// tipping nose-down, else the learned A_front (+inf before a trip).
  double frontBound() const;
  /// The bound of the path's acceleration along x_dot (m' <= rearBound()) [m/s^2], >= 0: 0 while
  /// tipping tail-down, else the learned A_rear (+inf before a trip).
  double rearBound() const;
  /// The learned A_front [m/s^2] (+inf before a nose-down trip).
  double learnedFront() const { return front_; }
  /// The learned A_rear [m/s^2] (+inf before a tail-down trip).
  double learnedRear() const { return rear_; }
  /// The pitch estimate theta_hat [rad] (> 0 nose down).
  double pitch() const { return theta_; }
  /// The low-passed longitudinal acceleration a_hat [m/s^2].
  double acceleration() const { return accel_; }
  /// Trips since construction or reset() (each nose-down or tail-down entry counts once).
  std::uint64_t trips() const { return trips_; }
  /// The state of the last update() (kLevel before any).
  State state() const { return state_; }
  /// Forget the learned bounds and the pitch: theta_hat = a_hat = 0, no speed history, bounds
  /// +inf, no trips. f_hat and the upside-down state are observations and are kept.
  void reset();
  /// The settings in use.
  const params::TipGuardParams& params() const { return params_; }
  /// Replace the settings, keeping the learned bounds (raised to the new floor).
  /// \throws std::invalid_argument as the constructor (the guard unchanged).
  void setParams(const params::TipGuardParams& params);

private:
  /// One direction's trip: active until the body is level again.
  struct Trip
  {
    bool active = false;
    double onset_acceleration = -1.0;  ///< the tipping acceleration at the lift's onset [m/s^2]; < 0: level
  };
  /// Trip, learn and release one direction (sign +1: nose-down, -1: tail-down).
  void follow(Trip* trip, double* bound, double sign);

  params::TipGuardParams params_;
  double theta_ = 0.0;
  double accel_ = 0.0;
  double speed_ = 0.0;      ///< the previous sample's v [m/s]
  bool has_speed_ = false;  ///< speed_ holds a sample
  double front_;
  double rear_;
  Trip front_trip_;
  Trip rear_trip_;
  State state_ = State::kLevel;
  std::uint64_t trips_ = 0;
  double up_ = kGravity;      ///< f_hat [m/s^2]
  bool upside_down_ = false;  ///< upsideDown()
};

/// Name of a guard state, e.g. "tipping nose-down".
const char* toString(TipGuard::State state);

/**
 * \brief The guard's status line for diagnostics: the state, the learned bounds and the trips, e.g.
 *        "level; front 1.84 m/s^2, rear none; 1 trip". Allocates (not for the belief loop).
 */
std::string statusText(const TipGuard& guard);

}  // namespace safety
}  // namespace jackal_aic
