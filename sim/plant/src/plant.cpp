#include "jackal_sim/plant/plant.hpp"

#include <cmath>
#include <mutex>
#include <stdexcept>

#include <ode/ode.h>

#include "jackal_sim/plant/tyre_contact.hpp"

namespace jackal_aic
{
namespace plant
{
namespace
{
/// Constraint force mixing of the drivetrain friction row [(rad/s) / (N m)]: a wheel held by its
/// Coulomb friction (0.16 N m) creeps at ~2e-5 rad/s.
constexpr double kFrictionCfm = 1e-4;

/// ODE needs one global initialisation; kept for the life of the process.
void initOdeOnce()
{
  static std::once_flag flag;
  std::call_once(flag, [] { dInitODE2(0); });
}

void toOde(const Eigen::Quaterniond& q, dQuaternion out)
{
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

Eigen::Isometry3d bodyPose(dBodyID b)
{
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return t;
}

Eigen::Vector3d vec(const dReal* v)
{
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

dBodyID makeBody(dWorldID world, const MassProperties& m, const Eigen::Isometry3d& link_pose)
{
  dBodyID b = dBodyCreate(world);
  dMass mass;
  dMassSetZero(&mass);
  const Eigen::Matrix3d& I = m.inertia;
  dMassSetParameters(&mass, m.mass, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  dBodySetMass(b, &mass);
  // ODE bodies sit at their centre of mass, with the link's axes.
  const Eigen::Vector3d com_world = link_pose * m.com;
  dBodySetPosition(b, com_world.x(), com_world.y(), com_world.z());
  dQuaternion q;
  toOde(Eigen::Quaterniond(link_pose.linear()), q);
  dBodySetQuaternion(b, q);
  dBodySetAutoDisableFlag(b, 0);
  return b;
}

/// Attach a geom to a body at `pose_in_link` (pose of the geom in the link frame; the
/// body origin is the link's COM).
void attachGeom(dGeomID g, dBodyID b, const Eigen::Vector3d& com, const Eigen::Isometry3d& pose_in_link)
{
  dGeomSetBody(g, b);
  const Eigen::Vector3d p = pose_in_link.translation() - com;
  dGeomSetOffsetPosition(g, p.x(), p.y(), p.z());
  dQuaternion q;
  toOde(Eigen::Quaterniond(pose_in_link.linear()), q);
  dGeomSetOffsetQuaternion(g, q);
}
}  // namespace

struct Plant::Ode
{
  dWorldID world = nullptr;
  dJointGroupID contacts = nullptr;
  dGeomID ground = nullptr;
  dBodyID chassis = nullptr;
  std::vector<dGeomID> chassis_geoms;
  std::array<dBodyID, kNumWheels> wheel{};
  std::array<dGeomID, kNumWheels> wheel_geom{};
  std::array<dJointID, kNumWheels> hinge{};
  std::vector<dContactGeom> scratch;
  /// Force feedback of each wheel's contact joint in the current step (the "slip" model's normal loads).
  std::array<dJointFeedback, kNumWheels> feedback{};
  /// Whether wheel i has a contact joint (and so feedback) in the current step.
  std::array<bool, kNumWheels> in_contact{};
  /// The ground normal of wheel i's contact in the current step.
  std::array<Eigen::Vector3d, kNumWheels> contact_normal{};
  double erp = 0.2;
  double cfm = 1e-5;

  ~Ode()
  {
    for (auto g : chassis_geoms)
    {
      dGeomDestroy(g);
    }
    for (auto g : wheel_geom)
    {
      if (g)
      {
        dGeomDestroy(g);
      }
    }
    if (ground)
    {
      dGeomDestroy(ground);
    }
    if (contacts)
    {
      dJointGroupDestroy(contacts);
    }
    if (world)
    {
      dWorldDestroy(world);  // also destroys bodies and joints
    }
  }
};

Plant::Plant(const RobotDescription& description, const PlantParams& params, double accel_window)
  : description_(description)
  , params_(params)
  , ode_(std::make_unique<Ode>())
  , servo_{ WheelSpeedServo(params.motor, params.physics.step), WheelSpeedServo(params.motor, params.physics.step) }
{
  const auto errors = params_.validate();
  if (!errors.empty())
  {
    std::string msg = "invalid plant parameters:";
    for (const auto& e : errors)
    {
      msg += " " + e + ";";
    }
    throw std::invalid_argument(msg);
  }
  if (!(accel_window >= params_.physics.step) || !std::isfinite(accel_window))
  {
    throw std::invalid_argument("accelerometer window must be >= the physics step");
  }
  if (params_.payload.mass > 0.0)
  {
    const Eigen::Vector3d p(params_.payload.position[0], params_.payload.position[1], params_.payload.position[2]);
    description_.chassis =
        withPointMass(description_.chassis, params_.payload.mass, description_.chassis_in_base.inverse() * p);
  }
  const auto window_steps = static_cast<std::size_t>(std::lround(accel_window / params_.physics.step));
  vel_ring_.assign(window_steps + 1, Eigen::Vector3d::Zero());
  initOdeOnce();
  build();
}

Plant::~Plant() = default;

void Plant::build()
{
  Ode& o = *ode_;
  const double h = params_.physics.step;
  const ContactParams& c = params_.contact;
  o.world = dWorldCreate();
  dWorldSetGravity(o.world, 0, 0, -params_.physics.gravity);
  // Gazebo's mapping of (kp, kd) onto ODE's ERP and CFM for a step h.
  o.erp = h * c.kp / (h * c.kp + c.kd);
  o.cfm = 1.0 / (h * c.kp + c.kd);
  dWorldSetERP(o.world, 0.2);
  dWorldSetCFM(o.world, 1e-10);
  dWorldSetContactMaxCorrectingVel(o.world, c.max_correcting_vel);
  dWorldSetContactSurfaceLayer(o.world, c.surface_layer);
  o.contacts = dJointGroupCreate(0);
  o.ground = dCreatePlane(nullptr, 0, 0, 1, 0);
  o.scratch.resize(static_cast<std::size_t>(c.max_contacts));

  // Place chassis_link so that the lowest wheel touches the ground.
  double height = 0.0;
  for (const auto& w : description_.wheels)
  {
    height = std::max(height, w.radius - w.origin.translation().z());
  }
  height += params_.physics.initial_clearance;
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Eigen::Vector3d(params_.physics.initial_x, params_.physics.initial_y, 0.0);
  base.linear() = Eigen::AngleAxisd(params_.physics.initial_yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d chassis_pose = base * description_.chassis_in_base;
  chassis_pose.translation().z() = height;

  o.chassis = makeBody(o.world, description_.chassis, chassis_pose);
  for (const auto& box : description_.chassis_boxes)
  {
    dGeomID g = dCreateBox(nullptr, box.size.x(), box.size.y(), box.size.z());
    attachGeom(g, o.chassis, description_.chassis.com, box.origin);
    o.chassis_geoms.push_back(g);
  }

  for (int i = 0; i < kNumWheels; ++i)
  {
    const WheelDescription& w = description_.wheels[i];
    const Eigen::Isometry3d wheel_pose = chassis_pose * w.origin;
    o.wheel[i] = makeBody(o.world, w.inertial, wheel_pose);
    o.wheel_geom[i] = dCreateCylinder(nullptr, w.radius, w.width);
    attachGeom(o.wheel_geom[i], o.wheel[i], w.inertial.com, w.collision_origin);

    o.hinge[i] = dJointCreateHinge(o.world, nullptr);
    // Wheel first: ODE's hinge rate is body1 - body2 about the axis and the hinge torque
    // acts positively on body1, so positive values spin the wheel forward.
    dJointAttach(o.hinge[i], o.wheel[i], o.chassis);
    const Eigen::Vector3d anchor = wheel_pose.translation();
    const Eigen::Vector3d axis = wheel_pose.linear() * w.axis;
    dJointSetHingeAnchor(o.hinge[i], anchor.x(), anchor.y(), anchor.z());
    dJointSetHingeAxis(o.hinge[i], axis.x(), axis.y(), axis.z());
    // Drivetrain Coulomb friction as an ODE joint motor held at zero speed (implicit,
    // stable at any friction level; the same as Gazebo's joint friction).
    dJointSetHingeParam(o.hinge[i], dParamVel, 0.0);
    dJointSetHingeParam(o.hinge[i], dParamFMax, params_.motor.coulomb_friction);
    // The friction row's constraint force mixing (ODE applies dParamCFM to a powered hinge's motor
    // row): a held wheel creeps at kFrictionCfm times its friction torque. Without it (the world's CFM,
    // 1e-10) a wheel held exactly at its break-away torque is a degenerate LCP (the row at its bound
    // with zero velocity): ODE's Dantzig solver then reports "LCP internal error, s <= 0".
    dJointSetHingeParam(o.hinge[i], dParamCFM, kFrictionCfm);
    last_raw_angle_[i] = dJointGetHingeAngle(o.hinge[i]);
    wheel_angle_[i] = 0.0;
  }
  // The "slip" model's normal loads start from the static share of the robot's weight; from the
  // first step on they are each wheel's contact force of the step before.
  double robot_mass = description_.chassis.mass;
  for (const auto& w : description_.wheels)
  {
    robot_mass += w.inertial.mass;
  }
  wheel_load_.fill(robot_mass * params_.physics.gravity / kNumWheels);
  updateImu();
  // Start the accelerometer window at rest.
  const Eigen::Isometry3d imu_pose = basePose() * description_.chassis_in_base * description_.imu_in_chassis;
  dVector3 v;
  dBodyGetPointVel(o.chassis, imu_pose.translation().x(), imu_pose.translation().y(), imu_pose.translation().z(), v);
  for (auto& e : vel_ring_)
  {
    e = vec(v);
  }
  updateImu();
}

bool Plant::setWheelSpeeds(double left, double right)
{
  if (!std::isfinite(left) || !std::isfinite(right))
  {
    return false;
  }
  servo_[kLeft].setSetpoint(left, time());
  servo_[kRight].setSetpoint(right, time());
  return true;
}

void Plant::releaseMotors()
{
  servo_[kLeft].release(time());
  servo_[kRight].release(time());
}

double Plant::wheelVelocity(int i) const
{
  return dJointGetHingeAngleRate(ode_->hinge[i]);
}

double Plant::sideVelocity(Side side) const
{
  return side == kLeft ? 0.5 * (wheelVelocity(kFrontLeft) + wheelVelocity(kRearLeft)) :
                         0.5 * (wheelVelocity(kFrontRight) + wheelVelocity(kRearRight));
}

void Plant::collide()
{
  Ode& o = *ode_;
  const ContactParams& c = params_.contact;
  const int max_contacts = c.max_contacts;
  const bool slip_model = c.friction_model == "slip";
  const bool cone = c.friction_model == "cone" || slip_model;
  for (int i = 0; i < kNumWheels; ++i)
  {
    o.in_contact[i] = false;
    const int n = dCollide(o.wheel_geom[i], o.ground, max_contacts, o.scratch.data(), sizeof(dContactGeom));
    if (n <= 0)
    {
      continue;
    }
    // One contact per wheel: ODE's cylinder-plane collider gives the tyre's two edges; they are
    // merged into one point at their mean position with the deepest penetration. Two rows of
    // friction per edge made the LCP degenerate whenever one edge carried no load (a pair of
    // friction rows bounded by a zero normal force: ODE's "LCP internal error, s <= 0"); the hinge
    // holds the wheel's camber, so one point loses nothing the model has.
    dContact contact{};
    contact.geom = o.scratch[0];
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    for (int k = 0; k < n; ++k)
    {
      position += vec(o.scratch[k].pos);
      contact.geom.depth = std::max(contact.geom.depth, o.scratch[k].depth);
    }
    position /= n;
    for (int d = 0; d < 3; ++d)
    {
      contact.geom.pos[d] = position[d];
    }
    // Rolling direction: perpendicular to the wheel axle, in the ground plane.
    dVector3 axis;
    dJointGetHingeAxis(o.hinge[i], axis);
    const Eigen::Vector3d a = vec(axis);
    contact.surface.mode = dContactMu2 | dContactSoftERP | dContactSoftCFM | dContactApprox1;
    contact.surface.soft_erp = o.erp;
    contact.surface.soft_cfm = o.cfm;
    const Eigen::Vector3d normal = vec(contact.geom.normal);
    // Sliding velocity of the tyre over the (static) ground at the contact point,
    // tangential part, from the state at the start of this step.
    dVector3 pv;
    dBodyGetPointVel(o.wheel[i], position.x(), position.y(), position.z(), pv);
    Eigen::Vector3d sliding = vec(pv);
    sliding -= sliding.dot(normal) * normal;
    // Friction pyramid: mu1 N along fdir1, mu2 N across, each with its force-dependent
    // slip. "pyramid": fdir1 is the wheel's rolling direction (perpendicular to the axle, in the
    // ground plane), as in Gazebo. "cone" and "slip": fdir1 follows the contact's sliding velocity,
    // so with mu1 = mu2 and slip1 = slip2 the friction force opposes the sliding whatever its
    // direction (isotropic friction); a contact that hardly slides keeps the rolling direction.
    // "cone": the constant slip1 = slip2 (a tyre compliance in m/s per N). "slip": ODE's slip from
    // the brush tyre law at the wheel's current slip and normal load (tyre_contact.hpp).
    const Eigen::Vector3d rolling_dir = a.cross(normal);
    Eigen::Vector3d fdir = rolling_dir;
    if (cone && sliding.norm() > c.sliding_threshold)
    {
      fdir = sliding;
    }
    const double mu1 = c.mu1 * friction_scale_[kWheelSide[i]];
    contact.surface.mu = mu1;
    contact.surface.mu2 = c.mu2 * friction_scale_[kWheelSide[i]];
    double slip1 = c.slip1;
    double slip2 = c.slip2;
    if (slip_model && mu1 > 0.0 && rolling_dir.norm() > 1e-6)
    {
      // Wheel centre's ground velocity along the rolling direction and the rolling speed of its spin
      // (the wheel body's angular velocity about its axle: the hinge rate plus the chassis's).
      const Eigen::Vector3d centre = vec(dBodyGetLinearVel(o.wheel[i]));
      const double forward = centre.dot(rolling_dir.normalized());
      const double spin = vec(dBodyGetAngularVel(o.wheel[i])).dot(a.normalized());
      const WheelSlip ws = wheelSlip(forward, spin * description_.wheels[i].radius, sliding.norm(), c.slip_min_speed);
      const double load = std::max(wheel_load_[i], kMinWheelLoad);
      const OdeSlip ode_slip = odeSlip(ws, c.slip_stiffness, mu1, load);
      slip1 = ode_slip.along;
      slip2 = ode_slip.across;
      wheel_slip_[i] = ws.slip;
    }
    if (slip1 > 0.0)
    {
      contact.surface.mode |= dContactSlip1;
      contact.surface.slip1 = slip1;
    }
    if (slip2 > 0.0)
    {
      contact.surface.mode |= dContactSlip2;
      contact.surface.slip2 = slip2;
    }
    if (fdir.norm() > 1e-6)
    {
      fdir.normalize();
      contact.surface.mode |= dContactFDir1;
      contact.fdir1[0] = fdir.x();
      contact.fdir1[1] = fdir.y();
      contact.fdir1[2] = fdir.z();
    }
    dJointID j = dJointCreateContact(o.world, o.contacts, &contact);
    dJointAttach(j, dGeomGetBody(contact.geom.g1), dGeomGetBody(contact.geom.g2));
    o.feedback[i] = dJointFeedback{};
    dJointSetFeedback(j, &o.feedback[i]);
    o.in_contact[i] = true;
    o.contact_normal[i] = normal;
  }
  for (dGeomID g : o.chassis_geoms)
  {
    const int n = dCollide(g, o.ground, max_contacts, o.scratch.data(), sizeof(dContactGeom));
    for (int k = 0; k < n; ++k)
    {
      dContact contact{};
      contact.geom = o.scratch[k];
      contact.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
      contact.surface.mu = c.mu1;
      contact.surface.soft_erp = o.erp;
      contact.surface.soft_cfm = o.cfm;
      dJointID j = dJointCreateContact(o.world, o.contacts, &contact);
      dJointAttach(j, dGeomGetBody(contact.geom.g1), dGeomGetBody(contact.geom.g2));
    }
  }
}

bool Plant::setFrictionScale(Side side, double scale)
{
  if (!std::isfinite(scale) || scale < 0.0 || scale > 10.0)
  {
    return false;
  }
  friction_scale_[side] = scale;
  return true;
}

bool Plant::setPayload(double payload)
{
  if (!std::isfinite(payload) || payload < 0.0 || payload > 1000.0)
  {
    return false;
  }
  dMass m;
  dBodyGetMass(ode_->chassis, &m);
  if (chassis_mass_ <= 0.0)
  {
    chassis_mass_ = m.mass;
  }
  dMassAdjust(&m, chassis_mass_ + payload);
  dBodySetMass(ode_->chassis, &m);
  payload_ = payload;
  return true;
}

void Plant::step()
{
  Ode& o = *ode_;
  const double t = time();
  const MotorParams& m = params_.motor;
  std::array<double, kNumWheels> w{};
  for (int i = 0; i < kNumWheels; ++i)
  {
    w[i] = wheelVelocity(i);
  }
  // MCU loop per side: one motor drives the front and rear wheel; torque split evenly.
  const double tau_left = servo_[kLeft].update(0.5 * (w[kFrontLeft] + w[kRearLeft]), t);
  const double tau_right = servo_[kRight].update(0.5 * (w[kFrontRight] + w[kRearRight]), t);
  for (int i = 0; i < kNumWheels; ++i)
  {
    const double side_torque = kWheelSide[i] == kLeft ? tau_left : tau_right;
    const int partner = i < 2 ? i + 2 : i - 2;  // the other wheel on the same side
    double tau = 0.5 * side_torque - m.viscous_friction * w[i] + m.coupling_damping * (w[partner] - w[i]);
    wheel_torque_[i] = 0.5 * side_torque;
    dJointAddHingeTorque(o.hinge[i], tau);
  }
  collide();
  dWorldStep(o.world, params_.physics.step);
  // Normal load of each wheel: the normal part of its contact force in this step (the contact can
  // only push); 0 for a wheel off the ground.
  for (int i = 0; i < kNumWheels; ++i)
  {
    wheel_load_[i] = o.in_contact[i] ? std::abs(vec(o.feedback[i].f1).dot(o.contact_normal[i])) : 0.0;
  }
  dJointGroupEmpty(o.contacts);
  ++steps_;
  for (int i = 0; i < kNumWheels; ++i)
  {
    const double raw = dJointGetHingeAngle(o.hinge[i]);
    double d = raw - last_raw_angle_[i];
    d = std::remainder(d, 2.0 * M_PI);
    wheel_angle_[i] += d;
    last_raw_angle_[i] = raw;
  }
  updateImu();
}

void Plant::step(std::uint64_t n)
{
  for (std::uint64_t k = 0; k < n; ++k)
  {
    step();
  }
}

Eigen::Isometry3d Plant::basePose() const
{
  // chassis_link pose = body pose with the COM offset removed.
  Eigen::Isometry3d chassis = bodyPose(ode_->chassis);
  chassis.translation() -= chassis.linear() * description_.chassis.com;
  return chassis * description_.chassis_in_base.inverse();
}

Eigen::Vector3d Plant::baseLinearVelocity() const
{
  const Eigen::Isometry3d base = basePose();
  dVector3 v;
  dBodyGetPointVel(ode_->chassis, base.translation().x(), base.translation().y(), base.translation().z(), v);
  return base.linear().transpose() * vec(v);
}

Eigen::Vector3d Plant::baseAngularVelocity() const
{
  return basePose().linear().transpose() * vec(dBodyGetAngularVel(ode_->chassis));
}

void Plant::updateImu()
{
  const Eigen::Isometry3d imu_pose = basePose() * description_.chassis_in_base * description_.imu_in_chassis;
  dVector3 v;
  dBodyGetPointVel(ode_->chassis, imu_pose.translation().x(), imu_pose.translation().y(), imu_pose.translation().z(),
                   v);
  // Ring holds the last N+1 velocities; mean acceleration over the window = (v_now - v_old) / T.
  ring_head_ = (ring_head_ + 1) % vel_ring_.size();
  vel_ring_[ring_head_] = vec(v);
  const std::size_t oldest = (ring_head_ + 1) % vel_ring_.size();
  const double window = static_cast<double>(vel_ring_.size() - 1) * params_.physics.step;
  const Eigen::Vector3d accel_world = (vel_ring_[ring_head_] - vel_ring_[oldest]) / window;
  const Eigen::Vector3d gravity(0.0, 0.0, -params_.physics.gravity);
  const Eigen::Matrix3d r = imu_pose.linear();
  imu_.orientation = Eigen::Quaterniond(r).normalized();
  imu_.angular_velocity = r.transpose() * vec(dBodyGetAngularVel(ode_->chassis));
  imu_.linear_acceleration = r.transpose() * (accel_world - gravity);
}

}  // namespace plant
}  // namespace jackal_aic
