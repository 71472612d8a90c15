"""Set-point profiles for step-response experiments.

A profile maps profile time t [s] (0 = start of the profile) to a desired body twist
(linear.x [m/s], angular.z [rad/s]) and lists its transitions ("segments"), each of which
is analysed as one step response (thesis ch. 5 experiments; doc/active_inference.md,
'Step-response metrics and experiments').
"""
import math
from collections import namedtuple

#: One set-point transition: on ``channel`` ('vx' or 'wz') the set point jumps from
#: ``start`` to ``target`` at profile time ``t0`` and is held until ``t1`` [s].
Segment = namedtuple("Segment", "t0 t1 channel start target")

CHANNELS = ("vx", "wz")
UNITS = {"vx": "m/s", "wz": "rad/s"}


class Profile(object):
    """Base class: piecewise-constant set point given by breakpoints.

    ``points`` is a list of (t [s], vx [m/s], wz [rad/s]) sorted by t, the set point being
    held (zero-order hold) from each t to the next; ``duration`` [s] ends the profile.
    """

    def __init__(self, points, duration, name):
        if not points:
            raise ValueError("profile %s: no set points" % name)
        last = -math.inf
        for t, vx, wz in points:
            if not all(math.isfinite(x) for x in (t, vx, wz)):
                raise ValueError("profile %s: non-finite value in (t=%r, vx=%r, wz=%r)" % (name, t, vx, wz))
            if t < 0.0 or t < last:
                raise ValueError("profile %s: times must be >= 0 and non-decreasing (t=%r after %r)" % (name, t, last))
            last = t
        if not (math.isfinite(duration) and duration > points[-1][0]):
            raise ValueError("profile %s: duration %r must exceed the last breakpoint %r"
                             % (name, duration, points[-1][0]))
        self.points = list(points)
        self.duration = float(duration)
        self.name = name

    def value(self, t):
        """Set point (vx [m/s], wz [rad/s]) at profile time ``t`` [s] (zero before the first point)."""
        vx, wz = 0.0, 0.0
        for tp, pvx, pwz in self.points:
            if tp <= t:
                vx, wz = pvx, pwz
            else:
                break
        return vx, wz

    def segments(self):
        """Every transition of the set point, per channel, as a :class:`Segment`."""
        out = []
        for ci, ch in enumerate(CHANNELS):
            prev = 0.0
            changes = []
            for tp, vx, wz in self.points:
                v = (vx, wz)[ci]
                if v != prev:
                    changes.append((tp, prev, v))
                prev = v
            for k, (tp, a, b) in enumerate(changes):
                t1 = changes[k + 1][0] if k + 1 < len(changes) else self.duration
                out.append(Segment(tp, t1, ch, a, b))
        return sorted(out, key=lambda s: s.t0)

    def channels(self):
        """Channels ('vx', 'wz') on which the set point ever changes."""
        chs = {s.channel for s in self.segments()}
        return [c for c in CHANNELS if c in chs] or ["vx"]

    def write_csv(self, path):
        """The profile as a CSV file of rows t,vx,wz (the format of from_csv and closed_loop_run
        --profile): of breakpoints at the same time the last one, then the end time."""
        rows = []
        for t, vx, wz in self.points:
            if rows and rows[-1][0] == t:
                rows.pop()
            rows.append((t, vx, wz))
        with open(path, "w") as f:
            f.write("t,vx,wz\n")
            for t, vx, wz in rows + [(self.duration, 0.0, 0.0)]:
                f.write("%r,%r,%r\n" % (float(t), float(vx), float(wz)))
        return path

    def max_abs(self, channel):
        i = CHANNELS.index(channel)
        return max(abs(p[1 + i]) for p in self.points)


def step(v=0.5, w=0.0, t_step=0.5, hold=3.0):
    """Step from rest to linear ``v`` [m/s] (and/or angular ``w`` [rad/s]) at ``t_step`` [s], held ``hold`` [s]."""
    if hold <= 0.0 or t_step < 0.0:
        raise ValueError("step: hold must be > 0 and t_step >= 0")
    name = "step_v%g" % v if w == 0.0 else ("step_w%g" % w if v == 0.0 else "step_v%g_w%g" % (v, w))
    return Profile([(0.0, 0.0, 0.0), (t_step, v, w)], t_step + hold, name)


def square(low=0.1, high=0.5, period=4.0, cycles=2, t_lead=2.0, channel="vx"):
    """Square wave between ``low`` and ``high`` (m/s for 'vx', rad/s for 'wz').

    Starts at rest, goes to ``low`` at t = 0.5 s, holds it ``t_lead`` [s] to settle, then
    alternates high/low every half ``period`` [s] for ``cycles`` full periods.
    """
    if period <= 0.0 or cycles < 1:
        raise ValueError("square: period must be > 0 and cycles >= 1")
    def pt(t, x):
        return (t, x, 0.0) if channel == "vx" else (t, 0.0, x)
    pts = [pt(0.0, 0.0), pt(0.5, low)]
    t = 0.5 + t_lead
    for _ in range(cycles):
        pts.append(pt(t, high))
        pts.append(pt(t + period / 2.0, low))
        t += period
    return Profile(pts, t, "square_%g_%g_T%g" % (low, high, period))


def mirror(profile, lead=0.5):
    """The profile that drives the ideal path of ``profile`` back to its start: time-reversed and
    negated (a twist held over [t_i, t_i+1) is played negated over [T - t_i+1, T - t_i)), after
    ``lead`` [s] of rest so that its first transition is a step from rest; the rest the out profile
    starts with is left out (the run's rest phase follows the mirror). A step's mirror is the same
    step backwards. aic_field_trial.py drives every run back with it; a ramp's end becomes its
    start, so a stick eased off becomes a stick pushed to its stop. Returns a Profile named '<name>_mirror'."""
    pts = [tuple(map(float, p)) for p in profile.points]
    if pts[0][0] > 0.0:
        pts.insert(0, (0.0, 0.0, 0.0))
    T = profile.duration
    spans = []
    for k, (t, vx, wz) in enumerate(pts):
        t_next = pts[k + 1][0] if k + 1 < len(pts) else T
        if t_next > t:
            spans.append((t, t_next, vx, wz))
    while len(spans) > 1 and spans[0][2] == 0.0 and spans[0][3] == 0.0:
        spans.pop(0)  # the out run's rest at its start: the mirror ends at its last motion (the run's rest follows)
    T = spans[-1][1] - spans[0][0]
    t_first = spans[0][0]
    spans = [(a - t_first, b - t_first, vx, wz) for a, b, vx, wz in spans]
    out = [(0.0, 0.0, 0.0)]
    for t, t_next, vx, wz in reversed(spans):
        out.append((lead + T - t_next, -vx if vx else 0.0, -wz if wz else 0.0))
    # merge equal neighbours (a profile ending at rest starts its mirror with more rest)
    merged = [out[0]]
    for p in out[1:]:
        if (p[1], p[2]) != (merged[-1][1], merged[-1][2]):
            merged.append(p)
    return Profile(merged, lead + T, profile.name + "_mirror")


def from_csv(path):
    """Profile from a CSV file of rows t,vx,wz (t [s] >= 0 and increasing, vx [m/s], wz [rad/s];
    header optional, a header without wz means 0; the last row's t ends the profile), read and
    checked by the core's reader through aic_track_metrics (jackal_aic_tools.common.tracking). Raises
    ValueError naming the file and line of what is wrong."""
    from . import tracking
    d = tracking.load_profile(path)
    prof = Profile([tuple(p) for p in d["points"]], d["duration"], "csv_" + d["name"])
    prof.csv_path = path
    return prof
