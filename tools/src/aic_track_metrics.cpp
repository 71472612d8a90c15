/**
 * \file aic_track_metrics.cpp
 * \brief CLI: tracking metrics of a recorded run against a twist profile
 *        (include/jackal_aic/analysis/tracking_metrics.hpp), printed as one JSON line; or the profile
 *        itself, read and checked. The experiment scripts call this so that the profile reader,
 *        the velocity tracking error and the path drift have one implementation.
 *
 * Usage: aic_track_metrics --profile PROFILE.csv --print-profile
 *        aic_track_metrics --profile PROFILE.csv --trace TRACE.csv [--time-column t]
 *            [--ideal-csv FILE]
 *        aic_track_metrics --profile PROFILE.csv --floor-latency L [--floor-accel-linear A]
 *            [--floor-accel-angular B] [--floor-period T]
 *            [--floor-wheel-acceleration A_w --floor-wheel-radius r --floor-track b]
 * The latency floor (latencyFloor): the error of an ideal servo with latency L [s], the given
 * acceleration limits of the body (0 = none) or of each of its two wheels (radius r, b apart), and
 * its aim held for T [s] (0 = none), once holding the set point and once predicting it with the
 * goal rate (the AIC's recommended goal-rate settings): {"profile", "duration", "latency",
 * "hold": {"vx", "wz", "samples"}, "predict": {...}}.
 * PROFILE: t,vx,wz rows, zero-order hold, the last row's t ends it (header optional).
 * TRACE: a header naming the columns; time in profile time [s] (0 = the profile's start). Every
 * pair of columns S_vx, S_wz is a measured body twist S [m/s, rad/s] (velocity tracking error
 * "tracking": {"S": ...}; and how far S_vx moves back after each stop of the profile, "stops":
 * {"S": {"stops", "reverse_speed_max", "reverse_travel_max", "window"}}, stopReversal()); columns
 * x, y, heading [m, m, rad] are a measured pose (path drift "path"). An empty cell leaves the
 * sample out of that signal; a signal without any sample is null. '#' lines and empty lines are
 * skipped.
 * Exit 0 on success, 1 on bad files or data, 2 on bad arguments.
 */
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_aic/analysis/csv_table.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/analysis/tracking_metrics.hpp"

using namespace jackal_aic;

namespace
{
/// Samples (time, a, b[, c]) of the rows where every one of the columns `cols` has a cell.
struct Series
{
  std::vector<double> time;
  std::vector<std::vector<double>> values;
};

Series series(const analysis::CsvTable& csv, int tcol, const std::vector<int>& cols)
{
  Series s;
  s.values.resize(cols.size());
  for (std::size_t r = 0; r < csv.rows.size(); ++r)
  {
    bool present = true;
    for (int c : cols)
    {
      present = present && static_cast<std::size_t>(c) < csv.rows[r].size() &&
                !csv.rows[r][static_cast<std::size_t>(c)].empty();
    }
    if (!present)
    {
      continue;
    }
    s.time.push_back(csv.number(r, tcol, csv.header[static_cast<std::size_t>(tcol)]));
    for (std::size_t i = 0; i < cols.size(); ++i)
    {
      s.values[i].push_back(csv.number(r, cols[i], csv.header[static_cast<std::size_t>(cols[i])]));
    }
  }
  return s;
}

std::string profileJson(const analysis::TwistProfile& p)
{
  std::ostringstream os;
  os << "{\"name\": \"" << p.name << "\", \"duration\": " << base::jsonNumber(p.duration, 12) << ", \"points\": [";
  for (std::size_t i = 0; i < p.points.size(); ++i)
  {
    os << (i ? ", " : "") << "[" << base::jsonNumber(p.points[i].t, 12) << ", " << base::jsonNumber(p.points[i].vx, 12)
       << ", " << base::jsonNumber(p.points[i].wz, 12) << "]";
  }
  os << "]}";
  return os.str();
}
}  // namespace

int main(int argc, char** argv)
{
  std::string profile_file;
  std::string trace_file;
  std::string time_column = "t";
  std::string ideal_csv;
  bool print_profile = false;
  double floor_latency = 0.0;
  double floor_accel_linear = 0.0;
  double floor_accel_angular = 0.0;
  double floor_period = 0.0;
  double floor_wheel_acceleration = 0.0;
  double floor_wheel_radius = 0.0;
  double floor_track = 0.0;
  CommandLine cl("aic_track_metrics", "Tracking metrics of a recorded run against a twist profile (t, vx, wz; "
                                      "zero-order hold), one JSON "
                                      "line: per measured twist S (columns S_vx, S_wz) the RMS and max error of vx "
                                      "[m/s] and wz [rad/s]; "
                                      "with columns x, y, heading the path drift from the profile's ideal path (final "
                                      "and max position "
                                      "error [m], final heading error [rad]).");
  cl.option("profile", &profile_file, "twist profile CSV: t,vx,wz rows, the last row's t ends it", true);
  cl.option("trace", &trace_file, "recorded run, CSV with a header; time in profile time");
  cl.option("time-column", &time_column, "name of the trace's time column");
  cl.option("ideal-csv", &ideal_csv, "write the ideal path at the trace's pose samples (t,x,y,heading)");
  cl.flag("print-profile", &print_profile, "read and check the profile, print it as JSON, no trace");
  cl.option("floor-latency", &floor_latency,
            "latency floor instead of a trace: the error of an ideal servo with this latency [s], holding and "
            "predicting the set point");
  cl.option("floor-accel-linear", &floor_accel_linear, "the floor servo's largest |dvx/dt| [m/s^2], 0 = unlimited");
  cl.option("floor-accel-angular", &floor_accel_angular, "the floor servo's largest |dwz/dt| [rad/s^2], 0 = unlimited");
  cl.option("floor-period", &floor_period,
            "the floor servo holds its aim this long [s] (a controller's action period), 0 = none");
  cl.option("floor-wheel-acceleration", &floor_wheel_acceleration,
            "the floor servo's largest |d omega/dt| of each wheel [rad/s^2], 0 = unlimited (excludes --floor-accel-*)");
  cl.option("floor-wheel-radius", &floor_wheel_radius, "the wheel radius of --floor-wheel-acceleration [m]");
  cl.option("floor-track", &floor_track, "the wheels' left-right distance of --floor-wheel-acceleration [m]");
  cl.footer("Exit 0 on success, 1 on bad files or data, 2 on bad arguments.");
  if (const int code = cl.parse(argc, argv); code >= 0)
  {
    return code;
  }
  const bool floor = cl.given("floor-latency");
  if (static_cast<int>(print_profile) + static_cast<int>(!trace_file.empty()) + static_cast<int>(floor) != 1)
  {
    return cl.bad("give exactly one of --trace, --print-profile and --floor-latency");
  }
  if (floor && (floor_latency < 0.0 || floor_accel_linear < 0.0 || floor_accel_angular < 0.0 || floor_period < 0.0))
  {
    return cl.bad("--floor-latency, --floor-accel-* and --floor-period must be >= 0");
  }
  try
  {
    const analysis::TwistProfile profile = analysis::loadTwistProfileCsv(profile_file);
    if (print_profile)
    {
      std::cout << profileJson(profile) << "\n";
      return 0;
    }
    if (floor)
    {
      analysis::LatencyFloorSettings settings;
      settings.latency = floor_latency;
      settings.accel_linear = floor_accel_linear;
      settings.accel_angular = floor_accel_angular;
      settings.period = floor_period;
      settings.wheel_acceleration = floor_wheel_acceleration;
      settings.wheel_radius = floor_wheel_radius;
      settings.track = floor_track;
      const params::AicParams goal_rate = params::recommendedAicParams();
      const analysis::VelocityTrackingError hold = analysis::latencyFloor(profile, goal_rate, settings);
      settings.predict = true;
      const analysis::VelocityTrackingError predict = analysis::latencyFloor(profile, goal_rate, settings);
      std::cout << "{\"profile\": \"" << profile.name << "\", \"duration\": " << base::jsonNumber(profile.duration)
                << ", \"latency\": " << base::jsonNumber(floor_latency)
                << ", \"period\": " << base::jsonNumber(floor_period) << ", \"hold\": " << analysis::toJson(hold)
                << ", \"predict\": " << analysis::toJson(predict) << "}\n";
      return 0;
    }
    std::ifstream f(trace_file);
    if (!f)
    {
      throw std::invalid_argument("cannot open trace '" + trace_file + "'");
    }
    const analysis::CsvTable csv = analysis::readCsv(f, trace_file, analysis::CsvHeader::kRequired);
    const int tcol = csv.column(time_column);
    if (tcol < 0)
    {
      throw std::invalid_argument(trace_file + ": no time column '" + time_column + "' in the header");
    }
    // Signals: every S with columns S_vx and S_wz, in header order.
    std::ostringstream tracking;
    std::ostringstream stops;
    int signals = 0;
    for (const std::string& h : csv.header)
    {
      const std::string suffix = "_vx";
      if (h.size() <= suffix.size() || h.compare(h.size() - suffix.size(), suffix.size(), suffix) != 0)
      {
        continue;
      }
      const std::string name = h.substr(0, h.size() - suffix.size());
      const int wcol = csv.column(name + "_wz");
      if (wcol < 0)
      {
        continue;
      }
      const Series s = series(csv, tcol, { csv.column(h), wcol });
      // A signal with no sample at all (empty columns) is null; one with samples is analysed.
      tracking << (signals ? ", " : "") << "\"" << name << "\": "
               << (s.time.empty() ?
                       std::string("null") :
                       analysis::toJson(analysis::velocityTrackingError(profile, s.time, s.values[0], s.values[1])));
      stops << (signals ? ", " : "") << "\"" << name << "\": "
            << (s.time.empty() ?
                    std::string("null") :
                    analysis::toJson(analysis::stopReversal(profile, s.time, s.values[0], analysis::kStopWindow)));
      ++signals;
    }
    const int xcol = csv.column("x");
    const int ycol = csv.column("y");
    const int hcol = csv.column("heading");
    const bool have_pose = xcol >= 0 && ycol >= 0 && hcol >= 0;
    if (signals == 0 && !have_pose)
    {
      throw std::invalid_argument(trace_file + ": no S_vx, S_wz column pair and no x, y, heading columns");
    }
    std::string path = "null";
    if (have_pose)
    {
      const Series s = series(csv, tcol, { xcol, ycol, hcol });
      const analysis::PathDrift d = analysis::pathDrift(profile, s.time, s.values[0], s.values[1], s.values[2]);
      path = analysis::toJson(d);
      if (!ideal_csv.empty())
      {
        std::ofstream out(ideal_csv);
        out.precision(9);
        out << "t,x,y,heading\n";
        for (std::size_t k = 0; k < d.time.size(); ++k)
        {
          out << d.time[k] << "," << d.ideal[k].x << "," << d.ideal[k].y << "," << d.ideal[k].heading << "\n";
        }
        if (!out)
        {
          throw std::invalid_argument("cannot write " + ideal_csv);
        }
      }
    }
    std::cout << "{\"profile\": \"" << profile.name << "\", \"duration\": " << base::jsonNumber(profile.duration)
              << ", \"tracking\": {" << tracking.str() << "}, \"stops\": {" << stops.str() << "}, \"path\": " << path
              << "}\n";
  }
  catch (const std::exception& e)
  {
    std::cerr << "aic_track_metrics: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
