/**
 * \file aic_timing.cpp
 * \brief CLI: how well the jackal_AIC belief loop keeps real time on the machine it runs on, beside a
 *        bare clock_nanosleep loop in the same run (doc/jackal_aic_node.md, 'Loops').
 *
 * For each rate, two PeriodicThreads run side by side for --duration seconds:
 *  - "belief": the node's belief loop without ROS (belief_schedule timer): under a mutex (as
 *    the node's), ControlLoop::beliefTimer() (catch-up scheduling, the belief steps), with a
 *    50 Hz sample and set point fed every 20 ms so the controller runs as in a 0.5 m/s step
 *    (the configuration given, default the schema's defaults);
 *  - "bare": the same thread and deadlines with an empty step (the floor set by the kernel's
 *    timer and scheduler).
 * Printed per loop: the achieved wake-up rate and, for the belief loop, the integration
 * step rate; the wake-up interval p50 / p99 / max; overruns (interval > 2 periods); and the
 * thread's CPU share of one core.
 *
 * Usage: aic_timing [--duration S] [--rates 1000,10000] [--config FILE] [--set KEY=VALUE ...]
 *                   [--priority N]
 * Exit: 0 ran; 1 the configuration is invalid or the controller cannot be built; 2 bad arguments.
 */
#include <chrono>
#include <memory>
#include <stdexcept>
#include <cstdio>
#include <fstream>
#include <exception>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "jackal_tools/cli.hpp"
#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/os/periodic_thread.hpp"

namespace
{
using jackal_aic::os::PeriodicStats;
using jackal_aic::os::PeriodicThread;
using jackal_aic::params::NodeParams;

/// CLOCK_MONOTONIC [s], the belief thread's own clock.
class MonotonicClock : public jackal_aic::loop::Clock
{
public:
  double now() const override { return 1e-9 * static_cast<double>(PeriodicThread::monotonicNow()); }
};

/// Commands go nowhere.
class NoOutput : public jackal_aic::loop::ControlLoop::Output
{
public:
  void command(const jackal_aic::loop::WheelCommand& /*command*/) override {}
};

/**
 * The node's belief loop without ROS (belief_schedule timer, src/ros/aic_node.cpp): each tick
 * takes a mutex as the node's does and runs ControlLoop::beliefTimer(); every 20 ms the tick
 * also feeds the loop a paired 50 Hz sample (wheels at 0.4 m/s) and the set point 0.5 m/s, so
 * the controller runs as it does on a robot in a 0.5 m/s step.
 */
class BeliefLoop
{
public:
  explicit BeliefLoop(NodeParams params) : names_{ "left", "right" }, velocity_(2, 0.0), empty_()
  {
    params.left_joints = { "left" };
    params.right_joints = { "right" };
    params.belief_schedule = jackal_aic::params::BeliefSchedule::kTimer;
    loop_ = std::make_unique<jackal_aic::loop::ControlLoop>(params, clock_, output_);
    wheels_ = 0.4 / params.aic.wheel_radius;
  }

  void tick(double interval)
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const double now = clock_.now();
    if (now - last_sample_ >= kSamplePeriod)
    {
      last_sample_ = now;
      const double set_point[6] = { 0.5, 0.0, 0.0, 0.0, 0.0, 0.0 };
      loop_->setPoint(set_point);
      jackal_aic::loop::ImuInput imu;
      imu.stamp = now;
      loop_->imu(imu);
      velocity_ = { wheels_, wheels_ };
      jackal_aic::loop::JointStateInput joints;
      joints.stamp = now;
      joints.name = &names_;
      joints.velocity = &velocity_;
      joints.position = &empty_;
      joints.effort = &empty_;
      loop_->jointState(joints);
    }
    loop_->beliefTimer(interval);
  }

  std::uint64_t steps() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return loop_->beliefSteps();
  }
  std::uint64_t runaways() const
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    return loop_->supervisor().runaways();
  }

private:
  static constexpr double kSamplePeriod = 0.02;  ///< the Jackal's 50 Hz sensors [s]
  mutable std::mutex mutex_;
  MonotonicClock clock_;
  NoOutput output_;
  std::unique_ptr<jackal_aic::loop::ControlLoop> loop_;
  std::vector<std::string> names_;
  std::vector<double> velocity_, empty_;
  double wheels_ = 0.0;
  double last_sample_ = -1.0;
};

void printRow(const char* loop, double rate, const PeriodicStats& s, double step_rate)
{
  char steps[32];
  if (step_rate >= 0.0)
  {
    std::snprintf(steps, sizeof(steps), "%.2f", step_rate);
  }
  else
  {
    std::snprintf(steps, sizeof(steps), "-");
  }
  std::printf("| %-6s | %8.0f | %10.2f | %6.2f %% | %10s | %8.3f | %8.3f | %8.3f | %8llu | %6.2f %% |\n", loop, rate,
              s.achievedRate(), 100.0 * s.achievedRate() / rate, steps, 1e3 * s.p50, 1e3 * s.p99, 1e3 * s.max,
              static_cast<unsigned long long>(s.overruns), 100.0 * s.cpuShare());
}
}  // namespace

int main(int argc, char** argv)
{
  jackal_aic::CommandLine cl("aic_timing", "aic_timing: the belief loop's real-time figures beside a bare "
                                           "clock_nanosleep loop");
  double duration = 10.0;
  std::vector<double> rates{ 1000.0, 10000.0 };
  std::string config;
  std::vector<std::string> overrides;
  int priority = 0;
  cl.option("duration", &duration, "seconds per rate, [0.1, 3600]");
  cl.list("rates", &rates, "loop rates [Hz], [1, 100000] (default 1000,10000)");
  cl.option("config", &config, "controller YAML (default: the schema's defaults, as the node without a YAML)");
  cl.overrides("set", &overrides, "override a controller parameter, e.g. --set tau=0.01");
  cl.option("priority", &priority, "SCHED_FIFO priority for both threads, 1..99 (0: none)");
  if (const int parsed = cl.parse(argc, argv); parsed >= 0)
  {
    return parsed;
  }
  if (!(duration >= 0.1 && duration <= 3600.0))
  {
    return cl.bad("--duration must be in [0.1, 3600] s");
  }
  for (double r : rates)
  {
    if (!(r >= 1.0 && r <= 100000.0))
    {
      return cl.bad("--rates: every rate must be in [1, 100000] Hz");
    }
  }
  if (priority < 0 || priority > 99)
  {
    return cl.bad("--priority must be in [0, 99]");
  }
  if (!config.empty() && !std::ifstream(config).good())
  {
    return cl.bad("--config: cannot read '" + config + "'");
  }

  if (config.empty() && !overrides.empty())
  {
    return cl.bad("--set needs --config");
  }
  NodeParams params;
  try
  {
    if (!config.empty())
    {
      params = jackal_aic::loadNodeParamsFiles({ config }, overrides);
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "aic_timing: " << e.what() << "\n";
    return 1;
  }

  const std::string source = config.empty() ? std::string(" (the node's defaults)") : ", " + config;
  std::printf("aic_timing: %.1f s per rate; controller p = %d, integrator %s%s\n", duration, params.aic.embedding_order,
              jackal_aic::params::toString(params.aic.integrator).c_str(), source.c_str());
  std::printf("| loop   | rate [Hz] | achieved [Hz] | of nominal | steps [Hz] | p50 [ms] | p99 [ms] | max [ms] | "
              "overruns "
              "| CPU (1 core) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const double rate : rates)
  {
    params.aic.belief_rate = rate;
    std::unique_ptr<BeliefLoop> loop;
    try
    {
      loop = std::make_unique<BeliefLoop>(params);
    }
    catch (const std::exception& e)
    {
      std::cerr << "aic_timing: cannot build the controller: " << e.what() << "\n";
      return 1;
    }
    PeriodicThread belief([&loop](double interval) { loop->tick(interval); }, "aic_belief");
    PeriodicThread bare([](double) {}, "aic_bare");
    for (PeriodicThread* t : { &belief, &bare })
    {
      const std::string message = t->start(rate, priority);
      if (!message.empty())
      {
        std::fprintf(stderr, "aic_timing: %s\n", message.c_str());
      }
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(duration));
    belief.stop();
    bare.stop();
    const PeriodicStats b = belief.stats();
    const double step_rate = b.elapsed > 0.0 ? static_cast<double>(loop->steps()) / b.elapsed : 0.0;
    printRow("belief", rate, b, step_rate);
    printRow("bare", rate, bare.stats(), -1.0);
    if (loop->runaways() > 0)
    {
      std::fprintf(stderr, "aic_timing: %llu runaway(s) in the belief loop at %.0f Hz\n",
                   static_cast<unsigned long long>(loop->runaways()), rate);
    }
  }
  return 0;
}
