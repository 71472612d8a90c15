"""Identification of the Jackal's wheel loop from a robot's bag, and the bags themselves.

The identification sequence (``SEQUENCES``): what scripts/record_identification.py drives a Jackal
through, at bounded speeds, through the stock base (straight steps forward and back, turns in
place both ways), as a profiles.Profile.

Reading a bag (``read_bag``): /cmd_drive (jackal_msgs/Drive, the MCU's input; or, without it, the
stock diff drive's geometry_msgs/Twist cmd_vel), /joint_states (wheel speeds, header stamps),
/imu/data (gyro z) and, when present, the MCU's /feedback (jackal_msgs/Feedback: each side's
measured_velocity), as numpy arrays on one time axis (0 = the first command).

The fit (``replay``, ``response_errors``, ``BAG_PARAMETERS``): the bag's command stream is replayed
on the plant (plant_replay, C++, headless) with candidate motor parameters, and the simulated
wheel speeds and yaw rate are compared with the bag's at the bag's sample times.

A simulated bag (``write_simulated_bag``): the sequence played on the simulated Jackal headless
(plant_replay --twist: the stock controller's /cmd_drive stream, the plant, the sensor models;
the same cores the plant node and the stock base node run) and written with the topics a Jackal
records, stamped on the plant's time.
"""
import csv
import math
import os
import subprocess
import tempfile

import numpy as np

from ..common import profiles

# jackal_msgs/Drive modes.
MODE_VELOCITY = 0
MODE_NONE = -1
WHEELS = ("front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel")
# The recorder never commands more than this, whatever it is asked [m/s, rad/s].
MAX_LINEAR = 1.0
MAX_ANGULAR = 2.0
# Topics of a bag (names as on the robot).
CMD_DRIVE = "/cmd_drive"
CMD_VEL = "/jackal_velocity_controller/cmd_vel"
JOINT_STATES = "/joint_states"
IMU = "/imu/data"
FEEDBACK = "/feedback"
STATUS = "/status"

# Identification sequences: (hold [s], vx [m/s], wz [rad/s]) pieces from rest. "standard" is the
# one to record on a robot (~37 s; it travels ~1 m forward and back: leave 1.5 m free ahead and
# behind and 0.5 m beside the robot); "short" (~12 s) is a quick check.
SEQUENCES = {
    "standard": [
        (2.0, 0.0, 0.0),
        (1.5, 0.4, 0.0), (1.5, 0.0, 0.0), (1.5, -0.4, 0.0), (1.5, 0.0, 0.0),
        (1.2, 0.8, 0.0), (1.5, 0.0, 0.0), (1.2, -0.8, 0.0), (1.5, 0.0, 0.0),
        (2.5, 0.0, 0.5), (1.5, 0.0, 0.0), (2.5, 0.0, -0.5), (1.5, 0.0, 0.0),
        (2.5, 0.0, 1.0), (1.5, 0.0, 0.0), (2.5, 0.0, -1.0), (1.5, 0.0, 0.0),
        (2.0, 0.0, 1.5), (1.5, 0.0, 0.0), (2.0, 0.0, -1.5), (2.0, 0.0, 0.0),
    ],
    "short": [
        (1.0, 0.0, 0.0),
        (1.5, 0.4, 0.0), (1.5, 0.0, 0.0),
        (2.5, 0.0, 1.0), (1.5, 0.0, 0.0),
        (2.5, 0.0, -1.5), (1.5, 0.0, 0.0),
    ],
}


def sequence_profile(name, max_linear=MAX_LINEAR, max_angular=MAX_ANGULAR):
    """The identification sequence ``name`` as a profiles.Profile, every set point clipped to
    +-max_linear [m/s] and +-max_angular [rad/s] (themselves at most MAX_LINEAR, MAX_ANGULAR).
    Raises ValueError on an unknown name or a bound that is not finite and > 0."""
    if name not in SEQUENCES:
        raise ValueError("unknown sequence %r (known: %s)" % (name, ", ".join(sorted(SEQUENCES))))
    for b, cap in ((max_linear, MAX_LINEAR), (max_angular, MAX_ANGULAR)):
        if not (math.isfinite(b) and 0.0 < b <= cap):
            raise ValueError("speed bound %r must be in (0, %g]" % (b, cap))
    points = []
    t = 0.0
    for hold, vx, wz in SEQUENCES[name]:
        points.append((t, max(-max_linear, min(max_linear, vx)), max(-max_angular, min(max_angular, wz))))
        t += hold
    return profiles.Profile(points, t, "identification_" + name)


# ------------------------------------------------------------------ reading a bag
class BagData(object):
    """The streams of one bag as numpy arrays, times [s] from the first command.

    cmd: columns t, mode, left, right (the MCU's input; from cmd_vel through the stock mapping if
    the bag has no /cmd_drive: then ``cmd_is_twist`` and the columns are t, vx, wz);
    wheels: t, left, right (side means of /joint_states' wheel speeds [rad/s]);
    gyro: t, wz (/imu/data angular_velocity.z [rad/s]); feedback: t, left, right (the MCU's
    measured_velocity, or None when the bag has no /feedback)."""

    def __init__(self, cmd, cmd_is_twist, wheels, gyro, feedback, t0, path):
        self.cmd = cmd
        self.cmd_is_twist = cmd_is_twist
        self.wheels = wheels
        self.gyro = gyro
        self.feedback = feedback
        self.t0 = t0
        self.path = path

    @property
    def duration(self):
        """Span of the wheel-speed samples after the first command [s]."""
        return float(self.wheels[-1, 0])


def read_bag(path):
    """Read the identification streams of the bag at ``path`` (see BagData).
    Raises ValueError naming the bag and what is missing or malformed: no command stream, no
    /joint_states with the four wheels' velocities, no /imu/data, a /cmd_drive in a mode the plant's
    MCU model does not have (PWM, effort), non-finite values."""
    import rosbag
    try:
        bag = rosbag.Bag(path)
    except Exception as e:  # rosbag raises ROSBagException, IOError, ...
        raise ValueError("%s: cannot be read as a bag (%s)" % (path, e))
    cmd, twist, joints, gyro, fb = [], [], [], [], []
    with bag:
        for topic, msg, t in bag.read_messages(topics=[CMD_DRIVE, CMD_VEL, JOINT_STATES, IMU, FEEDBACK]):
            if topic == CMD_DRIVE:
                if msg.mode not in (MODE_VELOCITY, MODE_NONE):
                    raise ValueError("%s: /cmd_drive in mode %d (the plant's MCU model has velocity (0) and "
                                     "none (-1) only)" % (path, msg.mode))
                cmd.append((t.to_sec(), msg.mode, msg.drivers[0], msg.drivers[1]))
            elif topic == CMD_VEL:
                twist.append((t.to_sec(), msg.linear.x, msg.angular.z))
            elif topic == JOINT_STATES:
                stamp = msg.header.stamp.to_sec() or t.to_sec()
                try:
                    v = [msg.velocity[list(msg.name).index(w)] for w in WHEELS]
                except (ValueError, IndexError):
                    continue  # another joint_states publisher (e.g. an arm's)
                joints.append((stamp, 0.5 * (v[0] + v[2]), 0.5 * (v[1] + v[3])))
            elif topic == IMU:
                gyro.append((msg.header.stamp.to_sec() or t.to_sec(), msg.angular_velocity.z))
            elif topic == FEEDBACK:
                fb.append((msg.header.stamp.to_sec() or t.to_sec(), msg.drivers[0].measured_velocity,
                           msg.drivers[1].measured_velocity))
    if not cmd and not twist:
        raise ValueError("%s: no %s and no %s: nothing drove the robot" % (path, CMD_DRIVE, CMD_VEL))
    if len(joints) < 10:
        raise ValueError("%s: no %s with the wheels %s" % (path, JOINT_STATES, ", ".join(WHEELS)))
    if len(gyro) < 10:
        raise ValueError("%s: no %s" % (path, IMU))
    cmd_is_twist = not cmd
    c = np.array(cmd if cmd else twist, dtype=float)
    t0 = float(c[0, 0])
    arrays = [c, np.array(joints, dtype=float), np.array(gyro, dtype=float)]
    if fb:
        arrays.append(np.array(fb, dtype=float))
    for a in arrays:
        if not np.all(np.isfinite(a)):
            raise ValueError("%s: non-finite values in the streams" % path)
        a[:, 0] -= t0
    wheels = arrays[1][arrays[1][:, 0] >= 0.0]
    g = arrays[2][arrays[2][:, 0] >= 0.0]
    feedback = arrays[3][arrays[3][:, 0] >= 0.0] if fb else None
    if len(wheels) < 10 or len(g) < 10:
        raise ValueError("%s: hardly any /joint_states or /imu/data after the first command" % path)
    return BagData(c, cmd_is_twist, wheels, g, feedback, t0, path)


# ------------------------------------------------------------------ replay and errors
def write_commands(data, path):
    """Write the bag's command stream as plant_replay's input CSV (--drive: t,mode,left,right;
    --twist: t,vx,wz, the last row ending the profile at the bag's end)."""
    with open(path, "w") as f:
        w = csv.writer(f)
        if data.cmd_is_twist:
            w.writerow(["t", "vx", "wz"])
            for row in data.cmd:
                w.writerow(["%.6f" % row[0], "%.6g" % row[1], "%.6g" % row[2]])
            w.writerow(["%.6f" % max(data.duration, data.cmd[-1, 0] + 0.02), "0", "0"])
        else:
            w.writerow(["t", "mode", "left", "right"])
            for row in data.cmd:
                w.writerow(["%.6f" % row[0], "%d" % int(row[1]), "%.6g" % row[2], "%.6g" % row[3]])


def run_plant_replay(plant_replay, args, config=None, overlays=(), sets=()):
    """Run the plant_replay executable with ``args`` on the plant YAML ``config`` (default: the
    tool's), ``overlays`` (paths) and ``sets`` (key=value); returns its standard output. Raises
    RuntimeError with the command and the tool's message when it fails."""
    cmd = [plant_replay] + list(args)
    if config:
        cmd += ["--config", config]
    for o in overlays:
        cmd += ["--overlay", o]
    for s in sets:
        cmd += ["--set", s]
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(cmd), out.stderr.strip()[-400:]))
    return out.stdout


def replay(plant_replay, commands_csv, is_twist, duration, config=None, overlays=(), sets=()):
    """Replay ``commands_csv`` (write_commands()) for ``duration`` s (run_plant_replay()). Returns
    a dict of numpy columns (plant_replay's header names). Raises RuntimeError as run_plant_replay."""
    stdout = run_plant_replay(plant_replay, ["--twist" if is_twist else "--drive", commands_csv,
                                             "--duration", "%.6f" % duration], config, overlays, sets)
    lines = stdout.splitlines()
    names = lines[0].split(",")
    values = np.array([[float(x) for x in line.split(",")] for line in lines[1:]], dtype=float)
    return {n: values[:, i] for i, n in enumerate(names)}


def simulated_streams(sim):
    """(t, left, right, gyro z) of a replay: side means of the wheel speeds, the IMU's yaw rate."""
    return (sim["t"], 0.5 * (sim["vel_fl"] + sim["vel_rl"]), 0.5 * (sim["vel_fr"] + sim["vel_rr"]), sim["gyro_z"])


def response_errors(sim, data):
    """RMS differences between a replay ``sim`` and the bag ``data`` at the bag's sample times:
    dict with 'left', 'right' (side wheel speeds [rad/s]), 'yaw' (gyro [rad/s]) and the bag's own
    RMS of each ('left_rms', ...); samples after the replay's end are not compared."""
    t, left, right, gz = simulated_streams(sim)
    end = t[-1]
    out = {}
    for name, bag_t, bag_v, sim_v in (("left", data.wheels[:, 0], data.wheels[:, 1], left),
                                      ("right", data.wheels[:, 0], data.wheels[:, 2], right),
                                      ("yaw", data.gyro[:, 0], data.gyro[:, 1], gz)):
        keep = bag_t <= end
        s = np.interp(bag_t[keep], t, sim_v)
        out[name] = float(np.sqrt(np.mean((s - bag_v[keep]) ** 2)))
        out[name + "_rms"] = float(np.sqrt(np.mean(bag_v[keep] ** 2)))
    return out


#: The streams the fit compares (response_errors()), with their labels.
STREAMS = {"left": "left wheels", "right": "right wheels", "yaw": "gyro yaw"}
#: [-] A stream whose RMS error is above this share of its RMS (stream_shares()) is poorly reproduced
#: by the identified plant: something the fit does not search differs. The identified plants of the
#: shipped plant conditions' bags (doc/robot_data.md) reproduce their streams within 1-5 % where only
#: the wheel loop, the latency, the floor or the payload's mass differs; the front-heavy body's gyro
#: (its weight on the front wheels, not searched) is at 27 %.
POOR_FIT_SHARE = 0.10


def stream_shares(errors):
    """{stream: RMS error / max(the bag's RMS, 0.1)} of response_errors()'s ``errors`` (the three
    streams of STREAMS; the floor of 0.1 rad/s keeps a stream that hardly moves from dominating)."""
    return {k: errors[k] / max(errors[k + "_rms"], 0.1) for k in STREAMS}


def fit_cost(errors):
    """The identification's cost of response_errors(): the mean over the three streams of
    stream_shares()^2."""
    return float(np.mean([share ** 2 for share in stream_shares(errors).values()]))


def poorly_reproduced(errors, share=POOR_FIT_SHARE):
    """{stream: its share} of the streams of response_errors()'s ``errors`` whose stream_shares() is
    above ``share`` (POOR_FIT_SHARE): empty when the plant reproduces the bag. Raises ValueError if
    ``share`` is not a finite number > 0."""
    if not (np.isfinite(share) and share > 0.0):
        raise ValueError("poorly_reproduced: share %r, need a finite number > 0" % (share,))
    return {k: v for k, v in stream_shares(errors).items() if not v <= share}


# Fitted motor parameters: name -> (lower, upper, scale), as jackal_aic_tools.identify.identify.Space.
# load_observer_bandwidth is 1 / motor.load_observer_time_constant [1/s] (below 0.2 /s: no observer),
# so that "no observer" lies inside the box.
BAG_PARAMETERS = {
    "speed_kp": (0.5, 30.0, "log"),            # N m / (rad/s)
    "proportional_limit": (0.3, 4.0, "lin"),   # N m
    "speed_ki": (0.0, 5.0, "lin"),             # N m / rad
    "load_observer_bandwidth": (0.0, 100.0, "lin"),  # 1/s
    "command_delay": (0.02, 0.25, "lin"),      # s
}
#: The turning parameters: what decides how a turn's load is held.
TURNING = ("speed_kp", "speed_ki", "load_observer_bandwidth")
OBSERVER_OFF_BANDWIDTH = 0.2  # 1/s
#: [N m/rad] An integral gain below this is the fit's "none" (its range starts at 0): about a fiftieth
#: of the default firmware's 0.4892, a fortieth of the slow break-away firmware's identified 0.40.
INTEGRAL_OFF_GAIN = 0.01


def has_observer(values):
    """Whether the fitted wheel loop ``values`` (fit_bag()'s fitted values by name) has a load
    observer: its load_observer_bandwidth at least OBSERVER_OFF_BANDWIDTH (True), below it (False),
    or None when the bandwidth was not fitted."""
    bandwidth = values.get("load_observer_bandwidth")
    return None if bandwidth is None else bandwidth >= OBSERVER_OFF_BANDWIDTH


def load_compensation(values):
    """How the fitted wheel loop ``values`` (fit_bag()'s fitted values by name) takes a load up:
    'observer' (has_observer()), 'integral' (no observer, speed_ki at least INTEGRAL_OFF_GAIN),
    'none' (neither: proportional only, a load stays a speed error), or None when the values that
    decide it were not fitted."""
    observer = has_observer(values)
    if observer is None:
        return None
    if observer:
        return "observer"
    ki = values.get("speed_ki")
    if ki is None:
        return None
    return "integral" if ki >= INTEGRAL_OFF_GAIN else "none"


def motor_sets(values):
    """plant_replay --set strings of fitted values (load_observer_bandwidth -> the time constant)."""
    out = []
    for k, v in values.items():
        if k == "load_observer_bandwidth":
            out.append("motor.load_observer_time_constant=%.6g" % (1.0 / v if v >= OBSERVER_OFF_BANDWIDTH else 0.0))
        else:
            out.append("motor.%s=%.6g" % (k, v))
    return out


def motor_values(motor):
    """The fitted parameters' values of a plant's motor section (a dict of its keys)."""
    tau = motor.get("load_observer_time_constant", 0.0)
    out = {k: motor[k] for k in BAG_PARAMETERS if k in motor}
    out["load_observer_bandwidth"] = 1.0 / tau if tau > 0.0 else 0.0
    return out


# ------------------------------------------------------------------ a simulated bag
def write_simulated_bag(out_path, plant_replay, profile, config=None, overlays=(), sets=(), noise=True):
    """Play ``profile`` (profiles.Profile) through the stock controller on the simulated Jackal
    headless (plant_replay --twist) and write the bag a Jackal would record: /cmd_drive (the stock
    controller's stream), /jackal_velocity_controller/cmd_vel (the profile, 50 Hz), /joint_states,
    /imu/data, /feedback (each side's measured_velocity and measured_travel), /status (1 Hz, drivers
    active). Stamps: the plant's time plus 100 s. ``noise``: the plant YAML's sensor noise (seeded).
    Returns the number of joint-state samples written."""
    import rosbag
    import rospy
    from geometry_msgs.msg import Twist
    from jackal_msgs.msg import Drive, Feedback, Status
    from sensor_msgs.msg import Imu, JointState

    epoch = 100.0
    with tempfile.TemporaryDirectory() as tmp:
        twist_csv = os.path.join(tmp, "profile.csv")
        with open(twist_csv, "w") as f:
            w = csv.writer(f)
            w.writerow(["t", "vx", "wz"])
            for t, vx, wz in profile.points:
                w.writerow(["%.6f" % t, "%.6g" % vx, "%.6g" % wz])
            w.writerow(["%.6f" % profile.duration, "0", "0"])
        commands_csv = os.path.join(tmp, "commands.csv")
        run_plant_replay(plant_replay, ["--twist", twist_csv, "--commands-out", commands_csv, "--out",
                                        os.path.join(tmp, "o.csv")] + (["--noise"] if noise else []),
                         config, overlays, sets)
        with open(commands_csv) as f:
            commands = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
        with open(os.path.join(tmp, "o.csv")) as f:
            samples = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]

    def stamp(t):
        return rospy.Time.from_sec(epoch + t)

    with rosbag.Bag(out_path, "w") as bag:
        for c in commands:
            d = Drive()
            d.mode = int(c["mode"])
            d.drivers = [c["left"], c["right"]]
            bag.write(CMD_DRIVE, d, stamp(c["t"]))
            tw = Twist()
            tw.linear.x, tw.angular.z = profile.value(c["t"])
            bag.write(CMD_VEL, tw, stamp(c["t"]))
        last_imu = None
        next_status = 0.0
        for s in samples:
            t = stamp(s["t"])
            js = JointState()
            js.header.stamp = t
            js.name = list(WHEELS)
            js.position = [s["pos_fl"], s["pos_fr"], s["pos_rl"], s["pos_rr"]]
            js.velocity = [s["vel_fl"], s["vel_fr"], s["vel_rl"], s["vel_rr"]]
            bag.write(JOINT_STATES, js, t)
            fb = Feedback()
            fb.header.stamp = t
            fb.commanded_mode = MODE_VELOCITY
            fb.actual_mode = int(s["cmd_mode"])
            fb.drivers[0].measured_velocity = 0.5 * (s["vel_fl"] + s["vel_rl"])
            fb.drivers[1].measured_velocity = 0.5 * (s["vel_fr"] + s["vel_rr"])
            fb.drivers[0].measured_travel = 0.5 * (s["pos_fl"] + s["pos_rl"])
            fb.drivers[1].measured_travel = 0.5 * (s["pos_fr"] + s["pos_rr"])
            bag.write(FEEDBACK, fb, t)
            if math.isfinite(s["imu_t"]) and s["imu_t"] != last_imu:
                last_imu = s["imu_t"]
                imu = Imu()
                imu.header.stamp = stamp(s["imu_t"])
                imu.header.frame_id = "imu_link"
                imu.orientation.x, imu.orientation.y, imu.orientation.z, imu.orientation.w = (
                    s["qx"], s["qy"], s["qz"], s["qw"])
                imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z = (
                    s["gyro_x"], s["gyro_y"], s["gyro_z"])
                imu.linear_acceleration.x, imu.linear_acceleration.y, imu.linear_acceleration.z = (
                    s["accel_x"], s["accel_y"], s["accel_z"])
                bag.write(IMU, imu, imu.header.stamp)
            if s["t"] >= next_status:
                st = Status()
                st.header.stamp = t
                st.hardware_id = "jackal_aic simulated base"
                st.drivers_active = True
                st.driver_external_stop_present = True
                bag.write(STATUS, st, t)
                next_status += 1.0
    return len(samples)


# ------------------------------------------------------------------ the fit
#: [m] The Jackal's wheel radius (published; the controller's wheel_radius, doc/jackal.md).
WHEEL_RADIUS = 0.098


def turn_deficits(gyro_t, gyro, cmd, separation=1.5 * 0.37559, radius=WHEEL_RADIUS):
    """Steady turn-in-place deficits of a run: for every stretch of >= 1.5 s in which the commanded
    wheel speeds are opposite (|left + right| < 0.05 |right - left|, |right - left| > 1 rad/s), the
    commanded yaw rate r (right - left) / separation minus the mean measured yaw rate (gyro) over the
    stretch's last second [rad/s], in the turn's direction. ``gyro_t``, ``gyro``: the measured yaw
    rate's times [s] and values [rad/s]; ``cmd``: the drive stream (columns t, mode, left, right);
    ``separation``, ``radius``: the stock controller's b_hat and wheel radius [m]. Returns a list of
    (commanded yaw rate, deficit)."""
    out = []
    k = 0
    n = len(cmd)
    while k < n:
        l, r = cmd[k, 2], cmd[k, 3]
        turning = cmd[k, 1] == MODE_VELOCITY and abs(r - l) > 1.0 and abs(l + r) < 0.05 * abs(r - l)
        if not turning:
            k += 1
            continue
        j = k
        while j + 1 < n and abs(cmd[j + 1, 2] - l) < 1e-6 and abs(cmd[j + 1, 3] - r) < 1e-6:
            j += 1
        t_end = cmd[j + 1, 0] if j + 1 < n else cmd[j, 0]
        if t_end - cmd[k, 0] >= 1.5:
            w_cmd = radius * (r - l) / separation
            keep = (gyro_t > t_end - 1.0) & (gyro_t <= t_end)
            if np.any(keep):
                out.append((w_cmd, math.copysign(1.0, w_cmd) * (w_cmd - float(np.mean(gyro[keep])))))
        k = j + 1
    return out


def fit_bag(data, plant_replay, base_motor, keys=tuple(BAG_PARAMETERS), config=None, overlays=(), jobs=2,
            max_evals=120, starts=2, samples=6, seed=1, log=print):
    """Identify the motor parameters ``keys`` (of BAG_PARAMETERS) of the wheel loop that recorded
    ``data`` (a BagData): candidates (the base plant's values ``base_motor``, the same without load
    observer, proportional-only loops, and ``samples`` random ones drawn with ``seed``) scored
    in parallel, then Nelder-Mead (jackal_aic_tools.identify.identify) from the ``starts`` best, ``jobs`` at
    a time, each at most ``max_evals`` replays of the bag's commands on the plant (``config``,
    ``overlays``).
    Returns a dict: 'start' and 'values' (fitted values), 'start_cost', 'cost', 'start_errors',
    'errors' (response_errors()), 'evaluations', 'start_replay' and 'replay' (the replays)."""

    with tempfile.TemporaryDirectory(prefix="plant_identify_bag_") as tmp:
        commands = os.path.join(tmp, "commands.csv")
        write_commands(data, commands)
        return _fit(data, plant_replay, base_motor, keys, config, overlays, jobs, max_evals, starts, samples, seed,
                    log, commands)


def _fit(data, plant_replay, base_motor, keys, config, overlays, jobs, max_evals, starts, samples, seed, log,
         commands):
    """fit_bag() with the bag's commands written to the CSV ``commands``."""
    from concurrent.futures import ThreadPoolExecutor
    from . import identify

    space = identify.Space({k: BAG_PARAMETERS[k] for k in keys})
    start = motor_values(base_motor)
    start = {k: start[k] for k in keys}
    duration = data.duration + 0.05
    count = [0]

    def run(values):
        return replay(plant_replay, commands, data.cmd_is_twist, duration, config, overlays, motor_sets(values))

    def cost_of(values):
        count[0] += 1
        try:
            return fit_cost(response_errors(run(values), data))
        except RuntimeError:
            return float("inf")  # e.g. an invalid combination the plant refuses

    # One candidate per structure of wheel loop, by what holds a turn's load: the plant's values
    # (load observer), the same without observer (integral path), and proportional-only loops (no
    # observer, no integral, no clamp below the current limit) of gains 1, 3 and 10 N m/(rad/s);
    # then random candidates (seeded) in the box.
    candidates = [dict(start)]
    integral = dict(start)
    if "load_observer_bandwidth" in integral:
        integral["load_observer_bandwidth"] = 0.0
        candidates.append(integral)
    for kp in (1.0, 3.0, 10.0):
        c = dict(integral)
        for k, v in (("speed_kp", kp), ("speed_ki", 0.0),
                     ("proportional_limit", BAG_PARAMETERS["proportional_limit"][1])):
            if k in c:
                c[k] = v
        if c not in candidates:
            candidates.append(c)
    rng = np.random.RandomState(seed)
    for _ in range(max(0, samples)):
        candidates.append(space.values(keys, rng.uniform(0.02, 0.98, len(keys))))
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        scored = list(pool.map(cost_of, candidates))
    order = sorted(range(len(candidates)), key=lambda i: scored[i])
    log("  %d candidates scored (the plant's values: cost %.4f); best %s"
        % (len(candidates), scored[0], ", ".join("%.4f" % scored[i] for i in order[:3])))
    units = [[space.to_unit(k, candidates[i][k]) for k in keys] for i in order[:max(1, starts)]]

    def search(args):
        index, u0 = args

        def progress(n, best):
            log("  search %d: %d replays, best cost %.4f" % (index, n, best))

        return identify.nelder_mead(lambda u: cost_of(space.values(keys, u)), u0, max_evals, progress)

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        results = sorted(pool.map(search, enumerate(units)), key=lambda r: r[0])
    best_cost, best_u, _ = results[0]
    values = space.values(keys, best_u)
    return {"start": start, "values": values, "start_cost": scored[0], "cost": best_cost,
            "start_errors": response_errors(run(start), data), "errors": response_errors(run(values), data),
            "evaluations": count[0], "replay": run(values), "start_replay": run(start)}
