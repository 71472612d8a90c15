"""The tracking benchmark's twist profiles: command streams a Jackal actually receives, generated
from fixed parameters (this module is the generator; ``aic_track.py --write-profiles DIR``
writes them, sim/profiles/*.csv are its output).

Every profile is a list of (t [s], vx [m/s], wz [rad/s]) rows at the publisher's rate, played
with zero-order hold; the last row's t ends it (the CSV format of closed_loop_run --profile and
aic_track_metrics). Sources of the figures:

- Joystick teleop: the Jackal's teleop_twist_joy configuration (github.com/jackal/jackal,
  jackal_control/config/teleop_ps4.yaml): scale_linear 0.4 m/s, scale_angular 1.4 rad/s, joy
  deadzone 0.1, autorepeat 20 Hz. The stick is moved by a thumb: its position follows the
  operator's intent through a first-order lag (STICK_TIME_CONSTANT) with a small seeded tremor.
- Planner-style profiles (a local planner publishing at 10 Hz): the set point ramps at
  Clearpath's J100 stock limits (github.com/clearpathrobotics/clearpath_common,
  clearpath_control/config/j100/control/diff_4wd.yaml): 2.0 m/s^2 linear, 4.0 rad/s^2 angular.
"""
import math
import os
import random

#: The J100 stock controller's acceleration limits [m/s^2], [rad/s^2].
LINEAR_ACCEL = 2.0
ANGULAR_ACCEL = 4.0
#: teleop_twist_joy scales of the Jackal [m/s], [rad/s] per full stick; joy_node deadzone.
SCALE_LINEAR = 0.4
SCALE_ANGULAR = 1.4
DEADZONE = 0.1
#: Thumb-on-stick first-order lag [s]; tremor: white noise through the same lag, of about this
#: standard deviation [stick units] (at the centre the deadzone hides it, at full stick the rim
#: clips it); seed of the tremor.
STICK_TIME_CONSTANT = 0.15
STICK_TREMOR = 0.03
TELEOP_SEED = 20
TELEOP_RATE = 20.0  # Hz, joy autorepeat
PLANNER_RATE = 10.0  # Hz

# Operator's intent for the joystick run: (seconds held, forward stick, turn stick), sticks in [-1, 1].
TELEOP_SCRIPT = [
    (1.0, 0.0, 0.0),
    (3.0, 1.0, 0.0),    # full forward: 0.4 m/s
    (2.5, 1.0, 0.5),    # forward, turning left
    (1.5, 0.6, 0.0),
    (1.0, 0.0, 0.0),    # release
    (3.0, 0.0, -1.0),   # turn in place right at full stick: -1.4 rad/s
    (1.0, 0.0, 0.0),
    (2.5, -0.8, 0.0),   # reversing
    (2.0, -0.8, 0.4),   # reversing while turning
    (1.0, 0.0, 0.0),
    (2.5, 0.0, 0.6),    # turn in place left
    (1.0, 1.0, 0.3),    # forward with a weaving stick
    (1.0, 1.0, -0.3),
    (1.0, 1.0, 0.3),
    (1.5, 0.0, 0.0),
]

# Planner-style profiles: (seconds held, vx target, wz target); the published set point ramps
# toward each target at the J100 limits.
PLANNER_SCRIPTS = {
    # A local planner to a goal: ramp to 0.8 m/s, arcs, an approach, a final turn in place to the
    # goal's heading.
    "planner_10hz": [
        (0.5, 0.0, 0.0), (4.0, 0.8, 0.0), (3.0, 0.8, 0.5), (2.0, 0.8, 0.0), (3.0, 0.6, -0.6),
        (2.5, 0.5, 0.0), (1.5, 0.2, 0.0), (0.5, 0.0, 0.0), (2.5, 0.0, 1.0), (1.5, 0.0, 0.0),
    ],
    # Stop and go: bursts of 0.3-1.2 m/s between stops, as in a crowd or at doors.
    "stop_and_go": [
        (0.5, 0.0, 0.0), (2.0, 1.0, 0.0), (1.0, 0.0, 0.0), (1.5, 0.5, 0.0), (1.0, 0.0, 0.0),
        (2.0, 1.2, 0.0), (0.8, 0.0, 0.0), (1.0, 0.3, 0.0), (0.7, 0.0, 0.0), (2.0, 0.8, 0.3),
        (1.5, 0.0, 0.0),
    ],
    # Creeping at 0.05-0.2 m/s, e.g. docking or close to obstacles, with gentle turns and a
    # short reverse.
    "creep": [
        (0.5, 0.0, 0.0), (3.0, 0.05, 0.0), (3.0, 0.1, 0.0), (3.0, 0.2, 0.0), (3.0, 0.15, 0.15),
        (3.0, 0.1, -0.2), (2.0, 0.0, 0.0), (2.0, -0.05, 0.0), (1.5, 0.0, 0.0),
    ],
    # Fast driving at 1.5 m/s with turns (outdoor, the Jackal's top speed is 2.0 m/s).
    "fast": [
        (0.5, 0.0, 0.0), (3.0, 1.5, 0.0), (3.0, 1.5, 0.6), (2.0, 1.5, 0.0), (2.5, 1.5, -0.8),
        (2.0, 1.5, 0.0), (2.0, 0.0, 0.0),
    ],
}

#: S-curves: a planner following a slalom at S_SPEED with wz = S_AMPLITUDE sin(2 pi t / S_PERIOD)
#: for S_CYCLES periods, entered and left through the J100 ramps.
S_SPEED = 0.7
S_AMPLITUDE = 0.7
S_PERIOD = 5.0
S_CYCLES = 3

#: Profile names, in the order of the benchmark's table.
NAMES = ("teleop_joystick", "planner_10hz", "s_curves", "stop_and_go", "creep", "fast")


def _toward(value, target, step):
    """value moved toward target by at most step."""
    return value + max(-step, min(step, target - value))


def ramp(targets, rate, linear_accel=LINEAR_ACCEL, angular_accel=ANGULAR_ACCEL):
    """The published set points of a planner that wants ``targets`` (a list of (vx, wz), one per
    tick of ``rate`` [Hz]) but changes its command by at most linear_accel / rate [m/s] and
    angular_accel / rate [rad/s] per tick. Starts from rest. Returns a list of (vx, wz)."""
    out = []
    vx, wz = 0.0, 0.0
    for tv, tw in targets:
        vx = _toward(vx, tv, linear_accel / rate)
        wz = _toward(wz, tw, angular_accel / rate)
        out.append((vx, wz))
    return out


def _script_targets(script, rate):
    """Per-tick targets of a (seconds, a, b) script at ``rate`` [Hz]."""
    out = []
    for seconds, a, b in script:
        out.extend([(a, b)] * int(round(seconds * rate)))
    return out


def _deadzone(axis):
    """joy_node's deadzone: |axis| < DEADZONE reads 0, the rest is rescaled to reach 1."""
    if abs(axis) < DEADZONE:
        return 0.0
    return math.copysign((abs(axis) - DEADZONE) / (1.0 - DEADZONE), axis)


def teleop(script=TELEOP_SCRIPT, rate=TELEOP_RATE, seed=TELEOP_SEED):
    """Joystick teleop rows: the operator's intent (``script``) through the thumb's lag and
    tremor, the deadzone and the Jackal's teleop scales, published at ``rate`` [Hz]."""
    rng = random.Random(seed)
    dt = 1.0 / rate
    alpha = dt / (STICK_TIME_CONSTANT + dt)  # discrete first-order lag
    stick = [0.0, 0.0]
    tremor = [0.0, 0.0]
    rows = []
    for k, intent in enumerate(_script_targets(script, rate)):
        for i in (0, 1):
            tremor[i] += alpha * (rng.gauss(0.0, STICK_TREMOR / math.sqrt(alpha)) - tremor[i])
            stick[i] += alpha * (intent[i] - stick[i])
        held = [max(-1.0, min(1.0, stick[i] + tremor[i])) for i in (0, 1)]
        rows.append((k * dt, SCALE_LINEAR * _deadzone(held[0]), SCALE_ANGULAR * _deadzone(held[1])))
    return rows + [(len(rows) * dt, 0.0, 0.0)]


def planner(script, rate=PLANNER_RATE):
    """Planner rows: ``script``'s targets through the J100 ramps at ``rate`` [Hz]."""
    sp = ramp(_script_targets(script, rate), rate)
    dt = 1.0 / rate
    return [(k * dt, v, w) for k, (v, w) in enumerate(sp)] + [(len(sp) * dt, 0.0, 0.0)]


def s_curves(rate=PLANNER_RATE):
    """S-curve rows: a slalom at S_SPEED, through the J100 ramps at ``rate`` [Hz]."""
    dt = 1.0 / rate
    targets = [(0.0, 0.0)] * int(round(0.5 * rate))
    lead = int(round(1.0 * rate))  # straight while speeding up
    targets += [(S_SPEED, 0.0)] * lead
    n = int(round(S_CYCLES * S_PERIOD * rate))
    targets += [(S_SPEED, S_AMPLITUDE * math.sin(2.0 * math.pi * k * dt / S_PERIOD)) for k in range(n)]
    targets += [(S_SPEED, 0.0)] * lead + [(0.0, 0.0)] * int(round(1.5 * rate))
    sp = ramp(targets, rate)
    return [(k * dt, v, w) for k, (v, w) in enumerate(sp)] + [(len(sp) * dt, 0.0, 0.0)]


def profile_rows(name):
    """Rows (t, vx, wz) of the benchmark profile ``name`` (one of NAMES)."""
    if name == "teleop_joystick":
        return teleop()
    if name == "s_curves":
        return s_curves()
    if name in PLANNER_SCRIPTS:
        return planner(PLANNER_SCRIPTS[name])
    raise ValueError("no benchmark profile %r (known: %s)" % (name, ", ".join(NAMES)))


def random_planner_script(seed, segments=8):
    """A seeded planner script (seconds, vx, wz) that is not one of the benchmark's: a start at
    rest, ``segments`` targets drawn from what a local planner sends (drives of 0.1-1.2 m/s, most
    with an arc of up to 0.8 rad/s; turns in place of 0.3-1.2 rad/s; pauses; now and then a
    reverse to -0.3 m/s), a stop. Raises ValueError for segments < 1."""
    if segments < 1:
        raise ValueError("random_planner_script: segments must be >= 1")
    rng = random.Random(seed)
    script = [(0.5, 0.0, 0.0)]
    for _ in range(segments):
        kind = rng.random()
        if kind < 0.15:
            script.append((rng.uniform(1.0, 2.5), 0.0, rng.choice((-1.0, 1.0)) * rng.uniform(0.3, 1.2)))
        elif kind < 0.25:
            script.append((rng.uniform(0.5, 1.5), 0.0, 0.0))
        else:
            vx = rng.uniform(-0.3, -0.05) if rng.random() < 0.1 else rng.uniform(0.1, 1.2)
            wz = rng.uniform(-0.8, 0.8) if rng.random() < 0.6 else 0.0
            script.append((rng.uniform(1.0, 3.0), vx, wz))
    return script + [(1.5, 0.0, 0.0)]


def random_teleop_script(seed, segments=10):
    """A seeded joystick script (seconds, forward stick, turn stick) that is not the benchmark's:
    a start at rest, ``segments`` stick positions held 0.8-3 s (forward, reverse, arcs, turns in
    place, releases), a release. Raises ValueError for segments < 1."""
    if segments < 1:
        raise ValueError("random_teleop_script: segments must be >= 1")
    rng = random.Random(seed)
    script = [(1.0, 0.0, 0.0)]
    for _ in range(segments):
        script.append((rng.uniform(0.8, 3.0), rng.choice((0.0, 0.5, 1.0, -0.6, 0.8)),
                       rng.choice((0.0, 0.0, 0.4, -0.5, 1.0, -1.0))))
    return script + [(1.5, 0.0, 0.0)]


def _write_profile(path, rows, comment):
    """Write ``rows`` (t [s], vx [m/s], wz [rad/s]) to ``path`` as csv_text(rows, comment)."""
    with open(path, "w") as f:
        f.write(csv_text(rows, comment))
    return path


def write_random(directory, count, seed):
    """Write ``count`` seeded planner streams and ``count`` seeded joystick streams, none of them
    the benchmark's, as <directory>/random_planner_<k>.csv and random_teleop_<k>.csv with k =
    seed .. seed + count - 1 (the seed of each: the same files for the same arguments); returns
    the paths. For checking that a configuration is not tuned to the benchmark's own profiles.
    Raises ValueError for count < 1."""
    if count < 1:
        raise ValueError("write_random: count must be >= 1")
    os.makedirs(directory, exist_ok=True)
    paths = []
    for k in range(seed, seed + count):
        for name, rows in (("random_planner_%d" % k, planner(random_planner_script(k))),
                           ("random_teleop_%d" % k, teleop(random_teleop_script(k), seed=k))):
            paths.append(_write_profile(
                os.path.join(directory, name + ".csv"), rows,
                "%s: a seeded command stream outside the tracking benchmark (t [s], vx [m/s],\n"
                "wz [rad/s]; zero-order hold; the last row's t ends it). Generated by\n"
                "aic_track.py --write-random-profiles from jackal_aic_tools/track/track_profiles.py." % name))
    return paths


def csv_text(rows, comment):
    """The CSV file of ``rows``: '#' comment lines, the header t,vx,wz, one row per set point
    (t to the millisecond, speeds to 0.1 mm/s and 0.1 mrad/s; -0 written as 0)."""
    lines = ["# " + c for c in comment.splitlines()] + ["t,vx,wz"]
    for t, v, w in rows:
        lines.append("%.3f,%.4f,%.4f" % (t, v + 0.0, w + 0.0))
    return "\n".join(lines).replace("-0.0000", "0.0000") + "\n"


def write_all(directory):
    """Write every benchmark profile as <directory>/<name>.csv; returns the paths."""
    os.makedirs(directory, exist_ok=True)
    paths = []
    for name in NAMES:
        paths.append(_write_profile(
            os.path.join(directory, name + ".csv"), profile_rows(name),
            "%s: tracking benchmark profile (t [s], vx [m/s], wz [rad/s]; zero-order hold;\n"
            "the last row's t ends it). Generated by aic_track.py --write-profiles from\n"
            "jackal_aic_tools/track/track_profiles.py; do not edit." % name))
    return paths
