"""The robot model's yaw response from a robot's bag (plant_identify.py --bag).

The robot model (doc/active_inference.md, 'The robot model') turns the body at the wheels' yaw
rate through an effective separation and a scrub lag:

    theta_dot' = (r alpha (omega_R - omega_L) / b_eff - theta_dot) / T_s,    y_gyro = theta_dot + beta,

b_eff = b / (1 - s) the separation the wheels' yaw rate has once the slip ratio s is taken up. Both
are fitted here to the bag's own streams: the side means of /joint_states' wheel speeds drive the
first-order lag (integrated exactly on a TIME_STEP grid, the wheel speeds interpolated linearly),
and its output plus a constant gyro offset beta is compared with /imu/data's yaw rate at the gyro's
sample times, by scipy.optimize.least_squares over (r alpha / b_eff, T_s, beta). Only the span of
the bag's turns in place counts (TURN_SETTLE seconds past each turn's end, so the stop's transient
is in): there the yaw rate follows the wheels alone. The fit gives ``yaw_time_constant`` T_s and
``wheel_separation`` (the learned separation's start b_hat_0 = b_eff) for the robot model's overlay
(jackal_aic_tools.identify.bag_fit.write_robot_model).

What it cannot see: a constant offset between the two streams' stamps is read as part of T_s (a
pure delay and a short lag look alike at 50 Hz), and a turn in place's b_eff is not an arc's (the
simulated Jackal: 0.541 m in place, 0.5355 m on a 0.5 m/s + 0.5 rad/s arc).
"""
import numpy as np

from .bag_identification import WHEEL_RADIUS
from .sensor_noise import command_segments

#: [s] grid of the lag's exact integration.
TIME_STEP = 0.001
#: [s] after a turn's end whose samples still count (the stop's transient).
TURN_SETTLE = 1.0
#: Fewest gyro samples in the turns' span.
MIN_SAMPLES = 50
#: Bounds of T_s [s] in the fit.
MIN_TIME_CONSTANT = 1e-4
MAX_TIME_CONSTANT = 1.0


def turn_windows(data, settle=TURN_SETTLE):
    """Windows [(t0, t1)] [s] of the bag's turns in place: the command segments whose sides are
    commanded opposite non-zero speeds (cmd_vel: a zero speed and a non-zero yaw rate), from their
    start to ``settle`` seconds past their end, overlapping ones merged (a ramped /cmd_drive stream
    is a run of such segments): one window per turn."""
    def turning(v):
        return (v[0] == 0.0 and v[1] != 0.0) if data.cmd_is_twist else (v[0] == -v[1] and v[0] != 0.0)
    windows = []
    for s, e, v in command_segments(data):
        if not turning(v):
            continue
        if windows and s <= windows[-1][1]:
            windows[-1] = (windows[-1][0], max(windows[-1][1], e + settle))
        else:
            windows.append((s, e + settle))
    return windows


def lag(t, u, time_constant, step=TIME_STEP):
    """The first-order lag x' = (u - x) / T of the input u(t) (samples at times t, interpolated
    linearly), x(t[0]) = u(t[0]), integrated exactly with the input held over each ``step``; returns
    (grid times, x on the grid)."""
    from scipy.signal import lfilter
    grid = np.arange(t[0], t[-1], step)
    ug = np.interp(grid, t, u)
    a = np.exp(-step / time_constant)
    x, _ = lfilter([0.0, 1.0 - a], [1.0, -a], ug, zi=[a * ug[0]])
    return grid, x


def yaw_response(data, wheel_radius=WHEEL_RADIUS, slip_factor=1.0):
    """T_s and b_eff of the bag ``data`` (bag_identification.BagData): a dict with
    yaw_time_constant [s], wheel_separation b_eff [m] (at ``wheel_radius`` [m] and ``slip_factor``
    alpha [-], the controller's: by default the schema's, the Jackal's published wheel, doc/jackal.md), gyro_offset beta [rad/s], the fit's residual RMS [rad/s], the
    samples and turns used. Raises ValueError naming the bag when it has no turn in place or fewer
    than MIN_SAMPLES gyro samples in their span, or when the wheels do not turn the body there."""
    from scipy.optimize import least_squares
    windows = turn_windows(data)
    t_w, t_g = data.wheels[:, 0], data.gyro[:, 0]
    inside = np.zeros(len(t_g), dtype=bool)
    for t0, t1 in windows:
        inside |= (t_g >= t0) & (t_g < t1)
    inside &= (t_g > t_w[0]) & (t_g < t_w[-1] - TIME_STEP)
    n = int(np.count_nonzero(inside))
    if not windows or n < MIN_SAMPLES:
        raise ValueError("%s: %d gyro samples in %d turns in place, fewer than %d: record turns in place "
                         "(record_identification.py's sequences have them)" % (data.path, n, len(windows), MIN_SAMPLES))
    difference = data.wheels[:, 2] - data.wheels[:, 1]  # omega_R - omega_L [rad/s]
    gyro = data.gyro[inside, 1]

    def residuals(p):
        gain, time_constant, offset = p
        grid, x = lag(t_w, difference, time_constant)
        return gain * np.interp(t_g[inside], grid, x) + offset - gyro

    # Starting point: the steady ratio of the gyro to the wheels' difference in the turns.
    diff_at_gyro = np.interp(t_g[inside], t_w, difference)
    gain0 = float(np.dot(diff_at_gyro, gyro) / max(np.dot(diff_at_gyro, diff_at_gyro), 1e-12))
    if not gain0 > 0.0:
        raise ValueError("%s: in its turns in place the gyro does not turn with the wheels (gain %.3g): the "
                         "joints or the IMU's axis are swapped or inverted" % (data.path, gain0))
    fit = least_squares(residuals, [gain0, 0.03, 0.0],
                        bounds=([1e-6, MIN_TIME_CONSTANT, -1.0], [10.0, MAX_TIME_CONSTANT, 1.0]))
    gain, time_constant, offset = (float(v) for v in fit.x)
    return {"yaw_time_constant": time_constant, "wheel_separation": wheel_radius * slip_factor / gain,
            "gyro_offset": offset, "residual_rms": float(np.sqrt(np.mean(fit.fun ** 2))), "samples": n,
            "turns": len(windows)}


def overlay_lines(response):
    """``response`` (yaw_response()) as commented controller-overlay YAML lines (yaw_time_constant,
    wheel_separation) with their source."""
    return ["# [s] T_s, the scrub lag of the body's yaw rate behind the wheels' (turns in place: %d, %d gyro"
            % (response["turns"], response["samples"]),
            "# samples, residual %.4f rad/s)." % response["residual_rms"],
            "yaw_time_constant: %.4g" % response["yaw_time_constant"],
            "# [m] b_hat_0, the effective separation of a turn in place: the learned separation starts here.",
            "wheel_separation: %.4g" % response["wheel_separation"]]
