/// Tests of the twist-profile CSV reader, the velocity tracking error and the path drift
/// against closed-form paths (include/jackal_aic/analysis/tracking_metrics.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "jackal_aic/analysis/tracking_metrics.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-9;

analysis::TwistProfile parse(const std::string& text)
{
  std::istringstream in(text);
  return analysis::parseTwistProfileCsv(in, "dir/test_profile.csv");
}

/// The message of the std::invalid_argument parse(text) throws ("" if none).
std::string parseError(const std::string& text)
{
  try
  {
    parse(text);
  }
  catch (const std::invalid_argument& e)
  {
    return e.what();
  }
  return "";
}

analysis::TwistProfile profileOf(std::vector<analysis::TwistProfilePoint> points, double duration)
{
  analysis::TwistProfile p;
  p.points = std::move(points);
  p.duration = duration;
  return p;
}

/// Times 0, dt, ..., <= t_end.
std::vector<double> grid(double t0, double t_end, double dt)
{
  std::vector<double> t;
  for (int k = 0; t0 + k * dt <= t_end + 1e-12; ++k)
  {
    t.push_back(t0 + k * dt);
  }
  return t;
}

/// Pose by Euler integration of the profile's set point with a fine step (reference for the exact arcs).
analysis::Pose2D eulerPose(const analysis::TwistProfile& p, double t_end, double h)
{
  analysis::Pose2D q;
  for (double t = 0.0; t < t_end - 1e-12; t += h)
  {
    double vx = 0.0;
    double wz = 0.0;
    p.setPointAt(t + 0.5 * h, &vx, &wz);
    const double th = q.heading + 0.5 * wz * h;  // midpoint rule
    q.x += vx * h * std::cos(th);
    q.y += vx * h * std::sin(th);
    q.heading += wz * h;
  }
  return q;
}
}  // namespace

TEST(TwistProfileCsv, HeaderCommentsAndZeroOrderHold)
{
  const analysis::TwistProfile p = parse("# a comment\n\nt,vx,wz\n0,0,0\n1.0,0.5,0\n2.5,0.5,-0.25\n4,0,0\n");
  EXPECT_EQ(p.name, "test_profile");
  ASSERT_EQ(p.points.size(), 3u);
  EXPECT_DOUBLE_EQ(p.duration, 4.0);
  double vx = 0.0;
  double wz = 0.0;
  p.setPointAt(0.999, &vx, &wz);
  EXPECT_EQ(vx, 0.0);
  p.setPointAt(1.0, &vx, &wz);
  EXPECT_EQ(vx, 0.5);
  EXPECT_EQ(wz, 0.0);
  p.setPointAt(3.0, &vx, &wz);
  EXPECT_EQ(vx, 0.5);
  EXPECT_EQ(wz, -0.25);
  // Round trip through twistProfileCsv.
  const analysis::TwistProfile q = parse(analysis::twistProfileCsv(p));
  ASSERT_EQ(q.points.size(), p.points.size());
  EXPECT_EQ(q.points[2].wz, -0.25);
  EXPECT_EQ(q.duration, 4.0);
}

TEST(TwistProfileCsv, NoHeaderColumnOrderAndMissingWz)
{
  const analysis::TwistProfile a = parse("0.5,0.2,0.1\n1,0,0\n");
  ASSERT_EQ(a.points.size(), 1u);
  EXPECT_EQ(a.points[0].t, 0.5);
  EXPECT_EQ(a.points[0].wz, 0.1);
  double vx = 1.0;
  double wz = 1.0;
  a.setPointAt(0.2, &vx, &wz);  // before the first point: rest
  EXPECT_EQ(vx, 0.0);
  EXPECT_EQ(wz, 0.0);
  const analysis::TwistProfile b = parse("wz, vx, t\n0.3,0.2,0\n0,0,2\n");
  EXPECT_EQ(b.points[0].vx, 0.2);
  EXPECT_EQ(b.points[0].wz, 0.3);
  EXPECT_EQ(b.duration, 2.0);
  const analysis::TwistProfile c = parse("t,vx\n0,0.4\n3,0\n");
  EXPECT_EQ(c.points[0].wz, 0.0);
}

TEST(TwistProfileCsv, BadFilesAreRefusedWithTheLine)
{
  EXPECT_NE(parseError("").find("at least two rows"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,0,0\n").find("at least two rows"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,nan,0\n1,0,0\n").find("line 2: vx 'nan' is not finite"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,0,inf\n1,0,0\n").find("wz 'inf' is not finite"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,0,0\n1,fast,0\n").find("line 3: vx 'fast' is not a number"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,0,0\n1,0.5\n").find("expected 3 cells, got 2"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n1,0,0\n1,0.5,0\n").find("t must increase"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n1,0,0\n0.5,0.5,0\n").find("line 3: t must increase"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n-1,0,0\n1,0.5,0\n").find("t must be >= 0"), std::string::npos);
  EXPECT_NE(parseError("time,speed\n0,0\n1,0\n").find("must name the columns t and vx"), std::string::npos);
  EXPECT_NE(parseError("t,vx,wz\n0,0,0\n1,,0\n").find("'' is not a number"), std::string::npos);
  EXPECT_THROW(analysis::loadTwistProfileCsv("/nonexistent/profile.csv"), std::invalid_argument);
}

TEST(TwistProfile, ValidateRefusesBadProfiles)
{
  EXPECT_THROW(profileOf({}, 1.0).validate(), std::invalid_argument);
  EXPECT_THROW(profileOf({ { 0.0, 0.1, 0.0 } }, 0.0).validate(), std::invalid_argument);
  EXPECT_THROW(profileOf({ { 0.0, std::numeric_limits<double>::quiet_NaN(), 0.0 } }, 1.0).validate(),
               std::invalid_argument);
  EXPECT_THROW(profileOf({ { 0.5, 0.1, 0.0 }, { 0.5, 0.2, 0.0 } }, 1.0).validate(), std::invalid_argument);
  EXPECT_NO_THROW(profileOf({ { 0.0, 0.1, 0.0 } }, 1.0).validate());
}

TEST(VelocityTrackingError, OffsetsAndWindow)
{
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 }, { 1.0, 0.5, 1.0 } }, 2.0);
  const std::vector<double> t = grid(-1.0, 3.0, 0.02);
  std::vector<double> vx;
  std::vector<double> wz;
  for (double x : t)
  {
    // Outside [0, 2] a wild value that must not count; inside: vx 0.1 low, wz alternating +-0.2 off.
    const bool in = x >= 0.0 && x <= 2.0;
    vx.push_back(in ? 0.4 : 100.0);
    double sv = 0.0;
    double sw = 0.0;
    p.setPointAt(x, &sv, &sw);
    const int k = static_cast<int>(std::lround(x / 0.02));
    wz.push_back(in ? sw + (k % 2 == 0 ? 0.2 : -0.2) : -100.0);
  }
  const analysis::VelocityTrackingError e = analysis::velocityTrackingError(p, t, vx, wz);
  EXPECT_EQ(e.samples, 101);
  EXPECT_NEAR(e.vx.rms, 0.1, kTol);
  EXPECT_NEAR(e.vx.max, 0.1, kTol);
  EXPECT_NEAR(e.wz.rms, 0.2, kTol);
  EXPECT_NEAR(e.wz.max, 0.2, kTol);
  // A first-order lag's RMS error: a 0.5 m/s step answered by 0.5 (1 - exp(-t / T)).
  const analysis::TwistProfile step = profileOf({ { 0.0, 0.5, 0.0 } }, 10.0);
  const std::vector<double> tt = grid(0.0, 10.0, 1e-3);
  std::vector<double> lag;
  const std::vector<double> zero(tt.size(), 0.0);
  for (double x : tt)
  {
    lag.push_back(0.5 * (1.0 - std::exp(-x / 0.2)));
  }
  const analysis::VelocityTrackingError l = analysis::velocityTrackingError(step, tt, lag, zero);
  // mean of 0.25 exp(-2 t / T) over 10 s = 0.25 T / 2 / 10.
  EXPECT_NEAR(l.vx.rms, std::sqrt(0.25 * 0.1 / 10.0), 2e-3);
  EXPECT_NEAR(l.vx.max, 0.5, kTol);
  EXPECT_EQ(l.wz.rms, 0.0);
}

TEST(VelocityTrackingError, BadInput)
{
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 } }, 1.0);
  EXPECT_THROW(analysis::velocityTrackingError(p, { 0.0, 0.5 }, { 0.0 }, { 0.0, 0.0 }), std::invalid_argument);
  EXPECT_THROW(
      analysis::velocityTrackingError(p, { 0.0, 0.5 }, { 0.0, std::numeric_limits<double>::infinity() }, { 0.0, 0.0 }),
      std::invalid_argument);
  EXPECT_THROW(analysis::velocityTrackingError(p, { 0.5, 0.5 }, { 0.0, 0.0 }, { 0.0, 0.0 }), std::invalid_argument);
  EXPECT_THROW(analysis::velocityTrackingError(p, { 2.0, 3.0 }, { 0.0, 0.0 }, { 0.0, 0.0 }), std::invalid_argument);
  EXPECT_THROW(analysis::velocityTrackingError(profileOf({}, 1.0), { 0.0 }, { 0.0 }, { 0.0 }), std::invalid_argument);
}

TEST(IdealPath, LinesArcsAndTurnsInPlace)
{
  // A full circle: 1 m/s at 0.5 rad/s for 4 pi s returns to the start; a quarter circle ends at (R, R).
  const analysis::TwistProfile circle = profileOf({ { 0.0, 1.0, 0.5 } }, 4.0 * kPi);
  const auto c = analysis::idealPath(circle, analysis::Pose2D{}, 0.0, { kPi, 4.0 * kPi });
  EXPECT_NEAR(c[0].x, 2.0, kTol);
  EXPECT_NEAR(c[0].y, 2.0, kTol);
  EXPECT_NEAR(c[0].heading, 0.5 * kPi, kTol);
  EXPECT_NEAR(c[1].x, 0.0, kTol);
  EXPECT_NEAR(c[1].y, 0.0, kTol);
  EXPECT_NEAR(c[1].heading, 2.0 * kPi, kTol);  // continuous heading
  // Straight from a rotated, offset start; rest before the first point.
  const analysis::TwistProfile line = profileOf({ { 1.0, 0.5, 0.0 } }, 5.0);
  analysis::Pose2D start;
  start.x = 1.0;
  start.y = -1.0;
  start.heading = 0.5 * kPi;
  const auto l = analysis::idealPath(line, start, -0.5, { -0.5, 1.0, 3.0 });
  EXPECT_NEAR(l[1].y, -1.0, kTol);
  EXPECT_NEAR(l[2].x, 1.0, kTol);
  EXPECT_NEAR(l[2].y, 0.0, kTol);
  // A turn in place only turns.
  const analysis::TwistProfile spin = profileOf({ { 0.0, 0.0, -1.5 } }, 2.0);
  const auto s = analysis::idealPath(spin, analysis::Pose2D{}, 0.0, { 2.0 });
  EXPECT_NEAR(s[0].x, 0.0, kTol);
  EXPECT_NEAR(s[0].heading, -3.0, kTol);
  // A mixed profile against fine midpoint integration.
  const analysis::TwistProfile mix = profileOf(
      { { 0.0, 0.8, 0.0 }, { 0.7, 0.8, 0.5 }, { 1.9, -0.3, -1.2 }, { 2.6, 0.0, 2.0 }, { 3.1, 1.5, 0.05 } }, 5.0);
  // (The reference's error is O(h * v) at each breakpoint a step straddles.)
  const analysis::Pose2D ref = eulerPose(mix, 4.9, 1e-6);
  const auto m = analysis::idealPath(mix, analysis::Pose2D{}, 0.0, grid(0.0, 4.9, 0.02));
  EXPECT_NEAR(m.back().x, ref.x, 1e-5);
  EXPECT_NEAR(m.back().y, ref.y, 1e-5);
  EXPECT_NEAR(m.back().heading, ref.heading, 1e-5);
  EXPECT_THROW(analysis::idealPath(mix, analysis::Pose2D{}, 1.0, { 0.5 }), std::invalid_argument);
  EXPECT_THROW(analysis::idealPath(mix, analysis::Pose2D{}, 0.0, { 1.0, 0.5 }), std::invalid_argument);
}

TEST(PathDrift, ExactOffsetAndWrappedHeading)
{
  // Two full turns on a circle; the measurement is the ideal path shifted 0.1 m in y, heading
  // wrapped to (-pi, pi] and 0.05 rad ahead; samples from t = -0.25 (at rest), 64 Hz (exact stamps).
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.6, 1.0 } }, 4.0 * kPi);
  const std::vector<double> t = grid(-0.25, 4.0 * kPi + 0.5, 1.0 / 64.0);
  const auto ideal = analysis::idealPath(p, analysis::Pose2D{}, -0.25, t);
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> h;
  for (std::size_t k = 0; k < t.size(); ++k)
  {
    const double off = t[k] > 0.0 ? 0.1 : 0.0;  // the start pose is exact
    x.push_back(ideal[k].x);
    y.push_back(ideal[k].y + off);
    h.push_back(std::remainder(ideal[k].heading + (t[k] > 0.0 ? 0.05 : 0.0), 2.0 * kPi));
  }
  const analysis::PathDrift d = analysis::pathDrift(p, t, x, y, h);
  EXPECT_EQ(d.t_start, 0.0);  // the last sample at t <= 0
  EXPECT_NEAR(d.final_position_error, 0.1, 1e-9);
  EXPECT_NEAR(d.max_position_error, 0.1, 1e-9);
  EXPECT_NEAR(d.final_heading_error, 0.05, 1e-9);
  EXPECT_NEAR(d.ideal_length, 0.6 * d.time.back(), 1e-9);
  EXPECT_LE(d.time.back(), p.duration);
  EXPECT_EQ(d.samples, static_cast<int>(d.time.size()));
  EXPECT_EQ(d.ideal.size(), d.time.size());
}

TEST(PathDrift, ATurnShortByARevolutionIsNotHidden)
{
  // Commanded: 2 pi rad in place over 4 s; measured: no turn at all. The heading error is
  // -2 pi, not 0 (continuous headings).
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.0, 0.5 * kPi } }, 4.0);
  const std::vector<double> t = grid(0.0, 4.0, 0.02);
  const std::vector<double> zero(t.size(), 0.0);
  const analysis::PathDrift d = analysis::pathDrift(p, t, zero, zero, zero);
  EXPECT_NEAR(d.final_heading_error, -2.0 * kPi, 1e-9);
  EXPECT_NEAR(d.final_position_error, 0.0, 1e-12);
  EXPECT_EQ(d.ideal_length, 0.0);
}

TEST(PathDrift, BadInput)
{
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 } }, 1.0);
  const std::vector<double> two{ 0.0, 0.5 };
  EXPECT_THROW(analysis::pathDrift(p, two, { 0.0 }, two, two), std::invalid_argument);
  EXPECT_THROW(analysis::pathDrift(p, { 0.0, 0.0 }, two, two, two), std::invalid_argument);
  EXPECT_THROW(analysis::pathDrift(p, two, two, { 0.0, std::numeric_limits<double>::quiet_NaN() }, two),
               std::invalid_argument);
  EXPECT_THROW(analysis::pathDrift(p, { 2.0, 3.0 }, two, two, two), std::invalid_argument);
  EXPECT_THROW(analysis::pathDrift(p, {}, {}, {}, {}), std::invalid_argument);
}

TEST(LatencyFloor, AStepArrivesOneLatencyLate)
{
  // 0.5 m/s from t = 1 s: the servo holding the set point is 0.5 m/s short for L = 0.1 s of the
  // 3 s (3001 samples at 1 ms), so RMS = 0.5 sqrt(100 / 3001); no latency, no error.
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.0, 0.0 }, { 1.0, 0.5, -1.0 } }, 3.0);
  analysis::LatencyFloorSettings s;
  s.latency = 0.1;
  const analysis::VelocityTrackingError e = analysis::latencyFloor(p, params::recommendedAicParams(), s);
  EXPECT_EQ(e.samples, 3001);
  EXPECT_NEAR(e.vx.rms, 0.5 * std::sqrt(100.0 / 3001.0), 1e-9);
  EXPECT_NEAR(e.vx.max, 0.5, 1e-12);
  EXPECT_NEAR(e.wz.rms, 1.0 * std::sqrt(100.0 / 3001.0), 1e-9);
  s.latency = 0.0;
  EXPECT_NEAR(analysis::latencyFloor(p, params::recommendedAicParams(), s).vx.rms, 0.0, 1e-12);
  // A step has no slope to predict: the same floor.
  s.latency = 0.1;
  s.predict = true;
  EXPECT_NEAR(analysis::latencyFloor(p, params::recommendedAicParams(), s).vx.rms, e.vx.rms, 1e-12);
}

TEST(LatencyFloor, AHeldAimWaitsForTheNextTick)
{
  // The step at 1.005 s, aims taken every 20 ms: the servo sees it at the 1.02 s tick, 15 ms late,
  // so it is 0.5 m/s short for L + 15 ms = 115 of the 3001 samples; with the step on a tick
  // (1.0 s) the hold costs nothing.
  analysis::LatencyFloorSettings s;
  s.latency = 0.1;
  s.period = 0.02;
  const analysis::TwistProfile off_tick = profileOf({ { 0.0, 0.0, 0.0 }, { 1.005, 0.5, 0.0 } }, 3.0);
  EXPECT_NEAR(analysis::latencyFloor(off_tick, params::recommendedAicParams(), s).vx.rms,
              0.5 * std::sqrt(115.0 / 3001.0), 1e-9);
  const analysis::TwistProfile on_tick = profileOf({ { 0.0, 0.0, 0.0 }, { 1.0, 0.5, 0.0 } }, 3.0);
  EXPECT_NEAR(analysis::latencyFloor(on_tick, params::recommendedAicParams(), s).vx.rms,
              0.5 * std::sqrt(100.0 / 3001.0), 1e-9);
  s.period = 0.0;
  EXPECT_NEAR(analysis::latencyFloor(off_tick, params::recommendedAicParams(), s).vx.rms,
              0.5 * std::sqrt(100.0 / 3001.0), 1e-9);
  for (const double bad : { -0.01, 1.5, std::numeric_limits<double>::quiet_NaN() })
  {
    s.period = bad;
    EXPECT_THROW(analysis::latencyFloor(on_tick, params::recommendedAicParams(), s), std::invalid_argument) << bad;
  }
}

TEST(LatencyFloor, TheAccelerationLimitRampsTheStep)
{
  // No latency, 5 m/s^2: the error falls from 0.5 to 0 over 0.1 s; RMS over 3 s ->
  // sqrt(0.5^3 / (3 * 5) / 3) = 0.0527 (0.0523 on the 1 ms grid).
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.0, 0.0 }, { 1.0, 0.5, 0.0 } }, 3.0);
  analysis::LatencyFloorSettings s;
  s.accel_linear = 5.0;
  const analysis::VelocityTrackingError e = analysis::latencyFloor(p, params::recommendedAicParams(), s);
  EXPECT_NEAR(e.vx.rms, std::sqrt(0.125 / 15.0 / 3.0), 1e-3);
  EXPECT_LT(e.vx.rms, std::sqrt(0.125 / 15.0 / 3.0));
  EXPECT_EQ(e.wz.rms, 0.0);
}

TEST(LatencyFloor, ATurnAndASpeedChangeShareTheWheels)
{
  // 1 m/s and 1 rad/s from t = 1 s on wheels of r = 0.1 m, 0.4 m apart, each at most 10 rad/s^2:
  // the wheels go to 8 and 12 rad/s side by side, so the turn starts only when the left wheel is
  // there (0.8 s) and is reached at 1.2 s. Error 1 rad/s for 800 samples, then falling to 0 over
  // 400: RMS sqrt((800 + 400 / 3) / 3001). The same bound on the body (A_w r, 2 A_w r / track)
  // takes the turn in 0.2 s.
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.0, 0.0 }, { 1.0, 1.0, 1.0 } }, 3.0);
  analysis::LatencyFloorSettings s;
  s.wheel_acceleration = 10.0;
  s.wheel_radius = 0.1;
  s.track = 0.4;
  const analysis::VelocityTrackingError wheels = analysis::latencyFloor(p, params::recommendedAicParams(), s);
  EXPECT_NEAR(wheels.wz.rms, std::sqrt((800.0 + 400.0 / 3.0) / 3001.0), 2e-3);
  EXPECT_NEAR(wheels.wz.max, 1.0, 1e-12);
  analysis::LatencyFloorSettings body;
  body.accel_linear = 1.0;
  body.accel_angular = 5.0;
  const analysis::VelocityTrackingError shared = analysis::latencyFloor(p, params::recommendedAicParams(), body);
  EXPECT_NEAR(shared.wz.rms, std::sqrt(200.0 / 3.0 / 3001.0), 2e-3);
  EXPECT_NEAR(wheels.vx.rms, shared.vx.rms, 0.05);  // the speed change is near the same
  // The wheel bound needs its geometry and stands alone.
  s.track = 0.0;
  EXPECT_THROW(analysis::latencyFloor(p, params::recommendedAicParams(), s), std::invalid_argument);
  s.track = 0.4;
  s.accel_linear = 1.0;
  EXPECT_THROW(analysis::latencyFloor(p, params::recommendedAicParams(), s), std::invalid_argument);
  s.accel_linear = 0.0;
  s.wheel_acceleration = std::numeric_limits<double>::infinity();
  EXPECT_THROW(analysis::latencyFloor(p, params::recommendedAicParams(), s), std::invalid_argument);
}

TEST(LatencyFloor, PredictingARampLowersTheFloor)
{
  // A 10 Hz planner's staircase ramp, 0.05 m/s each 0.1 s from 1 s to 3 s, then held: the
  // prediction misses only at the ramp's ends.
  std::vector<analysis::TwistProfilePoint> pts{ { 0.0, 0.0, 0.0 } };
  for (int k = 1; k <= 20; ++k)
  {
    pts.push_back({ 0.9 + 0.1 * k, 0.05 * k, 0.0 });
  }
  const analysis::TwistProfile p = profileOf(pts, 4.0);
  analysis::LatencyFloorSettings s;
  s.latency = 0.12;
  const double hold = analysis::latencyFloor(p, params::recommendedAicParams(), s).vx.rms;
  s.predict = true;
  const double predict = analysis::latencyFloor(p, params::recommendedAicParams(), s).vx.rms;
  EXPECT_GT(hold, 0.01);
  EXPECT_LT(predict, 0.6 * hold);
}

TEST(LatencyFloor, BadSettingsAreRefused)
{
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 } }, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [latency, accel, dt] : std::vector<std::tuple<double, double, double>>{ { -0.1, 0.0, 1e-3 },
                                                                                           { nan, 0.0, 1e-3 },
                                                                                           { 11.0, 0.0, 1e-3 },
                                                                                           { 0.1, -1.0, 1e-3 },
                                                                                           { 0.1, nan, 1e-3 },
                                                                                           { 0.1, 0.0, 0.0 },
                                                                                           { 0.1, 0.0, nan },
                                                                                           { 0.1, 0.0, 1.0 } })
  {
    analysis::LatencyFloorSettings s;
    s.latency = latency;
    s.accel_angular = accel;
    s.dt = dt;
    EXPECT_THROW(analysis::latencyFloor(p, params::recommendedAicParams(), s), std::invalid_argument)
        << latency << " " << accel << " " << dt;
  }
  EXPECT_THROW(
      analysis::latencyFloor(profileOf({}, 1.0), params::recommendedAicParams(), analysis::LatencyFloorSettings{}),
      std::invalid_argument);
}

TEST(SteadyEstimateError, CountsOnlySettledSamplesPerChannel)
{
  // vx: 0 until 1 s, then 0.5 (repeated rows with the same value are no change); wz: 0 until 2 s,
  // then 0.3. Estimate = truth + 0.02 on vx and + 0.1 on wz everywhere, except a 1.0 error on both
  // channels in the 0.5 s after each channel's change (the transient the measure leaves out).
  const analysis::TwistProfile p =
      profileOf({ { 0.0, 0.0, 0.0 }, { 1.0, 0.5, 0.0 }, { 1.5, 0.5, 0.0 }, { 2.0, 0.5, 0.3 } }, 4.0);
  const std::vector<double> t = grid(0.005, 3.995, 0.01);  // no sample on a boundary
  std::vector<double> tv(t.size(), 0.0), tw(t.size(), 0.0), ev(t.size()), ew(t.size());
  for (std::size_t k = 0; k < t.size(); ++k)
  {
    const bool transient = (t[k] >= 1.0 && t[k] < 1.5) || (t[k] >= 2.0 && t[k] < 2.5);
    ev[k] = tv[k] + (transient ? 1.0 : 0.02);
    ew[k] = tw[k] + (transient ? 1.0 : 0.1);
  }
  const analysis::SteadyEstimateError e = analysis::steadyEstimateError(p, t, ev, ew, tv, tw, 0.5);
  // vx changes at 1.0 only (0 at t = 0 is no change): steady [0.5, 1.0) and [1.5, 4.0].
  // vx is steady in wz's transient [2.0, 2.5): those 50 samples carry the 1.0 error.
  EXPECT_EQ(e.vx.segments, 2);
  EXPECT_EQ(e.vx.samples, 50 + 250);
  EXPECT_NEAR(e.vx.mean_abs, (250 * 0.02 + 50 * 1.0) / 300.0, 1e-12);
  EXPECT_NEAR(e.vx.max_abs, 1.0, 1e-12);
  // wz changes at 2.0 only: steady [0.5, 2.0) (vx's transient [1.0, 1.5) in it) and [2.5, 4.0].
  EXPECT_EQ(e.wz.segments, 2);
  EXPECT_EQ(e.wz.samples, 150 + 150);
  EXPECT_NEAR(e.wz.mean_abs, (250 * 0.1 + 50 * 1.0) / 300.0, 1e-12);
  EXPECT_EQ(e.unavailable, 0);
  // The control: with settle 0 every sample counts, the transients too.
  const analysis::SteadyEstimateError all = analysis::steadyEstimateError(p, t, ev, ew, tv, tw, 0.0);
  EXPECT_EQ(all.vx.samples, static_cast<int>(t.size()));
  EXPECT_GT(all.vx.mean_abs, 0.1);
}

TEST(SteadyEstimateError, AGoalBiasedBeliefOfAStallIsSeen)
{
  // A 1 rad/s turn the robot cannot make (truth 0.1 rad/s) with a belief at the goal.
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.0, 1.0 } }, 3.0);
  const std::vector<double> t = grid(0.0, 3.0, 0.02);
  const std::vector<double> zero(t.size(), 0.0), stall(t.size(), 0.1), goal(t.size(), 1.0);
  const analysis::SteadyEstimateError e = analysis::steadyEstimateError(p, t, zero, goal, zero, stall, 0.5);
  EXPECT_NEAR(e.wz.mean_abs, 0.9, 1e-12);
  EXPECT_EQ(e.wz.segments, 1);
  EXPECT_NEAR(analysis::steadyEstimateError(p, t, zero, stall, zero, stall, 0.5).wz.mean_abs, 0.0, 1e-15);
}

TEST(SteadyEstimateError, MissingEstimatesAreCountedAndBadInputRefused)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 } }, 2.0);
  const std::vector<double> t = grid(0.0, 2.0, 0.5);  // 0, 0.5, 1, 1.5, 2
  const std::vector<double> z(t.size(), 0.0);
  const analysis::SteadyEstimateError e =
      analysis::steadyEstimateError(p, t, { nan, 0.1, 0.1, nan, 0.1 }, z, z, z, 0.5);
  EXPECT_EQ(e.unavailable, 2);
  EXPECT_EQ(e.vx.samples, 3);  // 0.5 s after the change at 0: from t = 0.5 on, two NaN left out
  EXPECT_NEAR(e.vx.mean_abs, 0.1, 1e-12);
  EXPECT_THROW(analysis::steadyEstimateError(p, t, z, z, z, z, -0.1), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(p, t, z, z, z, z, nan), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(p, t, { 0.0 }, z, z, z, 0.5), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(p, t, z, z, { 0.0, nan, 0.0, 0.0, 0.0 }, z, 0.5), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(p, { 0.0, 0.0, 1.0, 1.5, 2.0 }, z, z, z, z, 0.5), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(profileOf({}, 1.0), t, z, z, z, z, 0.5), std::invalid_argument);
}

TEST(SteadyEstimateError, ABodyThatTurnedOverIsJudgedUpToTheTurnover)
{
  // A 0.5 m/s hold; the belief is right while the robot is on its wheels. At 2 s the body tips
  // past 90 degrees (up < 0) and tumbles (truth -1 m/s) while the belief reads the free wheels.
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 } }, 4.0);
  const std::vector<double> t = grid(0.005, 3.995, 0.01);
  std::vector<double> up(t.size(), 1.0), tv(t.size(), 0.5), ev(t.size(), 0.5);
  const std::vector<double> z(t.size(), 0.0);
  for (std::size_t k = 0; k < t.size(); ++k)
  {
    if (t[k] >= 1.6)
    {
      up[k] = std::cos(0.5 * M_PI * (t[k] - 1.6) / 0.4 + 0.05);  // past 90 degrees at 1.995 s
    }
    if (t[k] >= 2.0)
    {
      tv[k] = -1.0;
    }
  }
  const double t_over = analysis::turnoverTime(t, up);
  EXPECT_GT(t_over, 1.98);
  EXPECT_LT(t_over, 2.0);
  const analysis::SteadyEstimateError upright = analysis::steadyEstimateError(p, t, ev, z, tv, z, 0.5, t_over);
  EXPECT_NEAR(upright.vx.mean_abs, 0.0, 1e-12);
  EXPECT_EQ(upright.unavailable, 0);  // the samples after the turnover are left out, not missing
  // The control: the whole run carries the tumble's 1.5 m/s error.
  EXPECT_GT(analysis::steadyEstimateError(p, t, ev, z, tv, z, 0.5).vx.mean_abs, 0.7);
  // A robot that stays on its wheels has no turnover time, and bad input is refused.
  EXPECT_EQ(analysis::turnoverTime(t, std::vector<double>(t.size(), 0.2)), std::numeric_limits<double>::infinity());
  EXPECT_THROW(analysis::turnoverTime(t, { 1.0 }), std::invalid_argument);
  up[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(analysis::turnoverTime(t, up), std::invalid_argument);
  EXPECT_THROW(analysis::steadyEstimateError(p, t, ev, z, tv, z, 0.5, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
}

TEST(StopReversal, TheSpeedAgainstTheDirectionBeforeEachStopIsMeasured)
{
  // Forward at 0.5 until 1 s, stop; reverse at -0.3 from 3 s, stop at 4 s; 0 until 6 s. The truth
  // backs up after the first stop (-0.2 m/s over [1.1, 1.3): 0.04 m), runs on after the second
  // (-0.3 over [4.0, 4.3): the direction before that stop, no reversal) and then moves forward
  // (+0.05 over [4.5, 4.6): a reversal of 0.05 m/s and 0.005 m, less than the first).
  const analysis::TwistProfile p = profileOf(
      { { 0.0, 0.5, 0.0 }, { 1.0, 0.0, 0.0 }, { 2.0, 0.0, 0.0 }, { 3.0, -0.3, 0.0 }, { 4.0, 0.0, 0.0 } }, 6.0);
  const std::vector<double> t = grid(0.005, 5.995, 0.01);  // no sample on a boundary
  std::vector<double> v(t.size(), 0.0);
  for (std::size_t k = 0; k < t.size(); ++k)
  {
    if (t[k] >= 1.1 && t[k] < 1.3)
    {
      v[k] = -0.2;
    }
    if (t[k] >= 4.0 && t[k] < 4.3)
    {
      v[k] = -0.3;
    }
    if (t[k] >= 4.5 && t[k] < 4.6)
    {
      v[k] = 0.05;
    }
  }
  const analysis::StopReversal r = analysis::stopReversal(p, t, v, 1.0);
  EXPECT_EQ(r.stops, 2);  // 0 repeated at 2 s is no stop
  EXPECT_NEAR(r.reverse_speed, 0.2, 1e-12);
  EXPECT_NEAR(r.reverse_travel, 0.2 * 0.2, 1e-9);
  EXPECT_EQ(r.window, 1.0);
  // Within 0.1 s of the stops the first reversal has not begun, and the second stop's +0.05 at
  // 4.5 s is past its window.
  const analysis::StopReversal early = analysis::stopReversal(p, t, v, 0.1);
  EXPECT_EQ(early.stops, 2);
  EXPECT_EQ(early.reverse_speed, 0.0);
  // After the reverse drive's stop, moving forward is the reversal (the first stop's left out).
  std::vector<double> second = v;
  std::fill(second.begin(), second.begin() + 200, 0.0);  // t < 2 s
  const analysis::StopReversal after_reverse = analysis::stopReversal(p, t, second, 1.0);
  EXPECT_NEAR(after_reverse.reverse_speed, 0.05, 1e-12);
  EXPECT_NEAR(after_reverse.reverse_travel, 0.05 * 0.1, 1e-9);
  // A robot that stops where it is told scores 0; a profile without a stop has none.
  EXPECT_EQ(analysis::stopReversal(p, t, std::vector<double>(t.size(), 0.0), 1.0).reverse_speed, 0.0);
  EXPECT_EQ(analysis::stopReversal(profileOf({ { 0.0, 0.5, 0.0 } }, 6.0), t, v, 1.0).stops, 0);
}

TEST(StopReversal, BadInputIsRefused)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const analysis::TwistProfile p = profileOf({ { 0.0, 0.5, 0.0 }, { 1.0, 0.0, 0.0 } }, 2.0);
  const std::vector<double> t = grid(0.0, 2.0, 0.5);
  const std::vector<double> z(t.size(), 0.0);
  EXPECT_THROW(analysis::stopReversal(p, t, z, 0.0), std::invalid_argument);
  EXPECT_THROW(analysis::stopReversal(p, t, z, nan), std::invalid_argument);
  EXPECT_THROW(analysis::stopReversal(p, t, { 0.0 }, 1.0), std::invalid_argument);
  EXPECT_THROW(analysis::stopReversal(p, t, { 0.0, nan, 0.0, 0.0, 0.0 }, 1.0), std::invalid_argument);
  EXPECT_THROW(analysis::stopReversal(p, { 0.0, 0.0, 1.0, 1.5, 2.0 }, z, 1.0), std::invalid_argument);
  EXPECT_THROW(analysis::stopReversal(profileOf({}, 1.0), t, z, 1.0), std::invalid_argument);
}
