"""Sweep step-response experiments of jackal_aic across parameters; one table, one plot.

Every combination of the swept values is one run of aic_experiment.py (its own simulator
and master, one after the other). A run that diverges is stopped by the runner and shown
as `unstable`; one that fails (node died, no data, time-out) as `failed`; the sweep goes
on. The table has the thesis's layout: rows = the --rows dimension (step sizes or one
parameter's values), columns = rise and settling time of the measured velocity (/odom)
per setting of the other swept dimensions.

Examples:
  # tau at belief rates 50 and 1000 Hz (thesis table 5-3), rows = tau:
  aic_sweep.py --tau 0.03 0.01 0.001 --belief-rate 50 1000 --rows tau
  # the thesis's step sizes, AIC against stock:
  aic_sweep.py --step 0.1 0.3 0.5 1.0 --controller aic stock
  # gains, on the standard parameter set:
  aic_sweep.py --config config/thesis_standard.yaml --k-a 8 10 15 20 --k-mu 0.01 0.1 --rows k_a
  # any parameter of the YAML:
  aic_sweep.py --param var_y "[2,2,1e5,1e5]" "[2,1e5,1e5,1e5]"

Output (default results/sweep_<name>/): table.txt, table.csv, summary.json, sweep.png, sweep.pdf and
runs/ (each run's CSV, JSON, config).
"""
import csv
import itertools
import json
import os
import subprocess
import sys
import time

import numpy as np

from ..common import cli, figures, report, ros_process
from ..common.tables import fmt, fmt_value
from . import experiment

# sweep dimension -> controller YAML key (None: not a controller parameter)
PARAM_DIMS = [("belief_rate", "belief_rate"), ("action_rate", "action_rate"), ("tau", "tau"),
              ("k_mu", "k_mu"), ("k_a", "k_a"), ("integrator", "integrator")]
LABEL = {"belief_rate": "belief %s Hz", "action_rate": "action %s Hz", "tau": "tau=%s", "k_mu": "k_mu=%s",
         "k_a": "k_a=%s", "integrator": "%s", "controller": "%s", "step": "%s m/s"}


def dimensions(a):
    """Ordered list of (dimension, [values]) with every swept dimension."""
    dims = []
    for d, _ in PARAM_DIMS:
        vals = getattr(a, d)
        if vals:
            dims.append((d, list(vals)))
    for entry in a.param:
        if len(entry) < 2:
            raise ValueError("--param %s needs at least one value" % entry[0])
        key = entry[0]
        dims.append((key, [experiment.parse_override("%s=%s" % (key, v))[1] for v in entry[1:]]))
    dims.append(("controller", list(a.controller)))
    if a.step:
        if a.profile != "step":
            raise ValueError("--step applies to the step profile only")
        dims.append(("step", list(a.step)))
    return dims


def label(dim, v):
    """The caption of value ``v`` of the sweep dimension ``dim`` ("tau=0.01", "belief 50 Hz")."""
    return LABEL.get(dim, dim + "=%s") % fmt_value(v)


def run_key(combo):
    """Settings that matter for this run (the stock controller ignores AIC parameters)."""
    if combo["controller"] == "stock":
        return tuple(sorted((k, fmt_value(v)) for k, v in combo.items() if k in ("controller", "step")))
    return tuple(sorted((k, fmt_value(v)) for k, v in combo.items()))


def run_one(a, combo, out_dir, idx, script_dir):
    """Run one combination ``combo`` (dimension -> value) with aic_experiment.py (in
    ``script_dir``) under its own master, into ``out_dir`` (a: parsed arguments of aic_sweep.py;
    idx: the run's number). Returns aic_experiment's result dict (with "log" and "wall"), or a
    failed one (status, reason) when it timed out or wrote no result."""
    name = "run%02d_" % idx + "_".join("%s%s" % (k, fmt_value(v)) for k, v in sorted(combo.items())
                                       if not (combo["controller"] == "stock" and k not in ("controller", "step")))
    name = "".join(c if c.isalnum() or c in "._-" else "_" for c in name)[:120]
    cmd = [sys.executable, os.path.join(script_dir, "aic_experiment.py"),
           "--controller", combo["controller"], "--config", a.config, "--launch", a.launch,
           "--out", out_dir, "--name", name, "--settle", str(a.settle),
           "--ready-timeout", str(a.ready_timeout), "--bound-v", str(a.bound_v), "--bound-w", str(a.bound_w),
           "--profile", a.profile, "--v", str(combo.get("step", a.v)), "--w", str(a.w),
           "--t-step", str(a.t_step), "--hold", str(a.hold), "--low", str(a.low), "--high", str(a.high),
           "--period", str(a.period), "--cycles", str(a.cycles)]
    if a.csv:
        cmd += ["--csv", a.csv]
    if not a.run_plots:
        cmd.append("--no-plot")
    for la in a.launch_arg:
        cmd += ["--launch-arg", la]
    if combo["controller"] == "aic":
        for s in a.set:
            cmd += ["--set", s]
        for k, v in combo.items():
            if k not in ("controller", "step"):
                cmd += ["--set", "%s=%s" % (k, fmt_value(v))]
    prof = cli.make_profile(a)
    limit = a.run_timeout or 4.0 * prof.duration + 120.0
    t = time.time()
    log_path = os.path.join(out_dir, name + ".log")
    with open(log_path, "w") as logf:
        proc = ros_process.start(cmd, stdout=logf)
        try:
            proc.wait(timeout=limit)
        except subprocess.TimeoutExpired:
            ros_process.stop(proc)  # its roslaunch shuts the simulator and master down
            return {"name": name, "status": "failed", "reason": "timed out after %.0f s" % limit,
                    "segments": [], "log": log_path}
        except KeyboardInterrupt:  # the run is in its own session: stop it too
            ros_process.stop(proc)
            raise
    jpath = os.path.join(out_dir, name + ".json")
    if not os.path.exists(jpath):
        tail = open(log_path).read()[-400:]
        return {"name": name, "status": "failed", "reason": "exit %d, no result: %s" % (proc.returncode, tail),
                "segments": [], "log": log_path}
    with open(jpath) as f:
        res = json.load(f)
    res["log"] = log_path
    res["wall"] = time.time() - t
    return res


def headline(res):
    """(rise [s], settling [s]) of the measured velocity: the step, or for several
    transitions the worst (largest) of each; None when undefined."""
    rises, sets = [], []
    for seg in res.get("segments", []):
        m = seg["metrics"].get("measured") or {}
        if "error" in m:
            continue
        rises.append(m.get("rise_time"))
        sets.append(m.get("settling_time"))
    worst = lambda xs: None if not xs or any(x is None for x in xs) else max(xs)
    return worst(rises), worst(sets)


def run(a, dims, script_dir):
    """Run the sweep over ``dims`` (dimensions(a); a: parsed and checked arguments of aic_sweep.py),
    each run with aic_experiment.py in ``script_dir``; print and write the table, the summary and
    the plot. Returns the exit status (1 when --rows is not a swept dimension)."""
    swept = [d for d, v in dims if len(v) > 1]
    rows_dim = a.rows or ("step" if "step" in swept else (swept[0] if swept else "controller"))
    if rows_dim not in [d for d, _ in dims]:
        print("aic_sweep: --rows %s is not a swept dimension (%s)" % (rows_dim, ", ".join(d for d, _ in dims)),
              file=sys.stderr)
        return 1
    col_dims = [d for d in swept if d != rows_dim]
    fixed = [(d, v[0]) for d, v in dims if len(v) == 1 and d != rows_dim]
    name = a.name or "sweep_" + "_".join(swept or ["single"])
    out = a.out or os.path.join(cli.default_results_dir(), name)
    runs_dir = os.path.join(out, "runs")
    os.makedirs(runs_dir, exist_ok=True)

    dvals = dict(dims)
    col_combos = list(itertools.product(*[dvals[d] for d in col_dims])) or [()]
    cache, grid = {}, {}
    total = len(dvals[rows_dim]) * len(col_combos)
    n = 0
    for rv in dvals[rows_dim]:
        for cc in col_combos:
            combo = {d: v[0] for d, v in dims}
            combo[rows_dim] = rv
            combo.update(dict(zip(col_dims, cc)))
            key = run_key(combo)
            n += 1
            if key not in cache:
                print("[%d/%d] %s ..." % (n, total, ", ".join("%s=%s" % (k, fmt_value(v)) for k, v in
                                                                    sorted(combo.items()))), flush=True)
                res = run_one(a, combo, runs_dir, len(cache), script_dir)
                cache[key] = res
                r, s = headline(res)
                print("        %s  rise %s s  settling %s s%s" % (res["status"], fmt(r), fmt(s),
                      ("  (" + res["reason"] + ")") if res["status"] != "ok" else ""), flush=True)
            grid[(fmt_value(rv), fmt_value(list(cc)))] = cache[key]

    # the table
    headers = [rows_dim + (" [m/s]" if rows_dim == "step" else "")]
    for cc in col_combos:
        lab = ", ".join(label(d, v) for d, v in zip(col_dims, cc)) or "result"
        headers += [lab + ": rise [s]", "settling [s]"]
    rows = []
    for rv in dvals[rows_dim]:
        row = [fmt_value(rv)]
        for cc in col_combos:
            res = grid[(fmt_value(rv), fmt_value(list(cc)))]
            if res["status"] != "ok":
                row += [res["status"], ""]
            else:
                r, s = headline(res)
                row += [fmt(r), fmt(s) if s is not None else "not settled"]
        rows.append(row)
    fixed_txt = ", ".join(label(d, v) for d, v in fixed)
    prof = cli.make_profile(a)
    title = "Sweep %s: profile %s, config %s%s%s; rise 10-90 %% and settling +-5 %% of /odom %s" % (
        name, prof.name, os.path.basename(a.config), (" + " + " ".join(a.set)) if a.set else "",
        (", " + fixed_txt) if fixed_txt else "",
        "(worst transition)" if len(prof.segments()) > 1 else "")
    table = report.format_table(headers, rows)
    print()
    print(title)
    print(table)
    with open(os.path.join(out, "table.txt"), "w") as f:
        f.write(title + "\n" + table + "\n")
    with open(os.path.join(out, "table.csv"), "w") as f:
        w = csv.writer(f)
        w.writerow(headers)
        w.writerows(rows)
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump({"title": title, "rows": rows_dim, "columns": col_dims, "fixed": fixed,
                   "runs": [dict(settings=dict(k), **{kk: v for kk, v in r.items() if kk != "params"})
                            for k, r in cache.items()]}, f, indent=1, default=str)
    png = combined_plot(os.path.join(out, "sweep.png"), dvals[rows_dim], rows_dim, col_combos, col_dims, grid,
                        title, figures.zoom_events([s.t0 for s in prof.segments()], prof.duration + a.settle))
    print("table %s\nplot  %s\nruns  %s" % (os.path.join(out, "table.txt"), png, runs_dir))
    return 0


def combined_plot(path, row_vals, rows_dim, col_combos, col_dims, grid, title, events=()):
    """sweep.png and sweep.pdf (figures.save): one time axis per row value, in each the measured
    velocity [m/s or rad/s] of every column setting (figures.style) and the set point; beside it
    the first second after each time of ``events`` [s] (the profile's set-point changes worth a
    zoom, figures.zoom_events); the legends outside, ``title`` wrapped above. Returns ``path``."""
    plt = figures.pyplot()
    events = list(events)
    fig = plt.figure(figsize=(9.0 + 2.4 * len(events), 2.6 * len(row_vals) + 1.0))
    mains, zooms, _ = figures.grid(fig, len(row_vals), len(events))
    for ax, zs, rv in zip(mains, zooms, row_vals):
        axs = [ax] + zs
        sp_done = False
        for k, cc in enumerate(col_combos):
            res = grid[(fmt_value(rv), fmt_value(list(cc)))]
            lab = ", ".join(label(d, v) for d, v in zip(col_dims, cc)) or "measured"
            if res["status"] != "ok":
                lab += " [%s]" % res["status"]
            csvp = res.get("files", {}).get("csv")
            if not csvp or not os.path.exists(csvp):
                ax.plot([], [], label=lab + " (no data)", **figures.style(k))
                continue
            d = np.genfromtxt(csvp, delimiter=",", names=True, dtype=None, encoding=None)
            ch = "vx" if any(s["channel"] == "vx" for s in res.get("segments", [])) or not res.get("segments") else "wz"
            src = d["source"]
            odom = d[src == "odom"]
            spr = d[src == "setpoint"]
            for a in axs:
                a.plot(odom["t"], odom["odom_" + ch], label=lab, **figures.style(k))
                if not sp_done and spr.size:
                    a.step(spr["t"], spr["setpoint_" + ch], where="post", label="set point", **figures.REFERENCE)
            sp_done = sp_done or bool(spr.size)
        ax.set_title(label(rows_dim, rv), fontsize=9)
        ax.set_ylabel("velocity [m/s or rad/s]")
        for a, t in zip(zs, events):
            figures.zoom(a, t)
            if ax is not mains[0]:
                a.set_title("")  # the first row's zoom names the window
        for a in axs:
            a.grid(True, alpha=0.3)
        figures.legend_outside(axs[-1], *ax.get_legend_handles_labels(), fontsize=7)
    mains[-1].set_xlabel("time since profile start [s]")
    for a in zooms[-1]:
        a.set_xlabel("time [s]")
    for col in [mains] + [[z[k] for z in zooms] for k in range(len(events))]:
        for a in col[:-1]:
            plt.setp(a.get_xticklabels(), visible=False)
    top = figures.suptitle(fig, title, fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, top))
    return figures.save(fig, path, dpi=100)
