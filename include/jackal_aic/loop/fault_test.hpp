#pragma once
/**
 * \file fault_test.hpp
 * \brief The fault monitor's test of one sample with the controller's belief model: the robot
 *        model's innovation test, or the thesis's models' parity test against the beliefs
 *        (doc/active_inference.md, 'Fault detection and isolation'). ROS-free.
 */

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/base/types.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"

namespace jackal_aic
{
namespace loop
{
/**
 * \brief Test sample y (SensorIndex order: gyro z, omega_L, omega_R [rad/s], accel x, y [m/s^2]),
 *        h [s] after the previous one, with `monitor`: with belief_model robot against the robot
 *        model's prediction of it (aic::RobotBelief::sampleInnovation(), FaultMonitor::update(model,
 *        h)), else the parity residual against the beliefs mu^(0) (FaultMonitor::update(y, mu0, h)).
 *        Call it before the controller's beliefs take the sample. Bad input is the monitor's to
 *        ignore (counted, kNone).
 * \return the event this sample caused.
 */
safety::FaultMonitor::Event testSample(safety::FaultMonitor* monitor, const aic::ActiveInferenceController& controller,
                                       const base::Vector5& y, double h);

}  // namespace loop
}  // namespace jackal_aic
