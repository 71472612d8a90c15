"""The report of a field-trial session (scripts/aic_field_report.py; doc/field_trials.md,
'The report'): from the session's bags, the step tables, the tracking tables and the plots of
aic_experiment.py and aic_track.py, AIC against stock, and the session's runs replayed on the
simulated Jackal (closed_loop_run --profile) beside the robot's numbers with the relative error.

Nothing is computed here that the simulation's tools do not compute the same way: a bag becomes
the arrays jackal_aic_tools.common.recording.Recorder keeps during an aic_experiment.py run (the same
streams, stamps and units), and experiment.analyse() / experiment.analyse_tracking() turn them into
the metrics through the core's aic_step_metrics and aic_track_metrics. So a bag of aic_experiment.py
--bag gives the report its own numbers (read_bag(... set_point_topic='/jackal_AIC/set_point')).
"""
import json
import math
import os
import subprocess

import numpy as np

from ..common import closed_loop, profiles, recording, tracking
from ..common.tables import fmt, md_table, text_table
from ..experiment import experiment
from . import field_plan, field_trial

#: Kinematics used for the drive commands and wheel odometry as a twist when the session does not
#: say otherwise: the schema's wheel_radius [m] and wheel_separation [m] (config/default.yaml).
WHEEL_RADIUS = 0.098
WHEEL_SEPARATION = 0.5621
#: Step metrics compared robot against simulator, with their units.
STEP_METRICS = (("rise_time", "s"), ("settling_time", "s"), ("overshoot", "%"))
TRACK_METRICS = (("vx_rms", "m/s"), ("wz_rms", "rad/s"), ("drift_max", "m"))
#: closed_loop_run's names of the STEP_METRICS in its "segments".
SIM_KEYS = {"rise_time": "rise", "settling_time": "settling", "overshoot": "overshoot"}
#: Run kinds whose transitions are steps held long enough to settle: their STEP_METRICS are compared
#: (a tracking profile's transitions are its CSV rows, 0.05-0.1 s apart: only its TRACK_METRICS).
STEP_KINDS = ("step", "square", "identification")
#: Below these simulator values (in the figure's unit) a relative error says nothing (a straight
#: run's wz RMS of 0.0004 rad/s, an overshoot of 0.04 %): compare() leaves it out.
REL_FLOORS = {"overshoot": 1.0, "vx_rms": 0.01, "wz_rms": 0.01, "drift_max": 0.01}


class ReportError(RuntimeError):
    """A session folder or bag that cannot be reported; the message says which and why."""


def read_bag(path, odom_topic, set_point_topic=field_trial.BAG_SET_POINT, belief_topic="/jackal_AIC/belief"):
    """The streams of a run's bag as recording.Recorder.arrays() holds them during a run: setpoint
    (bag time, vx, wz), odom (header stamp, vx, wz of ``odom_topic``), pose (header stamp, x, y,
    heading), belief (header stamp), drive (/cmd_drive, bag time = receipt, left, right [rad/s]),
    wheels (/joint_states header stamp, mean left, mean right [rad/s]); plus "events" (list of
    (bag time, text) of /field_trial/event) and "publishers" (list of (bag time, topic, callerid)).
    A zero header stamp counts as the bag time, as the Recorder does. Raises ReportError."""
    import rosbag
    data = {s: [] for s in recording.WIDTH}
    events, pubs = [], []
    try:
        bag = rosbag.Bag(path)
    except Exception as e:  # rosbag raises ROSBagException, ROSBagUnindexedException, OSError
        raise ReportError("%s: cannot read the bag: %s (an interrupted write: try rosbag reindex)" % (path, e))
    with bag:
        for topic, msg, t in bag.read_messages():
            bt = t.to_sec()
            hs = msg.header.stamp.to_sec() if hasattr(msg, "header") and not msg.header.stamp.is_zero() else bt
            if topic == set_point_topic:
                data["setpoint"].append((bt, msg.linear.x, msg.angular.z))
            elif topic == odom_topic:
                tw = msg.twist.twist
                data["odom"].append((hs, tw.linear.x, tw.angular.z))
                p = msg.pose.pose
                data["pose"].append((hs, p.position.x, p.position.y, field_trial.yaw_of(p.orientation)))
            elif topic == belief_topic:
                data["belief"].append((hs, msg.twist.linear.x, msg.twist.angular.z))
            elif topic == "/cmd_drive":
                data["drive"].append((bt, msg.drivers[0], msg.drivers[1]))
            elif topic == "/joint_states":
                left = [v for n, v in zip(msg.name, msg.velocity) if "left" in n]
                right = [v for n, v in zip(msg.name, msg.velocity) if "right" in n]
                if left and right:
                    data["wheels"].append((hs, sum(left) / len(left), sum(right) / len(right)))
            elif topic == field_trial.BAG_EVENT:
                events.append((bt, msg.data))
            elif topic == field_trial.BAG_PUBLISHERS:
                topic_name, _, caller = msg.data.partition(" ")
                pubs.append((bt, topic_name, caller))
    arr = {s: np.array(v, dtype=float).reshape(-1, w) for s, w in recording.WIDTH.items() for v in [data[s]]}
    arr["events"] = events
    arr["publishers"] = pubs
    return arr


def trim(arr, t0, settle, t_end):
    """The arrays between ``t0 - settle`` and ``t_end`` [s], as aic_experiment keeps a run's
    (the settling before the profile, nothing after its end)."""
    return {s: (a[(a[:, 0] >= t0 - settle) & (a[:, 0] <= t_end)] if isinstance(a, np.ndarray) else a)
            for s, a in arr.items()}


def analyse_arrays(name, controller, profile, arr, t0, base, wheel_radius=WHEEL_RADIUS,
                   wheel_sep=WHEEL_SEPARATION, plot=True):
    """The result dict of aic_experiment.run() for recorded arrays: "segments" (experiment.analyse
    of every transition of ``profile`` from the published set points), "tracking" and "path"
    (experiment.analyse_tracking, writing <base>_track.csv, _ideal.csv, _profile.csv), "files"
    and, with ``plot``, <base>.png and .pdf (report.plot_run). ``t0`` is the profile's start [s]."""
    result = {"name": name, "controller": controller, "profile": profile.name, "status": "ok", "reason": "",
              "t0": t0, "segments": [], "files": {}}
    segs = recording.actual_segments(profile, arr["setpoint"], t0)
    result["segments"] = experiment.analyse(arr, segs, t0, wheel_radius, wheel_sep)
    ideal = experiment.analyse_tracking(profile, arr, t0, base, wheel_radius, wheel_sep, result)
    if plot:
        from ..common import report
        result["files"]["png"] = report.plot_run(base + ".png", arr, t0, profile, result, wheel_radius, wheel_sep,
                                                 ideal)
    return result


def switch_overlaps(publishers, period=0.02):
    """Command periods where two publishers fed the same topic: a list of (topic, period start [s],
    callerids) for every ``period``-long bin (50 Hz: 20 ms) of the bag time that holds messages of
    more than one callerid on one topic (empty: the controllers never overlapped)."""
    bins = {}
    for t, topic, caller in publishers:
        bins.setdefault((topic, int(math.floor(t / period))), set()).add(caller)
    return [(topic, k * period, sorted(c)) for (topic, k), c in sorted(bins.items()) if len(c) > 1]


def load_session(session_dir):
    """session.json of a field-trial folder (dict); ReportError if there is none or it is broken."""
    path = os.path.join(session_dir, "session.json")
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise ReportError("%s: %s" % (path, e))


def analyse_session(session_dir, out_dir, wheel_radius=WHEEL_RADIUS, wheel_sep=WHEEL_SEPARATION, plot=True):
    """Analyse every completed run of a session (its bag through analyse_arrays). Returns a list of
    result dicts (aic_experiment's, plus "experiment", "direction", "kind", "bag", "overlaps": the
    switch_overlaps of its bag), in the session's order; writes <out_dir>/<run>.json (and the CSV
    and PNG files beside it). Runs that did not complete are skipped."""
    s = load_session(session_dir)
    odom = s["topics"]["odom"]
    settle = float(s["plan"]["settle"])
    os.makedirs(out_dir, exist_ok=True)
    results = []
    for r in s["runs"]:
        if r["status"] != "completed":
            continue
        prof = field_plan.profile_from_dict(r["profile"])
        arr = read_bag(os.path.join(session_dir, r["bag"]), odom,
                       belief_topic=s["topics"].get("aic_node", "/jackal_AIC") + "/belief")
        t0 = float(r["t_profile"])
        overlaps = switch_overlaps(arr["publishers"])
        arr = trim(arr, t0, settle, t0 + prof.duration)
        base = os.path.join(out_dir, r["name"])
        res = analyse_arrays(r["name"], r["controller"], prof, arr, t0, base, wheel_radius, wheel_sep, plot)
        res.update(experiment=r["experiment"], direction=r["direction"], kind=r["kind"], bag=r["bag"],
                   overlaps=overlaps)
        res["files"]["json"] = base + ".json"
        with open(base + ".json", "w") as f:
            json.dump(res, f, indent=1, default=_json_default)
        results.append(res)
    return results


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    raise TypeError(repr(o))


def _measured(seg):
    return seg["metrics"].get("measured") or {}


def step_table(results, markdown=False):
    """AIC against stock, the layout of the scorecard's step criteria: one row per experiment,
    direction and transition of the step and square-wave runs, the measured rise [s], settling
    [s], overshoot [%] and steady-state error of each controller. A text table, or with
    ``markdown`` a Markdown one."""
    by = {}
    order = []
    for r in results:
        if r.get("kind") not in ("step", "square"):
            continue
        for k, seg in enumerate(r["segments"]):
            key = (r["experiment"], r["direction"], k)
            if key not in by:
                by[key] = {"transition": "%s %g->%g %s" % (seg["channel"], seg["start"], seg["target"],
                                                           profiles.UNITS[seg["channel"]])}
                order.append(key)
            by[key][r["controller"]] = _measured(seg)
    header = ["experiment", "dir", "transition"] + ["%s %s" % (c, m) for m in
                                                    ("rise [s]", "settle [s]", "OS [%]", "ss err") for c in
                                                    ("aic", "stock")]
    rows = []
    for key in order:
        d = by[key]
        a, s = d.get("aic", {}), d.get("stock", {})
        rows.append([key[0], key[1], d["transition"],
                     fmt(a.get("rise_time")), fmt(s.get("rise_time")), fmt(a.get("settling_time")),
                     fmt(s.get("settling_time")), fmt(a.get("overshoot"), "%.1f"), fmt(s.get("overshoot"), "%.1f"),
                     fmt(a.get("steady_state_error"), "%.4f"), fmt(s.get("steady_state_error"), "%.4f")])
    return _table(header, rows, markdown)


def _table(header, rows, markdown):
    return md_table(header, rows) if markdown else text_table(header, rows, rule=True)


def tracking_rows(results):
    """(experiment, direction, controller, flat metrics) of every run with tracking metrics."""
    return [(r["experiment"], r["direction"], r["controller"], tracking.flat(r)) for r in results if r.get("tracking")]


def tracking_table(results, markdown=False):
    """The tracking table in aic_track.py's layout: per run the RMS and maximum error of vx and wz of
    the measured twist against the set point and the path drift; then AIC / stock per experiment
    and direction. A text table, or with ``markdown`` a Markdown one."""
    from ..track.track_report import TABLE_METRICS, metric_header
    rows, ratio = [], []
    flat = tracking_rows(results)
    for exp, d, c, m in flat:
        rows.append([exp, d, c] + [fmt(m[k]) for k in TABLE_METRICS])
    pairs = {}
    for exp, d, c, m in flat:
        pairs.setdefault((exp, d), {})[c] = m
    for (exp, d), p in pairs.items():
        if "aic" in p and "stock" in p:
            ratio.append([exp, d, "aic/stock"] + [fmt(p["aic"][k] / p["stock"][k], "%.2f")
                                                 if p["aic"][k] is not None and p["stock"][k] else "-"
                                                 for k in TABLE_METRICS])
    return _table(["experiment", "dir", "controller"] + metric_header(TABLE_METRICS), rows + ratio, markdown)


# ------------------------------------------------------------------ robot against simulator
def simulate(run_result, profile_csv, controller, closed_loop_run, aic_config=None, overlays=(), settle=1.0):
    """The run's profile on the simulated Jackal (closed_loop_run --profile --segments, seeded
    sensor noise, from ``settle`` [s] at rest; plant ``overlays``, e.g. a wheel loop identified from
    the session's bags). Returns closed_loop_run's JSON (dict). Raises ReportError."""
    cmd = [closed_loop_run, "--controller", controller, "--profile", profile_csv, "--segments", "--noise",
           "--rest", repr(max(0.25, float(settle))), closed_loop.KEEP_GOING]  # reported beside the robot's run
    if controller == "aic" and aic_config:
        cmd += ["--aic-config", aic_config]
    for o in overlays:
        cmd += ["--overlay", o]
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=600)
    if out.returncode != 0:
        raise ReportError("%s: %s" % (" ".join(cmd), out.stderr.strip()[:300]))
    return json.loads(out.stdout)


def sim_figures(sim):
    """Flat figures of a closed_loop_run JSON comparable with a run's: per transition k the truth
    (ground-truth /odom, as the session's odometry in simulation) STEP_METRICS, named
    "<channel>[k] <metric>", and TRACK_METRICS of the whole profile."""
    out = {}
    for ch, key in (("vx", "segments"), ("wz", "angular_segments")):
        for k, seg in enumerate(sim.get(key) or []):
            m = seg.get("truth") or {}
            for name, _ in STEP_METRICS:
                out["%s[%d] %s" % (ch, k, name)] = _finite(m.get(SIM_KEYS[name]))
    out.update({k: v for k, v in tracking.flat(sim).items() if k in dict(TRACK_METRICS)})
    return out


def robot_figures(result):
    """The same flat figures (sim_figures()) of a run's result dict."""
    out = {}
    count = {"vx": 0, "wz": 0}
    for seg in result["segments"]:
        ch = seg["channel"]
        m = _measured(seg)
        for name, _ in STEP_METRICS:
            out["%s[%d] %s" % (ch, count[ch], name)] = _finite(m.get(name))
        count[ch] += 1
    out.update({k: v for k, v in tracking.flat(result).items() if k in dict(TRACK_METRICS)})
    return out


def _finite(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def relative_error(robot, sim, floor=0.0):
    """(robot - sim) / |sim|, None if either is missing, sim is 0 or |sim| < ``floor``."""
    if robot is None or sim is None or sim == 0.0 or abs(sim) < floor:
        return None
    return (robot - sim) / abs(sim)


def figure_metric(figure):
    """The metric of a compare() figure name: "vx[2] rise_time" -> "rise_time", "vx_rms" -> "vx_rms"."""
    return figure.rsplit(" ", 1)[-1]


def compare(results, out_dir, closed_loop_run, aic_config=None, overlays=(), settle=1.0, directions=("out",)):
    """Robot against simulator: every run of ``results`` in ``directions`` replayed by simulate() (its
    _profile.csv), figures side by side: STEP_METRICS of every transition of the STEP_KINDS runs,
    TRACK_METRICS of all. Returns a list of rows (run, controller, figure, robot, simulator,
    relative error: None below REL_FLOORS) and writes <out_dir>/robot_vs_sim.json."""
    rows = []
    dump = []
    for r in results:
        if r.get("direction") not in directions:
            continue
        sim = simulate(r, r["files"]["profile_csv"], r["controller"], closed_loop_run, aic_config, overlays, settle)
        rf, sf = robot_figures(r), sim_figures(sim)
        if r.get("kind") not in STEP_KINDS:
            rf = {k: v for k, v in rf.items() if k in dict(TRACK_METRICS)}
        for k in rf:
            if k in sf:
                rows.append((r["name"], r["controller"], k, rf[k], sf[k],
                             relative_error(rf[k], sf[k], REL_FLOORS.get(figure_metric(k), 0.0))))
        dump.append({"run": r["name"], "robot": rf, "simulator": sf})
    with open(os.path.join(out_dir, "robot_vs_sim.json"), "w") as f:
        json.dump({"overlays": list(overlays), "aic_config": aic_config, "runs": dump}, f, indent=1)
    return rows


def compare_table(rows, markdown=False):
    """Table of compare()'s rows: robot, simulator, relative error [%] (text, or ``markdown``)."""
    return _table(["run", "controller", "figure", "robot", "simulator", "rel. error [%]"],
                  [[a, b, c, fmt(d), fmt(e), fmt(None if f is None else 100.0 * f, "%+.1f")]
                   for a, b, c, d, e, f in rows], markdown)


def compare_summary(rows, markdown=False):
    """compare()'s relative errors per controller and metric (figure_metric(): the transitions'
    rise_time, settling_time, overshoot; the runs' vx_rms, wz_rms, drift_max): how many figures
    have one, the median and the largest |relative error| [%] and the median signed one [%]
    (positive: the robot slower, larger, farther than the simulator). A text or Markdown table."""
    groups, order = {}, []
    for _run, ctrl, fig, _r, _s, err in rows:
        key = (ctrl, figure_metric(fig))
        if key not in groups:
            groups[key] = []
            order.append(key)
        if err is not None:
            groups[key].append(100.0 * err)
    out = []
    for key in sorted(order, key=lambda k: (k[0], _METRIC_ORDER.index(k[1]) if k[1] in _METRIC_ORDER else 99)):
        e = np.array(groups[key])
        out.append([key[0], key[1], len(e)] + ([fmt(float(np.median(np.abs(e))), "%.1f"),
                                                 fmt(float(np.abs(e).max()), "%.1f"),
                                                 fmt(float(np.median(e)), "%+.1f")] if e.size else ["-"] * 3))
    return _table(["controller", "metric", "figures", "median abs. error [%]", "max abs. error [%]",
                   "median error [%]"], out, markdown)


_METRIC_ORDER = [m for m, _ in STEP_METRICS] + [m for m, _ in TRACK_METRICS]


def session_summary(session_dir):
    """The session's own figures from session.json: dict with plan (name), status, reason, runs
    (completed), planned (runs in the plan), wall_time [s] (confirmation to end; None if the
    session.json predates it), max_distance [m] (from the start pose, on the session's odometry),
    extent (dict ahead, behind, left, right [m] reached in the start frame, or None), corridor
    (the plan's, [m]), odom (topic), resumes and homing (number of returns to the start pose)."""
    s = load_session(session_dir)
    done = {r["name"] for r in s["runs"] if r["status"] == "completed"}
    return {"plan": s["plan"].get("name"), "status": s.get("status"), "reason": s.get("reason", ""),
            "runs": len(done), "planned": len(s.get("plan_runs", [])), "wall_time": s.get("wall_time"),
            "max_distance": s.get("max_distance_from_start"), "extent": s.get("corridor_extent"),
            "corridor": s["plan"]["corridor"], "odom": s["topics"]["odom"], "resumes": s.get("resumes", 0),
            "homing": len(s.get("homing", []))}


def summary_text(summary, markdown=False):
    """session_summary() as lines: status, runs, wall time, and per side of the corridor how far
    the robot reached against the corridor (text or a Markdown table)."""
    sides = ("ahead", "behind", "left", "right")
    ext = summary["extent"] or {}
    wall = summary["wall_time"]
    head = ["session: plan %s, %s%s" % (summary["plan"], summary["status"],
                                        (" (" + summary["reason"] + ")") if summary["reason"] else ""),
            "runs completed: %d of %d (resumed %d times; %d returns to the start pose)" % (
                summary["runs"], summary["planned"], summary["resumes"], summary["homing"]),
            "wall time: %s" % ("-" if wall is None else "%.0f s (%.1f min)" % (wall, wall / 60.0)),
            "max distance from the start pose on %s: %s m" % (summary["odom"], fmt(summary["max_distance"], "%.2f"))]
    rows = [[k, fmt(ext.get(k), "%.2f"), fmt(float(summary["corridor"][k]), "%.2f"),
             fmt(None if k not in ext else float(summary["corridor"][k]) - ext[k], "%.2f")] for k in sides]
    header = ["side", "reached [m]", "corridor [m]", "left over [m]"]
    if markdown:
        return "\n".join("- " + h for h in head) + "\n\n" + md_table(header, rows)
    return "\n".join(head) + "\n" + text_table(header, rows, rule=True)


def markdown_report(summary, results, overlaps, compare_rows=None, overlays=(), command=""):
    """The session's figures as a Markdown document: the command that made it, summary_text(), the
    step table, the tracking table, the controller-switch check (``overlaps``: (run, topic, period
    start, callerids) tuples), and with ``compare_rows`` (compare()'s) compare_summary() and
    compare_table() against the simulator with plant ``overlays`` (their names and values)."""
    out = ["# Field-trial session: %s" % summary["plan"], ""]
    if command:
        out += ["Generated by `%s`; do not edit." % command, ""]
    out += [summary_text(summary, markdown=True), "", "## Step responses, AIC against stock", "",
            step_table(results, markdown=True), "", "## Tracking", "", tracking_table(results, markdown=True), "",
            "## Controller switch", "", switch_text(overlaps), ""]
    if compare_rows is not None:
        sim = "the simulated Jackal (closed_loop_run)" + "".join(" + " + os.path.basename(o) for o in overlays)
        out += ["## Robot against simulator", "", "Out runs replayed on %s; relative error (robot - simulator) / "
                "|simulator|, left out below %s." % (sim, ", ".join("%s %g" % kv for kv in sorted(REL_FLOORS.items()))),
                ""]
        for o in overlays:
            out += ["`%s`:" % os.path.basename(o), "", "```yaml"] + _yaml_lines(o) + ["```", ""]
        out += [compare_summary(compare_rows, markdown=True), "", compare_table(compare_rows, markdown=True), ""]
    return "\n".join(out)


def _yaml_lines(path):
    """The lines of a YAML file without its comment lines (a plant overlay's values), or a note
    that it cannot be read."""
    try:
        with open(path) as f:
            return [line.rstrip("\n") for line in f if line.strip() and not line.lstrip().startswith("#")]
    except OSError as e:
        return ["# %s" % e]


def switch_text(overlaps):
    """One line on the controller switch: whether any 50 Hz period had two publishers on a command
    topic (``overlaps``: (run, topic, period start, callerids) tuples)."""
    if not overlaps:
        return "no 50 Hz period with two publishers on a command topic"
    return "%d periods with two publishers, e.g. %s" % (len(overlaps), overlaps[0])


def robot_vs_sim(results, session_dir, out_dir, tool, aic_configs=None, overlays=(), identify=False):
    """compare() for a session as aic_field_report.py --sim runs it: the AIC's YAML files
    ``aic_configs`` (default config/default.yaml then config/robot.yaml, as robot.launch loads them)
    merged into <out_dir>/aic_config.yaml; plant ``overlays``; with ``identify``, first the wheel loop
    identified from the session's identification bag (plant_identify.py --bag, written to
    <out_dir>/identified_wheel_loop.yaml) as the last overlay. ``tool``: cli.Tool of the calling
    script. Returns (rows of compare(), the overlays used). Raises ReportError."""
    import sys
    import yaml
    from ..common import cli
    configs = aic_configs or [tool.path("config", "default.yaml"), tool.path("config", "robot.yaml")]
    merged = os.path.join(out_dir, "aic_config.yaml")
    with open(merged, "w") as f:
        yaml.safe_dump(cli.effective_config(configs, tool.script, tool.name), f, default_flow_style=None)
    overlays = list(overlays)
    if identify:
        bags = [r["bag"] for r in results if r.get("kind") == "identification" and r["direction"] == "out"]
        if not bags:
            raise ReportError("--identify: the session has no completed identification run")
        ident = os.path.join(out_dir, "identified_wheel_loop.yaml")
        script = os.path.join(os.path.dirname(os.path.realpath(tool.script)), "plant_identify.py")
        rc = subprocess.call([sys.executable, script, "--bag", os.path.join(session_dir, bags[0]),
                              "--overlay-out", ident])
        if rc != 0:
            raise ReportError("plant_identify.py --bag %s failed (exit %d)" % (bags[0], rc))
        overlays.append(ident)
    settle = float(load_session(session_dir)["plan"]["settle"])
    return compare(results, out_dir, tool.exe("closed_loop_run"), merged, overlays, settle), overlays
