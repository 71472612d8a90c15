/// Google Benchmark of the controller's update path (targets: updateBeliefs at p = 3
/// under 1 us, updateAction under 0.5 us). Built with the tests, not run as a test:
///   .ws/devel/lib/jackal_aic/bench_controller
#include <benchmark/benchmark.h>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/generalizer.hpp"

using namespace jackal_aic;

namespace
{
aic::ActiveInferenceController makeController(int p, params::Integrator integ)
{
  params::AicParams params;
  params.embedding_order = p;
  params.var_mu.assign(static_cast<std::size_t>(p + 1), 2.0);
  params.var_y.assign(static_cast<std::size_t>(p + 1), 2.0);
  params.integrator = integ;
  params.tau = 0.03;  // stable with both integrators at 1 kHz
  aic::ActiveInferenceController c(params);
  base::YTilde y = base::YTilde::Zero(base::kYDim, p + 1);
  y(base::kOmegaLeft, 0) = 3.0;
  y(base::kOmegaRight, 0) = 3.2;
  y(base::kGyroZ, 0) = 0.03;
  c.setMeasurement(y);
  c.setGoal(base::Vector3(0.3, 0.0, 0.1));
  return c;
}

void BM_UpdateBeliefs(benchmark::State& state)
{
  const int p = static_cast<int>(state.range(0));
  const params::Integrator integ = state.range(1) ? params::Integrator::kExact : params::Integrator::kEuler;
  aic::ActiveInferenceController c = makeController(p, integ);
  c.updateBeliefs(1e-3);  // exact: compute the matrices once, outside the loop
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(c.updateBeliefs(1e-3));
    benchmark::ClobberMemory();
  }
  state.SetLabel(params::toString(integ));
}
BENCHMARK(BM_UpdateBeliefs)->ArgsProduct({ { 1, 2, 3, 4, 5 }, { 0, 1 } })->ArgNames({ "p", "exact" });

/// Exact integrator with a jittered h (+-1 %, within kExactSeriesLimit: the series correction path).
void BM_UpdateBeliefsExactJitter(benchmark::State& state)
{
  aic::ActiveInferenceController c = makeController(static_cast<int>(state.range(0)), params::Integrator::kExact);
  c.updateBeliefs(1e-3);
  int k = 0;
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(c.updateBeliefs((++k & 1) ? 1.01e-3 : 0.99e-3));
  }
}
BENCHMARK(BM_UpdateBeliefsExactJitter)->Arg(3)->ArgName("p");

/// Exact integrator recomputing its matrix exponential every call (h alternating by 10 %).
void BM_ExactRecompute(benchmark::State& state)
{
  aic::ActiveInferenceController c = makeController(static_cast<int>(state.range(0)), params::Integrator::kExact);
  int k = 0;
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(c.updateBeliefs((++k & 1) ? 1.1e-3 : 1e-3));
  }
}
BENCHMARK(BM_ExactRecompute)->DenseRange(1, 5)->ArgName("p");

void BM_UpdateAction(benchmark::State& state)
{
  aic::ActiveInferenceController c = makeController(static_cast<int>(state.range(0)), params::Integrator::kEuler);
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(c.updateAction(0.02));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_UpdateAction)->DenseRange(1, 5)->ArgName("p");

void BM_GeneralizerUpdate(benchmark::State& state)
{
  aic::Generalizer g(base::kYDim, static_cast<int>(state.range(0)));
  Eigen::Matrix<double, base::kYDim, 1> y = Eigen::Matrix<double, base::kYDim, 1>::Constant(0.5);
  for (auto _ : state)
  {
    y(0) += 1e-6;
    benchmark::DoNotOptimize(g.update(y, 0.02));
  }
}
BENCHMARK(BM_GeneralizerUpdate)->Arg(3)->ArgName("p");

void BM_FreeEnergy(benchmark::State& state)
{
  aic::ActiveInferenceController c = makeController(3, params::Integrator::kEuler);
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(c.freeEnergy());
  }
}
BENCHMARK(BM_FreeEnergy);
}  // namespace

BENCHMARK_MAIN();
