#pragma once
/**
 * \file tracking_metrics.hpp
 * \brief Tracking of a twist set-point profile: the profile itself (a CSV of t, vx, wz played
 *        with zero-order hold), the RMS and maximum error of a measured body twist against it,
 *        and the drift of a measured planar pose from the profile's ideal path (the pose
 *        obtained by integrating the commanded twist exactly from the same start).
 *        ROS-free; the one implementation used by closed_loop_run, the CLI aic_track_metrics
 *        and (through that CLI) the experiment scripts (doc/tools.md, 'Tracking benchmark').
 */

#include <iosfwd>
#include <string>
#include <vector>

#include "jackal_aic/params.hpp"

namespace jackal_aic
{
/// One breakpoint of a twist profile: from time t on, the set point is (vx, wz).
struct TwistProfilePoint
{
  double t = 0.0;   ///< profile time at which this set point begins [s], >= 0
  double vx = 0.0;  ///< body forward speed [m/s]
  double wz = 0.0;  ///< yaw rate [rad/s]
};

/**
 * \brief A body-twist set-point profile with zero-order hold.
 *
 * The set point at profile time t is the (vx, wz) of the last point with point.t <= t; before
 * the first point it is (0, 0). The profile ends at `duration`: a CSV file's last row gives
 * the end time (its vx, wz are not played), as a recorded command stream ends with its last
 * message's time.
 */
struct TwistProfile
{
  std::vector<TwistProfilePoint> points;  ///< breakpoints, t strictly increasing and >= 0
  double duration = 0.0;                  ///< end of the profile [s], > the last point's t
  std::string name;                       ///< label (a CSV file's name without folder and extension)

  /**
   * \brief The set point in force at profile time t (zero-order hold; (0, 0) before the first
   *        point). Times at or after `duration` get the last point's set point.
   * \param t     profile time [s]
   * \param vx    out: body forward speed [m/s]
   * \param wz    out: yaw rate [rad/s]
   */
  void setPointAt(double t, double* vx, double* wz) const;

  /// \throws std::invalid_argument unless: at least one point; every number finite; t >= 0 and
  ///         strictly increasing; duration > the last point's t (message says which).
  void validate() const;
};

/**
 * \brief Reads a twist profile from CSV text.
 *
 * Format: one row per set point, `t,vx,wz` (t [s], vx [m/s], wz [rad/s]); an optional header
 * line naming the columns (any order; `wz` may be absent, meaning 0); without a header the
 * columns are t, vx, wz. Lines starting with '#' and empty lines are skipped. At least two
 * rows; the last row's t ends the profile (TwistProfile).
 *
 * \param in      the CSV text
 * \param source  name used in error messages and, without folder and extension, as the name
 * \throws std::invalid_argument "<source> line N: ..." on: no rows, a header without t or vx,
 *         a row with the wrong number of cells, a cell that is not a finite number (nan and inf
 *         are refused), t < 0, t not strictly increasing, fewer than two rows.
 */
TwistProfile parseTwistProfileCsv(std::istream& in, const std::string& source);

/// parseTwistProfileCsv of a file. \throws std::invalid_argument also when it cannot be opened.
TwistProfile loadTwistProfileCsv(const std::string& path);

/// The profile as CSV text with a header `t,vx,wz`, the end time as the last row (the inverse
/// of parseTwistProfileCsv).
std::string twistProfileCsv(const TwistProfile& profile);

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
 * \return per channel the figures (all 0 for a channel without a steady sample)
 * \throws std::invalid_argument on an invalid profile, mismatched sizes, non-finite or
 *         non-increasing times, a non-finite truth or an invalid settle
 */
SteadyEstimateError steadyEstimateError(const TwistProfile& profile, const std::vector<double>& time,
                                        const std::vector<double>& est_vx, const std::vector<double>& est_wz,
                                        const std::vector<double>& true_vx, const std::vector<double>& true_wz,
                                        double settle);

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

/// The ideal servo of latencyFloor(): what it knows of the stream and what it can do.
struct LatencyFloorSettings
{
  double latency = 0.0;        ///< L: command-to-motion latency of the plant [s], finite, in [0, 10]
  double accel_linear = 0.0;   ///< largest |dvx/dt| [m/s^2]; 0 = unlimited; finite, >= 0
  double accel_angular = 0.0;  ///< largest |dwz/dt| [rad/s^2]; 0 = unlimited; finite, >= 0
  /// true: the servo aims at the set point predicted L ahead, mu_d + L mu_d' (mu_d' by the
  /// GoalRateEstimator, as the AIC's generalized goal); false: at the set point it has (hold)
  bool predict = false;
  double dt = 0.001;  ///< sample period of the servo and of the error [s], finite, in [1e-5, 0.1]
};

/**
 * \brief The latency floor of a profile: the velocity tracking error of an ideal servo, the
 *        best any controller can do through a plant that moves only L after it is commanded,
 *        for a given way of predicting the stream.
 *
 * The servo receives each profile point at its time, as the controller receives the stream, and
 * its body twist is y(t) = clamp_a(u(t - L)) with u the held set point mu_d(t) (predict false) or
 * its prediction mu_d(t) + L mu_d'(t) (predict true, mu_d' from a GoalRateEstimator with
 * goal_rate's goal_rate_hold and max_goal_rate_*), clamp_a a rate limit of
 * accel_linear / accel_angular (none where 0), y = 0 before t = L. No wheel loop, no slip, no
 * torque limit, no noise: a controller on the plant cannot do better than this servo with the same
 * predictor (doc/tools.md, 'Latency floor'). The error is velocityTrackingError() of y sampled
 * every dt over [0, duration].
 * \param goal_rate  parameters of the goal-rate estimator (validated AicParams; only its
 *                   goal-rate keys are used)
 * \throws std::invalid_argument on an invalid profile or settings out of range (message says which)
 */
VelocityTrackingError latencyFloor(const TwistProfile& profile, const AicParams& goal_rate,
                                   const LatencyFloorSettings& settings);

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

/// One-line JSON {"vx": {"rms", "max"}, "wz": {"rms", "max"}, "samples"}.
std::string toJson(const VelocityTrackingError& error);

/// One-line JSON {"final_position_error", "max_position_error", "final_heading_error",
/// "ideal_length", "samples"} (not the ideal poses).
std::string toJson(const PathDrift& drift);

/// JSON object of a SteadyEstimateError: {"vx": {"steady_mean_abs", "steady_max_abs", "samples",
/// "segments"}, "wz": {...}, "unavailable"} (units of the channels).
std::string toJson(const SteadyEstimateError& error);

}  // namespace jackal_aic
