/**
 * \file inference_sample.cpp
 * \brief The controller's inference as one record (include/jackal_aic/aic/inference_sample.hpp).
 */
#include "jackal_aic/aic/inference_sample.hpp"

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

InferenceSample inferenceSample(const ActiveInferenceController& controller)
{
  InferenceSample s;
  s.free_energy = controller.freeEnergy();
  s.sensory = controller.sensoryFreeEnergy();
  s.prior = controller.priorFreeEnergy();
  s.mu = controller.mu();
  s.eps_y = controller.epsY();
  s.eps_mu = controller.epsMu();
  s.action = controller.action();
  s.action_prior = controller.actionPrior();
  s.goal = controller.attractorGoal();
  s.precision_y = controller.precisionY().col(0);
  s.wheel_separation = controller.model().wheelSeparation();
  return s;
}

InferenceSample unavailableInferenceSample(int orders)
{
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
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
  return s;
}
}  // namespace aic
}  // namespace jackal_aic
