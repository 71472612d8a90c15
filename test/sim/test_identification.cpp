/**
 * \file test_identification.cpp
 * \brief gtests of the headless closed loop (jackal_sim/harness/closed_loop.hpp) and of the wheel-loop
 *        identification (jackal_sim/harness/identification.hpp): the robot data file, the fit
 *        arithmetic, the servo's integral clamp and acceleration feedforward, and the
 *        identified plant.yaml against the robot's steps. No roscore needed.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/analysis/step_metrics.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/harness/identification.hpp"
#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/harness/replay.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_sim/plant/wheel_speed_servo.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
/// Motor parameters with every optional element of the identified model off (slew, lag,
/// saturations, feedforwards, load observer, latency, voltage limit), for the servo's arithmetic.
MotorParams bareMotor()
{
  MotorParams m;
  m.setpoint_slew_rate = 0.0;
  m.setpoint_time_constant = 0.0;
  m.command_delay = 0.0;
  m.stall_torque = 0.0;
  m.proportional_limit = 0.0;
  m.integral_error_limit = 0.0;
  m.integral_limit = 0.0;
  m.setpoint_feedforward = 0.0;
  m.accel_feedforward = 0.0;
  m.load_observer_time_constant = 0.0;
  return m;
}

const std::string kRoot = JACKAL_SIM_SOURCE_DIR;
const std::string kUrdf = kRoot + "/sim/urdf/jackal.urdf";
const std::string kPlant = kRoot + "/sim/config/plant.yaml";
const std::string kData = kRoot + "/sim/config/robot_steps.yaml";
const std::string kThesisEquivalent = kRoot + "/config/thesis_equivalent.yaml";

constexpr double kTorqueTol = 1e-9;  // N m, exact arithmetic of the servo

std::string writeTemp(const std::string& text)
{
  char name[] = "/tmp/robot_steps_XXXXXX";
  const int fd = mkstemp(name);
  EXPECT_GE(fd, 0);
  std::FILE* f = fdopen(fd, "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return name;
}

std::string errorOf(const std::function<void()>& f)
{
  try
  {
    f();
  }
  catch (const std::exception& e)
  {
    return e.what();
  }
  return "";
}

analysis::StepMetrics stepOf(const ClosedLoopRecord& rec, double t_step, double target)
{
  analysis::StepMetricsOptions o;
  o.step_time = t_step;
  o.target = target;
  return analysis::computeStepMetrics(rec.time, rec.v_odom, o);
}

ClosedLoopRecord runStep(LoopController controller, const params::AicParams& aic, double v, double hold = 3.0)
{
  ClosedLoopConfig c;
  c.controller = controller;
  c.aic = aic;
  c.profile = stepProfile(1.01, v);
  c.duration = 1.01 + hold;
  return runClosedLoop(loadRobotDescription(kUrdf), loadPlantParams(kPlant), c);
}
}  // namespace

// ---------------------------------------------------------------- robot data
TEST(RobotData, ShippedFileHasTheThesisTables)
{
  const auto tables = loadRobotStepTables(kData);
  ASSERT_EQ(tables.size(), 4u);
  EXPECT_EQ(tables[0].id, "3-1b");
  EXPECT_EQ(tables[0].controller, LoopController::kStock);
  EXPECT_EQ(tables[0].rows.size(), 3u);
  EXPECT_DOUBLE_EQ(tables[0].rows[2].rise, 0.62);
  EXPECT_EQ(tables[1].id, "3-1a");
  EXPECT_EQ(tables[2].id, "5-1");
  EXPECT_EQ(tables[2].rows.size(), 9u);
  EXPECT_DOUBLE_EQ(tables[2].rows[8].belief_rate, 1000.0);
  EXPECT_DOUBLE_EQ(tables[2].rows[8].action_rate, 1000.0);
  EXPECT_EQ(tables[3].id, "5-2");
  EXPECT_DOUBLE_EQ(tables[3].rows[8].action_rate, 50.0);
}

TEST(RobotData, MalformedFilesAreNamedErrors)
{
  EXPECT_NE(errorOf([] { loadRobotStepTables("/nonexistent/steps.yaml"); }).find("/nonexistent/steps.yaml"),
            std::string::npos);
  const std::string no_tables = writeTemp("rows: []\n");
  EXPECT_NE(errorOf([&] { loadRobotStepTables(no_tables); }).find("tables"), std::string::npos);
  const std::string short_row = writeTemp("tables:\n  - {id: x, title: t, source: s, controller: stock, rows: [[0.1, "
                                          "50, 50, 0.14]]}\n");
  EXPECT_NE(errorOf([&] { loadRobotStepTables(short_row); }).find("row 0"), std::string::npos);
  const std::string bad_controller = writeTemp("tables:\n  - {id: x, title: t, source: s, controller: pid, rows: "
                                               "[[0.1, 50, 50, 0.14, 0.04]]}\n");
  EXPECT_NE(errorOf([&] { loadRobotStepTables(bad_controller); }).find("pid"), std::string::npos);
  const std::string negative = writeTemp("tables:\n  - {id: x, title: t, source: s, controller: aic, rows: [[0.1, 50, "
                                         "50, -0.14, 0.04]]}\n");
  EXPECT_THROW(loadRobotStepTables(negative), std::runtime_error);
  const std::string missing_id = writeTemp("tables:\n  - {title: t, source: s, controller: aic, rows: []}\n");
  EXPECT_THROW(loadRobotStepTables(missing_id), std::runtime_error);
}

// ---------------------------------------------------------------- fit arithmetic
TEST(FitSummary, ErrorsCostsAndAcceptance)
{
  RobotStepTable stock{
    "s", "stock", "src", LoopController::kStock, { { 0.1, 50, 50, 0.1, 0.1 }, { 0.5, 50, 50, 1.0, 1.0 } }
  };
  RobotStepTable aic{ "a", "aic", "src", LoopController::kAic, { { 0.5, 50, 50, 1.0, 1.0 } } };
  FitEntry e0;
  e0.table = "s";
  e0.robot = stock.rows[0];
  e0.settling_error = 0.4;  // within the 50 % of a 0.1 m/s step
  e0.rise_error = -0.4;
  FitEntry e1;
  e1.table = "s";
  e1.robot = stock.rows[1];
  e1.settling_error = 0.1;
  e1.rise_error = 0.3;  // beyond the 20 % of a 0.5 m/s step
  FitEntry e2;
  e2.table = "a";
  e2.robot = aic.rows[0];
  e2.settling_error = -0.2;
  e2.rise_error = 0.2;
  const auto fits = summarizeFit({ stock, aic }, { e0, e1, e2 });
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_NEAR(fits[0].mean_abs_error, (0.4 + 0.4 + 0.1 + 0.3) / 4, 1e-12);
  // (error / tolerance)^2 averaged, plus the weighted miss of the one entry out of its band (1.5 - 1)^2.
  EXPECT_NEAR(fits[0].cost, (0.64 + 0.64 + 0.25 + 2.25) / 4 + kAcceptanceWeight * 0.25, 1e-12);
  EXPECT_FALSE(fits[0].accepted);
  EXPECT_NEAR(fits[1].mean_abs_error, 0.2, 1e-12);
  EXPECT_TRUE(fits[1].accepted);
  EXPECT_NEAR(fitCost(fits), fits[0].cost + fits[1].cost, 1e-12);
  EXPECT_DOUBLE_EQ(stockTolerance(0.1), 0.5);
  EXPECT_DOUBLE_EQ(stockTolerance(1.0), 0.2);
}

TEST(FitSummary, RescoringKeepsTheRunAndComparesAnotherRow)
{
  FitEntry run;
  run.sim.settling_time = 0.8;
  run.sim.rise_time = std::nan("");
  RobotStepTable t{ "5-2", "t", "s", LoopController::kAic, {} };
  const FitEntry e = rescoreFitEntry(run, t, { 0.5, 50, 50, 1.0, 0.4 });
  EXPECT_EQ(e.table, "5-2");
  EXPECT_NEAR(e.settling_error, -0.2, 1e-12);
  EXPECT_DOUBLE_EQ(e.rise_error, kUnsettledError) << "an undefined metric is charged, not skipped";
}

// ---------------------------------------------------------------- servo model
TEST(WheelSpeedServo, IntegralLimitBoundsTheIntegralPath)
{
  MotorParams m = bareMotor();
  m.speed_kp = 0.1;
  m.speed_ki = 100.0;
  m.max_torque = 10.0;
  m.integral_limit = 1.5;
  WheelSpeedServo s(m, 0.001);
  s.setSetpoint(10.0, 0.0);
  double torque = 0.0;
  for (int k = 0; k < 1000; ++k)
  {
    torque = s.update(0.0, 0.001 * k);  // wheels held: the error stays 10 rad/s
  }
  // Torque = Kp e + I + Ki e h (the current step's integral increment), I clamped at 1.5 N m.
  EXPECT_NEAR(torque, 0.1 * 10.0 + 1.5 + 100.0 * 10.0 * 0.001, kTorqueTol);
  s.setSetpoint(20.0, 1.0);
  EXPECT_NEAR(s.update(0.0, 1.0), 0.1 * 20.0 + 1.5 + 100.0 * 20.0 * 0.001, kTorqueTol) << "a set point further ahead "
                                                                                          "gives more torque through "
                                                                                          "the proportional path";
}

TEST(WheelSpeedServo, FeedforwardFollowsTheCommandRate)
{
  MotorParams m = bareMotor();
  m.speed_kp = 0.0;
  m.speed_ki = 1e-9;  // validate() needs one gain > 0; negligible here
  m.max_torque = 10.0;
  m.accel_feedforward = 0.05;  // kg m^2
  WheelSpeedServo s(m, 0.001);
  // A ramp of 20 rad/s^2 commanded at 50 Hz: 0.4 rad/s per command.
  double t = 0.0;
  s.setSetpoint(0.0, t);
  s.update(0.0, t);
  for (int k = 1; k <= 5; ++k)
  {
    t = 0.02 * k;
    s.setSetpoint(0.4 * k, t);
    s.update(0.4 * k, t);  // wheels on the ramp: no error
    EXPECT_NEAR(s.feedforward(), 0.05 * 20.0, 1e-9) << "command " << k;
  }
  // The ramp stops: the next (equal) command takes the feedforward away.
  t += 0.02;
  s.setSetpoint(2.0, t);
  s.update(2.0, t);
  EXPECT_NEAR(s.feedforward(), 0.0, 1e-12);
  // Released: no feedforward.
  s.release(t + 0.02);
  EXPECT_DOUBLE_EQ(s.update(2.0, t + 0.02), 0.0);
  EXPECT_DOUBLE_EQ(s.feedforward(), 0.0);
}

namespace
{
/// One side of the robot as a rigid inertia J [kg m^2] against a Coulomb load L [N m] (static up to
/// L at rest), driven by the servo at 1 kHz for `duration` s with the set point `setpoint` [rad/s]
/// from t = 0; returns the side speed at each millisecond.
std::vector<double> driveSide(const MotorParams& m, double inertia, double load, double setpoint, double duration)
{
  constexpr double h = 0.001;
  WheelSpeedServo s(m, h);
  s.setSetpoint(setpoint, 0.0);
  double w = 0.0;
  std::vector<double> out;
  for (int k = 0; k < static_cast<int>(std::lround(duration / h)); ++k)
  {
    const double torque = s.update(w, k * h);
    if (w == 0.0 && std::abs(torque) <= load)
    {
      out.push_back(w);  // static friction holds the side
      continue;
    }
    const double w_next =
        w + h * (torque - load * (w != 0.0 ? (w > 0.0 ? 1.0 : -1.0) : (torque > 0.0 ? 1.0 : -1.0))) / inertia;
    w = (w != 0.0 && w * w_next < 0.0) ? 0.0 : w_next;  // friction stops, it does not reverse
    out.push_back(w);
  }
  return out;
}

/// First time [s] a series sampled at 1 kHz reaches `level`; NaN if never.
double timeToReach(const std::vector<double>& w, double level)
{
  for (std::size_t k = 0; k < w.size(); ++k)
  {
    if (w[k] >= level)
    {
      return 0.001 * static_cast<double>(k + 1);
    }
  }
  return std::nan("");
}

}  // namespace

/// The load observer (disturbance observer): a side with a turn's Coulomb load (2.8 N m, a third of
/// the straight inertia) accelerates under the servo's clamped proportional torque as the nominal
/// straight-driving inertia would without load, and holds its set point; without the observer the
/// clamped proportional path cannot break the load away. A side that is the nominal inertia without
/// load (a straight step) is hardly changed by the observer.
TEST(WheelSpeedServo, LoadObserverDeliversALoadOnTheTimeScaleOfTheNominalInertia)
{
  MotorParams m = bareMotor();
  m.speed_kp = 10.0;
  m.speed_ki = 0.0;  // no integral path: the observer alone holds the load
  m.proportional_limit = 0.8;
  m.max_torque = 4.0;
  m.load_observer_inertia = 0.0933;
  m.load_observer_time_constant = 0.04;
  constexpr double kSetpoint = 3.0;  // rad/s
  const std::vector<double> turn = driveSide(m, 0.035, 2.8, kSetpoint, 2.0);
  const std::vector<double> straight = driveSide(m, 0.0933, 0.0, kSetpoint, 2.0);
  // The nominal inertia under the 0.8 N m clamp: 0.9 * 3 rad/s in 0.9 * 3 * 0.0933 / 0.8 = 0.31 s.
  const double t_straight = timeToReach(straight, 0.9 * kSetpoint);
  const double t_turn = timeToReach(turn, 0.9 * kSetpoint);
  EXPECT_NEAR(t_straight, 0.31, 0.03);
  EXPECT_LT(t_turn, t_straight + 0.15) << "the load is delivered within a few observer time constants";
  EXPECT_NEAR(turn.back(), kSetpoint, 0.01) << "and held without steady error";

  MotorParams off = m;
  off.load_observer_time_constant = 0.0;
  EXPECT_DOUBLE_EQ(driveSide(off, 0.035, 2.8, kSetpoint, 2.0).back(), 0.0) << "0.8 N m cannot break 2.8 N m away";
  const double t_straight_off = timeToReach(driveSide(off, 0.0933, 0.0, kSetpoint, 2.0), 0.9 * kSetpoint);
  EXPECT_NEAR(t_straight, t_straight_off, 0.02) << "a load-free nominal side hardly notices the observer";
}

TEST(WheelSpeedServo, LoadObserverIsValidatedAndClearedOnRelease)
{
  MotorParams m;
  m.load_observer_time_constant = -0.1;
  EXPECT_FALSE(m.validate().empty());
  m.load_observer_time_constant = 0.05;
  m.load_observer_inertia = 0.0;
  ASSERT_EQ(m.validate().size(), 1u);
  EXPECT_NE(m.validate()[0].find("motor.load_observer_inertia"), std::string::npos);
  m.load_observer_inertia = 0.0933;
  m.command_delay = 0.0;
  WheelSpeedServo s(m, 0.001);
  s.setSetpoint(3.0, 0.0);
  for (int k = 0; k < 1000; ++k)
  {
    s.update(0.0, 0.001 * k);  // held at rest: the estimate grows to the current limit
  }
  EXPECT_NEAR(s.loadEstimate(), m.max_torque, 1e-4);
  s.release(1.0);
  EXPECT_DOUBLE_EQ(s.update(0.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(s.loadEstimate(), 0.0);
}

// ---------------------------------------------------------------- closed loop
TEST(ClosedLoop, RejectsBadConfigurations)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  ClosedLoopConfig c;
  c.profile = {};
  EXPECT_NE(errorOf([&] { runClosedLoop(d, p, c); }).find("empty"), std::string::npos);
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.0, 0.5, 0.0 }, { 0.5, 0.1, 0.0 } };
  EXPECT_NE(errorOf([&] { runClosedLoop(d, p, c); }).find("sorted"), std::string::npos);
  c.profile = { { 0.0, std::nan(""), 0.0 } };
  EXPECT_NE(errorOf([&] { runClosedLoop(d, p, c); }).find("non-finite"), std::string::npos);
  c.profile = stepProfile(0.5, 0.5);
  c.duration = -1.0;
  EXPECT_NE(errorOf([&] { runClosedLoop(d, p, c); }).find("duration"), std::string::npos);
  c.duration = 1.0;
  c.controller = LoopController::kAic;
  c.aic.tau = -1.0;
  EXPECT_NE(errorOf([&] { runClosedLoop(d, p, c); }).find("tau"), std::string::npos);
}

TEST(ClosedLoop, AicStartsBumplesslyAndReachesTheSetPoint)
{
  const params::AicParams aic = loadAicParams(kThesisEquivalent);
  const ClosedLoopRecord rec = runStep(LoopController::kAic, aic, 0.5);
  EXPECT_TRUE(rec.active);
  EXPECT_EQ(rec.runaways, 0u);
  ASSERT_GT(rec.time.size(), 150u);  // 50 Hz for 4 s
  for (std::size_t k = 0; k < rec.time.size() && rec.time[k] < 1.0; ++k)
  {
    EXPECT_NEAR(rec.v_odom[k], 0.0, 1e-3) << "at rest before the step, t = " << rec.time[k];
  }
  const analysis::StepMetrics m = stepOf(rec, 1.01, 0.5);
  EXPECT_TRUE(m.settled);
  EXPECT_NEAR(m.steady_state_error, 0.0, 0.005);  // m/s
}

// ---------------------------------------------------------------- the identified plant
/// The committed plant.yaml fits the stock controller's steps (thesis table 3-1b) within the
/// identification's acceptance: +-20 % at 0.5 and 1.0 m/s, +-50 % at 0.1 m/s.
TEST(IdentifiedPlant, StockStepsWithinTheAcceptance)
{
  const auto tables = loadRobotStepTables(kData);
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  for (const RobotStepRow& row : tables[0].rows)
  {
    const FitEntry e = runFitEntry(d, p, params::NodeParams(), tables[0], row);
    EXPECT_LE(std::abs(e.settling_error), stockTolerance(row.step))
        << row.step << " m/s: settling " << e.sim.settling_time;
    EXPECT_LE(std::abs(e.rise_error), stockTolerance(row.step)) << row.step << " m/s: rise " << e.sim.rise_time;
  }
}

/// What the slew-limited plant could not do: commanded beyond the target (the AIC's drive
/// commands overshoot), the wheel loop accelerates faster than on the stock controller's step.
/// And the headline of doc/robot_data.md: the thesis's improved controller (tau = 0.001, belief 1 kHz,
/// exact integrator, thesis-equivalent variances) rises to 0.5 m/s in <= 0.75 x the stock rise.
TEST(IdentifiedPlant, AFastControllerIsFasterThanTheStockOne)
{
  params::AicParams aic = loadAicParams(kThesisEquivalent);
  const double stock_rise_1 = stepOf(runStep(LoopController::kStock, aic, 1.0), 1.01, 1.0).rise_time;
  const double aic_rise_1 = stepOf(runStep(LoopController::kAic, aic, 1.0), 1.01, 1.0).rise_time;
  EXPECT_LT(aic_rise_1, stock_rise_1) << "thesis-equivalent AIC vs stock, 1.0 m/s";

  aic.tau = 0.001;
  aic.belief_rate = 1000.0;
  aic.action_rate = 50.0;
  aic.integrator = params::Integrator::kExact;
  const double stock_rise = stepOf(runStep(LoopController::kStock, aic, 0.5), 1.01, 0.5).rise_time;
  const ClosedLoopRecord improved = runStep(LoopController::kAic, aic, 0.5);
  const double improved_rise = stepOf(improved, 1.01, 0.5).rise_time;
  EXPECT_EQ(improved.runaways, 0u);
  EXPECT_LE(improved_rise, 0.75 * stock_rise) << "improved " << improved_rise << " s, stock " << stock_rise << " s";
}

/// The committed plant.yaml passes plant_fit's whole acceptance: every table, the steady checks
/// and the turning targets.
TEST(IdentifiedPlant, EveryTableAcceptedAndTheTurningTargetsMet)
{
  const FitReport r = runFit(loadRobotDescription(kUrdf), loadPlantParams(kPlant),
                             loadNodeParamsFiles({ kThesisEquivalent }), loadRobotStepTables(kData));
  for (const TableFit& f : r.fits)
  {
    EXPECT_TRUE(f.accepted) << "table " << f.id << ": mean |error| " << f.mean_abs_error;
  }
  EXPECT_TRUE(r.turning.ok);
  EXPECT_TRUE(r.accepted);
  EXPECT_DOUBLE_EQ(r.steady.penalty + r.turning.penalty, 0.0);
}

/// The turning targets (doc/robot_data.md, 'Turning'): the stock controller's 1 rad/s turn in place
/// rises within 0.5 s and settles within 0.8 s (wheel odometry and gyro), a 0.5 m/s + 0.5 rad/s
/// arc's yaw rate settles within 0.8 s; and the turn settles on the time scale of a straight step
/// of about the same wheel speeds (0.3 m/s: 3.1 rad/s; the turn: 2.9 rad/s per side).
TEST(IdentifiedPlant, TurnsOnTheTimeScaleOfAStraightStep)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  const TurningChecks c = runTurningChecks(d, p);
  EXPECT_LE(c.turn.rise_time, kTurnRiseTarget);
  EXPECT_LE(c.turn.settling_time, kTurnSettlingTarget);
  EXPECT_LE(c.turn_truth.rise_time, kTurnRiseTarget);
  EXPECT_LE(c.turn_truth.settling_time, kTurnSettlingTarget);
  EXPECT_LE(c.arc.settling_time, kArcSettlingTarget);
  EXPECT_TRUE(c.ok);
  const double straight = stepOf(runStep(LoopController::kStock, params::AicParams(), 0.3), 1.01, 0.3).settling_time;
  EXPECT_LE(c.turn.settling_time, 1.25 * straight) << "straight 0.3 m/s settles in " << straight << " s";
}

/// The load observer's nominal inertia is the straight-driving inertia of one side from the URDF:
/// half the robot's mass at the wheel radius plus the spin inertia of the side's two wheels.
TEST(IdentifiedPlant, ObserverInertiaIsTheUrdfsStraightDrivingInertia)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  double mass = d.chassis.mass;
  double spin = 0.0;
  for (const WheelDescription& w : d.wheels)
  {
    mass += w.inertial.mass;
    spin += w.inertial.inertia(1, 1);  // about the wheel's axle (axis 0 1 0)
  }
  const double r = d.wheelRadius();
  const double inertia = 0.5 * mass * r * r + 0.5 * spin;
  EXPECT_NEAR(loadPlantParams(kPlant).motor.load_observer_inertia, inertia, 0.01 * inertia);
}

/// The premise of the turning model: a turn in place on the default floor needs about 3 N m per
/// side (scrub plus drivetrain friction), which the default wheel loop holds at the set point.
TEST(IdentifiedPlant, ATurnInPlaceNeedsAboutThreeNewtonMetresPerSide)
{
  Plant plant(loadRobotDescription(kUrdf), loadPlantParams(kPlant));
  constexpr double kWheel = 2.874;  // rad/s: 1 rad/s through the stock controller's b_hat
  plant.setWheelSpeeds(-kWheel, kWheel);
  plant.step(3000);
  double torque = 0.0;
  double speed = 0.0;
  for (int k = 0; k < 1000; ++k)
  {
    plant.step();
    torque += 0.5 * (plant.servo(kRight).torque() - plant.servo(kLeft).torque()) / 1000.0;
    speed += 0.5 * (plant.sideVelocity(kRight) - plant.sideVelocity(kLeft)) / 1000.0;
  }
  EXPECT_GT(torque, 2.5);
  EXPECT_LT(torque, 3.5);
  EXPECT_NEAR(speed, kWheel, 0.02);
}

/// The identified plant keeps the steady checks: the servo holds a turn in place at 10 rad/s,
/// the stock controller reaches the 2.0 m/s top speed.
TEST(IdentifiedPlant, SteadyChecksHold)
{
  const SteadyChecks c = runSteadyChecks(loadRobotDescription(kUrdf), loadPlantParams(kPlant));
  EXPECT_TRUE(c.turn_ok) << "turn-in-place wheel speed error " << c.turn_hold_error << " rad/s";
  EXPECT_TRUE(c.top_speed_ok) << "top speed " << c.top_speed << " m/s";
  EXPECT_DOUBLE_EQ(c.penalty, 0.0);
}

TEST(ClosedLoop, OpenLoopSendsTheSetPointsWheelSpeedsAndRecordsTheYaw)
{
  // No controller: the MCU gets the set point's wheel speeds, so the drive command is the set
  // point at once and the wheels follow it (the wheel loop's own response, aic_tune.py).
  ClosedLoopConfig c;
  c.controller = LoopController::kOpenLoop;
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.01, 0.3, 0.0 }, { 3.01, 0.0, 1.0 } };
  c.duration = 7.0;
  const ClosedLoopRecord rec = runClosedLoop(loadRobotDescription(kUrdf), loadPlantParams(kPlant), c);
  ASSERT_EQ(rec.command_yaw.size(), rec.time.size());
  ASSERT_EQ(rec.belief_yaw.size(), rec.time.size());
  ASSERT_EQ(rec.angular_set_point.size(), rec.time.size());
  for (std::size_t k = 0; k < rec.time.size(); ++k)
  {
    const double t = rec.time[k];
    if (t > 1.05 && t < 3.0)
    {
      EXPECT_NEAR(rec.command[k], 0.3, 1e-9) << "t " << t;
      EXPECT_NEAR(rec.command_yaw[k], 0.0, 1e-9) << "t " << t;
    }
    if (t > 3.05)
    {
      EXPECT_NEAR(rec.command[k], 0.0, 1e-9) << "t " << t;
      EXPECT_NEAR(rec.command_yaw[k], 1.0, 1e-9) << "t " << t;
      EXPECT_EQ(rec.angular_set_point[k], 1.0);
    }
    EXPECT_TRUE(std::isnan(rec.belief_yaw[k]));  // no AIC
  }
  const std::size_t at_3s =
      static_cast<std::size_t>(std::lower_bound(rec.time.begin(), rec.time.end(), 3.0) - rec.time.begin());
  EXPECT_NEAR(rec.v_odom[at_3s], 0.3, 0.015);  // the wheels reached the set point
  EXPECT_GT(rec.yaw_odom.back(), 0.3);         // and turn once commanded to
}

// ---------------------------------------------------------------- replay of a /cmd_drive stream
/// Replaying the stock controller's /cmd_drive stream is the same run as the closed loop with the
/// stock controller (the same plant, the same commands at the same instants): the wheel odometry
/// agrees sample by sample.
TEST(Replay, StockCommandsReproduceTheClosedLoop)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  ClosedLoopConfig c;
  c.controller = LoopController::kStock;
  c.profile = { { 0.0, 0.0, 0.0 }, { 1.01, 0.5, 0.0 }, { 2.51, 0.0, 1.0 } };
  c.duration = 4.0;
  const ClosedLoopRecord rec = runClosedLoop(d, p, c);
  const std::vector<DriveCommand> commands = stockDriveCommands(c.profile, c.duration);
  ASSERT_EQ(commands.size(), 200u);  // 50 Hz for 4 s
  EXPECT_DOUBLE_EQ(commands[51].left, commands[51].right);
  const std::vector<ReplaySample> rep = replayDriveCommands(d, p, commands, c.duration);
  ASSERT_EQ(rep.size(), rec.time.size());
  const double r = d.wheelRadius();
  for (std::size_t k = 0; k < rep.size(); ++k)
  {
    const double wl = 0.5 * (rep[k].velocity[kFrontLeft] + rep[k].velocity[kRearLeft]);
    const double wr = 0.5 * (rep[k].velocity[kFrontRight] + rep[k].velocity[kRearRight]);
    EXPECT_DOUBLE_EQ(rep[k].time, rec.time[k]);
    EXPECT_NEAR(r * 0.5 * (wl + wr), rec.v_odom[k], 1e-12) << "t " << rep[k].time;
    EXPECT_NEAR(rep[k].yaw_true, rec.yaw_true[k], 1e-12) << "t " << rep[k].time;
  }
  EXPECT_GT(rep.back().yaw_true, 0.9);
}

TEST(Replay, ModeNoneReleasesAndBadStreamsAreRefused)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  const std::vector<ReplaySample> rep =
      replayDriveCommands(d, p, { { 0.0, true, 5.0, 5.0 }, { 1.0, false, 0.0, 0.0 } }, 1.5);
  EXPECT_TRUE(rep.front().command_enabled);
  EXPECT_FALSE(rep.back().command_enabled);
  EXPECT_DOUBLE_EQ(rep.back().torque_left, 0.0);    // released (after the command latency)
  EXPECT_GT(rep.back().velocity[kFrontLeft], 0.5);  // coasting
  EXPECT_NE(errorOf([&] { replayDriveCommands(d, p, {}, 1.0); }).find("empty"), std::string::npos);
  EXPECT_NE(errorOf([&] {
              replayDriveCommands(d, p, { { 0.5, true, 1, 1 }, { 0.2, true, 1, 1 } }, 1.0);
            }).find("out-of-order"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              replayDriveCommands(d, p, { { 0.0, true, std::nan(""), 1 } }, 1.0);
            }).find("non-finite"),
            std::string::npos);
  EXPECT_NO_THROW(replayDriveCommands(d, p, { { 0.0, false, std::nan(""), 1 } }, 0.1));  // MODE_NONE: values ignored
  EXPECT_NE(errorOf([&] {
              replayDriveCommands(d, p, { { 0.0, true, 1, 1 } }, -1.0);
            }).find("duration"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              stockDriveCommands({ { 0.0, INFINITY, 0.0 } }, 1.0);
            }).find("non-finite"),
            std::string::npos);
}
