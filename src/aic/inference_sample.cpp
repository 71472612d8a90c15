/**
 * \file inference_sample.cpp
 * \brief The controller's inference as one record (include/jackal_aic/aic/inference_sample.hpp).
 */
#include "jackal_aic/aic/inference_sample.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace jackal_aic
{
namespace aic
{
const char* const kBeliefChannelNames[base::kMuDim] = { "x_dot", "y_dot", "theta_dot" };
const char* const kBeliefChannelUnits[base::kMuDim] = { "m/s", "m/s", "rad/s" };
const char* const kSensorChannelNames[base::kYDim] = { "gyro_z", "omega_L", "omega_R", "accel_x", "accel_y" };
const char* const kSensorChannelUnits[base::kYDim] = { "rad/s", "rad/s", "rad/s", "m/s^2", "m/s^2" };

std::string orderUnit(const std::string& unit, int i)
{
  if (i == 0)
  {
    return unit;
  }
  const std::size_t slash = unit.find("/s");
  const std::string base = unit.substr(0, slash);
  int power = i;
  if (slash != std::string::npos)
  {
    power += (unit.size() > slash + 2 && unit[slash + 2] == '^') ? std::stoi(unit.substr(slash + 3)) : 1;
  }
  return base + "/s" + (power == 1 ? std::string() : "^" + std::to_string(power));
}

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The robot model's part of the sample: its slow states, and NaN where it has no such quantity
/// (InferenceSample). eps_y order 0 of the sensors it reads, at the beliefs as they are.
void fillRobotModel(const ActiveInferenceController& controller, InferenceSample* s)
{
  const RobotBelief& belief = controller.robotBelief();
  const base::YTilde& y = controller.yTilde();
  const base::Vector2 omega = belief.wheelSpeeds();
  const Eigen::Index orders = s->mu.cols();
  s->eps_y = base::YTilde::Constant(base::kYDim, orders, kNaN);
  s->eps_y(base::kGyroZ, 0) = y(base::kGyroZ, 0) - (belief.yawRate() + belief.gyroOffset());
  s->eps_y(base::kOmegaLeft, 0) = y(base::kOmegaLeft, 0) - omega(0);
  s->eps_y(base::kOmegaRight, 0) = y(base::kOmegaRight, 0) - omega(1);
  s->eps_mu = base::MuTilde::Constant(base::kMuDim, orders, kNaN);
  if (orders > 2)
  {
    s->mu.rightCols(orders - 2).setConstant(kNaN);
  }
  s->action_prior.setConstant(kNaN);
  s->shortfall = belief.shortfalls();
  s->turn_shortfall = belief.turnShortfalls();
  s->slip_ratio = belief.slipRatio();
  s->gyro_offset_belief = belief.gyroOffset();
}

/// Whether every element of m is finite, rows [row0, row0 + rows) and columns [0, cols) only.
template <typename M>
bool blockFinite(const M& m, int row0, int rows, int cols)
{
  return m.rows() >= row0 + rows && m.cols() >= cols && m.block(row0, 0, rows, cols).allFinite();
}
}  // namespace

InferenceSample inferenceSample(const ActiveInferenceController& controller)
{
  InferenceSample s;
  s.belief_model = controller.params().belief_model;
  s.free_energy = controller.freeEnergy();
  s.sensory = controller.sensoryFreeEnergy();
  s.prior = controller.priorFreeEnergy();
  s.mu = controller.mu();
  s.action = controller.action();
  s.goal = controller.attractorGoal();
  s.precision_y = controller.precisionY().col(0);
  s.wheel_separation = controller.model().wheelSeparation();
  if (s.belief_model == params::BeliefModel::kRobot)
  {
    fillRobotModel(controller, &s);
  }
  else
  {
    s.eps_y = controller.epsY();
    s.eps_mu = controller.epsMu();
    s.action_prior = controller.actionPrior();
    s.shortfall.setConstant(kNaN);
    s.turn_shortfall.setConstant(kNaN);
    s.slip_ratio = kNaN;
    s.gyro_offset_belief = kNaN;
  }
  return s;
}

bool modelledValuesFinite(const InferenceSample& s)
{
  const bool common = std::isfinite(s.free_energy) && std::isfinite(s.sensory) && std::isfinite(s.prior) &&
                      s.action.allFinite() && s.goal.allFinite() && s.precision_y.allFinite() &&
                      std::isfinite(s.wheel_separation);
  if (!common)
  {
    return false;
  }
  if (s.belief_model != params::BeliefModel::kRobot)
  {
    return s.mu.allFinite() && s.eps_y.allFinite() && s.eps_mu.allFinite() && s.action_prior.allFinite();
  }
  const int orders = static_cast<int>(std::min<Eigen::Index>(s.mu.cols(), 2));
  return blockFinite(s.mu, 0, base::kMuDim, orders) && blockFinite(s.eps_y, 0, base::kOmegaRight + 1, 1) &&
         s.shortfall.allFinite() && s.turn_shortfall.allFinite() && std::isfinite(s.slip_ratio) &&
         std::isfinite(s.gyro_offset_belief);
}

InferenceSample unavailableInferenceSample(int orders)
{
  InferenceSample s;
  s.free_energy = s.sensory = s.prior = kNaN;
  s.mu = base::MuTilde::Constant(base::kMuDim, orders, kNaN);
  s.eps_y = base::YTilde::Constant(base::kYDim, orders, kNaN);
  s.eps_mu = base::MuTilde::Constant(base::kMuDim, orders, kNaN);
  s.action = base::Vector2::Constant(kNaN);
  s.action_prior = base::Vector2::Constant(kNaN);
  s.goal = base::Vector3::Constant(kNaN);
  s.precision_y = base::Vector5::Constant(kNaN);
  s.wheel_separation = kNaN;
  s.shortfall.setConstant(kNaN);
  s.turn_shortfall.setConstant(kNaN);
  s.slip_ratio = kNaN;
  s.gyro_offset_belief = kNaN;
  return s;
}
}  // namespace aic
}  // namespace jackal_aic
