#include "jackal_sim/harness/turning.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "jackal_sim/harness/stock_controller.hpp"
#include "jackal_sim/plant/plant.hpp"

namespace jackal_aic
{
namespace harness
{
using namespace plant;

double TwistRun::separation() const
{
  if (!(std::abs(yaw_rate) > 1e-6))
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return wheel_radius * (wheel_right - wheel_left) / yaw_rate;
}

TwistRun runStockTwist(const RobotDescription& description, const PlantParams& params, double linear, double angular,
                       const TwistRunOptions& o)
{
  if (!std::isfinite(linear) || !std::isfinite(angular))
  {
    throw std::invalid_argument("runStockTwist: the twist must be finite");
  }
  if (!(o.settle >= 0.0) || !(o.window > 0.0) || !(o.duration > o.window) || !(o.reach > 0.0 && o.reach <= 1.0) ||
      !(o.tolerance > 0.0) || !std::isfinite(o.settle + o.duration))
  {
    throw std::invalid_argument("runStockTwist: options need settle >= 0, duration > window > 0, reach in (0, 1], "
                                "tolerance > 0");
  }
  Plant plant(description, params);
  StockController stock;
  const double h = params.physics.step;
  const auto ctrl_period = static_cast<std::uint64_t>(std::llround(1.0 / (stock.params().publish_rate * h)));
  const auto settle_steps = static_cast<std::uint64_t>(std::llround(o.settle / h));
  const auto total = settle_steps + static_cast<std::uint64_t>(std::llround(o.duration / h));
  const auto window_start = total - static_cast<std::uint64_t>(std::llround(o.window / h));
  TwistRun out;
  out.linear = linear;
  out.angular = angular;
  out.wheel_radius = description.wheelRadius();
  out.reach_time = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t n = 0;
  for (std::uint64_t k = 0; k < total; ++k)
  {
    // The command starts on a controller tick after the settling; streamed, as teleop would.
    if (k % ctrl_period == 0)
    {
      const double t = plant.time();
      const bool on = k >= settle_steps;
      stock.setCommand(on ? linear : 0.0, on ? angular : 0.0, t);
      const WheelSpeedCommand c = stock.update(t);
      plant.setWheelSpeeds(c.left, c.right);
    }
    plant.step();
    if (k < settle_steps)
    {
      continue;
    }
    const double v = plant.baseLinearVelocity().x();
    const double w = plant.baseAngularVelocity().z();
    if (std::isnan(out.reach_time))
    {
      const bool yaw_ok = angular == 0.0 || w * angular >= o.reach * angular * angular;
      const bool speed_ok = linear == 0.0 || v * linear >= o.reach * linear * linear;
      if (yaw_ok && speed_ok)
      {
        out.reach_time = static_cast<double>(k + 1 - settle_steps) * h;
      }
    }
    if (k >= window_start)
    {
      out.v_true += v;
      out.yaw_rate += w;
      out.wheel_left += plant.sideVelocity(kLeft);
      out.wheel_right += plant.sideVelocity(kRight);
      out.torque_left += plant.servo(kLeft).torque();
      out.torque_right += plant.servo(kRight).torque();
      ++n;
    }
  }
  const double inv = 1.0 / static_cast<double>(n);
  out.v_true *= inv;
  out.yaw_rate *= inv;
  out.wheel_left *= inv;
  out.wheel_right *= inv;
  out.torque_left *= inv;
  out.torque_right *= inv;
  const double v_band = linear == 0.0 ? 0.02 : o.tolerance * std::abs(linear);
  const double w_band = angular == 0.0 ? 0.02 : o.tolerance * std::abs(angular);
  out.followed = std::abs(out.v_true - linear) <= v_band && std::abs(out.yaw_rate - angular) <= w_band;
  return out;
}

std::vector<TwistRun> runTurningGrid(const RobotDescription& description, const PlantParams& params,
                                     const TurningGrid& grid, const TwistRunOptions& options)
{
  std::vector<TwistRun> out;
  for (double w : grid.in_place)
  {
    out.push_back(runStockTwist(description, params, 0.0, w, options));
  }
  for (double v : grid.speeds)
  {
    for (double w : grid.yaw_rates)
    {
      out.push_back(runStockTwist(description, params, v, w, options));
    }
  }
  return out;
}

}  // namespace harness
}  // namespace jackal_aic
