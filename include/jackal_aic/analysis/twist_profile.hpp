#pragma once
/**
 * \file twist_profile.hpp
 * \brief A twist set-point profile: breakpoints (t, vx, wz) played with zero-order hold, read from
 *        and written as CSV (doc/tools.md, 'Tracking benchmark'). ROS-free.
 */

#include <iosfwd>
#include <string>
#include <vector>

namespace jackal_aic
{
namespace analysis
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
}  // namespace analysis
}  // namespace jackal_aic
