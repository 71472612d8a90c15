#!/usr/bin/env python3
"""Python unit test: config/default.yaml on the tuning scorecard, the acceptance set apart from
the regression guards.

Runs scripts/aic_scorecard.py --driving once (closed_loop_run: the AIC and the stock controller
on the simulated Jackal's plant core through the node's logic, headless, seeded sensor noise, so
the figures are the same on every machine) on config/default.yaml and the default plant.

Acceptance (ScorecardAcceptance), each row against the bound doc/experiments.md states (the
scorecard's verdicts, whose bounds are jackal_aic_tools.track.driving's and scorecard's constants):
- every straight-step criterion (0.5 m/s step: settling <= 0.8 x and rise <= 0.7 x the stock
  controller's, overshoot <= 5 %, steady-state error <= 1 %, for every noise seed; the 1 rad/s
  turn settles no later than the stock's; every square-wave transition overshoots <= 10 %;
  stable with the plant's latency and torque +-20 %);
- of the driving set ('Driving acceptance'): the 0.1 and 0.5 m/s steps, the 1 rad/s turn in
  place and the arc's two channels within their settling-ratio bounds (yaw rates on the gyro), every step's overshoot <= 5 % but the arc's yaw,
  the arc's yaw overshoot <= 5 % when the model starts from the plant's effective wheel separation (table 6i),
  stability on every varied plant, the turn-deficit holds (0.3, 0.5, 1.0 rad/s) within 2 % of the
  command;
  the tracking benchmark holds every profile x variant pair, each with the ideal controller's
  and the classical peer's figures, and every plant-limited channel (ideal controller above
  plant_limits.PLANT_LIMIT_RATIO x the latency floor) carries its reason.

Regression guards (ScorecardRegressionGuards): the documented driving bounds config/default.yaml
does not meet today on the turning plant (the arc's yaw overshoot on the gyro, <= 5 %, where the
stock controller overshoots too; the tracking pairs' geometric mean AIC / stock, <= 0.6; AIC /
latency floor, geometric mean <= 1.20; all over the plant-following channels only, as the
scorecard judges them). The tracking pairs' AIC / stock, <= 1.02 each, is met and is acceptance
(test_every_plant_following_pair_is_within_its_bound). Each guard fails when the figure gets worse than
today's plus a margin; its output names today's figure, the guard and the documented bound. A
guard is not acceptance: when the default meets the documented bound, the row moves to the
acceptance test.
"""
import glob
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.realpath(__file__)), "..")
SCRIPT = os.path.join(ROOT, "scripts", "aic_scorecard.py")
sys.path.insert(0, os.path.join(ROOT, "src"))
from jackal_aic_tools.track import driving, plant_limits  # noqa: E402

#: Regression guards: (what, today's figure, the guard, the documented bound). Today's figures are
#: doc/results/scorecard.txt's (6a, 6b, 6d, 6e, 6g, 6h).
GUARD_GMEAN = ("tracking, geometric mean AIC / stock (plant-following channels)", 0.731, 0.77,
               driving.TRACK_GMEAN_BOUND)
#: AIC / latency floor (table 6e) over the plant-following channels; the bound 1.20 removes three
#: quarters of the error a controller acting through the plant's latency could avoid.
GUARD_FLOOR = ("tracking, geometric mean AIC / latency floor (plant-following channels)", 1.367, 1.41, 1.20)
GUARD_ARC_OVERSHOOT = ("arc, yaw overshoot [%]", 6.3, 7.0, driving.STEP_OVERSHOOT)
#: Tracking runs whose steady |belief - truth| is above its bound (table 6g; driving.BELIEF_BOUND where the
#: plant follows, BELIEF_LIMITED_BOUND where it cannot): the robot tipping over its front wheels
#: (`fast` on `front_heavy`), the slow-breakaway firmware's stick-slip and the turn-deficit
#: firmware's turns (`planner_10hz` on both).
GUARD_BELIEF = ("honest belief, tracking runs above their bound", 2, 3, 0)
#: Judged tracking runs whose end-of-profile |heading error| is above the stock controller's + 0.02 rad
#: (table 6h; pairs whose plant follows both channels): `s_curves` on low friction, with the rated
#: payload forward and on the turn-deficit firmware, `stop_and_go` on low friction,
#: `teleop_joystick` on `front_heavy` and at +20 % latency, and `fast` with the rated payload and
#: on the turn-deficit firmware (the cost of making an arc's shortfall up as the turn,
#: doc/active_inference.md, 'A shortfall in an arc').
GUARD_HEADING = ("end-of-profile heading, judged runs above their bound", 8, 9, 0)
#: The arc's yaw overshoot is acceptance with the model's initial wheel separation at the plant's
#: effective one (table 6i): what remains of GUARD_ARC_OVERSHOOT is the prior b_hat_0 (the thesis's
#: 0.5621 m, identified on the robot) against the turning the plant assumes.
ARC_PRIOR_FACTOR = 1.0
#: The driving step rows the default meets at their documented bound.
ACCEPTED_STEPS = ("0.1 m/s", "0.5 m/s", "1 rad/s turn", "arc, speed", "arc, yaw")
#: The step cases whose overshoot is a guard, not acceptance (GUARD_ARC_OVERSHOOT).
OVERSHOOT_GUARDED = ("arc, yaw",)

_REPORT = {}


def scorecard_report():
    """The scorecard's JSON report on config/default.yaml (run once per process)."""
    if not _REPORT:
        config = os.path.join(ROOT, "config", "default.yaml")
        with tempfile.TemporaryDirectory(prefix="scorecard_") as tmp:
            report_path = os.path.join(tmp, "score.json")
            proc = subprocess.run([sys.executable, SCRIPT, "--aic-config", config, "--jobs", "2", "--driving",
                                   "--json", report_path],
                                  capture_output=True, text=True, timeout=1800)
            sys.stderr.write(proc.stdout)
            if proc.returncode not in (0, 1):
                raise RuntimeError("aic_scorecard.py failed to run (exit %d):\n%s%s"
                                   % (proc.returncode, proc.stdout[-2000:], proc.stderr[-2000:]))
            with open(report_path) as f:
                _REPORT.update(json.load(f))
    return _REPORT


def failing_rows(report):
    """'criterion: row' strings of every row whose verdict is False in a scorecard JSON report."""
    out = []
    for name, rows in report.get("criteria", {}).items():
        for row in rows if isinstance(rows, list) else [rows]:
            if isinstance(row, dict) and row.get("pass") is False:
                out.append("%s: %s" % (name, json.dumps(row, sort_keys=True)))
    return out


class ScorecardAcceptance(unittest.TestCase):
    """The rows config/default.yaml is accepted on, each at the bound doc/experiments.md states."""

    def test_default_config_meets_the_straight_step_acceptance_set(self):
        crit = scorecard_report()["criteria"]
        straight = {k: v for k, v in crit.items() if not k.startswith("driving_")}
        self.assertTrue(straight, "the report holds no straight-step criteria")
        # Not vacuous: judged rows that pass are there (reported-only rows carry no verdict).
        self.assertTrue(any(row.get("pass") is True for rows in straight.values() for row in
                            (rows if isinstance(rows, list) else [rows]) if isinstance(row, dict)))
        failing = failing_rows({"criteria": straight})
        self.assertEqual(failing, [], "straight-step criteria not met:\n  %s" % "\n  ".join(failing))

    def test_default_config_meets_the_documented_driving_steps_deficit_and_stability_bounds(self):
        crit = scorecard_report()["criteria"]
        steps = {r["case"]: r for r in crit["driving_steps"]}
        self.assertEqual(set(steps), set(driving.STEP_CASES))
        for case, r in steps.items():
            if case not in OVERSHOOT_GUARDED:
                self.assertLessEqual(r["aic_overshoot"] or 0.0, driving.STEP_OVERSHOOT, r)
        for case in ACCEPTED_STEPS:
            r = steps[case]
            self.assertEqual(r["bound"], driving.STEP_BOUNDS[case])
            within = r["ratio"] is not None and r["ratio"] <= driving.STEP_BOUNDS[case]
            # The row's verdict also holds its overshoot; for OVERSHOOT_GUARDED cases that is a guard.
            self.assertTrue(within if case in OVERSHOOT_GUARDED else r["pass"],
                            "driving step %s not within its documented bound %.2f: %s"
                            % (case, driving.STEP_BOUNDS[case], json.dumps(r, sort_keys=True)))
        self.assertEqual(len(crit["driving_robust"]), 2 * len(driving.ROBUST_PLANTS))
        failing = [json.dumps(r, sort_keys=True) for r in crit["driving_robust"] if not r["pass"]]
        self.assertEqual(failing, [], "stability rows not met:\n  %s" % "\n  ".join(failing))
        self.assertEqual([r["command"] for r in crit["driving_deficit"]], list(driving.DEFICIT_TURNS))
        for r in crit["driving_deficit"]:
            # The learned wheel separation holds every turn on the deficit variant within 2 %.
            self.assertLessEqual(abs(r["aic_error"]), driving.DEFICIT_ERROR * r["command"], r)
            self.assertLess(r["stock_error"], -0.25, "the turn-deficit variant lost its deficit")

    def test_arc_yaw_overshoot_is_within_the_bound_with_the_plants_effective_separation(self):
        """Table 6i: the arc's yaw overshoot (gyro, worst phase) <= STEP_OVERSHOOT when the model
        starts from b_hat_0 = the plant's effective separation on that arc."""
        arc = scorecard_report()["criteria"]["driving_arc_prior"]
        rows = [r for r in arc["rows"] if not r["configured"] and abs(r["factor"] - ARC_PRIOR_FACTOR) < 1e-9]
        self.assertEqual(len(rows), 1, arc)
        self.assertLessEqual(rows[0]["overshoot"], driving.STEP_OVERSHOOT,
                             "arc yaw overshoot %.2f %% with b_hat_0 = b_eff %.4f m" % (rows[0]["overshoot"], arc["b_eff"]))
        # b_eff is the plant's: between the track and 1.5 x the track (doc/robot_data.md, 'Turning').
        self.assertTrue(0.37 < arc["b_eff"] < 0.57, arc["b_eff"])

    def test_the_tracking_benchmark_covers_every_profile_and_variant(self):
        crit = scorecard_report()["criteria"]
        pairs = {(r["profile"], r["variant"]) for r in crit["driving_tracking"]}
        profiles = [os.path.splitext(os.path.basename(p))[0] for p in driving.default_profiles(ROOT)]
        variants = ["default"] + [os.path.splitext(os.path.basename(v))[0]
                                  for v in sorted(glob.glob(os.path.join(ROOT, "sim", "config", "variants", "*.yaml")))]
        self.assertEqual(pairs, {(p, v) for p in profiles for v in variants})
        self.assertEqual(len(crit["driving_tracking"]), len(pairs))
        # The ideal controller and the classical peer (table 6j) beside every pair; the plant-limited
        # channels carry their reason, the others are judged (the verdict holds them all).
        self.assertIn("driving_aic_peer_gmean", crit)
        limited = 0
        for r in crit["driving_tracking"]:
            for ch in ("vx", "wz"):
                self.assertIsNotNone(r["ideal_" + ch], r)
                self.assertGreater(r["peer_" + ch], 0.0, r)
                is_limited = r["ideal_%s_ratio" % ch] > plant_limits.PLANT_LIMIT_RATIO
                self.assertEqual(r["limited_" + ch] is not None, is_limited, r)
                if is_limited:
                    limited += 1
                    self.assertIn("x floor on %s: " % ch, r["limited_" + ch])
            following = [r[ch + "_ratio"] for ch in ("vx", "wz") if r["limited_" + ch] is None]
            self.assertEqual(r["pass"], all(x <= driving.TRACK_PAIR_BOUND for x in following), r)
        self.assertEqual(crit["driving_limited_gmean"]["n"], limited)

    def test_every_plant_following_pair_is_within_its_bound(self):
        # Acceptance: table 6d's per-pair bound, AIC / stock <= 1.02 on every plant-following
        # channel (1.018 today, the slow break-away's `creep` vx).
        rows = scorecard_report()["criteria"]["driving_tracking"]
        worst = max(r[ch + "_ratio"] for r in rows for ch in ("vx", "wz") if r["limited_" + ch] is None)
        self.assertLessEqual(worst, driving.TRACK_PAIR_BOUND,
                             "worst plant-following pair AIC / stock %.3f > %.3f" % (worst, driving.TRACK_PAIR_BOUND))


class ScorecardRegressionGuards(unittest.TestCase):
    """Documented driving bounds config/default.yaml does not meet: the figure may not get worse
    than today's plus a margin. Not acceptance."""

    def guard(self, spec, figure):
        what, today, guard, documented = spec
        met = "met" if figure <= documented else "NOT met"
        sys.stderr.write("REGRESSION GUARD %s: %.3f now (%.3f in doc/results/scorecard.txt); guard <= %.3f; "
                         "documented bound <= %.3f, %s\n" % (what, figure, today, guard, documented, met))
        self.assertLessEqual(figure, guard, "regression guard %s: %.3f > guard %.3f (today's figure %.3f; "
                             "documented bound %.3f)" % (what, figure, guard, today, documented))

    def test_regression_guard_tracking_geometric_mean(self):
        self.guard(GUARD_GMEAN, scorecard_report()["criteria"]["driving_gmean"]["all"])

    def test_regression_guard_arc_yaw_overshoot(self):
        steps = {r["case"]: r for r in scorecard_report()["criteria"]["driving_steps"]}
        self.guard(GUARD_ARC_OVERSHOOT, steps["arc, yaw"]["aic_overshoot"] or 0.0)

    def test_regression_guard_tracking_against_the_latency_floor(self):
        self.guard(GUARD_FLOOR, scorecard_report()["criteria"]["driving_aic_floor_gmean"]["all"])

    def test_regression_guard_honest_belief(self):
        rows = scorecard_report()["criteria"]["driving_tracking"]
        self.guard(GUARD_BELIEF, sum(1 for r in rows if not r["belief_pass"]))

    def test_regression_guard_end_of_profile_heading(self):
        rows = scorecard_report()["criteria"]["driving_tracking"]
        self.guard(GUARD_HEADING, sum(1 for r in rows if r["heading_judged"] and not r["heading_pass"]))


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("scorecard", ScorecardAcceptance, ScorecardRegressionGuards)
