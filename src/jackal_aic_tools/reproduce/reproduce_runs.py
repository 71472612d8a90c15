"""The runs of aic_reproduce.py: one simulated experiment (Run), its verdict (ok, slow,
unstable), the backends that run it (closed_loop_run, or aic_experiment.py under ROS) and the
cached, parallel Runner."""
import csv
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

from ..common import closed_loop, recording
from ..common.tables import fmt_value

HOLD = 3.0           # s a step is held (the identification's record length)
SQUARE_PERIOD = 4.0  # s
BOUND_V = 3.0        # m/s: beyond it a run is unstable
# The oscillation rule of aic_experiment.py over the last 1.5 s of each level (not 1 s): with
# the plant's 0.12 s command delay a sustained oscillation has a period of 0.5-1 s, and two
# crossings of the set point in 1.5 s (a full period) already count.
LIMITS = recording.StabilityLimits(v_bound=BOUND_V, osc_window=1.5, osc_crossings=2)
#: Run.config of the improved controller (tables 5-9, 5-10): aic_reproduce.py's --improved-config,
#: config/thesis_improved_exact.yaml.
IMPROVED = "improved"


def config_of(r, a):
    """The controller YAML of the Run ``r``: a.improved_config for IMPROVED, else a.config."""
    return a.improved_config if r.config == IMPROVED else a.config


class Run(object):
    """One simulated experiment: a controller, its configuration (``config``: None, the
    reproduction's controller, --config; IMPROVED, the improved controller's file,
    --improved-config), its parameter overrides, and a profile."""

    def __init__(self, controller, step=None, square=None, params=None, config=None):
        self.controller = controller
        self.step = step
        self.square = square
        self.params = dict(params or {}) if controller == "aic" else {}
        self.config = config if controller == "aic" else None

    def key(self):
        """A string that identifies the run (equal for equal runs)."""
        return json.dumps([self.controller, self.config, self.step, self.square, sorted(self.params.items())])

    def name(self):
        """A file name of the run: controller, configuration, step or square wave, the overrides."""
        parts = [self.controller] + ([self.config] if self.config else [])
        parts += ["v%g" % self.step] if self.step is not None else ["sq%g-%g" % tuple(self.square)]
        parts += ["%s%s" % (k, fmt_value(v)) for k, v in sorted(self.params.items())]
        return "".join(c if c.isalnum() or c in "._-" else "_" for c in "_".join(parts))


def trace_oscillation(trace_path, segments):
    """The reason a closed_loop_run trace (CSV t, set_point, v_odom, ...) oscillates on a held
    level, by the rule of jackal_aic_tools.common.recording.StabilityLimits, else None."""
    if not trace_path or not os.path.exists(trace_path):
        return None
    with open(trace_path) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t"]) for r in rows]
    if not t:
        return None
    for i, seg in enumerate(segments):
        t1 = segments[i + 1]["t_step"] if i + 1 < len(segments) else t[-1]
        if t1 - seg["t_step"] < LIMITS.osc_after:
            continue
        for col, what in (("v_odom", "measured velocity"), ("command", "drive command")):
            window = [float(r[col]) for tt, r in zip(t, rows) if t1 - LIMITS.osc_window <= tt <= t1]
            span = recording.oscillation(window, seg["initial"], seg["target"], LIMITS)
            if span is not None:
                return "oscillation: %s spans %.3g m/s around %g m/s" % (what, span, seg["target"])
    return None


def verdict(runaways, max_abs, segments, oscillating=None):
    """ok | slow | unstable, and why. unstable: runaway, |v| > BOUND_V, or ``oscillating`` (a
    reason); slow: stable, but a segment not settled (+-5 %) by its end."""
    if runaways:
        return "unstable", "runaway"
    if max_abs is not None and max_abs > BOUND_V:
        return "unstable", "speed beyond %g m/s" % BOUND_V
    if oscillating:
        return "unstable", oscillating
    for s in segments:
        m = s.get("measured") or {}
        if not m.get("settled", False):
            return "slow", "not settled at %g m/s" % s["target"]
    return "ok", ""


class CoreBackend(object):
    """closed_loop_run (controller core + plant core, one process, simulated time). a: .config
    (the AIC's YAML), .improved_config (the improved controller's), .plant_config (or None);
    tool: cli.Tool."""

    def __init__(self, a, tool):
        self.exe = tool.exe("closed_loop_run")
        self.a = a

    def run(self, r, trace_path=None):
        """Run ``r`` (a Run), its trace written to ``trace_path``: dict status (ok, slow, unstable,
        failed), reason, segments (closed_loop_run's), trace."""
        # Unstable runs are results of the reproduction (verdict), not errors: KEEP_GOING.
        cmd = [self.exe, "--controller", r.controller, "--aic-config", config_of(r, self.a), "--hold", str(HOLD),
               closed_loop.KEEP_GOING]
        if self.a.plant_config:
            cmd += ["--config", self.a.plant_config]
        for k, v in sorted(r.params.items()):
            cmd += ["--aic-set", "%s=%s" % (k, fmt_value(v))]
        if r.step is not None:
            cmd += ["--step", str(r.step)]
        else:
            cmd += ["--square", str(r.square[0]), str(r.square[1]), "--period", str(SQUARE_PERIOD), "--cycles", "2",
                    "--rest", "2.0"]
        if trace_path:
            cmd += ["--csv", trace_path]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if out.returncode != 0:
            return {"status": "failed", "reason": out.stderr.strip()[-300:], "segments": []}
        res = json.loads(out.stdout)
        status, reason = verdict(res["runaways"], res["max_abs_speed"], res["segments"],
                                 trace_oscillation(trace_path, res["segments"]))
        return {"status": status, "reason": reason, "segments": res["segments"], "trace": trace_path}


class RosBackend(object):
    """aic_experiment.py (beside the tool's script): the nodes under their own master, on
    simulated time. a: .config, .improved_config, .plant_config (or None), .real_time_factor; tool:
    cli.Tool."""

    def __init__(self, a, tool):
        self.a = a
        self.script = os.path.join(os.path.dirname(os.path.abspath(tool.script)), "aic_experiment.py")
        self.tmp = tempfile.mkdtemp(prefix="aic_reproduce_")

    def run(self, r, trace_path=None):
        """Run ``r`` (a Run) with aic_experiment.py: dict status, reason, segments (in
        closed_loop_run's layout), trace (its CSV when ``trace_path`` is given), ros_csv."""
        name = r.name()
        cmd = [sys.executable, self.script, "--controller", r.controller, "--config", config_of(r, self.a),
               "--out", self.tmp, "--name", name, "--no-plot", "--settle", "1.0",
               "--launch-arg", "use_sim_time:=true",
               "--launch-arg", "overrides:=['node.real_time_factor=%g']" % self.a.real_time_factor]
        if self.a.plant_config:
            cmd += ["--launch-arg", "plant_config:=" + os.path.abspath(self.a.plant_config)]
        for k, v in sorted(r.params.items()):
            cmd += ["--set", "%s=%s" % (k, fmt_value(v))]
        if r.step is not None:
            cmd += ["--profile", "step", "--v", str(r.step), "--hold", str(HOLD)]
        else:
            cmd += ["--profile", "square", "--low", str(r.square[0]), "--high", str(r.square[1]),
                    "--period", str(SQUARE_PERIOD), "--cycles", "2"]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False, timeout=600)
        jpath = os.path.join(self.tmp, name + ".json")
        if not os.path.exists(jpath):
            return {"status": "failed", "reason": (out.stdout + out.stderr)[-300:], "segments": []}
        with open(jpath) as f:
            res = json.load(f)
        segments = []
        for s in res.get("segments", []):
            if s.get("channel") != "vx" or s["start"] == s["target"] or s["t_step"] < 0.1:
                continue
            m = s["metrics"].get("measured", {})
            segments.append({"t_step": s["t_step"], "initial": s["start"], "target": s["target"],
                             # aic_experiment's metrics (jackal_aic_tools.common.metrics): settling_time is
                             # None when the response never stayed inside the +-5 % band.
                             "measured": {"rise": m.get("rise_time"), "settling": m.get("settling_time"),
                                          "overshoot": m.get("overshoot"),
                                          "sse": m.get("steady_state_error"),
                                          "settled": m.get("settling_time") is not None}})
        status = res.get("status", "failed")
        if status == "ok":
            status, reason = verdict(0, None, segments)
        else:
            reason = res.get("reason", "")
        trace = None
        if trace_path and res.get("files", {}).get("csv"):
            trace = res["files"]["csv"]
        return {"status": status, "reason": reason, "segments": segments, "trace": trace, "ros_csv": True}


class Runner(object):
    """Runs each distinct Run once (cached), several in parallel, on a backend (CoreBackend,
    RosBackend: run(r, trace_path) -> result dict); traces go to ``trace_dir``. Failed runs are
    listed in ``failures`` as (key, reason)."""

    def __init__(self, backend, jobs, trace_dir):
        self.backend = backend
        self.jobs = max(1, jobs)
        self.cache = {}
        self.trace_dir = trace_dir
        self.failures = []

    def run_all(self, runs):
        """The result dicts of ``runs`` (a list of Run), in their order."""
        todo = [r for r in {r.key(): r for r in runs}.values() if r.key() not in self.cache]

        def one(r):
            trace = os.path.join(self.trace_dir, r.name() + ".csv")
            return r.key(), self.backend.run(r, trace)

        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            for k, res in pool.map(one, todo):
                self.cache[k] = res
                if res["status"] == "failed":
                    self.failures.append((k, res["reason"]))
        return [self.cache[r.key()] for r in runs]

    def get(self, r):
        """The result dict of one Run."""
        return self.run_all([r])[0]
