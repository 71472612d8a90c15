#pragma once
/**
 * \file plant.hpp
 * \brief The simulated Jackal: an ODE skid-steer plant built from a RobotDescription.
 *
 * ROS-free (ODE, Eigen). A chassis body and four wheel bodies joined by hinges, a ground
 * plane, one soft contact per wheel (ODE's two tyre-edge points merged) with finite friction
 * (so the robot skids when it turns) whose first direction (fdir1) follows each contact's
 * sliding velocity (ContactParams::friction_model "slip": the isotropic brush tyre of
 * tyre_contact.hpp, force following the wheel's slip up to mu N; "cone": isotropic Coulomb
 * friction) or each wheel's rolling direction ("pyramid", Gazebo's), and the MCU wheel-speed
 * loop per side (WheelSpeedServo). Fixed step (PhysicsParams::step).
 *
 * Contact softness follows Gazebo's ODE binding: with stiffness kp, damping kd and step h,
 * ERP = h kp / (h kp + kd) and CFM = 1 / (h kp + kd).
 *
 * Frames: "odom" is the world (z up, the robot starts at the configured pose); base_link
 * and the IMU frame are taken from the URDF.
 */

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_sim/plant/wheel_speed_servo.hpp"

namespace jackal_aic
{
namespace plant
{
/// Noise-free kinematic truth of the IMU frame.
struct ImuTruth
{
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< IMU frame in odom
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       ///< in the IMU frame [rad/s]
  /// Specific force (acceleration minus gravity) in the IMU frame [m/s^2], averaged over
  /// the accelerometer window (reads +g on z at rest).
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
};

/// ODE skid-steer plant. Not copyable; one ODE world per instance.
class Plant
{
public:
  /**
   * \param description robot model (from loadRobotDescription())
   * \param params      validated plant parameters
   * \param accel_window averaging window of the IMU specific force [s], >= step
   *                     (a real IMU low-pass filters; default: one 50 Hz sample period)
   * \throws std::invalid_argument if params do not validate
   */
  Plant(const RobotDescription& description, const PlantParams& params, double accel_window = 0.02);
  ~Plant();
  Plant(const Plant&) = delete;
  Plant& operator=(const Plant&) = delete;

  /// MODE_VELOCITY: wheel-speed set points [rad/s] for the left and right side; non-finite
  /// values are ignored (returns false).
  bool setWheelSpeeds(double left, double right);
  /// MODE_NONE: both motors released (no drive torque; drivetrain friction remains).
  void releaseMotors();

  /**
   * \brief Fault injection: scale the wheel-ground friction (mu1, mu2) of one side's wheels,
   *        e.g. 0.2 for a low-friction patch under that side (1 = the configured surface).
   * \return false (unchanged) unless scale is finite and in [0, 10].
   */
  bool setFrictionScale(Side side, double scale);
  /// The friction scale of a side [-].
  double frictionScale(Side side) const { return friction_scale_[side]; }
  /**
   * \brief Fault injection: a payload [kg] added to the chassis (its inertia scaled with the mass,
   *        centre of mass unchanged); 0 = none.
   * \return false (unchanged) unless payload is finite and in [0, 1000].
   */
  bool setPayload(double payload);
  /// The payload [kg].
  double payload() const { return payload_; }

  /// Advance one fixed step.
  void step();
  /// Advance n fixed steps.
  void step(std::uint64_t n);

  /// Simulated time since construction [s].
  double time() const { return static_cast<double>(steps_) * params_.physics.step; }
  /// Number of steps taken.
  std::uint64_t stepCount() const { return steps_; }
  /// Fixed step [s].
  double stepSize() const { return params_.physics.step; }

  /// Unwrapped wheel joint angle [rad], WheelIndex order.
  double wheelPosition(int i) const { return wheel_angle_[i]; }
  /// Wheel joint rate [rad/s], WheelIndex order.
  double wheelVelocity(int i) const;
  /// Drive torque applied on wheel i by the motor in the last step [N m].
  double wheelTorque(int i) const { return wheel_torque_[i]; }
  /// Mean wheel speed of one side [rad/s].
  double sideVelocity(Side side) const;
  /// Normal load of wheel i in the last step [N] (its contact force's normal part; 0 off the ground).
  double wheelLoad(int i) const { return wheel_load_[i]; }
  /// Combined slip sigma = |v_s| / V of wheel i at the start of the last step [-] (friction_model
  /// "slip" only; 0 otherwise; tyre_contact.hpp).
  double wheelSlipRatio(int i) const { return wheel_slip_[i]; }

  /// base_link pose in odom.
  Eigen::Isometry3d basePose() const;
  /// base_link linear velocity expressed in base_link [m/s].
  Eigen::Vector3d baseLinearVelocity() const;
  /// base_link angular velocity expressed in base_link [rad/s].
  Eigen::Vector3d baseAngularVelocity() const;
  /// Noise-free IMU truth at the current step.
  const ImuTruth& imuTruth() const { return imu_; }

  /// The servo of one side (read-only, for diagnostics).
  const WheelSpeedServo& servo(Side side) const { return servo_[side]; }
  /// The robot model the plant was built from; its chassis mass properties include the configured
  /// payload (PlantParams::payload), not the fault-injected one (setPayload()).
  const RobotDescription& description() const { return description_; }
  const PlantParams& params() const { return params_; }

private:
  struct Ode;
  void build();
  void collide();
  void updateImu();

  RobotDescription description_;
  PlantParams params_;
  std::unique_ptr<Ode> ode_;
  std::array<WheelSpeedServo, 2> servo_;
  std::uint64_t steps_ = 0;
  std::array<double, kNumWheels> wheel_angle_{};
  std::array<double, kNumWheels> last_raw_angle_{};
  std::array<double, kNumWheels> wheel_torque_{};
  /// The smallest normal load [N] the "slip" model divides by (a wheel just touching down).
  static constexpr double kMinWheelLoad = 1.0;
  std::array<double, kNumWheels> wheel_load_{};  ///< normal load of each wheel [N]
  std::array<double, kNumWheels> wheel_slip_{};  ///< combined slip of each wheel [-]
  // IMU specific-force averaging: ring of world IMU-point velocities.
  std::vector<Eigen::Vector3d> vel_ring_;
  std::size_t ring_head_ = 0;
  ImuTruth imu_;
  std::array<double, 2> friction_scale_{ 1.0, 1.0 };
  double payload_ = 0.0;
  double chassis_mass_ = 0.0;  ///< chassis mass without payload [kg]
};

}  // namespace plant
}  // namespace jackal_aic
