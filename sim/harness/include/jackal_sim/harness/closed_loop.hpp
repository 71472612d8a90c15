#pragma once
/**
 * \file closed_loop.hpp
 * \brief A controller in closed loop with the ODE plant, headless and faster than real
 *        time: the stock controller, or the active inference controller through the
 *        jackal_AIC node's own logic (ControlLoop, include/jackal_aic/loop/control_loop.hpp) on
 *        simulated time. ROS-free; the engine of closed_loop_run, plant_fit, aic_tune.py,
 *        aic_scorecard.py and aic_reproduce.py (--backend core), and of the identification
 *        gtests.
 *
 * The AIC runs exactly as in the node (doc/jackal_aic_node.md), the clock being the plant's:
 * - the plant steps at physics.step (1 kHz); after each step its sensor model is polled and
 *   every IMU and joint-state sample becomes the loop's event (pairing, generalization,
 *   supervisor, fault detection, the sample-triggered action);
 * - the set point is streamed at 50 Hz and sent at once when the profile changes it;
 * - the action timer ticks at action_rate, after the samples of its instant; the belief
 *   timer (belief_schedule timer only) at belief_rate, before them; each on whole plant steps;
 * - every command of the loop goes to the plant at once.
 * The stock controller (diff_drive_controller's open-loop mapping) runs at 50 Hz.
 *
 * What is measured: the body speed from wheel odometry r (omega_L + omega_R) / 2 of the
 * 50 Hz joint-state samples (the robot's own estimate, which the thesis's tables were
 * measured with), ground truth beside it, the body speed the drive command asks for, and
 * the AIC's belief mu^(0).
 */

#include <cstdint>
#include <functional>
#include <utility>
#include <string>
#include <limits>
#include <vector>

#include "jackal_aic/aic/inference_sample.hpp"
#include "jackal_aic/classical/pi_controller.hpp"
#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/params/aic_params.hpp"
#include "jackal_aic/analysis/tracking_metrics.hpp"
#include "jackal_sim/plant/fault_injection.hpp"
#include "jackal_sim/plant/jackal_node_sampler.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_aic
{
namespace harness
{
/// The plant's names this interface uses (jackal_sim/plant/).
using plant::FaultSpec;
using plant::PlantParams;
using plant::RobotDescription;
/// Which controller closes the loop.
enum class LoopController
{
  kStock,  ///< the Jackal's stock controller (diff_drive_controller mapping, 50 Hz)
  kAic,    ///< the active inference controller (jackal_aic core), scheduled as the node
  /// No controller: every 50 Hz tick the set point's wheel speeds (inverse kinematics of the
  /// stock controller, r and its b_hat) go to the MCU as they are. The wheel loop's own
  /// response, for identifying it (aic_tune.py).
  kOpenLoop,
  /**
   * The ideal controller's command sequence, a reference for what the plant allows (not a
   * controller a robot could run): every 50 Hz tick k it sends ClosedLoopConfig::ideal_commands[k]
   * (body speed, yaw rate) as the wheel speeds of the stock controller's inverse kinematics (r,
   * its b_hat); ticks past the sequence (all, when it is empty) send the set point
   * `command_delay` ahead (the plant's motor.command_delay: a lead that cancels the transport
   * delay). runIdealController() learns the sequence over repeated runs; where even it misses the
   * set point, the plant decides: torque, voltage or friction limits, a slow wheel loop.
   */
  kIdeal,
  /// The classical peer (jackal_aic/classical/pi_controller.hpp, ClosedLoopConfig::pi): the set
  /// point streamed at 50 Hz and at once when it changes, an update on every joint-state sample
  /// with that sample's side means and the newest gyro reading, each command to the plant at once.
  kPi
};

/// One piece of a piecewise-constant set-point profile.
struct SetPointSegment
{
  double start = 0.0;    ///< time from the run's start at which this set point begins [s], >= 0
  double linear = 0.0;   ///< body forward speed [m/s]
  double angular = 0.0;  ///< yaw rate [rad/s]
};

/**
 * \brief An ordinary operation around the node during an AIC run (the soak, aic_soak): what
 *        happens to the robot's clock, its sensor driver or the node itself, as the ROS
 *        scenarios of test/rostest/restart_*.test do it through the nodes.
 */
struct Operation
{
  enum class Kind
  {
    /// The node's clock and the sensors' stamps step back by `size` [s] (a wall clock stepped
    /// back, a bag's loop); the robot drives on.
    kClockBack,
    /// The simulator restarts: a new plant at rest at the origin, its clock and stamps from 0
    /// (the loop's clock follows it); the run's time and the set-point profile go on.
    kPlantRestart,
    /// The sensor driver stops for `size` [s]: no samples reach the node, the MCU reports its
    /// drivers inactive (mcuStatus()), the motors are released and commands are not forwarded;
    /// then all of it is back.
    kDriverPause,
    /// The node dies and respawns `size` [s] later: a new ControlLoop with the same parameters
    /// (the plant keeps the last command meanwhile).
    kNodeRestart
  };
  Kind kind = Kind::kClockBack;
  double start = 0.0;  ///< [s] from the run's start, finite, >= 0
  double size = 0.0;   ///< [s], finite, >= 0: the jump, the pause or the down time (kPlantRestart: ignored)
};

/// "clock_back", "plant_restart", "driver_pause", "node_restart".
const char* toString(Operation::Kind kind);

/**
 * \brief One joint-state sample of a run: what ClosedLoopRecord keeps per sample, and the loop
 *        for an observer (ClosedLoopConfig::observer).
 */
struct ClosedLoopSample
{
  double time = 0.0;               ///< the run's time of the sample [s] (its stamp; monotonic over plant restarts)
  double set_point = 0.0;          ///< linear set point in force [m/s]
  double angular_set_point = 0.0;  ///< yaw-rate set point in force [rad/s]
  double v_odom = 0.0;             ///< wheel-odometry body speed [m/s]
  double v_true = 0.0;             ///< ground-truth forward speed [m/s]
  double yaw_odom = 0.0;           ///< wheel-odometry yaw rate [rad/s]
  double yaw_true = 0.0;           ///< ground-truth yaw rate [rad/s]
  double yaw_gyro = 0.0;           ///< the IMU's newest gyro z reading (sensor noise and bias included) [rad/s]
  double command = 0.0;            ///< body speed of the last drive command [m/s]
  double command_yaw = 0.0;        ///< yaw rate of the last drive command [rad/s]
  double belief = 0.0;             ///< AIC belief mu^(0) x_dot [m/s] (NaN if none)
  double belief_yaw = 0.0;         ///< AIC belief mu^(0) theta_dot [rad/s] (NaN if none)
  double x_true = 0.0, y_true = 0.0, heading_true = 0.0;  ///< ground-truth pose [m, m, rad]
  base::Vector2 wheels_command = base::Vector2::Zero();   ///< the last drive command (omega_L, omega_R) [rad/s]
  base::Vector2 wheels_measured = base::Vector2::Zero();  ///< the sample's mean wheel speeds per side [rad/s]
  /// AIC: the loop after it took the sample (null for the other controllers and while the
  /// node is down, Operation::kNodeRestart); valid during the call only.
  const loop::ControlLoop* loop = nullptr;
};

/// What to run.
struct ClosedLoopConfig
{
  LoopController controller = LoopController::kStock;
  params::AicParams aic;             ///< used when controller == kAic (validated by runClosedLoop)
  classical::PiControllerParams pi;  ///< used when controller == kPi (validated by runClosedLoop)
  /**
   * The node's other settings for the AIC (timeouts, sensor pairing, fault detection,
   * action_trigger, belief_schedule, output_mode; the schema's defaults unless set). Its `aic`
   * member is ignored (`aic` above is used); empty joint lists are the plant's wheel joints.
   */
  params::NodeParams node;
  /// Set-point profile, sorted by start; the first segment should start at 0 (before it the
  /// set point is 0). Streamed, as teleop or a planner would, so no timeout fires.
  std::vector<SetPointSegment> profile;
  double duration = 4.0;  ///< length of the run [s], > 0
  /// true: joint-state and IMU noise, bias and dropout off; false: the plant YAML's sensor
  /// models (seeded: the same run every time)
  bool ideal_sensors = true;
  /// Injected faults (sim/README.md, 'Fault injection'), each from `start` [s] after the run's
  /// start, as the plant node applies its ~faults (FaultedSensors).
  std::vector<FaultSpec> faults;
  /// AIC only: operations around the node (clock steps, plant restarts, driver pauses, node
  /// restarts), sorted by start.
  std::vector<Operation> operations;
  /// false: no per-sample record, health events or IMU-missing times (long runs: use observer).
  bool record = true;
  /// With record, the AIC's inference at every sample too (ClosedLoopRecord::inference;
  /// jackal_aic/aic/inference_sample.hpp): F, its parts, the beliefs and prediction errors of
  /// every order, the action, its prior, the attractor goal, Pi_y^(0) and b_hat.
  bool record_inference = false;
  /// Called for every joint-state sample (optional).
  std::function<void(const ClosedLoopSample&)> observer;
  /// kIdeal: the command of every 50 Hz tick from the run's start, (body speed [m/s], yaw rate
  /// [rad/s]); ticks past its end send the set point command_delay ahead.
  std::vector<base::Vector2> ideal_commands;
  /**
   * true: the joint states are jackal_node's (plant::JackalNodeSampler with jackal_node_sampler):
   * the sensor model's samples are the MCU's feedback, re-sampled by jackal_node's free-running
   * loop (0..20 ms old, some repeated, stamped with the loop's time), for the record and for the
   * controller alike; false: the sensor model's samples as they are (fresh, distinct).
   */
  bool jackal_node = false;
  plant::JackalNodeSamplerParams jackal_node_sampler;  ///< with jackal_node (validated by runClosedLoop)
};

/// One event of the AIC's fault monitor during a run.
struct HealthEvent
{
  double time = 0.0;                                                       ///< plant time of the sample [s]
  safety::FaultMonitor::Event event = safety::FaultMonitor::Event::kNone;  ///< isolated, restored or detected
  int channel = -1;                                                        ///< SensorIndex of the channel
};

/// Recorded run, one entry per joint-state sample (50 Hz).
struct ClosedLoopRecord
{
  std::vector<double> time;               ///< sample time from the run's start [s]
  std::vector<double> set_point;          ///< linear set point in force [m/s]
  std::vector<double> v_odom;             ///< wheel-odometry body speed r (omega_L + omega_R) / 2 [m/s]
  std::vector<double> v_true;             ///< ground-truth forward speed in base_link [m/s]
  std::vector<double> yaw_odom;           ///< wheel-odometry yaw rate r (omega_R - omega_L) / b_hat [rad/s]
  std::vector<double> yaw_true;           ///< ground-truth yaw rate [rad/s]
  std::vector<double> yaw_gyro;           ///< the IMU's newest gyro z reading at the sample [rad/s]
  std::vector<double> command;            ///< body speed of the last drive command r (a_L + a_R) / 2 [m/s]
  std::vector<double> belief;             ///< AIC belief mu^(0) x_dot [m/s] (NaN for the stock controller)
  std::vector<double> angular_set_point;  ///< yaw-rate set point in force [rad/s]
  std::vector<double> command_yaw;        ///< yaw rate of the last drive command r (a_R - a_L) / b_hat [rad/s]
  std::vector<double> belief_yaw;         ///< AIC belief mu^(0) theta_dot [rad/s] (NaN for the others)
  /// AIC: the generative model's wheel separation b_hat [m] (learned with learn_wheel_separation;
  /// NaN for the others and before the controller starts).
  std::vector<double> separation;
  /// AIC: the gyro offset removed from the gyro [rad/s] (GyroBiasEstimator::offset(), learned at
  /// standstill with learn_gyro_bias; 0 until enough rest is learned; NaN for the others).
  std::vector<double> gyro_offset;
  /// AIC: the fault monitor's last residual r [rad/s] and its precision-weighted square s [-]
  /// (FaultMonitor::residual(), statistic(); NaN for the others, before its first test and while
  /// the IMU is missing).
  std::vector<double> fdi_residual;
  std::vector<double> fdi_statistic;
  std::vector<double> x_true;        ///< ground-truth position x of base_link in the world [m]
  std::vector<double> y_true;        ///< ground-truth position y of base_link in the world [m]
  std::vector<double> heading_true;  ///< ground-truth yaw of base_link in the world [rad], wrapped to (-pi, pi]
  /// Ground-truth pitch of base_link against the world's horizontal [rad] (REP 103: > 0 nose down):
  /// a rigid robot on flat ground pitches only when a pair of wheels leaves it.
  std::vector<double> pitch_true;
  /// Ground-truth z component in the world of base_link's z axis [-] (the cosine of its tilt): 1
  /// level, below 0 with the body past 90 degrees of tilt (on its side or its back: turned over).
  std::vector<double> up_true;
  /// Body speed r (s_L + s_R) / 2 [m/s] of the wheel loops' set points in effect (after the
  /// MCU's delay and lag: WheelSpeedServo::effectiveSetpoint()); what the wheels are driven to.
  std::vector<double> wheel_setpoint;
  std::vector<double> wheel_setpoint_yaw;  ///< its yaw rate r (s_R - s_L) / b_hat [rad/s]
  std::vector<double> v_wheels;    ///< body speed of the true side wheel speeds, r (w_L + w_R) / 2 [m/s] (no noise)
  std::vector<double> yaw_wheels;  ///< yaw rate of the true side wheel speeds, r (w_R - w_L) / b_hat [rad/s]
  /// Share of the two sides whose motor torque is clamped to its limit (current or voltage;
  /// WheelSpeedServo::torqueLimited()) in the step before the sample: 0, 0.5 or 1.
  std::vector<double> torque_limited;
  /// AIC: the inference at each sample, with time (ClosedLoopConfig::record_inference; empty
  /// otherwise, and for the other controllers). Before the controller starts a sample holds NaN.
  std::vector<aic::InferenceSample> inference;
  std::uint64_t runaways = 0;  ///< AIC runaway resets during the run
  /// AIC, robot model: the wheel loop's latency L at the end [s] (learned with learn_latency; NaN otherwise).
  double latency = std::numeric_limits<double>::quiet_NaN();
  /// AIC, robot model: its shortfall jumps' counts at the end, both sides (RobotBelief::shortfallJumps(),
  /// shortfallReleases(), unansweredJumps(), stalls()); zero for the other models.
  std::uint64_t shortfall_jumps = 0;
  std::uint64_t shortfall_releases = 0;
  std::uint64_t unanswered_jumps = 0;
  std::uint64_t stalls = 0;
  /// AIC: the tip-over guard's trips during the run and its learned bounds at the end [m/s^2]
  /// (TipGuard::learnedFront(), learnedRear(); +inf: none learned).
  std::uint64_t tip_trips = 0;
  double tip_front = std::numeric_limits<double>::infinity();
  double tip_rear = std::numeric_limits<double>::infinity();
  bool active = false;             ///< AIC: the controller started (p + 1 samples and a set point)
  std::uint64_t belief_steps = 0;  ///< AIC: belief integration steps run
  /// AIC: the sensory precisions Pi_y^(0) in use at the end of the run, per SensorIndex (learned
  /// with learn_precision); empty for the others.
  std::vector<double> sensory_precisions;
  std::vector<HealthEvent> health_events;  ///< AIC: the fault monitor's events, in order
  /// AIC: plant times [s] of the joint-state samples the loop paired without an IMU (degraded mode).
  std::vector<double> imu_missing;
  /// diff_drive_controller's odometry (DiffDriveOdometry, control.yaml's separation and radius)
  /// updated with every joint-state sample at its stamp: its smoothed body speed [m/s] and yaw
  /// rate [rad/s], as the stock bringup publishes them.
  std::vector<double> v_diff_drive;
  std::vector<double> yaw_diff_drive;
  /// Age of each joint-state sample: its stamp minus when its data was measured [s] (0 without
  /// ClosedLoopConfig::jackal_node).
  std::vector<double> sample_age;
  /// 1 where the sample repeats the previous one's data (jackal_node), else 0.
  std::vector<double> repeated;
  /// With ClosedLoopConfig::jackal_node: the re-sampler's counts over the run (the last plant's).
  plant::JackalNodeSamplerStats jackal_node_stats;
  /// AIC: joint-state and IMU inputs the loop dropped during the run, per DropReason name (e.g.
  /// "min_sample_interval", "no_imu"), counted from the loop's pairing.
  std::vector<std::pair<std::string, std::uint64_t>> drops;
};

/**
 * \brief Run a controller against a fresh plant for config.duration seconds.
 * \param description robot model
 * \param params      plant parameters (sensor noise switched off if config.ideal_sensors)
 * \param config      controller, profile, duration
 * \throws std::invalid_argument on an invalid AicParams (kAic) or PiControllerParams (kPi), an empty or unsorted profile, a
 *         non-finite set point, a non-positive duration, or operations that are unsorted, have a
 *         negative or non-finite start or size, or are given for a controller other than the
 *         AIC (message says which)
 */
ClosedLoopRecord runClosedLoop(const RobotDescription& description, PlantParams params, const ClosedLoopConfig& config);

/**
 * \brief A twist profile (tracking_metrics.hpp: t, vx, wz rows, zero-order hold) as set-point
 *        segments played from t0: 0 before t0, then each point's (vx, wz) from t0 + t.
 * \param profile  a validated profile (TwistProfile::validate())
 * \param t0       when the profile starts in the run [s], >= 0
 */
std::vector<SetPointSegment> profileSegments(const analysis::TwistProfile& profile, double t0);

/// A set-point step from rest: 0 until t_step, then `linear` [m/s] (and `angular` [rad/s]).
std::vector<SetPointSegment> stepProfile(double t_step, double linear, double angular = 0.0);

/// Runs of runIdealController(): the first with the set point command_delay ahead, then one per
/// learning update. On the default plant every profile of sim/profiles/ has its best run by the
/// 7th, and 10 runs improve none of fast, planner_10hz, stop_and_go further (doc/tools.md,
/// 'Plant-limited pairs').
constexpr int kIdealIterations = 8;
/// Learning gain of runIdealController() [-]: the share of a run's error added to the next run's
/// command; below 1 so a wheel loop slower than the lead does not make the update overshoot.
constexpr double kIdealLearningGain = 0.7;

/// What runIdealController() learned.
struct IdealRun
{
  ClosedLoopRecord record;              ///< the best run (least mean-square wheel-rim speed error)
  std::vector<base::Vector2> commands;  ///< its command sequence (ClosedLoopConfig::ideal_commands)
  int best = 0;                         ///< its run, 0-based
  std::vector<double> vx_rms;           ///< every run's RMS error of the ground-truth body speed [m/s]
  std::vector<double> wz_rms;           ///< every run's RMS error of the ground-truth yaw rate [rad/s]
};

/**
 * \brief The ideal controller: the command sequence that makes the plant follow config.profile
 *        best, learned by iterative learning control over repeated runs from rest (each a fresh
 *        plant, LoopController::kIdeal).
 *
 * Run 0 sends the set point command_delay ahead (L = motor.command_delay); after run j, with
 * e_j(t) = set point - ground truth (body speed and yaw rate, joint-state samples interpolated),
 *     u_{j+1}[k] = clamp( u_j[k] + g * M[e_j](t_k + L) ),
 * a P-type update (D. A. Bristow, M. Tharayil, A. G. Alleyne, "A survey of iterative learning
 * control", IEEE Control Systems 26(3), 2006) with the lead L, gain g, M a centred 5-tick moving
 * average (a zero-phase Q-filter), and the clamp keeping both wheel speeds within
 * motor.max_wheel_speed. Knowing the whole profile in advance and the ground truth, it is the
 * plant's response to the best command there is: no controller of the real robot does better.
 * Returns the run with the least mean of e_v^2 + (b_hat e_w / 2)^2 (the wheel rims' mean-square
 * speed error) over every run.
 * \param config       profile, duration, sensors and faults as for runClosedLoop (its controller
 *                     and ideal_commands are ignored)
 * \param iterations   runs, >= 1
 * \param gain         learning gain g, in (0, 2)
 * \throws std::invalid_argument as runClosedLoop, or on iterations < 1 or gain outside (0, 2)
 */
IdealRun runIdealController(const RobotDescription& description, const PlantParams& params,
                            const ClosedLoopConfig& config, int iterations = kIdealIterations,
                            double gain = kIdealLearningGain);

}  // namespace harness
}  // namespace jackal_aic
