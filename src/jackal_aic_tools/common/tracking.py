"""Tracking metrics through the core's ``aic_track_metrics`` CLI (the one implementation of the
twist-profile reader, the velocity tracking error and the path drift:
include/jackal_aic/analysis/tracking_metrics.hpp). This module prepares the CLI's input, runs it and
parses its output; it computes nothing itself.

Metrics of a run against a profile (t, vx, wz rows, zero-order hold): per measured body twist
the RMS and maximum error of vx [m/s] and wz [rad/s] against the set point in force; the drift of
the measured pose from the ideal path (the commanded twist integrated exactly from the same
start): final and maximum position error [m], final heading error [rad].
"""
import csv
import json
import math
import subprocess

import numpy as np

from . import metrics

#: Flat metric names of one run, as in the tables and CSV files of aic_track.py and
#: aic_experiment.py: (name, unit, path in the result dict).
FLAT_METRICS = (
    ("vx_rms", "m/s", ("tracking", "truth", "vx", "rms")),
    ("vx_max", "m/s", ("tracking", "truth", "vx", "max")),
    ("wz_rms", "rad/s", ("tracking", "truth", "wz", "rms")),
    ("wz_max", "rad/s", ("tracking", "truth", "wz", "max")),
    ("odom_vx_rms", "m/s", ("tracking", "odometry", "vx", "rms")),
    ("odom_vx_max", "m/s", ("tracking", "odometry", "vx", "max")),
    ("odom_wz_rms", "rad/s", ("tracking", "odometry", "wz", "rms")),
    ("odom_wz_max", "rad/s", ("tracking", "odometry", "wz", "max")),
    ("drift_final", "m", ("path", "final_position_error")),
    ("drift_max", "m", ("path", "max_position_error")),
    ("heading_final", "rad", ("path", "final_heading_error")),
)


class TrackingError(ValueError):
    """A profile or trace the CLI refused, or the CLI failed; the message is the CLI's."""


def find_cli():
    """Path of ``aic_track_metrics`` (metrics.find_tool; $AIC_TRACK_METRICS overrides)."""
    return metrics.find_tool("aic_track_metrics", "AIC_TRACK_METRICS")


def _run(cmd):
    """Run the CLI; its JSON output as a dict, or TrackingError with its first error line."""
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
    if out.returncode != 0:
        msg = out.stderr.strip().splitlines()
        raise TrackingError(msg[0] if msg else "%s failed (exit %d)" % (" ".join(cmd), out.returncode))
    return json.loads(out.stdout)


def load_profile(path, cli=None):
    """Read and check a twist profile CSV (t, vx, wz; header optional; the last row's t ends
    it). Returns {"name", "duration" [s], "points": [[t, vx, wz], ...]}. Raises TrackingError
    (a ValueError) with the file and line of what is wrong."""
    return _run([cli or find_cli(), "--profile", path, "--print-profile"])


def track_metrics(profile_csv, trace_csv, ideal_csv=None, cli=None):
    """Metrics of a trace CSV (header; column t in profile time [s]; pairs S_vx, S_wz of
    measured twists; x, y, heading of a measured pose; empty cells = no sample) against the
    profile CSV. Returns {"profile", "duration", "tracking": {S: {"vx": {"rms", "max"}, "wz":
    {...}, "samples"}}, "path": {"final_position_error", "max_position_error",
    "final_heading_error", "ideal_length", "samples"} or None}; writes the ideal path
    (t, x, y, heading) to ``ideal_csv`` if given. Raises TrackingError."""
    cmd = [cli or find_cli(), "--profile", profile_csv, "--trace", trace_csv]
    if ideal_csv:
        cmd += ["--ideal-csv", ideal_csv]
    return _run(cmd)


def latency_floor(profile_csv, latency, accel_linear=0.0, accel_angular=0.0, cli=None, period=0.0, wheels=None):
    """The latency floor of a profile (jackal_aic::analysis::latencyFloor through ``aic_track_metrics
    --floor-latency``): the RMS and maximum error of an ideal servo that moves ``latency`` [s] after
    it is commanded, with the given acceleration limits of the body [m/s^2, rad/s^2] (0 = none) or,
    ``wheels`` = (A_w [rad/s^2], radius [m], track [m]), of each of its two wheels instead, and its aim
    held for ``period`` [s] (a controller's action period; 0 = none), once holding the set point and
    once predicting it with the goal rate. Returns {"profile", "duration", "latency", "period",
    "hold": {"vx": {"rms", "max"}, "wz": {...}, "samples"}, "predict": {...}}. Raises TrackingError
    (the CLI's message) on a bad profile, or a negative or non-finite latency, limit or period."""
    cmd = [cli or find_cli(), "--profile", profile_csv, "--floor-latency", repr(float(latency)),
           "--floor-accel-linear", repr(float(accel_linear)), "--floor-accel-angular", repr(float(accel_angular)),
           "--floor-period", repr(float(period))]
    if wheels is not None:
        cmd += ["--floor-wheel-acceleration", repr(float(wheels[0])), "--floor-wheel-radius", repr(float(wheels[1])),
                "--floor-track", repr(float(wheels[2]))]
    return _run(cmd)


def flat(result):
    """{name: value} of FLAT_METRICS from a result dict with "tracking" and "path" (None where
    absent)."""
    out = {}
    for name, _, keys in FLAT_METRICS:
        v = result
        for k in keys:
            v = v.get(k) if isinstance(v, dict) else None
        out[name] = float(v) if v is not None and math.isfinite(float(v)) else None
    return out


def read_columns(path):
    """A CSV file with a header (lines starting with '#' skipped) as {column: float array};
    empty cells are NaN."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    header = [h.strip() for h in rows[0]]
    cols = {h: [] for h in header}
    for r in rows[1:]:
        for h, cell in zip(header, r):
            cols[h].append(float(cell) if cell.strip() else float("nan"))
    return {h: np.array(v, dtype=float) for h, v in cols.items()}


#: Trace columns of the AIC's belief mu^(0) and the ground truth, per channel (closed_loop_run --csv).
BELIEF_COLUMNS = {"vx": ("mu0_x_dot[m/s]", "v_true"), "wz": ("mu0_theta_dot[rad/s]", "yaw_true")}


def belief_truth_rms(trace, start=0.0, end=None):
    """RMS of belief mu^(0) minus the ground truth over a closed_loop_run trace (``trace``:
    read_columns() of an AIC run's --csv, columns BELIEF_COLUMNS and t in profile time [s]), over
    the samples with t in [``start``, ``end``] (None: to the end) where the belief is finite:
    {"vx": m/s, "wz": rad/s, "samples": n}; vx and wz None without such samples. Unlike
    closed_loop_run's tracking.belief (the steady segments only) it includes every transient.
    Raises KeyError when the trace has no belief columns (not an AIC run)."""
    t = trace["t"]
    keep = t >= start - 1e-9
    if end is not None:
        keep &= t <= end + 1e-9
    out = {}
    n = 0
    for ch, (belief, truth) in BELIEF_COLUMNS.items():
        d = trace[belief][keep] - trace[truth][keep]
        d = d[np.isfinite(d)]
        out[ch] = float(np.sqrt(np.mean(d ** 2))) if d.size else None
        n = max(n, int(d.size))
    out["samples"] = n
    return out
