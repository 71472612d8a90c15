#include "jackal_sim/plant/jackal_node_sampler.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace jackal_aic
{
namespace plant
{
namespace
{
void check(std::vector<std::string>* out, bool ok, const char* key, double value, const char* range)
{
  if (!ok)
  {
    std::ostringstream os;
    os << key << " = " << value << " (" << range << ")";
    out->push_back(os.str());
  }
}
}  // namespace

std::vector<std::string> JackalNodeSamplerParams::validate() const
{
  std::vector<std::string> v;
  const bool rate_ok = std::isfinite(loop_rate) && loop_rate > 0.0;
  check(&v, rate_ok, "loop_rate", loop_rate, "> 0 Hz");
  const double period = rate_ok ? 1.0 / loop_rate : 0.0;
  check(&v, std::isfinite(phase) && phase >= 0.0 && (!rate_ok || phase < period), "phase", phase,
        "[0, 1 / loop_rate) s");
  check(&v, std::isfinite(drift) && std::abs(drift) <= 1e4, "drift", drift, "[-1e4, 1e4] ppm");
  check(&v, std::isfinite(jitter_std) && jitter_std >= 0.0 && jitter_std <= 0.005, "jitter_std", jitter_std,
        "[0, 0.005] s");
  check(&v, std::isfinite(stall_probability) && stall_probability >= 0.0 && stall_probability <= 1.0,
        "stall_probability", stall_probability, "[0, 1]");
  check(&v, std::isfinite(stall_max) && stall_max >= 0.0 && (!rate_ok || stall_max < 2.0 * period), "stall_max",
        stall_max, "[0, 2 / loop_rate) s");
  check(&v, std::isfinite(cycle_time) && cycle_time >= 0.0 && cycle_time <= 0.005, "cycle_time", cycle_time,
        "[0, 0.005] s");
  check(&v, std::isfinite(link_delay) && link_delay >= 0.0 && link_delay <= 0.1, "link_delay", link_delay,
        "[0, 0.1] s");
  return v;
}

JackalNodeSampler::JackalNodeSampler(const JackalNodeSamplerParams& params) : params_(params), rng_(params.seed)
{
  const auto violations = params_.validate();
  if (!violations.empty())
  {
    std::ostringstream os;
    os << "JackalNodeSampler: invalid parameters:";
    for (const auto& s : violations)
    {
      os << " " << s << ";";
    }
    throw std::invalid_argument(os.str());
  }
  period_ = (1.0 - params_.drift * 1e-6) / params_.loop_rate;
  next_time_ = cycleTime(0, -1.0);
}

double JackalNodeSampler::cycleTime(std::uint64_t k, double prev)
{
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double late = params_.jitter_std * std::abs(normal(rng_));
  if (params_.stall_probability > 0.0 && uniform(rng_) < params_.stall_probability)
  {
    late += params_.stall_max * uniform(rng_);
  }
  const double due = params_.phase + static_cast<double>(k) * period_ + late;
  return prev < 0.0 ? due : std::max(due, prev + params_.cycle_time);
}

void JackalNodeSampler::feedback(const JointStateSample& s)
{
  // One measurement per side: both joints of a side carry the side's mean.
  JointStateSample m = s;
  for (const Side side : { kLeft, kRight })
  {
    double pos = 0.0;
    double vel = 0.0;
    for (int i = 0; i < kNumWheels; ++i)
    {
      if (kWheelSide[static_cast<std::size_t>(i)] == side)
      {
        pos += 0.5 * s.position[static_cast<std::size_t>(i)];
        vel += 0.5 * s.velocity[static_cast<std::size_t>(i)];
      }
    }
    for (int i = 0; i < kNumWheels; ++i)
    {
      if (kWheelSide[static_cast<std::size_t>(i)] == side)
      {
        m.position[static_cast<std::size_t>(i)] = pos;
        m.velocity[static_cast<std::size_t>(i)] = vel;
      }
    }
  }
  pending_.push_back(m);
}

void JackalNodeSampler::advance(double now, std::vector<ResampledJointState>* out)
{
  out->clear();
  while (next_time_ <= now)
  {
    const double t = next_time_;
    // Every MCU sample that reached the loop by its time; the newest is what the cycle copies.
    while (!pending_.empty() && pending_.front().stamp + params_.link_delay <= t)
    {
      latest_ = pending_.front();
      pending_.pop_front();
      have_latest_ = true;
      ++latest_seq_;
    }
    if (have_latest_)
    {
      if (!have_offset_)
      {
        offset_ = latest_.position;
        have_offset_ = true;
      }
      ResampledJointState r;
      r.sample = latest_;
      r.sample.stamp = t;
      for (std::size_t i = 0; i < offset_.size(); ++i)
      {
        r.sample.position[i] = latest_.position[i] - offset_[i];
      }
      r.source_stamp = latest_.stamp;
      r.repeated = published_seq_ == latest_seq_;
      r.cycle = k_;
      const double age = t - latest_.stamp;
      if (stats_.cycles == 0)
      {
        stats_.min_age = stats_.max_age = age;
      }
      stats_.min_age = std::min(stats_.min_age, age);
      stats_.max_age = std::max(stats_.max_age, age);
      if (r.repeated)
      {
        ++stats_.repeats;
        ++repeat_run_;
        stats_.max_repeat_run = std::max(stats_.max_repeat_run, repeat_run_);
        stats_.max_held = std::max(stats_.max_held, t - first_published_);
      }
      else
      {
        if (published_seq_ > 0)
        {
          stats_.skipped += latest_seq_ - published_seq_ - 1;
        }
        first_published_ = t;
        repeat_run_ = 0;
      }
      if (ran_ && t - last_time_ < 0.5 * period_)
      {
        ++stats_.catch_up;
      }
      ++stats_.cycles;
      published_seq_ = latest_seq_;
      out->push_back(r);
    }
    ran_ = true;
    last_time_ = t;
    ++k_;
    next_time_ = cycleTime(k_, t);
  }
}

}  // namespace plant
}  // namespace jackal_aic
