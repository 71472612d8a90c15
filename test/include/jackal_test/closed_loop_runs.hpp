#pragma once
/**
 * \file closed_loop_runs.hpp
 * \brief The simulated-time tests' way to run a closed loop on the simulated Jackal and to read its
 *        record (test/sim): the committed URDF and plant YAML with overlays, and statistics of a
 *        signal over a time window. Header-only; the harness is jackal_sim/harness/closed_loop.hpp.
 */

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "jackal_aic/overrides/yaml_overrides.hpp"
#include "jackal_sim/harness/closed_loop.hpp"
#include "jackal_sim/plant/plant_params.hpp"
#include "jackal_sim/plant/robot_description.hpp"

namespace jackal_test
{
/**
 * \brief Run `c` on the simulated Jackal: `root`/sim/urdf/jackal.urdf and `root`/sim/config/plant.yaml
 *        with `overlays` applied in order, each a plant YAML overlay file (a path relative to
 *        `root`, e.g. "sim/config/variants/turn_deficit.yaml") or one "key=value" of the plant.
 * \return the run's record (jackal_aic::harness::runClosedLoop()).
 * \throws what the URDF, plant or overlay loaders throw on a missing or invalid file or key.
 */
inline jackal_aic::harness::ClosedLoopRecord runOnJackal(const std::string& root,
                                                         const jackal_aic::harness::ClosedLoopConfig& c,
                                                         const std::vector<std::string>& overlays = {})
{
  std::vector<std::string> overrides;
  for (const std::string& o : overlays)
  {
    const std::vector<std::string> extra = o.find('=') != std::string::npos ?
                                               std::vector<std::string>{ o } :
                                               jackal_aic::overrides::loadOverlayFile(root + "/" + o);
    overrides.insert(overrides.end(), extra.begin(), extra.end());
  }
  return jackal_aic::harness::runClosedLoop(
      jackal_aic::plant::loadRobotDescription(root + "/sim/urdf/jackal.urdf"),
      jackal_aic::plant::loadPlantParams(root + "/sim/config/plant.yaml", overrides), c);
}

/// Mean of v (a signal of r, its unit) over the samples with time in [t0, t1] [s]; NaN when none.
inline double windowMean(const jackal_aic::harness::ClosedLoopRecord& r, const std::vector<double>& v, double t0,
                         double t1)
{
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      sum += v[k];
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

/// Mean |a - b| of two signals of r over the samples with time in [t0, t1] [s]; NaN when none.
inline double windowMeanAbsDiff(const jackal_aic::harness::ClosedLoopRecord& r, const std::vector<double>& a,
                                const std::vector<double>& b, double t0, double t1)
{
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      sum += std::abs(a[k] - b[k]);
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

/// Largest value of v over the samples with time in [t0, t1] [s]; -inf when none.
inline double windowPeak(const jackal_aic::harness::ClosedLoopRecord& r, const std::vector<double>& v, double t0,
                         double t1)
{
  double m = -INFINITY;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      m = std::max(m, v[k]);
    }
  }
  return m;
}

/// Largest |v - value| over the samples with time in [t0, t1] [s]; 0 when none.
inline double windowMaxDeviation(const jackal_aic::harness::ClosedLoopRecord& r, const std::vector<double>& v,
                                 double value, double t0, double t1)
{
  double worst = 0.0;
  for (std::size_t k = 0; k < r.time.size(); ++k)
  {
    if (r.time[k] >= t0 && r.time[k] <= t1)
    {
      worst = std::max(worst, std::abs(v[k] - value));
    }
  }
  return worst;
}
/// The first fault-isolation event of r at or after t0 [s], or nullptr.
inline const jackal_aic::harness::HealthEvent* firstIsolation(const jackal_aic::harness::ClosedLoopRecord& r, double t0)
{
  for (const jackal_aic::harness::HealthEvent& e : r.health_events)
  {
    if (e.time >= t0 && e.event == jackal_aic::safety::FaultMonitor::Event::kIsolated)
    {
      return &e;
    }
  }
  return nullptr;
}

/// Largest change of the learned b_hat over [t0, t1] [s] relative to its value at t0 (0 if not learning).
inline double separationMove(const jackal_aic::harness::ClosedLoopRecord& r, double t0, double t1)
{
  double start = NAN;
  double worst = 0.0;
  for (std::size_t i = 0; i < r.time.size(); ++i)
  {
    if (r.time[i] < t0 || r.time[i] > t1 || !std::isfinite(r.separation[i]))
    {
      continue;
    }
    if (!std::isfinite(start))
    {
      start = r.separation[i];
    }
    worst = std::max(worst, std::abs(r.separation[i] - start) / start);
  }
  return worst;
}

}  // namespace jackal_test
