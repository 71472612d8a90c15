#pragma once
/**
 * \file path_drift.hpp
 * \brief The ideal path of a twist profile (its commanded twist integrated exactly) and the drift
 *        of a measured planar path from it (doc/tools.md, 'Tracking benchmark'). ROS-free.
 */

#include <string>
#include <vector>

#include "jackal_aic/analysis/twist_profile.hpp"

namespace jackal_aic
{
namespace analysis
{
/// A planar pose.
struct Pose2D
{
  double x = 0.0;        ///< [m]
  double y = 0.0;        ///< [m]
  double heading = 0.0;  ///< yaw [rad], continuous (not wrapped)
};

/**
 * \brief The ideal path: the pose obtained by integrating the profile's set point exactly
 *        (unicycle kinematics x' = vx cos(theta), y' = vx sin(theta), theta' = wz, piecewise
 *        constant twist: straight lines and circular arcs) from `start` at time t_start.
 * \param t_start  time of the start pose, profile time [s], finite
 * \param times    times at which the pose is wanted [s], >= t_start, non-decreasing
 * \return one pose per time; the heading is continuous (a full turn adds 2 pi)
 * \throws std::invalid_argument on an invalid profile, non-finite values or unsorted times
 */
std::vector<Pose2D> idealPath(const TwistProfile& profile, const Pose2D& start, double t_start,
                              const std::vector<double>& times);

/// Drift of a measured path from the ideal one.
struct PathDrift
{
  double final_position_error = 0.0;  ///< |p - p_ideal| at the last analysed sample [m]
  double max_position_error = 0.0;    ///< max over the analysed samples of |p - p_ideal| [m]
  /// heading - heading_ideal at the last analysed sample [rad], both continuous (a turn short
  /// by a full revolution is -2 pi, not 0); positive: turned further left than commanded
  double final_heading_error = 0.0;
  double ideal_length = 0.0;  ///< length of the ideal path over the analysed span [m]
  int samples = 0;            ///< samples analysed
  double t_start = 0.0;       ///< time of the start pose [s]
  std::vector<double> time;   ///< times of the analysed samples [s]
  std::vector<Pose2D> ideal;  ///< ideal pose at each of them
};

/**
 * \brief Drift of a measured planar pose (x[k], y[k], heading[k]) from the profile's ideal path.
 *
 * The ideal path starts at the measured pose of the last sample with time <= 0 (the first
 * sample if none), at that sample's time; before profile time 0 the set point is 0. Analysed:
 * that sample and every later one with time <= profile.duration. The measured heading may be
 * wrapped (e.g. to (-pi, pi]); it is unwrapped before the comparison.
 * \param time     sample times, profile time [s], finite, strictly increasing
 * \param x, y     measured position [m], same size, finite
 * \param heading  measured yaw [rad], same size, finite
 * \throws std::invalid_argument on an invalid profile, mismatched sizes, non-finite or
 *         non-increasing values, fewer than one sample at or before the profile's end
 */
PathDrift pathDrift(const TwistProfile& profile, const std::vector<double>& time, const std::vector<double>& x,
                    const std::vector<double>& y, const std::vector<double>& heading);

/// One-line JSON {"final_position_error", "max_position_error", "final_heading_error",
/// "ideal_length", "samples"} (not the ideal poses).
std::string toJson(const PathDrift& drift);
}  // namespace analysis
}  // namespace jackal_aic
