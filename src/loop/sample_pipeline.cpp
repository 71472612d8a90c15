/**
 * \file sample_pipeline.cpp
 * \brief One sensor sample through generalizer, controller and fault monitor
 *        (include/jackal_aic/loop/sample_pipeline.hpp).
 */
#include "jackal_aic/loop/sample_pipeline.hpp"

#include <limits>
#include <stdexcept>
#include <string>

#include "jackal_aic/loop/fault_test.hpp"

namespace jackal_aic
{
namespace loop
{
namespace
{
/// No bound on the reference path's rate (ReferenceModel::setTipBounds).
constexpr double kNone = std::numeric_limits<double>::infinity();

/// Throws std::invalid_argument listing every violation of both sets, if any.
void requireValid(const params::AicParams& aic, const params::FdiParams& fdi)
{
  std::string message;
  for (const auto& violations : { aic.validate(), fdi.validate() })
  {
    for (const auto& v : violations)
    {
      message += (message.empty() ? "" : "; ") + v.toString();
    }
  }
  if (!message.empty())
  {
    throw std::invalid_argument("invalid parameters: " + message);
  }
}

/// aic.gyro_bias after requireValid(aic, fdi): the pipeline's first member to need the settings
/// reports every violation of both sets, not only the estimator's.
const params::GyroBiasEstimatorParams& validGyroBias(const params::AicParams& aic, const params::FdiParams& fdi)
{
  requireValid(aic, fdi);
  return aic.gyro_bias;
}
}  // namespace

SamplePipeline::SamplePipeline(const params::AicParams& aic, const params::FdiParams& fdi)
  : gyro_bias_(validGyroBias(aic, fdi)), tip_guard_(aic.tip_guard), pitch_bias_(aic.gyro_bias)
{
  controller_ = std::make_unique<aic::ActiveInferenceController>(aic);
  generalizer_ = std::make_unique<aic::Generalizer>(base::kYDim, aic.embedding_order);
  fault_monitor_ = std::make_unique<safety::FaultMonitor>(fdi, aic);
}

aic::Generalizer::Status SamplePipeline::generalize(base::Vector5* y, double h, bool imu_ok, bool restart,
                                                    bool* restarted)
{
  raw_gyro_ = (*y)(base::kGyroZ);
  if (imu_ok)
  {
    // The generative model's sensor row y_gyro = theta_dot + beta, with the offset learned at rest
    // removed first; when that removal changes, the controller's own offset belief (the robot
    // model's beta: what remains) takes the change back, so the two are not counted twice.
    const double removed = controller_->params().gyro_bias.enabled ? gyro_bias_.offset() : 0.0;
    (*y)(base::kGyroZ) -= removed;
    if (removed != removed_offset_)
    {
      controller_->gyroOffsetRemoved(removed - removed_offset_);
      removed_offset_ = removed;
    }
  }
  if (!imu_ok)
  {
    // Degraded mode: the gyro channel is masked; the wheels' yaw rate keeps its history smooth.
    (*y)(base::kGyroZ) =
        controller_->model().twistFromWheels(base::Vector2((*y)(base::kOmegaLeft), (*y)(base::kOmegaRight)))(2);
  }
  const bool restart_now = restart || !generalizer_->initialized();
  if (restart_now)
  {
    generalizer_->reset();
  }
  if (restarted != nullptr)
  {
    *restarted = restart_now;
  }
  return generalizer_->update(*y, h);
}

SamplePipeline::Measurement SamplePipeline::measure(const base::Vector5& y, double h, bool imu_ok, bool wheels_repeated)
{
  Measurement m;
  m.accepted = controller_->setMeasurement(generalizer_->yTilde(), wheels_repeated);
  if (!m.accepted)
  {
    return m;
  }
  fault_monitor_->setImuAvailable(imu_ok);
  if (controller_->params().separation_learner.enabled)
  {
    fault_monitor_->setWheelSeparation(controller_->model().wheelSeparation());  // the learned model
  }
  const int isolated_before = fault_monitor_->isolatedChannel();
  m.event = testSample(fault_monitor_.get(), *controller_, y, h);
  controller_->setSensorMask(fault_monitor_->sensorMask());
  controller_->setFaultState(fault_monitor_->awaitingConfirmation(), fault_monitor_->faultPresent());
  if (controller_->params().gyro_bias.enabled)
  {
    const bool gyro_ok =
        imu_ok && (fault_monitor_->sensorMask() & (1u << base::kGyroZ)) != 0 && !fault_monitor_->faultPresent();
    const base::Vector2& a = controller_->action();
    gyro_bias_.update(h, raw_gyro_, y(base::kOmegaLeft), y(base::kOmegaRight), a(0), a(1), gyro_ok);
  }
  if (m.event != safety::FaultMonitor::Event::kNone)
  {
    m.event_channel =
        m.event == safety::FaultMonitor::Event::kRestored ? isolated_before : fault_monitor_->suspectedChannel();
  }
  return m;
}

void SamplePipeline::guardTip(const base::Vector5& y, double pitch_rate, double h, bool imu_ok, double up_force)
{
  const params::AicParams& p = controller_->params();
  if (h > 0.0)
  {
    if (p.gyro_bias.enabled)
    {
      const base::Vector2& a = controller_->action();
      pitch_bias_.update(h, pitch_rate, y(base::kOmegaLeft), y(base::kOmegaRight), a(0), a(1), imu_ok);
    }
    const double speed =
        controller_->model().twistFromWheels(base::Vector2(y(base::kOmegaLeft), y(base::kOmegaRight)))(0);
    tip_guard_.update(h, pitch_rate - (p.gyro_bias.enabled ? pitch_bias_.offset() : 0.0), speed, imu_ok, up_force);
  }
  controller_->setTipBounds(p.tip_guard.enabled ? tip_guard_.frontBound() : kNone,
                            p.tip_guard.enabled ? tip_guard_.rearBound() : kNone);
  controller_->setTurnedOver(p.tip_guard.enabled && tip_guard_.turnedOver());
}

void SamplePipeline::resetTipGuard()
{
  tip_guard_.reset();
  pitch_bias_.reset();
  controller_->setTipBounds(kNone, kNone);
  controller_->setTurnedOver(false);
}

void SamplePipeline::restartHistory()
{
  generalizer_->reset();
  fault_monitor_->reset();
}

void SamplePipeline::activate(const base::Vector2& wheels, const base::Vector3& goal)
{
  controller_->reset();
  controller_->setGoal(goal);
  controller_->setMeasurement(generalizer_->yTilde());
  base::MuTilde mu = base::MuTilde::Zero(base::kMuDim, controller_->params().numOrders());
  mu.col(0) = controller_->model().twistFromWheels(wheels);
  controller_->setBeliefs(mu);
  controller_->startReference(mu.col(0));  // the expected path starts where the robot is
  controller_->setAction(wheels);          // bumpless start from the measured wheel speeds
}

bool SamplePipeline::setParams(const params::AicParams& aic, const params::FdiParams& fdi)
{
  requireValid(aic, fdi);
  controller_->setParams(aic);
  gyro_bias_.setParams(aic.gyro_bias);
  tip_guard_.setParams(aic.tip_guard);
  pitch_bias_.setParams(aic.gyro_bias);
  if (!aic.gyro_bias.enabled)
  {
    gyro_bias_.reset();  // off: the gyro is used as it reads, and a later start learns afresh
    pitch_bias_.reset();
  }
  fault_monitor_->setParams(fdi, aic);
  if (aic.embedding_order == generalizer_->embeddingOrder())
  {
    return false;
  }
  generalizer_ = std::make_unique<aic::Generalizer>(base::kYDim, aic.embedding_order);
  return true;
}
}  // namespace loop
}  // namespace jackal_aic
