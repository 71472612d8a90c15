/**
 * \file state_space.cpp
 * \brief Dual-rate linear closed-loop model (thesis ch. 4, appendix A;
 *        doc/active_inference.md, 'State-space model for analysis').
 */
#include "jackal_aic/analysis/state_space.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/generalizer.hpp"

namespace jackal_aic
{
namespace analysis
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

ClosedLoopModel::ClosedLoopModel(const params::AicParams& params, const PlantModel& plant)
  : params_(params), plant_(plant)
{
  aic::ActiveInferenceController c(params);  // validates
  if (params.belief_model != params::BeliefModel::kGoal)
  {
    // The probe below reads the goal model's belief and action dynamics whatever the setting: the
    // unbiased prior on the delayed action and the robot model's filter and latency action are
    // not in them, so the figures would be another model's.
    throw std::invalid_argument("ClosedLoopModel: belief_model " + params::toString(params.belief_model) +
                                " is not represented (the linear model is belief_model goal's, the thesis's)");
  }
  {
    // Probe with unit vectors: the runaway limit (not modelled) must not reject them. The
    // set-point dynamics and the action prior are not modelled either (the thesis's controller).
    params::AicParams probe_params = params;
    probe_params.runaway_limit = params::kMaxRunawayLimit;
    probe_params.reference.generalized_goal = false;
    probe_params.reference.time_constant = 0.0;
    probe_params.action_prior.gain = 0.0;
    c.setParams(probe_params);
  }
  if (plant.type == PlantModel::Type::kFirstOrder && !(std::isfinite(plant.time_constant) && plant.time_constant > 0.0))
  {
    throw std::invalid_argument("ClosedLoopModel: plant time_constant = " + std::to_string(plant.time_constant) +
                                " (allowed: > 0 and finite)");
  }
  if (!(std::isfinite(plant.gain) && plant.gain > 0.0))
  {
    throw std::invalid_argument("ClosedLoopModel: plant gain = " + std::to_string(plant.gain) +
                                " (allowed: > 0 and finite)");
  }
  if (!(std::isfinite(plant.delay) && plant.delay >= 0.0 && plant.delay <= 50.0 / params.action_rate))
  {
    throw std::invalid_argument("ClosedLoopModel: plant delay = " + std::to_string(plant.delay) +
                                " s (allowed: 0 ... 50 action periods)");
  }
  const double ratio = params.belief_rate / params.action_rate;
  n_belief_steps_ = static_cast<int>(std::lround(ratio));
  if (std::abs(ratio - n_belief_steps_) > 1e-9 * ratio)
  {
    throw std::invalid_argument("ClosedLoopModel: belief_rate / action_rate = " + std::to_string(ratio) +
                                " must be an integer for the dual-rate model");
  }
  const int n = params.numOrders();
  const int nm = base::kMuDim * n;
  const int ny = base::kYDim * n;

  // Probe the controller's (affine, here linear) dynamics with unit vectors.
  m_.setZero(nm, nm);
  n_y_.setZero(nm, ny);
  n_d_.setZero(nm, base::kMuDim);
  a_mu_.setZero(base::kADim, nm);
  a_y_.setZero(base::kADim, ny);
  const base::MuTilde mu0 = base::MuTilde::Zero(base::kMuDim, n);
  const base::YTilde y0 = base::YTilde::Zero(base::kYDim, n);
  auto probe = [&](const base::MuTilde& mu, const base::YTilde& y, const base::Vector3& d,
                   Eigen::Ref<Eigen::VectorXd> dmu, Eigen::Ref<Eigen::VectorXd> da) {
    if (!c.setBeliefs(mu) || !c.setMeasurement(y) || !c.setGoal(d))
    {
      throw std::logic_error("ClosedLoopModel: probing the controller failed");
    }
    const base::MuTilde f = c.muDot();
    dmu = Eigen::Map<const Eigen::VectorXd>(f.data(), nm);
    da = c.aDot();
  };
  Eigen::VectorXd scratch(base::kADim);
  for (int j = 0; j < nm; ++j)
  {
    base::MuTilde e = mu0;
    e.data()[j] = 1.0;
    probe(e, y0, base::Vector3::Zero(), m_.col(j), a_mu_.col(j));
  }
  for (int j = 0; j < ny; ++j)
  {
    base::YTilde e = y0;
    e.data()[j] = 1.0;
    probe(mu0, e, base::Vector3::Zero(), n_y_.col(j), a_y_.col(j));
  }
  for (int j = 0; j < base::kMuDim; ++j)
  {
    probe(mu0, y0, base::Vector3::Unit(j), n_d_.col(j), scratch);
    if (!scratch.isZero(0.0))
    {
      throw std::logic_error("ClosedLoopModel: da/dt depends on mu_d (not the thesis model)");
    }
  }

  // One belief step: mu' = Ab mu + Bb [y; mu_d].
  const double h = 1.0 / params.belief_rate;
  Eigen::MatrixXd nin(nm, ny + base::kMuDim);
  nin << n_y_, n_d_;
  Eigen::MatrixXd ab;
  Eigen::MatrixXd bb;
  if (params.integrator == params::Integrator::kExact)
  {
    Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(2 * nm, 2 * nm);
    aug.topLeftCorner(nm, nm) = m_ * h;
    aug.topRightCorner(nm, nm) = Eigen::MatrixXd::Identity(nm, nm) * h;
    const Eigen::MatrixXd ex = aug.exp();
    ab = ex.topLeftCorner(nm, nm);
    bb = ex.topRightCorner(nm, nm) * nin;
  }
  else
  {
    ab = Eigen::MatrixXd::Identity(nm, nm) + h * m_;
    bb = h * nin;
  }
  // N belief steps with the input held: mu' = Ab^N mu + (sum_k Ab^k) Bb u.
  Eigen::MatrixXd abn = Eigen::MatrixXd::Identity(nm, nm);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(nm, nm);
  for (int k = 0; k < n_belief_steps_; ++k)
  {
    sum += abn;
    abn = ab * abn;
  }
  const Eigen::MatrixXd bbn = sum * bb;  // nm x (ny + 3)

  // Delay d = (m + f) T, 0 <= f < 1: over period k the plant gets a_{k-m-1} for f T, then a_{k-m}.
  const double T = 1.0 / params.action_rate;
  const double periods_delay = plant.delay / T;
  int m_delay = static_cast<int>(std::floor(periods_delay + 1e-9));
  double f_delay = periods_delay - m_delay;
  if (f_delay < 1e-9)
  {
    f_delay = 0.0;
  }
  const int n_hist = m_delay + (f_delay > 0.0 ? 1 : 0);  // past commands kept: a_{k-1} ... a_{k-L}

  // State layout.
  const int i_mu = 0;
  const int i_a = nm;
  const int i_y = nm + base::kADim;
  const int i_w = nm + base::kADim + ny;
  const int i_h = i_w + base::kADim;  // past command j (1-based) at i_h + 2 (j - 1)
  const int dim = i_h + base::kADim * n_hist;
  i_w_ = i_w;
  // Index in z (after stage 3) of the command a_{k-j}: j = 0 is a, j >= 1 the history.
  auto command_index = [&](int j) { return j == 0 ? i_a : i_h + base::kADim * (j - 1); };
  const aic::SkidSteerModel& model = c.model();

  // Each stage is an affine map of the full state [z; mu_d]; compose them.
  const int da = dim + base::kMuDim;
  auto identity = [&]() { return Eigen::MatrixXd(Eigen::MatrixXd::Identity(da, da)); };

  // Stage 1: sensor sample + generalization. y^(0) = S_w omega + S_a a.
  Eigen::MatrixXd s1 = identity();
  {
    Eigen::MatrixXd sw = Eigen::MatrixXd::Zero(base::kYDim, base::kADim);
    Eigen::MatrixXd sa = Eigen::MatrixXd::Zero(base::kYDim, base::kADim);
    sw.row(base::kGyroZ) = model.G().row(2);
    sw(base::kOmegaLeft, 0) = 1.0;
    sw(base::kOmegaRight, 1) = 1.0;
    // The command in effect at the end of the last period (a_{k-m}, with a the newest).
    const int i_u = command_index(m_delay);
    if (plant.type == PlantModel::Type::kFirstOrder)
    {
      // accel_x = G_1 d(omega)/dt = G_1 (K u - omega) / T_p
      sa.row(base::kAccelX) = plant.gain * model.G().row(0) / plant.time_constant;
      sw.row(base::kAccelX) = -model.G().row(0) / plant.time_constant;
    }
    const Eigen::MatrixXd q = aic::Generalizer::buildQ(params.embedding_order, T);
    // y_new^(i) (per channel) = q(i,0) y^(0) + sum_{j>=1} q(i,j) y_old^(j-1)
    s1.block(i_y, 0, ny, da).setZero();
    for (int i = 0; i < n; ++i)
    {
      const int row = i_y + base::kYDim * i;
      s1.block(row, i_w, base::kYDim, base::kADim) += q(i, 0) * sw;
      s1.block(row, i_u, base::kYDim, base::kADim) += q(i, 0) * sa;
      for (int j = 1; j <= i; ++j)
      {
        s1.block(row, i_y + base::kYDim * (j - 1), base::kYDim, base::kYDim) +=
            q(i, j) * Eigen::MatrixXd::Identity(base::kYDim, base::kYDim);
      }
    }
  }
  // Stage 2: N belief steps.
  Eigen::MatrixXd s2 = identity();
  s2.block(i_mu, i_mu, nm, nm) = abn;
  s2.block(i_mu, i_y, nm, ny) = bbn.leftCols(ny);
  s2.block(i_mu, dim, nm, base::kMuDim) = bbn.rightCols(base::kMuDim);
  // Stage 3: shift the past commands (a_{k-1} into slot 1), then the action step a += T (a_mu mu + a_y y).
  Eigen::MatrixXd s3shift = identity();
  for (int j = n_hist; j >= 1; --j)
  {
    const int dst = command_index(j);
    const int src = j == 1 ? i_a : command_index(j - 1);
    s3shift.block(dst, 0, base::kADim, da).setZero();
    s3shift.block(dst, src, base::kADim, base::kADim) = Eigen::MatrixXd::Identity(base::kADim, base::kADim);
  }
  Eigen::MatrixXd s3 = identity();
  s3.block(i_a, i_mu, base::kADim, nm) += T * a_mu_;
  s3.block(i_a, i_y, base::kADim, ny) += T * a_y_;
  s3 = s3 * s3shift;
  // Stage 4: plant over T: a_{k-m-1} for f T (f > 0), then a_{k-m} for (1 - f) T.
  Eigen::MatrixXd s4 = identity();
  s4.block(i_w, 0, base::kADim, da).setZero();
  const Eigen::MatrixXd eye2 = Eigen::MatrixXd::Identity(base::kADim, base::kADim);
  const int i_late = command_index(m_delay);                            // a_{k-m}
  const int i_early = f_delay > 0.0 ? command_index(m_delay + 1) : -1;  // a_{k-m-1}
  if (plant.type == PlantModel::Type::kFirstOrder)
  {
    const double e1 = std::exp(-f_delay * T / plant.time_constant);
    const double e2 = std::exp(-(1.0 - f_delay) * T / plant.time_constant);
    s4.block(i_w, i_w, base::kADim, base::kADim) = e1 * e2 * eye2;
    if (i_early >= 0)
    {
      s4.block(i_w, i_early, base::kADim, base::kADim) += e2 * (1.0 - e1) * plant.gain * eye2;
    }
    s4.block(i_w, i_late, base::kADim, base::kADim) += (1.0 - e2) * plant.gain * eye2;
  }
  else
  {
    s4.block(i_w, i_late, base::kADim, base::kADim) = plant.gain * eye2;
  }
  const Eigen::MatrixXd full = s4 * s3 * s2 * s1;
  phi_ = full.topLeftCorner(dim, dim);
  gamma_ = full.topRightCorner(dim, base::kMuDim);
}

double ClosedLoopModel::spectralRadius() const
{
  const Eigen::EigenSolver<Eigen::MatrixXd> es(phi_, false);
  if (es.info() != Eigen::Success)
  {
    return std::numeric_limits<double>::infinity();
  }
  return es.eigenvalues().cwiseAbs().maxCoeff();
}

std::vector<ResponseSample> ClosedLoopModel::stepResponse(const base::Vector3& mu_d, double duration) const
{
  if (!(std::isfinite(duration) && duration > 0.0) || !mu_d.allFinite())
  {
    throw std::invalid_argument("ClosedLoopModel::stepResponse: duration must be > 0 and mu_d finite");
  }
  const double T = 1.0 / params_.action_rate;
  const int nm = base::kMuDim * params_.numOrders();
  const int i_w = i_w_;
  const int periods = static_cast<int>(std::floor(duration / T + 1e-9));
  std::vector<ResponseSample> out;
  out.reserve(static_cast<std::size_t>(periods) + 1);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(stateDim());
  const aic::SkidSteerModel model(params_.wheel_radius, params_.slip_factor, params_.wheel_separation);
  for (int k = 0; k <= periods; ++k)
  {
    ResponseSample s;
    s.t = k * T;
    const base::Vector2 w = z.segment<base::kADim>(i_w);
    s.twist = model.twistFromWheels(w);
    s.mu = z.head<base::kMuDim>();
    s.a = z.segment<base::kADim>(nm);
    out.push_back(s);
    z = phi_ * z + gamma_ * mu_d;
  }
  return out;
}

PredictedStep predictStep(const params::AicParams& params, const PlantModel& plant, double target, double duration)
{
  const ClosedLoopModel model(params, plant);
  PredictedStep p{};
  p.spectral_radius = model.spectralRadius();
  p.stable = p.spectral_radius < 1.0;
  p.velocity_valid = false;
  p.velocity = StepMetrics{ kNaN, kNaN, kNaN, kNaN, false, kNaN, kNaN, kNaN, kNaN, 0 };
  const auto r = model.stepResponse(base::Vector3(target, 0.0, 0.0), duration);
  std::vector<double> t;
  std::vector<double> v;
  for (const auto& s : r)
  {
    t.push_back(s.t);
    v.push_back(s.twist(0));
  }
  StepMetricsOptions o;
  o.initial = 0.0;
  o.target = target;
  try
  {
    p.velocity = computeStepMetrics(t, v, o);
    p.velocity_valid = true;
  }
  catch (const std::invalid_argument&)
  {
    // Diverged to a non-finite response: metrics undefined.
  }
  return p;
}

namespace
{
double* member(params::AicParams* p, ScanParameter s)
{
  switch (s)
  {
    case ScanParameter::kTau:
      return &p->tau;
    case ScanParameter::kKMu:
      return &p->k_mu;
    case ScanParameter::kKA:
      return &p->k_a;
  }
  return nullptr;
}
}  // namespace

StabilityLimit scanStabilityLimit(const params::AicParams& params, const PlantModel& plant, ScanParameter parameter,
                                  double lo, double hi, int grid_points)
{
  if (!(std::isfinite(lo) && std::isfinite(hi) && lo > 0.0 && hi > lo) || grid_points < 2)
  {
    throw std::invalid_argument("scanStabilityLimit: need 0 < lo < hi, finite, and grid_points >= 2");
  }
  params::AicParams p = params;
  double* x = member(&p, parameter);
  auto stable_at = [&](double value) {
    *x = value;
    if (!p.validate().empty())
    {
      return false;
    }
    return ClosedLoopModel(p, plant).stable();
  };
  // Walk from the stable end: tau is stable when large, the gains when small.
  const bool from_hi = parameter == ScanParameter::kTau;
  const double llo = std::log(lo);
  const double lhi = std::log(hi);
  auto grid = [&](int i) {
    const double f = static_cast<double>(i) / (grid_points - 1);
    return std::exp(from_hi ? lhi - f * (lhi - llo) : llo + f * (lhi - llo));
  };
  int first_stable = -1;
  for (int i = 0; i < grid_points && first_stable < 0; ++i)
  {
    if (stable_at(grid(i)))
    {
      first_stable = i;
    }
  }
  if (first_stable < 0)
  {
    return { kNaN, false, kNaN, false };
  }
  // Refine the start of the band (between an unstable and a stable grid point).
  auto refine = [&](double l_stable, double l_unstable) {
    while (std::abs(l_stable - l_unstable) > 1e-3)
    {
      const double mid = 0.5 * (l_stable + l_unstable);
      (stable_at(std::exp(mid)) ? l_stable : l_unstable) = mid;
    }
    return std::exp(l_stable);
  };
  const double band_start =
      first_stable == 0 ? grid(0) : refine(std::log(grid(first_stable)), std::log(grid(first_stable - 1)));
  int first_unstable = -1;
  for (int i = first_stable + 1; i < grid_points; ++i)
  {
    if (!stable_at(grid(i)))
    {
      first_unstable = i;
      break;
    }
  }
  if (first_unstable < 0)
  {
    return { from_hi ? lo : hi, true, band_start, first_stable == 0 };
  }
  return { refine(std::log(grid(first_unstable - 1)), std::log(grid(first_unstable))), false, band_start,
           first_stable == 0 };
}

}  // namespace analysis
}  // namespace jackal_aic
