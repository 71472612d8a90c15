#!/usr/bin/env python3
"""rostest node: config/default.yaml meets the tuning acceptance set on the plant core.

Runs scripts/aic_scorecard.py (closed_loop_run: the AIC and the stock controller on the
simulated Jackal's plant core, headless, seeded sensor noise, so the figures are the same on
every machine) on ~aic_config (default: config/default.yaml), on the plant with the overlay ~plant_overlay (a
path relative to the package; default none), and checks its verdict: every
criterion passes (0.5 m/s step: settling <= 0.8 x and rise <= 0.7 x the stock controller's,
overshoot <= 5 %, steady-state error <= 1 %, for every noise seed; the 1 rad/s turn settles no
later than the stock's; every square-wave transition overshoots <= 10 %; stable with the
plant's latency and torque +-20 %). A failure names the failing rows. doc/experiments.md,
'Tuning', has the figures.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import rospy
import rostest

PKG = "jackal_aic"
ROOT = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "..")
SCRIPT = os.path.join(ROOT, "scripts", "aic_scorecard.py")


def failing_rows(report):
    """'criterion: row' strings of every row whose verdict is False in a scorecard JSON report."""
    out = []
    for name, rows in report.get("criteria", {}).items():
        for row in rows if isinstance(rows, list) else [rows]:
            if isinstance(row, dict) and row.get("pass") is False:
                out.append("%s: %s" % (name, json.dumps(row, sort_keys=True)))
    return out


class ScorecardCheck(unittest.TestCase):

    def test_default_config_meets_the_acceptance_set(self):
        config = rospy.get_param("~aic_config", os.path.join(ROOT, "config", "default.yaml"))
        overlay = rospy.get_param("~plant_overlay", "")
        overlay_args = ["--plant-overlay", os.path.join(ROOT, overlay)] if overlay else []
        with tempfile.TemporaryDirectory(prefix="scorecard_") as tmp:
            report_path = os.path.join(tmp, "score.json")
            proc = subprocess.run([sys.executable, SCRIPT, "--aic-config", config, "--jobs", "2",
                                   "--json", report_path] + overlay_args, capture_output=True, text=True, timeout=300)
            rospy.loginfo("%s", proc.stdout)
            self.assertIn(proc.returncode, (0, 1), "aic_scorecard.py failed to run (exit %d):\n%s%s"
                          % (proc.returncode, proc.stdout[-2000:], proc.stderr[-2000:]))
            with open(report_path) as f:
                report = json.load(f)
        failing = failing_rows(report)
        self.assertTrue(report["pass"], "criteria not met by %s:\n  %s" % (config, "\n  ".join(failing)))
        self.assertEqual(proc.returncode, 0)
        self.assertEqual(failing, [])
        # Guard against a vacuous pass: the report must hold the judged rows.
        self.assertTrue(any(row.get("pass") is True for rows in report["criteria"].values()
                            for row in (rows if isinstance(rows, list) else [rows]) if isinstance(row, dict)))


if __name__ == "__main__":
    rospy.init_node("scorecard_check")
    rostest.rosrun(PKG, "scorecard_check", ScorecardCheck, sys.argv)
