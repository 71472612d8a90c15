#pragma once
/**
 * \file node_diagnostics.hpp
 * \brief /diagnostics of the jackal_AIC node (doc/jackal_aic_node.md, 'Diagnostics'): the
 *        achieved loop rates, loop timing, sensor freshness and drops, controller state.
 */

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/node_handle.h>

#include "jackal_aic/periodic_thread.hpp"
#include "jackal_aic/ros/sensor_sync.hpp"
#include "jackal_aic/supervisor.hpp"
#include "jackal_aic/types.hpp"

#include <string>

namespace jackal_aic
{
/// The controller's side of the diagnostics, gathered by the node when they are published.
struct ControllerReport
{
  double free_energy = 0.0;             ///< F (thesis eq. 3-10) at the diagnostics publication
  double belief_vx = 0.0;               ///< mu^(0) x_dot [m/s]
  double belief_wz = 0.0;               ///< mu^(0) theta_dot [rad/s]
  Vector2 command = Vector2::Zero();    ///< wheel command (omega_L, omega_R) [rad/s], zero when inactive
  std::uint64_t guarded_outputs = 0;    ///< non-finite outputs suppressed
  std::uint64_t generalizer_drops = 0;  ///< samples the generalizer or the controller refused
  std::string output_mode = "cmd_drive";  ///< output_mode parameter
  std::uint64_t output_clips = 0;       ///< cmd_vel mode: commands clipped to the stock controller's limits
  bool last_output_clipped = false;     ///< cmd_vel mode: the last command was clipped (anti-windup active)
};

/**
 * \brief The node's diagnostic_updater tasks, published every ~diagnostic_period (1 s):
 *        "belief loop rate", "action loop rate (/cmd_drive)" (FrequencyStatus, +-10 %),
 *        "loops", "sensors", "controller" (keys as in doc/jackal_aic_node.md).
 */
class NodeDiagnostics
{
public:
  /**
   * \param nh, pnh      node handles for the diagnostic_updater
   * \param supervisor   state, ages, counters and loop statistics (its statistics window is
   *                     reset at every publication); must outlive this object
   * \param sync         the sensor pairing (accepted samples, drops per reason); must outlive this object
   * \param controller   called at every publication for the controller's side
   */
  NodeDiagnostics(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, Supervisor& supervisor,
                  const SensorSynchronizer& sync, std::function<ControllerReport()> controller);

  /// The expected loop rates [Hz] (after a reconfigure).
  void setRates(double belief_rate, double action_rate);
  /// How the belief loop runs, e.g. "real-time thread (clock_nanosleep, default scheduler)".
  void setBeliefLoop(std::string description) { belief_loop_ = std::move(description); }
  /// One belief / action timer callback (for the achieved rates).
  void tickBelief() { belief_freq_->tick(); }
  void tickAction() { action_freq_->tick(); }
  /// The age [s] of the newest sensor sample when a command was published (the sensor-to-
  /// command latency; a window's p50 / p99 / max are shown in "loops").
  void commandLatency(double seconds) { latency_.add(seconds); }
  /// Poll the updater (publishes when ~diagnostic_period has passed).
  void update() { updater_->update(); }

private:
  void loops(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void sensors(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void controller(diagnostic_updater::DiagnosticStatusWrapper& stat);

  Supervisor& supervisor_;
  const SensorSynchronizer& sync_;
  std::function<ControllerReport()> report_;
  std::string belief_loop_ = "ROS timer";
  IntervalHistogram latency_;  ///< sensor-to-command latencies of the current window
  double belief_freq_min_ = 0.0, belief_freq_max_ = 0.0, action_freq_min_ = 0.0, action_freq_max_ = 0.0;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> belief_freq_, action_freq_;
};

}  // namespace jackal_aic
