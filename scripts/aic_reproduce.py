#!/usr/bin/env python3
"""aic_reproduce.py: reproduce the thesis's experiments on the simulated Jackal, one command.

Runs the step responses, sweeps, stability limits and square waves of B.D. van der Meer,
"Control analysis of an active inference controller for a skid-steer mobile robot" (MSc
thesis, TU Delft, 2022), chapter 3 and 5, with the thesis-equivalent controller
(config/thesis_equivalent.yaml) and the Jackal's stock controller, and writes each table in
the thesis's layout as Markdown + CSV and one PNG into results/reproduction/. Where the
robot's numbers are in sim/config/robot_steps.yaml (tables 3-1, 5-1, 5-2) they are printed
beside the simulated ones with the error of each entry.

Tables (--tables, default all):
  3-1   steps 0.1 / 0.5 / 1.0 m/s from rest: basic AIC (C-1 values, 50 Hz) (a), stock controller (b)
  5-1   steps 0.3 / 0.5 / 1.0 m/s, whole controller (belief and action loops) at 50 / 100 / 1000 Hz
  5-2   as 5-1, belief loop at 50 / 100 / 1000 Hz, action loop at 50 Hz
  5-4   tau in {0.03, 0.01, 0.001} s at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-5   k_mu in {0.01, 0.05, 0.1, 1} at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-6   k_a in {8, 10, 15, 20} at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-7   stability limits per belief rate: smallest stable tau, largest stable k_mu and k_a,
        each found by bisection (on a log scale) with the others at their C-1 values
  5-9   improved controller (tau = 0.001, belief loop 1 kHz, action 50 Hz, exact integrator, on
        the thesis-equivalent variances) against the stock controller, steps 0.3 / 0.5 / 1.0 m/s
  5-10  square waves (0.1, 0.5), (0.1, 1.0), (0.2, 1.2) m/s: improved controller and stock
Sweeps and limits run the action loop at 50 Hz. A run is "unstable" ("unst." in a table)
when the controller hit its runaway limit, the speed exceeded 3 m/s, or a held level
oscillates (the rule of aic_experiment.py, jackal_aic_tools.recording.StabilityLimits, over
a longer window: in the last 1.5 s of a level held >= 1.5 s the measured velocity or the
drive command spans more than half the step and crosses the set point twice). A stable run that has not settled (+-5 %) by the
end of the 3 s hold is "slow" ("n.s." in a table, no settling time); stability limits
(table 5-7) count only unstable runs as unstable.

Backends:
  core (default)  closed_loop_run: the controller core and the plant core in one process on
                  simulated time, the node's logic (ControlLoop, jackal_sim/closed_loop.hpp); fast and
                  deterministic (ideal sensors). The whole reproduction takes a few minutes.
  ros             aic_experiment.py: the jackal_AIC (or stock) node against the plant node,
                  each run under its own master with use_sim_time and the plant at
                  --real-time-factor; slower.

Usage:
  aic_reproduce.py [--tables 3-1 5-1 ...] [--backend core|ros] [--out DIR] [--jobs N]
                   [--rows N] [--real-time-factor F] [--config FILE] [--plant-config FILE]
Exit: 0 when every run ran (unstable runs are results, not failures), 1 on a failed run.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import yaml

from jackal_aic_tools import cli, recording

ALL_TABLES = ["3-1", "5-1", "5-2", "5-4", "5-5", "5-6", "5-7", "5-9", "5-10"]
RATES = [50, 100, 1000]
SQUARES = [(0.1, 0.5), (0.1, 1.0), (0.2, 1.2)]
IMPROVED = {"tau": 0.001, "belief_rate": 1000, "action_rate": 50, "integrator": "exact"}
HOLD = 3.0           # s a step is held (the identification's record length)
SQUARE_PERIOD = 4.0  # s
BOUND_V = 3.0        # m/s: beyond it a run is unstable
# The oscillation rule of aic_experiment.py over the last 1.5 s of each level (not 1 s): with
# the plant's 0.12 s command delay a sustained oscillation has a period of 0.5-1 s, and two
# crossings of the set point in 1.5 s (a full period) already count.
LIMITS = recording.StabilityLimits(v_bound=BOUND_V, osc_window=1.5, osc_crossings=2)
ROW_LIMIT = [0]      # --rows: only the first N rows of each table are run (0 = all)


def lim(values):
    """The first --rows entries of a table's row values."""
    return values[:ROW_LIMIT[0]] if ROW_LIMIT[0] > 0 else values


def repo_root():
    return cli.source_root(__file__)


def find_exe(name):
    return cli.find_executable(name, __file__, "aic_reproduce")


def fmt_val(v):
    return ("%g" % v) if isinstance(v, (int, float)) else str(v)


# --------------------------------------------------------------------------- runs

class Run(object):
    """One simulated experiment: a controller, its parameter overrides, and a profile."""

    def __init__(self, controller, step=None, square=None, params=None):
        self.controller = controller
        self.step = step
        self.square = square
        self.params = dict(params or {}) if controller == "aic" else {}

    def key(self):
        return json.dumps([self.controller, self.step, self.square, sorted(self.params.items())])

    def name(self):
        parts = [self.controller]
        parts += ["v%g" % self.step] if self.step is not None else ["sq%g-%g" % tuple(self.square)]
        parts += ["%s%s" % (k, fmt_val(v)) for k, v in sorted(self.params.items())]
        return "".join(c if c.isalnum() or c in "._-" else "_" for c in "_".join(parts))


def trace_oscillation(trace_path, segments):
    """The reason a closed_loop_run trace (CSV t, set_point, v_odom, ...) oscillates on a held
    level, by the rule of jackal_aic_tools.recording.StabilityLimits, else None."""
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
    """closed_loop_run (controller core + plant core, one process, simulated time)."""

    def __init__(self, a):
        self.exe = find_exe("closed_loop_run")
        self.a = a

    def run(self, r, trace_path=None):
        cmd = [self.exe, "--controller", r.controller, "--aic-config", self.a.config, "--hold", str(HOLD)]
        if self.a.plant_config:
            cmd += ["--config", self.a.plant_config]
        for k, v in sorted(r.params.items()):
            cmd += ["--aic-set", "%s=%s" % (k, fmt_val(v))]
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
    """aic_experiment.py: the nodes under their own master, on simulated time."""

    def __init__(self, a):
        self.a = a
        self.script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "aic_experiment.py")
        self.tmp = tempfile.mkdtemp(prefix="aic_reproduce_")

    def run(self, r, trace_path=None):
        name = r.name()
        cmd = [sys.executable, self.script, "--controller", r.controller, "--config", self.a.config,
               "--out", self.tmp, "--name", name, "--no-plot", "--settle", "1.0",
               "--launch-arg", "use_sim_time:=true",
               "--launch-arg", "overrides:=['node.real_time_factor=%g']" % self.a.real_time_factor]
        if self.a.plant_config:
            cmd += ["--launch-arg", "plant_config:=" + os.path.abspath(self.a.plant_config)]
        for k, v in sorted(r.params.items()):
            cmd += ["--set", "%s=%s" % (k, fmt_val(v))]
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
                             # aic_experiment's metrics (jackal_aic_tools.metrics): settling_time is
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
    """Runs each distinct Run once (cached), several in parallel."""

    def __init__(self, backend, jobs, trace_dir):
        self.backend = backend
        self.jobs = max(1, jobs)
        self.cache = {}
        self.trace_dir = trace_dir
        self.failures = []

    def run_all(self, runs):
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
        return self.run_all([r])[0]


def metric(res, name, seg=0):
    """A measured-speed metric of segment seg, or None (unstable, or undefined: a slow run's
    settling time)."""
    if res["status"] not in ("ok", "slow") or len(res["segments"]) <= seg:
        return None
    v = (res["segments"][seg].get("measured") or {}).get(name)
    return v if v is not None and math.isfinite(v) else None


# --------------------------------------------------------------------------- tables

def robot_tables(path):
    with open(path) as f:
        doc = yaml.safe_load(f)
    out = {}
    for t in doc["tables"]:
        out[t["id"]] = {(r[0], r[1], r[2]): (r[3], r[4]) for r in t["rows"]}
    return out


def cell(v, spec="%.2f", res=None):
    """v formatted, or why there is no value: "unst." (unstable run), "n.s." (stable, not
    settled within the hold), "-" (undefined)."""
    if v is not None:
        return spec % v
    if res is None or res["status"] == "unstable":
        return "unst."
    return "n.s." if res["status"] == "slow" else "-"


def err(sim, robot):
    if sim is None or robot is None:
        return ""
    return "%+.0f%%" % (100.0 * (sim - robot) / robot)


class Table(object):
    def __init__(self, tid, title, headers, note=""):
        self.id = tid
        self.title = title
        self.headers = headers
        self.rows = []
        self.note = note
        self.errors = []  # |relative errors| against the robot

    def add(self, row):
        self.rows.append([str(c) for c in row])

    def markdown(self):
        lines = ["### Table %s: %s" % (self.id, self.title), ""]
        lines.append("| " + " | ".join(self.headers) + " |")
        lines.append("|" + "|".join("---" for _ in self.headers) + "|")
        for r in self.rows:
            lines.append("| " + " | ".join(r) + " |")
        if self.errors:
            lines.append("")
            lines.append("Mean |error| against the robot: %.0f %% over %d entries."
                         % (100.0 * sum(self.errors) / len(self.errors), len(self.errors)))
        if self.note:
            lines += ["", self.note]
        return "\n".join(lines) + "\n"

    def write(self, out_dir):
        base = os.path.join(out_dir, "table_" + self.id)
        with open(base + ".md", "w") as f:
            f.write(self.markdown())
        with open(base + ".csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(self.headers)
            w.writerows(self.rows)
        return base


def step_pair(runner, tables_robot, tid, key, res):
    """Settling, rise cells (sim, robot, error) for a row with robot data."""
    s, r = metric(res, "settling"), metric(res, "rise")
    robot = tables_robot.get(tid, {}).get(key)
    cells = [cell(s, res=res), cell(robot[0]) if robot else "", err(s, robot[0] if robot else None),
             cell(r, res=res), cell(robot[1]) if robot else "", err(r, robot[1] if robot else None)]
    errs = []
    if robot:
        for sim_v, rob_v in ((s, robot[0]), (r, robot[1])):
            errs.append(abs((sim_v - rob_v) / rob_v) if sim_v is not None else 2.0)
    return cells, errs


def table_3_1(runner, robot, plots):
    t = Table("3-1", "steps from rest: (a) basic AIC, table C-1 values (thesis-equivalent), 50 Hz; "
                     "(b) stock controller",
              ["step [m/s]", "(a) settling sim [s]", "robot", "error", "(a) rise sim [s]", "robot", "error",
               "(b) settling sim [s]", "robot", "error", "(b) rise sim [s]", "robot", "error"])
    steps = lim([0.1, 0.5, 1.0])
    aic = [Run("aic", v, params={"belief_rate": 50, "action_rate": 50}) for v in steps]
    stock = [Run("stock", v) for v in steps]
    ra, rs = runner.run_all(aic), runner.run_all(stock)
    for v, a_res, s_res in zip(steps, ra, rs):
        ca, ea = step_pair(runner, robot, "3-1a", (v, 50, 50), a_res)
        cs, es = step_pair(runner, robot, "3-1b", (v, 50, 50), s_res)
        t.add(["%.1f" % v] + ca + cs)
        t.errors += ea + es
    plots.append((t, [("AIC %g m/s" % v, r) for v, r in zip(steps, ra)] +
                  [("stock %g m/s" % v, r) for v, r in zip(steps, rs)]))
    return t


def table_rates(runner, robot, plots, tid, action_follows):
    title = ("whole controller (belief and action loops) at 50 / 100 / 1000 Hz" if action_follows else
             "belief loop at 50 / 100 / 1000 Hz, action loop 50 Hz")
    headers = ["step [m/s]"]
    for rate in RATES:
        headers += ["%d Hz settling sim [s]" % rate, "robot", "error", "%d Hz rise sim [s]" % rate, "robot", "error"]
    t = Table(tid, title + " (thesis-equivalent controller)", headers)
    runs_plot = []
    for v in lim([0.3, 0.5, 1.0]):
        row = ["%.1f" % v]
        for rate in RATES:
            act = rate if action_follows else 50
            res = runner.get(Run("aic", v, params={"belief_rate": rate, "action_rate": act}))
            c, e = step_pair(runner, robot, tid, (v, rate, act), res)
            row += c
            t.errors += e
            runs_plot.append(("%g m/s, %d Hz" % (v, rate), res))
        t.add(row)
    plots.append((t, runs_plot))
    return t


def table_sweep(runner, plots, tid, param, values, symbol):
    headers = [symbol]
    for rate in RATES:
        headers += ["%d Hz settling [s]" % rate, "%d Hz rise [s]" % rate]
    t = Table(tid, "%s sweep at belief rates 50 / 100 / 1000 Hz, action 50 Hz, 0.5 m/s step "
                   "(others at C-1 values; \"unst.\" = unstable, \"n.s.\" = not settled in 3 s)" % symbol, headers)
    runs_plot = []
    for val in lim(values):
        row = [fmt_val(val)]
        for rate in RATES:
            res = runner.get(Run("aic", 0.5, params={param: val, "belief_rate": rate, "action_rate": 50}))
            row += [cell(metric(res, "settling"), res=res), cell(metric(res, "rise"), res=res)]
            runs_plot.append(("%s=%s, %d Hz" % (param, fmt_val(val), rate), res))
        t.add(row)
    plots.append((t, runs_plot))
    return t


def stable(runner, param, value, rate):
    """Not unstable (a slow run is stable) at param = value, belief rate [Hz], 0.5 m/s step."""
    res = runner.get(Run("aic", 0.5, params={param: value, "belief_rate": rate, "action_rate": 50}))
    if res["status"] == "failed":
        raise RuntimeError("run failed: %s" % res["reason"])
    return res["status"] in ("ok", "slow")


def bisect_limit(runner, param, rate, lo, hi, lower_is_limit, iterations):
    """Bisection on log(value) between a stable and an unstable bound. For tau the limit is the
    smallest stable value (lower_is_limit), for the gains the largest. Returns (limit, bracket)."""
    # lo, hi: the search range; find the stable end first.
    stable_end, unstable_end = (hi, lo) if lower_is_limit else (lo, hi)
    if not stable(runner, param, stable_end, rate):
        return None, "unstable at %g" % stable_end
    if stable(runner, param, unstable_end, rate):
        return unstable_end, "stable over the whole range"
    for _ in range(iterations):
        mid = math.sqrt(stable_end * unstable_end)
        if stable(runner, param, mid, rate):
            stable_end = mid
        else:
            unstable_end = mid
    return stable_end, "between %.3g and %.3g" % tuple(sorted((stable_end, unstable_end)))


def table_5_7(runner, a):
    t = Table("5-7", "stability limits of the thesis-equivalent controller per belief rate (action 50 Hz, "
                     "0.5 m/s step; bisection on a log scale, %d steps)" % a.bisections,
              ["belief rate [Hz]", "smallest stable tau [s]", "bracket", "largest stable k_mu", "bracket",
               "largest stable k_a", "bracket"])
    for rate in lim(RATES):
        row = [str(rate)]
        for param, lo, hi, lower in (("tau", 1e-4, 0.1, True), ("k_mu", 1e-3, 100.0, False),
                                     ("k_a", 1.0, 1000.0, False)):
            limit, bracket = bisect_limit(runner, param, rate, lo, hi, lower, a.bisections)
            row += [cell(limit, "%.3g") if limit is not None else "none", bracket]
        t.add(row)
    return t


def table_5_9(runner, plots):
    t = Table("5-9", "improved controller (tau = 0.001, belief 1 kHz, action 50 Hz, exact integrator, "
                     "thesis-equivalent variances) against the stock controller",
              ["step [m/s]", "improved settling [s]", "improved rise [s]", "improved overshoot [%]",
               "stock settling [s]", "stock rise [s]", "stock overshoot [%]", "rise improved / stock"])
    runs_plot = []
    for v in lim([0.3, 0.5, 1.0]):
        ri = runner.get(Run("aic", v, params=IMPROVED))
        rs = runner.get(Run("stock", v))
        ratio = ""
        if metric(ri, "rise") and metric(rs, "rise"):
            ratio = "%.2f" % (metric(ri, "rise") / metric(rs, "rise"))
        t.add(["%.1f" % v, cell(metric(ri, "settling"), res=ri), cell(metric(ri, "rise"), res=ri),
               cell(metric(ri, "overshoot"), "%.1f", ri), cell(metric(rs, "settling"), res=rs),
               cell(metric(rs, "rise"), res=rs), cell(metric(rs, "overshoot"), "%.1f", rs), ratio])
        runs_plot += [("improved %g m/s" % v, ri), ("stock %g m/s" % v, rs)]
    plots.append((t, runs_plot))
    return t


def table_5_10(runner, plots):
    t = Table("5-10", "square waves, period %g s: improved controller and stock controller "
                      "(worst of the transitions up / down)" % SQUARE_PERIOD,
              ["wave [m/s]", "controller", "up: rise [s]", "up: settling [s]", "up: overshoot [%]",
               "down: rise [s]", "down: settling [s]", "down: overshoot [%]"])
    runs_plot = []
    for low, high in lim(SQUARES):
        for name, r in (("improved", Run("aic", square=(low, high), params=IMPROVED)),
                        ("stock", Run("stock", square=(low, high)))):
            res = runner.get(r)
            row = ["%g <-> %g" % (low, high), name]
            for up in (True, False):
                segs = [i for i, s in enumerate(res["segments"])
                        if (s["target"] > s["initial"]) == up and s["initial"] != 0.0]
                vals = []
                for m in ("rise", "settling", "overshoot"):
                    xs = [metric(res, m, i) for i in segs]
                    vals.append(None if not xs or any(x is None for x in xs) else max(xs))
                row += [cell(vals[0], res=res), cell(vals[1], res=res), cell(vals[2], "%.1f", res)]
            t.add(row)
            runs_plot.append(("%s %g-%g" % (name, low, high), res))
    plots.append((t, runs_plot))
    return t


# --------------------------------------------------------------------------- plots

def plot_table(table, runs, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(10, 5.5))
    for label, res in runs:
        trace = res.get("trace")
        if not trace or not os.path.exists(trace) or res.get("ros_csv"):
            continue
        ts, vs = [], []
        with open(trace) as f:
            for row in csv.DictReader(f):
                ts.append(float(row["t"]))
                vs.append(float(row["v_odom"]))
        ax.plot(ts, vs, lw=1.0, label=label + ("" if res["status"] == "ok" else " (%s)" % res["status"]))
    ax.set_xlim(-0.2, None)
    ax.set_xlabel("time from the first step [s]")
    ax.set_ylabel("body speed, wheel odometry [m/s]")
    ax.set_title("Table %s: %s" % (table.id, table.title), fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=6, ncol=3)
    path = os.path.join(out_dir, "table_%s.png" % table.id)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- main

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 2)[2])
    ap.add_argument("--tables", nargs="+", default=ALL_TABLES, choices=ALL_TABLES)
    ap.add_argument("--backend", choices=("core", "ros"), default="core")
    ap.add_argument("--out", default=os.path.join(repo_root(), "results", "reproduction"))
    ap.add_argument("--config", default=os.path.join(repo_root(), "config", "thesis_equivalent.yaml"),
                    help="the thesis-equivalent controller YAML (default: %(default)s)")
    ap.add_argument("--plant-config", default=None, help="plant YAML (default: the package's sim/config/plant.yaml)")
    ap.add_argument("--jobs", type=int, default=2, help="runs in parallel (core backend)")
    ap.add_argument("--rows", type=int, default=0, help="only the first N rows of each step table (0 = all)")
    ap.add_argument("--bisections", type=int, default=6, help="bisection steps per stability limit")
    ap.add_argument("--real-time-factor", type=float, default=2.0, help="ros backend: plant speed-up")
    ap.add_argument("--no-plot", action="store_true")
    a = ap.parse_args(argv)

    ROW_LIMIT[0] = max(0, a.rows)
    os.makedirs(a.out, exist_ok=True)
    trace_dir = os.path.join(a.out, "traces")
    os.makedirs(trace_dir, exist_ok=True)
    backend = CoreBackend(a) if a.backend == "core" else RosBackend(a)
    runner = Runner(backend, a.jobs if a.backend == "core" else 1, trace_dir)
    robot = robot_tables(os.path.join(repo_root(), "sim", "config", "robot_steps.yaml"))
    plots = []
    started = time.time()
    written = []
    for tid in a.tables:
        t0 = time.time()
        if tid == "3-1":
            t = table_3_1(runner, robot, plots)
        elif tid in ("5-1", "5-2"):
            t = table_rates(runner, robot, plots, tid, tid == "5-1")
        elif tid == "5-4":
            t = table_sweep(runner, plots, tid, "tau", [0.03, 0.01, 0.001], "tau [s]")
        elif tid == "5-5":
            t = table_sweep(runner, plots, tid, "k_mu", [0.01, 0.05, 0.1, 1.0], "k_mu")
        elif tid == "5-6":
            t = table_sweep(runner, plots, tid, "k_a", [8.0, 10.0, 15.0, 20.0], "k_a")
        elif tid == "5-7":
            t = table_5_7(runner, a)
        elif tid == "5-9":
            t = table_5_9(runner, plots)
        else:
            t = table_5_10(runner, plots)
        base = t.write(a.out)
        written.append(base)
        print(t.markdown())
        print("(%s: %.0f s, %s.md / .csv)\n" % (tid, time.time() - t0, base))
    if not a.no_plot:
        for t, runs in plots:
            if t.id in a.tables:
                print("plot: %s" % plot_table(t, runs, a.out))
    with open(os.path.join(a.out, "README.md"), "w") as f:
        f.write("# Reproduction of the thesis's experiments (aic_reproduce.py, backend %s)\n\n" % a.backend)
        f.write("Controller: %s. Runs: %d, %.0f s wall.\n\n" % (a.config, len(runner.cache), time.time() - started))
        for base in written:
            with open(base + ".md") as tf:
                f.write(tf.read() + "\n")
    print("aic_reproduce: %d runs, %.0f s; tables in %s" % (len(runner.cache), time.time() - started, a.out))
    for k, reason in runner.failures:
        print("FAILED run %s: %s" % (k, reason), file=sys.stderr)
    return 1 if runner.failures else 0


if __name__ == "__main__":
    sys.exit(main())
