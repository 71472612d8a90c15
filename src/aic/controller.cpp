/**
 * \file controller.cpp
 * \brief Active inference controller (thesis eq. 3-6 ... 3-16; Pezzato et al. 2020; doc/active_inference.md,
 *        'Prediction errors and free energy' to 'Integrators'), composed of its stages ('Structure of
 *        the controller').
 */
#include "jackal_aic/aic/controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

namespace jackal_aic
{
namespace aic
{
namespace
{
std::string joinViolations(const std::vector<params::ParamViolation>& violations)
{
  std::string msg = "invalid AicParams:";
  for (const auto& v : violations)
  {
    msg += " " + v.toString() + ";";
  }
  return msg;
}

/// Returns params if valid, throws std::invalid_argument listing every violation otherwise.
const params::AicParams& checked(const params::AicParams& params)
{
  const auto violations = params.validate();
  if (!violations.empty())
  {
    throw std::invalid_argument(joinViolations(violations));
  }
  return params;
}

/// The robot model's goal path's least time constant [s]: with (1 - c) T_w = 0 the path is the
/// wheel loop's rate bound alone (a reference model needs T_r > 0).
constexpr double kMinPathTimeConstant = 1.0e-4;

/// The sensor mask's bits of the three channels that observe the twist twice (gyro, both wheels):
/// the robot model's slow states learn only from all three.
constexpr std::uint8_t kTwistChannels = (1u << base::kGyroZ) | (1u << base::kOmegaLeft) | (1u << base::kOmegaRight);
/// The sensor mask's bits of the two wheels.
constexpr std::uint8_t kWheelChannels = (1u << base::kOmegaLeft) | (1u << base::kOmegaRight);

/// A step the controller takes: finite, > 0 and at most params::kMaxStep [s].
bool validStep(double h)
{
  return std::isfinite(h) && h > 0.0 && h <= params::kMaxStep;
}

/**
 * \brief The goal stage's settings: params.reference, except with belief_model robot. The robot
 *        model's goal is predicted one latency ahead, `latency` [s] (the time the command sent now
 *        acts: the wheel loop's L, configured or learned), and its
 *        path is the wheel loop's own response to it: the time constant (1 - c) T_w, the model's
 *        steady lag to a ramped command (T_w without the MCU's feed-forward, c = 0; at least
 *        kMinPathTimeConstant, so that T_w = 0 keeps the rate bound) and per wheel the
 *        acceleration A_w at the rim; it is not delayed: the latency is in the model
 *        (WheelLoopModel), not in the goal's path. With params::goalRateParams() (the bounds of
 *        the goal's rate), the places a stage's settings are derived rather than taken as they are.
 */
params::ReferenceModelParams goalStageParams(const params::AicParams& params, double latency)
{
  params::ReferenceModelParams rp = params.reference;
  if (params.belief_model == params::BeliefModel::kRobot)
  {
    rp.goal_lead = latency;
    rp.goal_lead_angular = latency;
    rp.time_constant =
        std::max((1.0 - params.robot.wheel_feedforward) * params.robot.wheel_time_constant, kMinPathTimeConstant);
    rp.max_acceleration_linear = params::ReferenceModelParams().max_acceleration_linear;
    rp.max_acceleration_angular = params::ReferenceModelParams().max_acceleration_angular;
    rp.max_acceleration_wheel = params::robotWheelAcceleration(params);
    rp.delay = 0.0;
  }
  return rp;
}

/// The separation learner of params: its settings, the robot's geometry, and b_hat starting at
/// wheel_separation clamped to the learner's bounds.
SeparationLearner makeSeparationLearner(const params::AicParams& params)
{
  const params::SeparationLearnerParams& lp = params.separation_learner;
  return SeparationLearner(lp, params.wheel_radius, params.slip_factor,
                           std::clamp(params.wheel_separation, lp.min, lp.max));
}
}  // namespace

ActiveInferenceController::ActiveInferenceController(const params::AicParams& params)
  : params_(checked(params))
  , model_(params.wheel_radius, params.slip_factor, params.wheel_separation)
  , learner_(makeSeparationLearner(params))
{
  const int n = params.numOrders();
  mu_.setZero(base::kMuDim, n);
  y_tilde_.setZero(base::kYDim, n);
  applyParams(params);
  startReference(base::Vector3::Zero());
  action_line_.restart(model_.twistFromWheels(a_));
}

void ActiveInferenceController::setParams(const params::AicParams& params)
{
  checked(params);
  const bool order_changed = params.embedding_order != params_.embedding_order;
  applyParams(params);
  // A lower max_wheel_speed applies to the action held now, not only from the next action step
  // (found by test/fuzz/fuzz_core.cpp).
  a_ = anti_windup_.limitWheelSpeed(a_);
  if (order_changed)
  {
    const int n = params.numOrders();
    mu_.setZero(base::kMuDim, n);
    y_tilde_.setZero(base::kYDim, n);
    a_.setZero();
    a_F_.setZero();
    has_measurement_ = false;
  }
}

void ActiveInferenceController::applyParams(const params::AicParams& params)
{
  // What was learned survives a parameter change that keeps learning on and the geometry.
  const bool keep_learned = params.separation_learner.enabled && params_.separation_learner.enabled &&
                            params.wheel_separation == params_.wheel_separation &&
                            params.wheel_radius == params_.wheel_radius && params.slip_factor == params_.slip_factor;
  const double learned = learner_.separation();
  // And the learned latency, while its settings stay.
  const bool keep_latency = latency_learner_configured_ && params.robot.latency == params_.robot.latency &&
                            params.robot.encoder_noise == params_.robot.encoder_noise &&
                            params.robot.learn_latency == params_.robot.learn_latency;
  params_ = params;
  model_ = SkidSteerModel(params.wheel_radius, params.slip_factor, params.wheel_separation);
  learner_ = makeSeparationLearner(params);
  if (keep_learned)
  {
    learner_.setSeparation(learned);
  }
  if (params.separation_learner.enabled)
  {
    model_.setWheelSeparation(learner_.separation());
  }
  wheel_loop_.setParams(params.robot);
  robot_belief_.setParams(params.robot);
  if (!keep_latency)
  {
    latency_learner_ = LatencyLearner(params.robot.latency, params::kLatencyMinFactor * params.robot.latency,
                                      params::kLatencyMaxFactor * params.robot.latency, params.robot.encoder_noise);
    latency_learner_configured_ = true;
  }
  // The latency in use, configured or learned: the wheel loop's, and the robot model's goal lead.
  const double latency = params::learnsLatency(params) ? latency_learner_.latency() : params.robot.latency;
  wheel_loop_.setLatency(latency);
  reference_.setParams(goalStageParams(params, latency),
                       params.runaway_limit);               // zeroes the goal's rate unless generalized
  reference_.setWheelSeparation(model_.wheelSeparation());  // the learned b_hat when learning
  action_line_.setDelay(params.reference.delay);
  action_prior_ = ActionPrior(params.action_prior);
  release_ = RestRelease(params.action_release_time);
  if (params.goal_response_time_constant != response_.timeConstant())
  {
    response_ = GoalResponse(params.goal_response_time_constant);
    response_.start(reference_.attractorGoal());
  }
  anti_windup_ = AntiWindup(params.anti_windup, params.max_wheel_speed);
  slew_limit_ = ActionSlewLimit(params.action_slew);
  pi_mu_ = params.precisionMu();
  precision_learner_.setParams(params.precision_learner, precisionChannels(params));
  rebuildDynamics();
}

void ActiveInferenceController::applyLearnedSeparation(bool force)
{
  const double b = learner_.separation();
  const double b_model = model_.wheelSeparation();
  if (force || std::abs(b - b_model) > kSeparationApplyTolerance * b_model)
  {
    model_.setWheelSeparation(b);
    reference_.setWheelSeparation(b);
    if (params_.belief_model != params::BeliefModel::kRobot)  // the robot model has no linear belief dynamics
    {
      rebuildDynamics();
    }
  }
}

bool ActiveInferenceController::setLearnedSeparation(double b)
{
  if (!learner_.setSeparation(b))
  {
    return false;
  }
  if (params_.separation_learner.enabled)
  {
    applyLearnedSeparation(true);
  }
  return true;
}

void ActiveInferenceController::resetLearning()
{
  learner_.reset();
  latency_learner_.reset();
  useLatency(params::learnsLatency(params_) ? latency_learner_.latency() : params_.robot.latency);
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    robot_belief_.forgetSlowStates();
  }
  if (params_.separation_learner.enabled)
  {
    applyLearnedSeparation(true);
  }
}

void ActiveInferenceController::setSensorMask(std::uint8_t mask)
{
  mask &= static_cast<std::uint8_t>((1u << base::kYDim) - 1u);
  if (mask == sensor_mask_)
  {
    return;
  }
  sensor_mask_ = mask;
  rebuildDynamics();
}

void ActiveInferenceController::setFaultState(bool suspected, bool present)
{
  fault_suspected_ = suspected;
  fault_present_ = present;
}

void ActiveInferenceController::gyroOffsetRemoved(double change)
{
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    robot_belief_.shiftGyroOffset(-change);
  }
}

void ActiveInferenceController::rebuildDynamics()
{
  const params::AicParams& params = params_;
  pi_y_ = params.modelPrecisionY();
  if (params::learnsPrecision(params))
  {
    precision_learner_.applyTo(&pi_y_);
  }
  for (int j = 0; j < base::kYDim; ++j)
  {
    if ((sensor_mask_ & (1u << j)) == 0)
    {
      pi_y_.row(j).setZero();
    }
  }

  // The belief dynamics are affine in mu_tilde: dmu/dt = M vec(mu) + (terms in y_tilde, mu_d).
  // Column j of M is dmu/dt at mu = e_j with y_tilde = 0 and mu_d = 0.
  const int n = params.numOrders();
  const int dim = base::kMuDim * n;
  M_.setZero(dim, dim);
  base::MuTilde e(base::kMuDim, n);
  base::MuTilde f(base::kMuDim, n);
  base::YTilde y0 = base::YTilde::Zero(base::kYDim, n);
  const base::Vector3 zero3 = base::Vector3::Zero();
  for (int j = 0; j < dim; ++j)
  {
    e.setZero();
    e.data()[j] = 1.0;
    computeMuDot(e, y0, zero3, zero3, &f);
    M_.col(j) = Eigen::Map<const Eigen::VectorXd>(f.data(), dim);
  }
  m_norm_ = M_.cwiseAbs().rowwise().sum().maxCoeff();  // ||M||_inf [1/s]
  phi_.setZero(dim, dim);
  psi_.setZero(dim, dim);
  exact_h_ = 0.0;
}

bool ActiveInferenceController::setGoal(const base::Vector3& mu_d, const base::Vector3& mu_d_dot)
{
  return reference_.setGoal(mu_d, mu_d_dot);
}

base::Vector3 ActiveInferenceController::attractorGoal() const
{
  return reference_.attractorGoal();
}

base::Vector3 ActiveInferenceController::priorGoal() const
{
  return params_.belief_model == params::BeliefModel::kUnbiased ? action_line_.delayed() : reference_.attractorGoal();
}

base::Vector3 ActiveInferenceController::priorRate() const
{
  return params_.belief_model == params::BeliefModel::kUnbiased ? base::Vector3::Zero() : reference_.attractorRate();
}

base::Vector2 ActiveInferenceController::actionPrior() const
{
  return action_prior_.wheels(model_, reference_);
}

bool ActiveInferenceController::startReference(const base::Vector3& m0)
{
  if (!reference_.start(m0))
  {
    return false;
  }
  response_.start(m0);
  return true;
}

bool ActiveInferenceController::setMeasurement(const base::YTilde& y_tilde, bool wheels_repeated)
{
  if (y_tilde.cols() != params_.numOrders() || !y_tilde.allFinite() ||
      y_tilde.cwiseAbs().maxCoeff() > kMaxMeasurementMagnitude)
  {
    return false;
  }
  y_tilde_ = y_tilde;
  has_measurement_ = true;
  robot_sample_pending_ = true;
  robot_wheels_repeated_ = wheels_repeated;
  return true;
}

bool ActiveInferenceController::setBeliefs(const base::MuTilde& mu)
{
  if (mu.cols() != params_.numOrders() || !mu.allFinite() || mu.cwiseAbs().maxCoeff() > params_.runaway_limit)
  {
    return false;
  }
  mu_ = mu;
  return true;
}

void ActiveInferenceController::computeEpsY(const base::MuTilde& mu, const base::YTilde& y_tilde,
                                            base::YTilde* eps_y) const
{
  const int n = params_.numOrders();
  for (int i = 0; i < n; ++i)
  {
    eps_y->col(i) = epsYOrder(mu, y_tilde, i);
  }
}

base::Vector5 ActiveInferenceController::epsYOrder(const base::MuTilde& mu, const base::YTilde& y_tilde, int i) const
{
  base::Vector5 e;
  e.noalias() = y_tilde.col(i) - model_.R() * mu.col(i);
  if (params_.accel_in_model && i + 1 < params_.numOrders())
  {
    // Optional kinematic accelerometer row: accel_x^(i) predicted by x_dot^(i+1).
    e(base::kAccelX) -= mu(0, i + 1);
  }
  return e;
}

void ActiveInferenceController::computeEpsMu(const base::MuTilde& mu, const base::Vector3& g,
                                             const base::Vector3& g_dot, base::MuTilde* eps_mu) const
{
  const int n = params_.numOrders();
  const double inv_tau = 1.0 / params_.tau;
  // eps_mu^(0) = mu^(1) - g' - (g - mu^(0)) / tau (g = mu_d, g' = 0: eq. 3-9; a generalized goal or
  // the reference path: doc/active_inference.md, 'Set-point dynamics');
  // eps_mu^(i) = mu^(i+1) + mu^(i) / tau, mu^(p+1) = 0.
  eps_mu->col(0) = mu.col(1) - g_dot - (g - mu.col(0)) * inv_tau;
  for (int i = 1; i < n; ++i)
  {
    eps_mu->col(i) = mu.col(i) * inv_tau;
    if (i + 1 < n)
    {
      eps_mu->col(i) += mu.col(i + 1);
    }
  }
}

void ActiveInferenceController::computeDfDmu(const base::MuTilde& mu, const base::YTilde& y_tilde,
                                             const base::Vector3& g, const base::Vector3& g_dot,
                                             base::MuTilde* grad) const
{
  const int n = params_.numOrders();
  const double inv_tau = 1.0 / params_.tau;
  base::YTilde wy(base::kYDim, n);    // Pi_y eps_y
  base::MuTilde wm(base::kMuDim, n);  // Pi_mu eps_mu
  computeEpsY(mu, y_tilde, &wy);
  computeEpsMu(mu, g, g_dot, &wm);
  wy.array() *= pi_y_.array();
  wm.array() *= pi_mu_.array();
  const base::SensorMatrix& R = model_.R();
  for (int i = 0; i < n; ++i)
  {
    grad->col(i).noalias() = -R.transpose() * wy.col(i);
    grad->col(i) += inv_tau * wm.col(i);
    if (i >= 1)
    {
      grad->col(i) += wm.col(i - 1);
      if (params_.accel_in_model)
      {
        (*grad)(0, i) -= wy(base::kAccelX, i - 1);
      }
    }
  }
}

void ActiveInferenceController::computeMuDot(const base::MuTilde& mu, const base::YTilde& y_tilde,
                                             const base::Vector3& g, const base::Vector3& g_dot,
                                             base::MuTilde* mu_dot) const
{
  const int n = params_.numOrders();
  computeDfDmu(mu, y_tilde, g, g_dot, mu_dot);
  *mu_dot *= -params_.k_mu;
  // Shift operator D: (D mu)^(i) = mu^(i+1), (D mu)^(p) = 0.
  mu_dot->leftCols(n - 1) += mu.rightCols(n - 1);
}

base::YTilde ActiveInferenceController::epsY() const
{
  base::YTilde e(base::kYDim, params_.numOrders());
  computeEpsY(mu_, y_tilde_, &e);
  return e;
}

base::MuTilde ActiveInferenceController::epsMu() const
{
  base::MuTilde e(base::kMuDim, params_.numOrders());
  computeEpsMu(mu_, priorGoal(), priorRate(), &e);
  return e;
}

double ActiveInferenceController::freeEnergy() const
{
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    return sensoryFreeEnergy() + priorFreeEnergy();
  }
  const base::YTilde ey = epsY();
  const base::MuTilde em = epsMu();
  return 0.5 * ((ey.array().square() * pi_y_.array()).sum() + (em.array().square() * pi_mu_.array()).sum());
}

double ActiveInferenceController::sensoryFreeEnergy() const
{
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    return robot_belief_.sensoryFreeEnergy();
  }
  return 0.5 * (epsY().array().square() * pi_y_.array()).sum();
}

double ActiveInferenceController::priorFreeEnergy() const
{
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    return robot_belief_.priorFreeEnergy();
  }
  return 0.5 * (epsMu().array().square() * pi_mu_.array()).sum();
}

base::MuTilde ActiveInferenceController::dFdMu() const
{
  base::MuTilde g(base::kMuDim, params_.numOrders());
  computeDfDmu(mu_, y_tilde_, priorGoal(), priorRate(), &g);
  return g;
}

base::MuTilde ActiveInferenceController::muDot() const
{
  base::MuTilde d(base::kMuDim, params_.numOrders());
  computeMuDot(mu_, y_tilde_, priorGoal(), priorRate(), &d);
  return d;
}

base::Vector2 ActiveInferenceController::aDot() const
{
  const int n = params_.numOrders();
  base::YTilde ey(base::kYDim, n);
  if (params_.belief_model == params::BeliefModel::kUnbiased)
  {
    // The goal prior on the action's outcome: the predicted sensations R mu^(i) should be those of
    // the goal's path g = (mu_r, mu_r', 0, ...), so eps_g^(i) = R (mu^(i) - g^(i)) takes eps_y's
    // place (sign: a belief below the goal asks for more, as eps_y = y - R mu < 0 does).
    const base::SensorMatrix& R = model_.R();
    // With goal_response_time_constant T_g > 0 the goal's path as the robot is expected to follow
    // it (GoalResponse), else the reference path itself.
    const base::Vector3 g0 = response_.enabled() ? response_.goal() : reference_.attractorGoal();
    const base::Vector3 g1 = response_.enabled() ? response_.rate() : reference_.attractorRate();
    for (int i = 0; i < n; ++i)
    {
      base::Vector3 d = mu_.col(i);
      if (i == 0)
      {
        d -= g0;
      }
      else if (i == 1)
      {
        d -= g1;
      }
      ey.col(i).noalias() = R * d;
    }
  }
  else
  {
    computeEpsY(mu_, y_tilde_, &ey);
  }
  ey.array() *= pi_y_.array();
  // da/dt = -k_a sum_i K Pi_y^(i) eps_y^(i)
  const base::Vector5 sum = ey.rowwise().sum();
  return -params_.k_a * (model_.K() * sum);
}

void ActiveInferenceController::computeExactStep(double h)
{
  // Zero-order hold over one step with y_tilde and mu_d held: x' = M x + c (c constant), so
  //   x(h) = exp(M h) x + Psi c,  Psi = int_0^h exp(M s) ds,  and since exp(M h) = I + Psi M,
  //   x(h) = x + Psi (M x + c) = x + Psi * (dmu/dt at x).
  // Phi and Psi come from one exponential of the augmented matrix [[M, I], [0, 0]] h (Van Loan).
  using AugMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 2 * kMaxStateDim, 2 * kMaxStateDim>;
  const int dim = static_cast<int>(M_.rows());
  AugMatrix aug = AugMatrix::Zero(2 * dim, 2 * dim);
  aug.topLeftCorner(dim, dim) = M_ * h;
  aug.topRightCorner(dim, dim).setIdentity();
  aug.topRightCorner(dim, dim) *= h;
  AugMatrix ex(2 * dim, 2 * dim);
  ex = aug.exp();
  phi_ = ex.topLeftCorner(dim, dim);
  psi_ = ex.topRightCorner(dim, dim);
  exact_h_ = h;
  ++exact_recompute_count_;
}

ActiveInferenceController::Status ActiveInferenceController::updateBeliefs(double h)
{
  if (!validStep(h))
  {
    return Status::kBadInterval;
  }
  if (!has_measurement_)
  {
    return Status::kNoMeasurement;
  }
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    return updateRobotBeliefs(h);
  }
  // The belief step's stages, in order (control_loop.hpp, 'The controller's composition').
  if (!integrateBeliefs(h))  // mu_tilde towards priorGoal(): ReferenceModel's mu_r or ActionDelayLine's G a(t - d_r)
  {
    runawayReset();
    return Status::kRunaway;
  }
  reference_.advance(h);                                                         // ReferenceModel
  response_.advance(h, reference_.attractorGoal(), reference_.attractorRate());  // GoalResponse
  if (params_.separation_learner.enabled)
  {
    learn(h);  // SeparationLearner
  }
  if (params_.precision_learner.enabled)
  {
    learnPrecision(h);  // PrecisionLearner
  }
  return Status::kOk;
}

bool ActiveInferenceController::integrateBeliefs(double h)
{
  const int n = params_.numOrders();
  base::MuTilde f(base::kMuDim, n);
  computeMuDot(mu_, y_tilde_, priorGoal(), priorRate(), &f);
  base::MuTilde next(base::kMuDim, n);
  if (params_.integrator == params::Integrator::kExact)
  {
    if (exact_h_ <= 0.0 || std::abs(h - exact_h_) * m_norm_ > kExactSeriesLimit)
    {
      computeExactStep(h);
    }
    const int dim = base::kMuDim * n;
    Eigen::Map<const Eigen::VectorXd> fv(f.data(), dim);
    Eigen::Map<Eigen::VectorXd> nv(next.data(), dim);
    nv.noalias() = psi_ * fv;
    const double dh = h - exact_h_;
    if (dh != 0.0)
    {
      // h = h0 + dh: Psi(h) = Psi(h0) + Phi(h0) Psi(dh) (exact, either sign of dh), with
      // Psi(dh) = dh (I + dh M / 2 + dh^2 M^2 / 6 + ...) summed to the third term; the rest is
      // below (|dh| ||M||)^3 / 24 <= kExactSeriesLimit^3 / 24 of the first.
      StateVector g(dim);
      g.noalias() = M_ * fv;
      StateVector series(dim);
      series.noalias() = dh * fv + (0.5 * dh * dh) * g;
      StateVector g2(dim);
      g2.noalias() = M_ * g;
      series.noalias() += (dh * dh * dh / 6.0) * g2;
      nv.noalias() += phi_ * series;
    }
    next += mu_;
  }
  else
  {
    next = mu_ + h * f;
  }
  if (!next.allFinite() || next.cwiseAbs().maxCoeff() > params_.runaway_limit)
  {
    return false;
  }
  mu_ = next;
  return true;
}

ActiveInferenceController::Status ActiveInferenceController::updateRobotBeliefs(double h)
{
  // The robot model's belief step (doc/active_inference.md, 'The robot model'): the model's
  // prediction over h under the command in effect at the wheels, then, with a new sample, the
  // minimiser of the free energy (RobotBelief::correct()).
  robot_clock_ += h;
  const double yaw_gain = model_.G()(2, 1);  // r alpha / b_hat
  robot_belief_.predict(h, wheel_loop_, wheel_loop_.commandAt(robot_clock_), wheel_loop_.commandRateAt(robot_clock_),
                        yaw_gain, reference_.path()(2), slowStatesMayLearn());
  if (robot_sample_pending_ && fault_suspected_)
  {
    // A fault is being tested: the sample's channels disagree beyond their noise and which one is
    // wrong is not known yet, so the beliefs follow the model until a channel is isolated.
    robot_sample_pending_ = false;
  }
  if (robot_sample_pending_)
  {
    robot_sample_pending_ = false;
    // The slow states (slip ratio, gyro offset) learn from the three channels together only (under
    // a fault mask they are held), and only while the gyro's and the believed wheels' yaw
    // accelerations are within the separation learner's gate: a turn's scrub transient, which the
    // first-order yaw model does not describe, is left to theta_dot. The wheels' common acceleration
    // is held to the same gate, counted as the yaw acceleration it would give were it one side's
    // alone (2 |x_dot'| / b_hat): while the tyres' grip goes to a speed change, the body's yaw does
    // not follow the wheels as in a steady turn.
    const base::Vector2 wheel_rates = robot_belief_.wheelAccelerations();
    const double wheels_yaw_rate = model_.G()(2, 1) * (wheel_rates(1) - wheel_rates(0));
    const double wheels_common_rate = model_.G()(2, 1) * (wheel_rates(1) + wheel_rates(0));
    const double gate = params_.separation_learner.max_yaw_acceleration;
    const bool learn = slowStatesMayLearn() && std::abs(y_tilde_(base::kGyroZ, 1)) <= gate &&
                       std::abs(wheels_yaw_rate) <= gate && std::abs(wheels_common_rate) <= gate;
    const base::Vector2 wheels(y_tilde_(base::kOmegaLeft, 0), y_tilde_(base::kOmegaRight, 0));
    // A repeated joint state is the MCU's previous reading again, one period late: read as now, in
    // a ramp it says the wheels stood still for a period, and the action would push against it.
    if (!robot_wheels_repeated_)
    {
      learnLatency(wheels);
    }
    // With the latency learned, a start from rest whose wheels have not shown it yet is read as the
    // latency not yet elapsed, not as the wheels' speed: their readings wait until the start is
    // seen or dropped (LatencyLearner's window), so the action does not push against a late plant.
    const bool wheels_unused = robot_wheels_repeated_ || (params_.robot.learn_latency && latency_learner_.armed());
    RobotBelief::SampleUse use;
    use.left = !wheels_unused && (sensor_mask_ & (1u << base::kOmegaLeft)) != 0;
    use.right = !wheels_unused && (sensor_mask_ & (1u << base::kOmegaRight)) != 0;
    use.gyro = (sensor_mask_ & (1u << base::kGyroZ)) != 0;
    use.learn = learn;
    // A gyro reading that repeats bit for bit is a frozen gyro (or an ideal one at rest): no turn's
    // slip is in it (the goal model's learner refuses it alike, SeparationLearner::State::kStuckGyro).
    use.learn_slip = y_tilde_(base::kGyroZ, 1) != 0.0;
    // The turn shortfalls learn from the three channels together, without a fault: a biased or
    // frozen encoder's reading is not its side's load.
    use.learn_turn = slowStatesMayLearn();
    robot_belief_.correct(wheels, y_tilde_(base::kGyroZ, 0), use);
  }
  if (params_.separation_learner.enabled)
  {
    learnRobotSeparation(h);
  }
  // The beliefs in the thesis's coordinates: mu^(0) = (x_dot, 0, theta_dot), mu^(1) their rates.
  base::MuTilde next = base::MuTilde::Zero(base::kMuDim, params_.numOrders());
  next(0, 0) = model_.twistFromWheels(robot_belief_.wheelSpeeds())(0);
  next(2, 0) = robot_belief_.yawRate();
  if (params_.numOrders() > 1)
  {
    next(0, 1) = model_.twistFromWheels(robot_belief_.wheelAccelerations())(0);
    next(2, 1) = robot_belief_.yawAcceleration();
  }
  if (!next.allFinite() || !(next.cwiseAbs().maxCoeff() <= params_.runaway_limit))
  {
    runawayReset();
    return Status::kRunaway;
  }
  mu_ = next;
  reference_.advance(h);
  return Status::kOk;
}

void ActiveInferenceController::learnLatency(const base::Vector2& wheels)
{
  if (!params_.robot.learn_latency)
  {
    return;
  }
  if ((sensor_mask_ & kWheelChannels) != kWheelChannels || fault_present_)
  {
    latency_learner_.disarm();  // a masked or faulty wheel's reading is not the wheels' motion
    return;
  }
  if (latency_learner_.sample(robot_clock_, wheels, wheel_loop_))
  {
    useLatency(latency_learner_.latency());
  }
}

void ActiveInferenceController::useLatency(double latency)
{
  wheel_loop_.setLatency(latency);
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    reference_.setParams(goalStageParams(params_, latency), params_.runaway_limit);
  }
}

bool ActiveInferenceController::slowStatesMayLearn() const
{
  return (sensor_mask_ & kTwistChannels) == kTwistChannels && !fault_present_;
}

void ActiveInferenceController::learnRobotSeparation(double h)
{
  // The slip ratio's steady part is the separation's error: b_hat / (1 - s) turns (1 - s) u into
  // the new b_hat's u. b_hat moves there at most separation_max_rate b_hat per second (the
  // learner's bound), and the slip ratio is re-expressed on the b_hat it reached. Only in a turn
  // (the believed wheels' |yaw rate| at least separation_min_yaw_rate, as the goal model's learner
  // is frozen near rest): in straight driving the slip ratio has nothing to act on, and a ratio
  // taken at a turn's end would otherwise move b_hat on until the next turn.
  // Nor while a channel is masked, a fault is present or suspected: the slip ratio is held then
  // (updateRobotBeliefs()), and what it took in before the isolation is the fault's.
  const double s = robot_belief_.slipRatio();
  if (!(std::abs(s) > kSeparationApplyTolerance) || !(s < 1.0) || !slowStatesMayLearn() || fault_suspected_ ||
      !(std::abs(robot_belief_.wheelsYawRate()) >= params_.separation_learner.min_yaw_rate))
  {
    return;
  }
  const double before = learner_.separation();
  double factor = 1.0 / (1.0 - s);
  if (params_.separation_learner.max_rate > 0.0)
  {
    const double step = params_.separation_learner.max_rate * h;
    factor = std::clamp(factor, 1.0 - step, 1.0 + step);
  }
  if (!learner_.setSeparation(before * factor))
  {
    return;
  }
  robot_belief_.rescaleSlip(learner_.separation() / before);
  applyLearnedSeparation(false);
}

ActiveInferenceController::Status ActiveInferenceController::updateRobotAction(double h)
{
  // The robot model's action step: the goal's path, predicted one latency ahead and bounded by
  // the wheel loop (ReferenceModel), at the end of the step the command will be held for, in
  // the wheels' coordinates of the learned model; then LatencyAction's descent of F_a.
  base::Vector2 goal = base::Vector2::Zero();
  double goal_turn = 0.0;  // the goal's yaw rate at t + L + h_a [rad/s]
  // Not while a tip bound is tripped: a stop whose path has already reached zero when the body
  // lifts (a set point dropped to zero at once, the path down at the wheel loop's rate one latency
  // ahead of the wheels) would otherwise go on braking at the MCU's full deceleration through the
  // lift; the held path below asks for the speed the body has instead.
  const bool at_rest = !reference_.tipTripped() && reference_.target().isZero(0.0) &&
                       reference_.path().cwiseAbs().maxCoeff() <= kRobotRestPath;
  if (!at_rest)
  {
    // The tip guard's trip stops the wheels' braking (or acceleration) where they are now, not at
    // the path's value one latency ahead (ReferenceModel::holdTipSpeed()).
    reference_.holdTipSpeed(model_.twistFromWheels(robot_belief_.wheelSpeeds())(0));  // x_dot
    const base::Vector3 path = reference_.pathAhead(h);
    goal_turn = path(2);
    // The wheels through the learned b_hat (the slip ratio's steady part reaches the command
    // through b_hat, at the learner's rate: a transient's slip does not).
    const base::SensorMatrix& R = model_.R();
    goal << R.row(base::kOmegaLeft).dot(path), R.row(base::kOmegaRight).dot(path);
  }
  const double pi_e = 1.0 / (params_.robot.encoder_noise * params_.robot.encoder_noise);
  // At rest the command is zero: the MCU holds the wheels, there is no shortfall to make up.
  // The shortfall at the goal's turn the command is for (the turn's part: RobotBelief::shortfallsAt()).
  // None of it on a saturated or stalled side (RobotBelief::compensableShortfallsAt()).
  base::Vector2 shortfall = at_rest ? base::Vector2::Zero() : robot_belief_.compensableShortfallsAt(goal_turn);
  // In an arc, the speed's part only where the wheels are short of the goal's speed
  // (LatencyAction::inArc()); not while a side is stalled or saturated, whose zero stays zero.
  if (!at_rest && !robot_belief_.anySideHeld() && std::abs(goal_turn) > RobotBelief::kStraightTurn)
  {
    shortfall = LatencyAction::inArc(shortfall, goal, robot_belief_.wheelSpeeds());
  }
  // A stalled side's command stays within one kick of the goal's wheel speed: a held wheel that
  // does not answer the MCU's feed-forward would otherwise be asked for one more kick every latency. A
  // saturated side's speed does not depend on its command (F_a is flat in it): it is commanded
  // the goal's wheel speed, which leaves nothing to overrun when it frees.
  base::Vector2 reach = base::Vector2::Constant(std::numeric_limits<double>::infinity());
  for (int s = 0; s < 2; ++s)
  {
    if (robot_belief_.stalled(s))
    {
      reach(s) = wheel_loop_.kickRange(h);
    }
    if (robot_belief_.saturated(s))
    {
      reach(s) = 0.0;
    }
  }
  // Made up only as far as the MCU's proportional path answers (shortfall_compensation_limit).
  const LatencyActionResult r =
      LatencyAction::step(wheel_loop_, robot_belief_.wheelSpeeds(),
                          LatencyAction::compensated(shortfall, params_.robot.shortfall_compensation_limit),
                          robot_clock_, goal, a_, h, params_.robot.action_gain, params_.max_wheel_speed, pi_e, reach);
  if (!r.command.allFinite())
  {
    runawayReset();
    return Status::kRunaway;
  }
  const base::Vector2 previous = a_;
  // The slew limit (action_slew_limit, a bound the user sets) acts on what is sent; the wheel loop
  // model records the limited command, so the next step's prediction knows it.
  a_ = slew_limit_.limit(previous, at_rest ? base::Vector2::Zero() : r.command, h);
  a_F_ = a_;
  action_free_energy_ = r.free_energy;
  action_saturated_ = r.minimiser.cwiseAbs().maxCoeff() >= params_.max_wheel_speed;
  wheel_loop_.record(robot_clock_, a_);
  if (params_.robot.learn_latency)
  {
    const double rest = LatencyLearner::kOnsetSigmas * params_.robot.encoder_noise;
    latency_learner_.commandSent(robot_clock_, a_, previous, robot_belief_.wheelSpeeds().cwiseAbs().maxCoeff() <= rest);
  }
  return Status::kOk;
}

void ActiveInferenceController::learnPrecision(double h)
{
  precision_learner_.update(h, epsYOrder(mu_, y_tilde_, 0), y_tilde_(base::kOmegaLeft, 0),
                            y_tilde_(base::kOmegaRight, 0), sensor_mask_, action_saturated_);
  if (precision_learner_.changedSince(PrecisionLearner::kApplyTolerance))
  {
    rebuildDynamics();
  }
}

void ActiveInferenceController::learn(double h)
{
  learner_.update(h, y_tilde_(base::kGyroZ, 0), y_tilde_(base::kGyroZ, 1), y_tilde_(base::kOmegaLeft, 0),
                  y_tilde_(base::kOmegaRight, 0), y_tilde_(base::kOmegaLeft, 1), y_tilde_(base::kOmegaRight, 1),
                  pi_y_(base::kGyroZ, 0), (sensor_mask_ & kTwistChannels) == kTwistChannels, action_saturated_);
  applyLearnedSeparation(false);
}

ActiveInferenceController::Status ActiveInferenceController::updateAction(double h)
{
  if (!validStep(h))
  {
    return Status::kBadInterval;
  }
  if (!has_measurement_)
  {
    return Status::kNoMeasurement;
  }
  if (turned_over_)
  {
    stopTurnedOver(h);
    return Status::kOk;
  }
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    return updateRobotAction(h);
  }
  // The action step's stages, in order (control_loop.hpp, 'The controller's composition').
  // RestRelease, before the step's integration (a no-op with action_release_time 0).
  a_F_ = release_.apply(a_F_, reference_.target(), h);
  // da_F/dt does not depend on a, so with beliefs and measurement held over the step the
  // Euler step is also the exact one. a = a_F + a_ff.
  const base::Vector2 a_dot = aDot();         // eq. 3-16 (unbiased: the goal prior on GoalResponse's g)
  const base::Vector2 prior = actionPrior();  // ActionPrior
  const base::Vector2 increment = h * a_dot;
  const base::Vector2 candidate = a_F_ + increment;
  const base::Vector2 raw = candidate + prior;
  // A diverging action is never clamped and sent: a non-finite command, or one step that moves
  // a wheel's command by more than the whole range of wheel speeds (2 max_wheel_speed), resets
  // (zero action) here, before the command leaves. The belief update's runaway_limit catches
  // diverging beliefs only once they exceed it; on the way there (an Euler-unstable
  // belief update grows ~6x per step) the action step can read beliefs a hundred times the
  // robot's speed, whose action the wheel clamp would turn into +-max_wheel_speed.
  if (!raw.allFinite() || !(increment.cwiseAbs().maxCoeff() <= 2.0 * params_.max_wheel_speed))
  {
    runawayReset();
    return Status::kRunaway;
  }
  // AntiWindup: the clamps and conditional integration of a_F (a masked, isolated, wheel channel is not trusted).
  const base::Vector2 omega(y_tilde_(base::kOmegaLeft, 0), y_tilde_(base::kOmegaRight, 0));
  const AntiWindup::Result clamped =
      anti_windup_.apply(a_F_, candidate, a_dot, prior, omega, (sensor_mask_ & (1u << base::kOmegaLeft)) != 0,
                         (sensor_mask_ & (1u << base::kOmegaRight)) != 0);
  // ActionSlewLimit: the command's change since the previous step bounded, a_F integrated behind it.
  const ActionSlewLimit::Result slewed =
      slew_limit_.apply(a_, clamped.command, a_F_, clamped.free_energy_part, a_dot, prior, h);
  a_F_ = slewed.free_energy_part;
  // Saturation: the wheel-speed limit cut the command (the lead limits are anti-windup, not saturation).
  action_saturated_ = clamped.saturated;
  a_ = slewed.command;
  if (params_.belief_model == params::BeliefModel::kUnbiased)
  {
    action_line_.record(h, model_.twistFromWheels(a_));  // ActionDelayLine
  }
  return Status::kOk;
}

void ActiveInferenceController::stopTurnedOver(double h)
{
  // No wheel command rolls a turned-over body back, and the wheels of a robot on its back spin
  // free: a path held at the speed they report (ReferenceModel::holdTipSpeed()) would hold them
  // spinning. Nothing of the path held before is sent once the body is level again.
  a_.setZero();
  a_F_.setZero();
  action_saturated_ = false;
  action_free_energy_ = 0.0;
  startReference(base::Vector3::Zero());
  if (params_.belief_model == params::BeliefModel::kRobot)
  {
    wheel_loop_.record(robot_clock_, a_);
  }
  else if (params_.belief_model == params::BeliefModel::kUnbiased)
  {
    action_line_.record(h, model_.twistFromWheels(a_));
  }
}

void ActiveInferenceController::runawayReset()
{
  mu_.setZero();
  a_.setZero();
  a_F_.setZero();
  action_line_.reset(model_.twistFromWheels(a_));
  wheel_loop_.reset(robot_clock_, a_);
  robot_belief_.reset(base::Vector2::Zero(), 0.0);
  startReference(base::Vector3::Zero());
  ++runaway_count_;
}

void ActiveInferenceController::reset()
{
  mu_.setZero();
  a_.setZero();
  a_F_.setZero();
  action_line_.reset(model_.twistFromWheels(a_));
  wheel_loop_.reset(robot_clock_, a_);
  robot_belief_.reset(base::Vector2::Zero(), 0.0);
  y_tilde_.setZero();
  has_measurement_ = false;
  robot_sample_pending_ = false;
  robot_wheels_repeated_ = false;
  startReference(base::Vector3::Zero());
}

void ActiveInferenceController::setAction(const base::Vector2& a)
{
  if (!a.allFinite())
  {
    return;
  }
  a_ = anti_windup_.limitWheelSpeed(a);
  a_F_ = a_ - actionPrior();  // bumpless: the free-energy part takes the difference
  action_line_.restart(
      model_.twistFromWheels(a_));      // the unbiased prior expects the response to this action from now on
  wheel_loop_.reset(robot_clock_, a_);  // the robot model: this command is the one in flight
}

const char* toString(ActiveInferenceController::Status status)
{
  switch (status)
  {
    case ActiveInferenceController::Status::kOk:
      return "ok";
    case ActiveInferenceController::Status::kNoMeasurement:
      return "no measurement";
    case ActiveInferenceController::Status::kBadInterval:
      return "bad interval";
    case ActiveInferenceController::Status::kRunaway:
      return "runaway";
  }
  return "unknown";
}

}  // namespace aic
}  // namespace jackal_aic
