#pragma once
/**
 * \file tracking_error.hpp
 * \brief The RMS and maximum error of a measured body twist against a twist profile
 *        (doc/tools.md, 'Tracking benchmark'). ROS-free.
 */

#include <string>
#include <vector>

#include "jackal_aic/analysis/twist_profile.hpp"

namespace jackal_aic
{
namespace analysis
{
/// Error statistics of one velocity channel against its set point.
struct ChannelError
{
  double rms = 0.0;  ///< sqrt(mean over samples of (measured - set point)^2) [channel unit]
  double max = 0.0;  ///< max over samples of |measured - set point| [channel unit]
};

/// Tracking error of a measured body twist against a profile.
struct VelocityTrackingError
{
  ChannelError vx;  ///< forward speed [m/s]
  ChannelError wz;  ///< yaw rate [rad/s]
  int samples = 0;  ///< samples analysed (0 <= t <= duration)
};

/**
 * \brief RMS and maximum error of (vx[k], wz[k]) against the profile's set point in force at
 *        time[k] (zero-order hold), over the samples with 0 <= time[k] <= profile.duration.
 *        The mean is over samples: give evenly spaced samples (a fixed-rate sensor stream).
 * \param time  sample times in profile time [s], finite, strictly increasing
 * \param vx    measured forward speed [m/s], same size, finite
 * \param wz    measured yaw rate [rad/s], same size, finite
 * \throws std::invalid_argument on an invalid profile, mismatched sizes, non-finite or
 *         non-increasing values, or no sample in [0, duration]
 */
VelocityTrackingError velocityTrackingError(const TwistProfile& profile, const std::vector<double>& time,
                                            const std::vector<double>& vx, const std::vector<double>& wz);

/// One-line JSON {"vx": {"rms", "max"}, "wz": {"rms", "max"}, "samples"}.
std::string toJson(const VelocityTrackingError& error);
}  // namespace analysis
}  // namespace jackal_aic
