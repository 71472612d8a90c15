/// Verifies that the update path allocates no heap memory: a global operator new that counts
/// allocations while armed. Covers the exact integrator's matrix-exponential recomputation too.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/generalizer.hpp"
#include "jackal_aic/loop/sample_pipeline.hpp"

namespace
{
std::atomic<bool> g_armed{ false };
std::atomic<long> g_allocations{ 0 };

/// Counts heap allocations made between construction and count().
class AllocationCounter
{
public:
  AllocationCounter()
  {
    g_allocations = 0;
    g_armed = true;
  }
  ~AllocationCounter() { g_armed = false; }
  long count()
  {
    g_armed = false;
    return g_allocations.load();
  }
};
}  // namespace

// glibc: interpose malloc/calloc/realloc (operator new and Eigen's aligned_malloc both end
// here) and forward to the real allocator; count while armed.
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t n, std::size_t size);
extern "C" void* __libc_realloc(void* p, std::size_t size);

extern "C" void* malloc(std::size_t size)
{
  if (g_armed.load(std::memory_order_relaxed))
  {
    ++g_allocations;
  }
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t n, std::size_t size)
{
  if (g_armed.load(std::memory_order_relaxed))
  {
    ++g_allocations;
  }
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t size)
{
  if (g_armed.load(std::memory_order_relaxed))
  {
    ++g_allocations;
  }
  return __libc_realloc(p, size);
}

namespace
{
void* volatile g_sink = nullptr;
}

using namespace jackal_aic;

TEST(NoAlloc, CounterWorks)
{
  AllocationCounter counter;
  int* from_new = new int(3);
  g_sink = from_new;
  g_sink = std::malloc(64);
  const long n = counter.count();
  std::free(g_sink);
  delete from_new;
  EXPECT_EQ(n, 2);  // the counter itself can fail (operator new and malloc are both seen)
}

TEST(NoAlloc, ControllerUpdatePath)
{
  for (int p = 1; p <= base::kMaxEmbeddingOrder; ++p)
  {
    for (params::Integrator integ : { params::Integrator::kEuler, params::Integrator::kExact })
    {
      params::AicParams params;
      params.embedding_order = p;
      params.var_mu.assign(p + 1, 2.0);
      params.var_y.assign(p + 1, 2.0);
      params.integrator = integ;
      aic::ActiveInferenceController c(params);
      base::YTilde y = base::YTilde::Zero(base::kYDim, p + 1);
      y(1, 0) = 1.0;
      y(2, 0) = 2.0;
      AllocationCounter counter;
      c.setGoal(base::Vector3(0.5, 0.0, 0.1));
      c.setMeasurement(y);
      double h = 0.001;
      for (int k = 0; k < 200; ++k)
      {
        h = (k % 4 == 0) ? 0.001 :
                           (k % 4 == 1 ? 0.00102 : (k % 4 == 2 ? 0.01 : 0.0001));  // series reuse, recomputations
        c.updateBeliefs(h);
        if (k % 20 == 0)
        {
          c.updateAction(0.02);
        }
      }
      volatile double sink = c.freeEnergy() + c.aDot()(0) + c.muDot()(0, 0) + c.epsY()(0, 0) + c.epsMu()(0, 0);
      (void)sink;
      EXPECT_EQ(counter.count(), 0) << "p=" << p << " integrator=" << params::toString(integ);
      if (integ == params::Integrator::kExact)
      {
        EXPECT_GE(c.exactRecomputeCount(), 3u);
      }
    }
  }
}

TEST(NoAlloc, GeneralizerUpdate)
{
  aic::Generalizer g(5, 5);
  Eigen::Matrix<double, 5, 1> y;
  AllocationCounter counter;
  for (int k = 0; k < 100; ++k)
  {
    y.setConstant(0.1 * k);
    g.update(y, k % 2 ? 0.02 : 0.021);
  }
  EXPECT_EQ(counter.count(), 0);
}

TEST(NoAlloc, SamplePipelinePerSample)
{
  // The node's per-sample path: degraded-mode fill, generalization, measurement, FDI test and
  // channel mask, with and without the IMU, including an isolation (a biased gyro).
  loop::SamplePipeline pipeline(params::recommendedAicParams(), params::FdiParams());
  base::Vector5 y = base::Vector5::Zero();
  y(base::kOmegaLeft) = y(base::kOmegaRight) = 5.0;
  pipeline.generalize(&y, 0.02, true, false);
  pipeline.activate(base::Vector2(5.0, 5.0), base::Vector3(0.49, 0.0, 0.0));
  AllocationCounter counter;
  for (int k = 0; k < 200; ++k)
  {
    base::Vector5 s = base::Vector5::Zero();
    s(base::kOmegaLeft) = s(base::kOmegaRight) = 5.0;
    s(base::kGyroZ) = k > 50 ? 1.0 : 0.0;
    const bool imu_ok = k >= 40 || k % 7 != 0;  // some IMU-less samples first
    pipeline.generalize(&s, 0.02, imu_ok, false);
    pipeline.measure(s, 0.02, imu_ok);
    pipeline.controller().updateBeliefs(0.001);
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_EQ(pipeline.faultMonitor().isolatedChannel(), base::kGyroZ);  // the path with an isolation ran
}

TEST(NoAlloc, UnbiasedBeliefsAndLearningUpdatePath)
{
  // belief_model unbiased (the action delay line) and learn_wheel_separation (the learner and the
  // model's rebuild when b_hat moves, with the exact integrator's recomputation), and
  // learn_precision (the precision learner and the rebuild when a precision moves).
  for (params::Integrator integ : { params::Integrator::kEuler, params::Integrator::kExact })
  {
    params::AicParams params = params::recommendedAicParams();
    params.belief_model = params::BeliefModel::kUnbiased;
    params.separation_learner.enabled = true;
    params.precision_learner.enabled = true;
    params.reference.delay = 0.085;
    params.goal_response_time_constant = 0.05;
    params.integrator = integ;
    aic::ActiveInferenceController c(params);
    base::YTilde y = base::YTilde::Zero(base::kYDim, params.numOrders());
    y(base::kGyroZ, 0) = 0.5;   // the wheels' turn at b_hat = wheel_separation: 0.5 / 1.4
    y(base::kGyroZ, 1) = 1e-3;  // a live gyro (a rate of exactly 0 is a stuck one: no learning)
    y(base::kOmegaLeft, 0) = (0.5 - 0.25 * 1.4 * params.wheel_separation) / params.wheel_radius;
    y(base::kOmegaRight, 0) = (0.5 + 0.25 * 1.4 * params.wheel_separation) / params.wheel_radius;
    AllocationCounter counter;
    c.setGoal(base::Vector3(0.5, 0.0, 0.5));
    c.setMeasurement(y);
    for (int k = 0; k < 2000; ++k)
    {
      c.updateBeliefs(0.001);
      if (k % 20 == 0)
      {
        c.updateAction(0.02);
      }
    }
    const std::uint64_t steps = c.separationLearner().learningSteps();
    c.setLearnedSeparation(0.7);
    c.resetLearning();
    volatile double sink = c.freeEnergy() + c.aDot()(0) + c.priorGoal()(0);
    (void)sink;
    EXPECT_EQ(counter.count(), 0) << "integrator=" << params::toString(integ);
    EXPECT_GT(steps, 0u);
    EXPECT_GT(c.precisionLearner().learningSteps(), 0u);
    EXPECT_NE(c.precisionY()(base::kGyroZ, 0), params.precisionY()(base::kGyroZ, 0));  // it learned and rebuilt
  }
}

TEST(NoAlloc, ControllerStagesUpdatePath)
{
  // Each stage on its own, every option on: the reference model's and the action's delay lines
  // (fixed capacity, run past it), the goal's expected response, the action prior, the release at
  // rest, all clamps, the slew limit.
  params::ReferenceModelParams rp;
  rp.generalized_goal = true;
  rp.goal_lead = 0.05;
  rp.time_constant = 0.1;
  rp.delay = params::kMaxReferenceDelay;
  aic::ReferenceModel reference(rp);
  aic::ActionDelayLine line(0.085);
  params::ActionPriorParams ap;
  ap.gain = 1.0;
  ap.time_constant = 0.06;
  const aic::ActionPrior prior(ap);
  const aic::RestRelease release(0.5);
  aic::GoalResponse response(0.05);
  params::AntiWindupParams aw;
  aw.max_action_lead = 1.0;
  aw.max_action_lead_turn = 0.5;
  const aic::AntiWindup anti_windup(aw, 5.0);
  params::ActionSlewLimitParams sp;
  sp.max_rate = 20.0;
  const aic::ActionSlewLimit slew(sp);
  const aic::SkidSteerModel model(0.098, 1.0, 0.5621);
  base::Vector2 a_F = base::Vector2::Zero();
  base::Vector2 a = base::Vector2::Zero();
  AllocationCounter counter;
  reference.start(base::Vector3(0.1, 0.0, 0.0));
  line.restart(base::Vector3::Zero());
  for (int k = 0; k < 3 * aic::ReferenceModel::kLine; ++k)
  {
    reference.setGoal(base::Vector3((k / 500) % 2 == 0 ? 1.0 : 0.0, 0.0, 0.5), base::Vector3(0.5, 0.0, 0.0));
    reference.advance(0.001);
    response.advance(0.001, reference.attractorGoal(), reference.attractorRate());
    if (k % 2 == 0)
    {
      const base::Vector2 a_ff = prior.wheels(model, reference);
      a_F = release.apply(a_F, reference.target(), 0.002);
      const aic::AntiWindup::Result r = anti_windup.apply(
          a_F, a_F + base::Vector2(0.1, -0.1), base::Vector2(50.0, -50.0), a_ff, base::Vector2(1.0, 2.0), true, true);
      const aic::ActionSlewLimit::Result s =
          slew.apply(a, r.command, a_F, r.free_energy_part, base::Vector2(50.0, -50.0), a_ff, 0.002);
      a_F = s.free_energy_part;
      a = s.command;
      line.record(0.002, model.twistFromWheels(a));
    }
  }
  volatile double sink = reference.attractorGoal()(0) + line.delayed()(0) + a_F(0) + response.goal()(0);
  (void)sink;
  EXPECT_EQ(counter.count(), 0);
}
