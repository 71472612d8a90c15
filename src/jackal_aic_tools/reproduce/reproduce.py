"""aic_reproduce.py: reproduce the thesis's experiments on the simulated Jackal, one command.

Runs the step responses, sweeps, stability limits and square waves of B.D. van der Meer,
"Control analysis of an active inference controller for a skid-steer mobile robot" (MSc
thesis, TU Delft, 2022), chapter 3 and 5, with the thesis-equivalent controller
(config/thesis_equivalent.yaml) and the Jackal's stock controller, and writes each table in
the thesis's layout as Markdown + CSV and one figure (PNG and PDF) into results/reproduction/.
Where the robot's numbers are in sim/config/robot_steps.yaml (tables 3-1, 5-1, 5-2) they are
printed beside the simulated ones with the error of each entry.

Tables (--tables, default all):
  3-1   steps 0.1 / 0.5 / 1.0 m/s from rest: basic AIC (C-1 values, 50 Hz) (a), stock controller (b)
  5-1   steps 0.3 / 0.5 / 1.0 m/s, whole controller (belief and action loops) at 50 / 100 / 1000 Hz
  5-2   as 5-1, belief loop at 50 / 100 / 1000 Hz, action loop at 50 Hz
  5-4   tau in {0.03, 0.01, 0.001} s at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-5   k_mu in {0.01, 0.05, 0.1, 1} at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-6   k_a in {8, 10, 15, 20} at belief rates 50 / 100 / 1000 Hz (0.5 m/s step)
  5-7   stability limits per belief rate: smallest stable tau, largest stable k_mu and k_a,
        each found by bisection (on a log scale) with the others at their C-1 values
  5-9   improved controller (config/thesis_improved_exact.yaml, --improved-config: tau = 0.001,
        belief loop 1 kHz, action 50 Hz, exact integrator, on the thesis-equivalent variances)
        against the stock controller, steps 0.3 / 0.5 / 1.0 m/s
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
  aic_reproduce.py [--doc] [--tables 3-1 5-1 ...] [--backend core|ros] [--out DIR] [--jobs N]
                   [--rows N] [--real-time-factor F] [--config FILE] [--improved-config FILE]
                   [--plant-config FILE]
--doc also writes the tables (the block DOC_BLOCK in --out) into doc/reproduction.md between the
lines DOC_BEGIN and DOC_END; test/test_reproduce.py fails when the page's block differs from a
fresh run's.
Exit: 0 when every run ran (unstable runs are results, not failures), 1 on a failed run.
"""
import csv
import os
import sys
import time

from .reproduce_runs import CoreBackend, RosBackend, Runner
from .reproduce_tables import ALL_TABLES, build, robot_tables

#: The page whose tables --doc writes, relative to the package's folder, and the lines around them.
DOC_PAGE = os.path.join("doc", "reproduction.md")
DOC_BEGIN = "<!-- The tables below are written by `aic_reproduce.py --doc`; do not edit them. -->"
DOC_END = "<!-- End of the tables written by `aic_reproduce.py --doc`. -->"
#: The file in --out that holds the block of the tables as --doc writes it.
DOC_BLOCK = "doc_tables.md"


def doc_block(markdowns):
    """The tables' block of doc/reproduction.md: DOC_BEGIN, each table's Markdown (Table.markdown())
    separated by blank lines, DOC_END; ends with a newline."""
    return DOC_BEGIN + "\n\n" + "\n".join(markdowns) + "\n" + DOC_END + "\n"


def page_block(text):
    """The tables' block of the page's ``text`` (from DOC_BEGIN to DOC_END and its newline).
    Raises ValueError when the page has no such block."""
    start, end = text.find(DOC_BEGIN), text.find(DOC_END)
    if start < 0 or end < start:
        raise ValueError("%s has no block between %r and %r" % (DOC_PAGE, DOC_BEGIN, DOC_END))
    return text[start:end + len(DOC_END)] + "\n"


def write_doc(root, block):
    """Replace the tables' block of <root>/DOC_PAGE by ``block`` (doc_block()). Raises ValueError
    (page_block) or OSError."""
    path = os.path.join(root, DOC_PAGE)
    with open(path) as f:
        text = f.read()
    old = page_block(text)
    with open(path, "w") as f:
        f.write(text.replace(old, block))


def zoomed_changes(t, set_point):
    """The set-point changes of a trace worth a zoom in a table's figure: the times [s] of ``t``
    where ``set_point`` (arrays of one length) changes; with more than figures.MAX_ZOOMS of them
    (a square wave), the second and the third: the first step up from the settled low level and
    the first step down."""
    from ..common import figures
    changes = [t[k] for k in range(1, len(t)) if set_point[k] != set_point[k - 1]]
    return changes if len(changes) <= figures.MAX_ZOOMS else changes[1:3]


def plot_table(table, runs, out_dir):
    """table_<id>.png and .pdf (figures.save) in ``out_dir``: the measured speed [m/s] of every run
    of ``runs`` ([(label, result)]) with a closed_loop_run trace, each its own colour and dash
    pattern (figures.style), and beside it the first second after the set-point changes of the
    first run's trace zoomed (zoomed_changes, figures.zoom); titled by ``table`` (wrapped), the
    legend outside. Returns the PNG's path."""
    from ..common import figures
    plt = figures.pyplot()
    traces = []
    for label, res in runs:
        trace = res.get("trace")
        if not trace or not os.path.exists(trace) or res.get("ros_csv"):
            continue
        cols = {"t": [], "v_odom": [], "set_point": []}
        with open(trace) as f:
            for row in csv.DictReader(f):
                for k in cols:
                    cols[k].append(float(row[k]))
        traces.append((label + ("" if res["status"] == "ok" else " (%s)" % res["status"]), cols))
    events = zoomed_changes(traces[0][1]["t"], traces[0][1]["set_point"]) if traces else []
    fig = plt.figure(figsize=(8.0 + 2.7 * len(events), 5.0))
    (ax,), (zooms,), _ = figures.grid(fig, 1, len(events))
    for i, (label, cols) in enumerate(traces):
        for a in [ax] + zooms:
            a.plot(cols["t"], cols["v_odom"], label=label, **figures.style(i))
    ax.set_xlim(-0.2, None)
    for a, t in zip(zooms, events):
        figures.zoom(a, t)
        a.set_xlabel("time [s]")
    ax.set_xlabel("time from the first step [s]")
    ax.set_ylabel("body speed, wheel odometry [m/s]")
    for a in [ax] + zooms:
        a.grid(True, alpha=0.3)
    figures.set_title(ax, "Table %s: %s" % (table.id, table.title), fontsize=10)
    figures.legend_outside(([ax] + zooms)[-1], *ax.get_legend_handles_labels())
    fig.tight_layout()
    return figures.save(fig, os.path.join(out_dir, "table_%s.png" % table.id))


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
    markdowns = []
    for tid in a.tables:
        t0 = time.time()
        t = build(tid, runner, robot, plots, a.bisections, max(0, a.rows))
        base = t.write(a.out)
        written.append(base)
        markdowns.append(t.markdown())
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
    block = doc_block(markdowns)
    with open(os.path.join(a.out, DOC_BLOCK), "w") as f:
        f.write(block)
    print("aic_reproduce: %d runs, %.0f s; tables in %s" % (len(runner.cache), time.time() - started, a.out))
    for k, reason in runner.failures:
        print("FAILED run %s: %s" % (k, reason), file=sys.stderr)
    if runner.failures:
        return 1
    if getattr(a, "doc", False):
        defaults = (os.path.abspath(a.config) == tool.path("config", "thesis_equivalent.yaml") and
                    os.path.abspath(a.improved_config) == tool.path("config", "thesis_improved_exact.yaml") and
                    a.plant_config is None)
        if list(a.tables) != ALL_TABLES or a.backend != "core" or a.rows or a.bisections != 6 or not defaults:
            print("aic_reproduce: --doc writes the page's tables only from every table of the core backend with "
                  "the default configurations, rows and bisections", file=sys.stderr)
            return 1
        write_doc(tool.root, block)
        print("aic_reproduce: wrote the tables into %s" % DOC_PAGE)
    return 0
