#include "jackal_sim/harness/replay.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

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
void checkDuration(double duration, const char* who)
{
  if (!(duration > 0.0) || !std::isfinite(duration))
  {
    throw std::invalid_argument(std::string(who) + ": duration must be finite and > 0");
  }
}
}  // namespace

std::vector<ReplaySample> replayDriveCommands(const RobotDescription& description, PlantParams params,
                                              const std::vector<DriveCommand>& commands, double duration,
                                              bool ideal_sensors)
{
  checkDuration(duration, "replayDriveCommands");
  if (commands.empty())
  {
    throw std::invalid_argument("replayDriveCommands: empty command stream");
  }
  for (std::size_t i = 0; i < commands.size(); ++i)
  {
    const DriveCommand& c = commands[i];
    const bool bad_time = !std::isfinite(c.time) || c.time < 0.0 || (i > 0 && c.time < commands[i - 1].time);
    const bool bad_value = c.enabled && (!std::isfinite(c.left) || !std::isfinite(c.right));
    if (bad_time || bad_value)
    {
      throw std::invalid_argument(
          "replayDriveCommands: command " + std::to_string(i) +
          (bad_time ? " has a negative, non-finite or out-of-order time" : " has a non-finite set point"));
    }
  }
  if (ideal_sensors)
  {
    params.sensors = idealSensors(params.sensors);
  }
  Plant plant(description, params);
  SensorModel sensors(params.sensors, params.physics.step);
  const double h = params.physics.step;
  const auto total = static_cast<std::uint64_t>(std::llround(duration / h));
  std::vector<ReplaySample> out;
  std::size_t next = 0;
  DriveCommand last;
  last.enabled = false;
  ReplaySample imu;
  imu.imu_time = std::numeric_limits<double>::quiet_NaN();
  for (std::uint64_t k = 0; k < total; ++k)
  {
    const double t = plant.time();
    // Every command received by now reaches the MCU, in order (h / 2: receipt times are not on the grid).
    while (next < commands.size() && commands[next].time <= t + 0.5 * h)
    {
      last = commands[next++];
      if (last.enabled)
      {
        plant.setWheelSpeeds(last.left, last.right);
      }
      else
      {
        plant.releaseMotors();
      }
    }
    plant.step();
    sensors.record(plant);
    ImuSample imu_now;
    if (sensors.pollImu(&imu_now))
    {
      imu.imu_time = imu_now.stamp;
      imu.orientation = imu_now.orientation;
      imu.angular_velocity = imu_now.angular_velocity;
      imu.linear_acceleration = imu_now.linear_acceleration;
    }
    JointStateSample js;
    if (!sensors.pollJointStates(&js))
    {
      continue;
    }
    ReplaySample s = imu;
    s.time = js.stamp;
    s.position = js.position;
    s.velocity = js.velocity;
    s.v_true = plant.baseLinearVelocity().x();
    s.yaw_true = plant.baseAngularVelocity().z();
    s.command_enabled = last.enabled;
    s.command_left = last.left;
    s.command_right = last.right;
    s.torque_left = plant.servo(kLeft).torque();
    s.torque_right = plant.servo(kRight).torque();
    out.push_back(s);
  }
  return out;
}

std::vector<DriveCommand> stockDriveCommands(const std::vector<SetPointSegment>& profile, double duration)
{
  checkDuration(duration, "stockDriveCommands");
  if (profile.empty())
  {
    throw std::invalid_argument("stockDriveCommands: empty set-point profile");
  }
  for (std::size_t i = 0; i < profile.size(); ++i)
  {
    const SetPointSegment& s = profile[i];
    if (!std::isfinite(s.start) || !std::isfinite(s.linear) || !std::isfinite(s.angular) ||
        (i > 0 && s.start < profile[i - 1].start))
    {
      throw std::invalid_argument("stockDriveCommands: segment " + std::to_string(i) +
                                  " is non-finite or out of order");
    }
  }
  StockController stock;
  const double period = 1.0 / stock.params().publish_rate;
  std::vector<DriveCommand> out;
  std::size_t seg = 0;  // profile[seg - 1] is in force; 0 = none yet
  for (std::uint64_t k = 0;; ++k)
  {
    const double t = static_cast<double>(k) * period;
    if (t >= duration - 1e-9)
    {
      break;
    }
    while (seg < profile.size() && profile[seg].start <= t + 1e-9)
    {
      ++seg;
    }
    const double linear = seg > 0 ? profile[seg - 1].linear : 0.0;
    const double angular = seg > 0 ? profile[seg - 1].angular : 0.0;
    stock.setCommand(linear, angular, t);  // streamed, as teleop or a planner would
    const WheelSpeedCommand c = stock.update(t);
    out.push_back({ t, true, c.left, c.right });
  }
  return out;
}

}  // namespace harness
}  // namespace jackal_aic
