"""One step-response experiment: start the simulator (own ROS master on a free port),
drive the set point with a profile, record, watch for divergence, analyse, save.

The simulator is ``launch/sim.launch`` of jackal_aic (args: config, controller=aic|stock,
plus whatever extra launch args the caller passes), started with the roslaunch Python API
(jackal_aic_tools.common.ros_process.Simulator).
"""
import csv
import json
import logging
import os
import re
import time

import numpy as np
import yaml

from ..common import cli, closed_loop, figures, inference, metrics, profiles, recording, ros_process, tracking

log = logging.getLogger("aic_experiment")

SIGNALS = ("measured", "belief", "drive")
SIGNAL_STREAM = {"measured": "odom", "belief": "belief", "drive": "drive"}


def parse_override(text):
    """'key=value' -> (key, value) with value parsed as YAML (numbers, lists, names)."""
    if "=" not in text:
        raise ValueError("override %r is not key=value" % text)
    key, val = text.split("=", 1)
    key = key.strip()
    if not key:
        raise ValueError("override %r has an empty key" % text)
    return key, _numbers(yaml.safe_load(val))


def _numbers(v):
    """YAML 1.1 reads 1e5 (no dot) as a string: make such strings floats, in lists too."""
    if isinstance(v, list):
        return [_numbers(x) for x in v]
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return v
    return v


def write_config(base_path, overrides, out_path):
    """Controller YAML = every parameter as the node reads ``base_path`` (over the schema's
    defaults: cli.effective_config) with ``overrides`` set, written to ``out_path`` (a complete
    record of the run's parameters); returns the dict. Unknown keys are refused: a typo must not
    pass silently. The written file is then loaded as the node will load it: a controller unstable
    on the linear model at its rates gets the node's warning with its spectral radius on stderr
    (cli.effective_config)."""
    cfg = cli.effective_config([base_path], __file__, "aic_experiment", warn=False)
    if not isinstance(cfg, dict):
        raise ValueError("%s: not a YAML mapping" % base_path)
    for k, v in overrides.items():
        if k not in cfg:
            raise ValueError("override %s: no such parameter (known: %s)" % (k, ", ".join(sorted(cfg))))
        cfg[k] = v
    with open(out_path, "w") as f:
        f.write("# written by aic_experiment: %s with overrides %s\n" % (base_path, overrides or "none"))
        yaml.safe_dump(cfg, f, default_flow_style=None, sort_keys=False)
    cli.effective_config([out_path], __file__, "aic_experiment")  # the warnings of the run's configuration
    return cfg


class Experiment(object):
    """Settings of one run (see scripts/aic_experiment.py --help for their meaning)."""

    def __init__(self, profile, controller="aic", config=None, overrides=None, launch_file=None,
                 launch_args=None, out_dir="results", name=None, bag=False, settle=1.0,
                 ready_timeout=60.0, rate=50.0, limits=None, verbose=False, plot=True):
        if controller not in ("aic", "stock"):
            raise ValueError("controller must be aic or stock, not %r" % controller)
        self.profile = profile
        self.controller = controller
        self.config = config
        self.overrides = dict(overrides or {})
        self.launch_file = launch_file
        self.launch_args = list(launch_args or [])
        self.out_dir = out_dir
        self.name = name or "%s_%s" % (controller, profile.name)
        self.bag = bag
        self.settle = settle
        self.ready_timeout = ready_timeout
        self.rate = rate
        self.limits = limits or recording.StabilityLimits()
        self.verbose = verbose
        self.plot = plot


def _prepare(exp):
    """The run's output folder (created) and files: returns (base path <out_dir>/<name>, the
    written configuration's path <base>_config.yaml, its dict (write_config), wheel_radius [m],
    wheel_separation [m] of it)."""
    os.makedirs(exp.out_dir, exist_ok=True)
    base = os.path.join(exp.out_dir, exp.name)
    cfg_path = base + "_config.yaml"
    cfg = write_config(exp.config, exp.overrides, cfg_path)
    return base, cfg_path, cfg, float(cfg.get("wheel_radius", 0.098)), float(cfg.get("wheel_separation", 0.5621))


def run(exp):
    """Run ``exp``; returns the result dict (also saved as <out_dir>/<name>.json)."""
    base, cfg_path, cfg, wheel_radius, wheel_sep = _prepare(exp)
    args = ["config:=" + os.path.abspath(cfg_path), "controller:=" + exp.controller] + exp.launch_args
    result = {"name": exp.name, "controller": exp.controller, "profile": exp.profile.name,
              "base_config": exp.config, "config": cfg_path, "overrides": exp.overrides,
              "params": cfg if exp.controller == "aic" else None, "launch_args": args,
              "status": "ok", "reason": "", "segments": [], "files": {}}
    bag = None
    if exp.bag:
        import rosbag
        bag = rosbag.Bag(base + ".bag", "w")
        result["files"]["bag"] = base + ".bag"
    rec = recording.Recorder(bag)
    t_start_wall = time.time()
    try:
        with ros_process.Simulator(exp.launch_file, args, exp.verbose, log=log) as sim:
            t0, status, reason = _drive(exp, sim, rec, wheel_radius, wheel_sep)
    finally:
        if bag is not None:
            bag.close()
    result.update(status=status, reason=reason, t0=t0, wall_time=time.time() - t_start_wall)
    arr = rec.arrays()
    if t0 is not None and arr["setpoint"].size:
        # keep the settling time before the profile and nothing after its last set point
        t_end = arr["setpoint"][-1, 0] + 1.0 / exp.rate
        arr = {s: a[(a[:, 0] >= t0 - exp.settle) & (a[:, 0] <= t_end)] for s, a in arr.items()}
    if rec.bad_stamps:
        result["zero_stamps"] = rec.bad_stamps
    sep = arr["separation"]
    if sep.size:
        # the generative model's b_hat [m] over the run (learned with learn_wheel_separation)
        result["wheel_separation"] = {"first": sep[0, 1], "last": sep[-1, 1],
                                      "min": float(sep[:, 1].min()), "max": float(sep[:, 1].max())}
    beta = arr["gyro_offset"]
    if beta.size:
        # the gyro offset beta_hat [rad/s] the node removed over the run (learned with learn_gyro_bias)
        result["gyro_offset"] = {"first": beta[0, 1], "last": beta[-1, 1]}
    if t0 is not None:
        segs = recording.actual_segments(exp.profile, arr["setpoint"], t0)
        result["segments"] = analyse(arr, segs, t0, wheel_radius, wheel_sep)
        result["files"]["csv"] = write_csv(base + ".csv", arr, t0, rec.inference_columns())
        ideal = analyse_tracking(exp.profile, arr, t0, base, wheel_radius, wheel_sep, result)
        if exp.plot:
            from ..common import report
            result["files"]["png"] = report.plot_run(base + ".png", arr, t0, exp.profile, result,
                                                     wheel_radius, wheel_sep, ideal)
            result["files"]["pdf"] = figures.vector_path(result["files"]["png"])
    result["files"]["json"] = base + ".json"
    with open(base + ".json", "w") as f:
        json.dump(result, f, indent=1, default=_json_default)
    return result


def run_headless(exp):
    """Run ``exp`` on the headless closed loop instead of the nodes: one ``closed_loop_run`` (the
    node's logic, ControlLoop, on the plant core, simulated time, the plant YAML's seeded sensor
    noise; --rest exp.settle, at least 0.3 s) of the profile with the written configuration, its
    trace kept as <out_dir>/<name>_trace.csv (every column of closed_loop_run --csv: speeds,
    pose, b_hat, and with the AIC F, its parts, the beliefs and errors per order, the action and
    the stages' outputs, units in brackets), its metrics converted to the ROS run's result
    layout ("segments": measured = ground truth, belief, drive; "tracking": truth and odometry;
    "path"), and the same figure as run() with the F(t) panel (report.plot_run over
    trace_arrays()). A diverged run is status "unstable" with closed_loop_run's cause. Returns the
    result dict (also <out_dir>/<name>.json)."""
    base, cfg_path, cfg, wheel_radius, wheel_sep = _prepare(exp)
    profile_csv = getattr(exp.profile, "csv_path", None) or exp.profile.write_csv(base + "_profile.csv")
    trace = base + "_trace.csv"
    exe = cli.find_executable("closed_loop_run", __file__, "aic_experiment")
    cmd = closed_loop.command(exe, exp.controller, ["--profile", profile_csv, "--segments", "--rest",
                                                     "%g" % max(exp.settle, 0.3), "--csv", trace],
                              aic_config=os.path.abspath(cfg_path), keep_going=True)
    t_start_wall = time.time()
    run_ = closed_loop.execute(cmd)
    res = run_.result
    result = {"name": exp.name, "controller": exp.controller, "profile": exp.profile.name, "backend": "headless",
              "base_config": exp.config, "config": cfg_path, "overrides": exp.overrides,
              "params": cfg if exp.controller == "aic" else None, "command": cmd,
              "status": "unstable" if run_.diverged else "ok", "reason": run_.diverged or "", "t0": 0.0,
              "wall_time": time.time() - t_start_wall, "segments": headless_segments(res),
              "tracking": {k: res["tracking"][k] for k in ("truth", "odometry")}, "path": res.get("path"),
              "files": {"csv": trace, "profile_csv": profile_csv}}
    arr = trace_arrays(tracking.read_columns(trace), wheel_radius, wheel_sep)
    sep = arr["separation"]
    if sep.size:
        result["wheel_separation"] = {"first": sep[0, 1], "last": sep[-1, 1],
                                      "min": float(sep[:, 1].min()), "max": float(sep[:, 1].max())}
    if exp.plot:
        from ..common import report
        ideal = None
        cols = tracking.read_columns(trace)
        if "x_ideal" in cols:
            ok = np.isfinite(cols["x_ideal"])
            ideal = {"x": cols["x_ideal"][ok], "y": cols["y_ideal"][ok]} if np.any(ok) else None
        result["files"]["png"] = report.plot_run(base + ".png", arr, 0.0, exp.profile, result, wheel_radius,
                                                 wheel_sep, ideal)
        result["files"]["pdf"] = figures.vector_path(result["files"]["png"])
    result["files"]["json"] = base + ".json"
    with open(base + ".json", "w") as f:
        json.dump(result, f, indent=1, default=_json_default)
    return result


def headless_segments(res):
    """closed_loop_run's "segments" (vx) and "angular_segments" (wz) in run()'s layout: per
    transition {"channel", "start", "target", "t_step", "metrics": {"measured" (the ground truth),
    "belief", "drive": {"rise_time", "settling_time", "overshoot", "steady_state_error"}}}."""
    keys = (("rise_time", "rise"), ("settling_time", "settling"), ("overshoot", "overshoot"),
            ("steady_state_error", "sse"))
    out = []
    for channel, name in (("vx", "segments"), ("wz", "angular_segments")):
        for seg in res.get(name) or []:
            m = {}
            for sig, src in (("measured", "truth"), ("belief", "belief"), ("drive", "drive")):
                if seg.get(src):
                    m[sig] = {k: seg[src].get(j) for k, j in keys}
            out.append({"channel": channel, "start": seg["initial"], "target": seg["target"],
                        "t_step": seg["t_step"], "metrics": m})
    return out


def trace_arrays(cols, wheel_radius, wheel_sep):
    """A closed_loop_run --csv trace (``cols``: {column: array}, tracking.read_columns) as the
    arrays recording.Recorder.arrays() holds for a ROS run, t in profile time: setpoint (set_point,
    angular_set_point), odom (the ground truth v_true, yaw_true), belief, drive (the drive command's
    twist back to wheel speeds [rad/s] with ``wheel_radius`` [m], ``wheel_sep`` [m]), pose (x, y,
    heading), separation (b_hat where set), and with the AIC inference (F, F_sensory, F_prior, then
    the other inference columns in inference.columns() order and inference.LEARNED: every row
    where F is set). Raises KeyError naming a missing column."""
    t = cols["t"]

    def stack(*names):
        return np.column_stack([t] + [cols[n] for n in names])

    v, w = cols["command"], cols["command_yaw"]
    drive = np.column_stack([t, (v - 0.5 * w * wheel_sep) / wheel_radius, (v + 0.5 * w * wheel_sep) / wheel_radius])
    sep = stack("separation")
    arr = {"setpoint": stack("set_point", "angular_set_point"), "odom": stack("v_true", "yaw_true"),
           "belief": stack("belief", "belief_yaw"), "drive": drive, "pose": stack("x", "y", "heading"),
           "separation": sep[np.isfinite(sep[:, 1])], "gyro_offset": np.empty((0, 2))}
    arr["belief"] = arr["belief"][np.isfinite(arr["belief"][:, 1])]
    arr["wheels"] = np.empty((0, 3))
    if "F[-]" in cols:
        orders = sum(1 for c in cols if re.match(r"mu\d+_x_dot\[", c))
        names = inference.columns(max(orders, 1))
        have = [n for n in names if n in cols]
        learned = [cols["separation"], cols["gyro_offset"]]
        inf = np.column_stack([t] + [cols[n] for n in have] + learned)
        arr["inference"] = inf[np.isfinite(inf[:, 1])]
    else:
        arr["inference"] = np.empty((0, 1))
    return arr


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    raise TypeError(repr(o))


def _drive(exp, sim, rec, wheel_radius, wheel_sep):
    """Runner side: a node of our own on the simulator's master, then drive_profile()."""
    import rospy
    rospy.init_node("aic_experiment", anonymous=True, disable_signals=True)
    try:
        return drive_profile(exp.profile, rec, exp.controller, settle=exp.settle,
                             ready_timeout=exp.ready_timeout, rate=exp.rate, limits=exp.limits,
                             wheel_radius=wheel_radius, wheel_sep=wheel_sep,
                             died=sim.deaths, name=exp.name)
    finally:
        rospy.signal_shutdown("experiment done")


def drive_profile(profile, rec, controller="aic", settle=1.0, ready_timeout=60.0, rate=50.0, limits=None,
                  wheel_radius=0.098, wheel_sep=0.5621, died=lambda: [], name="run"):
    """Play ``profile`` on /jackal_AIC/set_point (rospy node already initialised) while
    ``rec`` records; wait first for /odom, /cmd_drive (and the belief for the AIC), then
    hold zero for ``settle`` [s]. Stops early when check_stability() finds divergence or
    ``died()`` lists dead nodes. Returns (t0 [s] = profile start, status ok|unstable|failed,
    reason); t0 is None if the run never started."""
    import rospy
    from geometry_msgs.msg import Twist, TwistStamped
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import JointState
    from jackal_msgs.msg import Drive

    limits = limits or recording.StabilityLimits()
    subs = [rospy.Subscriber("/odom", Odometry, rec.on_odom, queue_size=200, tcp_nodelay=True),
            rospy.Subscriber("/jackal_AIC/belief", TwistStamped, rec.on_belief, queue_size=2000, tcp_nodelay=True),
            rospy.Subscriber("/cmd_drive", Drive, rec.on_drive, queue_size=200, tcp_nodelay=True),
            rospy.Subscriber("/joint_states", JointState, rec.on_joint_states, queue_size=200, tcp_nodelay=True)]
    if controller == "aic":
        from std_msgs.msg import Float64
        subs.append(rospy.Subscriber("/jackal_AIC/wheel_separation", Float64, rec.on_separation, queue_size=50))
        subs.append(rospy.Subscriber("/jackal_AIC/gyro_offset", Float64, rec.on_gyro_offset, queue_size=50))
        from jackal_aic.msg import InferenceState
        subs.append(rospy.Subscriber("/jackal_AIC/inference", InferenceState, rec.on_inference, queue_size=500,
                                     tcp_nodelay=True))
    pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
    period = 1.0 / rate

    def publish(vx, wz, record):
        m = Twist()
        m.linear.x, m.angular.z = vx, wz
        pub.publish(m)
        if record:
            rec.on_setpoint(rospy.Time.now(), m)

    try:
        need = ["odom", "drive"] + (["belief"] if controller == "aic" else [])
        deadline = time.time() + ready_timeout
        while True:
            if died():
                return None, "failed", "node(s) died before the run: %s" % died()
            missing = [s for s in need if rec.count(s) == 0]
            if not missing:
                break
            if time.time() > deadline:
                return None, "failed", "no message on %s within %.0f s" % (", ".join(missing), ready_timeout)
            publish(0.0, 0.0, False)
            time.sleep(period)
        # settle at rest, then start the profile clock
        t_settle = rospy.Time.now().to_sec() + settle
        wall_settle = time.time() + 10.0 * settle + 30.0
        while rospy.Time.now().to_sec() < t_settle:
            if died():
                return None, "failed", "node(s) died before the run: %s" % died()
            if time.time() > wall_settle:
                return None, "failed", "time does not advance (is /clock published?)"
            publish(0.0, 0.0, False)
            time.sleep(period)
        t0 = rospy.Time.now().to_sec()
        nominal = [s._replace(t0=t0 + s.t0, t1=t0 + s.t1) for s in profile.segments()]
        wall_limit = time.time() + 4.0 * profile.duration + 30.0
        status, reason = "ok", ""
        k = 0
        while not rospy.is_shutdown():
            now = rospy.Time.now().to_sec()
            t = now - t0
            if t >= profile.duration:
                break
            if time.time() > wall_limit:
                status, reason = "failed", "time stalled (wall limit reached at t=%.2f s)" % t
                break
            vx, wz = profile.value(t)
            publish(vx, wz, True)
            k += 1
            if died():
                status, reason = "failed", "node(s) died during the run: %s" % died()
                break
            if k % 5 == 0:
                why = recording.check_stability(rec.arrays(), nominal, now, limits, wheel_radius, wheel_sep)
                if why:
                    status, reason = "unstable", why
                    log.warning("run %s stopped at t=%.2f s: %s", name, t, why)
                    break
            time.sleep(period)
        if status == "ok":  # a final look at everything recorded
            why = recording.check_stability(rec.arrays(), nominal, rospy.Time.now().to_sec(), limits,
                                            wheel_radius, wheel_sep)
            if why:
                status, reason = "unstable", why
        for _ in range(3):
            publish(0.0, 0.0, False)
            time.sleep(period)
        return t0, status, reason
    finally:
        for s in subs:
            s.unregister()
        pub.unregister()


def analyse(arr, segs, t0, wheel_radius, wheel_sep):
    """Metrics (through aic_step_metrics) of every segment for the measured velocity
    (/odom), the belief and the drive commands (as the body twist they ask for in the
    controller's model: recording.drive_twist() with the learned b_hat of arr["separation"] in
    force at each command, the configured wheel_sep [m] before it or without it)."""
    sep = arr.get("separation", np.zeros((0, 2)))
    drive = recording.drive_twist(arr["drive"], wheel_radius, wheel_sep, sep) if arr["drive"].size \
        else arr["drive"]
    streams = {"measured": arr["odom"], "belief": arr["belief"], "drive": drive}
    out = []
    for seg in segs:
        ci = 1 + profiles.CHANNELS.index(seg.channel)
        entry = {"channel": seg.channel, "start": seg.start, "target": seg.target,
                 "t_step": seg.t0 - t0, "t_end": seg.t1 - t0, "metrics": {}}
        for sig in SIGNALS:
            a = streams[sig]
            if not a.size:
                continue
            m = (a[:, 0] >= seg.t0) & (a[:, 0] <= seg.t1)
            if np.count_nonzero(m) < 2:
                continue
            try:
                entry["metrics"][sig] = metrics.step_metrics(a[m, 0] - t0, a[m, ci], seg.t0 - t0,
                                                             seg.start, seg.target)
            except metrics.MetricsError as e:
                entry["metrics"][sig] = {"error": str(e)}
        out.append(entry)
    return out


def analyse_tracking(profile, arr, t0, base, wheel_radius, wheel_sep, result):
    """Tracking metrics of the whole profile through aic_track_metrics (jackal_aic_tools.common.tracking):
    the ground-truth twist (/odom) and the wheel odometry (/joint_states through the kinematics
    G with the configuration's wheel_radius and wheel_separation) against the set point, and the
    /odom pose against the ideal path. Writes <base>_track.csv (the trace the CLI reads),
    <base>_ideal.csv (the ideal path) and, for a profile not read from a file, <base>_profile.csv;
    sets result["tracking"], result["stops"] (per signal: how far it moved back after each stop of
    the profile) and result["path"] (result["tracking_error"] if the CLI refuses).
    Returns the ideal path as {"x", "y"} arrays for the plot, or None."""
    profile_csv = getattr(profile, "csv_path", None) or profile.write_csv(base + "_profile.csv")
    wheels = recording.drive_equivalent(arr["wheels"], wheel_radius, wheel_sep) if arr["wheels"].size \
        else arr["wheels"]
    rows = [(st - t0, "%.6g" % vx, "%.6g" % wz, "", "", "%.9g" % x, "%.9g" % y, "%.9g" % yaw)
            for (st, vx, wz), (_, x, y, yaw) in zip(arr["odom"], arr["pose"])]
    rows += [(st - t0, "", "", "%.6g" % vx, "%.6g" % wz, "", "", "") for st, vx, wz in wheels]
    rows.sort(key=lambda r: r[0])
    trace = base + "_track.csv"
    with open(trace, "w") as f:
        w = csv.writer(f)
        w.writerow(["t", "truth_vx", "truth_wz", "odometry_vx", "odometry_wz", "x", "y", "heading"])
        for r in rows:
            w.writerow(["%.6f" % r[0]] + list(r[1:]))
    ideal_csv = base + "_ideal.csv"
    result["files"].update(track_csv=trace, ideal_csv=ideal_csv, profile_csv=profile_csv)
    try:
        m = tracking.track_metrics(profile_csv, trace, ideal_csv)
    except (tracking.TrackingError, metrics.MetricsError) as e:
        result["tracking_error"] = str(e)
        return None
    result["tracking"] = m["tracking"]
    result["stops"] = m.get("stops")
    result["path"] = m["path"]
    if m["path"] is None:
        return None
    ideal = tracking.read_columns(ideal_csv)
    return {"x": ideal["x"], "y": ideal["y"]}


def write_csv(path, arr, t0, inference_columns=()):
    """Merged record: one row per message (sorted by stamp), every column holding the latest
    value of its stream (empty before the first). t [s] is relative to the profile start, stamp
    [s] the message's. Columns: t, stamp, source, then setpoint_vx, setpoint_wz, odom_vx, odom_wz,
    belief_vx, belief_wz [m/s, rad/s], drive_left, drive_right [rad/s]; with the AIC's
    ``inference_columns`` (recording.Recorder.inference_columns(): units in brackets, as
    closed_loop_run --csv names them) the rows of arr["inference"] too (source "inference", stamped
    with the sensor sample the beliefs were updated on; empty where the belief model has no such
    quantity)."""
    cols = {"setpoint": ("setpoint_vx", "setpoint_wz"), "odom": ("odom_vx", "odom_wz"),
            "belief": ("belief_vx", "belief_wz"), "drive": ("drive_left", "drive_right")}
    names = [c for s in recording.STREAMS for c in cols[s]]
    inference_columns = list(inference_columns)
    events = []
    for s in recording.STREAMS:
        for row in arr[s]:
            events.append((row[0], s, ("%.6g" % row[1], "%.6g" % row[2])))
    inf = arr.get("inference")
    if inference_columns and inf is not None and inf.size:
        if inf.shape[1] != 1 + len(inference_columns):
            raise ValueError("inference rows have %d values, not %d columns" % (inf.shape[1] - 1, len(inference_columns)))
        for row in inf:
            # NaN: a quantity the belief model does not have, an empty cell as in closed_loop_run's trace.
            events.append((row[0], "inference", tuple("%.9g" % v if np.isfinite(v) else "" for v in row[1:])))
    events.sort(key=lambda e: e[0])
    state = {c: "" for c in names + inference_columns}
    with open(path, "w") as f:
        w = csv.writer(f)
        w.writerow(["t", "stamp", "source"] + names + inference_columns)
        for st, s, vals in events:
            for c, v in zip(cols[s] if s in cols else inference_columns, vals):
                state[c] = v
            w.writerow(["%.6f" % (st - t0), "%.6f" % st, s] + [state[c] for c in names + inference_columns])
    return path
