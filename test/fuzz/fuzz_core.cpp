/**
 * \file fuzz_core.cpp
 * \brief libFuzzer target over the ROS-free core: arbitrary bytes become a parameter set, sensor
 *        samples, sample intervals, goals, belief and action steps, channel masks and the fault
 *        monitor's inputs, fed through Generalizer -> ActiveInferenceController (+ FaultMonitor)
 *        -> action. Aborts (a finding) on: an exception other than std::invalid_argument from
 *        an invalid parameter set, a constructor accepting a set validate() rejects, or an action
 *        that is non-finite or beyond max_wheel_speed, or non-finite beliefs. Sanitizers (address,
 *        undefined) catch the rest. Built and run by dev/fuzz.sh (clang), in CI bounded in time.
 */
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <algorithm>
#include <stdexcept>

#include <fuzzer/FuzzedDataProvider.h>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/safety/fault_monitor.hpp"
#include "jackal_aic/aic/generalizer.hpp"
#include "jackal_aic/loop/fault_test.hpp"

using namespace jackal_aic;

namespace
{
[[noreturn]] void finding(const char* what, double value)
{
  std::fprintf(stderr, "fuzz_core: FINDING: %s (value %.17g)\n", what, value);
  std::abort();
}

/// A double that is usually in a useful log range, sometimes anything (NaN, Inf, huge, negative).
double number(FuzzedDataProvider& in, double lo_exp, double hi_exp)
{
  switch (in.ConsumeIntegralInRange<int>(0, 7))
  {
    case 0:
      return in.ConsumeFloatingPoint<double>();  // any finite double
    case 1: {
      const double special[] = { NAN, INFINITY, -INFINITY, 0.0, -0.0, -1.0, 1e308, 5e-324 };
      return special[in.ConsumeIntegralInRange<int>(0, 7)];
    }
    default:
      return std::pow(10.0, in.ConsumeFloatingPointInRange<double>(lo_exp, hi_exp));
  }
}

params::AicParams fuzzedParams(FuzzedDataProvider& in)
{
  params::AicParams p;
  p.belief_rate = number(in, 0.0, 4.0);
  p.action_rate = number(in, 0.0, 3.0);
  p.tau = number(in, -4.0, 1.0);
  p.k_mu = number(in, -3.0, 2.0);
  p.k_a = number(in, -2.0, 2.0);
  p.embedding_order = in.ConsumeIntegralInRange<int>(0, base::kMaxEmbeddingOrder + 1);
  const int n = std::max(1, p.embedding_order + 1);
  const bool per_channel = in.ConsumeBool();
  p.var_mu.resize(per_channel ? 3 * n : n);
  p.var_y.resize(per_channel ? 5 * n : n);
  for (auto& v : p.var_mu)
  {
    v = number(in, -2.0, 5.0);
  }
  for (auto& v : p.var_y)
  {
    v = number(in, -2.0, 6.0);
  }
  p.max_wheel_speed = number(in, -1.0, 2.0);
  p.runaway_limit = number(in, 0.0, 4.0);
  p.anti_windup.max_action_lead = in.ConsumeBool() ? 0.0 : number(in, -1.0, 1.0);
  p.accel_in_model = in.ConsumeBool();
  p.integrator = in.ConsumeBool() ? params::Integrator::kExact : params::Integrator::kEuler;
  // The belief model; with the robot model (the default's, doc/active_inference.md, 'The robot
  // model') its identified keys, noises, loop gain and learning switches.
  switch (in.ConsumeIntegralInRange<int>(0, 2))
  {
    case 0:
      p.belief_model = params::BeliefModel::kGoal;
      break;
    case 1:
      p.belief_model = params::BeliefModel::kUnbiased;
      break;
    default: {
      p.belief_model = params::BeliefModel::kRobot;
      // Half the draws keep every robot key in its range (log-uniform), so that the controller is
      // built and driven; the other half may draw anything (number()).
      const bool plausible = in.ConsumeBool();
      const auto draw = [&](double lo_exp, double hi_exp) {
        return plausible ? std::pow(10.0, in.ConsumeFloatingPointInRange<double>(lo_exp, hi_exp)) :
                           number(in, lo_exp, hi_exp);
      };
      params::RobotModelParams& r = p.robot;
      r.latency = draw(-3.0, -0.4);
      r.wheel_time_constant = in.ConsumeBool() ? 0.0 : draw(-4.0, 0.0);
      r.wheel_acceleration = draw(0.0, 3.0);
      r.wheel_feedforward = in.ConsumeBool() ? 0.0 : draw(-2.0, 0.3);
      r.wheel_feedforward_acceleration =
          in.ConsumeBool() ? 0.0 : r.wheel_acceleration * in.ConsumeFloatingPointInRange<double>(0.0, 0.99);
      r.yaw_time_constant = draw(-3.0, 1.0);
      r.encoder_noise = draw(-4.0, 0.0);
      r.gyro_noise = draw(-4.0, 0.0);
      r.wheel_model_noise = draw(-3.0, 1.0);
      r.shortfall_noise = in.ConsumeBool() ? 0.0 : draw(-4.0, 0.0);
      r.turn_shortfall_noise = in.ConsumeBool() ? 0.0 : draw(-3.0, 0.0);
      r.shortfall_compensation_limit = in.ConsumeBool() ? 0.0 : draw(-3.0, 1.0);
      r.yaw_model_noise = draw(-3.0, 1.0);
      r.yaw_slip_noise = draw(-3.0, 0.0);
      r.gyro_offset_noise = draw(-4.0, 0.0);
      r.action_gain = draw(0.0, 3.0);
      r.learn_latency = in.ConsumeBool();
      p.separation_learner.enabled = in.ConsumeBool();
      break;
    }
  }
  return p;
}

void checkAction(const aic::ActiveInferenceController& c)
{
  const base::Vector2& a = c.action();
  const double lim = c.params().max_wheel_speed;
  for (int i = 0; i < 2; ++i)
  {
    if (!std::isfinite(a(i)))
    {
      finding("non-finite action", a(i));
    }
    if (std::abs(a(i)) > lim)
    {
      finding("action beyond max_wheel_speed", a(i));
    }
  }
  if (!c.mu().allFinite())
  {
    finding("non-finite beliefs", c.mu().sum());
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  FuzzedDataProvider in(data, size);
  const params::AicParams p = fuzzedParams(in);
  const bool valid = p.validate().empty();
  std::unique_ptr<aic::ActiveInferenceController> c;
  std::unique_ptr<safety::FaultMonitor> monitor;
  try
  {
    c = std::make_unique<aic::ActiveInferenceController>(p);
    monitor = std::make_unique<safety::FaultMonitor>(params::FdiParams(), p);
  }
  catch (const std::invalid_argument&)
  {
    if (valid)
    {
      finding("valid parameters rejected", p.tau);
    }
    return 0;
  }
  if (!valid)
  {
    finding("invalid parameters accepted", p.tau);
  }
  aic::Generalizer gen(base::kYDim, p.embedding_order);
  for (int op = 0; op < 32 && in.remaining_bytes() > 0; ++op)
  {
    switch (in.ConsumeIntegralInRange<int>(0, 7))
    {
      case 0: {
        base::Vector5 y;
        for (int j = 0; j < base::kYDim; ++j)
        {
          y(j) = in.ConsumeBool() ? in.ConsumeFloatingPointInRange<double>(-30.0, 30.0) : number(in, -3.0, 3.0);
        }
        const double h = number(in, -4.0, 0.0);
        const auto status = gen.update(y, h);
        if (status == aic::Generalizer::Status::kOk || status == aic::Generalizer::Status::kFirstSample)
        {
          c->setMeasurement(gen.yTilde());
        }
        monitor->setImuAvailable(in.ConsumeBool() || in.ConsumeBool());
        loop::testSample(monitor.get(), *c, y, h);
        c->setSensorMask(monitor->sensorMask());
        break;
      }
      case 1:
        c->setGoal(base::Vector3(number(in, -2.0, 1.0), 0.0, number(in, -2.0, 1.0)));
        break;
      case 2:
      case 3: {
        const double h = number(in, -5.0, 0.0);
        const int steps = in.ConsumeIntegralInRange<int>(1, 10);
        for (int i = 0; i < steps; ++i)
        {
          c->updateBeliefs(h);
        }
        checkAction(*c);
        break;
      }
      case 4:
        c->updateAction(number(in, -4.0, 0.0));
        checkAction(*c);
        break;
      case 5:
        c->setSensorMask(in.ConsumeIntegral<std::uint8_t>());
        break;
      case 6: {
        const params::AicParams q = fuzzedParams(in);
        try
        {
          c->setParams(q);
          monitor->setParams(params::FdiParams(), q);
          if (q.embedding_order != gen.embeddingOrder())
          {
            gen = aic::Generalizer(base::kYDim, q.embedding_order);
          }
        }
        catch (const std::invalid_argument&)
        {
          if (q.validate().empty())
          {
            finding("valid parameters rejected by setParams", q.tau);
          }
        }
        checkAction(*c);
        break;
      }
      default:
        c->setAction(base::Vector2(number(in, -2.0, 2.0), number(in, -2.0, 2.0)));
        checkAction(*c);
        break;
    }
  }
  c->updateAction(0.02);
  checkAction(*c);
  return 0;
}
