#pragma once
/**
 * \file stop_reversal.hpp
 * \brief How far a robot moves against its previous direction after it is told to stop: the
 *        reversal a controller that predicts the set point past a ramp's end causes when the ramp
 *        ends in a stop (doc/active_inference.md, 'Where it is behind', a ramp's end; doc/tools.md,
 *        'Tracking benchmark'). ROS-free.
 */

#include <string>
#include <vector>

#include "jackal_aic/analysis/twist_profile.hpp"

namespace jackal_aic
{
namespace analysis
{
/// The window after each stop the tools search for a reversal (closed_loop_run's tracking.stops,
/// aic_track_metrics' stops) [s]: longer than a latency and a held slope's 1.25 change intervals.
constexpr double kStopWindow = 1.0;

/// stopReversal(): the profile's stops and the worst reversal after them.
struct StopReversal
{
  int stops = 0;                ///< changes of the linear set point from nonzero to 0 in the profile
  double reverse_speed = 0.0;   ///< largest true speed against the direction before the stop [m/s], >= 0
  double reverse_travel = 0.0;  ///< largest distance travelled against it after one stop [m], >= 0
  double window = 0.0;          ///< the window after each stop that was searched [s]
};

/**
 * \brief The reversal after each stop of a profile: for every change of the linear set point from
 *        a nonzero value v to 0 at time t_s, the true forward speed's component against sign(v)
 *        over [t_s, min(t_s + window, the set point's next change)]; its largest value and the
 *        largest integral of it (rectangle rule over the samples' spacing). A robot that stops
 *        without moving back scores 0.
 * \param profile  the set point (TwistProfile), valid
 * \param time     sample times in profile time [s], finite, strictly increasing
 * \param true_vx  true forward speed [m/s], same size, finite
 * \param window   how long after each stop to look [s], finite and > 0
 * \return the profile's stops and the worst reversal (all 0 without a stop)
 * \throws std::invalid_argument on an invalid profile, mismatched sizes, non-finite or
 *         non-increasing times, a non-finite speed or an invalid window
 */
StopReversal stopReversal(const TwistProfile& profile, const std::vector<double>& time,
                          const std::vector<double>& true_vx, double window);

/// One-line JSON {"stops", "reverse_speed_max" [m/s], "reverse_travel_max" [m], "window" [s]}.
std::string toJson(const StopReversal& reversal);
}  // namespace analysis
}  // namespace jackal_aic
