#pragma once
/**
 * \file jackal_node_sampler.hpp
 * \brief jackal_node's measurement side: the joint states a Jackal's bringup publishes, re-sampled
 *        by its free-running control loop from the MCU's wheel feedback. ROS-free.
 *
 * What it follows (jackal_robot, noetic-devel):
 * - the MCU publishes jackal_msgs/Feedback at 50 Hz on its own clock (per side: measured_velocity
 *   [rad/s], measured_travel [rad]); here every joint-state sample of the sensor model
 *   (sensor_model.hpp, its `rate`) is one such MCU sample, taken at its stamp;
 * - `jackal_base/src/jackal_base.cpp`: jackal_node's control thread runs `ros::Rate(50)`,
 *   independent of the MCU's clock; each cycle copies the latest Feedback received
 *   (`copyJointsFromHardware`), then runs the controllers with `ros::Time::now()` as their time;
 * - `jackal_base/src/jackal_hardware.cpp` (`copyJointsFromHardware`): each of the four joints takes
 *   its side's measured_travel minus the first travel seen (positions start at 0) and its side's
 *   measured_velocity; effort 0;
 * - ros_controllers' `joint_state_controller.cpp` (control.yaml: publish_rate 50): the joint states
 *   are stamped with the cycle's time and published once per cycle (its rate limiter skips at most
 *   one cycle, at start; not modelled).
 * So each published sample is the latest MCU sample, 0..20 ms old (+ the link's delay), stamped with
 * the loop's time; when no new Feedback arrived since the last cycle, it repeats the previous one,
 * and after a late cycle two arrive and one is never published.
 *
 * The loop's clock on the plant's: cycle k is due at phase + k / loop_rate * (1 - drift * 1e-6)
 * and runs late by a seeded wake-up latency |N(0, jitter_std)|, plus, with probability
 * stall_probability, a stall uniform in [0, stall_max] (a preempted thread). A cycle never runs
 * before the previous one plus cycle_time (ros::Rate runs late cycles back to back: catch-up
 * cycles). The MCU's samples reach the loop link_delay after they are taken (the serial link).
 *
 * Not modelled: the MCU's own estimate of the speed (the sensor model's is the wheel's speed at
 * the sample), the joint states before the first Feedback (jackal_node publishes zeros; here
 * nothing), ros::Rate's reset after a stall beyond two periods (stall_max is below).
 */

#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "jackal_sim/plant/sensor_model.hpp"

namespace jackal_aic
{
namespace plant
{
/// Parameters of JackalNodeSampler (defaults: a Jackal's jackal_node against its MCU).
struct JackalNodeSamplerParams
{
  double loop_rate = 50.0;  ///< jackal_node's control loop [Hz] (jackal_base.cpp: ros::Rate(50)), > 0
  /// When the first cycle is due on the plant's clock [s], in [0, 1 / loop_rate): its phase against
  /// the MCU's samples (sampled on the plant's clock from 0).
  double phase = 0.0;
  /// The loop clock's rate error against the MCU's [ppm], |drift| <= 1e4: > 0 runs fast; the phase
  /// drifts through one period every 1e6 / (|drift| * mcu_rate) cycles.
  double drift = 0.0;
  double jitter_std = 0.001;       ///< wake-up latency of a cycle, |N(0, jitter_std)| [s], in [0, 0.005]
  double stall_probability = 0.0;  ///< share of cycles that stall, in [0, 1]
  double stall_max = 0.03;         ///< a stall's length, uniform in [0, stall_max] [s], in [0, 2 / loop_rate)
  double cycle_time = 0.0002;      ///< a cycle's own run time, the least gap between cycles [s], in [0, 0.005]
  double link_delay = 0.0;         ///< MCU sample to its arrival at jackal_node [s], in [0, 0.1]
  std::uint32_t seed = 1;          ///< of the latency and stall draws

  /// Every violation as "key = value (allowed range)"; empty when valid.
  std::vector<std::string> validate() const;
};

/// One joint-state message of jackal_node.
struct ResampledJointState
{
  /// stamp: the loop's cycle time [s]; position: side travel minus the first travel [rad];
  /// velocity: the side's measured speed [rad/s] (both joints of a side alike).
  JointStateSample sample;
  double source_stamp = 0.0;  ///< when the MCU took the sample it carries [s] (age = stamp - source_stamp)
  bool repeated = false;      ///< no new MCU sample since the previous cycle: the same data again
  std::uint64_t cycle = 0;    ///< the loop's cycle number, from 0
};

/// Counts over a sampler's life.
struct JackalNodeSamplerStats
{
  std::uint64_t cycles = 0;    ///< joint-state messages published
  std::uint64_t repeats = 0;   ///< of them, repeats of the previous one's data
  std::uint64_t skipped = 0;   ///< MCU samples never published (two or more arrived in one cycle)
  std::uint64_t catch_up = 0;  ///< cycles run back to back after a late one (gap < half a period)
  double min_age = 0.0;        ///< least stamp - source_stamp [s] (0 before the first cycle)
  double max_age = 0.0;        ///< greatest [s]
  /// Longest run of consecutive repeats (1: repeats come singly, each after a new sample).
  std::uint64_t max_repeat_run = 0;
  /// Longest time one MCU sample's data stayed in the messages [s]: the stamp of its last repeat
  /// minus the stamp of its first publication (0 without repeats). What a frozen-stream check
  /// on the joint states (include/jackal_aic/safety/frozen_joint_states.hpp) must tolerate.
  double max_held = 0.0;

  /// repeats / cycles (0 without cycles).
  double repeatRate() const { return cycles == 0 ? 0.0 : static_cast<double>(repeats) / static_cast<double>(cycles); }
};

/// jackal_node's re-sampling of the MCU's feedback (see file comment).
class JackalNodeSampler
{
public:
  /// \throws std::invalid_argument if params do not validate (the message lists every violation)
  explicit JackalNodeSampler(const JackalNodeSamplerParams& params = JackalNodeSamplerParams());

  /**
   * \brief An MCU sample, taken at s.stamp [s] (non-decreasing between calls); it reaches the loop
   *        at s.stamp + link_delay. Per side, the mean of the side's two wheels is the MCU's
   *        measurement (one motor and encoder per side).
   */
  void feedback(const JointStateSample& s);

  /**
   * \brief Run every loop cycle due by `now` [s] (non-decreasing between calls): each appends one
   *        message to *out (cleared first) with the newest MCU sample that had arrived by its time.
   *        Cycles before the first arrival publish nothing.
   */
  void advance(double now, std::vector<ResampledJointState>* out);

  /// When the next cycle runs [s].
  double nextCycle() const { return next_time_; }
  /// Counts so far.
  const JackalNodeSamplerStats& stats() const { return stats_; }
  /// The parameters in force.
  const JackalNodeSamplerParams& params() const { return params_; }

private:
  /// Draw the time of cycle k (after the previous at prev [s]).
  double cycleTime(std::uint64_t k, double prev);

  JackalNodeSamplerParams params_;
  double period_;                         ///< the loop's period on the plant's clock [s]
  std::deque<JointStateSample> pending_;  ///< taken, not yet arrived
  JointStateSample latest_;               ///< the newest arrived
  bool have_latest_ = false;
  std::uint64_t latest_seq_ = 0;             ///< arrivals so far
  std::uint64_t published_seq_ = 0;          ///< the arrival the last message carried
  double first_published_ = 0.0;             ///< the stamp of its first publication [s]
  std::uint64_t repeat_run_ = 0;             ///< consecutive repeats so far
  std::array<double, kNumWheels> offset_{};  ///< the first travel per joint [rad]
  bool have_offset_ = false;
  std::uint64_t k_ = 0;
  double next_time_ = 0.0;
  double last_time_ = 0.0;
  bool ran_ = false;
  std::mt19937 rng_;
  JackalNodeSamplerStats stats_;
};

}  // namespace plant
}  // namespace jackal_aic
