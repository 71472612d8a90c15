#pragma once
/**
 * \file robot_description.hpp
 * \brief The robot model the ODE plant is built from, read from a URDF with urdfdom.
 *
 * ROS-free: urdfdom (urdf_parser) and Eigen only. Every number the plant uses about the
 * robot's geometry and mass (joint names and origins, wheel radius and width from each
 * wheel's collision cylinder, masses, centres of mass, inertias, the chassis collision
 * box, the IMU mounting) comes from here.
 */

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace jackal_aic
{
namespace plant
{
/// Number of wheels of the skid-steer robot.
constexpr int kNumWheels = 4;

/// Wheel order used throughout the plant: front left, front right, rear left, rear right.
enum WheelIndex : int
{
  kFrontLeft = 0,
  kFrontRight = 1,
  kRearLeft = 2,
  kRearRight = 3
};

/// Drive side of a wheel (the Jackal has one motor per side).
enum Side : int
{
  kLeft = 0,
  kRight = 1
};

/// Side of each wheel index (FL, FR, RL, RR).
constexpr std::array<Side, kNumWheels> kWheelSide{ kLeft, kRight, kLeft, kRight };

/// Thrown when a URDF cannot be read or lacks what the plant needs; what() names the file
/// and the missing or malformed element.
class RobotDescriptionError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Mass properties of a rigid body.
struct MassProperties
{
  double mass = 0.0;                                  ///< [kg], > 0
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      ///< centre of mass in the link frame [m]
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about the COM, link axes [kg m^2]
};

/**
 * \brief The mass properties of `body` (in its link frame) with a point mass added (a payload).
 * \param body     mass [kg] > 0, centre of mass [m] and inertia about it [kg m^2], link frame
 * \param mass     the point mass [kg], >= 0
 * \param position where it sits, link frame [m]
 * \return masses added, the centre of mass their weighted mean, each part's inertia moved to the
 *         new centre by the parallel-axis theorem, I + m ((d.d) 1 - d d^T). Inputs are not checked
 *         (PayloadParams::validate() bounds the payload).
 */
MassProperties withPointMass(const MassProperties& body, double mass, const Eigen::Vector3d& position);

/// An axis-aligned (in its own frame) collision box of the chassis.
struct CollisionBox
{
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< box centre pose in the chassis frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();            ///< edge lengths x, y, z [m]
};

/// One wheel: its continuous joint, link, collision cylinder and inertial.
struct WheelDescription
{
  std::string joint_name;  ///< URDF joint name (e.g. "front_left_wheel")
  std::string link_name;   ///< URDF child link name
  /// Joint frame (= wheel link frame at zero angle) in the chassis frame.
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();  ///< unit rotation axis, joint frame
  /// Collision cylinder pose in the wheel link frame (cylinder along its local z).
  Eigen::Isometry3d collision_origin = Eigen::Isometry3d::Identity();
  double radius = 0.0;      ///< collision cylinder radius [m], > 0
  double width = 0.0;       ///< collision cylinder length [m], > 0
  MassProperties inertial;  ///< wheel link inertial
};

/// Everything the plant needs from the URDF.
struct RobotDescription
{
  std::string source;        ///< file path (or "<string>") the description was parsed from
  std::string robot_name;    ///< URDF robot name
  std::string base_link;     ///< root link (the odometry child frame, "base_link")
  std::string chassis_link;  ///< common parent link of the wheel joints
  std::string imu_link;      ///< IMU frame (chassis_link if the URDF has no such link)
  /// chassis_link frame in the base_link frame (composed fixed joints).
  Eigen::Isometry3d chassis_in_base = Eigen::Isometry3d::Identity();
  /// imu_link frame in the chassis_link frame.
  Eigen::Isometry3d imu_in_chassis = Eigen::Isometry3d::Identity();
  /// Chassis mass properties in the chassis_link frame, including every link fixed to it
  /// (and the root links above it) except the wheels.
  MassProperties chassis;
  std::vector<CollisionBox> chassis_boxes;          ///< chassis collision boxes (may be empty)
  std::array<WheelDescription, kNumWheels> wheels;  ///< in WheelIndex order

  /// Mean wheel radius [m].
  double wheelRadius() const;
  /// Lateral distance between the left and right wheel joints [m] (the track).
  double track() const;
  /// Total mass of chassis and wheels [kg].
  double totalMass() const;
};

/// URDF joint names of the four wheels, in WheelIndex order.
using WheelJointNames = std::array<std::string, kNumWheels>;

/// The Jackal's wheel joint names: front_left_wheel, front_right_wheel, rear_left_wheel,
/// rear_right_wheel.
WheelJointNames defaultWheelJointNames();

/**
 * \brief Read a URDF file with urdfdom and extract the plant's robot description.
 * \param path         URDF file path
 * \param wheel_joints the four wheel joint names, FL, FR, RL, RR
 * \param imu_link     IMU link name; if the URDF has no such link the chassis frame is used
 * \throws RobotDescriptionError naming the file and what is missing or malformed: file
 *         missing or unreadable, XML that urdfdom cannot parse, a wheel joint that is
 *         absent or not continuous/revolute, wheels with different parents, a wheel link
 *         without a collision cylinder or a positive-mass inertial, a chassis without
 *         mass, or a chassis attached to the root by a moving joint.
 */
RobotDescription loadRobotDescription(const std::string& path,
                                      const WheelJointNames& wheel_joints = defaultWheelJointNames(),
                                      const std::string& imu_link = "imu_link");

/**
 * \brief As loadRobotDescription(), from a URDF XML string.
 * \param xml    URDF document
 * \param source name used in error messages
 */
RobotDescription parseRobotDescription(const std::string& xml, const std::string& source = "<string>",
                                       const WheelJointNames& wheel_joints = defaultWheelJointNames(),
                                       const std::string& imu_link = "imu_link");

}  // namespace plant
}  // namespace jackal_aic
