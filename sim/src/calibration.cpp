#include "jackal_sim/calibration.hpp"

#include <cmath>
#include <stdexcept>

#include "jackal_sim/plant.hpp"
#include "jackal_sim/sensor_model.hpp"
#include "jackal_sim/stock_controller.hpp"

namespace jackal_aic
{
namespace sim
{
namespace
{
constexpr double kStepPhase = 0.01;  // s after a controller tick at which the set point changes
}

StepRecord runStockStep(const RobotDescription& description, PlantParams params, double step, double settle_before,
                        double record)
{
  if (!std::isfinite(step) || step == 0.0 || !(settle_before >= 0.0) || !(record > 0.0))
  {
    throw std::invalid_argument("runStockStep: step must be finite and non-zero, times positive");
  }
  JointStateSensorParams& js = params.sensors.joint_states;
  js.position_noise_std = 0.0;
  js.velocity_noise_std = 0.0;
  js.velocity_bias = 0.0;
  js.dropout = 0.0;
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

StepMetrics stepMetricsOf(const StepRecord& record, bool ground_truth)
{
  StepMetricsOptions o;
  o.step_time = 0.0;
  o.initial = 0.0;
  o.target = record.step;
  return computeStepMetrics(record.time, ground_truth ? record.v_true : record.v_odom, o);
}

}  // namespace sim
}  // namespace jackal_aic
