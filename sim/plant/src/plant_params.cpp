#include "jackal_sim/plant/plant_params.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "jackal_aic/overrides/yaml_overrides.hpp"

namespace jackal_aic
{
namespace plant
{
namespace
{
std::string num(double v)
{
  std::ostringstream s;
  s << v;
  return s.str();
}

void check(std::vector<std::string>* e, bool ok, const std::string& key, double v, const std::string& range)
{
  if (!ok || !std::isfinite(v))
  {
    e->push_back(key + " = " + num(v) + " (allowed: " + range + ")");
  }
}

void append(std::vector<std::string>* to, const std::vector<std::string>& from)
{
  to->insert(to->end(), from.begin(), from.end());
}

/// Reads the keys of one YAML map into fields; records malformed values and unknown keys.
class Section
{
public:
  Section(const YAML::Node& node, std::string prefix, std::vector<std::string>* errors)
    : node_(node), prefix_(std::move(prefix)), errors_(errors)
  {
    if (node_ && !node_.IsMap() && !node_.IsNull())
    {
      errors_->push_back(prefix_ + " must be a map");
      node_ = YAML::Node();
    }
  }
  ~Section()
  {
    if (!node_ || !node_.IsMap())
    {
      return;
    }
    for (const auto& kv : node_)
    {
      const std::string k = kv.first.as<std::string>();
      if (known_.count(k) == 0)
      {
        errors_->push_back(prefix_ + "." + k + " is not a known parameter");
      }
    }
  }
  template <typename T>
  void get(const std::string& key, T* value)
  {
    known_.insert(key);
    if (!node_ || !node_.IsMap() || !node_[key])
    {
      return;
    }
    try
    {
      *value = node_[key].as<T>();
    }
    catch (const YAML::Exception&)
    {
      errors_->push_back(prefix_ + "." + key + " has a malformed value");
    }
  }
  void get3(const std::string& key, std::array<double, 3>* value)
  {
    known_.insert(key);
    if (!node_ || !node_.IsMap() || !node_[key])
    {
      return;
    }
    const YAML::Node n = node_[key];
    try
    {
      if (!n.IsSequence() || n.size() != 3)
      {
        throw YAML::Exception(YAML::Mark(), "size");
      }
      for (int i = 0; i < 3; ++i)
      {
        (*value)[i] = n[i].as<double>();
      }
    }
    catch (const YAML::Exception&)
    {
      errors_->push_back(prefix_ + "." + key + " must be a list of 3 numbers");
    }
  }
  Section sub(const std::string& key)
  {
    known_.insert(key);
    return Section(node_ && node_.IsMap() ? node_[key] : YAML::Node(), prefix_ + "." + key, errors_);
  }

private:
  YAML::Node node_;
  std::string prefix_;
  std::vector<std::string>* errors_;
  std::set<std::string> known_;
};

void readStream(Section& s, StreamParams* p)
{
  s.get("rate", &p->rate);
  s.get("delay", &p->delay);
  s.get("dropout", &p->dropout);
}

}  // namespace

std::vector<std::string> PhysicsParams::validate() const
{
  std::vector<std::string> e;
  check(&e, step > 0.0 && step <= 0.01, "physics.step", step, "(0, 0.01] s");
  check(&e, gravity > 0.0 && gravity < 100.0, "physics.gravity", gravity, "(0, 100) m/s^2");
  check(&e, true, "physics.initial_x", initial_x, "finite m");
  check(&e, true, "physics.initial_y", initial_y, "finite m");
  check(&e, true, "physics.initial_yaw", initial_yaw, "finite rad");
  check(&e, initial_clearance >= 0.0 && initial_clearance <= 1.0, "physics.initial_clearance", initial_clearance,
        "[0, 1] m");
  return e;
}

std::vector<std::string> ContactParams::validate() const
{
  std::vector<std::string> e;
  if (friction_model != "slip" && friction_model != "cone" && friction_model != "pyramid")
  {
    e.push_back("contact.friction_model = '" + friction_model + "' (allowed: slip, cone, pyramid)");
  }
  check(&e, sliding_threshold > 0.0 && sliding_threshold <= 1.0, "contact.sliding_threshold", sliding_threshold,
        "(0, 1] m/s");
  if (friction_model == "cone" && (mu1 != mu2 || slip1 != slip2))
  {
    e.push_back("contact.friction_model = cone needs isotropic friction: mu1 = " + num(mu1) + ", mu2 = " + num(mu2) +
                ", slip1 = " + num(slip1) + ", slip2 = " + num(slip2) + " (allowed: mu1 = mu2 and slip1 = slip2)");
  }
  if (friction_model == "slip" && mu1 != mu2)
  {
    e.push_back("contact.friction_model = slip needs isotropic friction: mu1 = " + num(mu1) + ", mu2 = " + num(mu2) +
                " (allowed: mu1 = mu2)");
  }
  check(&e, slip_stiffness > 0.0 && slip_stiffness <= 1000.0, "contact.slip_stiffness", slip_stiffness,
        "(0, 1000] (force over normal load per unit slip)");
  check(&e, slip_min_speed > 0.0 && slip_min_speed <= 1.0, "contact.slip_min_speed", slip_min_speed, "(0, 1] m/s");
  check(&e, mu1 >= 0.0 && mu1 <= 100.0, "contact.mu1", mu1, "[0, 100]");
  check(&e, mu2 >= 0.0 && mu2 <= 100.0, "contact.mu2", mu2, "[0, 100]");
  check(&e, slip1 >= 0.0 && slip1 <= 1.0, "contact.slip1", slip1, "[0, 1] m/(s N)");
  check(&e, slip2 >= 0.0 && slip2 <= 1.0, "contact.slip2", slip2, "[0, 1] m/(s N)");
  check(&e, kp > 0.0, "contact.kp", kp, "> 0 N/m");
  check(&e, kd >= 0.0, "contact.kd", kd, ">= 0 N s/m");
  check(&e, max_correcting_vel > 0.0, "contact.max_correcting_vel", max_correcting_vel, "> 0 m/s");
  check(&e, surface_layer >= 0.0 && surface_layer < 0.05, "contact.surface_layer", surface_layer, "[0, 0.05) m");
  check(&e, max_contacts >= 1 && max_contacts <= 16, "contact.max_contacts", max_contacts, "[1, 16]");
  return e;
}

std::vector<std::string> MotorParams::validate() const
{
  std::vector<std::string> e;
  check(&e, speed_kp >= 0.0, "motor.speed_kp", speed_kp, ">= 0 N m s/rad");
  check(&e, speed_ki >= 0.0, "motor.speed_ki", speed_ki, ">= 0 N m/rad");
  check(&e, speed_kp > 0.0 || speed_ki > 0.0, "motor.speed_kp", speed_kp, "speed_kp or speed_ki > 0");
  check(&e, max_torque > 0.0, "motor.max_torque", max_torque, "> 0 N m");
  check(&e, integral_limit >= 0.0, "motor.integral_limit", integral_limit, ">= 0 N m (0 = max_torque)");
  check(&e, integral_error_limit >= 0.0, "motor.integral_error_limit", integral_error_limit, ">= 0 rad/s (0 = none)");
  check(&e, proportional_limit >= 0.0, "motor.proportional_limit", proportional_limit, ">= 0 N m (0 = none)");
  check(&e, setpoint_feedforward >= 0.0 && setpoint_feedforward <= 100.0, "motor.setpoint_feedforward",
        setpoint_feedforward, "[0, 100] N m s/rad (0 = off)");
  check(&e, accel_feedforward >= 0.0 && accel_feedforward <= 10.0, "motor.accel_feedforward", accel_feedforward,
        "[0, 10] N m s^2/rad (0 = off)");
  check(&e, accel_feedforward_limit >= 0.0 && accel_feedforward_limit <= 100.0, "motor.accel_feedforward_limit",
        accel_feedforward_limit, "[0, 100] N m (0 = none)");
  check(&e, load_observer_time_constant >= 0.0 && load_observer_time_constant <= 5.0,
        "motor.load_observer_time_constant", load_observer_time_constant, "[0, 5] s (0 = no observer)");
  check(&e, load_observer_time_constant == 0.0 || (load_observer_inertia > 0.0 && load_observer_inertia <= 10.0),
        "motor.load_observer_inertia", load_observer_inertia, "(0, 10] kg m^2 when the observer is on");
  check(&e, stall_torque >= 0.0, "motor.stall_torque", stall_torque, ">= 0 N m (0 = no voltage limit)");
  check(&e, stall_torque == 0.0 || no_load_speed > 0.0, "motor.no_load_speed", no_load_speed,
        "> 0 rad/s when stall_torque > 0");
  check(&e, setpoint_slew_rate >= 0.0, "motor.setpoint_slew_rate", setpoint_slew_rate, ">= 0 rad/s^2 (0 = none)");
  check(&e, setpoint_time_constant >= 0.0 && setpoint_time_constant <= 5.0, "motor.setpoint_time_constant",
        setpoint_time_constant, "[0, 5] s");
  check(&e, command_delay >= 0.0 && command_delay <= 0.5, "motor.command_delay", command_delay, "[0, 0.5] s");
  check(&e, coulomb_friction >= 0.0, "motor.coulomb_friction", coulomb_friction, ">= 0 N m");
  check(&e, viscous_friction >= 0.0, "motor.viscous_friction", viscous_friction, ">= 0 N m s/rad");
  check(&e, coupling_damping >= 0.0, "motor.coupling_damping", coupling_damping, ">= 0 N m s/rad");
  check(&e, max_wheel_speed > 0.0, "motor.max_wheel_speed", max_wheel_speed, "> 0 rad/s");
  return e;
}

std::vector<std::string> PayloadParams::validate() const
{
  std::vector<std::string> e;
  check(&e, mass >= 0.0 && mass <= 100.0, "payload.mass", mass, "[0, 100] kg");
  for (int i = 0; i < 3; ++i)
  {
    check(&e, std::abs(position[i]) <= 1.0, "payload.position[" + std::to_string(i) + "]", position[i], "[-1, 1] m");
  }
  return e;
}

std::vector<std::string> StreamParams::validate(const std::string& prefix) const
{
  std::vector<std::string> e;
  check(&e, rate > 0.0 && rate <= 1000.0, prefix + ".rate", rate, "(0, 1000] Hz");
  check(&e, delay >= 0.0 && delay <= 1.0, prefix + ".delay", delay, "[0, 1] s");
  check(&e, dropout >= 0.0 && dropout < 1.0, prefix + ".dropout", dropout, "[0, 1)");
  return e;
}

std::vector<std::string> JointStateSensorParams::validate() const
{
  auto e = StreamParams::validate("sensors.joint_states");
  check(&e, position_noise_std >= 0.0, "sensors.joint_states.position_noise_std", position_noise_std, ">= 0 rad");
  check(&e, velocity_noise_std >= 0.0, "sensors.joint_states.velocity_noise_std", velocity_noise_std, ">= 0 rad/s");
  check(&e, true, "sensors.joint_states.velocity_bias", velocity_bias, "finite rad/s");
  return e;
}

std::vector<std::string> ImuSensorParams::validate() const
{
  auto e = StreamParams::validate("sensors.imu");
  check(&e, gyro_noise_std >= 0.0, "sensors.imu.gyro_noise_std", gyro_noise_std, ">= 0 rad/s");
  check(&e, accel_noise_std >= 0.0, "sensors.imu.accel_noise_std", accel_noise_std, ">= 0 m/s^2");
  check(&e, orientation_noise_std >= 0.0, "sensors.imu.orientation_noise_std", orientation_noise_std, ">= 0 rad");
  for (int i = 0; i < 3; ++i)
  {
    check(&e, true, "sensors.imu.gyro_bias[" + std::to_string(i) + "]", gyro_bias[i], "finite rad/s");
    check(&e, true, "sensors.imu.accel_bias[" + std::to_string(i) + "]", accel_bias[i], "finite m/s^2");
  }
  return e;
}

std::vector<std::string> SensorParams::validate() const
{
  auto e = joint_states.validate();
  append(&e, imu.validate());
  return e;
}

SensorParams idealSensors(SensorParams sensors)
{
  JointStateSensorParams& js = sensors.joint_states;
  js.position_noise_std = js.velocity_noise_std = js.velocity_bias = js.dropout = 0.0;
  ImuSensorParams& imu = sensors.imu;
  imu.gyro_noise_std = imu.accel_noise_std = imu.orientation_noise_std = imu.dropout = 0.0;
  imu.gyro_bias.fill(0.0);
  imu.accel_bias.fill(0.0);
  return sensors;
}

std::vector<std::string> PlantNodeParams::validate() const
{
  std::vector<std::string> e;
  check(&e, real_time_factor >= 0.0 && real_time_factor <= 100.0, "node.real_time_factor", real_time_factor,
        "[0, 100] (0 = as fast as possible)");
  check(&e, odom_rate > 0.0 && odom_rate <= 1000.0, "node.odom_rate", odom_rate, "(0, 1000] Hz");
  check(&e, clock_rate > 0.0 && clock_rate <= 1000.0, "node.clock_rate", clock_rate, "(0, 1000] Hz");
  check(&e, cmd_timeout >= 0.0, "node.cmd_timeout", cmd_timeout, ">= 0 s (0 = never)");
  if (odom_frame.empty())
  {
    e.push_back("node.odom_frame is empty (allowed: a frame name)");
  }
  return e;
}

std::vector<std::string> PlantParams::validate() const
{
  auto e = physics.validate();
  append(&e, node.validate());
  append(&e, contact.validate());
  append(&e, motor.validate());
  append(&e, payload.validate());
  append(&e, sensors.validate());
  return e;
}

PlantParams loadPlantParams(const std::string& path, const std::vector<std::string>& overrides)
{
  std::ifstream in(path);
  if (!in.good())
  {
    throw PlantParamsError("plant parameter file '" + path + "' does not exist or cannot be read");
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return parsePlantParams(ss.str(), path, overrides);
}

std::vector<std::string> plantOverrides(const std::vector<std::string>& overlay_files,
                                        const std::vector<std::string>& overrides)
{
  std::vector<std::string> out;
  for (const std::string& file : overlay_files)
  {
    try
    {
      const std::vector<std::string> o = overrides::loadOverlayFile(file);
      out.insert(out.end(), o.begin(), o.end());
    }
    catch (const std::invalid_argument& e)
    {
      throw PlantParamsError(e.what());
    }
  }
  out.insert(out.end(), overrides.begin(), overrides.end());
  return out;
}

PlantParams parsePlantParams(const std::string& yaml, const std::string& source,
                             const std::vector<std::string>& overrides)
{
  YAML::Node root;
  try
  {
    root = YAML::Load(yaml);
  }
  catch (const YAML::Exception& ex)
  {
    throw PlantParamsError("plant parameter file '" + source + "' is malformed YAML: " + ex.what());
  }
  if (root.IsNull())
  {
    root = YAML::Node(YAML::NodeType::Map);
  }
  if (!root.IsMap())
  {
    throw PlantParamsError("plant parameter file '" + source + "' must be a YAML map");
  }
  try
  {
    overrides::applyOverrides(root,
                              overrides);  // the shared KEY=VALUE parser (jackal_aic/overrides/yaml_overrides.hpp)
  }
  catch (const std::invalid_argument& e)
  {
    throw PlantParamsError("plant parameters '" + source + "': " + e.what());
  }

  PlantParams p;
  std::vector<std::string> errors;
  {
    Section s(root["physics"], "physics", &errors);
    s.get("step", &p.physics.step);
    s.get("gravity", &p.physics.gravity);
    s.get("initial_x", &p.physics.initial_x);
    s.get("initial_y", &p.physics.initial_y);
    s.get("initial_yaw", &p.physics.initial_yaw);
    s.get("initial_clearance", &p.physics.initial_clearance);
  }
  {
    Section s(root["contact"], "contact", &errors);
    s.get("friction_model", &p.contact.friction_model);
    s.get("sliding_threshold", &p.contact.sliding_threshold);
    s.get("slip_stiffness", &p.contact.slip_stiffness);
    s.get("slip_min_speed", &p.contact.slip_min_speed);
    s.get("mu1", &p.contact.mu1);
    s.get("mu2", &p.contact.mu2);
    s.get("slip1", &p.contact.slip1);
    s.get("slip2", &p.contact.slip2);
    s.get("kp", &p.contact.kp);
    s.get("kd", &p.contact.kd);
    s.get("max_correcting_vel", &p.contact.max_correcting_vel);
    s.get("surface_layer", &p.contact.surface_layer);
    s.get("max_contacts", &p.contact.max_contacts);
  }
  {
    Section s(root["motor"], "motor", &errors);
    MotorParams& m = p.motor;
    s.get("speed_kp", &m.speed_kp);
    s.get("speed_ki", &m.speed_ki);
    s.get("max_torque", &m.max_torque);
    s.get("integral_limit", &m.integral_limit);
    s.get("accel_feedforward", &m.accel_feedforward);
    s.get("accel_feedforward_limit", &m.accel_feedforward_limit);
    s.get("proportional_limit", &m.proportional_limit);
    s.get("integral_error_limit", &m.integral_error_limit);
    s.get("setpoint_feedforward", &m.setpoint_feedforward);
    s.get("load_observer_inertia", &m.load_observer_inertia);
    s.get("load_observer_time_constant", &m.load_observer_time_constant);
    s.get("stall_torque", &m.stall_torque);
    s.get("no_load_speed", &m.no_load_speed);
    s.get("setpoint_slew_rate", &m.setpoint_slew_rate);
    s.get("setpoint_time_constant", &m.setpoint_time_constant);
    s.get("command_delay", &m.command_delay);
    s.get("coulomb_friction", &m.coulomb_friction);
    s.get("viscous_friction", &m.viscous_friction);
    s.get("coupling_damping", &m.coupling_damping);
    s.get("max_wheel_speed", &m.max_wheel_speed);
  }
  {
    Section s(root["payload"], "payload", &errors);
    s.get("mass", &p.payload.mass);
    s.get3("position", &p.payload.position);
  }
  {
    Section s(root["sensors"], "sensors", &errors);
    s.get("seed", &p.sensors.seed);
    {
      Section j = s.sub("joint_states");
      readStream(j, &p.sensors.joint_states);
      j.get("position_noise_std", &p.sensors.joint_states.position_noise_std);
      j.get("velocity_noise_std", &p.sensors.joint_states.velocity_noise_std);
      j.get("velocity_bias", &p.sensors.joint_states.velocity_bias);
    }
    {
      Section i = s.sub("imu");
      readStream(i, &p.sensors.imu);
      i.get("gyro_noise_std", &p.sensors.imu.gyro_noise_std);
      i.get3("gyro_bias", &p.sensors.imu.gyro_bias);
      i.get("accel_noise_std", &p.sensors.imu.accel_noise_std);
      i.get3("accel_bias", &p.sensors.imu.accel_bias);
      i.get("orientation_noise_std", &p.sensors.imu.orientation_noise_std);
    }
  }
  {
    Section s(root["node"], "node", &errors);
    s.get("real_time_factor", &p.node.real_time_factor);
    s.get("odom_rate", &p.node.odom_rate);
    s.get("clock_rate", &p.node.clock_rate);
    s.get("cmd_timeout", &p.node.cmd_timeout);
    s.get("odom_frame", &p.node.odom_frame);
  }
  for (const auto& kv : root)
  {
    const std::string k = kv.first.as<std::string>();
    if (k != "physics" && k != "contact" && k != "motor" && k != "payload" && k != "sensors" && k != "node")
    {
      errors.push_back(k + " is not a known section (physics, contact, motor, payload, sensors, node)");
    }
  }
  append(&errors, p.validate());
  if (!errors.empty())
  {
    std::string msg = "plant parameter file '" + source + "' is invalid:";
    for (const auto& e : errors)
    {
      msg += "\n  " + e;
    }
    throw PlantParamsError(msg);
  }
  return p;
}

}  // namespace plant
}  // namespace jackal_aic
