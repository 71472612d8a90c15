/**
 * \file plant_replay.cpp
 * \brief plant_replay: replay a /cmd_drive stream (from a robot's bag) or a twist profile through
 *        the stock controller on the ODE plant, headless and faster than real time, and write the
 *        streams a Jackal publishes at each joint-state sample (jackal_sim/harness/replay.hpp): the command
 *        in force, wheel positions and speeds (/joint_states), the IMU sample (/imu/data), the
 *        servo torques and the ground truth. The engine of `plant_identify.py --bag`.
 *
 * Usage: plant_replay (--drive FILE | --twist FILE) [--duration S] [--config PLANT.yaml]
 *            [--overlay FILE]... [--set key=value]... [--urdf FILE] [--noise] [--out FILE]
 *            [--commands-out FILE]
 *   --drive FILE  CSV with columns t [s], mode (jackal_msgs/Drive: 0 MODE_VELOCITY, -1 MODE_NONE),
 *                 left, right [rad/s]: the commands as the MCU received them, sorted by t
 *   --twist FILE  CSV with columns t [s], vx [m/s], wz [rad/s] (the profile format of
 *                 aic_experiment.py --profile csv): a set-point profile (zero-order hold, 0 before
 *                 the first row; the last row's t ends it), streamed to the stock controller (the
 *                 Jackal's diff_drive_controller mapping and limits, 50 Hz)
 *   --duration S  replay length [s]; default: --drive the last command's t + 1 s, --twist the
 *                 last row's t
 *   --overlay     plant YAML with only the keys that differ, after --config; repeatable
 *   --noise       keep the plant YAML's sensor noise, bias and dropout (default: ideal sensors)
 *   --commands-out FILE  also write the /cmd_drive stream the plant received (t, mode, left, right;
 *                 with --twist the stock controller's commands)
 *   --out FILE    output CSV (default: standard output); columns: t, cmd_mode, cmd_left, cmd_right,
 *                 pos_fl, pos_fr, pos_rl, pos_rr, vel_fl, vel_fr, vel_rl, vel_rr, imu_t, qx, qy, qz,
 *                 qw, gyro_x, gyro_y, gyro_z, accel_x, accel_y, accel_z, v_true, yaw_true,
 *                 torque_left, torque_right (wheels front/rear left/right; [rad], [rad/s], [m/s^2],
 *                 [N m]); imu_t is nan before the first IMU sample
 * Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments.
 */

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_aic/analysis/csv_table.hpp"
#include "jackal_aic/base/json_number.hpp"
#include "jackal_aic/analysis/tracking_metrics.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_tools/plant_cli.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/harness/replay.hpp"
#include "jackal_sim/plant/robot_description.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
/// jackal_msgs/Drive modes the replay accepts.
constexpr int kModeVelocity = 0;
constexpr int kModeNone = -1;

/// The /cmd_drive stream of a CSV file with the header t,mode,left,right (any column order).
std::vector<DriveCommand> driveCommands(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
  {
    throw std::invalid_argument("'" + path + "' cannot be opened");
  }
  const analysis::CsvTable t = analysis::readCsv(in, "'" + path + "'", analysis::CsvHeader::kRequired);
  const int ct = t.column("t"), cm = t.column("mode"), cl = t.column("left"), cr = t.column("right");
  if (ct < 0 || cm < 0 || cl < 0 || cr < 0)
  {
    throw std::invalid_argument(t.source + ": the header must name the columns t, mode, left, right");
  }
  if (t.rows.empty())
  {
    throw std::invalid_argument(t.source + ": no data rows");
  }
  std::vector<DriveCommand> out;
  for (std::size_t i = 0; i < t.rows.size(); ++i)
  {
    const double m = t.number(i, cm, "mode");
    const int mode = static_cast<int>(std::lround(m));
    if (m != mode || (mode != kModeVelocity && mode != kModeNone))
    {
      throw std::invalid_argument(t.where(i) + "mode " + base::jsonNumber(m) +
                                  " (allowed: 0 MODE_VELOCITY, -1 MODE_NONE; the plant's MCU model has no PWM or "
                                  "effort mode)");
    }
    const double time = t.number(i, ct, "t");
    if (!out.empty() && time < out.back().time)
    {
      throw std::invalid_argument(t.where(i) + "t " + base::jsonNumber(time) + " before the previous row's");
    }
    out.push_back({ time, mode == kModeVelocity, t.number(i, cl, "left"), t.number(i, cr, "right") });
  }
  return out;
}
}  // namespace

int main(int argc, char** argv)
{
  PlantOptions plant;
  std::string drive_file;
  std::string twist_file;
  std::string out_file;
  std::string commands_file;
  double duration = 0.0;
  bool noise = false;
  CommandLine cl("plant_replay", "Replay a /cmd_drive stream (or a twist profile through the stock controller) on the "
                                 "ODE plant, "
                                 "headless; write the joint-state, IMU, torque and ground-truth streams as CSV.");
  cl.option("drive", &drive_file, "CSV t,mode,left,right: the /cmd_drive stream (mode 0 velocity, -1 none)");
  cl.option("twist", &twist_file, "CSV t,vx,wz: a set-point profile for the stock controller (last row ends it)");
  cl.option("duration", &duration, "replay length [s] (default: --drive last t + 1 s, --twist last t)");
  plant.addTo(&cl);
  cl.flag("noise", &noise, "keep the plant YAML's sensor noise (default: ideal sensors)");
  cl.option("out", &out_file, "output CSV (default: standard output)");
  cl.option("commands-out", &commands_file, "also write the /cmd_drive stream received (t,mode,left,right)");
  cl.footer("Exit 0 on success, 1 on bad files or parameters, 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  if (drive_file.empty() == twist_file.empty())
  {
    return cl.bad("give exactly one of --drive and --twist");
  }
  if (cl.given("duration") && !(duration > 0.0))
  {
    return cl.bad("--duration must be > 0");
  }

  std::vector<ReplaySample> samples;
  std::vector<DriveCommand> commands;
  try
  {
    const RobotDescription desc = plant.description();
    const PlantParams params = plant.params();
    if (!drive_file.empty())
    {
      commands = driveCommands(drive_file);
      duration = cl.given("duration") ? duration : commands.back().time + 1.0;
    }
    else
    {
      const analysis::TwistProfile twist = analysis::loadTwistProfileCsv(twist_file);
      const std::vector<SetPointSegment> profile = profileSegments(twist, 0.0);
      duration = cl.given("duration") ? duration : twist.duration;
      commands = stockDriveCommands(profile, duration);
    }
    samples = replayDriveCommands(desc, params, commands, duration, !noise);
  }
  catch (const std::exception& e)
  {
    std::cerr << "plant_replay: " << e.what() << "\n";
    return 1;
  }

  char buf[64];
  auto num = [&buf](double v) {
    std::snprintf(buf, sizeof(buf), "%.9g", v);
    return std::string(buf);
  };
  if (!commands_file.empty())
  {
    std::ofstream c(commands_file);
    c << "t,mode,left,right\n";
    for (const DriveCommand& d : commands)
    {
      c << num(d.time) << "," << (d.enabled ? kModeVelocity : kModeNone) << "," << num(d.left) << "," << num(d.right)
        << "\n";
    }
    if (!c)
    {
      std::cerr << "plant_replay: cannot write " << commands_file << "\n";
      return 1;
    }
  }
  std::ofstream file;
  if (!out_file.empty())
  {
    file.open(out_file);
    if (!file)
    {
      std::cerr << "plant_replay: cannot write " << out_file << "\n";
      return 1;
    }
  }
  std::ostream& out = out_file.empty() ? std::cout : file;
  out << "t,cmd_mode,cmd_left,cmd_right,pos_fl,pos_fr,pos_rl,pos_rr,vel_fl,vel_fr,vel_rl,vel_rr,imu_t,qx,qy,qz,qw,"
         "gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z,v_true,yaw_true,torque_left,torque_right\n";
  for (const ReplaySample& s : samples)
  {
    std::ostringstream row;
    row << num(s.time) << "," << (s.command_enabled ? kModeVelocity : kModeNone) << "," << num(s.command_left) << ","
        << num(s.command_right);
    for (double p : s.position)
    {
      row << "," << num(p);
    }
    for (double v : s.velocity)
    {
      row << "," << num(v);
    }
    row << "," << num(s.imu_time) << "," << num(s.orientation.x()) << "," << num(s.orientation.y()) << ","
        << num(s.orientation.z()) << "," << num(s.orientation.w());
    for (int i = 0; i < 3; ++i)
    {
      row << "," << num(s.angular_velocity[i]);
    }
    for (int i = 0; i < 3; ++i)
    {
      row << "," << num(s.linear_acceleration[i]);
    }
    row << "," << num(s.v_true) << "," << num(s.yaw_true) << "," << num(s.torque_left) << "," << num(s.torque_right);
    out << row.str() << "\n";
  }
  out.flush();
  if (!out)
  {
    std::cerr << "plant_replay: cannot write the output\n";
    return 1;
  }
  return 0;
}
