#pragma once
/**
 * \file frozen_joint_states.hpp
 * \brief A frozen MCU behind jackal_node: joint states that keep coming, freshly stamped, with
 *        the same wheel travel and speeds (doc/jackal_aic_node.md, 'Frozen joint states').
 *        ROS-free.
 *
 * On a Jackal, jackal_node re-samples the MCU's Feedback in its own 50 Hz loop and stamps each
 * joint-state message with its loop's time (jackal_robot, noetic-devel:
 * jackal_base/src/jackal_base.cpp, jackal_hardware.cpp; modelled by the simulator's
 * JackalNodeSampler, sim/plant/include/jackal_sim/plant/jackal_node_sampler.hpp). When the
 * MCU's Feedback stops, jackal_node keeps publishing its last positions and velocities with
 * fresh stamps, so a timeout on the stamps or on the arrivals (sensor_timeout) never fires.
 * A healthy re-sampled stream repeats a sample only when no Feedback arrived within one loop
 * cycle, and such repeats come one at a time: the same data last at most one period. Data that
 * repeat exactly, travel and speeds of both sides, for longer than kFrozenJointStateTime while a
 * wheel reads as turning are a stale stream: a turning wheel whose travel does not change is no
 * measurement.
 *
 * Repeats while the wheels read as standing are not counted, commanded or not: at rest the
 * travel is constant, and a wheel that friction holds against its command (a turn in place
 * winding the wheel loop up, AicParams::max_action_lead_turn) reads exactly as a feedback
 * that froze at rest. That case is left to the anti-windup, which keeps each command within
 * max_action_lead of the reading.
 */

#include <cstdint>

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace safety
{
/**
 * \brief How long [s] the joint states' travel and speeds may repeat exactly, by their stamps,
 *        while a wheel reads as turning, before the stream counts as frozen: 5 periods of the
 *        MCU's 50 Hz Feedback. A healthy jackal_node stream repeats one sample at a time (two
 *        after a stalled cycle's back-to-back catch-up), so the same data stay at most one period:
 *        19.9-20.0 ms at worst over the phase sweep of the simulator's sampler, with the robot's
 *        wake-up latency (1 ms) or 5 ms, stalls of up to 30 ms on a tenth of the cycles, the
 *        clock 5000 ppm fast or slow (tools/jackal_node_sweep --part resample, column held_ms).
 *        Five times that tolerates four Feedback messages lost in a row; a frozen MCU stops the
 *        controller within this time plus up to two periods (the last sample's age and the
 *        cycle that crosses it), 0.102-0.118 s in test/sim/test_jackal_node_closed_loop.cpp,
 *        where sensor_timeout (0.25 s) never fires.
 */
constexpr double kFrozenJointStateTime = 0.1;
/**
 * \brief A measured wheel speed above this [rad/s] (about 5 mm/s of travel) reads as turning,
 *        so the travel must change. Below it the wheel stands: constant travel is expected and
 *        repeats are not counted.
 */
constexpr double kFrozenMotionSpeed = 0.05;

/**
 * \brief Detects a frozen joint-state stream (see the file comment). One update() per joint
 *        state that reached the controller (after the pairing's checks). Not thread-safe; no
 *        allocation.
 *
 * A run starts at the first sample of a set of data (travel and speeds, compared exactly). Each
 * repeat extends the run; its time counts from the run's first stamp. The stream is frozen once a
 * run of data with a wheel turning (|speed| > motion_speed) lasts longer than hold_time, and stays
 * frozen until the data change. A message without positions cannot show a frozen MCU (speeds
 * alone repeat on a healthy encoder at constant speed): it ends the run.
 */
class FrozenJointStates
{
public:
  /**
   * \param hold_time     how long the data may repeat while the wheels turn [s], finite and > 0
   * \param motion_speed  wheel speed above which a wheel reads as turning [rad/s], finite, >= 0
   * \throws std::invalid_argument otherwise
   */
  explicit FrozenJointStates(double hold_time = kFrozenJointStateTime, double motion_speed = kFrozenMotionSpeed);

  /// One joint-state sample's data.
  struct Input
  {
    double stamp = 0.0;                            ///< the sample's stamp [s], increasing between calls
    base::Vector2 travel = base::Vector2::Zero();  ///< wheel travel (left, right) [rad] (SensorSample::travel)
    bool has_travel = false;                       ///< the message carried positions
    base::Vector2 speed = base::Vector2::Zero();   ///< wheel speeds (omega_L, omega_R) [rad/s]
  };

  /// What update() found.
  enum class Event
  {
    kNone,    ///< no change of the verdict
    kFrozen,  ///< the stream became frozen with this sample
    kThawed   ///< it is not frozen any more (new data)
  };

  /// Take one sample. \return the change of the verdict it made, if any.
  Event update(const Input& in);
  /// The stream is frozen now.
  bool frozen() const { return frozen_; }
  /// How long the current run has lasted at the last sample [s] (0 for a first sample of its data).
  double heldFor() const { return held_for_; }
  /// Repeats in the current run (0 for new data).
  std::uint64_t repeats() const { return repeats_; }
  /// Entries into frozen since construction.
  std::uint64_t events() const { return events_; }
  /// The hold time in force [s].
  double holdTime() const { return hold_time_; }
  /// Forget the last data (a restarted sample history; the verdict ends). Counters are kept.
  void reset();

private:
  double hold_time_;
  double motion_speed_;
  bool have_last_ = false;
  base::Vector2 last_travel_ = base::Vector2::Zero();
  base::Vector2 last_speed_ = base::Vector2::Zero();
  double run_start_ = 0.0;  ///< stamp the current run counts from [s]
  double held_for_ = 0.0;
  std::uint64_t repeats_ = 0;
  bool frozen_ = false;
  std::uint64_t events_ = 0;
};

/// "none", "frozen" or "thawed".
const char* toString(FrozenJointStates::Event event);

}  // namespace safety
}  // namespace jackal_aic
