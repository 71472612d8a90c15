#include "jackal_aic/ros/aic_node.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <boost/bind/bind.hpp>
#include <geometry_msgs/TwistStamped.h>
#include <jackal_msgs/Drive.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Float64MultiArray.h>

namespace jackal_aic
{
namespace
{
/// Diagnostics updater is polled at this rate (it publishes every ~diagnostic_period, default 1 s) [Hz].
constexpr double kDiagnosticsPollRate = 10.0;
/// Window (in diagnostics publications) of the FrequencyStatus tasks.
constexpr int kFrequencyWindow = 5;
/// Relative tolerance of the achieved loop rates before diagnostics warn [-].
constexpr double kFrequencyTolerance = 0.1;

double intervalOf(const ros::TimerEvent& event)
{
  if (event.last_real.isZero())
  {
    return -1.0;  // first tick: LoopStats uses the nominal period
  }
  return (event.current_real - event.last_real).toSec();
}

template <class Matrix>
bool allFinite(const Matrix& m)
{
  return m.allFinite();
}

std_msgs::Float64MultiArray toMultiArray(const Eigen::Ref<const Eigen::MatrixXd>& m, const std::string& rows_label)
{
  std_msgs::Float64MultiArray msg;
  msg.layout.dim.resize(2);
  msg.layout.dim[0].label = rows_label;
  msg.layout.dim[0].size = static_cast<unsigned int>(m.rows());
  msg.layout.dim[0].stride = static_cast<unsigned int>(m.rows() * m.cols());
  msg.layout.dim[1].label = "order";
  msg.layout.dim[1].size = static_cast<unsigned int>(m.cols());
  msg.layout.dim[1].stride = static_cast<unsigned int>(m.cols());
  msg.data.resize(static_cast<std::size_t>(m.rows() * m.cols()));
  for (int r = 0; r < m.rows(); ++r)
  {
    for (int c = 0; c < m.cols(); ++c)
    {
      msg.data[static_cast<std::size_t>(r * m.cols() + c)] = m(r, c);
    }
  }
  return msg;
}
}  // namespace

const char* toString(NodeState state)
{
  switch (state)
  {
    case NodeState::kWaiting:
      return "waiting";
    case NodeState::kRunning:
      return "running";
    case NodeState::kStale:
      return "stale";
    case NodeState::kRunaway:
      return "runaway";
  }
  return "unknown";
}

double LoopStats::record(double interval)
{
  if (!std::isfinite(interval) || interval <= 0.0)
  {
    interval = nominal_period;
  }
  ++ticks;
  ++window_ticks;
  window_max_interval = std::max(window_max_interval, interval);
  window_abs_jitter_sum += std::abs(interval - nominal_period);
  if (interval > 2.0 * nominal_period)
  {
    ++overruns;
  }
  if (interval > max_factor * nominal_period)
  {
    ++clamped;
    interval = max_factor * nominal_period;
  }
  return interval;
}

void LoopStats::resetWindow()
{
  window_max_interval = 0.0;
  window_abs_jitter_sum = 0.0;
  window_ticks = 0;
  window_max_duration = 0.0;
}

AicNode::AicNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh)
{
}

bool AicNode::init()
{
  std::vector<ParamViolation> violations;
  loadNodeParams(pnh_, &params_, &violations);
  for (auto& v : params_.validate())
  {
    violations.push_back(std::move(v));
  }
  if (!violations.empty())
  {
    for (const auto& v : violations)
    {
      ROS_FATAL_STREAM("jackal_AIC: invalid parameter ~" << v.toString());
    }
    ROS_FATAL_STREAM("jackal_AIC: " << violations.size() << " invalid parameter(s) in " << pnh_.getNamespace()
                                    << "; exiting");
    return false;
  }
  try
  {
    controller_ = std::make_unique<ActiveInferenceController>(params_.aic);
    generalizer_ = std::make_unique<Generalizer>(kYDim, params_.aic.embedding_order);
  }
  catch (const std::exception& e)
  {
    ROS_FATAL_STREAM("jackal_AIC: cannot build the controller: " << e.what());
    return false;
  }
  sync_ = std::make_unique<SensorSynchronizer>(syncConfig(params_));

  cmd_pub_ = nh_.advertise<jackal_msgs::Drive>("cmd_drive", 1);
  belief_pub_ = pnh_.advertise<geometry_msgs::TwistStamped>("belief", 50);
  free_energy_pub_ = pnh_.advertise<std_msgs::Float64>("free_energy", 10);
  eps_y_pub_ = pnh_.advertise<std_msgs::Float64MultiArray>("eps_y", 10);
  eps_mu_pub_ = pnh_.advertise<std_msgs::Float64MultiArray>("eps_mu", 10);

  const auto hints = ros::TransportHints().tcpNoDelay();
  joint_sub_ = nh_.subscribe("joint_states", 10, &AicNode::jointStateCallback, this, hints);
  imu_sub_ = nh_.subscribe("imu/data", 10, &AicNode::imuCallback, this, hints);
  set_point_sub_ = pnh_.subscribe("set_point", 10, &AicNode::setPointCallback, this, hints);

  reconfigure_server_ = std::make_unique<dynamic_reconfigure::Server<AICConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_server_->updateConfig(configFromParams(params_));  // the validated YAML values, not clamped ones
  reconfigure_server_->setCallback(
      boost::bind(&AicNode::reconfigureCallback, this, boost::placeholders::_1, boost::placeholders::_2));

  belief_stats_.nominal_period = 1.0 / params_.aic.belief_rate;
  belief_stats_.max_factor = kMaxBeliefIntervalFactor;
  action_stats_.nominal_period = 1.0 / params_.aic.action_rate;
  action_stats_.max_factor = kMaxActionIntervalFactor;
  belief_freq_min_ = belief_freq_max_ = params_.aic.belief_rate;
  action_freq_min_ = action_freq_max_ = params_.aic.action_rate;
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh_, pnh_);
  updater_->setHardwareID("jackal_aic");
  belief_freq_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&belief_freq_min_, &belief_freq_max_, kFrequencyTolerance,
                                               kFrequencyWindow),
      "belief loop rate");
  action_freq_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&action_freq_min_, &action_freq_max_, kFrequencyTolerance,
                                               kFrequencyWindow),
      "action loop rate (/cmd_drive)");
  updater_->add(*belief_freq_);
  updater_->add(*action_freq_);
  updater_->add("loops", this, &AicNode::loopDiagnostics);
  updater_->add("sensors", this, &AicNode::sensorDiagnostics);
  updater_->add("controller", this, &AicNode::controllerDiagnostics);

  belief_timer_ = nh_.createTimer(ros::Duration(belief_stats_.nominal_period), &AicNode::beliefTimerCallback, this);
  action_timer_ = nh_.createTimer(ros::Duration(action_stats_.nominal_period), &AicNode::actionTimerCallback, this);
  diagnostics_timer_ =
      nh_.createTimer(ros::Duration(1.0 / kDiagnosticsPollRate), &AicNode::diagnosticsTimerCallback, this);

  ROS_INFO_STREAM("jackal_AIC: belief " << params_.aic.belief_rate << " Hz, action " << params_.aic.action_rate
                                        << " Hz, tau " << params_.aic.tau << " s, k_mu " << params_.aic.k_mu
                                        << ", k_a " << params_.aic.k_a << ", p " << params_.aic.embedding_order
                                        << ", integrator " << toString(params_.aic.integrator)
                                        << "; waiting for /joint_states, /imu/data and ~set_point");
  return true;
}

SensorSynchronizer::Config AicNode::syncConfig(const NodeParams& params) const
{
  SensorSynchronizer::Config c;
  c.left_joints = params.left_joints;
  c.right_joints = params.right_joints;
  c.imu_max_skew = params.imu_max_skew;
  c.min_sample_interval = params.min_sample_interval;
  c.max_gap = params.sensor_timeout;
  return c;
}

// ---------------------------------------------------------------------------
// Subscribers: validate and store.

void AicNode::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg)
{
  const ros::Time now = ros::Time::now();
  SensorSample sample;
  if (!sync_->addJointState(msg, &sample))
  {
    return;
  }
  if (sample.first || !generalizer_->initialized())
  {
    generalizer_->reset();
    warm_samples_ = 0;
  }
  const Generalizer::Status status = generalizer_->update(sample.y, sample.h);
  if (status != Generalizer::Status::kOk && status != Generalizer::Status::kFirstSample)
  {
    ++generalizer_drops_;
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: generalizer rejected a sample: " << toString(status));
    return;
  }
  warm_samples_ = std::min(warm_samples_ + 1, kMaxOrders + 1);
  measured_wheels_ << sample.y(kOmegaLeft), sample.y(kOmegaRight);
  has_sample_ = true;
  last_sample_receipt_ = now;
  if (active_ && !controller_->setMeasurement(generalizer_->yTilde()))
  {
    ++generalizer_drops_;
    ROS_WARN_THROTTLE(1.0, "jackal_AIC: controller refused a generalized measurement");
  }
}

void AicNode::imuCallback(const sensor_msgs::Imu::ConstPtr& msg)
{
  if (sync_->addImu(msg))
  {
    has_imu_ = true;
    last_imu_receipt_ = ros::Time::now();
  }
}

void AicNode::setPointCallback(const geometry_msgs::Twist::ConstPtr& msg)
{
  const double values[6] = { msg->linear.x, msg->linear.y, msg->linear.z, msg->angular.x, msg->angular.y,
                             msg->angular.z };
  for (double v : values)
  {
    if (!std::isfinite(v))
    {
      ++set_point_drops_;
      ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: dropped a set point with a NaN/Inf field [" << set_point_drops_
                                                                                            << " so far]");
      return;
    }
  }
  double vx = msg->linear.x;
  double wz = msg->angular.z;
  const double vx_max = params_.max_linear_speed;
  const double wz_max = params_.max_angular_speed;
  if (std::abs(vx) > vx_max || std::abs(wz) > wz_max)
  {
    ++set_point_clamps_;
    vx = std::clamp(vx, -vx_max, vx_max);
    wz = std::clamp(wz, -wz_max, wz_max);
    ROS_WARN_STREAM_THROTTLE(1.0, "jackal_AIC: set point (" << msg->linear.x << " m/s, " << msg->angular.z
                                                            << " rad/s) clamped to (" << vx << ", " << wz
                                                            << ") by max_linear_speed / max_angular_speed");
  }
  mu_d_ << vx, 0.0, wz;
  controller_->setGoal(mu_d_);
  has_set_point_ = true;
  last_set_point_receipt_ = ros::Time::now();
}

// ---------------------------------------------------------------------------
// Watchdogs and state.

void AicNode::updateState(const ros::Time& now)
{
  const bool sensors_fresh = has_sample_ && (now - last_sample_receipt_).toSec() <= params_.sensor_timeout;
  const bool set_point_fresh =
      has_set_point_ && (now - last_set_point_receipt_).toSec() <= params_.set_point_timeout;
  const bool warm = generalizer_->initialized() && warm_samples_ >= params_.aic.numOrders();

  NodeState next = NodeState::kRunning;
  const bool changing = [&] {
    if (now < runaway_until_)
    {
      next = NodeState::kRunaway;
    }
    else if (!has_sample_ || (sensors_fresh && (!has_set_point_ || (set_point_fresh && !warm))))
    {
      next = NodeState::kWaiting;
    }
    else if (!sensors_fresh || !set_point_fresh)
    {
      next = NodeState::kStale;
    }
    return next != state_;
  }();

  if (has_sample_ && !sensors_fresh && generalizer_->initialized())
  {
    // Sensors are gone: the next sample starts a new history (and a new warm-up).
    generalizer_->reset();
    warm_samples_ = 0;
    sync_->restartHistory();
  }
  if (!changing)
  {
    return;
  }
  // Only on a change of state: this runs every belief tick.
  std::ostringstream reason;
  switch (next)
  {
    case NodeState::kRunaway:
      reason << "runaway reset; zero command until the hold time ends";
      break;
    case NodeState::kWaiting:
      reason << (!has_sample_ ? "no sensor sample yet" : !has_set_point_ ? "no set point yet on ~set_point" :
                                                                            "warming up the generalizer");
      break;
    case NodeState::kStale:
      if (!sensors_fresh)
      {
        reason << "no sensor sample for " << (now - last_sample_receipt_).toSec() << " s (sensor_timeout "
               << params_.sensor_timeout << " s)";
      }
      else
      {
        reason << "no set point for " << (now - last_set_point_receipt_).toSec() << " s (set_point_timeout "
               << params_.set_point_timeout << " s)";
      }
      ++stale_events_;
      ROS_WARN_STREAM("jackal_AIC: " << reason.str() << "; commanding zero");
      break;
    case NodeState::kRunning:
      reason << "controlling";
      break;
  }
  state_ = next;
  state_reason_ = reason.str();
  if (next == NodeState::kRunning)
  {
    activate();
  }
  else if (active_)
  {
    deactivate();
  }
}

void AicNode::activate()
{
  controller_->reset();
  controller_->setGoal(mu_d_);
  controller_->setMeasurement(generalizer_->yTilde());
  controller_->setAction(measured_wheels_);  // bumpless start from the measured wheel speeds
  // Beliefs start at the measured twist (mu^(0) = G omega), higher orders zero.
  MuTilde mu = MuTilde::Zero(kMuDim, params_.aic.numOrders());
  mu.col(0) = controller_->model().twistFromWheels(measured_wheels_);
  controller_->setBeliefs(mu);
  active_ = true;
  ROS_INFO_STREAM("jackal_AIC: running (start from measured wheels " << measured_wheels_.transpose()
                                                                     << " rad/s, goal " << mu_d_.transpose() << ")");
}

void AicNode::deactivate()
{
  active_ = false;
  publishCommand(0.0, 0.0);  // at once, not at the next action tick
}

void AicNode::handleRunaway(const ros::Time& now, const char* where)
{
  ++runaways_;
  runaway_until_ = now + ros::Duration(params_.runaway_hold_time);
  ROS_ERROR_STREAM_THROTTLE(1.0, "jackal_AIC: runaway beliefs in the " << where << " (|mu| > runaway_limit "
                                                                       << params_.aic.runaway_limit
                                                                       << " or non-finite); controller reset, zero "
                                                                          "command for "
                                                                       << params_.runaway_hold_time << " s ["
                                                                       << runaways_ << " runaway(s) so far]");
  state_ = NodeState::kRunaway;
  state_reason_ = std::string("runaway in the ") + where;
  deactivate();
}

// ---------------------------------------------------------------------------
// Timers: do the work.

void AicNode::beliefTimerCallback(const ros::TimerEvent& event)
{
  const ros::WallTime start = ros::WallTime::now();
  applyPendingParams();
  const double interval = belief_stats_.record(intervalOf(event));
  belief_freq_->tick();
  const ros::Time now = ros::Time::now();
  updateState(now);
  // Catch up: a late tick integrates its interval in steps of about one nominal period. The
  // fractional remainder is carried over (bounded), so early and late ticks average out to
  // belief_rate steps per second; every callback runs at least one step.
  belief_step_debt_ += interval / belief_stats_.nominal_period;
  const int steps = std::clamp(static_cast<int>(std::floor(belief_step_debt_ + 0.5)), 1,
                               static_cast<int>(kMaxBeliefIntervalFactor));
  belief_step_debt_ = std::clamp(belief_step_debt_ - steps, -1.0, 1.0);
  const double h = interval / steps;
  belief_stats_.catch_up_steps += static_cast<std::uint64_t>(steps - 1);
  for (int i = 0; i < steps; ++i)
  {
    if (active_ && controller_->updateBeliefs(h) == ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway(now, "belief update");
    }
    publishBelief(event.current_real - ros::Duration(h * (steps - 1 - i)));
  }
  belief_stats_.window_max_duration =
      std::max(belief_stats_.window_max_duration, (ros::WallTime::now() - start).toSec());
}

void AicNode::publishBelief(const ros::Time& stamp)
{
  geometry_msgs::TwistStamped belief;
  belief.header.stamp = stamp;
  belief.header.frame_id = "base_link";
  const auto mu0 = controller_->mu().col(0);
  if (mu0.allFinite())
  {
    belief.twist.linear.x = mu0(0);
    belief.twist.linear.y = mu0(1);
    belief.twist.angular.z = mu0(2);
  }
  else
  {
    ++guarded_outputs_;  // never publish a non-finite number (the controller resets on runaway)
  }
  belief_pub_.publish(belief);
}

void AicNode::actionTimerCallback(const ros::TimerEvent& event)
{
  const ros::WallTime start = ros::WallTime::now();
  applyPendingParams();
  const double h = action_stats_.record(intervalOf(event));
  action_freq_->tick();
  const ros::Time now = ros::Time::now();
  updateState(now);
  if (active_)
  {
    if (controller_->updateAction(h) == ActiveInferenceController::Status::kRunaway)
    {
      handleRunaway(now, "action update");  // publishes the zero command
    }
    else
    {
      publishCommand(controller_->action()(0), controller_->action()(1));
    }
  }
  else
  {
    publishCommand(0.0, 0.0);
  }
  publishDebug();
  action_stats_.window_max_duration =
      std::max(action_stats_.window_max_duration, (ros::WallTime::now() - start).toSec());
}

void AicNode::diagnosticsTimerCallback(const ros::TimerEvent& /*event*/)
{
  updater_->update();
}

void AicNode::publishCommand(double omega_left, double omega_right)
{
  if (!std::isfinite(omega_left) || !std::isfinite(omega_right))
  {
    ++guarded_outputs_;
    ROS_ERROR_THROTTLE(1.0, "jackal_AIC: non-finite wheel command replaced by zero");
    omega_left = 0.0;
    omega_right = 0.0;
  }
  const double limit = params_.aic.max_wheel_speed;
  jackal_msgs::Drive cmd;
  cmd.mode = jackal_msgs::Drive::MODE_VELOCITY;
  cmd.drivers[jackal_msgs::Drive::LEFT] = static_cast<float>(std::clamp(omega_left, -limit, limit));
  cmd.drivers[jackal_msgs::Drive::RIGHT] = static_cast<float>(std::clamp(omega_right, -limit, limit));
  cmd_pub_.publish(cmd);
}

void AicNode::publishDebug()
{
  const bool want_f = free_energy_pub_.getNumSubscribers() > 0;
  if (want_f || updater_)
  {
    last_free_energy_ = controller_->hasMeasurement() ? controller_->freeEnergy() : 0.0;
  }
  if (want_f)
  {
    if (std::isfinite(last_free_energy_))
    {
      std_msgs::Float64 f;
      f.data = last_free_energy_;
      free_energy_pub_.publish(f);
    }
    else
    {
      ++guarded_outputs_;
    }
  }
  // eps_y, eps_mu: built only for a subscriber (a message allocates), never published non-finite.
  auto publishErrors = [this](const ros::Publisher& pub, const auto& errors) {
    if (allFinite(errors))
    {
      pub.publish(toMultiArray(errors, "channel"));
    }
    else
    {
      ++guarded_outputs_;
    }
  };
  if (eps_y_pub_.getNumSubscribers() > 0)
  {
    publishErrors(eps_y_pub_, controller_->epsY());
  }
  if (eps_mu_pub_.getNumSubscribers() > 0)
  {
    publishErrors(eps_mu_pub_, controller_->epsMu());
  }
}

// ---------------------------------------------------------------------------
// dynamic_reconfigure: validate in the callback, apply between ticks.

AICConfig AicNode::configFromParams(const NodeParams& params) const
{
  AICConfig c = AICConfig::__getDefault__();
  const AicParams& a = params.aic;
  c.belief_rate = a.belief_rate;
  c.action_rate = a.action_rate;
  c.integrator = toString(a.integrator);
  c.tau = a.tau;
  c.k_mu = a.k_mu;
  c.k_a = a.k_a;
  c.embedding_order = a.embedding_order;
  c.accel_in_model = a.accel_in_model;
  c.runaway_limit = a.runaway_limit;
  c.max_action_lead = a.max_action_lead;
  c.wheel_radius = a.wheel_radius;
  c.slip_factor = a.slip_factor;
  c.wheel_separation = a.wheel_separation;
  c.max_wheel_speed = a.max_wheel_speed;
  c.sensor_timeout = params.sensor_timeout;
  c.set_point_timeout = params.set_point_timeout;
  c.max_linear_speed = params.max_linear_speed;
  c.max_angular_speed = params.max_angular_speed;
  c.imu_max_skew = params.imu_max_skew;
  c.runaway_hold_time = params.runaway_hold_time;
  // Per-order variances; with the per-channel form, the first channel of each order is shown.
  double* var_mu[6] = { &c.var_mu_0, &c.var_mu_1, &c.var_mu_2, &c.var_mu_3, &c.var_mu_4, &c.var_mu_5 };
  double* var_y[6] = { &c.var_y_0, &c.var_y_1, &c.var_y_2, &c.var_y_3, &c.var_y_4, &c.var_y_5 };
  const int orders = a.numOrders();
  const int stride_mu = static_cast<int>(a.var_mu.size()) == orders ? 1 : kMuDim;
  const int stride_y = static_cast<int>(a.var_y.size()) == orders ? 1 : kYDim;
  for (int i = 0; i < orders && i < 6; ++i)
  {
    *var_mu[i] = a.var_mu[static_cast<std::size_t>(i * stride_mu)];
    *var_y[i] = a.var_y[static_cast<std::size_t>(i * stride_y)];
  }
  return c;
}

void AicNode::reconfigureCallback(AICConfig& config, std::uint32_t /*level*/)
{
  if (!reconfigure_initialized_)
  {
    reconfigure_initialized_ = true;  // setCallback's first call carries the values we already run with
    return;
  }
  NodeParams base = params_;
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    if (pending_params_)
    {
      base = *pending_params_;
    }
  }
  NodeParams next = base;
  AicParams& a = next.aic;
  std::vector<ParamViolation> violations;
  a.belief_rate = config.belief_rate;
  a.action_rate = config.action_rate;
  if (!integratorFromString(config.integrator, &a.integrator))
  {
    violations.push_back({ "integrator", config.integrator, "euler or exact" });
  }
  a.tau = config.tau;
  a.k_mu = config.k_mu;
  a.k_a = config.k_a;
  a.embedding_order = config.embedding_order;
  a.accel_in_model = config.accel_in_model;
  a.runaway_limit = config.runaway_limit;
  a.max_action_lead = config.max_action_lead;
  a.wheel_radius = config.wheel_radius;
  a.slip_factor = config.slip_factor;
  a.wheel_separation = config.wheel_separation;
  a.max_wheel_speed = config.max_wheel_speed;
  next.sensor_timeout = config.sensor_timeout;
  next.set_point_timeout = config.set_point_timeout;
  next.max_linear_speed = config.max_linear_speed;
  next.max_angular_speed = config.max_angular_speed;
  next.imu_max_skew = config.imu_max_skew;
  next.runaway_hold_time = config.runaway_hold_time;

  const double var_mu[6] = { config.var_mu_0, config.var_mu_1, config.var_mu_2,
                             config.var_mu_3, config.var_mu_4, config.var_mu_5 };
  const double var_y[6] = { config.var_y_0, config.var_y_1, config.var_y_2,
                            config.var_y_3, config.var_y_4, config.var_y_5 };
  const AicParams& b = base.aic;
  const bool per_order =
      static_cast<int>(b.var_mu.size()) == b.numOrders() && static_cast<int>(b.var_y.size()) == b.numOrders();
  if (per_order)
  {
    a.var_mu.assign(var_mu, var_mu + a.numOrders());
    a.var_y.assign(var_y, var_y + a.numOrders());
  }
  else
  {
    const AICConfig shown = configFromParams(base);
    const double shown_mu[6] = { shown.var_mu_0, shown.var_mu_1, shown.var_mu_2,
                                 shown.var_mu_3, shown.var_mu_4, shown.var_mu_5 };
    const double shown_y[6] = { shown.var_y_0, shown.var_y_1, shown.var_y_2,
                                shown.var_y_3, shown.var_y_4, shown.var_y_5 };
    bool changed = a.embedding_order != b.embedding_order;
    for (int i = 0; i < 6; ++i)
    {
      changed = changed || var_mu[i] != shown_mu[i] || var_y[i] != shown_y[i];
    }
    if (changed)
    {
      violations.push_back({ "var_mu/var_y/embedding_order", "changed live",
                             "unchanged while the YAML gives per-channel variances (edit the YAML instead)" });
    }
  }

  for (auto& v : next.validate())
  {
    violations.push_back(std::move(v));
  }
  if (!violations.empty())
  {
    for (const auto& v : violations)
    {
      ROS_ERROR_STREAM("jackal_AIC: reconfigure refused: ~" << v.toString());
    }
    config = configFromParams(base);  // the server publishes the values still in force
    return;
  }
  ROS_INFO("jackal_AIC: reconfigure accepted; applied at the next tick");
  std::lock_guard<std::mutex> lock(pending_mutex_);
  pending_params_ = std::make_unique<NodeParams>(next);
}

void AicNode::applyPendingParams()
{
  std::unique_ptr<NodeParams> next;
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    next.swap(pending_params_);
  }
  if (!next)
  {
    return;
  }
  try
  {
    controller_->setParams(next->aic);
  }
  catch (const std::exception& e)
  {
    ROS_ERROR_STREAM("jackal_AIC: reconfigure not applied: " << e.what());
    return;
  }
  if (next->aic.embedding_order != params_.aic.embedding_order)
  {
    generalizer_ = std::make_unique<Generalizer>(kYDim, next->aic.embedding_order);
    warm_samples_ = 0;
    sync_->restartHistory();
    if (active_)
    {
      state_ = NodeState::kWaiting;
      state_reason_ = "embedding order changed; warming up";
      deactivate();
    }
  }
  if (next->aic.belief_rate != params_.aic.belief_rate)
  {
    belief_stats_.nominal_period = 1.0 / next->aic.belief_rate;
    belief_freq_min_ = belief_freq_max_ = next->aic.belief_rate;
    belief_timer_.setPeriod(ros::Duration(belief_stats_.nominal_period));
  }
  if (next->aic.action_rate != params_.aic.action_rate)
  {
    action_stats_.nominal_period = 1.0 / next->aic.action_rate;
    action_freq_min_ = action_freq_max_ = next->aic.action_rate;
    action_timer_.setPeriod(ros::Duration(action_stats_.nominal_period));
  }
  sync_->setConfig(syncConfig(*next));
  params_ = *next;
  ROS_INFO_STREAM("jackal_AIC: parameters applied (belief " << params_.aic.belief_rate << " Hz, action "
                                                            << params_.aic.action_rate << " Hz, tau "
                                                            << params_.aic.tau << ", k_mu " << params_.aic.k_mu
                                                            << ", k_a " << params_.aic.k_a << ", integrator "
                                                            << toString(params_.aic.integrator) << ")");
}

// ---------------------------------------------------------------------------
// Diagnostics.

void AicNode::loopDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  const LoopStats* loops[2] = { &belief_stats_, &action_stats_ };
  const char* names[2] = { "belief", "action" };
  bool late = false;
  for (int i = 0; i < 2; ++i)
  {
    const LoopStats& s = *loops[i];
    const double mean_jitter = s.window_ticks > 0 ? s.window_abs_jitter_sum / s.window_ticks : 0.0;
    stat.addf(std::string(names[i]) + " nominal period [ms]", "%.3f", 1e3 * s.nominal_period);
    stat.addf(std::string(names[i]) + " mean |jitter| [ms]", "%.3f", 1e3 * mean_jitter);
    stat.addf(std::string(names[i]) + " max interval [ms]", "%.3f", 1e3 * s.window_max_interval);
    stat.addf(std::string(names[i]) + " max callback duration [ms]", "%.3f", 1e3 * s.window_max_duration);
    stat.add(std::string(names[i]) + " overruns (interval > 2 periods)", s.overruns);
    stat.add(std::string(names[i]) + " clamped intervals", s.clamped);
    stat.add(std::string(names[i]) + " catch-up steps", s.catch_up_steps);
    late = late || s.window_max_duration > s.nominal_period;
  }
  if (late)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "a callback took longer than its period");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "loops on time");
  }
  belief_stats_.resetWindow();
  action_stats_.resetWindow();
}

void AicNode::sensorDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  const ros::Time now = ros::Time::now();
  auto age = [&](bool has, const ros::Time& t) { return has ? (now - t).toSec() : -1.0; };
  stat.addf("sample age [s] (-1: never)", "%.3f", age(has_sample_, last_sample_receipt_));
  stat.addf("imu age [s] (-1: never)", "%.3f", age(has_imu_, last_imu_receipt_));
  stat.addf("set point age [s] (-1: never)", "%.3f", age(has_set_point_, last_set_point_receipt_));
  stat.add("accepted samples", sync_->acceptedSamples());
  std::uint64_t dropped = 0;
  for (int i = 0; i < static_cast<int>(DropReason::kCount); ++i)
  {
    const std::uint64_t n = sync_->dropCounts()[static_cast<std::size_t>(i)];
    dropped += n;
    stat.add(std::string("dropped: ") + toString(static_cast<DropReason>(i)), n);
  }
  stat.add("dropped: generalizer/controller refused", generalizer_drops_);
  stat.add("dropped: set point non-finite", set_point_drops_);
  stat.add("set points clamped", set_point_clamps_);
  stat.add("stale events", stale_events_);
  const bool sensors_stale = !has_sample_ || (now - last_sample_receipt_).toSec() > params_.sensor_timeout;
  const bool set_point_stale =
      !has_set_point_ || (now - last_set_point_receipt_).toSec() > params_.set_point_timeout;
  if (sensors_stale || set_point_stale)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 sensors_stale ? "sensor samples stale or missing" : "set point stale or missing");
  }
  else if (dropped + set_point_drops_ + generalizer_drops_ > 0)
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "fresh (some inputs were dropped)");
  }
  else
  {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "fresh");
  }
}

void AicNode::controllerDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  stat.add("state", toString(state_));
  stat.add("reason", state_reason_);
  stat.add("runaway resets", runaways_);
  stat.add("non-finite outputs suppressed", guarded_outputs_);
  stat.addf("free energy", "%g", last_free_energy_);
  stat.addf("goal v_x [m/s]", "%.3f", mu_d_(0));
  stat.addf("goal omega_z [rad/s]", "%.3f", mu_d_(2));
  stat.addf("belief v_x [m/s]", "%.3f", controller_->mu()(0, 0));
  stat.addf("belief omega_z [rad/s]", "%.3f", controller_->mu()(2, 0));
  stat.addf("command left [rad/s]", "%.3f", active_ ? controller_->action()(0) : 0.0);
  stat.addf("command right [rad/s]", "%.3f", active_ ? controller_->action()(1) : 0.0);
  switch (state_)
  {
    case NodeState::kRunning:
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
      break;
    case NodeState::kWaiting:
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "waiting: " + state_reason_);
      break;
    case NodeState::kStale:
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "stale: " + state_reason_);
      break;
    case NodeState::kRunaway:
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "runaway: " + state_reason_);
      break;
  }
}

}  // namespace jackal_aic
