#include "jackal_sim/harness/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_sim/plant/sensor_model.hpp"
#include "jackal_sim/harness/diff_drive_odometry.hpp"
#include "jackal_sim/harness/stock_controller.hpp"
#include "jackal_sim/plant/jackal_node_sampler.hpp"

namespace jackal_aic
{
namespace harness
{
using namespace plant;  // the plant this part drives

namespace
{
/// Period of a rate in whole plant steps (>= 1).
std::uint64_t periodSteps(double rate, double step)
{
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(1.0 / (rate * step))));
}

void makeSensorsIdeal(SensorParams* s)
{
  s->joint_states.position_noise_std = 0.0;
  s->joint_states.velocity_noise_std = 0.0;
  s->joint_states.velocity_bias = 0.0;
  s->joint_states.dropout = 0.0;
  s->imu.gyro_noise_std = 0.0;
  s->imu.accel_noise_std = 0.0;
  s->imu.orientation_noise_std = 0.0;
  s->imu.gyro_bias = { 0.0, 0.0, 0.0 };
  s->imu.accel_bias = { 0.0, 0.0, 0.0 };
  s->imu.dropout = 0.0;
}

void checkConfig(const ClosedLoopConfig& config)
{
  if (!(config.duration > 0.0) || !std::isfinite(config.duration))
  {
    throw std::invalid_argument("runClosedLoop: duration must be finite and > 0");
  }
  if (config.profile.empty())
  {
    throw std::invalid_argument("runClosedLoop: empty set-point profile");
  }
  for (std::size_t i = 0; i < config.profile.size(); ++i)
  {
    const SetPointSegment& s = config.profile[i];
    if (!std::isfinite(s.start) || s.start < 0.0 || !std::isfinite(s.linear) || !std::isfinite(s.angular))
    {
      throw std::invalid_argument("runClosedLoop: profile segment " + std::to_string(i) +
                                  " has a negative or non-finite start or a non-finite set point");
    }
    if (i > 0 && s.start < config.profile[i - 1].start)
    {
      throw std::invalid_argument("runClosedLoop: profile not sorted by start time");
    }
  }
  if (config.jackal_node)
  {
    const auto violations = config.jackal_node_sampler.validate();
    if (!violations.empty())
    {
      std::string what = "runClosedLoop: invalid jackal_node_sampler:";
      for (const auto& v : violations)
      {
        what += " " + v + ";";
      }
      throw std::invalid_argument(what);
    }
  }
  if (!config.operations.empty() && config.controller != LoopController::kAic)
  {
    throw std::invalid_argument("runClosedLoop: operations around the node need the AIC");
  }
  for (std::size_t i = 0; i < config.operations.size(); ++i)
  {
    const Operation& o = config.operations[i];
    if (!std::isfinite(o.start) || o.start < 0.0 || !std::isfinite(o.size) || o.size < 0.0)
    {
      throw std::invalid_argument("runClosedLoop: operation " + std::to_string(i) +
                                  " has a negative or non-finite start or size");
    }
    if (i > 0 && o.start < config.operations[i - 1].start)
    {
      throw std::invalid_argument("runClosedLoop: operations not sorted by start time");
    }
  }
}

/// The node's parameters of an AIC run: config.node with config.aic and, if none are given,
/// the plant's wheel joints (front and rear of each side).
params::NodeParams aicNodeParams(const ClosedLoopConfig& config, const RobotDescription& description)
{
  params::NodeParams p = config.node;
  p.aic = config.aic;
  if (p.left_joints.empty() && p.right_joints.empty())
  {
    p.left_joints = { description.wheels[kFrontLeft].joint_name, description.wheels[kRearLeft].joint_name };
    p.right_joints = { description.wheels[kFrontRight].joint_name, description.wheels[kRearRight].joint_name };
  }
  return p;
}

/// Throws std::invalid_argument listing every violation of the AIC run's parameters.
void checkAicParams(const params::NodeParams& params)
{
  const auto violations = params.validate();
  if (!violations.empty())
  {
    std::ostringstream os;
    os << "runClosedLoop: invalid AIC parameters:";
    for (const auto& v : violations)
    {
      os << " " << v.toString() << ";";
    }
    throw std::invalid_argument(os.str());
  }
}

/// The plant's time as the loop's clock.
class SimClock : public loop::Clock
{
public:
  double now() const override { return t; }
  double t = 0.0;  ///< [s]
};

/// The loop's commands go to the plant at once (while the driver forwards them); its health
/// events into the record.
class PlantOutput : public loop::ControlLoop::Output
{
public:
  PlantOutput(Plant* plant, const SimClock& clock, ClosedLoopRecord& record, bool keep_events)
    : plant_(plant), clock_(clock), record_(record), keep_events_(keep_events)
  {
  }
  void command(const loop::WheelCommand& c) override
  {
    wheels = c.wheels;
    if (connected)
    {
      plant_->setWheelSpeeds(c.wheels(0), c.wheels(1));
    }
  }
  void healthEvent(safety::FaultMonitor::Event event, int channel) override
  {
    if (keep_events_)
    {
      record_.health_events.push_back({ clock_.now(), event, channel });
    }
  }
  /// A restarted plant.
  void setPlant(Plant* plant) { plant_ = plant; }
  base::Vector2 wheels = base::Vector2::Zero();  ///< the last command [rad/s]
  bool connected = true;                         ///< false: the driver is paused (commands are not forwarded)

private:
  Plant* plant_;
  const SimClock& clock_;
  ClosedLoopRecord& record_;
  bool keep_events_;
};

/// The set point in force at time t: the last segment starting by t, found with a cursor
/// (the times asked are non-decreasing; the profile is sorted).
class SegmentCursor
{
public:
  explicit SegmentCursor(const std::vector<SetPointSegment>& profile) : profile_(profile) {}
  const SetPointSegment* at(double t)
  {
    while (next_ < profile_.size() && profile_[next_].start <= t + 1e-9)
    {
      ++next_;
    }
    return next_ == 0 ? nullptr : &profile_[next_ - 1];
  }

private:
  const std::vector<SetPointSegment>& profile_;
  std::size_t next_ = 0;
};

}  // namespace

const char* toString(Operation::Kind kind)
{
  switch (kind)
  {
    case Operation::Kind::kClockBack:
      return "clock_back";
    case Operation::Kind::kPlantRestart:
      return "plant_restart";
    case Operation::Kind::kDriverPause:
      return "driver_pause";
    case Operation::Kind::kNodeRestart:
      return "node_restart";
  }
  return "unknown";
}

std::vector<SetPointSegment> profileSegments(const analysis::TwistProfile& profile, double t0)
{
  std::vector<SetPointSegment> out{ SetPointSegment{ 0.0, 0.0, 0.0 } };
  for (const analysis::TwistProfilePoint& p : profile.points)
  {
    out.push_back(SetPointSegment{ t0 + p.t, p.vx, p.wz });
  }
  return out;
}

std::vector<SetPointSegment> stepProfile(double t_step, double linear, double angular)
{
  return { { 0.0, 0.0, 0.0 }, { t_step, linear, angular } };
}

ClosedLoopRecord runClosedLoop(const RobotDescription& description, PlantParams params, const ClosedLoopConfig& config)
{
  checkConfig(config);
  if (config.ideal_sensors)
  {
    makeSensorsIdeal(&params.sensors);
  }
  auto plant = std::make_unique<Plant>(description, params);
  auto sensors = std::make_unique<FaultedSensors>(params.sensors, params.physics.step);
  sensors->setFaults(config.faults, 0.0);
  std::vector<JointStateSample> joint_samples;
  std::vector<ImuSample> imu_samples;
  // jackal_node's re-sampling of the MCU's feedback (ClosedLoopConfig::jackal_node).
  auto sampler = std::make_unique<JackalNodeSampler>(config.jackal_node_sampler);
  std::vector<ResampledJointState> resampled;
  std::vector<double> sample_source;  // when each joint sample's data was measured [s]
  std::vector<double> sample_repeated;
  const double dt = params.physics.step;
  const double r = description.wheelRadius();
  const auto total = static_cast<std::uint64_t>(std::llround(config.duration / dt));
  const bool aic = config.controller == LoopController::kAic;
  const bool classical = config.controller == LoopController::kPi;
  std::unique_ptr<classical::PiController> pi;
  if (classical)
  {
    pi = std::make_unique<classical::PiController>(config.pi);  // throws on invalid parameters
  }

  StockController stock;
  const std::uint64_t stock_period = periodSteps(stock.params().publish_rate, dt);
  // The stock bringup's odometry over the joint states (control.yaml's separation and radius).
  DiffDriveOdometry diff_drive(stock.params().wheel_separation * stock.params().wheel_separation_multiplier,
                               stock.params().wheel_radius);

  // The AIC: the node's logic on the plant's clock.
  ClosedLoopRecord out;
  SimClock clock;
  PlantOutput output(plant.get(), clock, out, config.record);
  std::unique_ptr<loop::ControlLoop> loop;
  params::NodeParams node;
  std::uint64_t belief_period = 1;
  std::uint64_t action_period = 1;
  bool belief_timer = false;
  if (aic)
  {
    node = aicNodeParams(config, description);
    checkAicParams(node);
    loop = std::make_unique<loop::ControlLoop>(node, clock, output);
    belief_period = periodSteps(config.aic.belief_rate, dt);
    action_period = periodSteps(config.aic.action_rate, dt);
    belief_timer = node.belief_schedule == params::BeliefSchedule::kTimer;
  }
  const double b_hat = aic       ? config.aic.wheel_separation :
                       classical ? config.pi.wheel_separation :
                                   stock.params().wheel_separation * stock.params().wheel_separation_multiplier;
  std::vector<std::string> joint_names;
  for (const WheelDescription& w : description.wheels)
  {
    joint_names.push_back(w.joint_name);
  }
  std::vector<double> joint_position(kNumWheels, 0.0);
  std::vector<double> joint_velocity(kNumWheels, 0.0);
  const std::vector<double> no_effort;

  double command_left = 0.0;
  double command_right = 0.0;
  double gyro_z = 0.0;  // the newest IMU sample's gyro z [rad/s], for the record
  const SetPointSegment* last_segment = nullptr;
  SegmentCursor segments(config.profile);
  SegmentCursor segments_ahead(config.profile);  // kIdeal: the set point command_delay ahead

  // Operations around the node (none: the run is exactly the plain closed loop).
  double run_offset = 0.0;    // the run's time at the current plant's time 0 [s] (plant restarts)
  double clock_offset = 0.0;  // the loop's clock and stamps minus the plant's time [s] (clock steps)
  std::size_t next_operation = 0;
  bool paused = false;
  double pause_until = 0.0;  // run time [s]
  double node_up_at = 0.0;   // run time [s] at which a killed node respawns
  bool first_action_tick = true;
  bool first_belief_tick = true;
  auto startNode = [&]() {
    loop = std::make_unique<loop::ControlLoop>(node, clock, output);
    first_action_tick = first_belief_tick = true;
  };

  for (std::uint64_t k = 0; k < total; ++k)
  {
    const double t = run_offset + plant->time();
    for (; next_operation < config.operations.size() && config.operations[next_operation].start <= t + 1e-9;
         ++next_operation)
    {
      const Operation& op = config.operations[next_operation];
      switch (op.kind)
      {
        case Operation::Kind::kClockBack:
          clock_offset -= op.size;
          break;
        case Operation::Kind::kPlantRestart:
          run_offset += plant->time();
          plant = std::make_unique<Plant>(description, params);
          sensors = std::make_unique<FaultedSensors>(params.sensors, params.physics.step);
          sensors->setFaults(config.faults, -run_offset);
          sampler = std::make_unique<JackalNodeSampler>(config.jackal_node_sampler);
          output.setPlant(plant.get());
          clock_offset = 0.0;  // the restarted simulator's clock starts at 0
          break;
        case Operation::Kind::kDriverPause:
          paused = true;
          pause_until = t + op.size;
          output.connected = false;
          plant->releaseMotors();
          clock.t = plant->time() + clock_offset;
          if (loop)
          {
            loop->mcuStatus(false, false, false);
          }
          break;
        case Operation::Kind::kNodeRestart:
          loop.reset();
          node_up_at = t + op.size;
          break;
      }
    }
    if (paused && t >= pause_until - 1e-9)
    {
      paused = false;
      output.connected = true;
      clock.t = plant->time() + clock_offset;
      if (loop)
      {
        loop->mcuStatus(true, false, false);
      }
    }
    if (aic && !loop && t >= node_up_at - 1e-9)
    {
      clock.t = plant->time() + clock_offset;
      startNode();
    }

    const SetPointSegment* seg = segments.at(t);
    const double sp_linear = seg ? seg->linear : 0.0;
    const double sp_angular = seg ? seg->angular : 0.0;

    if (config.controller == LoopController::kIdeal)
    {
      if (k % stock_period == 0)
      {
        const std::uint64_t tick = k / stock_period;
        double v = 0.0;
        double w = 0.0;
        if (tick < config.ideal_commands.size())
        {
          v = config.ideal_commands[tick](0);
          w = config.ideal_commands[tick](1);
        }
        else if (const SetPointSegment* ahead = segments_ahead.at(t + params.motor.command_delay))
        {
          v = ahead->linear;
          w = ahead->angular;
        }
        command_left = (v - 0.5 * b_hat * w) / r;
        command_right = (v + 0.5 * b_hat * w) / r;
        plant->setWheelSpeeds(command_left, command_right);
      }
    }
    else if (config.controller == LoopController::kOpenLoop)
    {
      if (k % stock_period == 0)
      {
        command_left = (sp_linear - 0.5 * b_hat * sp_angular) / r;
        command_right = (sp_linear + 0.5 * b_hat * sp_angular) / r;
        plant->setWheelSpeeds(command_left, command_right);
      }
    }
    else if (classical)
    {
      if (seg != last_segment || k % stock_period == 0)
      {
        // Streamed at 50 Hz as teleop would, and at once when the profile changes (as to the AIC).
        pi->setGoal(t, sp_linear, sp_angular);
      }
    }
    else if (!aic)
    {
      if (k % stock_period == 0)
      {
        stock.setCommand(sp_linear, sp_angular, t);
        const WheelSpeedCommand c = stock.update(t);
        command_left = c.left;
        command_right = c.right;
        plant->setWheelSpeeds(c.left, c.right);
      }
    }
    else
    {
      clock.t = plant->time() + clock_offset;
      if (loop && (seg != last_segment || k % stock_period == 0))
      {
        // Streamed at 50 Hz as teleop would, and at once when the profile changes.
        const double fields[6] = { sp_linear, 0.0, 0.0, 0.0, 0.0, sp_angular };
        loop->setPoint(fields);
      }
      if (loop && k % action_period == 0)
      {
        loop->actionTimer(first_action_tick ? -1.0 : static_cast<double>(action_period) * dt);
        first_action_tick = false;
      }
      command_left = output.wheels(0);
      command_right = output.wheels(1);
    }
    last_segment = seg;

    plant->step();
    clock.t = plant->time() + clock_offset;
    if (loop && belief_timer && (k + 1) % belief_period == 0)
    {
      // The belief timer ticks before the samples of its instant: what it integrates up to
      // now used the inputs held until now, as the event schedule does.
      loop->beliefTimer(first_belief_tick ? -1.0 : static_cast<double>(belief_period) * dt);
      first_belief_tick = false;
    }
    sensors->afterStep(*plant, &joint_samples, &imu_samples);
    sample_source.clear();
    sample_repeated.clear();
    if (config.jackal_node)
    {
      for (const JointStateSample& js : joint_samples)
      {
        sampler->feedback(js);
      }
      sampler->advance(plant->time(), &resampled);
      joint_samples.clear();
      for (const ResampledJointState& rs : resampled)
      {
        joint_samples.push_back(rs.sample);
        sample_source.push_back(rs.source_stamp);
        sample_repeated.push_back(rs.repeated ? 1.0 : 0.0);
      }
    }
    else
    {
      for (const JointStateSample& js : joint_samples)
      {
        sample_source.push_back(js.stamp);
        sample_repeated.push_back(0.0);
      }
    }
    if (!imu_samples.empty())
    {
      gyro_z = imu_samples.back().angular_velocity.z();
    }
    const bool deliver = aic && loop && !paused;  // the node is up and the driver publishes
    if (deliver)
    {
      for (const ImuSample& imu : imu_samples)
      {
        loop::ImuInput in;
        in.stamp = imu.stamp + clock_offset;
        in.angular_velocity = imu.angular_velocity;
        in.linear_acceleration = imu.linear_acceleration;
        loop->imu(in);
      }
    }
    for (std::size_t j = 0; j < joint_samples.size(); ++j)  // the record and the loop, per joint-state sample
    {
      const JointStateSample& js = joint_samples[j];
      diff_drive.update(0.5 * (js.position[kFrontLeft] + js.position[kRearLeft]),
                        0.5 * (js.position[kFrontRight] + js.position[kRearRight]), run_offset + js.stamp);
      if (deliver)
      {
        loop->advance();  // the beliefs at the sample's time, for the record
        out.active = out.active || loop->active();
        command_left = output.wheels(0);
        command_right = output.wheels(1);
      }
      ClosedLoopSample sample;
      const double wl = 0.5 * (js.velocity[kFrontLeft] + js.velocity[kRearLeft]);
      const double wr = 0.5 * (js.velocity[kFrontRight] + js.velocity[kRearRight]);
      if (classical)
      {
        const classical::PiCommand c = pi->update(run_offset + js.stamp, base::Vector2(wl, wr), gyro_z);
        command_left = c.wheels(0);
        command_right = c.wheels(1);
        plant->setWheelSpeeds(command_left, command_right);
      }
      const bool has_belief = aic && loop && out.active;
      sample.time = run_offset + js.stamp;
      sample.set_point = sp_linear;
      sample.v_odom = r * 0.5 * (wl + wr);
      sample.v_true = plant->baseLinearVelocity().x();
      sample.yaw_odom = r * (wr - wl) / b_hat;
      sample.yaw_true = plant->baseAngularVelocity().z();
      sample.yaw_gyro = gyro_z;
      sample.command = r * 0.5 * (command_left + command_right);
      sample.belief = has_belief ? loop->controller().mu()(0, 0) : std::numeric_limits<double>::quiet_NaN();
      sample.angular_set_point = sp_angular;
      sample.command_yaw = r * (command_right - command_left) / b_hat;
      sample.belief_yaw = has_belief ? loop->controller().mu()(2, 0) : std::numeric_limits<double>::quiet_NaN();
      const Eigen::Isometry3d pose = plant->basePose();
      sample.x_true = pose.translation().x();
      sample.y_true = pose.translation().y();
      sample.heading_true = std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
      sample.wheels_command = base::Vector2(command_left, command_right);
      sample.wheels_measured = base::Vector2(wl, wr);
      if (config.record)
      {
        out.time.push_back(sample.time);
        out.set_point.push_back(sample.set_point);
        out.v_odom.push_back(sample.v_odom);
        out.v_true.push_back(sample.v_true);
        out.yaw_odom.push_back(sample.yaw_odom);
        out.yaw_true.push_back(sample.yaw_true);
        out.yaw_gyro.push_back(sample.yaw_gyro);
        out.command.push_back(sample.command);
        out.belief.push_back(sample.belief);
        out.angular_set_point.push_back(sample.angular_set_point);
        out.command_yaw.push_back(sample.command_yaw);
        out.belief_yaw.push_back(sample.belief_yaw);
        out.separation.push_back(has_belief ? loop->controller().model().wheelSeparation() :
                                              std::numeric_limits<double>::quiet_NaN());
        // The believed offset: the rest estimate removed before the controller, plus the robot
        // model's beta on top of it.
        out.gyro_offset.push_back(loop ? loop->gyroBias().offset() + loop->controller().robotBelief().gyroOffset() :
                                         std::numeric_limits<double>::quiet_NaN());
        out.fdi_residual.push_back(loop ? loop->faultMonitor().residual() : std::numeric_limits<double>::quiet_NaN());
        out.fdi_statistic.push_back(loop ? loop->faultMonitor().statistic() : std::numeric_limits<double>::quiet_NaN());
        out.x_true.push_back(sample.x_true);
        out.y_true.push_back(sample.y_true);
        out.heading_true.push_back(sample.heading_true);
        out.pitch_true.push_back(std::asin(std::clamp(-pose.linear()(2, 0), -1.0, 1.0)));
        out.up_true.push_back(pose.linear()(2, 2));
        const double sl = plant->servo(kLeft).effectiveSetpoint();
        const double sr = plant->servo(kRight).effectiveSetpoint();
        out.wheel_setpoint.push_back(r * 0.5 * (sl + sr));
        out.wheel_setpoint_yaw.push_back(r * (sr - sl) / b_hat);
        const double tl = plant->sideVelocity(kLeft);
        const double tr = plant->sideVelocity(kRight);
        out.v_wheels.push_back(r * 0.5 * (tl + tr));
        out.yaw_wheels.push_back(r * (tr - tl) / b_hat);
        out.v_diff_drive.push_back(diff_drive.linear());
        out.yaw_diff_drive.push_back(diff_drive.angular());
        out.sample_age.push_back(js.stamp - sample_source[j]);
        out.repeated.push_back(sample_repeated[j]);
        out.torque_limited.push_back(0.5 * (static_cast<double>(plant->servo(kLeft).torqueLimited()) +
                                            static_cast<double>(plant->servo(kRight).torqueLimited())));
        if (config.record_inference && aic)
        {
          out.inference.push_back(has_belief ? aic::inferenceSample(loop->controller()) :
                                               aic::unavailableInferenceSample(config.aic.numOrders()));
        }
      }

      if (deliver)
      {
        for (int i = 0; i < kNumWheels; ++i)
        {
          joint_position[static_cast<std::size_t>(i)] = js.position[static_cast<std::size_t>(i)];
          joint_velocity[static_cast<std::size_t>(i)] = js.velocity[static_cast<std::size_t>(i)];
        }
        loop::JointStateInput in;
        in.stamp = js.stamp + clock_offset;
        in.name = &joint_names;
        in.position = &joint_position;
        in.velocity = &joint_velocity;
        in.effort = &no_effort;
        const std::uint64_t no_imu = loop->pairing().drops(loop::DropReason::kNoImu);
        loop->jointState(in);
        if (config.record && loop->pairing().drops(loop::DropReason::kNoImu) > no_imu)
        {
          out.imu_missing.push_back(js.stamp);
        }
        out.active = out.active || loop->active();
      }
      if (config.observer)
      {
        sample.loop = aic ? loop.get() : nullptr;
        config.observer(sample);
      }
    }
  }
  out.jackal_node_stats = sampler->stats();
  if (aic && loop)
  {
    for (int i = 0; i < static_cast<int>(loop::DropReason::kCount); ++i)
    {
      const auto reason = static_cast<loop::DropReason>(i);
      if (loop->pairing().drops(reason) > 0)
      {
        out.drops.emplace_back(loop::toString(reason), loop->pairing().drops(reason));
      }
    }
    out.runaways = loop->supervisor().runaways();
    if (loop->controller().params().belief_model == params::BeliefModel::kRobot)
    {
      out.latency = loop->controller().wheelLoop().latency();
      const aic::RobotBelief& belief = loop->controller().robotBelief();
      out.shortfall_jumps = belief.shortfallJumps();
      out.shortfall_releases = belief.shortfallReleases();
      out.unanswered_jumps = belief.unansweredJumps();
      out.stalls = belief.stalls();
    }
    out.tip_trips = loop->tipGuard().trips();
    out.tip_front = loop->tipGuard().learnedFront();
    out.tip_rear = loop->tipGuard().learnedRear();
    out.belief_steps = loop->beliefSteps();
    const auto pi_y = loop->controller().precisionY();
    for (int j = 0; j < pi_y.rows(); ++j)
    {
      out.sensory_precisions.push_back(pi_y(j, 0));
    }
  }
  return out;
}

namespace
{
/// y(t) of samples (time, y) sorted by time, linearly interpolated, held beyond the ends.
double interpolate(const std::vector<double>& time, const std::vector<double>& y, double t)
{
  if (time.empty())
  {
    return 0.0;
  }
  const auto it = std::lower_bound(time.begin(), time.end(), t);
  if (it == time.begin())
  {
    return y.front();
  }
  if (it == time.end())
  {
    return y.back();
  }
  const std::size_t i = static_cast<std::size_t>(it - time.begin());
  const double a = (t - time[i - 1]) / (time[i] - time[i - 1]);
  return y[i - 1] + a * (y[i] - y[i - 1]);
}
}  // namespace

IdealRun runIdealController(const RobotDescription& description, const PlantParams& params,
                            const ClosedLoopConfig& config, int iterations, double gain)
{
  if (iterations < 1 || !(gain > 0.0) || !(gain < 2.0))
  {
    throw std::invalid_argument("runIdealController: iterations must be >= 1 and the gain in (0, 2)");
  }
  checkConfig(config);
  const StockControllerParams stock = StockController().params();
  const double tick = 1.0 / stock.publish_rate;
  const double r = description.wheelRadius();
  const double b_hat = stock.wheel_separation * stock.wheel_separation_multiplier;
  const double lead = params.motor.command_delay;
  const double rim = params.motor.max_wheel_speed * r;  // wheel speed clamp at the rim [m/s]
  const auto ticks = static_cast<std::size_t>(std::ceil(config.duration / tick - 1e-9));

  ClosedLoopConfig c = config;
  c.controller = LoopController::kIdeal;
  c.record = true;
  c.ideal_commands.assign(ticks, base::Vector2::Zero());
  {
    SegmentCursor ahead(c.profile);
    for (std::size_t k = 0; k < ticks; ++k)
    {
      const SetPointSegment* s = ahead.at(static_cast<double>(k) * tick + lead);
      c.ideal_commands[k] = s ? base::Vector2(s->linear, s->angular) : base::Vector2::Zero();
    }
  }
  IdealRun out;
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<base::Vector2> error(ticks, base::Vector2::Zero());
  for (int j = 0; j < iterations; ++j)
  {
    ClosedLoopRecord rec = runClosedLoop(description, params, c);
    double sv = 0.0;
    double sw = 0.0;
    for (std::size_t i = 0; i < rec.time.size(); ++i)
    {
      sv += std::pow(rec.set_point[i] - rec.v_true[i], 2);
      sw += std::pow(rec.angular_set_point[i] - rec.yaw_true[i], 2);
    }
    const double n = std::max<double>(1.0, static_cast<double>(rec.time.size()));
    out.vx_rms.push_back(std::sqrt(sv / n));
    out.wz_rms.push_back(std::sqrt(sw / n));
    const double cost = (sv + 0.25 * b_hat * b_hat * sw) / n;
    if (j + 1 < iterations)
    {
      // e_j at t_k + L: the error the command of tick k acts on.
      std::vector<double> ev(rec.time.size());
      std::vector<double> ew(rec.time.size());
      for (std::size_t i = 0; i < rec.time.size(); ++i)
      {
        ev[i] = rec.set_point[i] - rec.v_true[i];
        ew[i] = rec.angular_set_point[i] - rec.yaw_true[i];
      }
      for (std::size_t k = 0; k < ticks; ++k)
      {
        const double t = static_cast<double>(k) * tick + lead;
        error[k] = base::Vector2(interpolate(rec.time, ev, t), interpolate(rec.time, ew, t));
      }
    }
    if (cost < best_cost)
    {
      best_cost = cost;
      out.best = j;
      out.commands = c.ideal_commands;
      out.record = std::move(rec);
    }
    if (j + 1 == iterations)
    {
      break;
    }
    for (std::size_t k = 0; k < ticks; ++k)
    {
      base::Vector2 m = base::Vector2::Zero();
      int count = 0;
      for (std::size_t i = k >= 2 ? k - 2 : 0; i <= std::min(ticks - 1, k + 2); ++i)
      {
        m += error[i];
        ++count;
      }
      base::Vector2 u = c.ideal_commands[k] + gain * m / static_cast<double>(count);
      // Both wheel speeds within the clamp: scale the rim speeds v -+ b_hat w / 2 down together.
      const double peak = std::abs(u(0)) + 0.5 * b_hat * std::abs(u(1));
      if (peak > rim)
      {
        u *= rim / peak;
      }
      c.ideal_commands[k] = u;
    }
  }
  return out;
}

}  // namespace harness
}  // namespace jackal_aic
