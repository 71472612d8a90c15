#include "jackal_sim/harness/calibration.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/sensor_model.hpp"
#include "jackal_sim/harness/stock_controller.hpp"

namespace jackal_aic
{
namespace harness
{
using namespace plant;  // the plant this part drives

namespace
{
constexpr double kStepPhase = 0.01;  // s after a controller tick at which the set point changes

/// The robot's table was measured from its own wheel odometry: calibrate on noiseless,
/// bias-free, gap-free joint states.
void makeJointStatesIdeal(PlantParams* params)
{
  JointStateSensorParams& js = params->sensors.joint_states;
  js.position_noise_std = 0.0;
  js.velocity_noise_std = 0.0;
  js.velocity_bias = 0.0;
  js.dropout = 0.0;
}
}  // namespace

StepRecord runStockStep(const RobotDescription& description, PlantParams params, double step, double settle_before,
                        double record)
{
  if (!std::isfinite(step) || step == 0.0 || !(settle_before >= 0.0) || !(record > 0.0))
  {
    throw std::invalid_argument("runStockStep: step must be finite and non-zero, times positive");
  }
  makeJointStatesIdeal(&params);
  Plant plant(description, params);
  SensorModel sensors(params.sensors, params.physics.step);
  StockController stock;
  const double h = params.physics.step;
  const auto ctrl_period = static_cast<std::uint64_t>(std::llround(1.0 / (stock.params().publish_rate * h)));
  const double r = description.wheelRadius();
  const double t_step = settle_before + kStepPhase;
  const auto total = static_cast<std::uint64_t>(std::llround((t_step + record) / h));
  StepRecord out;
  out.step = step;
  for (std::uint64_t k = 0; k < total; ++k)
  {
    const double t = plant.time();
    const bool stepped = t >= t_step - 1e-9;
    // The set point is streamed (as teleop or a planner would), so cmd_vel_timeout never fires.
    if (k % ctrl_period == 0 || (stepped && t < t_step + h / 2))
    {
      stock.setCommand(stepped ? step : 0.0, 0.0, t);
    }
    if (k % ctrl_period == 0)
    {
      const WheelSpeedCommand c = stock.update(t);
      plant.setWheelSpeeds(c.left, c.right);
    }
    plant.step();
    sensors.record(plant);
    JointStateSample s;
    if (sensors.pollJointStates(&s) && plant.time() >= t_step)
    {
      const double wl = 0.5 * (s.velocity[kFrontLeft] + s.velocity[kRearLeft]);
      const double wr = 0.5 * (s.velocity[kFrontRight] + s.velocity[kRearRight]);
      out.time.push_back(plant.time() - t_step);
      out.v_odom.push_back(r * 0.5 * (wl + wr));
      out.v_true.push_back(plant.baseLinearVelocity().x());
      out.command.push_back(stock.lastLinear());
    }
  }
  return out;
}

double SteadyDrive::effectiveSeparation() const
{
  if (!(std::abs(yaw_rate) > 1e-6))
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return wheel_radius * (wheel_right - wheel_left) / yaw_rate;
}

SteadyDrive runSteadyDrive(const RobotDescription& description, PlantParams params, const SteadyScenario& scenario,
                           double settle, double measure)
{
  if (!std::isfinite(scenario.a) || !std::isfinite(scenario.b) || !(settle > 0.0) || !(measure > 0.0) ||
      !std::isfinite(settle + measure))
  {
    throw std::invalid_argument("runSteadyDrive: inputs must be finite, times positive");
  }
  makeJointStatesIdeal(&params);
  Plant plant(description, params);
  SensorModel sensors(params.sensors, params.physics.step);
  StockController stock;
  const double h = params.physics.step;
  const auto ctrl_period = static_cast<std::uint64_t>(std::llround(1.0 / (stock.params().publish_rate * h)));
  const auto total = static_cast<std::uint64_t>(std::llround((settle + measure) / h));
  const bool use_stock = scenario.input == DriveInput::kStockTwist;
  if (!use_stock)
  {
    plant.setWheelSpeeds(scenario.a, scenario.b);
  }
  SteadyDrive out;
  out.wheel_radius = description.wheelRadius();
  std::size_t n = 0;
  for (std::uint64_t k = 0; k < total; ++k)
  {
    if (use_stock && k % ctrl_period == 0)
    {
      const double t = plant.time();
      stock.setCommand(scenario.a, scenario.b, t);  // streamed, as teleop or a planner would
      const WheelSpeedCommand c = stock.update(t);
      plant.setWheelSpeeds(c.left, c.right);
    }
    plant.step();
    sensors.record(plant);
    JointStateSample s;
    if (sensors.pollJointStates(&s) && plant.time() >= settle - 1e-9)
    {
      out.wheel_left += 0.5 * (s.velocity[kFrontLeft] + s.velocity[kRearLeft]);
      out.wheel_right += 0.5 * (s.velocity[kFrontRight] + s.velocity[kRearRight]);
      const Eigen::Vector3d v = plant.baseLinearVelocity();
      out.v_true += v.x();
      out.v_lateral += v.y();
      out.yaw_rate += plant.baseAngularVelocity().z();
      ++n;
    }
  }
  if (n == 0)
  {
    throw std::invalid_argument("runSteadyDrive: no joint-state sample in the measuring window");
  }
  const double inv = 1.0 / static_cast<double>(n);
  out.wheel_left *= inv;
  out.wheel_right *= inv;
  out.v_true *= inv;
  out.v_lateral *= inv;
  out.yaw_rate *= inv;
  out.v_odom = out.wheel_radius * 0.5 * (out.wheel_left + out.wheel_right);
  return out;
}

analysis::StepMetrics stepMetricsOf(const StepRecord& record, bool ground_truth)
{
  analysis::StepMetricsOptions o;
  o.step_time = 0.0;
  o.initial = 0.0;
  o.target = record.step;
  return analysis::computeStepMetrics(record.time, ground_truth ? record.v_true : record.v_odom, o);
}

}  // namespace harness
}  // namespace jackal_aic
