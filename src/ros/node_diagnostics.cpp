/**
 * \file node_diagnostics.cpp
 * \brief /diagnostics of the jackal_AIC node (doc/jackal_aic_node.md, 'Diagnostics').
 */
#include "jackal_aic/ros/node_diagnostics.hpp"

#include "jackal_aic/params/param_schema.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include <diagnostic_updater/update_functions.h>
#include <ros/console.h>

namespace jackal_aic
{
namespace node
{
namespace
{
/// Window (in diagnostics publications) of the FrequencyStatus tasks.
constexpr int kFrequencyWindow = 5;
/// Relative tolerance of the achieved loop rates before diagnostics warn [-].
constexpr double kFrequencyTolerance = 0.1;

/// The sides for which `holds` (a RobotBelief side test) is true: "both", "left", "right" or "none".
template <typename Test>
const char* sidesWhere(Test holds)
{
  const bool left = holds(0);
  const bool right = holds(1);
  return left && right ? "both" : (left ? "left" : (right ? "right" : "none"));
}
}  // namespace

ControllerReport ControllerReport::of(const aic::ActiveInferenceController& controller, bool active)
{
  ControllerReport r;
  r.free_energy = controller.hasMeasurement() ? controller.freeEnergy() : 0.0;
  r.belief_vx = controller.mu()(0, 0);
  r.belief_wz = controller.mu()(2, 0);
  r.command = active ? controller.action() : base::Vector2::Zero();
  r.wheel_separation = controller.model().wheelSeparation();
  if (controller.params().separation_learner.enabled)
  {
    r.separation_learning = aic::toString(controller.separationLearner().state());
    r.separation_learning_steps = controller.separationLearner().learningSteps();
  }
  if (controller.params().belief_model == params::BeliefModel::kRobot)
  {
    r.latency = controller.wheelLoop().latency();  // the L in use, configured or learned (useLatency())
    if (params::learnsLatency(controller.params()))
    {
      char text[96];
      std::snprintf(text, sizeof text, "%d starts, newest %.4f s", controller.latencyLearner().starts(),
                    controller.latencyLearner().lastStart());
      r.latency_learning = text;
    }
    const aic::RobotBelief& belief = controller.robotBelief();
    const char* stalled = sidesWhere([&belief](int side) { return belief.stalled(side); });
    const char* saturated = sidesWhere([&belief](int side) { return belief.saturated(side); });
    char jumps[192];
    std::snprintf(jumps, sizeof jumps,
                  "%llu taken, %llu released, %llu unanswered, %llu stalls; stalled: %s; saturated: %s",
                  static_cast<unsigned long long>(belief.shortfallJumps()),
                  static_cast<unsigned long long>(belief.shortfallReleases()),
                  static_cast<unsigned long long>(belief.unansweredJumps()),
                  static_cast<unsigned long long>(belief.stalls()), stalled, saturated);
    r.shortfall_jumps = jumps;
  }
  if (params::learnsPrecision(controller.params()))
  {
    r.precision_learning = aic::toString(controller.precisionLearner().state());
  }
  char pi[128];
  std::snprintf(pi, sizeof pi, "gyro_z %.4g, omega_left %.4g, omega_right %.4g",
                controller.precisionY()(base::kGyroZ, 0), controller.precisionY()(base::kOmegaLeft, 0),
                controller.precisionY()(base::kOmegaRight, 0));
  r.sensory_precisions = pi;
  return r;
}

void NodeDiagnostics::start(ros::NodeHandle& nh, std::mutex& mutex)
{
  poll_timer_ = nh.createTimer(ros::Duration(1.0 / kPollRate), [this, &mutex](const ros::TimerEvent&) {
    const std::lock_guard<std::mutex> lock(mutex);
    loop_.advance();
    if (loop_.timeJumps() != seen_time_jumps_)
    {
      // ROS time moved back: the updater's and the health topic's schedules are on the old
      // timeline; publish now (which schedules them on the new one).
      seen_time_jumps_ = loop_.timeJumps();
      updater_->force_update();
      if (monitor_ != nullptr)
      {
        publishHealth(safety::FaultMonitor::Event::kNone, -1);
      }
      return;
    }
    update();
    pollHealth();
  });
}

NodeDiagnostics::~NodeDiagnostics() = default;

NodeDiagnostics::NodeDiagnostics(const ros::NodeHandle& nh, const ros::NodeHandle& pnh, loop::ControlLoop& loop,
                                 std::function<ControllerReport()> controller)
  : loop_(loop), report_(std::move(controller))
{
  paramsApplied(loop.params());
  rate_time_ = ros::WallTime::now();
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh);
  updater_->setHardwareID("jackal_aic");
  action_freq_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&action_freq_min_, &action_freq_max_, kFrequencyTolerance,
                                               kFrequencyWindow),
      "action loop rate (/cmd_drive)");
  updater_->add("belief step rate", this, &NodeDiagnostics::beliefRate);
  updater_->add(*action_freq_);
  updater_->add("loops", this, &NodeDiagnostics::loops);
  updater_->add("sensors", this, &NodeDiagnostics::sensors);
  updater_->add("controller", this, &NodeDiagnostics::controller);
}

void NodeDiagnostics::paramsApplied(const params::NodeParams& params)
{
  belief_rate_ = params.aic.belief_rate;
  action_freq_min_ = action_freq_max_ = params.aic.action_rate;
  std::string keys;
  for (const params::ParamSpec* row : params::keysWithoutEffect(params))
  {
    keys += (keys.empty() ? "" : ", ") + std::string(row->key);
  }
  without_effect_ = keys.empty() ? "none" : keys;
}

void NodeDiagnostics::commandPublished(double latency)
{
  action_freq_->tick();
  if (std::isfinite(latency))
  {
    latency_.add(latency);
  }
}

void NodeDiagnostics::beliefRate(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  const ros::WallTime now = ros::WallTime::now();
  const double span = (now - rate_time_).toSec();
  const std::uint64_t steps = loop_.beliefSteps();
  const double integrated = loop_.beliefTimeIntegrated();
  const double rate = span > 0.0 ? static_cast<double>(steps - rate_steps_) / span : 0.0;
  const double fraction = span > 0.0 ? (integrated - rate_integrated_) / span : 0.0;
  rate_steps_ = steps;
  rate_integrated_ = integrated;
  rate_time_ = now;
  stat.addf("belief steps per second [Hz]", "%.2f", rate);
  stat.addf("belief rate [Hz]", "%.2f", belief_rate_);
  stat.addf("belief time integrated per second [-]", "%.4f", fraction);
  if (!loop_.active())
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "controller not running: no belief steps");
  }
  else if (std::abs(fraction - 1.0) > kFrequencyTolerance || rate < (1.0 - kFrequencyTolerance) * belief_rate_)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "beliefs behind time or steps below the belief rate");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "beliefs integrated in time, steps at the belief rate");
  }
}

void NodeDiagnostics::loops(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  loop::LoopScheduler* loops[2] = { &loop_.supervisor().beliefLoop(), &loop_.supervisor().actionLoop() };
  const char* names[2] = { "belief", "action" };
  bool late = false;
  stat.add("belief loop", belief_loop_);
  for (int i = 0; i < 2; ++i)
  {
    const loop::LoopStats& s = loops[i]->stats();
    const double mean_jitter = s.window_ticks > 0 ? s.window_abs_jitter_sum / s.window_ticks : 0.0;
    stat.addf(std::string(names[i]) + " nominal period [ms]", "%.3f", 1e3 * s.nominal_period);
    stat.addf(std::string(names[i]) + " mean |jitter| [ms]", "%.3f", 1e3 * mean_jitter);
    stat.addf(std::string(names[i]) + " max interval [ms]", "%.3f", 1e3 * s.window_max_interval);
    stat.addf(std::string(names[i]) + " max callback duration [ms]", "%.3f", 1e3 * s.window_max_duration);
    stat.add(std::string(names[i]) + " overruns (interval > 2 periods)", s.overruns);
    stat.add(std::string(names[i]) + " clamped intervals", s.clamped);
    stat.add(std::string(names[i]) + " catch-up steps", s.catch_up_steps);
    stat.add(std::string(names[i]) + " ticks", s.ticks);
    late = late || s.window_max_duration > s.nominal_period;
  }
  // Integration steps since start, either schedule (the rate the beliefs see).
  stat.add("belief steps", loop_.beliefSteps());
  stat.addf("belief time integrated [s]", "%.6f", loop_.beliefTimeIntegrated());
  stat.add("action steps", loop_.actionSteps());
  stat.add("command latency samples", latency_.count());
  stat.addf("command latency p50 [ms] (sensor stamp -> /cmd_drive)", "%.3f", 1e3 * latency_.quantile(0.5));
  stat.addf("command latency p99 [ms]", "%.3f", 1e3 * latency_.quantile(0.99));
  stat.addf("command latency max [ms]", "%.3f", 1e3 * latency_.max());
  latency_.clear();
  if (late)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "a callback took longer than its period");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "loops on time");
  }
  loops[0]->resetWindow();
  loops[1]->resetWindow();
}

void NodeDiagnostics::sensors(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  const ControllerReport report = report_();
  stat.addf("sample age [s] (-1: never)", "%.3f", loop_.supervisor().sampleAge());
  stat.addf("imu age [s] (-1: never)", "%.3f", loop_.supervisor().imuAge());
  stat.addf("set point age [s] (-1: never)", "%.3f", loop_.supervisor().setPointAge());
  stat.add("accepted samples", loop_.pairing().acceptedSamples());
  std::uint64_t dropped = 0;
  for (int i = 0; i < static_cast<int>(loop::DropReason::kCount); ++i)
  {
    const std::uint64_t n = loop_.pairing().dropCounts()[static_cast<std::size_t>(i)];
    dropped += n;
    stat.add(std::string("dropped: ") + loop::toString(static_cast<loop::DropReason>(i)), n);
  }
  stat.add("dropped: generalizer/controller refused", report.generalizer_drops);
  stat.add("dropped: set point non-finite", loop_.supervisor().setPointDrops());
  stat.add("set points clamped", loop_.supervisor().setPointClamps());
  stat.add("stale events", loop_.supervisor().staleEvents());
  stat.add("dropped: joint_states frozen", loop_.frozenSamples());
  stat.add("frozen joint-state streams", loop_.frozenJointStates().events());
  stat.add("joint states frozen", loop_.supervisor().jointStatesFrozen() ? "yes" : "no");
  const bool sensors_stale = !loop_.supervisor().sensorsFresh();
  const bool set_point_stale = !loop_.supervisor().setPointFresh();
  if (sensors_stale || set_point_stale)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, loop_.supervisor().jointStatesFrozen() ? "joint states "
                                                                                                   "frozen (the same "
                                                                                                   "data while the "
                                                                                                   "wheels turn: MCU "
                                                                                                   "feedback stopped)" :
                                                          sensors_stale ? "sensor samples stale or missing" :
                                                                          "set point stale or missing");
  }
  else if (dropped + loop_.supervisor().setPointDrops() + report.generalizer_drops > 0)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "fresh (some inputs were dropped)");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "fresh");
  }
}

void NodeDiagnostics::controller(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  const ControllerReport report = report_();
  const std::string& reason = loop_.supervisor().reason();
  stat.add("state", loop::toString(loop_.supervisor().state()));
  stat.add("reason", reason);
  stat.add("runaway resets", loop_.supervisor().runaways());
  stat.add("non-finite outputs suppressed", report.guarded_outputs);
  stat.addf("free energy", "%g", report.free_energy);
  stat.addf("goal v_x [m/s]", "%.3f", loop_.supervisor().goal()(0));
  stat.addf("goal omega_z [rad/s]", "%.3f", loop_.supervisor().goal()(2));
  stat.addf("belief v_x [m/s]", "%.3f", report.belief_vx);
  stat.addf("belief omega_z [rad/s]", "%.3f", report.belief_wz);
  stat.addf("command left [rad/s]", "%.3f", report.command(0));
  stat.addf("command right [rad/s]", "%.3f", report.command(1));
  stat.addf("model wheel separation b_hat [m]", "%.4f", report.wheel_separation);
  stat.add("wheel separation learning", report.separation_learning);
  stat.add("wheel separation learning steps", report.separation_learning_steps);
  stat.addf("gyro offset beta_hat [rad/s]", "%.4f", report.gyro_bias);
  stat.add("gyro offset learning", report.gyro_bias_learning);
  stat.addf("model latency L [s]", "%.4f", report.latency);
  stat.add("latency learning", report.latency_learning);
  stat.add("shortfall jumps (robot model)", report.shortfall_jumps);
  stat.add("tip-over guard", report.tip_guard);
  stat.add("sensory precisions Pi_y^(0) [1/(rad/s)^2]", report.sensory_precisions);
  stat.add("sensory precision learning", report.precision_learning);
  stat.add("parameters without effect (not read by the belief model)", without_effect_);
  stat.add("output mode", report.output_mode);
  stat.add("commands clipped to the stock controller's limits (cmd_vel)", report.output_clips);
  stat.add("MCU stops", loop_.supervisor().mcuStops());
  stat.add("output topic", report.output_topic);
  stat.add("other publishers on the output topic", report.other_publishers);
  stat.add("output conflicts", report.output_conflicts);
  stat.add("commands withheld (output conflict)", report.blocked_commands);
  stat.add("controller starts", loop_.starts());
  stat.add("ROS time jumps back", loop_.timeJumps());
  stat.addf("last time jump back [s]", "%.3f", loop_.lastTimeJump());
  switch (loop_.supervisor().state())
  {
    case loop::NodeState::kRunning:
      if (report.last_output_clipped)
      {
        stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "running; command clipped to the stock controller's "
                                                              "velocity/acceleration limits "
                                                              "(fed back as the action)");
      }
      else
      {
        stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
      }
      break;
    case loop::NodeState::kHeld:
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "held: " + reason);
      break;
    case loop::NodeState::kWaiting:
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "waiting: " + reason);
      break;
    case loop::NodeState::kStale:
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "stale: " + reason);
      break;
    case loop::NodeState::kRunaway:
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "runaway: " + reason);
      break;
    case loop::NodeState::kBlocked:
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "blocked: " + reason);
      break;
  }
}

void NodeDiagnostics::addFaultMonitor(ros::NodeHandle& pnh, const safety::FaultMonitor& monitor)
{
  monitor_ = &monitor;
  health_pub_ = pnh.advertise<diagnostic_msgs::DiagnosticStatus>("sensor_health", 10, true);
  updater_->add("sensor health", [this](diagnostic_updater::DiagnosticStatusWrapper& stat) { fillHealth(stat); });
}

void NodeDiagnostics::fillHealth(diagnostic_updater::DiagnosticStatusWrapper& stat) const
{
  if (monitor_ == nullptr)
  {
    return;
  }
  const safety::FaultMonitor& m = *monitor_;
  std::string missing;
  for (int j = 0; j < base::kYDim; ++j)
  {
    const bool imu_channel = j == base::kGyroZ || j == base::kAccelX || j == base::kAccelY;
    std::string health = "ok";
    if (imu_channel && !m.imuAvailable())
    {
      health = "missing (no imu within imu_max_skew)";
    }
    else if (j == m.isolatedChannel())
    {
      health = m.params().enabled ? "isolated (Pi_y = 0)" : "faulty (isolation off)";
    }
    stat.add(safety::FaultMonitor::channelName(j), health);
  }
  stat.add("isolation enabled", m.params().enabled ? "true" : "false");
  stat.addf("residual r [rad/s]", "%.4f", m.residual());
  stat.addf("statistic s = r^2 / Var(r) [-]", "%.4g", m.statistic());
  stat.addf("threshold [-]", "%.4g", m.threshold());
  stat.add("isolations", m.isolations());
  stat.add("restorations", m.restorations());
  stat.add("detections (isolation off)", m.detections());
  stat.addf("last detection delay [s]", "%.3f", m.lastDetectionDelay());
  stat.add("last event", last_event_);
  if (!m.imuAvailable())
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "imu missing or stale: controlling on the wheel encoders");
  }
  else if (m.isolatedChannel() >= 0)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 std::string("sensor fault: ") + safety::FaultMonitor::channelName(m.isolatedChannel()) + " isolated");
  }
  else if (m.faultPresent())
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "sensors disagree (residual above the threshold)");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "all channels healthy");
  }
}

void NodeDiagnostics::publishHealth(safety::FaultMonitor::Event event, int channel)
{
  if (monitor_ == nullptr)
  {
    return;
  }
  if (event != safety::FaultMonitor::Event::kNone)
  {
    last_event_ = std::string(safety::toString(event)) + " " + safety::FaultMonitor::channelName(channel) + " at " +
                  std::to_string(ros::Time::now().toSec());
    if (event == safety::FaultMonitor::Event::kRestored)
    {
      ROS_INFO_STREAM("jackal_AIC: sensor channel " << safety::FaultMonitor::channelName(channel)
                                                    << " agrees with the others again: restored");
    }
    else
    {
      ROS_WARN_STREAM("jackal_AIC: sensor fault: residual s = "
                      << monitor_->statistic() << " above the threshold " << monitor_->threshold() << " for "
                      << monitor_->lastDetectionDelay() << " s; channel " << safety::FaultMonitor::channelName(channel)
                      << (event == safety::FaultMonitor::Event::kIsolated ? " isolated (Pi_y = 0)" :
                                                                            " suspected (fdi_enabled false: not "
                                                                            "isolated)"));
    }
  }
  published_state_ = healthState();
  published_at_ = ros::Time::now();
  diagnostic_updater::DiagnosticStatusWrapper stat;
  stat.name = "jackal_AIC: sensor health";
  stat.hardware_id = "jackal_aic";
  fillHealth(stat);
  health_pub_.publish(static_cast<diagnostic_msgs::DiagnosticStatus>(stat));
}

int NodeDiagnostics::healthState() const
{
  const safety::FaultMonitor& m = *monitor_;
  return (m.imuAvailable() ? 1 : 0) + 2 * (m.faultPresent() ? 1 : 0) + 4 * (m.isolatedChannel() + 1);
}

void NodeDiagnostics::pollHealth()
{
  if (monitor_ == nullptr)
  {
    return;
  }
  if (healthState() != published_state_ || (ros::Time::now() - published_at_).toSec() >= kHealthPeriod)
  {
    publishHealth(safety::FaultMonitor::Event::kNone, -1);
  }
}

}  // namespace node
}  // namespace jackal_aic
