"""aic_track.py: the tracking benchmark of real driving, headless: the AIC against the stock
controller on command streams a Jackal actually receives, over plant variants, in one command.

Plays every twist profile (default: sim/profiles/*.csv, written by --write-profiles from
jackal_aic_tools/track/track_profiles.py: joystick teleop, a 10 Hz planner, S-curves, stop-and-go,
creeping, fast driving) with `closed_loop_run --profile` on the simulated Jackal's plant core
(headless, faster than real time, the plant YAML's seeded sensor noise: the same figures on every
machine), once with the AIC (--aic-config), once with the stock controller and once with the
classical peer (`closed_loop_run --controller pi`, --pi-config: PI loops on the wheel speeds and the
yaw rate around the robot model's feed-forward; doc/active_inference.md, 'A classical peer'), on
the default plant and on every plant variant (an overlay YAML of sim/config/variants/). Per run, against the
set point: the RMS and maximum error of vx [m/s] and wz [rad/s] (ground truth; wheel odometry in
the JSON and CSV) and the path drift (ground-truth pose against the ideal path, the commanded
twist integrated from the same start: final and maximum position error [m], final heading error
[rad]); all computed by the core (jackal_aic/analysis/tracking_metrics.hpp). Then the AIC / stock ratio of
every metric and its geometric mean over profiles x variants (< 1: the AIC tracks better), and
the AIC against the peer and the latency floor (RMS of vx and wz: AIC / peer, AIC / floor, peer /
floor).

Per pair also the ideal controller (`closed_loop_run --controller ideal`, the command learned over
repeated runs) against the latency floor (driving.floor_rms): a channel (vx, wz) whose ideal error
exceeds plant_limits.PLANT_LIMIT_RATIO x the floor is plant-limited (jackal_aic_tools.track.plant_limits,
with the reason measured in the ideal run); the geometric means are over the plant-following
channels (a drift or heading metric: pairs that follow on both), the plant-limited ones apart.
Beside the floor, reported and not judged, the acceleration-bounded floor: the same servo on two
wheels of the robot's radius, the geometric track apart, each accelerating at most the variant's
wheel-loop A_w (plant_limits.floor_accelerations), its aim taken at the AIC's action rate and held
between (tracking.json's floor_period, 1 / action_rate of the AIC's configuration), and the AIC,
the peer and the stock controller against it.

Writes to --out: tracking.json (everything), tracking.csv (one row per run), ratios.csv,
traces/<profile>__<variant>__<controller>.csv (closed_loop_run's traces) and
plots/<profile>__<variant>.png (set point and both controllers' velocities; both x-y paths
against the ideal one); --results-md FILE a results page; --doc writes doc/results/tracking.md
and the default plant's plots to doc/img/tracking/.

Usage:
  aic_track.py [--profiles CSV ...] [--variants default|OVERLAY.yaml ...] [--aic-config FILE]
               [--pi-config FILE] [--plant-config FILE] [--jobs N] [--out DIR] [--no-plots] [--results-md FILE] [--doc]
  aic_track.py --write-profiles DIR      # regenerate the benchmark's profiles
  aic_track.py --write-random-profiles DIR [--count N] [--seed S]
                                         # seeded streams outside the benchmark (planner, joystick)

  e.g.  scripts/aic_track.py --doc
        scripts/aic_track.py --profiles my_log.csv --variants default sim/config/variants/payload_10kg.yaml

Exit: 0 done, 1 a bad profile or overlay file or a failed run (the message names it), 2 bad
arguments.
"""
import csv
import glob
import json
import os
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor

from ..common import cli, closed_loop, tracking
from . import driving, plant_limits, track_profiles, track_report
from .track_report import CONTROLLERS, TABLE_METRICS, UNITS


class SuiteError(Exception):
    """A bad profile or overlay file, or failed runs (the message names them)."""


def default_profiles(root):
    """<root>/sim/profiles/*.csv: the benchmark's profiles in the order of track_profiles.NAMES,
    then any other CSV there, alphabetically."""
    found = sorted(glob.glob(os.path.join(root, "sim", "profiles", "*.csv")))
    order = {n: k for k, n in enumerate(track_profiles.NAMES)}
    return sorted(found, key=lambda p: (order.get(_stem(p), len(order)), _stem(p)))


def default_variants(root):
    """'default' (the plant YAML alone) and every overlay <root>/sim/config/variants/*.yaml."""
    return ["default"] + sorted(glob.glob(os.path.join(root, "sim", "config", "variants", "*.yaml")))


def _stem(path):
    """File name without folder and extension."""
    return os.path.splitext(os.path.basename(path))[0]


def run_job(exe, controller, profile, variant, aic_config, plant_config, trace, pi_config=None):
    """One closed_loop_run of ``controller`` on ``profile`` (CSV) with the plant ``variant``
    ('default' or an overlay file), seeded sensor noise, the trace written to ``trace``; the AIC
    with ``aic_config``, the peer (pi) with ``pi_config`` (None: the program's default). Returns
    (result dict or None, error message or None)."""
    cmd = [exe, "--controller", controller, "--noise", "--config", plant_config, "--profile", profile,
           "--csv", trace, closed_loop.KEEP_GOING]  # a diverged run is a result of the benchmark
    if variant != "default":
        cmd += ["--overlay", variant]
    if controller == "aic":
        cmd += ["--aic-config", aic_config]
    if controller == "pi" and pi_config:
        cmd += ["--pi-config", pi_config]
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if out.returncode != 0:
        # The tool's own message (the plant's ODE library may print notices as well).
        lines = [l for l in out.stderr.splitlines() if l.startswith("closed_loop_run")] or \
            out.stderr.strip().splitlines()[-1:]
        return None, "%s (exit %d): %s" % (" ".join(cmd), out.returncode, " ".join(lines))
    return json.loads(out.stdout), None


def ratio(a, b):
    """|a| / |b| or None when either is missing or b is 0."""
    if a is None or b is None or b == 0.0:
        return None
    return abs(a) / abs(b)


def metric_limited(metric, limited):
    """True when a TABLE_METRICS ``metric`` of a pair whose plant-limited channels are ``limited``
    (a list of "vx", "wz") is not the plant-following kind: a vx_* or wz_* metric when its channel is
    limited, a drift or heading metric when either is."""
    for ch in plant_limits.CHANNELS:
        if metric.startswith(ch + "_"):
            return ch in limited
    return bool(limited)


def suite(a, tool):
    """Run the suite (a: parsed arguments of aic_track.py, tool: cli.Tool); returns the report
    dict (also written to <out>/tracking.json, with tracking.csv and ratios.csv). Raises
    SuiteError (its message names the bad file or the failed runs)."""
    exe = tool.exe("closed_loop_run")
    metrics_cli = tool.exe("aic_track_metrics")
    for f in (a.aic_config, a.pi_config, a.plant_config):
        if not os.path.isfile(f):
            raise SuiteError("no such file: %s" % f)
    profiles = []
    for p in a.profiles:
        try:
            profiles.append(dict(tracking.load_profile(p, cli=metrics_cli), path=p))
        except tracking.TrackingError as e:
            raise SuiteError("bad profile: %s" % e)
    names = [p["name"] for p in profiles]
    if len(set(names)) != len(names):
        raise SuiteError("two profiles with the same name: %s" % ", ".join(names))
    variants = []
    for v in a.variants:
        if v != "default" and not os.path.isfile(v):
            raise SuiteError("no such overlay file: %s (a variant is 'default' or an overlay YAML)" % v)
        variants.append({"name": "default" if v == "default" else _stem(v), "overlay": None if v == "default" else v})
    if len({v["name"] for v in variants}) != len(variants):
        raise SuiteError("two variants with the same name")
    urdf = tool.path("sim", "urdf", "jackal.urdf")  # closed_loop_run's robot description
    try:
        radius, track = plant_limits.urdf_geometry(urdf)
    except (OSError, ValueError) as e:
        raise SuiteError("robot description %s: %s" % (urdf, e))
    for v in variants:
        try:
            motor = closed_loop.plant_motor(a.plant_config, [v["overlay"]] if v["overlay"] else [])
            v["floor_accelerations"] = plant_limits.floor_accelerations(motor, radius, track)
        except (OSError, ValueError) as e:
            raise SuiteError("acceleration-bounded floor of variant %s: %s" % (v["name"], e))
    # The acceleration-bounded floor's servo takes its aim at the AIC's action rate and holds it.
    action_period = 1.0 / float(cli.effective_config([a.aic_config], tool.script, tool.name, warn=False)["action_rate"])
    for sub in ("traces", "plots"):
        os.makedirs(os.path.join(a.out, sub), exist_ok=True)

    jobs = [(p, v, c) for p in profiles for v in variants for c in CONTROLLERS + ("ideal",)]
    start = time.time()

    def one(job):
        p, v, c = job
        if c == "ideal":
            try:
                return job, None, plant_limits.run_ideal(exe, a.plant_config, p["path"], v["overlay"]), None
            except RuntimeError as e:
                return job, None, None, str(e)
        trace = os.path.join(a.out, "traces", "%s__%s__%s.csv" % (p["name"], v["name"], c))
        res, err = run_job(exe, c, p["path"], v["overlay"] or "default", a.aic_config, a.plant_config, trace,
                           a.pi_config)
        return job, trace, res, err

    runs = []
    ideal = {}
    latency = {}
    errors = []
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for (p, v, c), trace, res, err in pool.map(one, jobs):
            if err:
                errors.append(err)
                continue
            if c == "ideal":
                ideal[(p["name"], v["name"])] = res
                continue
            latency[v["name"]] = res["command_delay"]
            runs.append({"profile": p["name"], "variant": v["name"], "controller": c, "trace": trace,
                         "runaways": res["runaways"], "tracking": res["tracking"], "path": res["path"],
                         "metrics": tracking.flat(res)})
    if errors:
        raise SuiteError("%d run(s) failed:\n  %s" % (len(errors), "\n  ".join(errors)))

    by_key = {(r["profile"], r["variant"], r["controller"]): r for r in runs}
    ratios = []
    limits = []
    floors = {}
    for p in profiles:
        for v in variants:
            aic = by_key[(p["name"], v["name"], "aic")]["metrics"]
            stock = by_key[(p["name"], v["name"], "stock")]["metrics"]
            peer = by_key[(p["name"], v["name"], "pi")]["metrics"]
            best = ideal[(p["name"], v["name"])]
            acc = v["floor_accelerations"]
            try:
                floor = driving.floor_rms(p["path"], latency[v["name"]], floors)
                floor_accel = driving.floor_rms(p["path"], latency[v["name"]], floors, period=action_period,
                                                wheels=(acc["wheel_acceleration"], radius, track))
            except tracking.TrackingError as e:
                raise SuiteError("latency floor of %s: %s" % (p["path"], e))
            limited = plant_limits.classify(best, floor)
            ratios.append({"profile": p["name"], "variant": v["name"],
                           "ratios": {m: ratio(aic[m], stock[m]) for m in TABLE_METRICS},
                           "limited": sorted(ch for ch in plant_limits.CHANNELS if limited[ch])})
            limits.append({"profile": p["name"], "variant": v["name"], "ideal": best, "floor": floor,
                           "floor_accel": floor_accel,
                           "ideal_floor": {ch: ratio(best[ch], floor[ch]) for ch in plant_limits.CHANNELS},
                           "aic": {ch: aic[ch + "_rms"] for ch in plant_limits.CHANNELS},
                           "stock": {ch: stock[ch + "_rms"] for ch in plant_limits.CHANNELS},
                           "pi": {ch: peer[ch + "_rms"] for ch in plant_limits.CHANNELS},
                           "aic_wheels": {ch: aic["odom_" + ch + "_rms"] for ch in plant_limits.CHANNELS},
                           "limited": limited})
    gmean, gmean_limited = {}, {}
    for m in TABLE_METRICS:
        following, lim = plant_limits.split((q["ratios"][m], metric_limited(m, q["limited"])) for q in ratios)
        gmean[m], gmean_limited[m] = plant_limits.gmean(following), plant_limits.gmean(lim)
    peer = peer_means(limits)

    plots = {}
    if not a.no_plots:
        for p in profiles:
            for v in variants:
                traces = {c: tracking.read_columns(by_key[(p["name"], v["name"], c)]["trace"]) for c in CONTROLLERS}
                mets = {c: by_key[(p["name"], v["name"], c)]["metrics"] for c in CONTROLLERS}
                path = os.path.join(a.out, "plots", "%s__%s.png" % (p["name"], v["name"]))
                track_report.plot_pair(path, p, traces, "%s on the %s plant: AIC (%s), the stock controller and the "
                                                        "classical peer" % (p["name"], v["name"],
                                                                            os.path.basename(a.aic_config)), mets)
                plots[(p["name"], v["name"])] = path
    wall = time.time() - start

    data = {"command": a.command, "wall_time": wall, "jobs": a.jobs, "aic_config": a.aic_config_shown,
            "pi_config": a.pi_config_shown, "peer_geometric_mean": peer,
            "plant_config": a.plant_config_shown,
            "simulated_time": sum(p["duration"] for p in profiles) * len(variants) * len(CONTROLLERS),
            "profiles": [{"name": p["name"], "file": p["path"], "duration": p["duration"]} for p in profiles],
            "variants": variants, "runs": runs, "ratios": ratios,
            "geometric_mean": {m: list(g) for m, g in gmean.items()},
            "geometric_mean_limited": {m: list(g) for m, g in gmean_limited.items()},
            "plant_limit_ratio": plant_limits.PLANT_LIMIT_RATIO, "plant_limits": limits,
            "floor_period": action_period,
            "plots": {"%s__%s" % k: v for k, v in plots.items()}}
    with open(os.path.join(a.out, "tracking.json"), "w") as f:
        json.dump(data, f, indent=1)
    with open(os.path.join(a.out, "tracking.csv"), "w") as f:
        w = csv.writer(f)
        names = [n for n, _, _ in tracking.FLAT_METRICS]
        w.writerow(["profile", "variant", "controller"] + ["%s [%s]" % (n, UNITS[n]) for n in names] +
                   ["ideal_length [m]", "runaways", "trace"])
        for r in runs:
            w.writerow([r["profile"], r["variant"], r["controller"]] +
                       ["" if r["metrics"][n] is None else "%.6g" % r["metrics"][n] for n in names] +
                       ["%.6g" % r["path"]["ideal_length"], r["runaways"], os.path.relpath(r["trace"], a.out)])
    with open(os.path.join(a.out, "ratios.csv"), "w") as f:
        w = csv.writer(f)
        w.writerow(["profile", "variant"] + ["%s aic/stock" % m for m in TABLE_METRICS] + ["plant-limited"])
        for q in ratios:
            w.writerow([q["profile"], q["variant"]] + ["" if q["ratios"][m] is None else "%.6g" % q["ratios"][m]
                                                       for m in TABLE_METRICS] + [" ".join(q["limited"])])
        w.writerow(["geometric mean (plant-following)", ""] + ["" if gmean[m][0] is None else "%.6g" % gmean[m][0]
                                                               for m in TABLE_METRICS])
    return data


def peer_means(limits):
    """The geometric means of the AIC against the classical peer and the latency floors over the
    plant-following channels of ``limits`` (suite()'s plant_limits list, with "aic", "pi",
    "stock", "floor", "floor_accel" and "aic_wheels" RMS per channel): {"aic_pi", "aic_floor",
    "pi_floor", "aic_stock", "pi_stock", "aic_floor_accel", "pi_floor_accel", "stock_floor_accel"
    (against the acceleration-bounded floor), "floor_accel_floor" (it against the floor),
    "wheels_floor_accel" (the AIC's wheel odometry against the acceleration-bounded floor),
    "truth_wheels" (the AIC's ground truth against its wheel odometry: what the body adds to the
    wheels): {"vx", "wz", "all": [value, count]}}; a channel of a default-plant pair counts in
    "default" too ([value, count]: the nominal channels), and per channel in "default_vx" and
    "default_wz"."""
    out = {}
    pairs = {"aic_pi": ("aic", "pi"), "aic_floor": ("aic", "floor"), "pi_floor": ("pi", "floor"),
             "aic_stock": ("aic", "stock"), "pi_stock": ("pi", "stock"),
             "aic_floor_accel": ("aic", "floor_accel"), "pi_floor_accel": ("pi", "floor_accel"),
             "stock_floor_accel": ("stock", "floor_accel"), "floor_accel_floor": ("floor_accel", "floor"),
             "wheels_floor_accel": ("aic_wheels", "floor_accel"), "truth_wheels": ("aic", "aic_wheels")}
    for name, (num, den) in pairs.items():
        per = {ch: [ratio(q[num][ch], q[den][ch]) for q in limits if not q["limited"][ch]]
               for ch in plant_limits.CHANNELS}
        out[name] = {ch: list(plant_limits.gmean(v)) for ch, v in per.items()}
        out[name]["all"] = list(plant_limits.gmean(per["vx"] + per["wz"]))
        nominal = {ch: [ratio(q[num][ch], q[den][ch]) for q in limits if q["variant"] == "default"]
                   for ch in plant_limits.CHANNELS}
        out[name]["default"] = list(plant_limits.gmean(nominal["vx"] + nominal["wz"]))
        for ch in plant_limits.CHANNELS:
            out[name]["default_" + ch] = list(plant_limits.gmean(nominal[ch]))
    return out


def complete_args(a, argv, root):
    """Fill in the defaults of aic_track.py's parsed arguments ``a`` that depend on the package's
    folder ``root``: the AIC and plant YAMLs (and the names the results show for them), the
    profiles, the variants and the output folder; a.command is the command line (``argv``: its
    arguments)."""
    a.command = " ".join(["aic_track.py"] + list(argv))
    a.aic_config_shown = a.aic_config or "config/default.yaml"
    a.plant_config_shown = a.plant_config or "sim/config/plant.yaml"
    a.aic_config = a.aic_config or os.path.join(root, "config", "default.yaml")
    a.pi_config_shown = a.pi_config or "config/classical/pi.yaml"
    a.pi_config = a.pi_config or os.path.join(root, "config", "classical/pi.yaml")
    a.plant_config = a.plant_config or os.path.join(root, "sim", "config", "plant.yaml")
    a.profiles = a.profiles or default_profiles(root)
    a.variants = a.variants or default_variants(root)
    a.out = a.out or os.path.join(cli.default_results_dir(), "tracking")
