/**
 * \file output_enable.cpp
 * \brief The jackal_AIC node's ~enable_output service (include/jackal_aic/ros/output_enable.hpp).
 */
#include "jackal_aic/ros/output_enable.hpp"

#include <utility>

#include <diagnostic_updater/diagnostic_updater.h>
#include <std_srvs/SetBool.h>

namespace jackal_aic
{
namespace node
{
OutputEnable::OutputEnable(ros::NodeHandle& nh, ros::NodeHandle& pnh, std::mutex& mutex, safety::OutputGate& gate,
                           std::function<std::string()> restart, std::string topic)
  : mutex_(mutex), gate_(gate), restart_(std::move(restart)), topic_(std::move(topic))
{
  server_ = pnh.advertiseService<std_srvs::SetBool::Request, std_srvs::SetBool::Response>(
      "enable_output", [this](std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
        res.message = apply(req.data);
        res.success = true;
        return true;
      });
  updater_ = std::make_unique<diagnostic_updater::Updater>(nh, pnh);
  updater_->setHardwareID("jackal_aic");
  updater_->add("output gate", [this](diagnostic_updater::DiagnosticStatusWrapper& stat) {
    const std::lock_guard<std::mutex> lock(mutex_);
    stat.add("enabled", gate_.enabled() ? "true" : "false");
    stat.add("commands suppressed while disabled", gate_.suppressed());
    stat.add("switches", gate_.switches());
    stat.add("command topic", topic_);
    if (gate_.enabled())
    {
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "output enabled");
    }
    else
    {
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "output disabled by ~enable_output: publishing nothing on " + topic_);
    }
  });
  diagnostics_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { updater_->update(); });
}

OutputEnable::~OutputEnable() = default;

std::string OutputEnable::apply(bool enable)
{
  std::string text;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const safety::OutputGate::Change change = gate_.set(enable);
    if (!change.changed)
    {
      text = std::string("output already ") + (enable ? "enabled" : "disabled");
    }
    else if (!enable)
    {
      text = "output disabled: publishing nothing on " + topic_ +
             "; the controller restarts from the measured state when enabled";
    }
    else
    {
      text = "output enabled on " + topic_ + "; " + (change.restart ? restart_() : std::string());
    }
  }
  ROS_INFO_STREAM("jackal_AIC: ~enable_output " << (enable ? "true" : "false") << ": " << text);
  updater_->force_update();
  return text;
}

}  // namespace node
}  // namespace jackal_aic
