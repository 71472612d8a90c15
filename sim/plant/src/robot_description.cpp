#include "jackal_sim/plant/robot_description.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

namespace jackal_aic
{
namespace plant
{
namespace
{
Eigen::Isometry3d toIsometry(const urdf::Pose& p)
{
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  Eigen::Quaterniond q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  if (q.norm() < 1e-9)
  {
    q = Eigen::Quaterniond::Identity();
  }
  t.linear() = q.normalized().toRotationMatrix();
  return t;
}

/// Inertial of a URDF link expressed in the link frame (COM and inertia in link axes).
bool linkMass(const urdf::Link& link, MassProperties* out)
{
  if (!link.inertial)
  {
    return false;
  }
  const urdf::Inertial& in = *link.inertial;
  const Eigen::Isometry3d o = toIsometry(in.origin);
  Eigen::Matrix3d i_com;
  i_com << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  out->mass = in.mass;
  out->com = o.translation();
  out->inertia = o.linear() * i_com * o.linear().transpose();
  return true;
}

/// Combine two mass properties given in the same frame (parallel-axis theorem).
MassProperties combine(const MassProperties& a, const MassProperties& b)
{
  MassProperties c;
  c.mass = a.mass + b.mass;
  if (c.mass <= 0.0)
  {
    return c;
  }
  c.com = (a.mass * a.com + b.mass * b.com) / c.mass;
  auto shifted = [&c](const MassProperties& m) {
    const Eigen::Vector3d d = m.com - c.com;
    return Eigen::Matrix3d(m.inertia + m.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose()));
  };
  c.inertia = shifted(a) + shifted(b);
  return c;
}

/// Express mass properties given in frame B in frame A, where t = pose of B in A.
MassProperties transformed(const MassProperties& m, const Eigen::Isometry3d& t)
{
  MassProperties r;
  r.mass = m.mass;
  r.com = t * m.com;
  r.inertia = t.linear() * m.inertia * t.linear().transpose();
  return r;
}

bool isWheelJoint(const std::string& name, const WheelJointNames& names)
{
  for (const auto& n : names)
  {
    if (n == name)
    {
      return true;
    }
  }
  return false;
}

/// Add the inertials and collision boxes of `link` and every link fixed below it (pose of
/// `link` in the chassis frame = t) into the chassis; wheel subtrees are skipped.
void accumulateFixed(const urdf::Link& link, const Eigen::Isometry3d& t, const WheelJointNames& wheels,
                     RobotDescription* d)
{
  MassProperties m;
  if (linkMass(link, &m) && m.mass > 0.0)
  {
    d->chassis = combine(d->chassis, transformed(m, t));
  }
  for (const auto& col : link.collision_array)
  {
    if (col && col->geometry && col->geometry->type == urdf::Geometry::BOX)
    {
      const auto* box = static_cast<const urdf::Box*>(col->geometry.get());
      CollisionBox b;
      b.origin = t * toIsometry(col->origin);
      b.size = Eigen::Vector3d(box->dim.x, box->dim.y, box->dim.z);
      d->chassis_boxes.push_back(b);
    }
  }
  for (const auto& j : link.child_joints)
  {
    if (!j || isWheelJoint(j->name, wheels) || j->type != urdf::Joint::FIXED)
    {
      continue;
    }
    for (const auto& child : link.child_links)
    {
      if (child && child->name == j->child_link_name)
      {
        accumulateFixed(*child, t * toIsometry(j->parent_to_joint_origin_transform), wheels, d);
      }
    }
  }
}

std::string fail(const std::string& source, const std::string& what)
{
  return "URDF '" + source + "': " + what;
}

bool finiteMass(const MassProperties& m)
{
  return std::isfinite(m.mass) && m.com.allFinite() && m.inertia.allFinite();
}
}  // namespace

double RobotDescription::wheelRadius() const
{
  double sum = 0.0;
  for (const auto& w : wheels)
  {
    sum += w.radius;
  }
  return sum / kNumWheels;
}

double RobotDescription::track() const
{
  const double left = 0.5 * (wheels[kFrontLeft].origin.translation().y() + wheels[kRearLeft].origin.translation().y());
  const double right =
      0.5 * (wheels[kFrontRight].origin.translation().y() + wheels[kRearRight].origin.translation().y());
  return left - right;
}

double RobotDescription::totalMass() const
{
  double m = chassis.mass;
  for (const auto& w : wheels)
  {
    m += w.inertial.mass;
  }
  return m;
}

WheelJointNames defaultWheelJointNames()
{
  return { "front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel" };
}

RobotDescription loadRobotDescription(const std::string& path, const WheelJointNames& wheel_joints,
                                      const std::string& imu_link)
{
  std::ifstream in(path);
  if (!in.good())
  {
    throw RobotDescriptionError("URDF file '" + path + "' does not exist or cannot be read");
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return parseRobotDescription(ss.str(), path, wheel_joints, imu_link);
}

RobotDescription parseRobotDescription(const std::string& xml, const std::string& source,
                                       const WheelJointNames& wheel_joints, const std::string& imu_link)
{
  if (xml.find_first_not_of(" \t\r\n") == std::string::npos)
  {
    throw RobotDescriptionError(fail(source, "the file is empty"));
  }
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model)
  {
    throw RobotDescriptionError(fail(source, "malformed: urdfdom could not parse it (see its message above)"));
  }
  RobotDescription d;
  d.source = source;
  d.robot_name = model->getName();
  const urdf::LinkConstSharedPtr root = model->getRoot();
  if (!root)
  {
    throw RobotDescriptionError(fail(source, "has no root link"));
  }
  d.base_link = root->name;

  // Wheel joints: present, rotating, one common parent.
  std::string missing;
  for (const auto& name : wheel_joints)
  {
    if (!model->getJoint(name))
    {
      missing += (missing.empty() ? "" : ", ") + name;
    }
  }
  if (!missing.empty())
  {
    throw RobotDescriptionError(fail(source, "missing wheel joint(s): " + missing +
                                                 " (required: front_left_wheel, front_right_wheel, "
                                                 "rear_left_wheel, rear_right_wheel or the configured names)"));
  }
  for (int i = 0; i < kNumWheels; ++i)
  {
    const urdf::JointConstSharedPtr j = model->getJoint(wheel_joints[i]);
    if (j->type != urdf::Joint::CONTINUOUS && j->type != urdf::Joint::REVOLUTE)
    {
      throw RobotDescriptionError(fail(source, "wheel joint '" + j->name + "' must be continuous or revolute"));
    }
    if (i == 0)
    {
      d.chassis_link = j->parent_link_name;
    }
    else if (j->parent_link_name != d.chassis_link)
    {
      throw RobotDescriptionError(fail(source, "wheel joints must share one parent link; '" + j->name +
                                                   "' hangs from '" + j->parent_link_name + "', not '" +
                                                   d.chassis_link + "'"));
    }
    WheelDescription& w = d.wheels[i];
    w.joint_name = j->name;
    w.link_name = j->child_link_name;
    w.origin = toIsometry(j->parent_to_joint_origin_transform);
    Eigen::Vector3d axis(j->axis.x, j->axis.y, j->axis.z);
    if (!(axis.norm() > 1e-9) || !axis.allFinite())
    {
      throw RobotDescriptionError(fail(source, "wheel joint '" + j->name + "' has a zero axis"));
    }
    w.axis = axis.normalized();
    const urdf::LinkConstSharedPtr link = model->getLink(w.link_name);
    if (!link)
    {
      throw RobotDescriptionError(fail(source, "wheel link '" + w.link_name + "' is missing"));
    }
    bool found_cylinder = false;
    for (const auto& col : link->collision_array)
    {
      if (col && col->geometry && col->geometry->type == urdf::Geometry::CYLINDER)
      {
        const auto* cyl = static_cast<const urdf::Cylinder*>(col->geometry.get());
        w.radius = cyl->radius;
        w.width = cyl->length;
        w.collision_origin = toIsometry(col->origin);
        found_cylinder = true;
        break;
      }
    }
    if (!found_cylinder)
    {
      throw RobotDescriptionError(
          fail(source, "wheel link '" + w.link_name + "' has no collision cylinder (the wheel radius comes from it)"));
    }
    if (!(w.radius > 0.0) || !(w.width > 0.0) || !std::isfinite(w.radius) || !std::isfinite(w.width))
    {
      throw RobotDescriptionError(
          fail(source, "wheel link '" + w.link_name + "' has a collision cylinder with non-positive radius or length"));
    }
    if (!linkMass(*link, &w.inertial) || !(w.inertial.mass > 0.0) || !finiteMass(w.inertial))
    {
      throw RobotDescriptionError(fail(source, "wheel link '" + w.link_name + "' has no inertial with mass > 0"));
    }
  }

  // Chassis: the wheels' parent plus everything fixed to it.
  const urdf::LinkConstSharedPtr chassis = model->getLink(d.chassis_link);
  if (!chassis)
  {
    throw RobotDescriptionError(fail(source, "chassis link '" + d.chassis_link + "' is missing"));
  }
  accumulateFixed(*chassis, Eigen::Isometry3d::Identity(), wheel_joints, &d);

  // Walk up to the root: chassis_in_base, and fold the inertials of the links above.
  Eigen::Isometry3d chassis_in_base = Eigen::Isometry3d::Identity();
  for (urdf::LinkConstSharedPtr l = chassis; l->getParent();)
  {
    const urdf::JointConstSharedPtr j = l->parent_joint;
    if (!j || j->type != urdf::Joint::FIXED)
    {
      throw RobotDescriptionError(fail(source, "chassis link '" + d.chassis_link + "' must be attached to the root '" +
                                                   d.base_link + "' by fixed joints only"));
    }
    chassis_in_base = toIsometry(j->parent_to_joint_origin_transform) * chassis_in_base;
    l = l->getParent();
    MassProperties m;
    if (linkMass(*l, &m) && m.mass > 0.0)
    {
      d.chassis = combine(d.chassis, transformed(m, chassis_in_base.inverse()));
    }
  }
  d.chassis_in_base = chassis_in_base;
  if (!(d.chassis.mass > 0.0) || !finiteMass(d.chassis))
  {
    throw RobotDescriptionError(fail(source, "chassis link '" + d.chassis_link + "' has no inertial with mass > 0"));
  }

  // IMU frame: the named link if fixed to the chassis, else the chassis frame.
  d.imu_link = d.chassis_link;
  if (model->getLink(imu_link))
  {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    urdf::LinkConstSharedPtr l = model->getLink(imu_link);
    bool ok = true;
    while (l && l->name != d.chassis_link)
    {
      const urdf::JointConstSharedPtr j = l->parent_joint;
      if (!j || j->type != urdf::Joint::FIXED)
      {
        ok = false;
        break;
      }
      t = toIsometry(j->parent_to_joint_origin_transform) * t;
      l = l->getParent();
    }
    if (!ok || !l)
    {
      throw RobotDescriptionError(fail(source, "IMU link '" + imu_link + "' is not fixed to '" + d.chassis_link + "'"));
    }
    d.imu_link = imu_link;
    d.imu_in_chassis = t;
  }
  return d;
}

/// The mass properties of `body` (in its link frame) with a point mass `mass` [kg] added at
/// `position` (link frame) [m]: masses add, the centre of mass is their weighted mean, and each
/// part's inertia moves to the new centre by the parallel-axis theorem, I + m ((d.d) 1 - d d^T).
MassProperties withPointMass(const MassProperties& body, double mass, const Eigen::Vector3d& position)
{
  MassProperties out;
  out.mass = body.mass + mass;
  out.com = (body.mass * body.com + mass * position) / out.mass;
  auto shift = [](double m, const Eigen::Vector3d& d) {
    return (m * (d.dot(d) * Eigen::Matrix3d::Identity() - d * d.transpose())).eval();
  };
  out.inertia = body.inertia + shift(body.mass, body.com - out.com) + shift(mass, position - out.com);
  return out;
}

}  // namespace plant
}  // namespace jackal_aic
