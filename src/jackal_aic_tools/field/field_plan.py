"""Field-trial session plans: reading and checking the YAML plan, the runs it expands to, each
run's ideal path and the corridor it must stay in, and the dry-run text (doc/field_trials.md).

A plan (config/field_trials/standard.yaml is the shipped one, commented key by key) lists
experiments: step responses, square waves, tracking profiles (sim/profiles/*.csv or a path) and
the identification sequence. Each experiment runs for every controller of the plan (the AIC and
the stock controller, alternating which goes first), and every run is followed by its mirror: the
same profile time-reversed and negated, which drives the ideal path back to its start, so the
robot goes out and back and stays inside the corridor the plan states. The plan is refused
(PlanError, naming the file, the key and what is wrong) when a value is out of range, a profile
exceeds the speed limits, or an ideal path (with the margin) leaves the corridor.

Frames: a run's path is in the frame of the pose it starts from (x ahead, y to the left [m]);
the corridor is a rectangle in the session's start frame: ``ahead`` and ``behind`` along x,
``left`` and ``right`` along y [m]. Pure Python (numpy), no ROS.
"""
import math
import os

import numpy as np
import yaml

from ..common import profiles
from ..common.profiles import mirror

#: Controllers a plan may name.
CONTROLLERS = ("aic", "stock")
#: The Jackal's top speeds (doc/jackal.md: 2.0 m/s; the stock controller's 4.0 rad/s): limits above are refused.
TOP_LINEAR = 2.0
TOP_ANGULAR = 4.0
#: Step of the ideal-path integration [s].
PATH_DT = 0.01

#: Defaults of the optional keys (units in doc/field_trials.md and the standard plan).
DEFAULTS = {
    "controllers": ["aic", "stock"],
    "alternate": True,
    "margin": 0.5,
    "settle": 1.0,
    "rest": 1.5,
    "rate": 50.0,
    "safety": {"data_timeout": 0.5, "status_timeout": 3.0, "overspeed_factor": 1.3, "start_tolerance": 0.5,
               "heading_tolerance": 0.5, "stop_hold": 1.0, "fault_persistence": 0.25},
    "homing": {"enabled": True, "max_linear": 0.3, "max_angular": 0.8, "min_angular": 0.5, "tolerance": 0.1,
               "heading_tolerance": 0.1, "timeout": 30.0},
}
#: (min, max) of every number a plan may set; min exclusive where the tuple's third item is True.
RANGES = {
    "limits.max_linear": (0.0, TOP_LINEAR, True),
    "limits.max_angular": (0.0, TOP_ANGULAR, True),
    "corridor.ahead": (0.0, 50.0, True),
    "corridor.behind": (0.0, 50.0, True),
    "corridor.left": (0.0, 50.0, True),
    "corridor.right": (0.0, 50.0, True),
    "margin": (0.0, 5.0, False),
    "settle": (0.2, 10.0, False),
    "rest": (0.5, 10.0, False),
    "rate": (10.0, 100.0, False),
    "safety.data_timeout": (0.05, 5.0, False),
    "safety.status_timeout": (0.5, 10.0, False),
    "safety.overspeed_factor": (1.0, 3.0, True),
    "safety.start_tolerance": (0.05, 5.0, False),
    "safety.heading_tolerance": (0.05, math.pi, False),
    "safety.stop_hold": (0.2, 5.0, False),
    "safety.fault_persistence": (0.0, 2.0, False),
    "homing.max_linear": (0.0, 1.0, True),
    "homing.max_angular": (0.0, 2.0, True),
    "homing.min_angular": (0.0, 2.0, False),
    "homing.tolerance": (0.02, 1.0, False),
    "homing.heading_tolerance": (0.02, 1.0, False),
    "homing.timeout": (1.0, 300.0, False),
}


class PlanError(ValueError):
    """A plan that cannot be run; the message names the file, the key and what is wrong."""


class Run(object):
    """One run of a session: ``index`` (from 0), ``experiment`` (its name), ``controller`` ('aic' or
    'stock'), ``direction`` ('out' or 'back': the mirror of the out run before it), ``profile``
    (profiles.Profile, set point in profile time [s]), ``kind`` (step, square, profile,
    identification) and ``name`` (file stem of its bag: NN_experiment_controller_direction)."""

    def __init__(self, index, experiment, controller, direction, profile, kind):
        self.index = index
        self.experiment = experiment
        self.controller = controller
        self.direction = direction
        self.profile = profile
        self.kind = kind
        self.name = "%02d_%s_%s_%s" % (index, experiment, controller, direction)

    def to_dict(self):
        """The run as the session summary stores it (the profile's breakpoints and duration [s])."""
        return {"index": self.index, "name": self.name, "experiment": self.experiment, "kind": self.kind,
                "controller": self.controller, "direction": self.direction,
                "profile": {"name": self.profile.name, "duration": self.profile.duration,
                            "points": [list(map(float, p)) for p in self.profile.points]}}


def profile_from_dict(d):
    """The profiles.Profile of a run dict's "profile" (Run.to_dict()); ValueError if it is malformed."""
    return profiles.Profile([tuple(p) for p in d["points"]], float(d["duration"]), d["name"])


class Plan(object):
    """A checked session plan (load_plan()). Attributes: ``path``, ``name``, ``controllers``,
    ``alternate``, ``max_linear`` [m/s], ``max_angular`` [rad/s], ``corridor`` (dict ahead, behind,
    left, right [m]), ``margin`` [m], ``settle`` and ``rest`` [s] (zero set point before and after
    each profile), ``rate`` [Hz], ``safety`` (dict: data_timeout, status_timeout [s],
    overspeed_factor [-], start_tolerance [m], heading_tolerance [rad], stop_hold [s],
    fault_persistence [s]), ``homing``
    (dict: enabled, max_linear [m/s], max_angular, min_angular [rad/s], tolerance [m],
    heading_tolerance [rad], timeout [s]: the slow return to the start pose before an out run),
    ``experiments`` (list of (name, kind, profile)) and ``runs`` (list of Run)."""

    def run_duration(self, run):
        """Set-point time of one run [s]: settle + profile + rest."""
        return self.settle + run.profile.duration + self.rest

    def duration(self):
        """Set-point time of the whole session [s] (without the switching and waiting between runs)."""
        return sum(self.run_duration(r) for r in self.runs)

    def to_dict(self):
        """The plan's settings (not its runs) as the session summary stores them."""
        return {"path": self.path, "name": self.name, "controllers": list(self.controllers),
                "limits": {"max_linear": self.max_linear, "max_angular": self.max_angular},
                "corridor": dict(self.corridor), "margin": self.margin, "settle": self.settle, "rest": self.rest,
                "rate": self.rate, "safety": dict(self.safety), "homing": dict(self.homing)}


def _err(path, key, msg):
    return PlanError("%s: %s: %s" % (path, key, msg))


def _number(path, key, value):
    """value as a finite float checked against RANGES[key]."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _err(path, key, "must be a number, not %r" % (value,))
    v = float(value)
    if not math.isfinite(v):
        raise _err(path, key, "must be finite, not %r" % (value,))
    if key in RANGES:
        lo, hi, open_lo = RANGES[key]
        if (v <= lo if open_lo else v < lo) or v > hi:
            raise _err(path, key, "%g is outside %s%g, %g]" % (v, "(" if open_lo else "[", lo, hi))
    return v


def _mapping(path, key, value, known):
    if not isinstance(value, dict):
        raise _err(path, key, "must be a mapping, not %r" % (value,))
    unknown = sorted(set(value) - set(known))
    if unknown:
        raise _err(path, key, "unknown key(s) %s (known: %s)" % (", ".join(map(str, unknown)), ", ".join(known)))
    return value


def profile_dir():
    """The benchmark's profiles (sim/profiles) of the package: beside this module in a source
    checkout, else the installed package's share folder (rospack)."""
    here = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "..", "sim",
                                         "profiles"))
    if os.path.isdir(here):
        return here
    from ..common import cli
    pkg = cli.package_path()
    return os.path.join(pkg, "sim", "profiles") if pkg else here


def _experiment(path, k, e, profile_root, limits=(TOP_LINEAR, TOP_ANGULAR)):
    """(name, kind, profile) of the plan's k-th experiment; the identification sequence is played
    within ``limits`` (max |vx| [m/s], max |wz| [rad/s])."""
    key = "experiments[%d]" % k
    if not isinstance(e, dict) or "name" not in e:
        raise _err(path, key, "must be a mapping with a name and one of step, square, profile, identification")
    name = e["name"]
    if not isinstance(name, str) or not name or not all(c.isalnum() or c in "._-" for c in name):
        raise _err(path, key + ".name", "%r: use letters, digits, '.', '_', '-' (it names the bags)" % (name,))
    kinds = [kd for kd in ("step", "square", "profile", "identification") if kd in e]
    _mapping(path, key, e, ("name", "step", "square", "profile", "identification"))
    if len(kinds) != 1:
        raise _err(path, key, "needs exactly one of step, square, profile, identification (has %s)"
                   % (", ".join(kinds) or "none"))
    kind = kinds[0]
    item = e[kind]
    sub = "%s.%s" % (key, kind)
    try:
        if kind == "step":
            _mapping(path, sub, item, ("v", "w", "t_step", "hold"))
            v = _number(path, sub + ".v", item.get("v", 0.0))
            w = _number(path, sub + ".w", item.get("w", 0.0))
            if v == 0.0 and w == 0.0:
                raise _err(path, sub, "v and w are both zero: nothing to step")
            prof = profiles.step(v=v, w=w, t_step=_number(path, sub + ".t_step", item.get("t_step", 0.5)),
                                 hold=_number(path, sub + ".hold", item.get("hold", 3.0)))
        elif kind == "square":
            _mapping(path, sub, item, ("low", "high", "period", "cycles", "lead", "channel"))
            channel = item.get("channel", "vx")
            if channel not in profiles.CHANNELS:
                raise _err(path, sub + ".channel", "%r is not vx or wz" % (channel,))
            cycles = item.get("cycles", 1)
            if isinstance(cycles, bool) or not isinstance(cycles, int) or not 1 <= cycles <= 10:
                raise _err(path, sub + ".cycles", "must be an integer in [1, 10], not %r" % (cycles,))
            prof = profiles.square(low=_number(path, sub + ".low", item.get("low", 0.1)),
                                   high=_number(path, sub + ".high", item.get("high", 0.5)),
                                   period=_number(path, sub + ".period", item.get("period", 4.0)), cycles=cycles,
                                   t_lead=_number(path, sub + ".lead", item.get("lead", 2.0)), channel=channel)
        elif kind == "profile":
            if not isinstance(item, str) or not item:
                raise _err(path, sub, "must be a profile name of sim/profiles or a CSV path, not %r" % (item,))
            csv_path = item if item.endswith(".csv") else os.path.join(profile_root, item + ".csv")
            if not os.path.isabs(csv_path) and not os.path.exists(csv_path):
                csv_path = os.path.join(os.path.dirname(os.path.abspath(path)), csv_path)
            if not os.path.isfile(csv_path):
                raise _err(path, sub, "no profile %s" % csv_path)
            prof = profiles.from_csv(csv_path)
        else:
            from ..identify import bag_identification
            if not isinstance(item, str):
                raise _err(path, sub, "must name a sequence (%s), not %r" % (
                    ", ".join(sorted(bag_identification.SEQUENCES)), item))
            prof = bag_identification.sequence_profile(item, min(limits[0], bag_identification.MAX_LINEAR),
                                                       min(limits[1], bag_identification.MAX_ANGULAR))
    except PlanError:
        raise
    except ValueError as ex:  # the profile constructors' and the CSV reader's messages
        raise _err(path, sub, str(ex))
    return name, kind, prof


def ideal_path(profile, settle=0.0, rest=0.0, start=(0.0, 0.0, 0.0), dt=PATH_DT):
    """The pose of a unicycle driven exactly by the set point: ``settle`` [s] at rest, the profile,
    ``rest`` [s] at rest, from ``start`` (x [m], y [m], heading [rad]). Returns an (n, 4) array of
    t [s] (from the profile's start), x, y [m], heading [rad]; exact for piecewise-constant twists
    (arcs integrated in closed form over each step of ``dt`` [s])."""
    x, y, th = map(float, start)
    end = profile.duration + rest
    cuts = sorted({0.0, end} | {float(p[0]) for p in profile.points if 0.0 < p[0] < profile.duration} |
                  {profile.duration})
    out = [(0.0, x, y, th)]
    for a, b in zip(cuts[:-1], cuts[1:]):
        mid = 0.5 * (a + b)  # the twist held over [a, b): no breakpoint inside
        vx, wz = profile.value(mid) if mid < profile.duration else (0.0, 0.0)
        n = max(1, int(math.ceil((b - a) / dt - 1e-9)))
        h = (b - a) / n
        for k in range(n):
            if abs(wz) < 1e-9:
                x += vx * h * math.cos(th)
                y += vx * h * math.sin(th)
            else:
                x += vx / wz * (math.sin(th + wz * h) - math.sin(th))
                y -= vx / wz * (math.cos(th + wz * h) - math.cos(th))
            th += wz * h
            out.append((a + (k + 1) * h, x, y, th))
    return np.array(out)


def in_frame(xy, origin):
    """Points ``xy`` ((n, 2) world x, y [m]) in the frame of ``origin`` (x, y, heading): (n, 2) of
    ahead, left [m]."""
    x0, y0, th = origin
    c, s = math.cos(th), math.sin(th)
    d = np.asarray(xy, dtype=float).reshape(-1, 2) - (x0, y0)
    return np.column_stack((c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]))


def extents(xy):
    """How far points ((n, 2) ahead, left [m], in the start frame) reach: dict ahead, behind, left,
    right (each >= 0) and max_distance from the origin [m]."""
    a = np.asarray(xy, dtype=float).reshape(-1, 2)
    return {"ahead": max(0.0, float(a[:, 0].max())), "behind": max(0.0, float(-a[:, 0].min())),
            "left": max(0.0, float(a[:, 1].max())), "right": max(0.0, float(-a[:, 1].min())),
            "max_distance": float(np.hypot(a[:, 0], a[:, 1]).max())}


def outside(xy, corridor, margin=0.0):
    """How far the points ((n, 2) ahead, left [m], start frame) reach beyond the corridor shrunk by
    ``margin`` [m]: 0 when all are inside, else the largest excess [m] (a geofence breach is
    outside(...) > 0 with margin 0)."""
    e = extents(xy)
    return max(0.0, max(e[side] - (corridor[side] - margin) for side in ("ahead", "behind", "left", "right")))


def run_path(plan, run, start=(0.0, 0.0, 0.0)):
    """The ideal path of one run of ``plan`` (ideal_path with the plan's settle and rest) from
    ``start`` (x, y, heading in the session's start frame)."""
    return ideal_path(run.profile, plan.settle, plan.rest, start)


def load_plan(path, profile_root=None):
    """Read and check the plan YAML at ``path``; sim/profiles names resolve in ``profile_root``
    (default: profile_dir()). Returns a Plan. Raises PlanError naming the file, the key and what
    is wrong: unknown keys, missing limits or corridor, a number out of RANGES, an unknown
    controller, a bad experiment, a profile beyond the limits, an ideal path (and its mirror,
    chained from the end of the out run) that does not fit the corridor shrunk by the margin."""
    try:
        with open(path) as f:
            d = yaml.safe_load(f)
    except OSError as ex:
        raise PlanError("%s: cannot read: %s" % (path, ex.strerror or ex))
    except yaml.YAMLError as ex:
        raise PlanError("%s: not valid YAML: %s" % (path, ex))
    return plan_from_dict(d, path, profile_root)


def plan_from_dict(d, path="<plan>", profile_root=None):
    """The Plan of an already parsed YAML mapping ``d`` (load_plan(); ``path`` names it in errors)."""
    top = ("name", "controllers", "alternate", "limits", "corridor", "margin", "settle", "rest", "rate", "safety",
           "homing", "experiments")
    _mapping(path, "plan", d, top)
    for key in ("limits", "corridor", "experiments"):
        if key not in d:
            raise _err(path, key, "missing (the plan must state it)")
    p = Plan()
    p.path = path
    p.name = str(d.get("name", os.path.splitext(os.path.basename(path))[0]))
    ctrl = d.get("controllers", DEFAULTS["controllers"])
    if not isinstance(ctrl, list) or not ctrl or any(c not in CONTROLLERS for c in ctrl) or len(set(ctrl)) != len(ctrl):
        raise _err(path, "controllers", "must list aic and/or stock once each, not %r" % (ctrl,))
    p.controllers = list(ctrl)
    p.alternate = bool(d.get("alternate", DEFAULTS["alternate"]))
    lim = _mapping(path, "limits", d["limits"], ("max_linear", "max_angular"))
    for k in ("max_linear", "max_angular"):
        if k not in lim:
            raise _err(path, "limits." + k, "missing")
    p.max_linear = _number(path, "limits.max_linear", lim["max_linear"])
    p.max_angular = _number(path, "limits.max_angular", lim["max_angular"])
    cor = _mapping(path, "corridor", d["corridor"], ("ahead", "behind", "left", "right"))
    p.corridor = {}
    for k in ("ahead", "behind", "left", "right"):
        if k not in cor:
            raise _err(path, "corridor." + k, "missing")
        p.corridor[k] = _number(path, "corridor." + k, cor[k])
    for k in ("margin", "settle", "rest", "rate"):
        setattr(p, k, _number(path, k, d.get(k, DEFAULTS[k])))
    saf = _mapping(path, "safety", d.get("safety", {}) or {}, tuple(DEFAULTS["safety"]))
    p.safety = {k: _number(path, "safety." + k, saf.get(k, v)) for k, v in DEFAULTS["safety"].items()}
    hom = _mapping(path, "homing", d.get("homing", {}) or {}, tuple(DEFAULTS["homing"]))
    p.homing = {"enabled": bool(hom.get("enabled", True))}
    p.homing.update({k: _number(path, "homing." + k, hom.get(k, v)) for k, v in DEFAULTS["homing"].items()
                     if k != "enabled"})
    if p.homing["max_linear"] > p.max_linear or p.homing["max_angular"] > p.max_angular:
        raise _err(path, "homing", "max_linear, max_angular must be within the plan's limits")
    if p.homing["min_angular"] > p.homing["max_angular"]:
        raise _err(path, "homing.min_angular", "above homing.max_angular")
    exps = d["experiments"]
    if not isinstance(exps, list) or not exps:
        raise _err(path, "experiments", "must be a non-empty list")
    root = profile_root or profile_dir()
    p.experiments = []
    names = set()
    for k, e in enumerate(exps):
        name, kind, prof = _experiment(path, k, e, root, (p.max_linear, p.max_angular))
        if name in names:
            raise _err(path, "experiments[%d].name" % k, "%r is used twice" % name)
        names.add(name)
        for ch, lim_v, unit in (("vx", p.max_linear, "m/s"), ("wz", p.max_angular, "rad/s")):
            peak = prof.max_abs(ch)
            if peak > lim_v + 1e-9:
                raise _err(path, "experiments[%d] (%s)" % (k, name),
                           "|%s| reaches %g %s, beyond limits.%s %g" % (
                               ch, peak, unit, "max_linear" if ch == "vx" else "max_angular", lim_v))
        p.experiments.append((name, kind, prof))
    p.runs = expand_runs(p)
    check_corridor(p)
    return p


def expand_runs(plan):
    """The runs of a plan: per experiment, per controller (the order flipped on every other
    experiment when ``plan.alternate``), the out run then its mirror. The identification sequence
    runs for the stock controller only (it drives through the stock base)."""
    runs = []
    for k, (name, kind, prof) in enumerate(plan.experiments):
        order = list(plan.controllers)
        if plan.alternate and k % 2 == 1:
            order.reverse()
        if kind == "identification":
            order = [c for c in order if c == "stock"]
        for c in order:
            runs.append(Run(len(runs), name, c, "out", prof, kind))
            runs.append(Run(len(runs), name, c, "back", mirror(prof), kind))
    return runs


def check_corridor(plan):
    """Raise PlanError if an out run's ideal path followed by its mirror's (from where the out run
    ends) leaves the corridor shrunk by the margin; each pair starts at the session's start pose."""
    for out, back in zip(plan.runs[0::2], plan.runs[1::2]):
        p1 = run_path(plan, out)
        p2 = run_path(plan, back, start=tuple(p1[-1, 1:]))
        xy = np.vstack((p1[:, 1:3], p2[:, 1:3]))
        excess = outside(xy, plan.corridor, plan.margin)
        if excess > 0.0:
            e = extents(xy)
            raise _err(plan.path, "experiments (%s)" % out.experiment,
                       "the ideal path reaches ahead %.2f, behind %.2f, left %.2f, right %.2f m: %.2f m beyond the "
                       "corridor (ahead %g, behind %g, left %g, right %g m) less the margin %g m" % (
                           e["ahead"], e["behind"], e["left"], e["right"], excess, plan.corridor["ahead"],
                           plan.corridor["behind"], plan.corridor["left"], plan.corridor["right"], plan.margin))


def dry_run_text(plan, overhead=2.0):
    """What --dry-run prints: the limits, the corridor (geofence), the safety settings, one line per
    run (controller, direction, duration [s], peak |vx| [m/s] and |wz| [rad/s], how far its ideal
    path reaches ahead/behind/left/right and its end pose, chained out and back from the start) and
    the session's duration (set-point time plus ``overhead`` [s] per run for switching and checks)."""
    lines = ["plan %s (%s): %d experiments, %d runs, controllers %s" % (
        plan.name, plan.path, len(plan.experiments), len(plan.runs), ", ".join(plan.controllers))]
    lines.append("speed limits: |vx| <= %g m/s, |wz| <= %g rad/s (set points; measured beyond x%g stops)" % (
        plan.max_linear, plan.max_angular, plan.safety["overspeed_factor"]))
    c = plan.corridor
    lines.append("corridor (geofence, start frame): ahead %g m, behind %g m, left %g m, right %g m; "
                 "paths planned %g m inside it" % (c["ahead"], c["behind"], c["left"], c["right"], plan.margin))
    s = plan.safety
    lines.append("stops: e-stop or drivers off on /status (none for %g s), no /joint_states or odometry for %g s, "
                 "geofence, AIC fault, joystick, Ctrl-C; zero command then for %g s" % (
                     s["status_timeout"], s["data_timeout"], s["stop_hold"]))
    lines.append("each run: %g s at rest, the profile, %g s at rest; a run starts only within %g m and %g rad "
                 "of the session's start pose" % (plan.settle, plan.rest, s["start_tolerance"], s["heading_tolerance"]))
    h = plan.homing
    if h["enabled"]:
        lines.append("before each out run, the robot returns to the start pose (within %g m, %g rad) at <= %g m/s, "
                     "%g rad/s through the stock path" % (h["tolerance"], h["heading_tolerance"], h["max_linear"],
                                                         h["max_angular"]))
    header = ("run", "controller", "dir", "time [s]", "|vx| [m/s]", "|wz| [rad/s]", "ahead", "behind", "left",
              "right", "end x, y [m], heading [rad]")
    rows = []
    start = (0.0, 0.0, 0.0)
    reach = []
    for r in plan.runs:
        path = run_path(plan, r, start if r.direction == "back" else (0.0, 0.0, 0.0))
        e = extents(path[:, 1:3])
        reach.append(e["max_distance"])
        end = path[-1, 1:]
        rows.append((r.name, r.controller, r.direction, "%.1f" % plan.run_duration(r), "%.2f" % r.profile.max_abs("vx"),
                     "%.2f" % r.profile.max_abs("wz"), "%.2f" % e["ahead"], "%.2f" % e["behind"], "%.2f" % e["left"],
                     "%.2f" % e["right"], "%+.2f, %+.2f, %+.2f" % tuple(end)))
        start = tuple(end)
    from ..common.tables import text_table
    lines.append(text_table(header, rows, rule=True))
    total = plan.duration() + overhead * len(plan.runs)
    lines.append("ideal paths reach at most %.2f m from the start pose" % max(reach))
    lines.append("duration: %.0f s of set points, about %.1f min with switching (%d runs)" % (
        plan.duration(), total / 60.0, len(plan.runs)))
    return "\n".join(lines)
