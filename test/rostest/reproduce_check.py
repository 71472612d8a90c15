#!/usr/bin/env python3
"""Test node of reproduce_subset.test: aic_reproduce.py, table 3-1, first rows, both backends."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

import rospy
import rostest

PKG = "jackal_aic"
SCRIPT = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..", "scripts", "aic_reproduce.py")


def read_table(path):
    with open(path) as f:
        return list(csv.reader(f))


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


class ReproduceSubset(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node("reproduce_check", anonymous=True)
        cls.rows = int(rospy.get_param("~rows", 2))
        cls.backend_tol = float(rospy.get_param("~backend_tolerance", 0.2))
        cls.aic_tol = float(rospy.get_param("~aic_tolerance", 0.4))
        cls.tables = {}
        cls.logs = {}
        for backend in ("core", "ros"):
            out = tempfile.mkdtemp(prefix="reproduce_%s_" % backend)
            # The ROS backend starts its own masters: keep this test's master out of its environment.
            env = dict(os.environ)
            proc = subprocess.run([sys.executable, SCRIPT, "--tables", "3-1", "--rows", str(cls.rows),
                                   "--backend", backend, "--out", out, "--no-plot"],
                                  capture_output=True, text=True, env=env, timeout=360)
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

    def test_ros_backend(self):
        self.check_against_robot(self.check_backend("ros"))

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

    def test_backends_agree(self):
        core = self.check_backend("core")
        ros = self.check_backend("ros")
        for rc, rr in zip(core, ros):
            for i in (1, 4, 7, 10):
                c, r = number(rc[i]), number(rr[i])
                self.assertIsNotNone(c)
                self.assertIsNotNone(r)
                # Absolute floor 0.03 s: the 0.1 m/s stock rise is two 50 Hz samples.
                self.assertLessEqual(abs(c - r), max(self.backend_tol * c, 0.03),
                                     "step %s column %d: core %.3f s, ros %.3f s" % (rc[0], i, c, r))


if __name__ == "__main__":
    rostest.rosrun(PKG, "reproduce_subset", ReproduceSubset)
