/**
 * \file test_turning.cpp
 * \brief gtests of the slip-based tyre contact (tyre_contact.hpp: the brush law, the slip, its
 *        mapping onto ODE's force-dependent slip) and of how the simulated Jackal turns with it
 *        (turning.hpp): turns in place within a second on the default floor, with the rated payload
 *        and on mu 0.8; arcs at 1.5 m/s within 5 %; the scrub falling with the turning radius; the
 *        effective separation within the Jackal's band on a grid of arcs; no ODE solver messages.
 *        Deterministic (simulated time, no sensor noise); no roscore needed.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdarg>
#include <string>
#include <vector>

#include <ode/ode.h>

#include "jackal_tools/params_yaml.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/harness/turning.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_sim/plant/tyre_contact.hpp"

using namespace jackal_aic;
using namespace jackal_aic::plant;
using namespace jackal_aic::harness;

namespace
{
const std::string kRoot = JACKAL_SIM_SOURCE_DIR;
const std::string kUrdf = kRoot + "/sim/urdf/jackal.urdf";
const std::string kPlant = kRoot + "/sim/config/plant.yaml";
const std::string kVariants = kRoot + "/sim/config/variants/";
constexpr double kTrack = 0.37559;  // m, jackal_description

PlantParams variant(const std::string& name, const std::vector<std::string>& overrides = {})
{
  if (name == "default")
  {
    return loadPlantParams(kPlant, overrides);
  }
  return loadPlantParams(kPlant, plantOverrides({ kVariants + name + ".yaml" }, overrides));
}

/// Counts ODE's messages and debug messages (dMessage, dDebug) while it lives.
struct OdeMessageCounter
{
  static int& count()
  {
    static int n = 0;
    return n;
  }
  static void handler(int, const char*, va_list) { ++count(); }
  OdeMessageCounter()
  {
    count() = 0;
    dSetMessageHandler(&OdeMessageCounter::handler);
    dSetDebugHandler(&OdeMessageCounter::handler);
  }
  ~OdeMessageCounter()
  {
    dSetMessageHandler(nullptr);
    dSetDebugHandler(nullptr);
  }
};
}  // namespace

// ---------------------------------------------------------------- the brush law
/// The brush tyre's force over normal load: slope C at zero slip, monotonic, never above mu, mu from
/// the full-sliding slip 3 mu / C on (continuously), Coulomb as C grows.
TEST(TyreContact, BrushCurveRisesWithSlopeCAndSaturatesAtMu)
{
  const double mu = 0.5;
  const double c = 10.0;
  EXPECT_DOUBLE_EQ(brushForceRatio(0.0, c, mu), 0.0);
  EXPECT_NEAR(brushForceRatio(1e-6, c, mu) / 1e-6, c, 1e-3 * c) << "initial slope C";
  double previous = 0.0;
  for (double s = 0.0; s <= 1.0; s += 0.001)
  {
    const double f = brushForceRatio(s, c, mu);
    EXPECT_GE(f, previous - 1e-15) << "monotonic at slip " << s;
    EXPECT_LE(f, mu + 1e-15);
    previous = f;
  }
  const double full = 3.0 * mu / c;
  EXPECT_NEAR(brushForceRatio(full * (1.0 - 1e-9), c, mu), mu, 1e-9) << "continuous at full sliding";
  EXPECT_DOUBLE_EQ(brushForceRatio(full, c, mu), mu);
  EXPECT_DOUBLE_EQ(brushForceRatio(2.0, c, mu), mu);
  // A third of the full-sliding slip: 3t - 3t^2 + t^3 at t = 1/3.
  EXPECT_NEAR(brushForceRatio(full / 3.0, c, mu), mu * (19.0 / 27.0), 1e-12);
  // The lateral force of a freely rolling wheel at slip angle alpha (slip tan alpha) rises with alpha and
  // saturates: at half a degree within 10 % of C tan(alpha), at 10 degrees mu on this floor.
  const double half_degree = std::tan(0.5 * M_PI / 180.0);
  EXPECT_NEAR(brushForceRatio(half_degree, c, mu), c * half_degree, 0.1 * c * half_degree);
  EXPECT_LT(brushForceRatio(half_degree, c, mu), c * half_degree);
  EXPECT_DOUBLE_EQ(brushForceRatio(std::tan(10.0 * M_PI / 180.0), c, mu), mu);
  // Coulomb (the "cone" model) as C grows; no friction on a frictionless floor.
  EXPECT_NEAR(brushForceRatio(0.01, 1e6, mu), mu, 1e-9);
  EXPECT_DOUBLE_EQ(brushForceRatio(0.1, c, 0.0), 0.0);
  // The force scales with mu at the same slip relative to full sliding.
  EXPECT_NEAR(brushForceRatio(3.0 * 0.8 / c / 2.0, c, 0.8) / brushForceRatio(full / 2.0, c, mu), 0.8 / mu, 1e-12);
}

/// The slip is the slip ratio along the wheel and the tangent of the slip angle across it, with the
/// larger of the forward and rolling speeds (at least v_min) as the reference.
TEST(TyreContact, SlipIsTheSlipRatioOrTheTangentOfTheSlipAngle)
{
  // Driving: the tyre's surface at 1.1 m/s, the wheel centre at 1.0 m/s: slip ratio 0.1 / 1.1.
  const WheelSlip drive = wheelSlip(1.0, 1.1, 0.1, 0.05);
  EXPECT_DOUBLE_EQ(drive.reference_speed, 1.1);
  EXPECT_NEAR(drive.slip, 0.1 / 1.1, 1e-12);
  // Braking: locked wheel dragged at 1 m/s: slip 1.
  EXPECT_NEAR(wheelSlip(1.0, 0.0, 1.0, 0.05).slip, 1.0, 1e-12);
  // Cornering: rolling freely at 1.5 m/s, sliding sideways at 0.04 m/s: tan(alpha) = 0.04 / 1.5.
  EXPECT_NEAR(wheelSlip(-1.5, 1.5, 0.04, 0.05).slip, 0.04 / 1.5, 1e-12);
  // The same sideways sliding at a tenth of the speed is ten times the slip.
  EXPECT_NEAR(wheelSlip(0.15, 0.15, 0.04, 0.05).slip, 0.04 / 0.15, 1e-12);
  // At rest the reference is v_min.
  const WheelSlip rest = wheelSlip(0.0, 0.0, 0.005, 0.05);
  EXPECT_DOUBLE_EQ(rest.reference_speed, 0.05);
  EXPECT_NEAR(rest.slip, 0.1, 1e-12);
  EXPECT_THROW(wheelSlip(1.0, 1.0, 0.1, 0.0), std::invalid_argument);
  EXPECT_THROW(wheelSlip(std::nan(""), 1.0, 0.1, 0.05), std::invalid_argument);
}

/// ODE's damper F = |v_s| / slip1 gives the brush force below full sliding and exceeds mu N beyond it
/// (the pyramid's cap then gives mu N); across the sliding the slip is the law's zero-slip slope.
TEST(TyreContact, OdeSlipReproducesTheBrushForce)
{
  const double c = 10.0;
  const double mu = 0.5;
  const double n = 45.0;
  for (double sliding : { 1e-6, 0.001, 0.01, 0.05, 0.1, 0.14 })
  {
    const WheelSlip s = wheelSlip(1.0, 1.0, sliding, 0.05);
    const OdeSlip o = odeSlip(s, c, mu, n);
    EXPECT_NEAR(sliding / o.along, brushForceRatio(s.slip, c, mu) * n, 1e-9 * n) << "sliding " << sliding;
    EXPECT_NEAR(o.across, 1.0 / (c * n), 1e-15);
  }
  for (double sliding : { 0.15, 0.3, 1.0 })
  {
    const WheelSlip s = wheelSlip(1.0, 1.0, sliding, 0.05);
    EXPECT_GE(sliding / odeSlip(s, c, mu, n).along, mu * n * (1.0 - 1e-12)) << "full sliding at " << sliding;
  }
  const WheelSlip s = wheelSlip(1.0, 1.0, 0.1, 0.05);
  EXPECT_THROW(odeSlip(s, 0.0, mu, n), std::invalid_argument);
  EXPECT_THROW(odeSlip(s, c, 0.0, n), std::invalid_argument);
  EXPECT_THROW(odeSlip(s, c, mu, 0.0), std::invalid_argument);
}

TEST(TyreContact, SlipParametersAreValidated)
{
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.slip_stiffness=0" }), PlantParamsError);
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.slip_stiffness=-3" }), PlantParamsError);
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.slip_stiffness=nan" }), PlantParamsError);
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.slip_min_speed=0" }), PlantParamsError);
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.slip_min_speed=2" }), PlantParamsError);
  EXPECT_THROW(loadPlantParams(kPlant, { "contact.mu2=0.8" }), PlantParamsError) << "slip is isotropic";
  EXPECT_THROW(loadPlantParams(kPlant, { "motor.accel_feedforward_limit=-1" }), PlantParamsError);
  try
  {
    loadPlantParams(kPlant, { "contact.slip_stiffness=0", "contact.slip_min_speed=0" });
  }
  catch (const PlantParamsError& e)
  {
    EXPECT_NE(std::string(e.what()).find("contact.slip_stiffness = 0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("contact.slip_min_speed = 0"), std::string::npos) << e.what();
  }
  const PlantParams p = loadPlantParams(kPlant);
  EXPECT_EQ(p.contact.friction_model, "slip");
  EXPECT_NO_THROW(loadPlantParams(kPlant, { "contact.slip2=0.02" })) << "slip1 / slip2 are not the slip model's";
}

// ---------------------------------------------------------------- the robot turning
/// The stock controller turns the robot in place to 95 % of 0.3 and 1.0 rad/s within 1 s on the default
/// floor, with the rated 20 kg payload (centred and 0.15 m forward) and on a mu 0.8 floor.
TEST(Turning, TurnsInPlaceWithinASecond)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  for (const char* name : { "default", "payload_20kg", "payload_20kg_forward", "floor_mu_0.8" })
  {
    for (double w : { 0.3, 1.0 })
    {
      const TwistRun r = runStockTwist(d, variant(name), 0.0, w);
      EXPECT_LE(r.reach_time, 1.0) << name << " at " << w << " rad/s";
      EXPECT_GE(r.yaw_rate, 0.95 * w) << name << " at " << w << " rad/s";
    }
  }
}

/// On arcs at 1.5 m/s the steady speed and yaw rate are within 5 % of the command; 2.0 m/s straight is
/// reached.
TEST(Turning, ArcsAtSpeedFollowWithinFivePercent)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const PlantParams p = loadPlantParams(kPlant);
  for (double w : { 0.3, 0.6 })
  {
    const TwistRun r = runStockTwist(d, p, 1.5, w);
    EXPECT_TRUE(r.followed) << "1.5 m/s + " << w << " rad/s: v " << r.v_true << ", yaw " << r.yaw_rate;
  }
  EXPECT_GE(runStockTwist(d, p, 2.0, 0.0).v_true, 1.98);
}

/// The scrub a turn costs the motors falls as the turning radius grows (the wheels' slips fall as
/// ~wheelbase / 2R): at 0.3 rad/s, the torque the sides need beyond straight driving at 1.5 m/s
/// (R = 5 m) is well below that at 0.2 m/s (R = 0.67 m). The Coulomb ("cone") contact charges the full
/// mu N at any radius.
TEST(Turning, ScrubFallsAsTheTurningRadiusGrows)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  auto turningTorque = [&](const PlantParams& p, double v) {
    const TwistRun r = runStockTwist(d, p, v, 0.3);
    return 0.5 * (r.torque_right - r.torque_left);
  };
  const PlantParams slip = loadPlantParams(kPlant);
  const PlantParams cone = loadPlantParams(kPlant, { "contact.friction_model=cone" });
  const double slip_ratio = turningTorque(slip, 1.5) / turningTorque(slip, 0.2);
  const double cone_ratio = turningTorque(cone, 1.5) / turningTorque(cone, 0.2);
  EXPECT_LT(slip_ratio, 0.6);
  EXPECT_GT(cone_ratio, 0.8);
}

/// The effective separation r (w_R - w_L) / yaw rate lies within the Jackal's band [1.0, 1.6] x track
/// (Clearpath's multiplier 1.5; a J100 that tracked with ~1.0) on every arc of the grid (0.2-1.5 m/s x
/// 0.2-1.5 rad/s) and turning in place, on the default plant; near 1.5 x track turning in place.
TEST(Turning, EffectiveSeparationWithinTheJackalsBand)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  for (const TwistRun& r : runTurningGrid(d, loadPlantParams(kPlant), TurningGrid{}))
  {
    const double b = r.separation() / kTrack;
    EXPECT_GE(b, 1.0) << r.linear << " m/s + " << r.angular << " rad/s";
    EXPECT_LE(b, 1.6) << r.linear << " m/s + " << r.angular << " rad/s";
    if (r.linear == 0.0 && r.angular >= 1.0)
    {
      EXPECT_NEAR(b, 1.5, 0.1) << "in place at " << r.angular << " rad/s";
    }
  }
}

/// ODE's solver prints no message (formerly "LCP internal error, s <= 0") turning in place, slowly and
/// fast, on the variants that load the motors most, nor during the thesis-equivalent AIC's slow steps.
TEST(Turning, NoOdeSolverMessages)
{
  const OdeMessageCounter counter;
  const RobotDescription d = loadRobotDescription(kUrdf);
  TwistRunOptions o;
  o.duration = 3.0;
  o.window = 1.0;
  for (const char* name : { "default", "payload_20kg", "floor_mu_0.8", "turn_deficit" })
  {
    for (double w : { 0.3, 1.0, 3.0, -1.0 })
    {
      runStockTwist(d, variant(name), 0.0, w, o);
    }
  }
  for (double rate : { 50.0, 100.0 })
  {
    for (double step : { 0.1, 0.3 })
    {
      ClosedLoopConfig c;
      c.controller = LoopController::kAic;
      c.node = loadNodeParamsFiles({ kRoot + "/config/thesis_equivalent.yaml" },
                                   { "belief_rate=" + std::to_string(rate), "action_rate=" + std::to_string(rate) });
      c.aic = c.node.aic;
      c.profile = stepProfile(1.01, step);
      c.duration = 2.5;
      runClosedLoop(d, loadPlantParams(kPlant), c);
    }
  }
  EXPECT_EQ(OdeMessageCounter::count(), 0);
}

// ---------------------------------------------------------------- the ideal controller
// The record's yaw_gyro (closed_loop_run's "measured" yaw rate) is the IMU's reading, not wheel
// odometry: on an arc of the default plant the two differ (the effective separation is not the
// b_hat odometry assumes), and the gyro (ideal sensors here) is the truth.
TEST(ClosedLoopRecord, MeasuredYawRateIsTheGyroNotWheelOdometry)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  ClosedLoopConfig arc;
  arc.controller = LoopController::kStock;
  arc.profile = stepProfile(1.0, 0.5, 0.5);
  arc.duration = 5.0;
  const ClosedLoopRecord r = runClosedLoop(d, loadPlantParams(kPlant), arc);
  ASSERT_EQ(r.yaw_gyro.size(), r.time.size());
  double gyro_error = 0.0, odom_error = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < r.time.size(); ++i)
  {
    if (r.time[i] >= 3.0)
    {
      gyro_error += std::abs(r.yaw_gyro[i] - r.yaw_true[i]);
      odom_error += std::abs(r.yaw_odom[i] - r.yaw_true[i]);
      ++n;
    }
  }
  ASSERT_GT(n, 0);
  EXPECT_LT(gyro_error / n, 1e-3);
  EXPECT_GT(odom_error / n, 0.01) << "control: wheel odometry's yaw rate is off on this arc";
}

/// Mean of y over the samples with time >= from.
double meanFrom(const std::vector<double>& time, const std::vector<double>& y, double from)
{
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < time.size(); ++i)
  {
    if (time[i] >= from)
    {
      sum += y[i];
      ++n;
    }
  }
  return n > 0 ? sum / n : std::nan("");
}

/// The ideal controller (runIdealController: the command learned over repeated runs) is the plant's
/// reference: on the default plant its learning cuts the planner profile's error to less than half
/// of its first run's (the set point command_delay ahead) and it tracks far better than the stock
/// controller; on the turn-deficit firmware it learns to remove the deficit of a 1 rad/s turn in
/// place, which its first run (the lead alone) keeps.
TEST(IdealController, LearnsToTrackBetterThanTheStockControllerAndRemovesADeficit)
{
  const RobotDescription d = loadRobotDescription(kUrdf);
  const analysis::TwistProfile planner = analysis::loadTwistProfileCsv(kRoot + "/sim/profiles/planner_10hz.csv");
  const double t0 = 1.0;
  ClosedLoopConfig c;
  c.controller = LoopController::kStock;
  c.profile = profileSegments(planner, t0);
  c.duration = t0 + planner.duration;
  const IdealRun ideal = runIdealController(d, loadPlantParams(kPlant), c);
  ASSERT_EQ(ideal.vx_rms.size(), static_cast<std::size_t>(kIdealIterations));
  ASSERT_EQ(ideal.commands.size(), static_cast<std::size_t>(std::ceil(c.duration / 0.02 - 1e-9)));
  EXPECT_LT(ideal.vx_rms[ideal.best], 0.5 * ideal.vx_rms[0]);
  EXPECT_LT(ideal.wz_rms[ideal.best], 0.6 * ideal.wz_rms[0]);
  const ClosedLoopRecord stock = runClosedLoop(d, loadPlantParams(kPlant), c);
  analysis::VelocityTrackingError e[2];
  int k = 0;
  for (const ClosedLoopRecord* r : { &ideal.record, &stock })
  {
    std::vector<double> t;
    for (double x : r->time)
    {
      t.push_back(x - t0);
    }
    e[k++] = analysis::velocityTrackingError(planner, t, r->v_true, r->yaw_true);
  }
  EXPECT_LT(e[0].vx.rms, 0.4 * e[1].vx.rms);
  EXPECT_LT(e[0].wz.rms, 0.4 * e[1].wz.rms);
  // Replaying the learned commands is the best run again (the plant is deterministic).
  ClosedLoopConfig replay = c;
  replay.controller = LoopController::kIdeal;
  replay.ideal_commands = ideal.commands;
  const ClosedLoopRecord again = runClosedLoop(d, loadPlantParams(kPlant), replay);
  ASSERT_EQ(again.v_true.size(), ideal.record.v_true.size());
  EXPECT_NEAR(again.v_true.back(), ideal.record.v_true.back(), 1e-9);

  ClosedLoopConfig turn;
  turn.profile = stepProfile(1.0, 0.0, 1.0);
  turn.duration = 5.0;
  const IdealRun learned = runIdealController(d, variant("turn_deficit"), turn);
  EXPECT_NEAR(meanFrom(learned.record.time, learned.record.yaw_true, 4.0), 1.0, 0.05);
  turn.controller = LoopController::kIdeal;  // the lead alone: the first run
  const ClosedLoopRecord lead = runClosedLoop(d, variant("turn_deficit"), turn);
  EXPECT_LT(meanFrom(lead.time, lead.yaw_true, 4.0), 0.8) << "the firmware alone holds ~0.5 rad/s";
  EXPECT_THROW(runIdealController(d, variant("turn_deficit"), turn, 0), std::invalid_argument);
  EXPECT_THROW(runIdealController(d, variant("turn_deficit"), turn, 2, 2.0), std::invalid_argument);
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
