/**
 * \file learned_model.cpp
 * \brief The jackal_AIC node's ~save_learned_model and ~reset_learned_model services
 *        (include/jackal_aic/ros/learned_model.hpp).
 */
#include "jackal_aic/ros/learned_model.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <std_srvs/Trigger.h>

#include "jackal_aic/aic/learned_model_overlay.hpp"
#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/params/aic_params.hpp"

namespace jackal_aic
{
namespace node
{
namespace
{
/// Write `text` to `path` through a temporary file in the same folder renamed over it (atomic on
/// POSIX: a reader sees the old file or the new one). Creates missing folders.
/// \throw std::runtime_error naming the path and the system's reason
void writeAtomically(const std::string& path, const std::string& text)
{
  const std::filesystem::path target(path);
  std::error_code ec;
  if (target.has_parent_path())
  {
    std::filesystem::create_directories(target.parent_path(), ec);
    if (ec)
    {
      throw std::runtime_error("cannot create " + target.parent_path().string() + ": " + ec.message());
    }
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    out.flush();
    if (!out)
    {
      throw std::runtime_error("cannot write " + tmp + ": " + std::strerror(errno));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
  {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path + ": " + reason);
  }
}
}  // namespace

LearnedModelService::LearnedModelService(ros::NodeHandle& pnh, std::mutex& mutex, loop::ControlLoop& loop,
                                         const std::string& file)
  : mutex_(mutex), loop_(loop), file_(file.empty() ? defaultFile() : file)
{
  save_server_ = pnh.advertiseService<std_srvs::Trigger::Request, std_srvs::Trigger::Response>(
      "save_learned_model", [this](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
        res.success = save(&res.message);
        return true;
      });
  reset_server_ = pnh.advertiseService<std_srvs::Trigger::Request, std_srvs::Trigger::Response>(
      "reset_learned_model", [this](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
        res.success = reset(&res.message);
        return true;
      });
}

std::string LearnedModelService::defaultFile()
{
  const char* ros_home = std::getenv("ROS_HOME");
  std::string base;
  if (ros_home != nullptr && *ros_home != '\0')
  {
    base = ros_home;
  }
  else
  {
    const char* home = std::getenv("HOME");
    base = std::string(home != nullptr ? home : ".") + "/.ros";
  }
  return base + "/jackal_aic/learned_model.yaml";
}

bool LearnedModelService::save(std::string* message)
{
  aic::LearnedModel learned;
  bool latency_on = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const aic::ActiveInferenceController& controller = loop_.controller();
    learned = aic::learnedModel(controller);
    latency_on = params::learnsLatency(controller.params());
    if (!controller.params().separation_learner.enabled && !latency_on)
    {
      *message = "learn_wheel_separation and learn_latency (belief_model: robot) are off: nothing learned to save";
      ROS_WARN_STREAM("jackal_AIC: ~save_learned_model: " << *message);
      return false;
    }
  }
  const char* const no_start = "latency not learned yet (no start from rest seen)";
  if (!learned.wheel_separation && !learned.latency)
  {
    *message = std::string(no_start) + " and learn_wheel_separation is off: nothing learned to save";
    ROS_WARN_STREAM("jackal_AIC: ~save_learned_model: " << *message);
    return false;
  }
  try
  {
    writeAtomically(file_, aic::learnedModelOverlay(learned));
  }
  catch (const std::exception& e)
  {
    *message = std::string("not saved: ") + e.what();
    ROS_ERROR_STREAM("jackal_AIC: ~save_learned_model: " << *message);
    return false;
  }
  std::ostringstream text;
  if (learned.wheel_separation)
  {
    text << "wheel_separation " << *learned.wheel_separation << " m";
  }
  if (learned.latency)
  {
    text << (learned.wheel_separation ? ", " : "") << "latency " << *learned.latency << " s (" << learned.latency_starts
         << (learned.latency_starts == 1 ? " start)" : " starts)");
  }
  text << " written to " << file_ << " (load it with learned_model:=" << file_ << ")";
  if (latency_on && !learned.latency)
  {
    text << "; " << no_start << ": not written";
  }
  *message = text.str();
  ROS_INFO_STREAM("jackal_AIC: ~save_learned_model: " << *message);
  return true;
}

bool LearnedModelService::reset(std::string* message)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  const params::AicParams& params = loop_.controller().params();
  const bool separation_on = params.separation_learner.enabled;
  const bool latency_on = params::learnsLatency(params);
  if (!separation_on && !latency_on)
  {
    *message = "learn_wheel_separation and learn_latency (belief_model: robot) are off: nothing learned to reset";
    ROS_WARN_STREAM("jackal_AIC: ~reset_learned_model: " << *message);
    return false;
  }
  const double separation_before = loop_.controller().separationLearner().separation();
  const double latency_before = loop_.controller().latencyLearner().latency();
  const bool latency_learned = loop_.controller().latencyLearner().starts() > 0;
  loop_.resetLearning();
  std::ostringstream text;
  const char* separator = "";
  if (separation_on)
  {
    text << "learned wheel separation " << separation_before << " m forgotten; b_hat "
         << loop_.controller().separationLearner().separation() << " m (wheel_separation)";
    separator = "; ";
  }
  if (latency_on)
  {
    if (latency_learned)
    {
      text << separator << "learned latency " << latency_before << " s forgotten; L ";
    }
    else
    {
      text << separator << "no latency learned yet; L ";
    }
    text << loop_.controller().wheelLoop().latency() << " s (latency)";
  }
  if (params.gyro_bias.enabled)
  {
    text << "; gyro offset back to 0 (learned again at the next standstill)";
  }
  if (params.belief_model == params::BeliefModel::kRobot)
  {
    text << "; the robot model's shortfalls (d and the turn shortfalls e), slip ratio and gyro offset back to 0";
  }
  if (params.tip_guard.enabled)
  {
    text << "; tip-over guard's learned bounds forgotten";
  }
  *message = text.str();
  ROS_INFO_STREAM("jackal_AIC: ~reset_learned_model: " << *message);
  return true;
}

}  // namespace node
}  // namespace jackal_aic
