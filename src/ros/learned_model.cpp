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

#include "jackal_aic/loop/control_loop.hpp"
#include "jackal_aic/aic/separation_learner.hpp"

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
  double b_hat = 0.0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!loop_.controller().params().separation_learner.enabled)
    {
      *message = "learn_wheel_separation is off: nothing learned to save";
      ROS_WARN_STREAM("jackal_AIC: ~save_learned_model: " << *message);
      return false;
    }
    b_hat = loop_.controller().separationLearner().separation();
  }
  try
  {
    writeAtomically(file_, aic::learnedSeparationOverlay(b_hat));
  }
  catch (const std::exception& e)
  {
    *message = std::string("not saved: ") + e.what();
    ROS_ERROR_STREAM("jackal_AIC: ~save_learned_model: " << *message);
    return false;
  }
  std::ostringstream text;
  text << "wheel_separation " << b_hat << " m written to " << file_ << " (load it with learned_model:=" << file_ << ")";
  *message = text.str();
  ROS_INFO_STREAM("jackal_AIC: ~save_learned_model: " << *message);
  return true;
}

bool LearnedModelService::reset(std::string* message)
{
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!loop_.controller().params().separation_learner.enabled)
  {
    *message = "learn_wheel_separation is off: nothing learned to reset";
    ROS_WARN_STREAM("jackal_AIC: ~reset_learned_model: " << *message);
    return false;
  }
  const double before = loop_.controller().separationLearner().separation();
  loop_.resetLearning();
  std::ostringstream text;
  text << "learned wheel separation " << before << " m forgotten; b_hat "
       << loop_.controller().separationLearner().separation() << " m (wheel_separation)";
  if (loop_.controller().params().gyro_bias.enabled)
  {
    text << "; gyro offset back to 0 (learned again at the next standstill)";
  }
  if (loop_.controller().params().belief_model == params::BeliefModel::kRobot)
  {
    text << "; the robot model's shortfalls, slip ratio and gyro offset back to 0";
  }
  if (loop_.controller().params().tip_guard.enabled)
  {
    text << "; tip-over guard's learned bounds forgotten";
  }
  *message = text.str();
  ROS_INFO_STREAM("jackal_AIC: ~reset_learned_model: " << *message);
  return true;
}

}  // namespace node
}  // namespace jackal_aic
