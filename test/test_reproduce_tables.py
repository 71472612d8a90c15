#!/usr/bin/env python3
"""Python unit test: aic_reproduce.py's tables and runs (jackal_aic_tools.reproduce.reproduce_tables,
reproduce_runs) and the shared table formatter (jackal_aic_tools.common.tables), on made-up run results
whose table is known; no simulator. Deterministic."""
import csv
import math
import os
import tempfile
import unittest

from jackal_aic_tools.common import figures, tables
from jackal_aic_tools.reproduce import reproduce_runs, reproduce_tables
from jackal_aic_tools.reproduce.reproduce_runs import Run


def result(status="ok", settling=None, rise=None, overshoot=None, segments=None):
    """A run's result as a backend gives it (one segment unless ``segments`` is given)."""
    if segments is None:
        segments = [{"t_step": 0.0, "initial": 0.0, "target": 0.5,
                     "measured": {"rise": rise, "settling": settling, "overshoot": overshoot,
                                  "settled": settling is not None}}]
    return {"status": status, "reason": "", "segments": segments}


class FakeRunner(object):
    """Answers each Run from ``answer(run)``; counts the runs asked for."""

    def __init__(self, answer):
        self.answer = answer
        self.asked = []

    def run_all(self, runs):
        self.asked += runs
        return [self.answer(r) for r in runs]

    def get(self, r):
        return self.run_all([r])[0]


ROBOT = {"3-1a": {(0.1, 50, 50): (1.0, 0.5), (0.5, 50, 50): (2.0, 0.4)},
         "3-1b": {(0.1, 50, 50): (0.8, 0.3)}}


def answer_3_1(r):
    if r.controller == "aic" and r.step == 0.1:
        return result(settling=1.2, rise=0.4)
    if r.controller == "aic" and r.step == 0.5:
        return result("slow", settling=None, rise=0.3)
    if r.controller == "stock" and r.step == 0.1:
        return result("unstable", settling=9.0, rise=9.0)
    return result(settling=0.9, rise=0.45)


class Table31Test(unittest.TestCase):

    def setUp(self):
        self.runner = FakeRunner(answer_3_1)
        self.plots = []
        self.table = reproduce_tables.table_3_1(self.runner, ROBOT, self.plots, rows=2)

    def test_rows(self):
        self.assertEqual(self.table.rows, [
            # step; (a) settling sim, robot, error, rise sim, robot, error; (b) the same
            ["0.1", "1.20", "1.00", "+20%", "0.40", "0.50", "-20%", "unst.", "0.80", "", "unst.", "0.30", ""],
            ["0.5", "n.s.", "2.00", "", "0.30", "0.40", "-25%", "0.90", "", "", "0.45", "", ""],
        ])

    def test_errors_against_the_robot(self):
        # |errors|: 0.2, 0.2 (AIC 0.1), 2 and 2 (stock unstable), 2 (AIC 0.5 unsettled), 0.25.
        self.assertEqual(len(self.table.errors), 6)
        self.assertAlmostEqual(sum(self.table.errors), 0.2 + 0.2 + 2.0 + 2.0 + 2.0 + 0.25)
        md = self.table.markdown()
        self.assertIn("Mean |error| against the robot: %.0f %% over 6 entries." % (100 * 6.65 / 6), md)

    def test_runs_and_plots(self):
        self.assertEqual(sorted((r.controller, r.step, tuple(sorted(r.params.items()))) for r in self.runner.asked),
                         [("aic", 0.1, (("action_rate", 50), ("belief_rate", 50))),
                          ("aic", 0.5, (("action_rate", 50), ("belief_rate", 50))),
                          ("stock", 0.1, ()), ("stock", 0.5, ())])
        (t, runs), = self.plots
        self.assertIs(t, self.table)
        self.assertEqual([label for label, _ in runs], ["AIC 0.1 m/s", "AIC 0.5 m/s", "stock 0.1 m/s", "stock 0.5 m/s"])

    def test_markdown_and_csv(self):
        md = self.table.markdown().splitlines()
        self.assertTrue(md[0].startswith("### Table 3-1: steps from rest"))
        self.assertEqual(md[3], "|" + "|".join(["---"] * 13) + "|")
        self.assertEqual(md[4], "| 0.1 | 1.20 | 1.00 | +20% | 0.40 | 0.50 | -20% | unst. | 0.80 |  | unst. | 0.30 |  |")
        with tempfile.TemporaryDirectory() as tmp:
            base = self.table.write(tmp)
            with open(base + ".csv") as f:
                rows = list(csv.reader(f))
            with open(base + ".md") as f:
                self.assertEqual(f.read(), self.table.markdown())
        self.assertEqual(rows[0][0], "step [m/s]")
        self.assertEqual(rows[1:], self.table.rows)


class OtherTablesTest(unittest.TestCase):

    def test_rates_table_runs_each_rate(self):
        def answer(r):
            rate = r.params["belief_rate"]
            return result(settling=1.0 / rate * 100, rise=0.1)
        runner = FakeRunner(answer)
        robot = {"5-2": {(0.3, 100, 50): (2.0, 0.2)}}
        t = reproduce_tables.table_rates(runner, robot, [], "5-2", False, rows=1)
        self.assertEqual(t.rows, [["0.3", "2.00", "", "", "0.10", "", "", "1.00", "2.00", "-50%", "0.10", "0.20",
                                   "-50%", "0.10", "", "", "0.10", "", ""]])
        self.assertEqual(sorted(r.params["action_rate"] for r in runner.asked), [50, 50, 50])
        t = reproduce_tables.table_rates(FakeRunner(answer), {}, [], "5-1", True, rows=1)
        self.assertEqual(t.headers[1], "50 Hz settling sim [s]")

    def test_sweep_table(self):
        def answer(r):
            return result("unstable") if r.params["k_a"] > 12 else result(settling=r.params["k_a"] / 10.0, rise=0.2)
        t = reproduce_tables.table_sweep(FakeRunner(answer), [], "5-6", "k_a", [8.0, 15.0], "k_a")
        self.assertEqual(t.rows, [["8", "0.80", "0.20", "0.80", "0.20", "0.80", "0.20"],
                                  ["15", "unst.", "unst.", "unst.", "unst.", "unst.", "unst."]])

    def test_improved_against_stock(self):
        def answer(r):
            if r.controller == "stock":
                return result(settling=1.0, rise=0.5, overshoot=0.0)
            return result(settling=0.6, rise=0.2, overshoot=2.5)
        t = reproduce_tables.table_5_9(FakeRunner(answer), [], rows=1)
        self.assertEqual(t.rows, [["0.3", "0.60", "0.20", "2.5", "1.00", "0.50", "0.0", "0.40"]])

    def test_square_waves_take_the_worst_transition(self):
        def seg(initial, target, rise, settling, overshoot):
            return {"t_step": 0.0, "initial": initial, "target": target,
                    "measured": {"rise": rise, "settling": settling, "overshoot": overshoot}}
        segments = [seg(0.0, 0.5, 9.0, 9.0, 99.0),  # the lead-in from rest: not counted
                    seg(0.5, 0.1, 0.3, 0.6, 1.0), seg(0.1, 0.5, 0.2, 0.5, 4.0),
                    seg(0.5, 0.1, 0.4, 0.7, 2.0), seg(0.1, 0.5, 0.25, 0.4, 3.0)]

        def answer(r):
            if r.controller == "stock":
                return result("slow", segments=[seg(0.0, 0.5, 1, 1, 1), seg(0.5, 0.1, 0.3, None, 1.0)])
            return result(segments=segments)
        t = reproduce_tables.table_5_10(FakeRunner(answer), [], rows=1)
        self.assertEqual(t.rows, [["0.1 <-> 0.5", "improved", "0.25", "0.50", "4.0", "0.40", "0.70", "2.0"],
                                  ["0.1 <-> 0.5", "stock", "n.s.", "n.s.", "n.s.", "0.30", "n.s.", "1.0"]])

    def test_stability_limit_by_bisection(self):
        def answer(r):
            return result(settling=1.0, rise=0.1) if r.params["k_a"] <= 2.0 else result("unstable")
        limit, bracket = reproduce_tables.bisect_limit(FakeRunner(answer), "k_a", 50, 1.0, 1000.0, False, 6)
        lo, hi = 1.0, 1000.0
        for _ in range(6):
            mid = math.sqrt(lo * hi)
            lo, hi = (mid, hi) if mid <= 2.0 else (lo, mid)
        self.assertAlmostEqual(limit, lo)
        self.assertEqual(bracket, "between %.3g and %.3g" % (lo, hi))
        self.assertTrue(1.0 < limit <= 2.0 < hi)

        def tau_answer(r):  # tau: the smallest stable value is the limit
            return result(settling=1.0, rise=0.1) if r.params["tau"] >= 0.01 else result("unstable")
        limit, _ = reproduce_tables.bisect_limit(FakeRunner(tau_answer), "tau", 50, 1e-4, 0.1, True, 8)
        self.assertTrue(0.01 <= limit < 0.012, limit)
        limit, bracket = reproduce_tables.bisect_limit(FakeRunner(answer), "k_a", 50, 1.0, 1.5, False, 6)
        self.assertEqual((limit, bracket), (1.5, "stable over the whole range"))
        self.assertEqual(reproduce_tables.bisect_limit(FakeRunner(answer), "k_a", 50, 3.0, 9.0, False, 6),
                         (None, "unstable at 3"))

    def test_cells(self):
        self.assertEqual(reproduce_tables.cell(0.123), "0.12")
        self.assertEqual(reproduce_tables.cell(None, res=result("slow")), "n.s.")
        self.assertEqual(reproduce_tables.cell(None, res=result("unstable")), "unst.")
        self.assertEqual(reproduce_tables.cell(None, res=result("ok")), "-")
        self.assertEqual(reproduce_tables.err(1.1, 1.0), "+10%")
        self.assertEqual(reproduce_tables.err(None, 1.0), "")
        self.assertIsNone(reproduce_tables.metric(result("unstable", settling=1.0), "settling"))
        self.assertIsNone(reproduce_tables.metric(result("ok", settling=float("nan")), "settling"))
        self.assertEqual(reproduce_tables.metric(result("slow", rise=0.3), "rise"), 0.3)


class RunsTest(unittest.TestCase):

    def test_verdict(self):
        settled = [{"target": 0.5, "measured": {"settled": True}}]
        self.assertEqual(reproduce_runs.verdict(1, 0.5, settled), ("unstable", "runaway"))
        self.assertEqual(reproduce_runs.verdict(0, 3.5, settled), ("unstable", "speed beyond 3 m/s"))
        self.assertEqual(reproduce_runs.verdict(0, 0.5, settled, "oscillation: x"), ("unstable", "oscillation: x"))
        self.assertEqual(reproduce_runs.verdict(0, 0.5, [{"target": 0.5, "measured": {"settled": False}}]),
                         ("slow", "not settled at 0.5 m/s"))
        self.assertEqual(reproduce_runs.verdict(0, 0.5, settled), ("ok", ""))

    def test_oscillation_in_a_trace(self):
        segs = [{"t_step": 0.0, "initial": 0.0, "target": 0.5}]
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "trace.csv")
            with open(path, "w") as f:
                f.write("t,v_odom,command\n")
                for k in range(301):  # 3 s: a 0.4 m/s swing around 0.5 m/s, period 0.5 s
                    t = k * 0.01
                    f.write("%g,%g,%g\n" % (t, 0.5 + 0.4 * math.sin(2 * math.pi * t / 0.5), 0.5))
            self.assertIn("oscillation: measured velocity spans", reproduce_runs.trace_oscillation(path, segs))
            with open(path, "w") as f:
                f.write("t,v_odom,command\n" + "".join("%g,0.5,0.5\n" % (k * 0.01) for k in range(301)))
            self.assertIsNone(reproduce_runs.trace_oscillation(path, segs))

    def test_runner_runs_each_run_once(self):
        class Backend(object):
            calls = []

            def run(self, r, trace_path=None):
                self.calls.append((r.name(), os.path.basename(trace_path)))
                return result("failed" if r.controller == "stock" else "ok", settling=1.0)
        runner = reproduce_runs.Runner(Backend(), 2, "/nonexistent")
        a, b = Run("aic", 0.5, params={"tau": 0.01}), Run("aic", 0.5, params={"tau": 0.01})
        out = runner.run_all([a, b, Run("stock", 0.5, params={"tau": 1})])
        self.assertEqual([o["status"] for o in out], ["ok", "ok", "failed"])
        self.assertEqual(runner.get(a)["status"], "ok")
        self.assertEqual(sorted(Backend.calls), [("aic_v0.5_tau0.01", "aic_v0.5_tau0.01.csv"),
                                                 ("stock_v0.5", "stock_v0.5.csv")])
        self.assertEqual(len(runner.failures), 1)
        self.assertEqual(Run("aic", square=(0.1, 0.5), params={"integrator": "exact"}).name(),
                         "aic_sq0.1-0.5_integratorexact")


class FormatterTest(unittest.TestCase):

    def test_fmt(self):
        self.assertEqual(tables.fmt(0.12345), "0.123")
        self.assertEqual(tables.fmt(2.0, "%.1f"), "2.0")
        self.assertEqual(tables.fmt(None), "-")
        self.assertEqual(tables.fmt(float("nan")), "-")
        self.assertEqual(tables.fmt(3, "%d"), "3")
        self.assertEqual(tables.fmt_value([2.0, 1e5]), "[2,100000]")
        self.assertEqual(tables.fmt_value(50), "50")

    def test_text_tables(self):
        rows = [["a", "1"], ["bbb", ""]]
        self.assertEqual(tables.text_table(["x", "yy"], rows), "x    yy\na    1\nbbb")
        self.assertEqual(tables.text_table(["x", "yy"], rows, rule=True, rstrip=False),
                         "x    yy\n---  --\na    1 \nbbb    ")
        self.assertEqual(tables.text_table(["x"], [], indent="  "), "  x")
        self.assertEqual(tables.md_table(["x", "y"], [[1, ""]]), "| x | y |\n|---|---|\n| 1 |  |")


class PlotTableTest(unittest.TestCase):
    """reproduce.plot_table on made-up traces: twelve runs get twelve distinct (colour, dash)
    styles, the figure is written as PNG and PDF, and the zoom sits on the step (on a square
    wave, on its first step up and down)."""

    def test_zoomed_changes(self):
        from jackal_aic_tools.reproduce import reproduce
        t = [0.01 * k for k in range(1000)]
        self.assertEqual(reproduce.zoomed_changes(t, [0.0 if x < 1.0 else 0.5 for x in t]), [t[100]])
        square = [0.0 if x < 0.5 else 0.1 if x < 2.5 or 4.5 <= x < 6.5 else 0.5 for x in t]
        self.assertEqual(reproduce.zoomed_changes(t, square), [t[250], t[450]])
        self.assertEqual(reproduce.zoomed_changes(t, [0.0] * len(t)), [])

    def test_twelve_runs(self):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from jackal_aic_tools.reproduce import reproduce
        seen = {}
        real_savefig = plt.Figure.savefig

        def keep(fig, path, **kw):
            seen[os.path.basename(path)] = [[(ln.get_label(), ln.get_color()) for ln in a.get_lines()]
                                            for a in fig.axes]
            return real_savefig(fig, path, **kw)
        plt.Figure.savefig = keep
        try:
            with tempfile.TemporaryDirectory() as tmp:
                runs = []
                for k in range(12):
                    trace = os.path.join(tmp, "run%d.csv" % k)
                    with open(trace, "w") as f:
                        f.write("t,v_odom,set_point\n")
                        for i in range(-20, 300):
                            t = 0.01 * i
                            f.write("%g,%g,%g\n" % (t, 0.5 * (1 - math.exp(-t / (0.1 + 0.02 * k))) if t > 0 else 0.0,
                                                    0.5 if t >= 0 else 0.0))
                    runs.append(("run %d" % k, {"trace": trace, "status": "ok"}))
                table = reproduce_tables.Table("5-5", "a long title " * 12, ["a"])
                path = reproduce.plot_table(table, runs, tmp)
                self.assertEqual(path, os.path.join(tmp, "table_5-5.png"))
                self.assertGreater(os.path.getsize(path), 1000)
                self.assertGreater(os.path.getsize(os.path.join(tmp, "table_5-5.pdf")), 1000)
        finally:
            plt.Figure.savefig = real_savefig
        main, zoom = seen["table_5-5.png"]
        # run k in figures.style(k): no two of the twelve alike in both colour and dashes
        self.assertEqual(main, [("run %d" % k, figures.style(k)["color"]) for k in range(12)])
        self.assertEqual(len({(st["color"], repr(st["ls"])) for st in figures.styles(12)}), 12)
        self.assertEqual(main, zoom)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("reproduce_tables", Table31Test, OtherTablesTest, RunsTest, FormatterTest, PlotTableTest)
