/**
 * \file test_pi_controller.cpp
 * \brief The classical peer (include/jackal_aic/classical/pi_controller.hpp): its parameters'
 *        checks, bad input refused with its status and never a non-finite command, the
 *        feed-forward alone on the model's own plant, the integrals against a shortfall and a
 *        turn deficit, anti-windup at the wheel clamp, a gyro offset at rest.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>

#include "jackal_aic/classical/pi_controller.hpp"

using namespace jackal_aic;

namespace
{
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A test plant: each side's wheel follows its command through the latency and the robot
/// model's wheel loop (WheelLoopModel), less a shortfall; the body's yaw rate follows the wheels'
/// times `turn` (a skid that delivers less of the turn) through the scrub lag T_s; the gyro reads
/// it plus `offset`.
struct TestPlant
{
  explicit TestPlant(const classical::PiControllerParams& p) : params(p), loop(p.robot) {}
  classical::PiControllerParams params;
  aic::WheelLoopModel loop;
  base::Vector2 omega = base::Vector2::Zero();
  base::Vector2 shortfall = base::Vector2::Zero();
  double turn = 1.0;
  double offset = 0.0;
  double yaw = 0.0;

  void advance(double t0, double t1)
  {
    for (double t = t0; t < t1 - 1e-12; t += aic::WheelLoopModel::kSubstep)
    {
      omega = loop.predict(omega, shortfall, t, t + aic::WheelLoopModel::kSubstep);
      const double wheels_yaw = turn * params.wheel_radius * (omega(1) - omega(0)) / params.wheel_separation;
      yaw += (wheels_yaw - yaw) * (1.0 - std::exp(-aic::WheelLoopModel::kSubstep / params.robot.yaw_time_constant));
    }
  }
  double gyro() const { return yaw + offset; }
};

/// Runs the peer against the plant for `duration` s at its period from t0 [s], the goal held.
/// Returns the last command.
classical::PiCommand drive(classical::PiController* c, TestPlant* plant, double linear, double angular, double duration,
                           double t0 = 0.0)
{
  const double h = c->params().period;
  classical::PiCommand cmd;
  const int n = static_cast<int>(std::lround(duration / h));
  for (int k = 0; k < n; ++k)
  {
    const double t = t0 + k * h;
    EXPECT_EQ(c->setGoal(t, linear, angular), classical::PiStatus::kOk);
    cmd = c->update(t, plant->omega, plant->gyro());
    EXPECT_EQ(cmd.status, classical::PiStatus::kOk);
    EXPECT_TRUE(cmd.wheels.allFinite());
    plant->loop.record(t, cmd.wheels);
    plant->advance(t, t + h);
  }
  return cmd;
}
}  // namespace

TEST(PiControllerParams, DefaultsAreValidAndShareTheRobotModel)
{
  const classical::PiControllerParams p;
  EXPECT_TRUE(p.validate().empty());
  EXPECT_EQ(p.robot.latency, params::RobotModelParams().latency);
  EXPECT_EQ(p.robot.wheel_time_constant, params::RobotModelParams().wheel_time_constant);
  EXPECT_EQ(p.wheel_separation, params::AicParams().wheel_separation);
}

TEST(PiControllerParams, EveryBadValueIsNamed)
{
  classical::PiControllerParams p;
  p.wheel.kp = -1.0;
  p.yaw.ki = kNaN;
  p.period = 0.0;
  p.robot.latency = -0.1;
  p.wheel_radius = 0.0;
  const std::vector<std::string> v = p.validate();
  ASSERT_EQ(v.size(), 5u);
  EXPECT_NE(v[0].find("latency"), std::string::npos);
  EXPECT_THROW(classical::PiController{ p }, std::invalid_argument);
  try
  {
    classical::PiController c(p);
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("wheel.kp = -1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("period = 0"), std::string::npos) << e.what();
  }
}

TEST(PiController, BadInputIsRefusedAndTheCommandStaysFinite)
{
  classical::PiController c;
  EXPECT_EQ(c.setGoal(0.0, kNaN, 0.0), classical::PiStatus::kNotFinite);
  EXPECT_EQ(c.setGoal(kNaN, 0.5, 0.0), classical::PiStatus::kNotFinite);
  EXPECT_EQ(c.setGoal(0.0, 0.5, 0.0), classical::PiStatus::kOk);
  EXPECT_EQ(c.setGoal(0.2, 0.6, 0.0), classical::PiStatus::kOk);
  EXPECT_EQ(c.setGoal(0.1, 0.7, 0.0), classical::PiStatus::kGoalOutOfOrder);  // before the previous change
  const classical::PiCommand first = c.update(0.2, base::Vector2::Zero(), 0.0);
  ASSERT_EQ(first.status, classical::PiStatus::kOk);
  EXPECT_GT(first.wheels(0), 0.0);
  const base::Vector2 integral = c.wheelIntegral();
  for (const classical::PiCommand& bad :
       { c.update(kNaN, base::Vector2::Zero(), 0.0), c.update(0.22, base::Vector2(kNaN, 0.0), 0.0),
         c.update(0.22, base::Vector2::Zero(), std::numeric_limits<double>::infinity()) })
  {
    EXPECT_EQ(bad.status, classical::PiStatus::kNotFinite);
    EXPECT_TRUE(bad.wheels.allFinite());
    EXPECT_EQ(bad.wheels, first.wheels);
  }
  for (double t : { 0.2, 0.19 })  // no step, a step back
  {
    const classical::PiCommand bad = c.update(t, base::Vector2::Zero(), 0.0);
    EXPECT_EQ(bad.status, classical::PiStatus::kNonPositiveStep);
    EXPECT_EQ(bad.wheels, first.wheels);
  }
  EXPECT_EQ(c.wheelIntegral(), integral);  // nothing refused moved a state
  EXPECT_EQ(c.update(0.22, base::Vector2::Zero(), 0.0).status, classical::PiStatus::kOk);
  EXPECT_STREQ(classical::toString(classical::PiStatus::kNonPositiveStep), "non_positive_step");
}

TEST(PiController, AGapLongerThanTheLongestStepRestartsTheModelsNotSimulatesThem)
{
  // The expected responses advance in 1 ms steps: a gap of 1e300 s would never end. A gap beyond
  // params::kMaxStep restarts them from the measured wheels, and the loop goes on from there.
  classical::PiController c;
  ASSERT_EQ(c.setGoal(0.0, 0.5, 0.2), classical::PiStatus::kOk);
  ASSERT_EQ(c.update(0.02, base::Vector2::Zero(), 0.0).status, classical::PiStatus::kOk);
  double t = 0.02 + 0.5 * params::kMaxStep;  // within the longest step: integrated
  ASSERT_EQ(c.update(t, base::Vector2::Zero(), 0.0).status, classical::PiStatus::kOk);
  const base::Vector2 wheels(4.0, 6.0);
  for (double gap : { 1.5 * params::kMaxStep, 1.0e300 })
  {
    t += gap;
    const classical::PiCommand cmd = c.update(t, wheels, 0.0);
    ASSERT_EQ(cmd.status, classical::PiStatus::kRestarted) << gap;  // simulated, the next gap would not end
    EXPECT_EQ(cmd.expected, wheels) << "the expected response restarts from the measured wheels";
    EXPECT_TRUE(cmd.wheels.allFinite());
    EXPECT_LE(cmd.wheels.cwiseAbs().maxCoeff(), c.params().max_wheel_speed);
    EXPECT_TRUE(c.wheelIntegral().allFinite());
    if (gap < 1.0e3)
    {
      t += 0.02;
      EXPECT_EQ(c.update(t, wheels, 0.0).status, classical::PiStatus::kOk) << "the loop goes on after a restart";
    }
  }
  EXPECT_STREQ(classical::toString(classical::PiStatus::kRestarted), "restarted");
}

TEST(PiController, FeedForwardAloneTracksTheModelsOwnPlant)
{
  // On the plant the model describes, the wheels reach the goal's speed one latency after it
  // changes and the feedback has nothing to add.
  classical::PiController c;
  TestPlant plant(c.params());
  const classical::PiCommand cmd = drive(&c, &plant, 0.5, 0.4, 2.0);
  const base::Vector2 goal = aic::SkidSteerModel(c.params().wheel_radius, 1.0, c.params().wheel_separation)
                                 .wheelsFromTwist(base::Vector3(0.5, 0.0, 0.4));
  // (the feedback's share: the yaw lag's reference is integrated over the 20 ms step, the test
  // plant's over 1 ms substeps)
  EXPECT_NEAR(plant.omega(0), goal(0), 1e-3);
  EXPECT_NEAR(plant.omega(1), goal(1), 1e-3);
  EXPECT_NEAR(cmd.feed_forward(0), goal(0), 1e-3);
  EXPECT_NEAR(c.wheelIntegral().norm(), 0.0, 1e-3);
  EXPECT_NEAR(c.yawIntegral(), 0.0, 1e-3);
}

TEST(PiController, IntegralsRemoveAShortfallAndATurnDeficit)
{
  classical::PiController c;
  TestPlant plant(c.params());
  plant.shortfall = base::Vector2(0.4, 0.2);  // the wheels fall short [rad/s]
  plant.turn = 0.7;                           // the skid delivers 70 % of the wheels' turn
  drive(&c, &plant, 0.5, 0.5, 8.0);
  const double r = c.params().wheel_radius;
  const double speed = r * 0.5 * (plant.omega(0) + plant.omega(1));
  EXPECT_NEAR(speed, 0.5, 0.005);
  EXPECT_NEAR(plant.gyro(), 0.5, 0.005);
  EXPECT_GT(c.yawIntegral(), 0.1);  // the outer loop widened the wheels' differential
}

TEST(PiController, AntiWindupAtTheWheelClamp)
{
  // Wheels that fall 1 rad/s short of a goal near the clamp: the command reaches the clamp and the
  // integrals stop there instead of growing; when the goal drops, the wheels follow it at once
  // (no integral to unwind).
  classical::PiControllerParams p;
  p.max_wheel_speed = 5.0;
  classical::PiController c(p);
  TestPlant plant(p);
  plant.shortfall = base::Vector2(1.0, 1.0);
  classical::PiCommand cmd = drive(&c, &plant, 0.45, 0.0, 4.0);  // 0.45 m/s: 4.59 rad/s
  EXPECT_DOUBLE_EQ(cmd.wheels(0), 5.0);
  EXPECT_TRUE(cmd.saturated);
  const double held = c.wheelIntegral()(0);
  EXPECT_LT(held, 1.0);
  drive(&c, &plant, 0.45, 0.0, 2.0, 4.0);
  EXPECT_DOUBLE_EQ(c.wheelIntegral()(0), held);
  drive(&c, &plant, 0.2, 0.0, 1.0, 6.0);  // 2.04 rad/s, well within the clamp
  EXPECT_NEAR(c.params().wheel_radius * plant.omega(0), 0.2, 0.02);
}

TEST(PiController, AGyroOffsetAtRestTurnsNothing)
{
  classical::PiController c;
  TestPlant plant(c.params());
  plant.offset = 0.02;  // [rad/s]
  const classical::PiCommand cmd = drive(&c, &plant, 0.0, 0.0, 5.0);
  EXPECT_EQ(cmd.wheels, base::Vector2::Zero());
  EXPECT_EQ(c.yawIntegral(), 0.0);
}
