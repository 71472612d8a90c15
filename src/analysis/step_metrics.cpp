/**
 * \file step_metrics.cpp
 * \brief Step-response metrics (thesis ch. 5; doc/active_inference.md,
 *        'Step-response metrics and experiments').
 */
#include "jackal_aic/analysis/step_metrics.hpp"

#include "jackal_aic/base/json_number.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace analysis
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void require(bool ok, const std::string& message)
{
  if (!ok)
  {
    throw std::invalid_argument("step metrics: " + message);
  }
}

/// Time at which the linear interpolation between (t0, r0) and (t1, r1) reaches level.
double crossing(double t0, double r0, double t1, double r1, double level)
{
  if (r1 == r0)
  {
    return t1;
  }
  const double s = std::clamp((level - r0) / (r1 - r0), 0.0, 1.0);
  return t0 + s * (t1 - t0);
}
}  // namespace

StepMetrics computeStepMetrics(const std::vector<double>& time, const std::vector<double>& value,
                               const StepMetricsOptions& o)
{
  require(time.size() == value.size(),
          "time has " + std::to_string(time.size()) + " samples but value has " + std::to_string(value.size()));
  require(std::isfinite(o.step_time) && std::isfinite(o.initial) && std::isfinite(o.target) &&
              std::isfinite(o.end_time),
          "step_time, initial, target and end_time must be finite");
  require(o.target != o.initial, "target equals initial: a step of size 0 has no metrics");
  require(o.rise_low > 0.0 && o.rise_low < o.rise_high && o.rise_high <= 1.0, "rise thresholds must satisfy 0 < "
                                                                              "rise_low < rise_high <= 1");
  require(std::isfinite(o.settling_band) && o.settling_band > 0.0, "settling_band must be > 0");
  require(std::isfinite(o.steady_state_window) && o.steady_state_window > 0.0, "steady_state_window must be > 0");
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    require(std::isfinite(time[k]), "time[" + std::to_string(k) + "] is not finite");
    require(std::isfinite(value[k]), "value[" + std::to_string(k) + "] is not finite");
    require(k == 0 || time[k] > time[k - 1], "time is not strictly increasing at sample " + std::to_string(k));
  }
  const bool has_end = o.end_time > o.step_time;
  std::vector<double> t;
  std::vector<double> v;
  for (std::size_t k = 0; k < time.size(); ++k)
  {
    if (time[k] >= o.step_time && (!has_end || time[k] <= o.end_time))
    {
      t.push_back(time[k] - o.step_time);
      v.push_back(value[k]);
    }
  }
  require(t.size() >= 2, "fewer than 2 samples between step_time and end_time (" + std::to_string(t.size()) + ")");

  StepMetrics m{};
  m.samples = static_cast<int>(t.size());
  const double step = o.target - o.initial;
  // Normalized response: 0 before the step, 1 at the target.
  std::vector<double> r(v.size());
  for (std::size_t k = 0; k < v.size(); ++k)
  {
    r[k] = (v[k] - o.initial) / step;
  }

  // Rise time: first crossings of rise_low and rise_high.
  auto first_crossing = [&](double level) {
    if (r[0] >= level)
    {
      return 0.0;
    }
    for (std::size_t k = 1; k < r.size(); ++k)
    {
      if (r[k] >= level)
      {
        return crossing(t[k - 1], r[k - 1], t[k], r[k], level);
      }
    }
    return kNaN;
  };
  m.t_rise_low = first_crossing(o.rise_low);
  m.t_rise_high = first_crossing(o.rise_high);
  m.rise_time = m.t_rise_high - m.t_rise_low;  // NaN propagates

  // Overshoot.
  const double r_max = *std::max_element(r.begin(), r.end());
  m.overshoot_percent = std::max(0.0, (r_max - 1.0) * 100.0);

  // Settling.
  const bool final_basis = o.band_basis == SettlingBandBasis::kFinalValue && o.target != 0.0;
  m.band = o.settling_band * (final_basis ? std::abs(o.target) : std::abs(step));
  auto err = [&](std::size_t k) { return std::abs(v[k] - o.target); };
  std::size_t last_out = r.size();  // none
  for (std::size_t k = r.size(); k-- > 0;)
  {
    if (err(k) > m.band)
    {
      last_out = k;
      break;
    }
  }
  if (last_out == r.size())
  {
    m.settled = true;
    m.settling_time = 0.0;
  }
  else if (last_out == r.size() - 1)
  {
    m.settled = false;
    m.settling_time = kNaN;
  }
  else
  {
    m.settled = true;
    m.settling_time = crossing(t[last_out], err(last_out), t[last_out + 1], err(last_out + 1), m.band);
  }

  // Steady-state error: trapezoidal time average of target - value over the last window.
  const double t_end = t.back();
  const double t_start = std::max(t.front(), t_end - o.steady_state_window);
  double integral = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k)
  {
    const double a = std::max(t[k - 1], t_start);
    const double b = t[k];
    if (b <= a)
    {
      continue;
    }
    // Linear interpolation of the error on [t[k-1], t[k]], integrated over [a, b].
    const double e0 = o.target - v[k - 1];
    const double e1 = o.target - v[k];
    const double ea = e0 + (e1 - e0) * (a - t[k - 1]) / (t[k] - t[k - 1]);
    integral += 0.5 * (ea + e1) * (b - a);
  }
  m.steady_state_window_used = t_end - t_start;
  m.steady_state_error = integral / m.steady_state_window_used;

  // IAE: |e| with e linear between samples; where e changes sign, the two triangles.
  m.iae = 0.0;
  for (std::size_t k = 1; k < t.size(); ++k)
  {
    const double e0 = o.target - v[k - 1];
    const double e1 = o.target - v[k];
    const double dt = t[k] - t[k - 1];
    m.iae += (e0 * e1 >= 0.0) ? 0.5 * (std::abs(e0) + std::abs(e1)) * dt :
                                0.5 * (e0 * e0 + e1 * e1) / (std::abs(e0) + std::abs(e1)) * dt;
  }
  return m;
}

std::string toJson(const StepMetrics& m, const StepMetricsOptions& o)
{
  const auto num = [](double x) { return base::jsonNumber(x, 10); };
  std::ostringstream os;
  os << "{\"rise_time\": " << num(m.rise_time) << ", \"t_rise_low\": " << num(m.t_rise_low)
     << ", \"t_rise_high\": " << num(m.t_rise_high) << ", \"settling_time\": " << num(m.settling_time)
     << ", \"settled\": " << (m.settled ? "true" : "false") << ", \"settling_band\": " << num(m.band)
     << ", \"overshoot_percent\": " << num(m.overshoot_percent)
     << ", \"steady_state_error\": " << num(m.steady_state_error)
     << ", \"steady_state_window\": " << num(m.steady_state_window_used) << ", \"iae\": " << num(m.iae)
     << ", \"samples\": " << m.samples << ", \"step_time\": " << num(o.step_time) << ", \"initial\": " << num(o.initial)
     << ", \"target\": " << num(o.target) << ", \"band_basis\": \""
     << (o.band_basis == SettlingBandBasis::kFinalValue ? "final" : "step") << "\"}";
  return os.str();
}

}  // namespace analysis
}  // namespace jackal_aic
