#pragma once
/**
 * \file tracking_metrics.hpp
 * \brief Tracking of a twist set-point profile: the profile itself (a CSV of t, vx, wz played
 *        with zero-order hold), the RMS and maximum error of a measured body twist against it,
 *        and the drift of a measured planar pose from the profile's ideal path (the pose
 *        obtained by integrating the commanded twist exactly from the same start).
 *        ROS-free; the one implementation used by closed_loop_run, the CLI aic_track_metrics
 *        and (through that CLI) the experiment scripts (doc/tools.md, 'Tracking benchmark').
 *
 * Each concept has its own header; this one gathers them for the tools and the harness.
 */

#include "jackal_aic/analysis/latency_floor.hpp"
#include "jackal_aic/analysis/path_drift.hpp"
#include "jackal_aic/analysis/steady_estimate.hpp"
#include "jackal_aic/analysis/stop_reversal.hpp"
#include "jackal_aic/analysis/tracking_error.hpp"
#include "jackal_aic/analysis/twist_profile.hpp"
