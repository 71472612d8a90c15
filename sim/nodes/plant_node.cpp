#include "plant_node.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>

#include <geometry_msgs/TransformStamped.h>
#include <jackal_msgs/Feedback.h>
#include <jackal_msgs/Status.h>
#include <ros/master.h>
#include <rosgraph_msgs/Clock.h>

namespace jackal_aic
{
namespace sim_nodes
{
using namespace plant;  // the plant this part drives

namespace
{
std::string requiredPath(const ros::NodeHandle& pnh, const std::string& name)
{
  std::string v;
  if (!pnh.getParam(name, v) || v.empty())
  {
    throw std::runtime_error("parameter " + pnh.resolveName(name) + " (a file path) is not set");
  }
  return v;
}

/// ~overlay: one path, a list of paths, or "" / absent (none).
std::vector<std::string> overlayFiles(const ros::NodeHandle& pnh)
{
  XmlRpc::XmlRpcValue v;
  std::vector<std::string> files;
  if (!pnh.getParam("overlay", v))
  {
    return files;
  }
  auto add = [&](XmlRpc::XmlRpcValue& item) {
    if (item.getType() != XmlRpc::XmlRpcValue::TypeString)
    {
      throw std::runtime_error("parameter " + pnh.resolveName("overlay") +
                               " must be a plant YAML path or a list of them");
    }
    const std::string path = static_cast<std::string>(item);
    if (!path.empty())
    {
      files.push_back(path);
    }
  };
  if (v.getType() == XmlRpc::XmlRpcValue::TypeArray)
  {
    for (int i = 0; i < v.size(); ++i)
    {
      add(v[i]);
    }
  }
  else
  {
    add(v);
  }
  return files;
}

std::uint64_t periodSteps(double rate, double step)
{
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(1.0 / (rate * step))));
}

void toMsg(const Eigen::Quaterniond& q, geometry_msgs::Quaternion* m)
{
  m->w = q.w();
  m->x = q.x();
  m->y = q.y();
  m->z = q.z();
}

void toMsg(const Eigen::Vector3d& v, geometry_msgs::Vector3* m)
{
  m->x = v.x();
  m->y = v.y();
  m->z = v.z();
}
}  // namespace

PlantNode::PlantNode(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh)
{
  const std::string urdf = requiredPath(pnh_, "urdf");
  const std::string config = requiredPath(pnh_, "plant_config");
  std::vector<std::string> overrides;
  pnh_.getParam("overrides", overrides);
  description_ = loadRobotDescription(urdf);
  params_ = loadPlantParams(config, plantOverrides(overlayFiles(pnh_), overrides));
  plant_ = std::make_unique<Plant>(description_, params_, 1.0 / params_.sensors.imu.rate);
  sensors_ = std::make_unique<FaultedSensors>(params_.sensors, params_.physics.step);
  nh_.param("/use_sim_time", use_sim_time_, false);
  odom_period_ = periodSteps(params_.node.odom_rate, params_.physics.step);
  clock_period_ = periodSteps(params_.node.clock_rate, params_.physics.step);

  joint_msg_.name.resize(kNumWheels);
  for (int i = 0; i < kNumWheels; ++i)
  {
    joint_msg_.name[i] = description_.wheels[i].joint_name;
  }
  joint_msg_.position.resize(kNumWheels);
  joint_msg_.velocity.resize(kNumWheels);
  joint_msg_.effort.resize(kNumWheels);

  const std::string source = pnh_.param<std::string>("joint_states_source", "direct");
  if (source == "jackal_node")
  {
    joint_source_ = JointSource::kJackalNode;
    sampler_ = std::make_unique<plant::JackalNodeSampler>(samplerParams());  // throws on a bad value
  }
  else if (source == "none")
  {
    joint_source_ = JointSource::kNone;
  }
  else if (source != "direct")
  {
    throw std::runtime_error("parameter " + pnh_.resolveName("joint_states_source") + " = '" + source +
                             "' (allowed: direct, jackal_node, none)");
  }
  publish_mcu_ = pnh_.param("publish_mcu", false);
  pnh_.param("mcu/torque_constant", torque_constant_, torque_constant_);
  pnh_.param("mcu/temperature", mcu_temperature_, mcu_temperature_);
  if (!std::isfinite(torque_constant_) || !(torque_constant_ > 0.0) || !std::isfinite(mcu_temperature_))
  {
    throw std::runtime_error("parameter " + pnh_.resolveName("mcu/torque_constant") +
                             " must be finite and > 0 [N m / A], " + pnh_.resolveName("mcu/temperature") +
                             " finite [deg C]");
  }
  status_period_ = periodSteps(1.0, params_.physics.step);
  if (joint_source_ != JointSource::kNone)
  {
    joint_pub_ = nh_.advertise<sensor_msgs::JointState>("joint_states", 10);
  }
  if (publish_mcu_)
  {
    feedback_pub_ = nh_.advertise<jackal_msgs::Feedback>("feedback", 10);
    status_pub_ = nh_.advertise<jackal_msgs::Status>("status", 1, true);
  }
  imu_pub_ = nh_.advertise<sensor_msgs::Imu>("imu/data", 10);
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 10);
  if (use_sim_time_)
  {
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  }
  fault_poll_period_ = periodSteps(5.0, params_.physics.step);
  pollFaults();
  drive_sub_ = nh_.subscribe("cmd_drive", 10, &PlantNode::onDrive, this, ros::TransportHints().tcpNoDelay());

  ROS_INFO_STREAM("jackal_plant: URDF " << urdf << " (robot '" << description_.robot_name << "', wheel radius "
                                        << description_.wheelRadius() << " m, track " << description_.track()
                                        << " m, mass " << description_.totalMass() << " kg); config " << config
                                        << "; step " << params_.physics.step << " s; joint_states "
                                        << params_.sensors.joint_states.rate << " Hz, imu " << params_.sensors.imu.rate
                                        << " Hz; real_time_factor " << params_.node.real_time_factor
                                        << (use_sim_time_ ? "; publishing /clock" : "") << "; joint_states " << source
                                        << (publish_mcu_ ? "; /feedback and /status" : ""));
}

plant::JackalNodeSamplerParams PlantNode::samplerParams() const
{
  plant::JackalNodeSamplerParams p;
  pnh_.param("jackal_node/phase", p.phase, p.phase);
  pnh_.param("jackal_node/drift", p.drift, p.drift);
  pnh_.param("jackal_node/jitter_std", p.jitter_std, p.jitter_std);
  pnh_.param("jackal_node/stall_probability", p.stall_probability, p.stall_probability);
  pnh_.param("jackal_node/stall_max", p.stall_max, p.stall_max);
  pnh_.param("jackal_node/link_delay", p.link_delay, p.link_delay);
  int seed = static_cast<int>(p.seed);
  pnh_.param("jackal_node/seed", seed, seed);
  p.seed = static_cast<std::uint32_t>(seed);
  return p;
}

void PlantNode::publishFeedback(const JointStateSample& s)
{
  jackal_msgs::Feedback fb;
  fb.header.stamp = stamp(s.stamp);
  for (const Side side : { kLeft, kRight })
  {
    double travel = 0.0, speed = 0.0, torque = 0.0;
    for (int i = 0; i < kNumWheels; ++i)
    {
      if (kWheelSide[static_cast<std::size_t>(i)] == side)
      {
        travel += 0.5 * s.position[static_cast<std::size_t>(i)];
        speed += 0.5 * s.velocity[static_cast<std::size_t>(i)];
        torque += plant_->wheelTorque(i);
      }
    }
    jackal_msgs::DriveFeedback& d = fb.drivers[side == kLeft ? jackal_msgs::Drive::LEFT : jackal_msgs::Drive::RIGHT];
    d.measured_travel = static_cast<float>(travel);
    d.measured_velocity = static_cast<float>(speed);
    d.current = static_cast<float>(std::abs(torque) / torque_constant_);
    const MotorParams& m = params_.motor;
    const double duty = m.stall_torque > 0.0 ? torque / m.stall_torque + speed / m.no_load_speed : 0.0;
    d.duty_cycle = static_cast<float>(std::clamp(duty, -1.0, 1.0));
    d.bridge_temperature = d.motor_temperature = static_cast<float>(mcu_temperature_);
    d.driver_fault = false;
  }
  fb.pcb_temperature = fb.mcu_temperature = static_cast<float>(mcu_temperature_);
  bool velocity = false;
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    velocity = command_.velocity && !timed_out_;
  }
  fb.commanded_mode = fb.actual_mode = velocity ? jackal_msgs::Drive::MODE_VELOCITY : jackal_msgs::Drive::MODE_NONE;
  feedback_pub_.publish(fb);
}

void PlantNode::publishStatus()
{
  jackal_msgs::Status st;
  st.header.stamp = stamp(plant_->time());
  st.hardware_id = "jackal_aic simulated MCU";
  st.mcu_uptime = ros::Duration(plant_->time());
  st.connection_uptime = ros::Duration(plant_->time());
  st.drivers_active = true;
  st.driver_external_stop_present = false;
  st.driver_external_stop_stopped = false;
  st.measured_battery = 26.0f;
  st.measured_12v = 12.0f;
  st.measured_5v = 5.0f;
  status_pub_.publish(st);
}

void PlantNode::onDrive(const jackal_msgs::Drive::ConstPtr& msg)
{
  const double left = msg->drivers[jackal_msgs::Drive::LEFT];
  const double right = msg->drivers[jackal_msgs::Drive::RIGHT];
  bool velocity = false;
  if (msg->mode == jackal_msgs::Drive::MODE_VELOCITY)
  {
    if (!std::isfinite(left) || !std::isfinite(right))
    {
      ROS_WARN_THROTTLE(1.0, "jackal_plant: dropped /cmd_drive with non-finite drivers [%f, %f]", left, right);
      return;
    }
    velocity = true;
  }
  else if (msg->mode != jackal_msgs::Drive::MODE_NONE)
  {
    ROS_WARN_THROTTLE(1.0,
                      "jackal_plant: /cmd_drive mode %d is not supported (only MODE_VELOCITY=0 and "
                      "MODE_NONE=-1); treated as MODE_NONE (motors released)",
                      static_cast<int>(msg->mode));
  }
  std::lock_guard<std::mutex> lock(command_mutex_);
  ++command_.seq;
  command_.velocity = velocity;
  command_.left = velocity ? left : 0.0;
  command_.right = velocity ? right : 0.0;
}

void PlantNode::applyCommand()
{
  Command c;
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    c = command_;
  }
  const double t = plant_->time();
  if (c.seq != applied_seq_)
  {
    applied_seq_ = c.seq;
    last_command_time_ = t;
    if (timed_out_)
    {
      ROS_INFO("jackal_plant: /cmd_drive resumed");
      timed_out_ = false;
    }
    if (c.velocity)
    {
      plant_->setWheelSpeeds(c.left, c.right);
    }
    else
    {
      plant_->releaseMotors();
    }
  }
  else if (params_.node.cmd_timeout > 0.0 && applied_seq_ > 0 && !timed_out_ &&
           t - last_command_time_ > params_.node.cmd_timeout)
  {
    timed_out_ = true;
    ROS_WARN("jackal_plant: no /cmd_drive for %.3f s; wheel set points set to zero", params_.node.cmd_timeout);
    if (c.velocity)
    {
      plant_->setWheelSpeeds(0.0, 0.0);
    }
  }
}

ros::Time PlantNode::stamp(double plant_time) const
{
  return origin_ + ros::Duration(plant_time);
}

void PlantNode::stepOnce()
{
  applyCommand();
  plant_->step();
  const std::uint64_t k = plant_->stepCount();
  if (use_sim_time_ && k % clock_period_ == 0)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp(plant_->time());
    clock_pub_.publish(clock);
  }
  if (k % fault_poll_period_ == 0)
  {
    pollFaults();
  }
  checkClock();
  const FaultedSensors::Changes changes = sensors_->afterStep(*plant_, &joint_samples_, &imu_samples_);
  if (changes.payload)
  {
    ROS_WARN("jackal_plant: payload now %.2f kg", plant_->payload());
  }
  for (const Side side : { kLeft, kRight })
  {
    if (changes.friction[static_cast<std::size_t>(side)])
    {
      ROS_WARN("jackal_plant: %s wheel-ground friction scaled by %.3f", side == kLeft ? "left" : "right",
               plant_->frictionScale(side));
    }
  }
  for (const JointStateSample& js : joint_samples_)
  {
    if (publish_mcu_)
    {
      publishFeedback(js);
    }
    if (joint_source_ == JointSource::kDirect)
    {
      publishJointStates(js);
    }
    else if (joint_source_ == JointSource::kJackalNode)
    {
      sampler_->feedback(js);
    }
  }
  if (joint_source_ == JointSource::kJackalNode)
  {
    sampler_->advance(plant_->time(), &resampled_);
    for (const plant::ResampledJointState& r : resampled_)
    {
      publishJointStates(r.sample);
    }
  }
  if (publish_mcu_ && (k % status_period_ == 0 || k == 1))
  {
    publishStatus();
  }
  for (const ImuSample& imu : imu_samples_)
  {
    imu_pub_.publish(imuMessage(imu));
  }
  if (k % odom_period_ == 0)
  {
    publishOdom();
  }
}

void PlantNode::waitForSubscribers()
{
  // The nodes the master lists as subscribers of /joint_states (a plant restarted under running nodes).
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  std::size_t expected = 0;
  if (ros::master::execute("getSystemState", request, response, payload, false) && payload.size() > 1)
  {
    XmlRpc::XmlRpcValue& subscriptions = payload[1];
    for (int i = 0; i < subscriptions.size(); ++i)
    {
      if (static_cast<std::string>(subscriptions[i][0]) == joint_pub_.getTopic())
      {
        expected = static_cast<std::size_t>(subscriptions[i][1].size());
      }
    }
  }
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kSubscriberWait);
  while (ros::ok() && joint_pub_.getNumSubscribers() < expected && ros::WallTime::now() < deadline)
  {
    ros::WallDuration(0.005).sleep();
  }
}

void PlantNode::checkClock()
{
  if (use_sim_time_)
  {
    return;
  }
  const ros::Time now = ros::Time::now();
  const double back = time_jump_.observe(now.toSec());
  if (back > 0.0)
  {
    origin_ = now - ros::Duration(plant_->time());
    ROS_WARN("jackal_plant: ROS time moved back %.3f s; stamps follow it from plant time %.3f s [%lu jump(s) back "
             "so far]",
             back, plant_->time(), static_cast<unsigned long>(time_jump_.jumps()));
  }
}

void PlantNode::pollFaults()
{
  std::vector<std::string> lines;
  pnh_.getParamCached("faults", lines);
  if (lines == fault_lines_)
  {
    return;
  }
  fault_lines_ = lines;
  std::vector<FaultSpec> specs;
  for (const auto& line : lines)
  {
    FaultSpec f;
    std::string error;
    if (parseFaultSpec(line, &f, &error))
    {
      specs.push_back(f);
      ROS_WARN_STREAM("jackal_plant: injecting fault '" << line << "' from t = " << plant_->time() + f.start
                                                        << " s (plant time)");
    }
    else
    {
      ROS_ERROR_STREAM("jackal_plant: ignored fault '" << line << "' in " << pnh_.resolveName("faults") << ": "
                                                       << error);
    }
  }
  if (specs.empty())
  {
    ROS_INFO("jackal_plant: no faults injected");
  }
  sensors_->setFaults(specs, plant_->time());
}

void PlantNode::fillJointStates(const JointStateSample& s)
{
  joint_msg_.header.stamp = stamp(s.stamp);
  for (int i = 0; i < kNumWheels; ++i)
  {
    joint_msg_.position[i] = s.position[i];
    joint_msg_.velocity[i] = s.velocity[i];
    joint_msg_.effort[i] = joint_source_ == JointSource::kJackalNode ? 0.0 : plant_->wheelTorque(i);
  }
}

void PlantNode::publishJointStates(const JointStateSample& s)
{
  fillJointStates(s);
  joint_pub_.publish(joint_msg_);
}

void PlantNode::publishImu(const ImuSample& s)
{
  imu_pub_.publish(imuMessage(s));
}

sensor_msgs::Imu PlantNode::imuMessage(const ImuSample& s) const
{
  sensor_msgs::Imu m;
  m.header.stamp = stamp(s.stamp);
  m.header.frame_id = description_.imu_link;
  toMsg(s.orientation, &m.orientation);
  toMsg(s.angular_velocity, &m.angular_velocity);
  toMsg(s.linear_acceleration, &m.linear_acceleration);
  const ImuSensorParams& p = params_.sensors.imu;
  for (int k = 0; k < 3; ++k)
  {
    m.orientation_covariance[4 * k] = p.orientation_noise_std * p.orientation_noise_std;
    m.angular_velocity_covariance[4 * k] = p.gyro_noise_std * p.gyro_noise_std;
    m.linear_acceleration_covariance[4 * k] = p.accel_noise_std * p.accel_noise_std;
  }
  return m;
}

void PlantNode::publishOdom()
{
  const ros::Time t = stamp(plant_->time());
  const Eigen::Isometry3d pose = plant_->basePose();
  const Eigen::Quaterniond q(pose.linear());
  nav_msgs::Odometry odom;
  odom.header.stamp = t;
  odom.header.frame_id = params_.node.odom_frame;
  odom.child_frame_id = description_.base_link;
  odom.pose.pose.position.x = pose.translation().x();
  odom.pose.pose.position.y = pose.translation().y();
  odom.pose.pose.position.z = pose.translation().z();
  toMsg(q.normalized(), &odom.pose.pose.orientation);
  toMsg(plant_->baseLinearVelocity(), &odom.twist.twist.linear);
  toMsg(plant_->baseAngularVelocity(), &odom.twist.twist.angular);
  odom_pub_.publish(odom);

  geometry_msgs::TransformStamped tf;
  tf.header = odom.header;
  tf.child_frame_id = odom.child_frame_id;
  tf.transform.translation.x = pose.translation().x();
  tf.transform.translation.y = pose.translation().y();
  tf.transform.translation.z = pose.translation().z();
  tf.transform.rotation = odom.pose.pose.orientation;
  tf_.sendTransform(tf);
}

int PlantNode::run()
{
  using Clock = std::chrono::steady_clock;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  if (use_sim_time_)
  {
    origin_ = ros::Time(0);
    rosgraph_msgs::Clock clock;
    clock.clock = origin_;
    clock_pub_.publish(clock);
    waitForSubscribers();
  }
  else
  {
    origin_ = ros::Time::now();
  }
  const double rtf = params_.node.real_time_factor;
  const double h = params_.physics.step;
  // Plant time it may run behind the wall clock before it drops the lag instead of catching up in
  // a burst. On the wall clock the stamps must stay near it: up to kWallClockCatchUp. On simulated
  // time every node waits for /clock, so a host stall (the plant descheduled) pauses the whole
  // system: a burst would instead run the plant open loop for the stall's length while the nodes
  // catch up (a 0.15 s stall overshoots a 0.5 m/s step by 19 %). Up to one 50 Hz period is
  // caught up (ordinary scheduling jitter), no more.
  // In steps, at least one: a slow-motion plant (rtf < h / catch_up) would otherwise find every
  // due step a lag to drop and never step.
  const std::uint64_t max_lag_steps = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>((use_sim_time_ ? kSimTimeCatchUp : kWallClockCatchUp) * rtf / h));
  const auto start = Clock::now();
  std::uint64_t base_steps = 0;  // steps before the last resynchronisation
  auto sync = start;
  std::uint64_t lag_events = 0;
  while (ros::ok())
  {
    if (rtf <= 0.0)
    {
      stepOnce();
      continue;
    }
    // Steps due by now at the requested rate.
    const double wall = std::chrono::duration<double>(Clock::now() - sync).count();
    const auto due = base_steps + static_cast<std::uint64_t>(wall * rtf / h);
    if (due > plant_->stepCount() + max_lag_steps)
    {
      ++lag_events;
      ROS_WARN_THROTTLE(5.0, "jackal_plant: %.3f s behind real time; dropping the lag (%lu times so far)%s",
                        (due - plant_->stepCount()) * h / rtf, static_cast<unsigned long>(lag_events),
                        use_sim_time_ ? ": simulated time paused with the host" : "");
      sync = Clock::now();
      base_steps = plant_->stepCount();
      continue;
    }
    while (plant_->stepCount() < due && ros::ok())
    {
      stepOnce();
    }
    const double next_wall = static_cast<double>(plant_->stepCount() + 1 - base_steps) * h / rtf;
    std::this_thread::sleep_until(
        sync + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(next_wall)));
  }
  spinner.stop();
  return 0;
}

}  // namespace sim_nodes
}  // namespace jackal_aic
