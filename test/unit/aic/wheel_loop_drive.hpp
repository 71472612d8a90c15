#pragma once
/**
 * \file wheel_loop_drive.hpp
 * \brief The unit tests' way to drive the robot model against a plant that is its own wheel loop
 *        (WheelLoopModel with the plant's parameters: no body, no noise) on the node's schedule.
 *        Header-only.
 */

#include <algorithm>

#include <gtest/gtest.h>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/wheel_loop_model.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/params/robot_model_params.hpp"

namespace jackal_test
{
/**
 * \brief Drive `c` from rest toward the goal `goal` (x_dot [m/s], y_dot, theta_dot [rad/s]) for
 *        `seconds` [s] against a wheel-loop plant with the parameters `plant`: belief steps of 1 ms,
 *        a wheel sample every 20 ms (the plant's wheel speeds, no noise), an action step every
 *        20 ms whose command the plant records. `shortfall` [rad/s]: what each of the plant's wheels
 *        does not deliver of its command (WheelLoopModel::predict()'s d; a payload, a worn drive).
 * \return the largest wheel command sent [rad/s]; a goal, sample or step the controller refuses
 *         fails the test (gtest) and ends the drive.
 */
inline double driveAgainstWheelLoop(jackal_aic::aic::ActiveInferenceController* c,
                                    const jackal_aic::params::RobotModelParams& plant,
                                    const jackal_aic::base::Vector3& goal, double seconds = 1.0,
                                    const jackal_aic::base::Vector2& shortfall = jackal_aic::base::Vector2::Zero())
{
  using jackal_aic::base::Vector2;
  using Status = jackal_aic::aic::ActiveInferenceController::Status;
  jackal_aic::aic::WheelLoopModel wheels(plant);
  Vector2 omega = Vector2::Zero();
  jackal_aic::base::YTilde y = jackal_aic::base::YTilde::Zero(jackal_aic::base::kYDim, c->params().numOrders());
  double highest = 0.0;
  if (!c->setGoal(goal))
  {
    ADD_FAILURE() << "goal refused";
    return highest;
  }
  const int steps = static_cast<int>(seconds * 1000.0 + 0.5);
  for (int k = 0; k < steps; ++k)
  {
    const double t = 0.001 * k;
    if (k % 20 == 0)
    {
      if (k > 0)
      {
        omega = wheels.predict(omega, shortfall, t - 0.02, t);
      }
      y(jackal_aic::base::kOmegaLeft, 0) = omega(0);
      y(jackal_aic::base::kOmegaRight, 0) = omega(1);
      if (!c->setMeasurement(y))
      {
        ADD_FAILURE() << "sample refused at t = " << t;
        return highest;
      }
    }
    if (c->updateBeliefs(0.001) != Status::kOk)
    {
      ADD_FAILURE() << "belief step failed at t = " << t;
      return highest;
    }
    if (k % 20 == 19)
    {
      if (c->updateAction(0.02) != Status::kOk)
      {
        ADD_FAILURE() << "action step failed at t = " << t;
        return highest;
      }
      wheels.record(t + 0.001, c->action());
      highest = std::max(highest, c->action().maxCoeff());
    }
  }
  return highest;
}

}  // namespace jackal_test
