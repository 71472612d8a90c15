/**
 * \file params.cpp
 * \brief AicParams validation and precisions (thesis tables C-1 and 5-8; doc/active_inference.md,
 *        'Prediction errors and free energy' and 'Parameter sets of the thesis').
 */
#include "jackal_aic/params.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
bool integratorFromString(const std::string& name, Integrator* out)
{
  if (out == nullptr)
  {
    return false;
  }
  if (name == "euler")
  {
    *out = Integrator::kEuler;
    return true;
  }
  if (name == "exact")
  {
    *out = Integrator::kExact;
    return true;
  }
  return false;
}

std::string toString(Integrator integrator)
{
  switch (integrator)
  {
    case Integrator::kEuler:
      return "euler";
    case Integrator::kExact:
      return "exact";
  }
  return "unknown";
}

std::string ParamViolation::toString() const
{
  return name + " = " + value + " (allowed: " + allowed + ")";
}

namespace
{
std::string formatValue(double v)
{
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

/// Adds a violation if v is not finite or outside [lo, hi] (lo excluded if lo_open).
void requireRange(const std::string& name, double v, double lo, bool lo_open, double hi,
                  std::vector<ParamViolation>* out)
{
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!ok)
  {
    out->push_back({ name, formatValue(v),
                     (lo_open ? "> " : ">= ") + formatValue(lo) + " and <= " + formatValue(hi) + ", finite" });
  }
}
}  // namespace

std::vector<ParamViolation> AicParams::validate() const
{
  std::vector<ParamViolation> v;
  requireRange("belief_rate", belief_rate, 0.0, true, kMaxRate, &v);
  requireRange("action_rate", action_rate, 0.0, true, kMaxRate, &v);
  if (std::isfinite(belief_rate) && std::isfinite(action_rate) && belief_rate > 0.0 && action_rate > 0.0 &&
      belief_rate < action_rate)
  {
    v.push_back({ "belief_rate", formatValue(belief_rate), ">= action_rate (" + formatValue(action_rate) + ")" });
  }
  requireRange("tau", tau, kMinTau, false, kMaxTau, &v);
  requireRange("k_mu", k_mu, 0.0, true, kMaxGain, &v);
  requireRange("k_a", k_a, 0.0, true, kMaxGain, &v);

  const bool order_ok = embedding_order >= 1 && embedding_order <= kMaxEmbeddingOrder;
  if (!order_ok)
  {
    v.push_back({ "embedding_order", std::to_string(embedding_order),
                  "integer in [1, " + std::to_string(kMaxEmbeddingOrder) + "]" });
  }

  auto check_variances = [&v, order_ok, this](const std::string& name, const std::vector<double>& var,
                                              int channels) {
    if (order_ok)
    {
      const std::size_t n = static_cast<std::size_t>(numOrders());
      if (var.size() != n && var.size() != n * static_cast<std::size_t>(channels))
      {
        v.push_back({ name + ".size()", std::to_string(var.size()),
                      std::to_string(n) + " (one per order) or " + std::to_string(n * channels) +
                          " (per order and channel, order-major) for embedding_order " +
                          std::to_string(embedding_order) });
      }
    }
    else if (var.empty())
    {
      v.push_back({ name + ".size()", "0", "embedding_order + 1 or " + std::to_string(channels) +
                                               " * (embedding_order + 1)" });
    }
    for (std::size_t i = 0; i < var.size(); ++i)
    {
      requireRange(name + "[" + std::to_string(i) + "]", var[i], kMinVariance, false, kMaxVariance, &v);
    }
  };
  check_variances("var_mu", var_mu, kMuDim);
  check_variances("var_y", var_y, kYDim);

  requireRange("wheel_radius", wheel_radius, kMinLength, false, kMaxLength, &v);
  requireRange("slip_factor", slip_factor, kMinSlipFactor, false, kMaxSlipFactor, &v);
  requireRange("wheel_separation", wheel_separation, kMinLength, false, kMaxLength, &v);
  requireRange("max_wheel_speed", max_wheel_speed, 0.0, true, kMaxWheelSpeedLimit, &v);
  requireRange("runaway_limit", runaway_limit, 0.0, true, kMaxRunawayLimit, &v);
  requireRange("max_action_lead", max_action_lead, 0.0, false, kMaxWheelSpeedLimit, &v);
  if (integrator != Integrator::kEuler && integrator != Integrator::kExact)
  {
    v.push_back({ "integrator", std::to_string(static_cast<int>(integrator)), "euler | exact" });
  }
  return v;
}

namespace
{
template <int Rows>
Eigen::Matrix<double, Rows, Eigen::Dynamic, Eigen::ColMajor, Rows, kMaxOrders>
precisionFrom(const std::vector<double>& var, int orders)
{
  if (orders < 1 || orders > kMaxOrders ||
      (var.size() != static_cast<std::size_t>(orders) && var.size() != static_cast<std::size_t>(Rows * orders)))
  {
    throw std::invalid_argument("AicParams: variances of size " + std::to_string(var.size()) +
                                " do not fit embedding_order " + std::to_string(orders - 1) +
                                " (call validate() first)");
  }
  Eigen::Matrix<double, Rows, Eigen::Dynamic, Eigen::ColMajor, Rows, kMaxOrders> pi(Rows, orders);
  const bool per_channel = var.size() == static_cast<std::size_t>(Rows * orders);
  for (int i = 0; i < orders; ++i)
  {
    for (int c = 0; c < Rows; ++c)
    {
      const double s2 = per_channel ? var[static_cast<std::size_t>(i * Rows + c)] : var[static_cast<std::size_t>(i)];
      pi(c, i) = 1.0 / s2;
    }
  }
  return pi;
}
}  // namespace

MuTilde AicParams::precisionMu() const
{
  return precisionFrom<kMuDim>(var_mu, numOrders());
}

YTilde AicParams::precisionY() const
{
  return precisionFrom<kYDim>(var_y, numOrders());
}

}  // namespace jackal_aic
