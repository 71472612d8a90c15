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
oscillates (the rule of aic_experiment.py, jackal_aic_tools.common.recording.StabilityLimits, over
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
import csv
import os
import sys
import time

from .reproduce_runs import CoreBackend, RosBackend, Runner
from .reproduce_tables import build, robot_tables


def plot_table(table, runs, out_dir):
    """table_<id>.png in ``out_dir``: the measured speed of every run of ``runs`` ([(label,
    result)]) with a closed_loop_run trace, titled by ``table``. Returns the PNG's path."""
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


def run(a, tool):
    """Run the tables ``a.tables`` (a: parsed arguments of aic_reproduce.py; tool: cli.Tool), write
    each as Markdown + CSV (and a PNG unless a.no_plot) and README.md into a.out, print them.
    Returns the exit status: 1 when a run failed, else 0."""
    os.makedirs(a.out, exist_ok=True)
    trace_dir = os.path.join(a.out, "traces")
    os.makedirs(trace_dir, exist_ok=True)
    backend = CoreBackend(a, tool) if a.backend == "core" else RosBackend(a, tool)
    runner = Runner(backend, a.jobs if a.backend == "core" else 1, trace_dir)
    robot = robot_tables(tool.path("sim", "config", "robot_steps.yaml"))
    plots = []
    started = time.time()
    written = []
    for tid in a.tables:
        t0 = time.time()
        t = build(tid, runner, robot, plots, a.bisections, max(0, a.rows))
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
