#pragma once
/**
 * \file steady_estimate.hpp
 * \brief The error of an estimate (a belief) of the body twist against the truth over a
 *        profile's steady segments (doc/tools.md, 'Tracking benchmark'). ROS-free.
 */

#include <limits>
#include <string>
#include <vector>

#include "jackal_aic/analysis/twist_profile.hpp"

namespace jackal_aic
{
namespace analysis
{
/// Error of an estimate of one velocity channel against the truth over its steady segments.
struct SteadyEstimateChannel
{
  double mean_abs = 0.0;  ///< mean over the steady samples of |estimate - truth| [channel unit]
  double max_abs = 0.0;   ///< max over the steady samples of |estimate - truth| [channel unit]
  int samples = 0;        ///< steady samples with a finite estimate
  int segments = 0;       ///< steady segments with at least one such sample
};

/// steadyEstimateError(): both channels, and the samples left out for a non-finite estimate.
struct SteadyEstimateError
{
  SteadyEstimateChannel vx;  ///< forward speed [m/s]
  SteadyEstimateChannel wz;  ///< yaw rate [rad/s]
  int unavailable = 0;       ///< samples in [0, duration] whose estimate (either channel) is not finite
};

/**
 * \brief How far an estimate of the body twist (the controller's belief mu^(0)) is from the truth
 *        where the set point holds still: per channel, the mean and maximum of |estimate - truth|
 *        over that channel's steady segments, each from `settle` after a change of the channel's
 *        set point (or after profile time 0) to its next change (or the profile's end). The
 *        honest-belief measure of doc/experiments.md, 'Driving acceptance': a belief pulled to
 *        the goal shows up here wherever the robot does not reach the goal (a stall, a
 *        saturation, a biased wheel model).
 * \param profile    the set point (TwistProfile), valid
 * \param time       sample times in profile time [s], finite, strictly increasing
 * \param est_vx     estimated forward speed [m/s], same size; a non-finite sample (no estimate:
 *                   the controller not running) is left out and counted in `unavailable`
 * \param est_wz     estimated yaw rate [rad/s], same size; as est_vx
 * \param true_vx    true forward speed [m/s], same size, finite
 * \param true_wz    true yaw rate [rad/s], same size, finite
 * \param settle     time after a set-point change before the channel counts as steady [s],
 *                   finite and >= 0
 * \param until      samples at or after this profile time [s] are left out (not counted as
 *                   unavailable): the body's turnover (turnoverTime()), after which its twist is
 *                   a tumble no wheel-based belief describes; +infinity (default): none left out
 * \return per channel the figures (all 0 for a channel without a steady sample)
 * \throws std::invalid_argument on an invalid profile, mismatched sizes, non-finite or
 *         non-increasing times, a non-finite truth, an invalid settle or a NaN until
 */
SteadyEstimateError steadyEstimateError(const TwistProfile& profile, const std::vector<double>& time,
                                        const std::vector<double>& est_vx, const std::vector<double>& est_wz,
                                        const std::vector<double>& true_vx, const std::vector<double>& true_wz,
                                        double settle, double until = std::numeric_limits<double>::infinity());

/**
 * \brief When the body turned over: the time of the first sample whose `up` (the world z
 *        component of the body's z axis, the cosine of its tilt) is below 0, the body past 90
 *        degrees of tilt, on its side or its back. A robot on its wheels never gets there, on
 *        any slope it can drive.
 * \param time  sample times [s], finite, strictly increasing
 * \param up    the body's up component [-], same size, finite
 * \return that time [s], or +infinity when the body stays upright
 * \throws std::invalid_argument on mismatched sizes, non-finite or non-increasing times, or a
 *         non-finite up
 */
double turnoverTime(const std::vector<double>& time, const std::vector<double>& up);

/// JSON object of a SteadyEstimateError: {"vx": {"steady_mean_abs", "steady_max_abs", "samples",
/// "segments"}, "wz": {...}, "unavailable"} (units of the channels).
std::string toJson(const SteadyEstimateError& error);
}  // namespace analysis
}  // namespace jackal_aic
