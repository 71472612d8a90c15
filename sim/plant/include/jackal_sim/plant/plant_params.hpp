#pragma once
/**
 * \file plant_params.hpp
 * \brief Parameters of the simulated Jackal (physics, contacts, the MCU wheel-speed loop,
 *        sensors), with defaults, units, validation, and loading from sim/config/plant.yaml.
 *
 * ROS-free (yaml-cpp). One struct per component, each with validate() returning every
 * violation by name; PlantParams::validate() collects them all.
 */

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace jackal_aic
{
namespace plant
{
/// Thrown on an unreadable or invalid plant parameter file; what() names the file and
/// every offending key with its value and the allowed range.
class PlantParamsError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Rigid-body simulation settings.
struct PhysicsParams
{
  double step = 0.001;             ///< fixed ODE step [s], (0, 0.01]
  double gravity = 9.81;           ///< magnitude of gravity, along -z [m/s^2], > 0
  double initial_x = 0.0;          ///< initial base_link x in odom [m]
  double initial_y = 0.0;          ///< initial base_link y in odom [m]
  double initial_yaw = 0.0;        ///< initial heading [rad]
  double initial_clearance = 0.0;  ///< wheel bottom above the ground at start [m], >= 0

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/**
 * Wheel-ground (and chassis-ground) contact, as Gazebo's ODE <surface> parameters, plus the
 * choice of friction law.
 *
 * friction_model "slip" (default) is an isotropic brush tyre (tyre_contact.hpp): the friction
 * force opposes the contact's sliding velocity and follows the wheel's combined slip
 * sigma = |v_s| / max(|v_x|, r |omega|, slip_min_speed) (slip ratio and tangent of the slip angle)
 * with initial slope slip_stiffness N and a smooth saturation at mu1 N from sigma = 3 mu1 /
 * slip_stiffness on (H.B. Pacejka, Tire and Vehicle Dynamics, 2012, section 3.2; Gazebo's
 * WheelSlipPlugin scales ODE's slip with the wheel's speed for the same reason). Turning in place
 * the wheels slide at slips of ~0.5, so the contact is Coulomb's and the robot turns with an
 * effective separation of track + wheelbase^2 / track (0.558 m for the Jackal; identified on the
 * robot: 0.5621 m); on arcs the slips, and with them the scrub torque, fall as the turning radius
 * grows. slip1 and slip2 are not used (the law sets ODE's slip per step).
 * friction_model "cone" is isotropic Coulomb friction, as rubber sliding on a hard floor:
 * a contact whose tangential sliding speed exceeds sliding_threshold gets a friction force
 * of magnitude <= mu1 N opposite to its sliding velocity (ODE: the pyramid's fdir1 follows
 * the sliding velocity at the start of the step; with mu1 = mu2 and slip1 = slip2, both
 * required, the law is isotropic and, through the compliance, linear below mu N); the scrub
 * is mu N at any forward speed.
 * friction_model "pyramid" is ODE's (and Gazebo's) default: two independent Coulomb limits
 * mu1 N along the rolling direction (fdir1) and mu2 N along the axle. It is anisotropic: a
 * wheel that slides both along and across its rolling direction (every wheel of a
 * skid-steer robot turning) gets the full mu N in both directions, so the longitudinal
 * (driving) forces win over the lateral (resisting) ones and the robot turns almost like
 * an ideal differential drive (effective separation ~ the track).
 * "cone" and "slip": slower contacts than sliding_threshold keep fdir1 along the rolling direction.
 */
struct ContactParams
{
  std::string friction_model =
      "slip";  ///< "slip" (brush tyre), "cone" (isotropic Coulomb) or "pyramid" (ODE/Gazebo default)
  double sliding_threshold = 0.001;  ///< cone, slip: sliding speed above which fdir1 follows the sliding [m/s], > 0
  /// slip: slip stiffness C, the initial slope of friction force over normal load against the combined
  /// slip [-] (per unit slip), (0, 1000]; the force reaches mu1 N at a slip of 3 mu1 / C.
  double slip_stiffness = 10.0;
  /// slip: the smallest reference speed of the slip [m/s], (0, 1]: below it (starting, stopping, slow
  /// turns) the force follows the sliding speed, C N |v_s| / slip_min_speed, as a tyre compliance.
  double slip_min_speed = 0.15;
  double mu1 = 0.5;      ///< Coulomb friction along the rolling direction (fdir1) [-], >= 0
  double mu2 = 0.5;      ///< Coulomb friction along the axle [-], >= 0
  double slip1 = 0.001;  ///< ODE force-dependent slip along fdir1 [m/(s N)], >= 0 (Gazebo slip1); not slip
  double slip2 = 0.001;  ///< ODE force-dependent slip along the axle [m/(s N)], >= 0 (Gazebo slip2); not slip
  double kp = 1.0e7;     ///< contact stiffness [N/m], > 0
  double kd = 1.0;       ///< contact damping [N s/m], >= 0
  double max_correcting_vel = 100.0;  ///< ODE contact_max_correcting_vel [m/s], > 0
  double surface_layer = 0.001;       ///< ODE contact_surface_layer (allowed penetration) [m], >= 0
  int max_contacts = 4;               ///< contact points per wheel-ground pair, [1, 16]

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/**
 * MCU wheel-speed loop of one side (one motor drives both wheels of a side), expressed at
 * the wheels: the set point passes a transport delay, an optional slew-rate limit (ramp)
 * and an optional first-order lag, then a PI speed servo on the side's mean wheel speed,
 * torque limited by the motor current limit and by the supply voltage (back-EMF: a DC motor's available torque falls
 * linearly from the stall torque at rest to zero at the no-load speed), plus drivetrain
 * friction per wheel.
 */
struct MotorParams
{
  double speed_kp = 10.38;   ///< proportional gain [N m / (rad/s)], >= 0
  double speed_ki = 0.4892;  ///< integral gain [N m / rad], >= 0
  double max_torque = 8.0;   ///< current (torque) limit of one side, at the wheels [N m], > 0
  /// Clamp of the PI integrator [N m], >= 0; 0 = max_torque. Below max_torque the integral path alone
  /// cannot drive the motor to its limit: on a large error the torque is integral_limit + speed_kp * error,
  /// so a set point further ahead of the wheels accelerates them faster.
  double integral_limit = 0.0;
  /// Clamp of the proportional path Kp * e [N m], >= 0; 0 = none. The high-gain proportional path
  /// makes small steps fast and well damped but cannot, on its own, push a large error harder than this.
  double proportional_limit = 0.7571;
  /// Clamp of the error the integrator integrates [rad/s], >= 0; 0 = none: dI/dt = speed_ki * clamp(e,
  /// +-integral_error_limit). The integral path then grows at a bounded rate whatever the error: it
  /// trims the steady speed yet adds little during the large-error transient of a straight step.
  double integral_error_limit = 0.5643;
  /// Voltage (speed) feedforward [N m / (rad/s)], >= 0; 0 = off. Driving the motor at the set point's
  /// no-load voltage makes the back-EMF give a torque of this gain times (set point - wheel speed)
  /// (ideally stall_torque / no_load_speed), outside the PI's limits: a set point further ahead of the
  /// wheels accelerates them harder.
  double setpoint_feedforward = 0.0326;
  /// Acceleration feedforward of the set point [N m s^2/rad] (an inertia, kg m^2), >= 0; 0 = off.
  /// The MCU adds accel_feedforward * (rate of change of the received set point) to the PI torque,
  /// the rate estimated from consecutive received commands and held until the next one: a ramping
  /// command (the AIC's) gets a sustained torque, a step (the stock controller's) one period's kick.
  double accel_feedforward = 0.07343;
  /// Clamp of the acceleration feedforward torque [N m], >= 0; 0 = none (only the current limit).
  /// A stock step's one-period kick (accel_feedforward times a set-point jump over 20 ms: ~15 N m for
  /// 1.0 m/s) is bounded by this; the stock steps (thesis table 3-1b) fix the bound at ~4 N m but
  /// cannot tell it from the current limit (doc/robot_data.md, 'Motor limits').
  double accel_feedforward_limit = 3.243;
  /// Load-torque observer (disturbance observer): the nominal inertia of one side at the wheels
  /// [kg m^2], > 0 when the observer is on. The servo estimates the load torque as the torque it
  /// applied minus this inertia times the side's acceleration, both low-pass filtered with
  /// load_observer_time_constant, and adds the estimate to its torque: whatever the load (the scrub
  /// of a turn, a slope, drivetrain friction), a side then accelerates under the PI torque as this
  /// inertia would. With the straight-driving inertia (half the robot's mass times r^2 plus the
  /// side's two wheels' spin inertia, 0.0933 kg m^2 from the URDF) a straight step is unchanged and
  /// a turn spins up on the time scale of a straight step.
  double load_observer_inertia = 0.0933;
  /// Time constant of the load-torque observer's filter [s], [0, 5]; 0 = no observer.
  double load_observer_time_constant = 0.04105;
  double stall_torque = 12.0;                ///< voltage limit: stall torque of one side [N m]; 0 = no voltage limit
  double no_load_speed = 26.0;               ///< voltage limit: no-load wheel speed [rad/s], > 0 if stall_torque > 0
  double setpoint_slew_rate = 0.0;           ///< MCU ramp of the speed set point [rad/s^2]; 0 = none
  double setpoint_time_constant = 0.004661;  ///< first-order lag on the set point inside the MCU [s], >= 0
  double command_delay = 0.1187;             ///< transport delay /cmd_drive -> MCU [s], [0, 0.5]
  double coulomb_friction = 0.1565;          ///< drivetrain Coulomb friction per wheel [N m], >= 0
  double viscous_friction = 0.01;            ///< drivetrain viscous friction per wheel [N m / (rad/s)], >= 0
  double coupling_damping = 1.0;             ///< front-rear drivetrain coupling on a side [N m / (rad/s)], >= 0
  double max_wheel_speed = 25.0;             ///< set points are clamped to +-this [rad/s], > 0

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/**
 * A payload fixed to the chassis: a point mass at a position in base_link (a box on the top
 * plate, a manipulator, a battery). The chassis body's mass, centre of mass and inertia become
 * those of chassis plus payload (parallel-axis theorem), so the payload loads the wheels, shifts
 * the weight between them and adds to the inertia the wheel loop drives.
 */
struct PayloadParams
{
  double mass = 0.0;                 ///< [kg], [0, 100]; 0 = none
  std::array<double, 3> position{};  ///< x, y, z in base_link [m], each within [-1, 1]

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("payload.mass = -1 (allowed: [0, 100] kg)"); empty = valid.
  std::vector<std::string> validate() const;
};

/// Noise model of one sensor stream.
struct StreamParams
{
  double rate = 50.0;    ///< publication rate [Hz], > 0; the period is rounded to whole physics steps
  double delay = 0.0;    ///< age of the data in a sample [s], [0, 1]
  double dropout = 0.0;  ///< probability that a sample is not published [-], [0, 1)

  /// As the other validate()s, with the YAML keys prefixed by \p prefix (e.g. "sensors.imu.").
  std::vector<std::string> validate(const std::string& prefix) const;
};

/// Joint-state sensor (wheel encoders).
struct JointStateSensorParams : StreamParams
{
  double position_noise_std = 0.0;  ///< Gaussian noise on positions [rad], >= 0
  double velocity_noise_std = 0.0;  ///< Gaussian noise on velocities [rad/s], >= 0
  double velocity_bias = 0.0;       ///< constant offset on velocities [rad/s]

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/// IMU (angular velocity, specific force, orientation), in the IMU frame.
struct ImuSensorParams : StreamParams
{
  double gyro_noise_std = 0.0;         ///< Gaussian noise per axis [rad/s], >= 0
  std::array<double, 3> gyro_bias{};   ///< constant offset per axis [rad/s]
  double accel_noise_std = 0.0;        ///< Gaussian noise per axis [m/s^2], >= 0
  std::array<double, 3> accel_bias{};  ///< constant offset per axis [m/s^2]
  double orientation_noise_std = 0.0;  ///< Gaussian noise per Euler angle [rad], >= 0

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/// All sensors.
struct SensorParams
{
  std::uint32_t seed = 42;  ///< random seed of every noise and dropout draw
  JointStateSensorParams joint_states;
  ImuSensorParams imu;

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/// The same sensors without noise, bias and dropout (rates and delays kept): the streams a
/// replay or a fit compares are then reproducible.
SensorParams idealSensors(SensorParams sensors);

/// Settings of the ROS node around the plant (ignored by the ROS-free core).
struct PlantNodeParams
{
  double real_time_factor = 1.0;    ///< plant seconds per wall second; 0 = as fast as possible, [0, 100]
  double odom_rate = 50.0;          ///< /odom and tf rate [Hz], (0, 1000]
  double clock_rate = 1000.0;       ///< /clock rate with use_sim_time [Hz], (0, 1000]
  double cmd_timeout = 0.5;         ///< /cmd_drive silence after which set points are zeroed [s]; 0 = never
  std::string odom_frame = "odom";  ///< world frame name

  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/// Everything the plant needs besides the URDF.
struct PlantParams
{
  PhysicsParams physics;
  ContactParams contact;
  MotorParams motor;
  PayloadParams payload;
  SensorParams sensors;
  PlantNodeParams node;

  /// Every violation, as "key = value (allowed range)"; empty when valid.
  /// Every violated rule of the members above, one message each naming the YAML key, its
  /// value and the allowed range ("motor.stall_torque = -1 (allowed: > 0)"); empty = valid.
  std::vector<std::string> validate() const;
};

/**
 * \brief Load plant parameters from a YAML file; keys absent from the file keep their
 *        defaults.
 * \param path      YAML file (sections physics, contact, motor, payload, sensors, node)
 * \param overrides "dotted.key=value" strings applied on top of the file
 *                  (e.g. "motor.max_torque=1.5", "sensors.imu.gyro_bias=[0,0,0.01]")
 * \throws PlantParamsError on an unreadable file, a malformed value, an unknown override
 *         key, or any violation of validate() (all listed).
 */
PlantParams loadPlantParams(const std::string& path, const std::vector<std::string>& overrides = {});

/**
 * \brief The overrides of a base plant YAML, overlays first: every overlay file's keys as
 *        "dotted.key=value" (jackal_aic::overrides::loadOverlayFile(), in the order given, later ones
 *        winning), then `overrides` (command-line --set), for loadPlantParams().
 * \param overlay_files plant YAMLs with only the keys that differ (e.g. sim/config/variants/turn_deficit.yaml)
 * \param overrides     "dotted.key=value" strings applied after the overlays
 * \throws PlantParamsError naming the overlay file that cannot be read or is not a YAML map
 */
std::vector<std::string> plantOverrides(const std::vector<std::string>& overlay_files,
                                        const std::vector<std::string>& overrides = {});

/// As loadPlantParams() from a YAML string (source names it in errors).
PlantParams parsePlantParams(const std::string& yaml, const std::string& source,
                             const std::vector<std::string>& overrides = {});

}  // namespace plant
}  // namespace jackal_aic
