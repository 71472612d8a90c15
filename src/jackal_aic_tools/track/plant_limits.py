"""Plant-limited pairs of the tracking benchmark: where the plant, not the controller, decides.

For a profile x plant variant pair, the ideal controller (`closed_loop_run --controller ideal`:
the command sequence learned over repeated runs by iterative learning control, knowing the whole
profile in advance and the ground truth; sim/harness closed_loop.hpp, runIdealController) is the
plant's best response to the profile. The latency floor (driving.floor_rms) is the error of a
servo that only has the variant's latency and no preview of the stream. A channel (vx or wz) of a
pair is *plant-limited* when the ideal controller's RMS error exceeds PLANT_LIMIT_RATIO x the
floor: with the whole profile known in advance the ideal controller ends well below the floor
wherever the plant can follow (0.2-0.8 x on the default plant), so an ideal above it means the
plant cannot follow that channel, whatever the controller (doc/tools.md, 'Plant-limited pairs').

The reason names the error's largest measured part in the ideal run (closed_loop_run's "plant"
figures over the profile's span): the wheel loop not following its set point (the MCU loop's
lag; with the share of the time the motor torque sits at its limit) or the wheels slipping
against the body (wheel speeds' twist minus the ground truth).

The acceleration-bounded latency floor (doc/tools.md, 'Latency floor') bounds each wheel of the
floor's ideal servo by the wheel loop's largest acceleration: wheel_acceleration() from the
plant's motor keys (common.wheel_loop_model, the robot model's A_w), on the robot's wheel radius and geometric track (urdf_geometry());
floor_accelerations() also gives what it is on the body alone.

Pure functions but run_ideal() and urdf_geometry(); the benchmark's modules (driving,
track_suite) use them.
"""
import math
import xml.etree.ElementTree as ElementTree

from ..common import closed_loop
from ..common.wheel_loop_model import wheel_acceleration

#: A channel is plant-limited when the ideal controller's RMS error > this x the latency floor.
PLANT_LIMIT_RATIO = 1.2
#: Share of the run with the motor torque at its limit above which the reason is the torque limit.
TORQUE_LIMITED_SHARE = 0.05
CHANNELS = ("vx", "wz")
UNITS = {"vx": "m/s", "wz": "rad/s"}
#: The URDF wheel joints of each side (the plant's, jackal_sim/plant/robot_description.hpp).
LEFT_WHEELS = ("front_left_wheel", "rear_left_wheel")
RIGHT_WHEELS = ("front_right_wheel", "rear_right_wheel")


def ideal_command(exe, plant_config, args, overlay=None, plant_sets=()):
    """closed_loop_run's argument list of the ideal controller with the profile arguments ``args``
    (e.g. ["--profile", CSV]), the plant YAML ``plant_config``, the overlay file ``overlay`` (None:
    the plant YAML alone) and plant KEY=VALUE overrides ``plant_sets``; ideal sensors (the ideal
    controller uses the ground truth; sensor noise would change no figure of it); a run that does
    not follow is reported, not an error (closed_loop.KEEP_GOING)."""
    return closed_loop.command(exe, "ideal", args, plant_config=plant_config, overlays=[overlay] if overlay else [],
                               plant_sets=plant_sets, noise=False, keep_going=True)


def ideal_figures(result):
    """The ideal controller's figures of closed_loop_run's JSON ``result`` (--controller ideal):
    {"vx", "wz": RMS error of the ground truth [m/s, rad/s], "plant": the run's "plant" dict
    (torque_limited, wheel_loop {vx, wz}, slip {vx, wz}), "runs", "best"}. Raises KeyError when
    the result is not an ideal run's."""
    t = result["tracking"]["truth"]
    return {"vx": t["vx"]["rms"], "wz": t["wz"]["rms"], "plant": result["plant"],
            "runs": result["ideal"]["runs"], "best": result["ideal"]["best"]}


def run_ideal(exe, plant_config, profile, overlay=None):
    """Run the ideal controller (ideal_command) and return ideal_figures(). Raises RuntimeError
    when closed_loop_run fails."""
    return ideal_figures(closed_loop.execute(ideal_command(exe, plant_config, ["--profile", profile], overlay)).result)


def reason(channel, ratio, plant):
    """The reason string of a plant-limited ``channel`` ("vx" or "wz") whose ideal error is
    ``ratio`` x the floor, from the ideal run's ``plant`` figures (ideal_figures()["plant"]):
    the larger of the wheel loop's RMS lag and the wheels' RMS slip on that channel names the
    cause; a wheel-loop lag is the torque limit when the torque sits at its limit at least
    TORQUE_LIMITED_SHARE of the time, else the MCU's loop below the limit.
    e.g. "ideal 3.7 x floor on wz: the wheel loop lags its set point (RMS 2.19 rad/s), torque at
    its limit 2 % of the time: the MCU's loop, not the motor". Raises KeyError on a bad channel."""
    unit = UNITS[channel]
    lag, slip = plant["wheel_loop"][channel], plant["slip"][channel]
    share = plant["torque_limited"]
    head = "ideal %.1f x floor on %s: " % (ratio, channel)
    if slip >= lag:
        return head + "the wheels slip against the body (RMS %.3g %s; wheel loop lag %.3g %s)" % (
            slip, unit, lag, unit)
    what = "the motor's torque limit" if share >= TORQUE_LIMITED_SHARE else "the MCU's loop, not the motor"
    return head + "the wheel loop lags its set point (RMS %.3g %s), torque at its limit %.0f %% of the time: %s" % (
        lag, unit, 100.0 * share, what)


def classify(ideal, floor, limit=PLANT_LIMIT_RATIO):
    """Per channel, whether the plant limits a pair: ``ideal`` is ideal_figures() (or a dict
    with "vx", "wz" and "plant"), ``floor`` {"vx", "wz"} the latency floor's RMS [m/s, rad/s].
    Returns {"vx": reason or None, "wz": ...}: a reason() string where ideal > limit x floor, None
    where the plant follows (a zero floor: limited when the ideal error is > 0). Raises KeyError on
    missing figures, ValueError on a negative or non-finite error."""
    out = {}
    for ch in CHANNELS:
        i, f = float(ideal[ch]), float(floor[ch])
        if not (math.isfinite(i) and math.isfinite(f)) or i < 0.0 or f < 0.0:
            raise ValueError("classify: bad RMS error on %s: ideal %r, floor %r" % (ch, i, f))
        ratio = i / f if f > 0.0 else (math.inf if i > 0.0 else 0.0)
        out[ch] = reason(ch, ratio, ideal["plant"]) if ratio > limit else None
    return out


def gmean(values):
    """(geometric mean, count) of the positive values (None, 0 when there is none)."""
    vals = [v for v in values if v is not None and v > 0.0]
    if not vals:
        return None, 0
    return math.exp(sum(math.log(v) for v in vals) / len(vals)), len(vals)


def split(items):
    """``items``: (value, limited) pairs. Returns (the values where limited is falsy, those where
    it is truthy): the plant-following and the plant-limited ones, in order."""
    items = list(items)
    following = [v for v, lim in items if not lim]
    limited = [v for v, lim in items if lim]
    return following, limited


def floor_accelerations(motor, radius, track):
    """The acceleration limits of the acceleration-bounded latency floor: {"wheel_acceleration": A_w
    [rad/s^2] (wheel_acceleration(motor)), "linear": A_w r [m/s^2], "angular": 2 A_w r / track
    [rad/s^2]}, ``radius`` r and ``track`` the wheel radius and the geometric track (left-right
    wheel distance) [m] (urdf_geometry). The geometric track, not the larger effective skid
    separation, gives the larger yaw acceleration: the floor stays below every controller. Raises
    ValueError as wheel_acceleration, or when radius or track is not > 0."""
    if not (radius > 0.0 and track > 0.0 and math.isfinite(radius) and math.isfinite(track)):
        raise ValueError("floor_accelerations: wheel radius %r m and track %r m must be > 0" % (radius, track))
    a_w = wheel_acceleration(motor)
    return {"wheel_acceleration": a_w, "linear": a_w * radius, "angular": 2.0 * a_w * radius / track}


def urdf_geometry(path):
    """(wheel radius [m], track [m]) of the robot description ``path`` (a URDF, the plant's
    sim/urdf/jackal.urdf): the mean radius of the wheel links' collision cylinders and the lateral
    distance between the mean left and right wheel-joint origins (LEFT_WHEELS, RIGHT_WHEELS), as
    the plant's RobotDescription::wheelRadius() and track(). Raises OSError when the file cannot
    be read, ValueError naming the joint or link the URDF lacks."""
    robot = ElementTree.parse(path).getroot()
    joints = {j.get("name"): j for j in robot.iter("joint")}
    links = {l.get("name"): l for l in robot.iter("link")}
    radii, lateral = [], {}
    for name in LEFT_WHEELS + RIGHT_WHEELS:
        joint = joints.get(name)
        origin = joint.find("origin") if joint is not None else None
        child = joint.find("child") if joint is not None else None
        if origin is None or child is None:
            raise ValueError("urdf_geometry: %s has no wheel joint %s with an origin and a child" % (path, name))
        lateral[name] = float(origin.get("xyz", "0 0 0").split()[1])
        cylinder = links.get(child.get("link"))
        cylinder = cylinder.find("collision/geometry/cylinder") if cylinder is not None else None
        if cylinder is None:
            raise ValueError("urdf_geometry: %s: the link of %s has no collision cylinder" % (path, name))
        radii.append(float(cylinder.get("radius")))
    left = sum(lateral[n] for n in LEFT_WHEELS) / len(LEFT_WHEELS)
    right = sum(lateral[n] for n in RIGHT_WHEELS) / len(RIGHT_WHEELS)
    return sum(radii) / len(radii), abs(left - right)
