#pragma once
/**
 * \file fault_injection.hpp
 * \brief Fault injection for the simulated Jackal (sim/README.md, 'Fault injection'): sensor
 *        faults (freeze, bias step, spike train, delay spike, dropout burst) on one sensor channel,
 *        and physical faults (a low-friction patch under one side, a payload). ROS-free.
 *
 * A fault is written as one line, "TARGET KIND [VALUE] [START] [DURATION] [PERIOD]", where VALUE is
 * given only for the kinds that take one (bias, spikes, delay, set: required) and PERIOD only for
 * spikes; so "gyro freeze 0 4" freezes the gyro now for 4 s and "gyro bias 0.5 2 4" adds 0.5 rad/s
 * from 2 s on for 4 s:
 *   TARGET  left_encoder | right_encoder (both joints of the side) | gyro (angular_velocity.z) |
 *           imu (the whole Imu message) | joint_states (the whole JointState message) |
 *           friction_left | friction_right | payload
 *   KIND    freeze (hold the last value) | bias (add VALUE [rad/s]) | spikes (add VALUE every PERIOD) |
 *           delay (publish VALUE [s] late, stamps unchanged) | dropout (publish nothing) |
 *           set (physical targets: friction scale VALUE [-] or payload VALUE [kg])
 *   START   [s] after the line is read (default 0); DURATION [s] (default: for ever, also when <= 0);
 *   PERIOD  [s] of the spike train (default 0.1).
 * delay and dropout apply to whole messages: targets imu and joint_states (an encoder or the gyro
 * selects the message that carries it); freeze, bias and spikes need an encoder or the gyro.
 */

#include <array>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "jackal_sim/plant/plant.hpp"
#include "jackal_sim/plant/robot_description.hpp"
#include "jackal_sim/plant/sensor_model.hpp"

namespace jackal_aic
{
namespace plant
{
/// One injected fault (see the file comment for the text form).
struct FaultSpec
{
  enum class Target
  {
    kLeftEncoder,
    kRightEncoder,
    kGyro,
    kImu,
    kJointStates,
    kFrictionLeft,
    kFrictionRight,
    kPayload
  };
  enum class Kind
  {
    kFreeze,
    kBias,
    kSpikes,
    kDelay,
    kDropout,
    kSet
  };
  Target target = Target::kGyro;
  Kind kind = Kind::kFreeze;
  double value = 0.0;      ///< bias / spike amplitude [rad/s], delay [s], friction scale [-] or payload [kg]
  double start = 0.0;      ///< [s] after activation, >= 0
  double duration = -1.0;  ///< [s]; <= 0: for ever
  double period = 0.1;     ///< spike period [s], > 0
};

/**
 * \brief Parse one fault line.
 * \param text   "TARGET KIND [VALUE] [START] [DURATION] [PERIOD]" (VALUE only for bias, spikes, delay
 *               and set; PERIOD only for spikes)
 * \param out    filled on success
 * \param error  on failure: what is wrong (unknown target or kind, a non-number, a missing VALUE, too
 *               many numbers for the kind, a kind that does not
 *               apply to the target, a negative start, a non-positive period or delay, a friction scale
 *               outside [0, 10] or a payload outside [0, 1000] kg)
 * \return true on success
 */
bool parseFaultSpec(const std::string& text, FaultSpec* out, std::string* error);

/**
 * \brief Applies a set of faults to the sensor samples and reports the physical faults in force.
 *
 * setFaults() activates a set at plant time `now`: each fault acts on [now + start, now + start +
 * duration). Not thread-safe.
 */
class FaultInjector
{
public:
  /// Replace the active faults (the held values of freeze faults are forgotten).
  void setFaults(const std::vector<FaultSpec>& faults, double now);
  const std::vector<FaultSpec>& faults() const { return faults_; }

  /**
   * \brief Apply the faults to a joint-state sample at plant time t.
   * \param delay  set to the extra publication delay [s] (0: none)
   * \return false to drop the sample (dropout)
   */
  bool applyJoints(double t, JointStateSample* sample, double* delay);
  /// As applyJoints() for an IMU sample.
  bool applyImu(double t, ImuSample* sample, double* delay);

  /// Friction scale of a side at t [-] (1 without a fault).
  double frictionScale(Side side, double t) const;
  /// Payload at t [kg] (0 without a fault).
  double payload(double t) const;

private:
  bool active(std::size_t k, double t) const;
  std::vector<FaultSpec> faults_;
  std::vector<double> starts_;                      ///< absolute start per fault [s]
  std::vector<double> last_spike_;                  ///< time of the last spike per fault [s]
  std::array<double, kNumWheels> last_velocity_{};  ///< last published wheel velocities
  double last_gyro_ = 0.0;
  bool have_last_joints_ = false, have_last_imu_ = false;
};

/**
 * \brief The plant's sensors with injected faults, as the plant node publishes them and the
 *        headless closed loop feeds them to the controller: after every plant step, the state
 *        is recorded (SensorModel), the physical faults in force are applied to the plant (from
 *        the next step on), samples whose delay has run out are released in order, and the
 *        samples due now pass the sensor faults (dropped, changed or delayed; a sample behind
 *        a delayed one waits for it, so the order is kept). Not thread-safe.
 */
class FaultedSensors
{
public:
  /// \param params validated sensor parameters; \param step plant step [s], > 0
  FaultedSensors(const SensorParams& params, double step) : model_(params, step) {}

  /// Replace the active faults at plant time `now` (FaultInjector::setFaults()).
  void setFaults(const std::vector<FaultSpec>& faults, double now) { injector_.setFaults(faults, now); }
  /// The faults in force.
  const FaultInjector& injector() const { return injector_; }
  /// The sensor model (rates, dropped samples).
  const SensorModel& model() const { return model_; }

  /// What afterStep() changed on the plant (for logs).
  struct Changes
  {
    bool payload = false;            ///< the payload changed (Plant::payload())
    std::array<bool, 2> friction{};  ///< the friction scale of a Side changed
  };

  /**
   * \brief Call after every plant step.
   * \param plant   the plant just stepped (its physical faults are set here)
   * \param joints  out: the joint-state samples published now, oldest first (cleared first)
   * \param imu     out: the IMU samples published now, oldest first (cleared first)
   * \return the physical changes made
   */
  Changes afterStep(Plant& plant, std::vector<JointStateSample>* joints, std::vector<ImuSample>* imu);

private:
  SensorModel model_;
  FaultInjector injector_;
  std::deque<std::pair<double, JointStateSample>> delayed_joints_;  ///< (release time, sample)
  std::deque<std::pair<double, ImuSample>> delayed_imu_;
};

}  // namespace plant
}  // namespace jackal_aic
