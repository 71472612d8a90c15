#!/usr/bin/env python3
"""Python unit test: the field trial's logic without ROS (doc/field_trials.md).

- plans (jackal_aic_tools.field.field_plan): the shipped standard plan loads, fits its corridor and its
  dry run states the corridor, the limits and a duration under 12 minutes; bad plans (not YAML,
  unknown keys, missing corridor, absurd limits, a profile beyond the limits, a corridor too small,
  a bad experiment) are refused with a message naming the file and the key;
- runs: every experiment for every controller, alternating, each followed by its mirror, whose ideal
  path ends where the out run started; corridor arithmetic (frames, extents, excess);
- safety (jackal_aic_tools.field.field_safety): every stop condition, in its order, and the start checks;
- the report's pieces (jackal_aic_tools.field.field_report): the switch-overlap check on publisher
  records, a bag written with the rosbag API read back as the recorder's arrays, the relative error
  and its floor, the Markdown report (its lines and the shape of its tables).
"""
import math
import os
import sys
import tempfile
import textwrap
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import pyunit  # noqa: E402

from jackal_aic_tools.common import profiles  # noqa: E402
from jackal_aic_tools.field import field_plan, field_report, field_safety  # noqa: E402

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), ".."))
STANDARD = os.path.join(ROOT, "config", "field_trials", "standard.yaml")
MINIMAL = textwrap.dedent("""\
    name: t
    controllers: [aic, stock]
    limits: {max_linear: 0.6, max_angular: 1.0}
    corridor: {ahead: 2.0, behind: 0.6, left: 1.0, right: 0.6}
    margin: 0.3
    experiments:
      - {name: s, step: {v: 0.5, hold: 2.0}}
      - {name: w, step: {w: 1.0, hold: 2.0}}
    """)


def write(text):
    f = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)
    f.write(text)
    f.close()
    return f.name


def load(text):
    path = write(text)
    try:
        return field_plan.load_plan(path)
    finally:
        os.unlink(path)


class PlanTest(unittest.TestCase):
    def test_standard_plan_loads_and_fits_twelve_minutes(self):
        plan = field_plan.load_plan(STANDARD)
        self.assertEqual(plan.controllers, ["aic", "stock"])
        names = [e[0] for e in plan.experiments]
        for n in ("step_0.1", "step_0.5", "step_1.0", "turn_1.0", "arc_0.5_0.5", "square_0.1_0.5", "creep",
                  "teleop", "identification"):
            self.assertIn(n, names)
        text = field_plan.dry_run_text(plan)
        self.assertIn("corridor (geofence, start frame): ahead 4.6 m", text)
        self.assertIn("|vx| <= 1.2 m/s", text)
        for r in plan.runs:
            self.assertIn(r.name, text)
        self.assertLess(plan.duration() + 2.0 * len(plan.runs), 12 * 60.0)

    def test_runs_alternate_and_are_followed_by_their_mirror(self):
        plan = load(MINIMAL)
        got = [(r.experiment, r.controller, r.direction) for r in plan.runs]
        self.assertEqual(got, [("s", "aic", "out"), ("s", "aic", "back"), ("s", "stock", "out"),
                               ("s", "stock", "back"), ("w", "stock", "out"), ("w", "stock", "back"),
                               ("w", "aic", "out"), ("w", "aic", "back")])
        self.assertEqual(plan.runs[0].name, "00_s_aic_out")
        for out, back in zip(plan.runs[0::2], plan.runs[1::2]):
            p1 = field_plan.run_path(plan, out)
            p2 = field_plan.run_path(plan, back, start=tuple(p1[-1, 1:]))
            np.testing.assert_allclose(p2[-1, 1:], [0.0, 0.0, 0.0], atol=1e-9)

    def test_mirror_of_a_step_is_the_step_backwards(self):
        m = profiles.mirror(profiles.step(v=0.5, t_step=0.5, hold=3.0))
        self.assertEqual(m.points, [(0.0, 0.0, 0.0), (0.5, -0.5, 0.0)])
        self.assertAlmostEqual(m.duration, 3.5)

    def test_mirror_retraces_a_turning_profile(self):
        prof = profiles.Profile([(0.0, 0.0, 0.0), (0.3, 0.4, 0.0), (1.0, 0.4, 0.8), (2.0, 0.0, -1.0)], 3.0, "p")
        p1 = field_plan.ideal_path(prof, 0.5, 0.5)
        p2 = field_plan.ideal_path(profiles.mirror(prof), 0.5, 0.5, tuple(p1[-1, 1:]))
        np.testing.assert_allclose(p2[-1, 1:], [0.0, 0.0, 0.0], atol=1e-9)

    def test_ideal_path_of_an_arc_is_exact(self):
        prof = profiles.Profile([(0.0, 0.5, 1.0)], math.pi, "half_circle")
        path = field_plan.ideal_path(prof)
        np.testing.assert_allclose(path[-1, 1:], [0.0, 1.0, math.pi], atol=1e-9)  # radius 0.5 m

    def test_corridor_arithmetic(self):
        xy = field_plan.in_frame([(1.0, 1.0)], (1.0, 0.0, math.pi / 2))
        np.testing.assert_allclose(xy, [[1.0, 0.0]], atol=1e-12)  # 1 m ahead of a robot facing +y
        e = field_plan.extents([(1.0, 0.2), (-0.3, -0.4)])
        self.assertEqual((e["ahead"], e["behind"], e["left"], e["right"]), (1.0, 0.3, 0.2, 0.4))
        c = {"ahead": 1.0, "behind": 1.0, "left": 0.5, "right": 0.5}
        self.assertEqual(field_plan.outside([(0.9, 0.0)], c), 0.0)
        self.assertAlmostEqual(field_plan.outside([(0.9, 0.0)], c, margin=0.3), 0.2)
        self.assertAlmostEqual(field_plan.outside([(0.0, -0.8)], c), 0.3)

    def assertRefused(self, text, *parts):
        with self.assertRaises(field_plan.PlanError) as cm:
            load(text)
        msg = str(cm.exception)
        self.assertIn(".yaml:", msg)
        for p in parts:
            self.assertIn(p, msg)

    def test_bad_plans_are_refused_with_the_key(self):
        self.assertRefused("limits: [1, 2\n", "not valid YAML")
        self.assertRefused(MINIMAL + "colour: red\n", "unknown key", "colour")
        self.assertRefused(MINIMAL.replace("corridor: {ahead: 2.0, behind: 0.6, left: 1.0, right: 0.6}\n", ""),
                           "corridor", "missing")
        self.assertRefused(MINIMAL.replace("max_linear: 0.6", "max_linear: 25"), "limits.max_linear", "25")
        self.assertRefused(MINIMAL.replace("max_angular: 1.0", "max_angular: -1"), "limits.max_angular")
        self.assertRefused(MINIMAL.replace("max_linear: 0.6", "max_linear: .nan"), "limits.max_linear", "finite")
        self.assertRefused(MINIMAL.replace("v: 0.5", "v: 0.9"), "experiments[0] (s)", "beyond limits.max_linear")
        self.assertRefused(MINIMAL.replace("ahead: 2.0", "ahead: 1.0"), "experiments (s)", "beyond the corridor")
        self.assertRefused(MINIMAL.replace("controllers: [aic, stock]", "controllers: [aic, pid]"), "controllers")
        self.assertRefused(MINIMAL.replace("{v: 0.5, hold: 2.0}", "{v: 0.5, hold: 0}"), "experiments[0].step")
        self.assertRefused(MINIMAL.replace("{name: w, step:", "{name: s, step:"), "used twice")
        self.assertRefused(MINIMAL.replace("{name: w, step: {w: 1.0, hold: 2.0}}", "{name: w, profile: no_such}"),
                           "experiments[1].profile", "no profile")
        self.assertRefused(MINIMAL.replace("{name: w, step: {w: 1.0, hold: 2.0}}", "{name: w}"), "exactly one of")
        self.assertRefused(MINIMAL + "safety: {data_timeout: 0}\n", "safety.data_timeout")
        self.assertRefused(MINIMAL + "homing: {max_linear: 0.9}\n", "homing", "within the plan's limits")
        self.assertRefused(MINIMAL.replace("name: s,", "name: 'a b',"), "experiments[0].name")

    def test_dry_run_prints_the_corridor_and_publishes_nothing(self):
        import subprocess
        script = os.path.join(ROOT, "scripts", "aic_field_trial.py")
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:1")  # no master: nothing can be published
        out = subprocess.run([sys.executable, script, "--plan", STANDARD, "--dry-run"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, universal_newlines=True, env=env, timeout=60)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("corridor (geofence, start frame)", out.stdout)
        self.assertIn("dry run: nothing published", out.stdout)
        bad = write(MINIMAL.replace("max_linear: 0.6", "max_linear: 9"))
        try:
            out = subprocess.run([sys.executable, script, "--plan", bad, "--dry-run"], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, universal_newlines=True, env=env, timeout=60)
        finally:
            os.unlink(bad)
        self.assertEqual(out.returncode, 2)
        self.assertIn("limits.max_linear", out.stderr)

    def test_a_missing_file_is_refused(self):
        with self.assertRaises(field_plan.PlanError) as cm:
            field_plan.load_plan("/nonexistent/plan.yaml")
        self.assertIn("cannot read", str(cm.exception))


class SafetyTest(unittest.TestCase):
    def setUp(self):
        self.plan = load(MINIMAL)

    def snap(self, **kw):
        s = field_safety.Snapshot(now=100.0, wall=1000.0)
        s.status = (True, False)
        s.last_status = s.last_joints = s.last_odom = 99.99
        s.wall_joints = s.wall_odom = 999.99
        s.pose = (0.0, 0.0, 0.0)
        s.twist = (0.0, 0.0)
        s.aic_health = (0, "all channels healthy")
        s.__dict__.update(kw)
        return s

    def kind(self, **kw):
        d = field_safety.check(self.snap(**kw), self.plan)
        return None if d is None else d.kind

    def test_nothing_wrong_goes_on(self):
        self.assertIsNone(self.kind())
        self.assertIsNone(field_safety.ready(self.snap(), self.plan, need_aic=True))

    def test_each_stop_condition(self):
        self.assertEqual(self.kind(interrupted="Ctrl-C"), "interrupted")
        self.assertEqual(self.kind(status=(True, True)), "estop")
        self.assertEqual(self.kind(status=(False, False)), "estop")
        self.assertEqual(self.kind(last_status=96.0), "status_lost")
        self.assertEqual(self.kind(last_joints=99.4), "sensor_lost")
        self.assertEqual(self.kind(last_odom=99.4), "sensor_lost")
        self.assertEqual(self.kind(wall_joints=997.0), "sensor_lost")  # a stalled simulated clock
        self.assertEqual(self.kind(pose=(2.01, 0.0, 0.0)), "geofence")
        self.assertEqual(self.kind(pose=(0.0, -0.61, 0.0)), "geofence")
        self.assertIsNone(self.kind(pose=(1.99, 0.99, 3.0)))
        self.assertEqual(self.kind(twist=(0.79, 0.0)), "overspeed")  # 1.3 x 0.6 m/s
        self.assertIsNone(self.kind(twist=(0.77, 1.29)))
        self.assertEqual(self.kind(aic_driving=True, aic_health=(1, "sensor fault: left isolated")), "aic_fault")
        self.assertIsNone(self.kind(aic_driving=False, aic_health=(1, "sensor fault: left isolated")))
        self.assertIsNone(self.kind(aic_driving=True, aic_health=(1, "imu missing"), aic_health_since=99.9))
        self.assertEqual(self.kind(aic_driving=True, aic_health=(1, "imu missing"), aic_health_since=99.7),
                         "aic_fault")
        self.assertEqual(self.kind(aic_driving=True, aic_controller=(2, "runaway")), "aic_fault")
        self.assertIsNone(self.kind(aic_driving=True, aic_controller=(1, "stale")))
        self.assertEqual(self.kind(last_joystick=99.0), "joystick")

    def test_the_first_condition_is_reported(self):
        self.assertEqual(self.kind(interrupted="Ctrl-C", status=(True, True), pose=(5.0, 0.0, 0.0)), "interrupted")
        self.assertEqual(self.kind(status=(True, True), pose=(5.0, 0.0, 0.0)), "estop")
        d = field_safety.check(self.snap(pose=(2.5, 0.0, 0.0)), self.plan)
        self.assertIn("0.50 m outside the corridor", d.reason)

    @staticmethod
    def drive_home(pose, homing, centre=0.0, steps=1500):
        """homing_command in closed loop with a unicycle at 50 Hz whose turns are about a point
        ``centre`` m ahead of the pose's point (skid steer: turning in place moves the odometry's
        point); returns (final pose, done, the largest |vx|, |wz|)."""
        x, y, th = pose
        approaching, done, vmax, wmax = None, False, 0.0, 0.0
        for _ in range(steps):
            vx, wz, done, approaching = field_safety.homing_command((x, y, th), homing, approaching)
            if done:
                break
            vmax, wmax = max(vmax, abs(vx)), max(wmax, abs(wz))
            x += vx * 0.02 * math.cos(th) + centre * (math.cos(th) - math.cos(th + wz * 0.02))
            y += vx * 0.02 * math.sin(th) + centre * (math.sin(th) - math.sin(th + wz * 0.02))
            th += wz * 0.02
        return (x, y, th), done, vmax, wmax

    def test_homing_returns_to_the_start_pose(self):
        h = self.plan.homing
        starts = ((0.6, 0.2, 0.3), (-0.5, -0.3, -2.5), (0.05, 0.0, 0.4), (1.0, -1.0, 3.0), (0.06, -0.10, 0.08))
        for centre in (0.0, 0.04, -0.04):
            for start in starts:
                (x, y, th), done, vmax, wmax = self.drive_home(start, h, centre)
                self.assertTrue(done, "no return from %s, turning centre %g m" % (start, centre))
                self.assertLessEqual(math.hypot(x, y), h["tolerance"])
                self.assertLessEqual(abs(math.atan2(math.sin(th), math.cos(th))), h["heading_tolerance"])
                self.assertLessEqual(vmax, h["max_linear"] + 1e-12)
                self.assertLessEqual(wmax, h["max_angular"] + 1e-12)

    def test_homing_drives_inside_the_tolerance_before_turning(self):
        # just outside the tolerance, facing away: without the hysteresis each turn in place moved
        # the point back across 0.1 m and the two phases turned the robot one way and the other
        h = self.plan.homing
        vx, wz, done, approaching = field_safety.homing_command((0.06, -0.10, 0.08), h)
        self.assertTrue(approaching)
        self.assertFalse(done)
        inside = (0.0, -0.09, 0.3)  # 0.09 m: inside the tolerance, not within HOMING_GOAL of it
        self.assertTrue(field_safety.homing_command(inside, h, True)[3])
        self.assertFalse(field_safety.homing_command(inside, h, False)[3])
        self.assertFalse(field_safety.homing_command(inside, h)[3])

    def test_start_checks(self):
        ready = field_safety.ready
        self.assertIn("no /status", ready(self.snap(status=None), self.plan, True))
        self.assertIn("e-stop", ready(self.snap(status=(True, True)), self.plan, True))
        self.assertIn("inactive", ready(self.snap(status=(False, False)), self.plan, True))
        self.assertIn("/joint_states", ready(self.snap(last_joints=None), self.plan, True))
        self.assertIn("sensor health", ready(self.snap(aic_health=None), self.plan, True))
        self.assertIsNone(ready(self.snap(aic_health=None), self.plan, False))
        self.assertIn("not OK", ready(self.snap(aic_health=(1, "imu missing")), self.plan, True))
        self.assertIsNone(field_safety.start_offset((0.3, 0.2, 0.1), self.plan))
        self.assertIn("--resume", field_safety.start_offset((0.6, 0.0, 0.0), self.plan))
        self.assertIn("--resume", field_safety.start_offset((0.0, 0.0, -2.0), self.plan))


class ReportPiecesTest(unittest.TestCase):
    def test_switch_overlaps(self):
        recs = [(1.000, "/cmd_vel", "/jackal_AIC"), (1.015, "/cmd_vel", "/jackal_AIC"),
                (1.105, "/cmd_vel", "/field_trial"), (1.119, "/cmd_vel", "/field_trial"),
                (1.105, "/cmd_drive", "/stock_base")]
        self.assertEqual(field_report.switch_overlaps(recs), [])
        recs.append((1.101, "/cmd_vel", "/jackal_AIC"))
        self.assertEqual(field_report.switch_overlaps(recs), [("/cmd_vel", 1.1, ["/field_trial", "/jackal_AIC"])])

    def test_relative_error(self):
        self.assertAlmostEqual(field_report.relative_error(1.1, 1.0), 0.1)
        self.assertAlmostEqual(field_report.relative_error(-0.9, -1.0), 0.1)
        self.assertIsNone(field_report.relative_error(None, 1.0))
        self.assertIsNone(field_report.relative_error(1.0, 0.0))

    def test_a_bag_reads_back_as_the_recorder_arrays(self):
        import rosbag
        import rospy
        from geometry_msgs.msg import Twist
        from jackal_msgs.msg import Drive
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState
        from std_msgs.msg import String
        path = tempfile.mktemp(suffix=".bag")
        with rosbag.Bag(path, "w") as bag:
            for k in range(5):
                t = rospy.Time.from_sec(10.0 + 0.02 * k)
                sp = Twist()
                sp.linear.x = 0.1 * k
                bag.write("/field_trial/set_point", sp, t)
                od = Odometry()
                od.header.stamp = rospy.Time.from_sec(9.99 + 0.02 * k)
                od.twist.twist.linear.x = 0.05 * k
                od.pose.pose.position.x = 0.001 * k
                od.pose.pose.orientation.w = 1.0
                bag.write("/odom", od, t)
                d = Drive()
                d.drivers = [1.0 * k, 2.0 * k]
                bag.write("/cmd_drive", d, t)
                js = JointState()
                js.header.stamp = t
                js.name = ["front_left_wheel", "rear_left_wheel", "front_right_wheel", "rear_right_wheel"]
                js.velocity = [1.0, 3.0, 2.0, 2.0]
                bag.write("/joint_states", js, t)
                bag.write("/field_trial/publishers", String(data="/cmd_drive /stock_base"), t)
            bag.write("/field_trial/event", String(data="profile_start 10.0"), rospy.Time.from_sec(10.0))
        try:
            arr = field_report.read_bag(path, "/odom")
        finally:
            os.unlink(path)
        np.testing.assert_allclose(arr["setpoint"][:, 1], [0.0, 0.1, 0.2, 0.3, 0.4])
        np.testing.assert_allclose(arr["odom"][:, 0], 9.99 + 0.02 * np.arange(5))
        np.testing.assert_allclose(arr["pose"][:, 1], 0.001 * np.arange(5))
        np.testing.assert_allclose(arr["drive"][:, 2], 2.0 * np.arange(5))
        np.testing.assert_allclose(arr["wheels"][0, 1:], [2.0, 2.0])
        self.assertEqual(arr["events"], [(10.0, "profile_start 10.0")])
        self.assertEqual(arr["publishers"][0][1:], ("/cmd_drive", "/stock_base"))
        self.assertEqual(arr["belief"].shape, (0, 3))

    def test_relative_error_below_its_floor_is_left_out(self):
        self.assertIsNone(field_report.relative_error(0.5, 0.04, floor=1.0))
        self.assertAlmostEqual(field_report.relative_error(5.5, 5.0, floor=1.0), 0.1)
        self.assertEqual(field_report.figure_metric("vx[2] rise_time"), "rise_time")
        self.assertEqual(field_report.figure_metric("wz_rms"), "wz_rms")

    def test_markdown_report(self):
        def step_run(controller, rise):
            seg = {"channel": "vx", "start": 0.0, "target": 0.5, "metrics": {"measured": {
                "rise_time": rise, "settling_time": 2 * rise, "overshoot": 1.25, "steady_state_error": 0.001}}}
            return {"name": "00_s_%s_out" % controller, "experiment": "s", "direction": "out", "kind": "step",
                    "controller": controller, "segments": [seg],
                    "tracking": {"truth": {"vx": {"rms": 0.1 * rise, "max": 0.5}, "wz": {"rms": 0.0, "max": 0.0}}},
                    "path": {"drift_end": 0.1, "drift_max": 0.2, "heading_end": 0.0}}
        results = [step_run("aic", 0.2), step_run("stock", 0.4)]
        summary = {"plan": "standard", "status": "completed", "reason": "", "runs": 42, "planned": 42,
                   "wall_time": 483.0, "max_distance": 4.421, "odom": "/odom", "resumes": 0, "homing": 3,
                   "extent": {"ahead": 3.818, "behind": 0.073, "left": 2.509, "right": 0.798},
                   "corridor": {"ahead": 4.6, "behind": 1.0, "left": 2.7, "right": 1.2}}
        rows = [("00_s_aic_out", "aic", "vx[0] rise_time", 0.22, 0.2, 0.1),
                ("02_s_aic_out", "aic", "vx[0] rise_time", 0.14, 0.2, -0.3),
                ("00_s_aic_out", "aic", "wz_rms", 0.0004, 0.0002, None)]
        overlay = tempfile.mktemp(prefix="identified_wheel_loop_", suffix=".yaml")
        with open(overlay, "w") as f:
            f.write("# identified\nmotor:\n  speed_kp: 24.82  # gain\n")
        try:
            md = field_report.markdown_report(summary, results, [], rows, [overlay],
                                              command="aic_field_report.py S --sim --markdown S.md")
        finally:
            os.unlink(overlay)
        lines = md.split("\n")
        k = lines.index("`%s`:" % os.path.basename(overlay))
        self.assertEqual(lines[k + 2:k + 6], ["```yaml", "motor:", "  speed_kp: 24.82  # gain", "```"])
        self.assertEqual(lines[0], "# Field-trial session: standard")
        self.assertIn("Generated by `aic_field_report.py S --sim --markdown S.md`; do not edit.", lines)
        self.assertIn("- runs completed: 42 of 42 (resumed 0 times; 3 returns to the start pose)", lines)
        self.assertIn("- wall time: 483 s (8.1 min)", lines)
        self.assertIn("- max distance from the start pose on /odom: 4.42 m", lines)
        self.assertIn("| ahead | 3.82 | 4.60 | 0.78 |", lines)
        self.assertIn("| right | 0.80 | 1.20 | 0.40 |", lines)
        self.assertIn("no 50 Hz period with two publishers on a command topic", lines)
        self.assertIn("+ " + os.path.basename(overlay), md)
        # every table: a header, a |---| rule, rows with as many cells as the header
        k = 0
        tables = 0
        while k < len(lines):
            if lines[k].startswith("|"):
                block = []
                while k < len(lines) and lines[k].startswith("|"):
                    block.append(lines[k])
                    k += 1
                ncol = block[0].count("|")
                self.assertTrue(set(block[1]) <= set("|-"), block[1])
                self.assertTrue(all(b.count("|") == ncol for b in block), block)
                tables += 1
            k += 1
        self.assertEqual(tables, 5)  # corridor, steps, tracking, robot-vs-sim summary and rows
        self.assertIn("| s | out | vx 0->0.5 m/s | 0.200 | 0.400 | 0.400 | 0.800 | 1.2 | 1.2 | 0.0010 | 0.0010 |", lines)
        # the summary: rise errors +10 % and -30 %: median |err| 20, max 30, median -10; wz_rms has none
        self.assertIn("| aic | rise_time | 2 | 20.0 | 30.0 | -10.0 |", lines)
        self.assertIn("| aic | wz_rms | 0 | - | - | - |", lines)
        self.assertIn("| 02_s_aic_out | aic | vx[0] rise_time | 0.140 | 0.200 | -30.0 |", lines)
        # without a comparison: no simulator section; a stopped session says why
        stopped = dict(summary, status="stopped", reason="geofence: 1.31 m right", wall_time=None, extent=None)
        md = field_report.markdown_report(stopped, results, [("r", "/cmd_vel", 1.1, ["/a", "/b"])])
        self.assertNotIn("Robot against simulator", md)
        self.assertIn("- session: plan standard, stopped (geofence: 1.31 m right)", md.split("\n"))
        self.assertIn("- wall time: -", md.split("\n"))
        self.assertIn("| ahead | - | 4.60 | - |", md.split("\n"))
        self.assertIn("1 periods with two publishers", md)

    def test_an_unreadable_bag_is_a_report_error(self):
        with self.assertRaises(field_report.ReportError):
            field_report.read_bag("/nonexistent.bag", "/odom")


if __name__ == "__main__":
    pyunit.main("test_field_trial", PlanTest, SafetyTest, ReportPiecesTest)
