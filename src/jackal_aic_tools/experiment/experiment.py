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
import time

import numpy as np
import yaml

from ..common import cli, metrics, profiles, recording, ros_process, tracking

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
    pass silently."""
    cfg = cli.effective_config([base_path], __file__, "aic_experiment")
    if not isinstance(cfg, dict):
        raise ValueError("%s: not a YAML mapping" % base_path)
    for k, v in overrides.items():
        if k not in cfg:
            raise ValueError("override %s: no such parameter (known: %s)" % (k, ", ".join(sorted(cfg))))
        cfg[k] = v
    with open(out_path, "w") as f:
        f.write("# written by aic_experiment: %s with overrides %s\n" % (base_path, overrides or "none"))
        yaml.safe_dump(cfg, f, default_flow_style=None, sort_keys=False)
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


def run(exp):
    """Run ``exp``; returns the result dict (also saved as <out_dir>/<name>.json)."""
    os.makedirs(exp.out_dir, exist_ok=True)
    base = os.path.join(exp.out_dir, exp.name)
    cfg_path = base + "_config.yaml"
    cfg = write_config(exp.config, exp.overrides, cfg_path)
    wheel_radius = float(cfg.get("wheel_radius", 0.098))
    wheel_sep = float(cfg.get("wheel_separation", 0.5621))
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
        result["files"]["csv"] = write_csv(base + ".csv", arr, t0)
        ideal = analyse_tracking(exp.profile, arr, t0, base, wheel_radius, wheel_sep, result)
        if exp.plot:
            from ..common import report
            result["files"]["png"] = report.plot_run(base + ".png", arr, t0, exp.profile, result,
                                                     wheel_radius, wheel_sep, ideal)
    result["files"]["json"] = base + ".json"
    with open(base + ".json", "w") as f:
        json.dump(result, f, indent=1, default=_json_default)
    return result


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
    (/odom), the belief and the drive commands (as the body twist they ask for)."""
    drive = recording.drive_equivalent(arr["drive"], wheel_radius, wheel_sep) if arr["drive"].size \
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
    sets result["tracking"], result["path"] (result["tracking_error"] if the CLI refuses).
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
    result["path"] = m["path"]
    if m["path"] is None:
        return None
    ideal = tracking.read_columns(ideal_csv)
    return {"x": ideal["x"], "y": ideal["y"]}


def write_csv(path, arr, t0):
    """Merged record: one row per message (sorted by stamp), every column holding the latest
    value of its stream (empty before the first). t [s] is relative to the profile start."""
    cols = {"setpoint": ("setpoint_vx", "setpoint_wz"), "odom": ("odom_vx", "odom_wz"),
            "belief": ("belief_vx", "belief_wz"), "drive": ("drive_left", "drive_right")}
    events = []
    for s in recording.STREAMS:
        for row in arr[s]:
            events.append((row[0], s, row[1], row[2]))
    events.sort(key=lambda e: e[0])
    state = {c: "" for s in recording.STREAMS for c in cols[s]}
    with open(path, "w") as f:
        w = csv.writer(f)
        w.writerow(["t", "stamp", "source"] + [c for s in recording.STREAMS for c in cols[s]])
        for st, s, a, b in events:
            state[cols[s][0]] = "%.6g" % a
            state[cols[s][1]] = "%.6g" % b
            w.writerow(["%.6f" % (st - t0), "%.6f" % st, s] + [state[c] for s2 in recording.STREAMS
                                                              for c in cols[s2]])
    return path
