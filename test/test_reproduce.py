#!/usr/bin/env python3
"""Python unit test: aic_reproduce.py on the first two rows of thesis table 3-1 (0.1 and 0.5 m/s
steps; the thesis-equivalent AIC at 50 Hz and the stock controller) with the core backend
(closed_loop_run: the node's logic on the plant core, headless, deterministic). Checks: the
table is written (Markdown, CSV) with the robot's numbers beside; every run is stable; the
simulated rise and settling times are within the identification's acceptance of the robot's
(stock +-50 % at 0.1 m/s, +-20 % at 0.5 m/s; AIC +-40 % per entry, looser than the 25 % table
mean).

And the published tables cannot go stale: every table on the core backend (deterministic: ideal
sensors, simulated time), and its block of tables must equal doc/reproduction.md's, the block
`aic_reproduce.py --doc` writes there."""
import csv
import difflib
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "scripts", "aic_reproduce.py")
ROWS = 2
AIC_TOLERANCE = 0.4  # relative, simulation against the robot per entry


def read_table(path):
    with open(path) as f:
        return list(csv.reader(f))


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "src"))
from jackal_aic_tools.reproduce import reproduce  # noqa: E402


def stale_diff(page_text, fresh_block):
    """The unified diff of the page's block of tables against a fresh run's, "" when equal."""
    old = reproduce.page_block(page_text)
    return "".join(difflib.unified_diff(old.splitlines(True), fresh_block.splitlines(True),
                                        reproduce.DOC_PAGE, "a fresh run"))


class PublishedTablesAreFresh(unittest.TestCase):
    def test_the_page_holds_a_fresh_runs_tables(self):
        root = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
        with tempfile.TemporaryDirectory() as out:
            proc = subprocess.run([sys.executable, SCRIPT, "--out", out, "--no-plot"], capture_output=True,
                                  text=True, timeout=600)
            self.assertEqual(proc.returncode, 0, (proc.stdout + proc.stderr)[-2000:])
            with open(os.path.join(out, reproduce.DOC_BLOCK)) as f:
                fresh = f.read()
        with open(os.path.join(root, reproduce.DOC_PAGE)) as f:
            diff = stale_diff(f.read(), fresh)
        self.assertEqual(diff, "", "%s's tables differ from a fresh run (regenerate them: scripts/aic_reproduce.py "
                                   "--doc, then check the page's text against them):\n%s"
                         % (reproduce.DOC_PAGE, diff[:6000]))

    def test_a_changed_figure_is_caught(self):
        # The control: one figure changed in a page's block is a difference.
        block = reproduce.doc_block(["### Table 1\n\n| a |\n|---|\n| 0.42 |\n"])
        page = "intro\n" + block + "outro\n"
        self.assertEqual(stale_diff(page, block), "")
        self.assertIn("+| 0.65 |", stale_diff(page, block.replace("0.42", "0.65")))
        with self.assertRaises(ValueError):
            reproduce.page_block("no block here")


class ReproduceSubset(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.rows = ROWS
        cls.aic_tol = AIC_TOLERANCE
        cls.tables = {}
        cls.logs = {}
        for backend in ("core",):
            out = tempfile.mkdtemp(prefix="reproduce_%s_" % backend)
            proc = subprocess.run([sys.executable, SCRIPT, "--tables", "3-1", "--rows", str(cls.rows),
                                   "--backend", backend, "--out", out, "--no-plot"],
                                  capture_output=True, text=True, timeout=360)
            cls.logs[backend] = proc.stdout + proc.stderr
            cls.tables[backend] = (proc.returncode, os.path.join(out, "table_3-1.csv"),
                                   os.path.join(out, "table_3-1.md"))

    def check_backend(self, backend):
        rc, csv_path, md_path = self.tables[backend]
        self.assertEqual(rc, 0, "%s backend failed:\n%s" % (backend, self.logs[backend][-2000:]))
        self.assertTrue(os.path.exists(md_path))
        rows = read_table(csv_path)
        self.assertEqual(rows[0][0], "step [m/s]")
        self.assertEqual(len(rows) - 1, self.rows)
        return rows[1:]

    def test_core_backend(self):
        self.check_against_robot(self.check_backend("core"))

    def check_against_robot(self, rows):
        for r in rows:
            step = float(r[0])
            # Columns: step, (a) settling sim, robot, error, (a) rise sim, robot, error, (b) ... the same.
            for sim_i, label, tol in ((1, "AIC settling", self.aic_tol), (4, "AIC rise", self.aic_tol),
                                      (7, "stock settling", 0.5 if step < 0.3 else 0.2),
                                      (10, "stock rise", 0.5 if step < 0.3 else 0.2)):
                sim, robot = number(r[sim_i]), number(r[sim_i + 1])
                self.assertIsNotNone(sim, "%s at %g m/s: %r (unstable?)" % (label, step, r[sim_i]))
                self.assertIsNotNone(robot, "%s at %g m/s: no robot value" % (label, step))
                self.assertLessEqual(abs(sim - robot) / robot, tol,
                                     "%s at %g m/s: sim %.3f s, robot %.3f s" % (label, step, sim, robot))


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("reproduce", ReproduceSubset, PublishedTablesAreFresh)
