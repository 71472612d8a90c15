/**
 * \file fault_injection.cpp
 * \brief Fault injection for the simulated Jackal (sim/plant/include/jackal_sim/plant/fault_injection.hpp).
 */
#include "jackal_sim/plant/fault_injection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace jackal_aic
{
namespace plant
{
namespace
{
using Target = FaultSpec::Target;
using Kind = FaultSpec::Kind;

bool parseNumber(const std::string& token, const char* what, double* out, std::string* error)
{
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (token.empty() || end != token.c_str() + token.size() || !std::isfinite(v))
  {
    *error = std::string(what) + " '" + token + "' is not a finite number";
    return false;
  }
  *out = v;
  return true;
}

bool isEncoder(Target t)
{
  return t == Target::kLeftEncoder || t == Target::kRightEncoder;
}

bool isJointMessage(Target t)
{
  return isEncoder(t) || t == Target::kJointStates;
}

bool isImuMessage(Target t)
{
  return t == Target::kGyro || t == Target::kImu;
}
}  // namespace

bool parseFaultSpec(const std::string& text, FaultSpec* out, std::string* error)
{
  std::istringstream in(text);
  std::vector<std::string> tok;
  for (std::string t; in >> t;)
  {
    tok.push_back(t);
  }
  if (tok.size() < 2 || tok.size() > 6)
  {
    *error = "'" + text + "': expected TARGET KIND [VALUE] [START] [DURATION] [PERIOD]";
    return false;
  }
  FaultSpec f;
  const std::string& target = tok[0];
  if (target == "left_encoder")
    f.target = Target::kLeftEncoder;
  else if (target == "right_encoder")
    f.target = Target::kRightEncoder;
  else if (target == "gyro")
    f.target = Target::kGyro;
  else if (target == "imu")
    f.target = Target::kImu;
  else if (target == "joint_states")
    f.target = Target::kJointStates;
  else if (target == "friction_left")
    f.target = Target::kFrictionLeft;
  else if (target == "friction_right")
    f.target = Target::kFrictionRight;
  else if (target == "payload")
    f.target = Target::kPayload;
  else
  {
    *error = "unknown target '" + target +
             "' (left_encoder, right_encoder, gyro, imu, joint_states, friction_left, friction_right, payload)";
    return false;
  }
  const std::string& kind = tok[1];
  if (kind == "freeze")
    f.kind = Kind::kFreeze;
  else if (kind == "bias")
    f.kind = Kind::kBias;
  else if (kind == "spikes")
    f.kind = Kind::kSpikes;
  else if (kind == "delay")
    f.kind = Kind::kDelay;
  else if (kind == "dropout")
    f.kind = Kind::kDropout;
  else if (kind == "set")
    f.kind = Kind::kSet;
  else
  {
    *error = "unknown kind '" + kind + "' (freeze, bias, spikes, delay, dropout, set)";
    return false;
  }
  // The numbers that follow depend on the kind: freeze and dropout take no VALUE (so
  // "gyro freeze 0 4" is a 4 s freeze from now, not a freeze from 4 s on), and only spikes has a
  // PERIOD.
  std::vector<const char*> names;
  std::vector<double*> fields;
  if (f.kind != Kind::kFreeze && f.kind != Kind::kDropout)
  {
    names.push_back("VALUE");
    fields.push_back(&f.value);
  }
  names.insert(names.end(), { "START", "DURATION" });
  fields.insert(fields.end(), { &f.start, &f.duration });
  if (f.kind == Kind::kSpikes)
  {
    names.push_back("PERIOD");
    fields.push_back(&f.period);
  }
  if (tok.size() - 2 > fields.size())
  {
    std::string form = "TARGET " + kind;
    for (const char* n : names)
    {
      form += std::string(" [") + n + "]";
    }
    *error = "'" + text + "': too many numbers; '" + kind + "' takes " + form;
    return false;
  }
  if ((f.kind == Kind::kBias || f.kind == Kind::kSpikes || f.kind == Kind::kDelay || f.kind == Kind::kSet) &&
      tok.size() < 3)
  {
    *error = "'" + text + "': '" + kind + "' needs a VALUE";
    return false;
  }
  for (std::size_t i = 2; i < tok.size(); ++i)
  {
    if (!parseNumber(tok[i], names[i - 2], fields[i - 2], error))
    {
      return false;
    }
  }
  const bool physical =
      f.target == Target::kFrictionLeft || f.target == Target::kFrictionRight || f.target == Target::kPayload;
  if (physical != (f.kind == Kind::kSet))
  {
    *error = "kind '" + kind + "' does not apply to target '" + target +
             "' (set is for friction_left, friction_right, payload only)";
    return false;
  }
  if ((f.kind == Kind::kFreeze || f.kind == Kind::kBias || f.kind == Kind::kSpikes) &&
      !(isEncoder(f.target) || f.target == Target::kGyro))
  {
    *error = "kind '" + kind + "' needs a channel target (left_encoder, right_encoder, gyro)";
    return false;
  }
  if (f.start < 0.0)
  {
    *error = "START must be >= 0";
    return false;
  }
  if (!(f.period > 0.0))
  {
    *error = "PERIOD must be > 0";
    return false;
  }
  if (f.kind == Kind::kDelay && !(f.value > 0.0 && f.value <= 10.0))
  {
    *error = "a delay VALUE must be in (0, 10] s";
    return false;
  }
  if (f.target == Target::kPayload && !(f.value >= 0.0 && f.value <= 1000.0))
  {
    *error = "a payload VALUE must be in [0, 1000] kg";
    return false;
  }
  if ((f.target == Target::kFrictionLeft || f.target == Target::kFrictionRight) && !(f.value >= 0.0 && f.value <= 10.0))
  {
    *error = "a friction scale VALUE must be in [0, 10]";
    return false;
  }
  *out = f;
  return true;
}

void FaultInjector::setFaults(const std::vector<FaultSpec>& faults, double now)
{
  faults_ = faults;
  starts_.assign(faults.size(), 0.0);
  last_spike_.assign(faults.size(), -1e300);
  for (std::size_t k = 0; k < faults.size(); ++k)
  {
    starts_[k] = now + faults[k].start;
  }
}

bool FaultInjector::active(std::size_t k, double t) const
{
  const FaultSpec& f = faults_[k];
  return t >= starts_[k] && (f.duration <= 0.0 || t < starts_[k] + f.duration);
}

bool FaultInjector::applyJoints(double t, JointStateSample* s, double* delay)
{
  *delay = 0.0;
  bool keep = true;
  for (std::size_t k = 0; k < faults_.size(); ++k)
  {
    const FaultSpec& f = faults_[k];
    if (!isJointMessage(f.target) || !active(k, t))
    {
      continue;
    }
    const Side side = f.target == Target::kRightEncoder ? kRight : kLeft;
    for (int i = 0; i < kNumWheels; ++i)
    {
      if (!isEncoder(f.target) || kWheelSide[i] != side)
      {
        continue;
      }
      switch (f.kind)
      {
        case Kind::kFreeze:
          if (have_last_joints_)
          {
            s->velocity[i] = last_velocity_[i];
          }
          break;
        case Kind::kBias:
          s->velocity[i] += f.value;
          break;
        case Kind::kSpikes:
          if (t - last_spike_[k] >= f.period - 1e-9)
          {
            s->velocity[i] += f.value;
          }
          break;
        default:
          break;
      }
    }
    if (f.kind == Kind::kSpikes && t - last_spike_[k] >= f.period - 1e-9)
    {
      last_spike_[k] = t;
    }
    if (f.kind == Kind::kDropout)
    {
      keep = false;
    }
    if (f.kind == Kind::kDelay)
    {
      *delay = std::max(*delay, f.value);
    }
  }
  if (keep)
  {
    last_velocity_ = s->velocity;
    have_last_joints_ = true;
  }
  return keep;
}

bool FaultInjector::applyImu(double t, ImuSample* s, double* delay)
{
  *delay = 0.0;
  bool keep = true;
  for (std::size_t k = 0; k < faults_.size(); ++k)
  {
    const FaultSpec& f = faults_[k];
    if (!isImuMessage(f.target) || !active(k, t))
    {
      continue;
    }
    switch (f.kind)
    {
      case Kind::kFreeze:
        if (have_last_imu_)
        {
          s->angular_velocity.z() = last_gyro_;
        }
        break;
      case Kind::kBias:
        s->angular_velocity.z() += f.value;
        break;
      case Kind::kSpikes:
        if (t - last_spike_[k] >= f.period - 1e-9)
        {
          s->angular_velocity.z() += f.value;
          last_spike_[k] = t;
        }
        break;
      case Kind::kDropout:
        keep = false;
        break;
      case Kind::kDelay:
        *delay = std::max(*delay, f.value);
        break;
      case Kind::kSet:
        break;
    }
  }
  if (keep)
  {
    last_gyro_ = s->angular_velocity.z();
    have_last_imu_ = true;
  }
  return keep;
}

double FaultInjector::frictionScale(Side side, double t) const
{
  double scale = 1.0;
  const Target target = side == kLeft ? Target::kFrictionLeft : Target::kFrictionRight;
  for (std::size_t k = 0; k < faults_.size(); ++k)
  {
    if (faults_[k].target == target && active(k, t))
    {
      scale = faults_[k].value;
    }
  }
  return scale;
}

double FaultInjector::payload(double t) const
{
  double m = 0.0;
  for (std::size_t k = 0; k < faults_.size(); ++k)
  {
    if (faults_[k].target == Target::kPayload && active(k, t))
    {
      m = faults_[k].value;
    }
  }
  return m;
}

namespace
{
/// Release the queued samples due at t into *out, then queue or publish `sample` (if any).
template <class Sample>
void releaseAndQueue(double t, std::deque<std::pair<double, Sample>>* queue, const Sample* sample, double delay,
                     std::vector<Sample>* out)
{
  while (!queue->empty() && queue->front().first <= t)
  {
    out->push_back(queue->front().second);
    queue->pop_front();
  }
  if (sample == nullptr)
  {
    return;
  }
  if (delay > 0.0 || !queue->empty())
  {
    const double release = std::max(t + delay, queue->empty() ? 0.0 : queue->back().first);
    queue->emplace_back(release, *sample);
  }
  else
  {
    out->push_back(*sample);
  }
}
}  // namespace

FaultedSensors::Changes FaultedSensors::afterStep(Plant& plant, std::vector<JointStateSample>* joints,
                                                  std::vector<ImuSample>* imu)
{
  model_.record(plant);
  const double t = plant.time();
  Changes changes;
  const double payload = injector_.payload(t);
  if (payload != plant.payload())
  {
    plant.setPayload(payload);
    changes.payload = true;
  }
  for (const Side side : { kLeft, kRight })
  {
    const double scale = injector_.frictionScale(side, t);
    if (scale != plant.frictionScale(side))
    {
      plant.setFrictionScale(side, scale);
      changes.friction[static_cast<std::size_t>(side)] = true;
    }
  }
  joints->clear();
  imu->clear();
  JointStateSample js;
  double delay = 0.0;
  const bool js_due = model_.pollJointStates(&js) && injector_.applyJoints(t, &js, &delay);
  releaseAndQueue(t, &delayed_joints_, js_due ? &js : nullptr, delay, joints);
  ImuSample im;
  delay = 0.0;
  const bool imu_due = model_.pollImu(&im) && injector_.applyImu(t, &im, &delay);
  releaseAndQueue(t, &delayed_imu_, imu_due ? &im : nullptr, delay, imu);
  return changes;
}

}  // namespace plant
}  // namespace jackal_aic
