/**
 * \file tracking_metrics.cpp
 * \brief Twist profiles (CSV), velocity tracking error and path drift
 *        (include/jackal_aic/analysis/tracking_metrics.hpp; doc/tools.md, 'Tracking benchmark').
 */
#include "jackal_aic/analysis/tracking_metrics.hpp"

#include "jackal_aic/analysis/csv_table.hpp"
#include "jackal_aic/aic/goal_rate.hpp"
#include "jackal_aic/aic/skid_steer_model.hpp"
#include "jackal_aic/base/json_number.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <istream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace analysis
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
/// Below this |wz| [rad/s] a constant-twist piece is integrated as a straight line.
constexpr double kStraight = 1e-12;

void require(bool ok, const std::string& message)
{
  if (!ok)
  {
    throw std::invalid_argument(message);
  }
}

std::string baseName(const std::string& path)
{
  std::string name = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  const auto dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

std::string fmt(double v)
{
  return base::jsonNumber(v, 9);
}

void checkSeries(const std::string& what, const std::vector<double>& time,
                 const std::vector<const std::vector<double>*>& values)
{
  for (const auto* v : values)
  {
    require(v->size() == time.size(), what + ": time has " + std::to_string(time.size()) +
                                          " samples but a value "
                                          "series has " +
                                          std::to_string(v->size()));
  }
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    require(std::isfinite(time[k]), what + ": time[" + std::to_string(k) + "] is not finite");
    require(k == 0 || time[k] > time[k - 1], what + ": time is not strictly increasing at sample " + std::to_string(k));
    for (const auto* v : values)
    {
      require(std::isfinite((*v)[k]), what + ": a value at sample " + std::to_string(k) + " is not finite");
    }
  }
}

/// Pose after holding (vx, wz) for dt from p (exact: a straight line or a circular arc).
Pose2D advance(const Pose2D& p, double vx, double wz, double dt)
{
  Pose2D q;
  const double th1 = p.heading + wz * dt;
  if (std::abs(wz) < kStraight)
  {
    q.x = p.x + vx * dt * std::cos(p.heading);
    q.y = p.y + vx * dt * std::sin(p.heading);
  }
  else
  {
    q.x = p.x + vx / wz * (std::sin(th1) - std::sin(p.heading));
    q.y = p.y - vx / wz * (std::cos(th1) - std::cos(p.heading));
  }
  q.heading = th1;
  return q;
}
}  // namespace

void TwistProfile::setPointAt(double t, double* vx, double* wz) const
{
  *vx = 0.0;
  *wz = 0.0;
  // Last point with point.t <= t (points sorted by t).
  auto it = std::upper_bound(points.begin(), points.end(), t,
                             [](double value, const TwistProfilePoint& p) { return value < p.t; });
  if (it != points.begin())
  {
    --it;
    *vx = it->vx;
    *wz = it->wz;
  }
}

void TwistProfile::validate() const
{
  const std::string who = "twist profile" + (name.empty() ? std::string() : " " + name);
  require(!points.empty(), who + ": no set points");
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    const TwistProfilePoint& p = points[i];
    require(std::isfinite(p.t) && std::isfinite(p.vx) && std::isfinite(p.wz),
            who + ": point " + std::to_string(i) + " has a non-finite value");
    require(p.t >= 0.0, who + ": point " + std::to_string(i) + " has t < 0");
    require(i == 0 || p.t > points[i - 1].t, who + ": t is not strictly increasing at point " + std::to_string(i));
  }
  require(std::isfinite(duration) && duration > points.back().t, who + ": the end time must be finite and after the "
                                                                       "last set point");
}

TwistProfile parseTwistProfileCsv(std::istream& in, const std::string& source)
{
  const CsvTable csv = readCsv(in, source, CsvHeader::kOptional);
  int col_t = 0;
  int col_vx = 1;
  int col_wz = 2;
  std::size_t width = 3;
  if (!csv.header.empty())
  {
    col_t = csv.column("t");
    col_vx = csv.column("vx");
    col_wz = csv.column("wz");
    width = csv.header.size();
    require(col_t >= 0 && col_vx >= 0, source + " line " + std::to_string(csv.header_line) +
                                           ": the header must name the columns t and vx (and wz, else 0)");
  }
  std::vector<TwistProfilePoint> rows;
  for (std::size_t r = 0; r < csv.rows.size(); ++r)
  {
    require(csv.rows[r].size() == width,
            csv.where(r) + "expected " + std::to_string(width) + " cells, got " + std::to_string(csv.rows[r].size()));
    TwistProfilePoint p;
    p.t = csv.number(r, col_t, "t");
    p.vx = csv.number(r, col_vx, "vx");
    p.wz = col_wz >= 0 ? csv.number(r, col_wz, "wz") : 0.0;
    require(p.t >= 0.0, csv.where(r) + "t must be >= 0");
    require(rows.empty() || p.t > rows.back().t,
            csv.where(r) + "t must increase (" + fmt(p.t) + " after " + fmt(rows.empty() ? 0.0 : rows.back().t) + ")");
    rows.push_back(p);
  }
  require(rows.size() >= 2, source + ": need at least two rows (t, vx, wz); the last row's t ends the profile");
  TwistProfile profile;
  profile.duration = rows.back().t;
  rows.pop_back();
  profile.points = std::move(rows);
  profile.name = baseName(source);
  profile.validate();
  return profile;
}

TwistProfile loadTwistProfileCsv(const std::string& path)
{
  std::ifstream f(path);
  require(static_cast<bool>(f), "cannot open twist profile '" + path + "'");
  return parseTwistProfileCsv(f, path);
}

std::string twistProfileCsv(const TwistProfile& profile)
{
  std::ostringstream os;
  os.precision(10);
  os << "t,vx,wz\n";
  for (const TwistProfilePoint& p : profile.points)
  {
    os << p.t << "," << p.vx << "," << p.wz << "\n";
  }
  os << profile.duration << ",0,0\n";
  return os.str();
}

VelocityTrackingError velocityTrackingError(const TwistProfile& profile, const std::vector<double>& time,
                                            const std::vector<double>& vx, const std::vector<double>& wz)
{
  profile.validate();
  checkSeries("velocity tracking error", time, { &vx, &wz });
  VelocityTrackingError e;
  double sum_vx = 0.0;
  double sum_wz = 0.0;
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    if (time[k] < 0.0 || time[k] > profile.duration)
    {
      continue;
    }
    double sp_vx = 0.0;
    double sp_wz = 0.0;
    profile.setPointAt(time[k], &sp_vx, &sp_wz);
    const double ev = vx[k] - sp_vx;
    const double ew = wz[k] - sp_wz;
    sum_vx += ev * ev;
    sum_wz += ew * ew;
    e.vx.max = std::max(e.vx.max, std::abs(ev));
    e.wz.max = std::max(e.wz.max, std::abs(ew));
    ++e.samples;
  }
  require(e.samples > 0,
          "velocity tracking error: no sample between profile time 0 and the end " + fmt(profile.duration) + " s");
  e.vx.rms = std::sqrt(sum_vx / e.samples);
  e.wz.rms = std::sqrt(sum_wz / e.samples);
  return e;
}

namespace
{
/// The times at which one channel of the profile's set point changes value (from (0, 0) before
/// the first point), in order.
std::vector<double> changeTimes(const TwistProfile& profile, bool linear)
{
  std::vector<double> out;
  double value = 0.0;
  for (const auto& p : profile.points)
  {
    const double v = linear ? p.vx : p.wz;
    if (v != value)
    {
      out.push_back(p.t);
      value = v;
    }
  }
  return out;
}

/// Adds |estimate - truth| at profile time t to c when t is `settle` past the channel's last
/// change (changes: changeTimes()); a new segment counts when its first steady sample does.
void accumulateSteady(SteadyEstimateChannel* c, int* last_segment, const std::vector<double>& changes, double t,
                      double settle, double estimate, double truth)
{
  const auto it = std::upper_bound(changes.begin(), changes.end(), t);
  const int segment = static_cast<int>(it - changes.begin());
  const double last_change = segment > 0 ? *(it - 1) : 0.0;
  if (t - last_change < settle)
  {
    return;
  }
  const double e = std::abs(estimate - truth);
  c->mean_abs += e;  // the sum until the end
  c->max_abs = std::max(c->max_abs, e);
  ++c->samples;
  if (segment != *last_segment)
  {
    ++c->segments;
    *last_segment = segment;
  }
}
}  // namespace

SteadyEstimateError steadyEstimateError(const TwistProfile& profile, const std::vector<double>& time,
                                        const std::vector<double>& est_vx, const std::vector<double>& est_wz,
                                        const std::vector<double>& true_vx, const std::vector<double>& true_wz,
                                        double settle, double until)
{
  profile.validate();
  require(std::isfinite(settle) && settle >= 0.0,
          "steady estimate error: settle must be finite and >= 0 s, got " + fmt(settle));
  require(!std::isnan(until), "steady estimate error: until must not be NaN");
  require(est_vx.size() == time.size() && est_wz.size() == time.size(),
          "steady estimate error: time has " + std::to_string(time.size()) + " samples but an estimate series has " +
              std::to_string(est_vx.size() != time.size() ? est_vx.size() : est_wz.size()));
  checkSeries("steady estimate error", time, { &true_vx, &true_wz });
  const std::vector<double> changes_vx = changeTimes(profile, true);
  const std::vector<double> changes_wz = changeTimes(profile, false);
  SteadyEstimateError e;
  int seg_vx = -1;
  int seg_wz = -1;
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    const double t = time[k];
    if (t < 0.0 || t > profile.duration || t >= until)
    {
      continue;
    }
    if (!std::isfinite(est_vx[k]) || !std::isfinite(est_wz[k]))
    {
      ++e.unavailable;
      continue;
    }
    accumulateSteady(&e.vx, &seg_vx, changes_vx, t, settle, est_vx[k], true_vx[k]);
    accumulateSteady(&e.wz, &seg_wz, changes_wz, t, settle, est_wz[k], true_wz[k]);
  }
  for (SteadyEstimateChannel* c : { &e.vx, &e.wz })
  {
    c->mean_abs = c->samples > 0 ? c->mean_abs / c->samples : 0.0;
  }
  return e;
}

double turnoverTime(const std::vector<double>& time, const std::vector<double>& up)
{
  checkSeries("turnover time", time, { &up });
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    if (up[k] < 0.0)
    {
      return time[k];
    }
  }
  return std::numeric_limits<double>::infinity();
}

StopReversal stopReversal(const TwistProfile& profile, const std::vector<double>& time,
                          const std::vector<double>& true_vx, double window)
{
  profile.validate();
  require(std::isfinite(window) && window > 0.0, "stop reversal: window must be finite and > 0 s, got " + fmt(window));
  checkSeries("stop reversal", time, { &true_vx });
  StopReversal r;
  r.window = window;
  double before = 0.0;  // the linear set point before the point
  for (std::size_t i = 0; i < profile.points.size(); ++i)
  {
    const TwistProfilePoint& p = profile.points[i];
    if (p.vx == 0.0 && before != 0.0)
    {
      ++r.stops;
      double end = std::min(p.t + window, profile.duration);
      for (std::size_t j = i + 1; j < profile.points.size(); ++j)
      {
        if (profile.points[j].vx != 0.0)
        {
          end = std::min(end, profile.points[j].t);
          break;
        }
      }
      const double direction = before > 0.0 ? 1.0 : -1.0;
      double travel = 0.0;
      for (std::size_t k = 0; k < time.size(); ++k)
      {
        if (time[k] < p.t || time[k] >= end)
        {
          continue;
        }
        const double back = std::max(0.0, -direction * true_vx[k]);
        const double dt = k + 1 < time.size() ? time[k + 1] - time[k] : (k > 0 ? time[k] - time[k - 1] : 0.0);
        r.reverse_speed = std::max(r.reverse_speed, back);
        travel += back * dt;
      }
      r.reverse_travel = std::max(r.reverse_travel, travel);
    }
    before = p.vx;
  }
  return r;
}

VelocityTrackingError latencyFloor(const TwistProfile& profile, const params::AicParams& goal_rate,
                                   const LatencyFloorSettings& settings)
{
  profile.validate();
  const LatencyFloorSettings& s = settings;
  require(std::isfinite(s.latency) && s.latency >= 0.0 && s.latency <= 10.0,
          "latency floor: latency must be finite and in [0, 10] s, got " + fmt(s.latency));
  require(std::isfinite(s.accel_linear) && s.accel_linear >= 0.0 && std::isfinite(s.accel_angular) &&
              s.accel_angular >= 0.0,
          "latency floor: accelerations must be finite and >= 0 (0 = unlimited), got " + fmt(s.accel_linear) + ", " +
              fmt(s.accel_angular));
  require(std::isfinite(s.dt) && s.dt >= 1e-5 && s.dt <= 0.1,
          "latency floor: dt must be finite and in [1e-5, 0.1] s, got " + fmt(s.dt));
  require(std::isfinite(s.period) && s.period >= 0.0 && s.period <= 1.0,
          "latency floor: the hold period must be finite and in [0, 1] s, got " + fmt(s.period));
  require(std::isfinite(s.wheel_acceleration) && s.wheel_acceleration >= 0.0, "latency floor: the wheel acceleration "
                                                                              "must be finite and >= 0 (0 = "
                                                                              "unbounded), got " +
                                                                                  fmt(s.wheel_acceleration));
  const bool wheel_bound = s.wheel_acceleration > 0.0;
  require(!wheel_bound || (std::isfinite(s.wheel_radius) && s.wheel_radius > 0.0 && std::isfinite(s.track) &&
                           s.track > 0.0 && s.accel_linear == 0.0 && s.accel_angular == 0.0),
          "latency floor: a wheel acceleration needs a finite wheel radius and track > 0 and no body accelerations, "
          "got radius " +
              fmt(s.wheel_radius) + ", track " + fmt(s.track));
  aic::GoalRateEstimator estimator(goal_rate.reference);
  const std::size_t n = static_cast<std::size_t>(std::floor(profile.duration / s.dt)) + 1;
  const std::size_t lag = static_cast<std::size_t>(std::llround(s.latency / s.dt));
  // A new aim every `aim_every` samples (T_h / dt, at least 1), held between.
  const std::size_t aim_every = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(s.period / s.dt)));
  const double lead = s.latency + 0.5 * s.period;
  // u[k]: what the servo aims at, from the stream as received up to time k dt.
  std::vector<double> time(n), u_vx(n), u_wz(n);
  std::size_t next = 0;
  for (std::size_t k = 0; k < n; ++k)
  {
    const double t = static_cast<double>(k) * s.dt;
    time[k] = t;
    for (; next < profile.points.size() && profile.points[next].t <= t + 1e-12; ++next)
    {
      const TwistProfilePoint& p = profile.points[next];
      estimator.update(p.t, base::Vector3(p.vx, 0.0, p.wz));
    }
    if (k % aim_every != 0)
    {
      u_vx[k] = u_vx[k - 1];
      u_wz[k] = u_wz[k - 1];
      continue;
    }
    double vx = 0.0;
    double wz = 0.0;
    profile.setPointAt(t, &vx, &wz);
    if (s.predict)
    {
      const base::Vector3 ahead =
          aic::predictGoal(base::Vector3(vx, 0.0, wz), estimator.rate(t), base::Vector3::Constant(lead));
      vx = ahead.x();
      wz = ahead.z();
    }
    u_vx[k] = vx;
    u_wz[k] = wz;
  }
  // y[k] = rate-limited u[k - lag], zero before the latency has passed: the body's twist, or
  // each wheel's speed of it.
  auto follow = [](double y, double target, double limit) {
    return limit > 0.0 ? y + std::clamp(target - y, -limit, limit) : target;
  };
  std::vector<double> y_vx(n), y_wz(n);
  double prev_vx = 0.0;
  double prev_wz = 0.0;
  std::optional<aic::SkidSteerModel> wheels;
  if (wheel_bound)
  {
    wheels.emplace(s.wheel_radius, 1.0, s.track);
  }
  base::Vector2 omega = base::Vector2::Zero();
  for (std::size_t k = 0; k < n; ++k)
  {
    const double vx = k >= lag ? u_vx[k - lag] : 0.0;
    const double wz = k >= lag ? u_wz[k - lag] : 0.0;
    if (wheels)
    {
      const base::Vector2 target = wheels->wheelsFromTwist(base::Vector3(vx, 0.0, wz));
      omega(0) = follow(omega(0), target(0), s.wheel_acceleration * s.dt);
      omega(1) = follow(omega(1), target(1), s.wheel_acceleration * s.dt);
      const base::Vector3 twist = wheels->twistFromWheels(omega);
      y_vx[k] = twist(0);
      y_wz[k] = twist(2);
      continue;
    }
    prev_vx = y_vx[k] = follow(prev_vx, vx, s.accel_linear * s.dt);
    prev_wz = y_wz[k] = follow(prev_wz, wz, s.accel_angular * s.dt);
  }
  return velocityTrackingError(profile, time, y_vx, y_wz);
}

std::vector<Pose2D> idealPath(const TwistProfile& profile, const Pose2D& start, double t_start,
                              const std::vector<double>& times)
{
  profile.validate();
  require(std::isfinite(start.x) && std::isfinite(start.y) && std::isfinite(start.heading) && std::isfinite(t_start),
          "ideal path: non-finite start pose or time");
  std::vector<Pose2D> out;
  out.reserve(times.size());
  Pose2D pose = start;
  double t = t_start;
  // Index of the next breakpoint after t.
  std::size_t next =
      static_cast<std::size_t>(std::upper_bound(profile.points.begin(), profile.points.end(), t,
                                                [](double value, const TwistProfilePoint& p) { return value < p.t; }) -
                               profile.points.begin());
  for (std::size_t k = 0; k < times.size(); ++k)
  {
    const double target = times[k];
    require(std::isfinite(target) && target >= t,
            "ideal path: times must be finite, >= t_start and non-decreasing (sample " + std::to_string(k) + ")");
    // Constant twist between breakpoints: advance piece by piece.
    while (t < target)
    {
      const double piece_end = next < profile.points.size() ? std::min(profile.points[next].t, target) : target;
      double vx = 0.0;
      double wz = 0.0;
      profile.setPointAt(t, &vx, &wz);
      pose = advance(pose, vx, wz, piece_end - t);
      t = piece_end;
      while (next < profile.points.size() && profile.points[next].t <= t)
      {
        ++next;
      }
    }
    out.push_back(pose);
  }
  return out;
}

PathDrift pathDrift(const TwistProfile& profile, const std::vector<double>& time, const std::vector<double>& x,
                    const std::vector<double>& y, const std::vector<double>& heading)
{
  profile.validate();
  checkSeries("path drift", time, { &x, &y, &heading });
  require(!time.empty() && time.front() <= profile.duration,
          "path drift: no sample at or before the profile's end " + fmt(profile.duration) + " s");
  std::size_t s = 0;
  for (std::size_t k = 0; k < time.size() && time[k] <= 0.0; ++k)
  {
    s = k;
  }
  PathDrift d;
  d.t_start = time[s];
  std::vector<Pose2D> measured;
  double unwrapped = heading[s];
  for (std::size_t k = s; k < time.size() && time[k] <= profile.duration; ++k)
  {
    if (k > s)
    {
      // Continuous heading: add the wrapped increment.
      unwrapped += std::remainder(heading[k] - heading[k - 1], 2.0 * kPi);
    }
    d.time.push_back(time[k]);
    Pose2D p;
    p.x = x[k];
    p.y = y[k];
    p.heading = unwrapped;
    measured.push_back(p);
  }
  d.ideal = idealPath(profile, measured.front(), d.t_start, d.time);
  d.samples = static_cast<int>(d.time.size());
  for (std::size_t k = 0; k < measured.size(); ++k)
  {
    const double err = std::hypot(measured[k].x - d.ideal[k].x, measured[k].y - d.ideal[k].y);
    d.max_position_error = std::max(d.max_position_error, err);
    d.final_position_error = err;
  }
  // Length of the ideal path: the integral of |vx| over the analysed span, piece by piece.
  for (double t = d.t_start; t < d.time.back();)
  {
    const auto next = std::upper_bound(profile.points.begin(), profile.points.end(), t,
                                       [](double value, const TwistProfilePoint& p) { return value < p.t; });
    const double piece_end = next == profile.points.end() ? d.time.back() : std::min(next->t, d.time.back());
    double vx = 0.0;
    double wz = 0.0;
    profile.setPointAt(t, &vx, &wz);
    d.ideal_length += std::abs(vx) * (piece_end - t);
    t = piece_end;
  }
  d.final_heading_error = measured.back().heading - d.ideal.back().heading;
  return d;
}

std::string toJson(const VelocityTrackingError& e)
{
  std::ostringstream os;
  os << "{\"vx\": {\"rms\": " << fmt(e.vx.rms) << ", \"max\": " << fmt(e.vx.max)
     << "}, \"wz\": {\"rms\": " << fmt(e.wz.rms) << ", \"max\": " << fmt(e.wz.max) << "}, \"samples\": " << e.samples
     << "}";
  return os.str();
}

std::string toJson(const SteadyEstimateError& e)
{
  std::ostringstream os;
  os << "{";
  for (const auto& [name, c] : { std::pair<const char*, const SteadyEstimateChannel&>("vx", e.vx),
                                 std::pair<const char*, const SteadyEstimateChannel&>("wz", e.wz) })
  {
    os << "\"" << name << "\": {\"steady_mean_abs\": " << fmt(c.mean_abs) << ", \"steady_max_abs\": " << fmt(c.max_abs)
       << ", \"samples\": " << c.samples << ", \"segments\": " << c.segments << "}, ";
  }
  os << "\"unavailable\": " << e.unavailable << "}";
  return os.str();
}

std::string toJson(const StopReversal& r)
{
  std::ostringstream os;
  os << "{\"stops\": " << r.stops << ", \"reverse_speed_max\": " << fmt(r.reverse_speed)
     << ", \"reverse_travel_max\": " << fmt(r.reverse_travel) << ", \"window\": " << fmt(r.window) << "}";
  return os.str();
}

std::string toJson(const PathDrift& d)
{
  std::ostringstream os;
  os << "{\"final_position_error\": " << fmt(d.final_position_error)
     << ", \"max_position_error\": " << fmt(d.max_position_error)
     << ", \"final_heading_error\": " << fmt(d.final_heading_error) << ", \"ideal_length\": " << fmt(d.ideal_length)
     << ", \"samples\": " << d.samples << "}";
  return os.str();
}

}  // namespace analysis
}  // namespace jackal_aic
