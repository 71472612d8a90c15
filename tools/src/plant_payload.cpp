/**
 * \file plant_payload.cpp
 * \brief plant_payload: where a payload puts the Jackal's centre of mass, at which acceleration
 *        the robot then tips over its wheels, and the AIC's tip-over bound that keeps it on
 *        them (doc/usage.md, 'Payloads').
 *
 * Usage: plant_payload [--mass KG --position X,Y,Z] [--overlay PLANT.yaml]... [--set key=value]...
 *            [--urdf FILE] [--config PLANT.yaml] [--aic-config FILE] [--aic-set key=value]...
 *            [--margin F]
 * The payload is the plant YAML's `payload` (e.g. --overlay sim/config/variants/payload_20kg_forward.yaml),
 * or --mass and --position (base_link [m]) instead. Prints the centre of mass of chassis, wheels
 * and payload (URDF inertials), the wheels' contact lines, the quasi-static tip-over limits of a
 * rigid robot (a_tip = g d / h: d the horizontal distance of the centre of mass from the contact
 * line it tips over, h its height above the ground) over the front wheels, the rear wheels and
 * sideways, and turning in place about base_link (the centre of mass's w^2 |x| against the front or
 * rear limit), and the YAML overlay of the AIC's bounds at --margin (0.8) of the lower
 * of the front and rear limits: max_reference_deceleration_linear always (every belief model reads
 * it: the path's braking, forward or in reverse, and its speeding up in reverse, which tips the
 * robot over its front wheels as braking forward does), and max_reference_acceleration_linear
 * (speeding up forward) when the configuration (--aic-config, default config/default.yaml) reads it
 * (the goal and unbiased models) and it is above the bound. With the robot model, whose path speeds
 * up per wheel at the wheel loop's acceleration instead, a comment line says so when that is above
 * the rear limit's bound; and max_angular_speed (the node's set-point clamp, node key of the same
 * configuration) when a turn in place at it would pass margin x the limit. Suspension, tyre
 * compliance, the wheels' spin-up and a turn's axis away from base_link are left out: a lower
 * bound on stability is what the margin is for. A centre of mass outside the wheels' contact box
 * (the robot tips over at rest) is an error.
 * Exit 0 on success, 1 on bad files or parameters or a layout that tips over at rest, 2 on bad
 * arguments.
 */

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/params/param_schema.hpp"
#include "jackal_tools/cli.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_tools/share_path.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kGravity = 9.80665;  ///< [m/s^2]

/// Mass, centre of mass and the wheels' contact box of the robot with its payload (base_link [m]).
struct MassLayout
{
  double mass = 0.0;                              ///< chassis, wheels and payload [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  ///< centre of mass [m]
  double front = 0.0, rear = 0.0;                 ///< x of the front and rear wheel axles [m]
  double left = 0.0, right = 0.0;                 ///< y of the left and right wheels' centre planes [m]
  double ground = 0.0;                            ///< z of the ground under the wheels [m]
};

/**
 * \brief The robot's mass layout: the URDF's chassis with a point payload (mass [kg] >= 0 at
 *        position [m], base_link) composed as the plant composes it (plant::withPointMass, in the
 *        chassis frame), and the wheel inertials, in base_link through chassis_in_base and each
 *        wheel joint's origin. The contact box spans the wheel joints' x and y; the ground is the
 *        lowest wheel's centre less its radius.
 */
MassLayout massLayout(const plant::RobotDescription& d, double payload_mass, const Eigen::Vector3d& payload_position)
{
  MassLayout m;
  const plant::MassProperties chassis =
      plant::withPointMass(d.chassis, payload_mass, d.chassis_in_base.inverse() * payload_position);
  m.mass = chassis.mass;
  Eigen::Vector3d moment = chassis.mass * (d.chassis_in_base * chassis.com);
  m.front = m.left = -1e9;
  m.rear = m.right = m.ground = 1e9;
  for (const plant::WheelDescription& w : d.wheels)
  {
    const Eigen::Isometry3d joint = d.chassis_in_base * w.origin;
    m.mass += w.inertial.mass;
    moment += w.inertial.mass * (joint * w.inertial.com);
    const Eigen::Vector3d c = joint.translation();
    m.front = std::max(m.front, c.x());
    m.rear = std::min(m.rear, c.x());
    m.left = std::max(m.left, c.y());
    m.right = std::min(m.right, c.y());
    m.ground = std::min(m.ground, c.z() - w.radius);
  }
  m.com = moment / m.mass;
  return m;
}

/// The quasi-static tip-over acceleration over a contact line at horizontal distance d [m] from a
/// centre of mass h [m] above the ground: g d / h [m/s^2]; 0 when d <= 0 (it tips at rest).
double tipAcceleration(double d, double h)
{
  return d > 0.0 && h > 0.0 ? kGravity * d / h : 0.0;
}

/// Parse "X,Y,Z" (three finite numbers, nothing else) into *p. \return false if it is not that.
bool parsePosition(const std::string& text, Eigen::Vector3d* p)
{
  std::stringstream in(text);
  std::string part;
  int i = 0;
  while (std::getline(in, part, ','))
  {
    if (i >= 3)
    {
      return false;
    }
    try
    {
      std::size_t used = 0;
      (*p)(i) = std::stod(part, &used);
      if (used != part.size() || !std::isfinite((*p)(i)))
      {
        return false;
      }
    }
    catch (const std::exception&)
    {
      return false;
    }
    ++i;
  }
  return i == 3;
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string aic_config = packageFile("config/default.yaml");
  std::vector<std::string> aic_overrides;
  double mass = -1.0;
  std::string position_text;
  double margin = 0.8;
  CommandLine cl("plant_payload", "Where a payload puts the Jackal's centre of mass, the acceleration at which the "
                                  "robot then tips "
                                  "over its wheels (quasi-static, rigid: g d / h), and the AIC's reference-path bound "
                                  "that keeps it on "
                                  "them, as a YAML overlay.");
  plant.addTo(&cl);
  cl.option("mass", &mass, "payload mass [kg], in [0, 100] (instead of the plant YAML's payload.mass)");
  cl.option("position", &position_text, "payload position X,Y,Z in base_link [m] (with --mass)");
  cl.option("aic-config", &aic_config,
            "controller YAML whose belief model and max_reference_acceleration_linear are checked");
  cl.overrides("aic-set", &aic_overrides, "override a controller key");
  cl.option("margin", &margin, "the bounds' fraction of the lower tip-over limit, in (0, 1]");
  cl.footer("Exit 0 on success, 1 on bad files or parameters or a robot that tips over at rest, 2 on bad "
            "arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (!(margin > 0.0 && margin <= 1.0))
  {
    return cl.bad("--margin must be in (0, 1]");
  }
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  const bool given = mass >= 0.0 || !position_text.empty();
  if (given && (!(mass >= 0.0 && mass <= 100.0) || !parsePosition(position_text, &position) ||
                position.cwiseAbs().maxCoeff() > 1.0))
  {
    return cl.bad("--mass (in [0, 100] kg) and --position X,Y,Z (each in [-1, 1] m) go together");
  }
  plant::RobotDescription description;
  double accel = 0.0;         // the configuration's max_reference_acceleration_linear [m/s^2]
  bool reads_accel = false;   // the configuration's belief model reads that key (the schema's tag)
  bool robot_model = false;   // belief_model robot: its path's bound is the wheel loop's
  double wheel_accel = 0.0;   // the robot model's path bound per wheel at the rim [m/s^2]
  double max_yaw_rate = 0.0;  // the configuration's max_angular_speed [rad/s]
  try
  {
    description = plant.description();
    const plant::PlantParams params = plant.params();
    if (!given)
    {
      mass = params.payload.mass;
      position = Eigen::Vector3d(params.payload.position[0], params.payload.position[1], params.payload.position[2]);
    }
    const auto node = loadNodeParamsFiles({ aic_config }, aic_overrides);
    accel = node.aic.reference.max_acceleration_linear;
    const params::ParamSpec* accel_row = params::findParam("max_reference_acceleration_linear");
    reads_accel = accel_row != nullptr && accel_row->readBy(node.aic.belief_model);
    robot_model = node.aic.belief_model == params::BeliefModel::kRobot;
    wheel_accel = params::robotWheelAcceleration(node.aic);
    max_yaw_rate = node.max_angular_speed;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "plant_payload: %s\n", e.what());
    return 1;
  }
  const MassLayout m = massLayout(description, mass, position);
  const double h = m.com.z() - m.ground;
  const double front = tipAcceleration(m.front - m.com.x(), h);
  const double rear = tipAcceleration(m.com.x() - m.rear, h);
  const double side = tipAcceleration(std::min(m.left - m.com.y(), m.com.y() - m.right), h);
  std::printf("robot %.3f kg with a payload of %.3f kg at (%.3f, %.3f, %.3f) m in base_link: %.3f kg\n", m.mass - mass,
              mass, position.x(), position.y(), position.z(), m.mass);
  std::printf("centre of mass (%.4f, %.4f, %.4f) m in base_link, %.4f m above the ground\n", m.com.x(), m.com.y(),
              m.com.z(), h);
  std::printf("wheel contacts: axles at x %.4f and %.4f m, wheels at y %.4f and %.4f m, ground at z %.4f m\n", m.front,
              m.rear, m.left, m.right, m.ground);
  std::printf("tips over its front wheels above a deceleration of %.3f m/s^2 (braking forward, speeding up in "
              "reverse): %.4f m ahead over %.4f m up\n",
              front, m.front - m.com.x(), h);
  std::printf("tips over its rear wheels above an acceleration of %.3f m/s^2 (speeding up forward, braking in "
              "reverse): %.4f m behind over %.4f m up\n",
              rear, m.com.x() - m.rear, h);
  std::printf("tips sideways above a centripetal acceleration (speed x yaw rate) of %.3f m/s^2\n", side);
  if (!(front > 0.0 && rear > 0.0 && side > 0.0))
  {
    std::fprintf(stderr, "plant_payload: the centre of mass is outside the wheels' contact box: the robot tips over at "
                         "rest; no bound keeps it on its wheels\n");
    return 1;
  }
  // Turning in place about base_link, the centre of mass |x| off the turn's axis is accelerated
  // toward it at w^2 |x|: toward the rear for a load ahead (the front wheels' limit), and so on.
  const double x_com = m.com.x();
  const double spin_limit = x_com > 0.0 ? front : rear;
  const double spin =
      std::abs(x_com) > 1e-9 ? std::sqrt(spin_limit / std::abs(x_com)) : std::numeric_limits<double>::infinity();
  if (std::isfinite(spin))
  {
    std::printf("turning in place about base_link, tips over its %s wheels above a yaw rate of %.3f rad/s (w^2 |x|: "
                "the centre of mass %.4f m %s of the turn's axis)\n",
                x_com > 0.0 ? "front" : "rear", spin, std::abs(x_com), x_com > 0.0 ? "ahead" : "behind");
  }
  const double bound = margin * std::min(front, rear);
  std::printf("\n# YAML overlay for the AIC (plant_payload, margin %.2f of the lower tip-over limit; doc/usage.md, "
              "'Payloads')\n",
              margin);
  std::printf("max_reference_deceleration_linear: %.3f\n", bound);
  if (reads_accel && accel > bound)
  {
    std::printf("max_reference_acceleration_linear: %.3f  # was %.3f: speeding up forward\n", bound, accel);
  }
  const double spin_bound = std::sqrt(margin) * spin;  // w^2 |x| at margin x the limit
  if (spin_bound < max_yaw_rate)
  {
    std::printf("max_angular_speed: %.3f  # was %.3f: a turn in place\n", spin_bound, max_yaw_rate);
  }
  if (robot_model && margin * rear < wheel_accel)
  {
    std::printf("# belief_model robot: its path speeds up forward at up to %.3f m/s^2 (the wheel loop's); above "
                "%.3f m/s^2 this robot tips over its rear wheels: only the tip-over guard bounds that\n",
                wheel_accel, rear);
  }
  return 0;
}
