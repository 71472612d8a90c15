/**
 * \file controller.cpp
 * \brief Active inference controller (thesis eq. 3-6 ... 3-16; Pezzato et al. 2020; doc/active_inference.md,
 *        'Prediction errors and free energy' to 'Integrators').
 */
#include "jackal_aic/controller.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <unsupported/Eigen/MatrixFunctions>

namespace jackal_aic
{
namespace
{
std::string joinViolations(const std::vector<ParamViolation>& violations)
{
  std::string msg = "invalid AicParams:";
  for (const auto& v : violations)
  {
    msg += " " + v.toString() + ";";
  }
  return msg;
}

/// Returns params if valid, throws std::invalid_argument listing every violation otherwise.
const AicParams& checked(const AicParams& params)
{
  const auto violations = params.validate();
  if (!violations.empty())
  {
    throw std::invalid_argument(joinViolations(violations));
  }
  return params;
}

bool finiteStep(double h)
{
  return std::isfinite(h) && h > 0.0;
}
}  // namespace

ActiveInferenceController::ActiveInferenceController(const AicParams& params)
  : params_(checked(params)), model_(params.wheel_radius, params.slip_factor, params.wheel_separation)
{
  const int n = params.numOrders();
  mu_.setZero(kMuDim, n);
  y_tilde_.setZero(kYDim, n);
  applyParams(params);
}

void ActiveInferenceController::setParams(const AicParams& params)
{
  checked(params);
  const bool order_changed = params.embedding_order != params_.embedding_order;
  applyParams(params);
  // A lower max_wheel_speed applies to the action held now, not only from the next action step
  // (found by test/fuzz/fuzz_core.cpp).
  a_ = a_.cwiseMax(-params.max_wheel_speed).cwiseMin(params.max_wheel_speed);
  if (order_changed)
  {
    const int n = params.numOrders();
    mu_.setZero(kMuDim, n);
    y_tilde_.setZero(kYDim, n);
    a_.setZero();
    has_measurement_ = false;
  }
}

void ActiveInferenceController::applyParams(const AicParams& params)
{
  params_ = params;
  model_ = SkidSteerModel(params.wheel_radius, params.slip_factor, params.wheel_separation);
  pi_mu_ = params.precisionMu();
  rebuildDynamics();
}

void ActiveInferenceController::setSensorMask(std::uint8_t mask)
{
  mask &= static_cast<std::uint8_t>((1u << kYDim) - 1u);
  if (mask == sensor_mask_)
  {
    return;
  }
  sensor_mask_ = mask;
  rebuildDynamics();
}

void ActiveInferenceController::rebuildDynamics()
{
  const AicParams& params = params_;
  pi_y_ = params.precisionY();
  for (int j = 0; j < kYDim; ++j)
  {
    if ((sensor_mask_ & (1u << j)) == 0)
    {
      pi_y_.row(j).setZero();
    }
  }

  // The belief dynamics are affine in mu_tilde: dmu/dt = M vec(mu) + (terms in y_tilde, mu_d).
  // Column j of M is dmu/dt at mu = e_j with y_tilde = 0 and mu_d = 0.
  const int n = params.numOrders();
  const int dim = kMuDim * n;
  M_.setZero(dim, dim);
  MuTilde e(kMuDim, n);
  MuTilde f(kMuDim, n);
  YTilde y0 = YTilde::Zero(kYDim, n);
  const Vector3 zero3 = Vector3::Zero();
  for (int j = 0; j < dim; ++j)
  {
    e.setZero();
    e.data()[j] = 1.0;
    computeMuDot(e, y0, zero3, &f);
    M_.col(j) = Eigen::Map<const Eigen::VectorXd>(f.data(), dim);
  }
  m_norm_ = M_.cwiseAbs().rowwise().sum().maxCoeff();  // ||M||_inf [1/s]
  phi_.setZero(dim, dim);
  psi_.setZero(dim, dim);
  exact_h_ = 0.0;
}

bool ActiveInferenceController::setGoal(const Vector3& mu_d)
{
  if (!mu_d.allFinite() || mu_d.cwiseAbs().maxCoeff() > params_.runaway_limit)
  {
    return false;
  }
  mu_d_ = mu_d;
  return true;
}

bool ActiveInferenceController::setMeasurement(const YTilde& y_tilde)
{
  if (y_tilde.cols() != params_.numOrders() || !y_tilde.allFinite() ||
      y_tilde.cwiseAbs().maxCoeff() > kMaxMeasurementMagnitude)
  {
    return false;
  }
  y_tilde_ = y_tilde;
  has_measurement_ = true;
  return true;
}

bool ActiveInferenceController::setBeliefs(const MuTilde& mu)
{
  if (mu.cols() != params_.numOrders() || !mu.allFinite() || mu.cwiseAbs().maxCoeff() > params_.runaway_limit)
  {
    return false;
  }
  mu_ = mu;
  return true;
}

void ActiveInferenceController::computeEpsY(const MuTilde& mu, const YTilde& y_tilde, YTilde* eps_y) const
{
  const int n = params_.numOrders();
  const SensorMatrix& R = model_.R();
  for (int i = 0; i < n; ++i)
  {
    eps_y->col(i).noalias() = y_tilde.col(i) - R * mu.col(i);
    if (params_.accel_in_model && i + 1 < n)
    {
      // Optional kinematic accelerometer row: accel_x^(i) predicted by x_dot^(i+1).
      (*eps_y)(kAccelX, i) -= mu(0, i + 1);
    }
  }
}

void ActiveInferenceController::computeEpsMu(const MuTilde& mu, const Vector3& mu_d, MuTilde* eps_mu) const
{
  const int n = params_.numOrders();
  const double inv_tau = 1.0 / params_.tau;
  // eps_mu^(0) = mu^(1) - (mu_d - mu^(0)) / tau; eps_mu^(i) = mu^(i+1) + mu^(i) / tau, mu^(p+1) = 0.
  eps_mu->col(0) = mu.col(1) - (mu_d - mu.col(0)) * inv_tau;
  for (int i = 1; i < n; ++i)
  {
    eps_mu->col(i) = mu.col(i) * inv_tau;
    if (i + 1 < n)
    {
      eps_mu->col(i) += mu.col(i + 1);
    }
  }
}

void ActiveInferenceController::computeDfDmu(const MuTilde& mu, const YTilde& y_tilde, const Vector3& mu_d,
                                            MuTilde* grad) const
{
  const int n = params_.numOrders();
  const double inv_tau = 1.0 / params_.tau;
  YTilde wy(kYDim, n);   // Pi_y eps_y
  MuTilde wm(kMuDim, n); // Pi_mu eps_mu
  computeEpsY(mu, y_tilde, &wy);
  computeEpsMu(mu, mu_d, &wm);
  wy.array() *= pi_y_.array();
  wm.array() *= pi_mu_.array();
  const SensorMatrix& R = model_.R();
  for (int i = 0; i < n; ++i)
  {
    grad->col(i).noalias() = -R.transpose() * wy.col(i);
    grad->col(i) += inv_tau * wm.col(i);
    if (i >= 1)
    {
      grad->col(i) += wm.col(i - 1);
      if (params_.accel_in_model)
      {
        (*grad)(0, i) -= wy(kAccelX, i - 1);
      }
    }
  }
}

void ActiveInferenceController::computeMuDot(const MuTilde& mu, const YTilde& y_tilde, const Vector3& mu_d,
                                            MuTilde* mu_dot) const
{
  const int n = params_.numOrders();
  computeDfDmu(mu, y_tilde, mu_d, mu_dot);
  *mu_dot *= -params_.k_mu;
  // Shift operator D: (D mu)^(i) = mu^(i+1), (D mu)^(p) = 0.
  mu_dot->leftCols(n - 1) += mu.rightCols(n - 1);
}

YTilde ActiveInferenceController::epsY() const
{
  YTilde e(kYDim, params_.numOrders());
  computeEpsY(mu_, y_tilde_, &e);
  return e;
}

MuTilde ActiveInferenceController::epsMu() const
{
  MuTilde e(kMuDim, params_.numOrders());
  computeEpsMu(mu_, mu_d_, &e);
  return e;
}

double ActiveInferenceController::freeEnergy() const
{
  const YTilde ey = epsY();
  const MuTilde em = epsMu();
  return 0.5 * ((ey.array().square() * pi_y_.array()).sum() + (em.array().square() * pi_mu_.array()).sum());
}

MuTilde ActiveInferenceController::dFdMu() const
{
  MuTilde g(kMuDim, params_.numOrders());
  computeDfDmu(mu_, y_tilde_, mu_d_, &g);
  return g;
}

MuTilde ActiveInferenceController::muDot() const
{
  MuTilde d(kMuDim, params_.numOrders());
  computeMuDot(mu_, y_tilde_, mu_d_, &d);
  return d;
}

Vector2 ActiveInferenceController::aDot() const
{
  const int n = params_.numOrders();
  YTilde ey(kYDim, n);
  computeEpsY(mu_, y_tilde_, &ey);
  ey.array() *= pi_y_.array();
  // da/dt = -k_a sum_i K Pi_y^(i) eps_y^(i)
  const Vector5 sum = ey.rowwise().sum();
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
  if (!finiteStep(h))
  {
    return Status::kBadInterval;
  }
  if (!has_measurement_)
  {
    return Status::kNoMeasurement;
  }
  const int n = params_.numOrders();
  MuTilde f(kMuDim, n);
  computeMuDot(mu_, y_tilde_, mu_d_, &f);
  MuTilde next(kMuDim, n);
  if (params_.integrator == Integrator::kExact)
  {
    if (exact_h_ <= 0.0 || std::abs(h - exact_h_) * m_norm_ > kExactSeriesLimit)
    {
      computeExactStep(h);
    }
    const int dim = kMuDim * n;
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
    runawayReset();
    return Status::kRunaway;
  }
  mu_ = next;
  return Status::kOk;
}

ActiveInferenceController::Status ActiveInferenceController::updateAction(double h)
{
  if (!finiteStep(h))
  {
    return Status::kBadInterval;
  }
  if (!has_measurement_)
  {
    return Status::kNoMeasurement;
  }
  // da/dt does not depend on a, so with beliefs and measurement held over the step the
  // Euler step is also the exact one.
  const Vector2 next = a_ + h * aDot();
  if (!next.allFinite())
  {
    runawayReset();
    return Status::kRunaway;
  }
  Vector2 a = next;
  if (params_.max_action_lead > 0.0)
  {
    // Conditional integration: the action may lead the measured wheel speeds by at most
    // max_action_lead, so it cannot wind up while the wheel loop saturates.
    // A masked (isolated) wheel channel is not trusted, so it does not bound its command.
    const Vector2 omega(y_tilde_(kOmegaLeft, 0), y_tilde_(kOmegaRight, 0));
    const Vector2 lead = Vector2::Constant(params_.max_action_lead);
    const Vector2 bounded = a.cwiseMax(omega - lead).cwiseMin(omega + lead);
    if ((sensor_mask_ & (1u << kOmegaLeft)) != 0)
    {
      a(0) = bounded(0);
    }
    if ((sensor_mask_ & (1u << kOmegaRight)) != 0)
    {
      a(1) = bounded(1);
    }
  }
  const std::uint8_t wheels = (1u << kOmegaLeft) | (1u << kOmegaRight);
  if (params_.max_action_lead_turn > 0.0 && (sensor_mask_ & wheels) == wheels)
  {
    // Differential (turning) lead bounded, common lead kept: e_L = c - d, e_R = c + d.
    // Both wheel channels must be trusted: the lead is measured against them.
    const Vector2 omega(y_tilde_(kOmegaLeft, 0), y_tilde_(kOmegaRight, 0));
    const double e_left = a(0) - omega(0);
    const double e_right = a(1) - omega(1);
    const double c = 0.5 * (e_left + e_right);
    const double d = std::clamp(0.5 * (e_right - e_left), -params_.max_action_lead_turn, params_.max_action_lead_turn);
    a = Vector2(omega(0) + c - d, omega(1) + c + d);
  }
  const double lim = params_.max_wheel_speed;  // applied last: the wheel clamp always wins
  a_ = a.cwiseMax(-lim).cwiseMin(lim);
  return Status::kOk;
}

void ActiveInferenceController::runawayReset()
{
  mu_.setZero();
  a_.setZero();
  ++runaway_count_;
}

void ActiveInferenceController::reset()
{
  mu_.setZero();
  a_.setZero();
  y_tilde_.setZero();
  has_measurement_ = false;
}

void ActiveInferenceController::setAction(const Vector2& a)
{
  if (!a.allFinite())
  {
    return;
  }
  const double lim = params_.max_wheel_speed;
  a_ = a.cwiseMax(-lim).cwiseMin(lim);
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

}  // namespace jackal_aic
