#pragma once
/**
 * \file output_enable.hpp
 * \brief The jackal_AIC node's ~enable_output service (std_srvs/SetBool) over its OutputGate
 *        (include/jackal_aic/safety/output_gate.hpp; doc/jackal_aic_node.md, 'Output gate'): a field trial
 *        switches between the AIC and the stock controller on a live robot without two command
 *        streams reaching the diff drive (doc/field_trials.md).
 *
 * Disabled: the node publishes nothing on its command topic; the state is logged and reported in
 * /diagnostics ("jackal_AIC: output gate", WARN while disabled). Enabled again: the controller
 * restarts from the measured state (bumpless). The service's header keeps std_srvs out of the
 * installed headers.
 */

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <ros/ros.h>

#include "jackal_aic/safety/output_gate.hpp"

namespace diagnostic_updater
{
class Updater;
}

namespace jackal_aic
{
namespace node
{
/// ~enable_output and its diagnostics; the gate itself is the node's (guarded by the node's lock).
class OutputEnable
{
public:
  /**
   * \param pnh      the node's private handle (the service ~enable_output, the diagnostics)
   * \param nh       the node's public handle (/diagnostics)
   * \param mutex    the node's lock, held while the gate is read or changed
   * \param gate     the node's gate
   * \param restart  called (lock held) on disabled -> enabled: restart the controller from the
   *                 measured state; returns a line for the log (what it started from)
   * \param topic    the command topic the gate silences (for the log lines)
   */
  OutputEnable(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::mutex& mutex, safety::OutputGate& gate,
               std::function<std::string()> restart, std::string topic);
  ~OutputEnable();
  OutputEnable(const OutputEnable&) = delete;
  OutputEnable& operator=(const OutputEnable&) = delete;

  /**
   * \brief Apply a request (also the service's body): set the gate, restart on re-enable, log.
   * \return the service's message: the new state and what it means
   */
  std::string apply(bool enable);

private:
  std::mutex& mutex_;
  safety::OutputGate& gate_;
  std::function<std::string()> restart_;
  std::string topic_;
  ros::ServiceServer server_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::Timer diagnostics_timer_;
};

}  // namespace node
}  // namespace jackal_aic
