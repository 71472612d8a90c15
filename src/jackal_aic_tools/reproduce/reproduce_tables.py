"""The tables of aic_reproduce.py: thesis tables 3-1, 5-1 ... 5-10 in the thesis's layout, built
from the results of a Runner (jackal_aic_tools.reproduce.reproduce_runs), with the robot's figures beside
where sim/config/robot_steps.yaml has them."""
import csv
import math
import os

import yaml

from ..common.tables import fmt_value, md_table
from .reproduce_runs import IMPROVED, SQUARE_PERIOD, Run

ALL_TABLES = ["3-1", "5-1", "5-2", "5-4", "5-5", "5-6", "5-7", "5-9", "5-10"]
RATES = [50, 100, 1000]
SQUARES = [(0.1, 0.5), (0.1, 1.0), (0.2, 1.2)]


def lim(values, rows):
    """The first ``rows`` entries of a table's row values (all when rows is 0)."""
    return values[:rows] if rows > 0 else values


def metric(res, name, seg=0):
    """A measured-speed metric of segment seg, or None (unstable, or undefined: a slow run's
    settling time)."""
    if res["status"] not in ("ok", "slow") or len(res["segments"]) <= seg:
        return None
    v = (res["segments"][seg].get("measured") or {}).get(name)
    return v if v is not None and math.isfinite(v) else None


def robot_tables(path):
    """The robot's figures of sim/config/robot_steps.yaml (``path``): table id -> {(step [m/s],
    belief rate [Hz], action rate [Hz]): (settling [s], rise [s])}."""
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
    """The relative error of a simulated figure against the robot's, "+12%"; "" when either is
    missing."""
    if sim is None or robot is None:
        return ""
    return "%+.0f%%" % (100.0 * (sim - robot) / robot)


class Table(object):
    """One table of the reproduction: id ("3-1"), title, column headers, rows (lists of strings),
    a note under it, and the |relative errors| of its entries against the robot (``errors``)."""

    def __init__(self, tid, title, headers, note=""):
        self.id = tid
        self.title = title
        self.headers = headers
        self.rows = []
        self.note = note
        self.errors = []  # |relative errors| against the robot

    def add(self, row):
        """Append a row (its cells as strings)."""
        self.rows.append([str(c) for c in row])

    def markdown(self):
        """The table as Markdown: a "### Table" title, the table, the mean |error| against the
        robot (when there are errors) and the note."""
        lines = ["### Table %s: %s" % (self.id, self.title), "", md_table(self.headers, self.rows)]
        if self.errors:
            lines.append("")
            lines.append("Mean |error| against the robot: %.0f %% over %d entries."
                         % (100.0 * sum(self.errors) / len(self.errors), len(self.errors)))
        if self.note:
            lines += ["", self.note]
        return "\n".join(lines) + "\n"

    def write(self, out_dir):
        """Write table_<id>.md and table_<id>.csv into ``out_dir``; returns their path without the
        extension."""
        base = os.path.join(out_dir, "table_" + self.id)
        with open(base + ".md", "w") as f:
            f.write(self.markdown())
        with open(base + ".csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(self.headers)
            w.writerows(self.rows)
        return base


def step_pair(tables_robot, tid, key, res):
    """Settling, rise cells (sim, robot, error) of the result ``res`` for the row ``key`` of the
    robot's table ``tid`` (tables_robot: robot_tables()), and the entries' |relative errors| (2 for
    a missing simulated figure); no robot cells or errors when the robot has no such row."""
    s, r = metric(res, "settling"), metric(res, "rise")
    robot = tables_robot.get(tid, {}).get(key)
    cells = [cell(s, res=res), cell(robot[0]) if robot else "", err(s, robot[0] if robot else None),
             cell(r, res=res), cell(robot[1]) if robot else "", err(r, robot[1] if robot else None)]
    errs = []
    if robot:
        for sim_v, rob_v in ((s, robot[0]), (r, robot[1])):
            errs.append(abs((sim_v - rob_v) / rob_v) if sim_v is not None else 2.0)
    return cells, errs


def table_3_1(runner, robot, plots, rows=0):
    """Table 3-1: steps from rest, (a) the thesis-equivalent AIC at 50 Hz, (b) the stock
    controller, against the robot. runner: Runner (or any run_all/get of Run); robot:
    robot_tables(); plots: list to which (table, [(label, result)]) is appended; rows: only the
    first rows (0 = all). Returns the Table."""
    t = Table("3-1", "steps from rest: (a) basic AIC, table C-1 values (thesis-equivalent), 50 Hz; "
                     "(b) stock controller",
              ["step [m/s]", "(a) settling sim [s]", "robot", "error", "(a) rise sim [s]", "robot", "error",
               "(b) settling sim [s]", "robot", "error", "(b) rise sim [s]", "robot", "error"])
    steps = lim([0.1, 0.5, 1.0], rows)
    aic = [Run("aic", v, params={"belief_rate": 50, "action_rate": 50}) for v in steps]
    stock = [Run("stock", v) for v in steps]
    ra, rs = runner.run_all(aic), runner.run_all(stock)
    for v, a_res, s_res in zip(steps, ra, rs):
        ca, ea = step_pair(robot, "3-1a", (v, 50, 50), a_res)
        cs, es = step_pair(robot, "3-1b", (v, 50, 50), s_res)
        t.add(["%.1f" % v] + ca + cs)
        t.errors += ea + es
    plots.append((t, [("AIC %g m/s" % v, r) for v, r in zip(steps, ra)] +
                  [("stock %g m/s" % v, r) for v, r in zip(steps, rs)]))
    return t


def table_rates(runner, robot, plots, tid, action_follows, rows=0):
    """Tables 5-1 (action_follows: both loops at the belief rate) and 5-2 (action 50 Hz): steps
    at belief rates RATES against the robot (arguments as table_3_1; tid "5-1" or "5-2")."""
    title = ("whole controller (belief and action loops) at 50 / 100 / 1000 Hz" if action_follows else
             "belief loop at 50 / 100 / 1000 Hz, action loop 50 Hz")
    headers = ["step [m/s]"]
    for rate in RATES:
        headers += ["%d Hz settling sim [s]" % rate, "robot", "error", "%d Hz rise sim [s]" % rate, "robot", "error"]
    t = Table(tid, title + " (thesis-equivalent controller)", headers)
    runs_plot = []
    for v in lim([0.3, 0.5, 1.0], rows):
        row = ["%.1f" % v]
        for rate in RATES:
            act = rate if action_follows else 50
            res = runner.get(Run("aic", v, params={"belief_rate": rate, "action_rate": act}))
            c, e = step_pair(robot, tid, (v, rate, act), res)
            row += c
            t.errors += e
            runs_plot.append(("%g m/s, %d Hz" % (v, rate), res))
        t.add(row)
    plots.append((t, runs_plot))
    return t


def table_sweep(runner, plots, tid, param, values, symbol, rows=0):
    """Tables 5-4 ... 5-6: a sweep of ``param`` over ``values`` (rows; ``symbol`` heads them) at
    belief rates RATES, action 50 Hz, 0.5 m/s step (runner, plots, rows as table_3_1)."""
    headers = [symbol]
    for rate in RATES:
        headers += ["%d Hz settling [s]" % rate, "%d Hz rise [s]" % rate]
    t = Table(tid, "%s sweep at belief rates 50 / 100 / 1000 Hz, action 50 Hz, 0.5 m/s step "
                   "(others at C-1 values; \"unst.\" = unstable, \"n.s.\" = not settled in 3 s)" % symbol, headers)
    runs_plot = []
    for val in lim(values, rows):
        row = [fmt_value(val)]
        for rate in RATES:
            res = runner.get(Run("aic", 0.5, params={param: val, "belief_rate": rate, "action_rate": 50}))
            row += [cell(metric(res, "settling"), res=res), cell(metric(res, "rise"), res=res)]
            runs_plot.append(("%s=%s, %d Hz" % (param, fmt_value(val), rate), res))
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


def table_5_7(runner, bisections, rows=0):
    """Table 5-7: per belief rate, the smallest stable tau and the largest stable k_mu and k_a
    (bisect_limit with ``bisections`` steps; runner, rows as table_3_1)."""
    t = Table("5-7", "stability limits of the thesis-equivalent controller per belief rate (action 50 Hz, "
                     "0.5 m/s step; bisection on a log scale, %d steps)" % bisections,
              ["belief rate [Hz]", "smallest stable tau [s]", "bracket", "largest stable k_mu", "bracket",
               "largest stable k_a", "bracket"])
    for rate in lim(RATES, rows):
        row = [str(rate)]
        for param, lo, hi, lower in (("tau", 1e-4, 0.1, True), ("k_mu", 1e-3, 100.0, False),
                                     ("k_a", 1.0, 1000.0, False)):
            limit, bracket = bisect_limit(runner, param, rate, lo, hi, lower, bisections)
            row += [cell(limit, "%.3g") if limit is not None else "none", bracket]
        t.add(row)
    return t


def table_5_9(runner, plots, rows=0):
    """Table 5-9: the improved controller (IMPROVED: config/thesis_improved_exact.yaml) against the
    stock controller, steps 0.3 / 0.5 / 1.0 m/s (runner, plots, rows as table_3_1)."""
    t = Table("5-9", "improved controller (tau = 0.001, belief 1 kHz, action 50 Hz, exact integrator, "
                     "thesis-equivalent variances) against the stock controller",
              ["step [m/s]", "improved settling [s]", "improved rise [s]", "improved overshoot [%]",
               "stock settling [s]", "stock rise [s]", "stock overshoot [%]", "rise improved / stock"])
    runs_plot = []
    for v in lim([0.3, 0.5, 1.0], rows):
        ri = runner.get(Run("aic", v, config=IMPROVED))
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


def table_5_10(runner, plots, rows=0):
    """Table 5-10: square waves SQUARES, the improved and the stock controller, the worst of the
    transitions up and down (runner, plots, rows as table_3_1)."""
    t = Table("5-10", "square waves, period %g s: improved controller and stock controller "
                      "(worst of the transitions up / down)" % SQUARE_PERIOD,
              ["wave [m/s]", "controller", "up: rise [s]", "up: settling [s]", "up: overshoot [%]",
               "down: rise [s]", "down: settling [s]", "down: overshoot [%]"])
    runs_plot = []
    for low, high in lim(SQUARES, rows):
        for name, r in (("improved", Run("aic", square=(low, high), config=IMPROVED)),
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


def build(tid, runner, robot, plots, bisections, rows=0):
    """The table ``tid`` (one of ALL_TABLES): runner, robot, plots, rows as table_3_1, bisections
    the steps of table 5-7's bisections. Returns the Table."""
    if tid == "3-1":
        return table_3_1(runner, robot, plots, rows)
    if tid in ("5-1", "5-2"):
        return table_rates(runner, robot, plots, tid, tid == "5-1", rows)
    if tid == "5-4":
        return table_sweep(runner, plots, tid, "tau", [0.03, 0.01, 0.001], "tau [s]", rows)
    if tid == "5-5":
        return table_sweep(runner, plots, tid, "k_mu", [0.01, 0.05, 0.1, 1.0], "k_mu", rows)
    if tid == "5-6":
        return table_sweep(runner, plots, tid, "k_a", [8.0, 10.0, 15.0, 20.0], "k_a", rows)
    if tid == "5-7":
        return table_5_7(runner, bisections, rows)
    if tid == "5-9":
        return table_5_9(runner, plots, rows)
    return table_5_10(runner, plots, rows)
