/**
 * \file fault_test.cpp
 * \brief The fault monitor's test of one sample with the controller's belief model
 *        (include/jackal_aic/loop/fault_test.hpp).
 */
#include "jackal_aic/loop/fault_test.hpp"

namespace jackal_aic
{
namespace loop
{
safety::FaultMonitor::Event testSample(safety::FaultMonitor* monitor, const aic::ActiveInferenceController& controller,
                                       const base::Vector5& y, double h)
{
  if (controller.params().belief_model == params::BeliefModel::kRobot)
  {
    // The robot model's innovation test: the sample against the model's prediction of it.
    const base::Vector2 wheels(y(base::kOmegaLeft), y(base::kOmegaRight));
    return monitor->update(controller.robotBelief().sampleInnovation(wheels, y(base::kGyroZ)), h);
  }
  return monitor->update(y, controller.mu().col(0), h);
}

}  // namespace loop
}  // namespace jackal_aic
