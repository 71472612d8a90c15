#include "jackal_sim/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "jackal_aic/controller.hpp"
#include "jackal_aic/generalizer.hpp"
#include "jackal_sim/plant.hpp"
#include "jackal_sim/sensor_model.hpp"
#include "jackal_sim/stock_controller.hpp"

namespace jackal_aic
{
namespace sim
{
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
  if (config.controller == LoopController::kAic)
  {
    const auto violations = config.aic.validate();
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
}

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
  SensorModel sensors(params.sensors, params.physics.step);
  const double dt = params.physics.step;
  const double r = description.wheelRadius();
  const auto total = static_cast<std::uint64_t>(std::llround(config.duration / dt));
  const bool aic = config.controller == LoopController::kAic;

  StockController stock;
  const std::uint64_t stock_period = periodSteps(stock.params().publish_rate, dt);

  std::unique_ptr<ActiveInferenceController> controller;
  std::unique_ptr<Generalizer> generalizer;
  std::uint64_t belief_period = 1;
  std::uint64_t action_period = 1;
  if (aic)
  {
    controller = std::make_unique<ActiveInferenceController>(config.aic);
    generalizer = std::make_unique<Generalizer>(kYDim, config.aic.embedding_order);
    belief_period = periodSteps(config.aic.belief_rate, dt);
    action_period = periodSteps(config.aic.action_rate, dt);
  }
  const double b_hat = aic ? config.aic.wheel_separation : stock.params().wheel_separation *
                                                               stock.params().wheel_separation_multiplier;

  ClosedLoopRecord out;
  ImuSample imu;
  bool have_imu = false;
  double last_sample_stamp = 0.0;
  bool have_sample = false;
  int warm_samples = 0;
  Vector2 measured_wheels = Vector2::Zero();
  double last_belief_time = 0.0;
  double last_action_time = 0.0;
  double command_left = 0.0;
  double command_right = 0.0;

  for (std::uint64_t k = 0; k < total; ++k)
  {
    const double t = plant.time();
    const SetPointSegment* seg = segmentAt(config.profile, t);
    const double sp_linear = seg ? seg->linear : 0.0;
    const double sp_angular = seg ? seg->angular : 0.0;

    if (config.controller == LoopController::kOpenLoop)
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
      controller->setGoal(Vector3(sp_linear, 0.0, sp_angular));
      if (!out.active && warm_samples >= config.aic.numOrders())
      {
        // The node's activation: bumpless start from the measured wheels and twist.
        controller->reset();
        controller->setGoal(Vector3(sp_linear, 0.0, sp_angular));
        controller->setMeasurement(generalizer->yTilde());
        controller->setAction(measured_wheels);
        MuTilde mu = MuTilde::Zero(kMuDim, config.aic.numOrders());
        mu.col(0) = controller->model().twistFromWheels(measured_wheels);
        controller->setBeliefs(mu);
        out.active = true;
        last_belief_time = t;
        last_action_time = t;
      }
      if (out.active && k % belief_period == 0 && t > last_belief_time)
      {
        if (controller->updateBeliefs(t - last_belief_time) == ActiveInferenceController::Status::kRunaway)
        {
          ++out.runaways;
        }
        last_belief_time = t;
      }
      if (out.active && k % action_period == 0 && t > last_action_time)
      {
        if (controller->updateAction(t - last_action_time) == ActiveInferenceController::Status::kRunaway)
        {
          ++out.runaways;
        }
        last_action_time = t;
        command_left = controller->action()(0);
        command_right = controller->action()(1);
        plant.setWheelSpeeds(command_left, command_right);
      }
    }

    plant.step();
    sensors.record(plant);
    ImuSample imu_now;
    if (sensors.pollImu(&imu_now))
    {
      imu = imu_now;
      have_imu = true;
    }
    JointStateSample js;
    if (!sensors.pollJointStates(&js))
    {
      continue;
    }
    const double wl = 0.5 * (js.velocity[kFrontLeft] + js.velocity[kRearLeft]);
    const double wr = 0.5 * (js.velocity[kFrontRight] + js.velocity[kRearRight]);
    out.time.push_back(js.stamp);
    out.set_point.push_back(sp_linear);
    out.v_odom.push_back(r * 0.5 * (wl + wr));
    out.v_true.push_back(plant.baseLinearVelocity().x());
    out.yaw_odom.push_back(r * (wr - wl) / b_hat);
    out.yaw_true.push_back(plant.baseAngularVelocity().z());
    out.command.push_back(r * 0.5 * (command_left + command_right));
    out.belief.push_back(aic && out.active ? controller->mu()(0, 0) : std::numeric_limits<double>::quiet_NaN());
    out.angular_set_point.push_back(sp_angular);
    out.command_yaw.push_back(r * (command_right - command_left) / b_hat);
    out.belief_yaw.push_back(aic && out.active ? controller->mu()(2, 0) : std::numeric_limits<double>::quiet_NaN());
    const Eigen::Isometry3d pose = plant.basePose();
    out.x_true.push_back(pose.translation().x());
    out.y_true.push_back(pose.translation().y());
    out.heading_true.push_back(std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)));

    if (aic && have_imu)
    {
      Vector5 y;
      y(kGyroZ) = imu.angular_velocity.z();
      y(kOmegaLeft) = wl;
      y(kOmegaRight) = wr;
      y(kAccelX) = imu.linear_acceleration.x();
      y(kAccelY) = imu.linear_acceleration.y();
      const double h = have_sample ? js.stamp - last_sample_stamp : 0.0;
      const Generalizer::Status s = generalizer->update(y, h);
      if (s == Generalizer::Status::kOk || s == Generalizer::Status::kFirstSample)
      {
        have_sample = true;
        last_sample_stamp = js.stamp;
        warm_samples = std::min(warm_samples + 1, kMaxOrders + 1);
        measured_wheels << wl, wr;
        if (out.active)
        {
          controller->setMeasurement(generalizer->yTilde());
        }
      }
    }
  }
  return out;
}

}  // namespace sim
}  // namespace jackal_aic
