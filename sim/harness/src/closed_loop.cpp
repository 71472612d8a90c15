#include "jackal_sim/harness/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "jackal_aic/control_loop.hpp"
#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_sim/plant/sensor_model.hpp"
#include "jackal_sim/harness/stock_controller.hpp"

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
}

/// The node's parameters of an AIC run: config.node with config.aic and, if none are given,
/// the plant's wheel joints (front and rear of each side).
NodeParams aicNodeParams(const ClosedLoopConfig& config, const RobotDescription& description)
{
  NodeParams p = config.node;
  p.aic = config.aic;
  if (p.left_joints.empty() && p.right_joints.empty())
  {
    p.left_joints = { description.wheels[kFrontLeft].joint_name, description.wheels[kRearLeft].joint_name };
    p.right_joints = { description.wheels[kFrontRight].joint_name, description.wheels[kRearRight].joint_name };
  }
  return p;
}

/// Throws std::invalid_argument listing every violation of the AIC run's parameters.
void checkAicParams(const NodeParams& params)
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
class SimClock : public Clock
{
public:
  double now() const override { return t; }
  double t = 0.0;  ///< [s]
};

/// The loop's commands go to the plant at once; its health events into the record.
class PlantOutput : public ControlLoop::Output
{
public:
  PlantOutput(Plant& plant, const SimClock& clock, ClosedLoopRecord& record)
    : plant_(plant), clock_(clock), record_(record)
  {
  }
  void command(const WheelCommand& c) override
  {
    wheels = c.wheels;
    plant_.setWheelSpeeds(c.wheels(0), c.wheels(1));
  }
  void healthEvent(FaultMonitor::Event event, int channel) override
  {
    record_.health_events.push_back({ clock_.now(), event, channel });
  }
  Vector2 wheels = Vector2::Zero();  ///< the last command [rad/s]

private:
  Plant& plant_;
  const SimClock& clock_;
  ClosedLoopRecord& record_;
};

/// The set point in force at time t.
const SetPointSegment* segmentAt(const std::vector<SetPointSegment>& profile, double t)
{
  const SetPointSegment* current = nullptr;
  for (const SetPointSegment& s : profile)
  {
    if (s.start <= t + 1e-9)
    {
      current = &s;
    }
  }
  return current;
}
}  // namespace

std::vector<SetPointSegment> profileSegments(const TwistProfile& profile, double t0)
{
  std::vector<SetPointSegment> out{ SetPointSegment{ 0.0, 0.0, 0.0 } };
  for (const TwistProfilePoint& p : profile.points)
  {
    out.push_back(SetPointSegment{ t0 + p.t, p.vx, p.wz });
  }
  return out;
}

std::vector<SetPointSegment> stepProfile(double t_step, double linear, double angular)
{
  return { { 0.0, 0.0, 0.0 }, { t_step, linear, angular } };
}

ClosedLoopRecord runClosedLoop(const RobotDescription& description, PlantParams params,
                               const ClosedLoopConfig& config)
{
  checkConfig(config);
  if (config.ideal_sensors)
  {
    makeSensorsIdeal(&params.sensors);
  }
  Plant plant(description, params);
  FaultedSensors sensors(params.sensors, params.physics.step);
  sensors.setFaults(config.faults, 0.0);
  std::vector<JointStateSample> joint_samples;
  std::vector<ImuSample> imu_samples;
  const double dt = params.physics.step;
  const double r = description.wheelRadius();
  const auto total = static_cast<std::uint64_t>(std::llround(config.duration / dt));
  const bool aic = config.controller == LoopController::kAic;

  StockController stock;
  const std::uint64_t stock_period = periodSteps(stock.params().publish_rate, dt);

  // The AIC: the node's logic on the plant's clock.
  ClosedLoopRecord out;
  SimClock clock;
  PlantOutput output(plant, clock, out);
  std::unique_ptr<ControlLoop> loop;
  std::uint64_t belief_period = 1;
  std::uint64_t action_period = 1;
  bool belief_timer = false;
  if (aic)
  {
    const NodeParams node = aicNodeParams(config, description);
    checkAicParams(node);
    loop = std::make_unique<ControlLoop>(node, clock, output);
    belief_period = periodSteps(config.aic.belief_rate, dt);
    action_period = periodSteps(config.aic.action_rate, dt);
    belief_timer = node.belief_schedule == BeliefSchedule::kTimer;
  }
  const double b_hat = aic ? config.aic.wheel_separation : stock.params().wheel_separation *
                                                               stock.params().wheel_separation_multiplier;
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
  double ideal_linear = 0.0;   // kIdeal's integral correction of the body speed [m/s]
  double ideal_angular = 0.0;  // and of the yaw rate [rad/s]
  const SetPointSegment* last_segment = nullptr;

  for (std::uint64_t k = 0; k < total; ++k)
  {
    const double t = plant.time();
    const SetPointSegment* seg = segmentAt(config.profile, t);
    const double sp_linear = seg ? seg->linear : 0.0;
    const double sp_angular = seg ? seg->angular : 0.0;

    if (config.controller == LoopController::kIdeal)
    {
      if (k % stock_period == 0)
      {
        // Lead: the set point command_delay ahead; integral of the ground-truth errors against the set
        // point in force (the command sent now acts after the delay, so the error is that of the
        // commands sent command_delay ago: the gain is kept well below 1 / delay).
        const double period = static_cast<double>(stock_period) * dt;
        ideal_linear += kIdealIntegralGain * (sp_linear - plant.baseLinearVelocity().x()) * period;
        ideal_angular += kIdealIntegralGain * (sp_angular - plant.baseAngularVelocity().z()) * period;
        const double clamp = params.motor.max_wheel_speed * r;
        ideal_linear = std::clamp(ideal_linear, -clamp, clamp);
        ideal_angular = std::clamp(ideal_angular, -2.0 * clamp / b_hat, 2.0 * clamp / b_hat);
        const SetPointSegment* ahead = segmentAt(config.profile, t + params.motor.command_delay);
        const double v = (ahead ? ahead->linear : 0.0) + ideal_linear;
        const double w = (ahead ? ahead->angular : 0.0) + ideal_angular;
        command_left = (v - 0.5 * b_hat * w) / r;
        command_right = (v + 0.5 * b_hat * w) / r;
        plant.setWheelSpeeds(command_left, command_right);
      }
    }
    else if (config.controller == LoopController::kOpenLoop)
    {
      if (k % stock_period == 0)
      {
        command_left = (sp_linear - 0.5 * b_hat * sp_angular) / r;
        command_right = (sp_linear + 0.5 * b_hat * sp_angular) / r;
        plant.setWheelSpeeds(command_left, command_right);
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
        plant.setWheelSpeeds(c.left, c.right);
      }
    }
    else
    {
      clock.t = t;
      if (seg != last_segment || k % stock_period == 0)
      {
        // Streamed at 50 Hz as teleop would, and at once when the profile changes.
        const double fields[6] = { sp_linear, 0.0, 0.0, 0.0, 0.0, sp_angular };
        loop->setPoint(fields);
      }
      if (k % action_period == 0)
      {
        loop->actionTimer(k == 0 ? -1.0 : static_cast<double>(action_period) * dt);
      }
      command_left = output.wheels(0);
      command_right = output.wheels(1);
    }
    last_segment = seg;

    plant.step();
    clock.t = plant.time();
    if (belief_timer && (k + 1) % belief_period == 0)
    {
      // The belief timer ticks before the samples of its instant: what it integrates up to
      // now used the inputs held until now, as the event schedule does.
      loop->beliefTimer(k + 1 == belief_period ? -1.0 : static_cast<double>(belief_period) * dt);
    }
    sensors.afterStep(plant, &joint_samples, &imu_samples);
    if (aic)
    {
      for (const ImuSample& imu : imu_samples)
      {
        ImuInput in;
        in.stamp = imu.stamp;
        in.angular_velocity = imu.angular_velocity;
        in.linear_acceleration = imu.linear_acceleration;
        loop->imu(in);
      }
    }
    for (const JointStateSample& js : joint_samples)  // the record and the loop, per joint-state sample
    {
      if (aic)
      {
        loop->advance();  // the beliefs at the sample's time, for the record
        out.active = out.active || loop->active();
        command_left = output.wheels(0);
        command_right = output.wheels(1);
      }
      const double wl = 0.5 * (js.velocity[kFrontLeft] + js.velocity[kRearLeft]);
      const double wr = 0.5 * (js.velocity[kFrontRight] + js.velocity[kRearRight]);
      const double belief_x = aic && out.active ? loop->controller().mu()(0, 0) : std::numeric_limits<double>::quiet_NaN();
      const double belief_w = aic && out.active ? loop->controller().mu()(2, 0) : std::numeric_limits<double>::quiet_NaN();
      out.time.push_back(js.stamp);
      out.set_point.push_back(sp_linear);
      out.v_odom.push_back(r * 0.5 * (wl + wr));
      out.v_true.push_back(plant.baseLinearVelocity().x());
      out.yaw_odom.push_back(r * (wr - wl) / b_hat);
      out.yaw_true.push_back(plant.baseAngularVelocity().z());
      out.command.push_back(r * 0.5 * (command_left + command_right));
      out.belief.push_back(belief_x);
      out.angular_set_point.push_back(sp_angular);
      out.command_yaw.push_back(r * (command_right - command_left) / b_hat);
      out.belief_yaw.push_back(belief_w);
      const Eigen::Isometry3d pose = plant.basePose();
      out.x_true.push_back(pose.translation().x());
      out.y_true.push_back(pose.translation().y());
      out.heading_true.push_back(std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)));

      if (aic)
      {
        for (int i = 0; i < kNumWheels; ++i)
        {
          joint_position[static_cast<std::size_t>(i)] = js.position[static_cast<std::size_t>(i)];
          joint_velocity[static_cast<std::size_t>(i)] = js.velocity[static_cast<std::size_t>(i)];
        }
        JointStateInput in;
        in.stamp = js.stamp;
        in.name = &joint_names;
        in.position = &joint_position;
        in.velocity = &joint_velocity;
        in.effort = &no_effort;
        const std::uint64_t no_imu = loop->pairing().drops(DropReason::kNoImu);
        loop->jointState(in);
        if (loop->pairing().drops(DropReason::kNoImu) > no_imu)
        {
          out.imu_missing.push_back(js.stamp);
        }
        out.active = out.active || loop->active();
      }
    }
  }
  if (aic)
  {
    out.runaways = loop->supervisor().runaways();
    out.belief_steps = loop->beliefSteps();
  }
  return out;
}

}  // namespace harness
}  // namespace jackal_aic
