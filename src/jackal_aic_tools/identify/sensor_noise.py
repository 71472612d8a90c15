"""The robot model's sensor noises from a robot's bag (plant_identify.py --bag; written into the
robot model's overlay by jackal_aic_tools.identify.bag_fit.write_robot_model).

The robot model weighs each sensor by its measured noise in its own units (doc/active_inference.md,
'The robot model', the parameter table): ``encoder_noise`` sigma_e, the standard deviation of one
side's wheel speed (the mean of its two joints, as the node reads /joint_states) [rad/s], and
``gyro_noise`` sigma_g, the gyro's [rad/s]. Both are measured where the robot does not move: on the
bag's rest segments (the command zero), from SETTLE seconds after the command became zero to its
next change (the MCU's wheel loop takes most of a second to come to rest after a turn), as the
standard deviation about each segment's straight-line trend (a gyro offset and its drift, and what
is left of the wheels' settling, are trends, not noise), pooled over the segments.

A wheel loop whose MCU reports a still wheel as exactly zero (quantized speeds) shows no noise at
rest: then sigma_e comes from the straight segments (both sides commanded the same non-zero speed,
or cmd_vel's yaw rate zero), from STRAIGHT_SETTLE seconds after the command's change, about each
segment's straight-line trend (a slow load change is not noise).
"""
import numpy as np

#: [s] after the command became zero before the wheels count as stopped (the simulated Jackal's
#: wheel loop still turns at 0.26 rad/s 0.5 s after a 0.4 m/s stop, within its noise after 1 s).
SETTLE = 1.0
#: [s] after a straight segment's command change before its speed counts as steady.
STRAIGHT_SETTLE = 1.0
#: Fewest samples a noise is measured on (all segments together).
MIN_SAMPLES = 50
#: A pooled standard deviation below this [rad/s] is a quantized stream, not a measured noise.
QUANTIZED = 1e-9


def command_segments(data):
    """The bag's command stream (bag_identification.BagData.cmd) as segments over which it held one
    value: a list of (start [s], end [s], value tuple), end the next change's time or the end of the
    wheel-speed samples. /cmd_drive in mode none (-1) counts as zero."""
    cmd = data.cmd
    if data.cmd_is_twist:
        values = [(float(r[1]), float(r[2])) for r in cmd]
    else:
        values = [(0.0, 0.0) if int(r[1]) == -1 else (float(r[2]), float(r[3])) for r in cmd]
    segments = []
    start = 0
    for i in range(1, len(values) + 1):
        if i == len(values) or values[i] != values[start]:
            end = float(cmd[i, 0]) if i < len(values) else data.duration
            segments.append((float(cmd[start, 0]), end, values[start]))
            start = i
    return segments


def rest_windows(data, settle=SETTLE):
    """Windows [(t0, t1)] of the rest segments: the command zero, from ``settle`` after it became zero."""
    return [(s + settle, e) for s, e, v in command_segments(data) if v == (0.0, 0.0) and e > s + settle]


def straight_windows(data, settle=STRAIGHT_SETTLE):
    """Windows [(t0, t1)] of the straight segments: both sides commanded the same non-zero speed
    (cmd_vel: a non-zero speed and a zero yaw rate), from ``settle`` after the change."""
    def straight(v):
        return (v[0] != 0.0 and v[1] == 0.0) if data.cmd_is_twist else (v[0] == v[1] and v[0] != 0.0)
    return [(s + settle, e) for s, e, v in command_segments(data) if straight(v) and e > s + settle]


def pooled_std(t, x, windows, detrend=False):
    """Standard deviation of the samples x at times t within ``windows`` about each window's mean
    (``detrend``: its least-squares line), pooled: sqrt(sum of squared residuals / (n - fitted
    parameters)). Returns (std, n samples); (nan, n) when there are too few samples to fit."""
    ss, n, dof = 0.0, 0, 0
    for t0, t1 in windows:
        m = (t >= t0) & (t < t1)
        k = int(np.count_nonzero(m))
        p = 2 if detrend else 1
        if k <= p:
            continue
        tw, xw = t[m], x[m]
        fit = np.polyval(np.polyfit(tw - tw[0], xw, p - 1), tw - tw[0])
        ss += float(np.sum((xw - fit) ** 2))
        n += k
        dof += k - p
    return (float(np.sqrt(ss / dof)) if dof > 0 else float("nan")), n


def sensor_noise(data, settle=SETTLE):
    """sigma_e and sigma_g of the bag ``data`` (bag_identification.BagData): a dict with
    encoder_noise and gyro_noise [rad/s], their sources ("rest" or "straight"), the samples and
    windows used. sigma_e is the root mean square of the two sides' (each side the mean of its two
    joints). Raises ValueError naming the bag when it has fewer than MIN_SAMPLES samples at rest (or,
    for quantized wheel speeds, on straight segments)."""
    rest = rest_windows(data, settle)
    t_w, t_g = data.wheels[:, 0], data.gyro[:, 0]
    gyro, n_g = pooled_std(t_g, data.gyro[:, 1], rest, detrend=True)
    if n_g < MIN_SAMPLES or not np.isfinite(gyro):
        raise ValueError("%s: %d gyro samples at rest (the command zero for more than %.1f s), fewer than %d: "
                         "record a rest segment" % (data.path, n_g, settle, MIN_SAMPLES))
    sides = [pooled_std(t_w, data.wheels[:, j], rest, detrend=True) for j in (1, 2)]
    source, windows = "rest", rest
    if max(s for s, _ in sides) < QUANTIZED:
        source, windows = "straight", straight_windows(data)
        sides = [pooled_std(t_w, data.wheels[:, j], windows, detrend=True) for j in (1, 2)]
    n_e = min(n for _, n in sides)
    if n_e < MIN_SAMPLES or not all(np.isfinite(s) for s, _ in sides):
        raise ValueError("%s: %d wheel-speed samples %s, fewer than %d" % (
            data.path, n_e, "at rest" if source == "rest" else
            "on straight segments (the wheel speeds at rest are quantized: no noise there)", MIN_SAMPLES))
    if max(s for s, _ in sides) < QUANTIZED:
        raise ValueError("%s: the wheel speeds are constant at rest and on straight segments: no noise to measure"
                         % data.path)
    encoder = float(np.sqrt(0.5 * (sides[0][0] ** 2 + sides[1][0] ** 2)))
    return {"encoder_noise": encoder, "gyro_noise": gyro, "encoder_source": source, "gyro_source": "rest",
            "encoder_samples": n_e, "gyro_samples": n_g, "encoder_windows": len(windows), "gyro_windows": len(rest)}


def overlay_lines(noise):
    """``noise`` (sensor_noise()) as commented controller-overlay YAML lines (encoder_noise,
    gyro_noise) with their source."""
    return ["# [rad/s] sigma_e, one side's wheel-speed noise: %d samples, %d %s segments."
            % (noise["encoder_samples"], noise["encoder_windows"], noise["encoder_source"]),
            "encoder_noise: %.4g" % noise["encoder_noise"],
            "# [rad/s] sigma_g, the gyro's noise: %d samples, %d rest segments." % (noise["gyro_samples"],
                                                                                    noise["gyro_windows"]),
            "gyro_noise: %.4g" % noise["gyro_noise"]]
