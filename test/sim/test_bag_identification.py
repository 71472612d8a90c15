#!/usr/bin/env python3
"""The identification of a wheel loop from a robot's bag, round trip: a bag of the simulated Jackal
with the turn-deficit firmware (sim/config/variants/turn_deficit.yaml), written headless by
scripts/record_identification.py --headless (plant_replay: the stock controller's /cmd_drive
stream on the plant with its seeded sensor noise), is identified by scripts/plant_identify.py --bag
starting from the default plant; the turning parameters come back within 20 % and the identified
plant reproduces the bag's responses, and the robot model's sensor noises measured on its rests are
the plant's, its yaw response (T_s, b_eff) fitted on its turns in place is the plant's, and its
wheel loop's lag T_w is the identified loop's, and that robot model drives the variant better than
the default configuration. Also the bag
reader's errors, the noise measurement and the yaw response's fit on synthetic streams, and what is
written of a fit (the overlays, the warning for a bag the fit does not reproduce). No roscore needed (rosbag's
Python API); deterministic (seeded noise, seeded candidates); ~30 s.

Run: python3 test/sim/test_bag_identification.py (in the sourced workspace, plant_replay built).
"""
import csv
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import yaml

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "src"))

from jackal_aic_tools.identify import bag_identification as bi  # noqa: E402
from jackal_aic_tools.common import cli  # noqa: E402
from jackal_aic_tools.identify import identify  # noqa: E402
from jackal_aic_tools.identify import sensor_noise as sn  # noqa: E402
from jackal_aic_tools.identify import yaw_response as yr  # noqa: E402

VARIANT = os.path.join(ROOT, "sim", "config", "variants", "turn_deficit.yaml")
PLANT = os.path.join(ROOT, "sim", "config", "plant.yaml")
TOLERANCE = 0.2  # the turning parameters within 20 %


def run(script, *args):
    return subprocess.run([sys.executable, os.path.join(ROOT, "scripts", script)] + list(args),
                          capture_output=True, text=True, check=False)


class BagRoundTrip(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.bag = os.path.join(cls.tmp.name, "turn_deficit.bag")
        out = run("record_identification.py", "--headless", cls.bag, "--sequence", "short", "--overlay", VARIANT)
        assert out.returncode == 0, out.stderr
        cls.json = os.path.join(cls.tmp.name, "fit.json")
        cls.overlay = os.path.join(cls.tmp.name, "identified.yaml")
        cls.out = run("plant_identify.py", "--bag", cls.bag, "--samples", "6", "--starts", "1", "--max-evals", "70",
                      "--jobs", "2", "--json", cls.json, "--overlay-out", cls.overlay)
        assert cls.out.returncode == 0, cls.out.stdout + cls.out.stderr
        with open(cls.json) as f:
            cls.fit = json.load(f)
        with open(VARIANT) as f:
            cls.truth = bi.motor_values(dict(identify.read_motor(PLANT), **yaml.safe_load(f)["motor"]))
        cls.default = bi.motor_values(identify.read_motor(PLANT))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def loaded(self, overlay):
        """The controller's parameters (aic_params --yaml) with the controller overlay ``overlay``
        loaded after config/default.yaml (it must load)."""
        aic_params = cli.find_executable("aic_params", os.path.join(ROOT, "scripts", "plant_identify.py"), "test")
        out = subprocess.run([aic_params, "--yaml", "--config", os.path.join(ROOT, "config", "default.yaml"), "--config",
                              overlay], capture_output=True, text=True, check=False)
        self.assertEqual(out.returncode, 0, out.stderr)
        return yaml.safe_load(out.stdout)

    def test_the_bag_has_the_robot_topics(self):
        data = bi.read_bag(self.bag)
        self.assertFalse(data.cmd_is_twist)
        self.assertGreater(data.duration, 11.0)
        self.assertIsNotNone(data.feedback)
        self.assertIn("/feedback measured_velocity vs /joint_states", self.out.stdout)

    def test_turning_parameters_within_20_percent(self):
        got = self.fit["values"]
        # The proportional gain sets the deficit: identified within 20 % of the variant's.
        self.assertLess(abs(got["speed_kp"] - self.truth["speed_kp"]), TOLERANCE * self.truth["speed_kp"], got)
        # Integral path and load observer: the variant has none; identified within 20 % of the default
        # firmware's (the scale on which "none" is measured).
        for k in ("speed_ki", "load_observer_bandwidth"):
            self.assertEqual(self.truth[k], 0.0)
            self.assertLessEqual(got[k], TOLERANCE * self.default[k], "%s %r" % (k, got))
        # The default plant, where the fit starts, is far off.
        self.assertGreater(abs(self.fit["start"]["speed_kp"] - self.truth["speed_kp"]), TOLERANCE * self.truth["speed_kp"])

    def test_the_identified_plant_reproduces_the_bag(self):
        for stream in ("left", "right", "yaw"):
            err, rms = self.fit["errors"][stream], self.fit["errors"][stream + "_rms"]
            self.assertLess(err, 0.05 * rms, stream)
            self.assertLess(err, 0.2 * self.fit["start_errors"][stream], stream)
        # Reproduced: no warning, and the default plant where the fit starts would have drawn one.
        self.assertEqual(self.fit["poorly_reproduced"], {})
        self.assertNotIn("poorly", self.out.stderr)
        self.assertTrue(bi.poorly_reproduced(self.fit["start_errors"]))
        bag, identified = self.fit["deficits"]["bag"], self.fit["deficits"]["replay"]
        self.assertEqual(len(bag), 2)  # the short sequence's two turns in place
        for (w, d_bag), (_, d_id) in zip(bag, identified):
            self.assertAlmostEqual(d_bag, 0.5, delta=0.1)  # the variant's deficit, in the bag
            self.assertLess(abs(d_id - d_bag), TOLERANCE * d_bag, "command %g rad/s" % w)

    def test_the_sensor_noises_are_the_plants(self):
        # The plant's joint noise 0.01 rad/s over a side's two joints (0.0071) and its gyro noise
        # 0.005 rad/s, measured on the short sequence's rests (72 samples): within 20 %.
        noise = self.fit["sensor_noise"]
        self.assertEqual(noise["encoder_source"], "rest")
        self.assertAlmostEqual(noise["encoder_noise"], 0.01 / 2 ** 0.5, delta=0.2 * 0.01 / 2 ** 0.5)
        self.assertAlmostEqual(noise["gyro_noise"], 0.005, delta=0.2 * 0.005)
        # Written into the robot model's overlay, which loads alone after config/default.yaml.
        model = self.loaded(self.fit["robot_model"])
        self.assertEqual(model["belief_model"], "robot")
        self.assertAlmostEqual(model["encoder_noise"], noise["encoder_noise"], delta=1e-3 * noise["encoder_noise"])
        self.assertAlmostEqual(model["gyro_noise"], noise["gyro_noise"], delta=1e-3 * noise["gyro_noise"])

    def test_the_yaw_response_is_the_plants(self):
        # The wheels' yaw rate to the gyro on the short sequence's two turns in place: the plant's
        # effective separation in a 1 rad/s turn in place is 0.541 m (doc/active_inference.md, 'The
        # robot model'; b_hat_0 x wheel-odometry yaw / true yaw); its scrub lag is a few ms (a
        # standard-sequence bag gives 0.0091 s, this one 0.0100 s on the nominal plant).
        yaw = self.fit["yaw_response"]
        self.assertEqual(yaw["turns"], 2)
        self.assertAlmostEqual(yaw["wheel_separation"], 0.541, delta=0.02 * 0.541)
        self.assertGreater(yaw["yaw_time_constant"], 0.003)
        self.assertLess(yaw["yaw_time_constant"], 0.03)
        self.assertLess(yaw["residual_rms"], 0.03)
        model = self.loaded(self.fit["robot_model"])
        self.assertAlmostEqual(model["yaw_time_constant"], yaw["yaw_time_constant"], delta=1e-3 * yaw["yaw_time_constant"])
        self.assertAlmostEqual(model["wheel_separation"], yaw["wheel_separation"], delta=1e-3)
        self.assertEqual(model["belief_model"], "robot")  # config/default.yaml's, under the overlay
        with open(self.fit["robot_model"]) as f:
            self.assertEqual(set(yaml.safe_load(f)), {"encoder_noise", "gyro_noise", "yaw_time_constant",
                                                      "wheel_separation", "turn_shortfall_noise",
                                                      "wheel_time_constant"})

    def test_a_proportional_only_wheel_loop_switches_the_turn_shortfalls_on(self):
        # The variant's loop, identified without observer or integral path, leaves a turn's load as a
        # speed error: the robot model's overlay turns the turn shortfalls on.
        model = self.loaded(self.fit["robot_model"])
        self.assertEqual(model["turn_shortfall_noise"], 0.3)
        self.assertLess(self.fit["values"]["load_observer_bandwidth"], bi.OBSERVER_OFF_BANDWIDTH)
        self.assertLess(self.fit["values"]["speed_ki"], bi.INTEGRAL_OFF_GAIN)

    def test_the_robot_models_wheel_loop_is_the_identified_one(self):
        # The variant's proportional-only loop: T_w = setpoint_time_constant + J_n / speed_kp =
        # 0.004661 + 0.0933 / 2.0 = 0.0513 s against the default firmware's 0.01365 s, from the
        # identified speed_kp (within 20 %, as the turning parameters). A_w is not written (the
        # fit's proportional clamp is unconstrained on this loop), and the latency is the plant's
        # (within 1 %): both stay config/default.yaml's.
        model = self.loaded(self.fit["robot_model"])
        truth = 0.004661 + 0.0933 / self.truth["speed_kp"]
        self.assertAlmostEqual(model["wheel_time_constant"], truth, delta=TOLERANCE * truth)
        self.assertEqual(model["wheel_acceleration"], 42.87)
        self.assertEqual(model["latency"], 0.1187)
        self.assertAlmostEqual(self.fit["values"]["command_delay"], 0.1187, delta=0.01 * 0.1187)
        self.assertIn("the robot model's wheel loop: wheel_time_constant", self.out.stdout)

    def drive(self, sets):
        """closed_loop_run's JSON: the AIC (config/default.yaml, ``sets`` as --aic-set) on the
        variant's plant over sim/profiles/s_curves.csv, seeded noise."""
        exe = cli.find_executable("closed_loop_run", os.path.join(ROOT, "scripts", "plant_identify.py"), "test")
        cmd = [exe, "--controller", "aic", "--aic-config", os.path.join(ROOT, "config", "default.yaml"), "--noise",
               "--overlay", VARIANT, "--profile", os.path.join(ROOT, "sim", "profiles", "s_curves.csv")]
        for key, value in sets.items():
            cmd += ["--aic-set", "%s=%s" % (key, value)]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        self.assertEqual(out.returncode, 0, out.stderr)
        return json.loads(out.stdout)

    def test_regression_guard_the_bags_robot_model_halves_the_firmwares_yaw_error(self):
        # A regression guard of a documented figure, not an acceptance bound: the robot model's
        # overlay the bag gives, loaded over config/default.yaml, follows the firmware's S-curves'
        # turns where the default configuration (the Jackal MCU's loop, no turn shortfalls) is left
        # behind by the firmware's deficit: yaw-rate RMS error 0.068 against 0.186 rad/s (the
        # latency floor 0.028; doc/robot_data.md, the round trip), asked here to stay below half.
        with open(self.fit["robot_model"]) as f:
            overlay = yaml.safe_load(f)
        default = self.drive({})["tracking"]["truth"]
        identified = self.drive(overlay)["tracking"]["truth"]
        self.assertLess(identified["wz"]["rms"], 0.5 * default["wz"]["rms"])
        self.assertLess(identified["vx"]["rms"], default["vx"]["rms"])

    def test_the_overlay_loads_and_holds_the_identified_keys(self):
        with open(self.overlay) as f:
            text = f.read()
        doc = yaml.safe_load(text)
        self.assertAlmostEqual(doc["motor"]["speed_kp"], self.fit["values"]["speed_kp"], delta=1e-3 * 2)
        self.assertEqual(doc["motor"]["load_observer_time_constant"], 0)
        self.assertIn("# proportional gain [N m / (rad/s)]", text)
        # The overlay drives the plant: a 3 s turn in place at 1 rad/s through plant_replay turns
        # the variant's deficit (0.5 rad/s) short with it, and does not without it (the control).
        replay = cli.find_executable("plant_replay", os.path.join(ROOT, "scripts", "plant_identify.py"), "test")

        def late_yaw_rate(*extra):
            with tempfile.NamedTemporaryFile("w", suffix=".csv") as f:
                f.write("t,vx,wz\n0,0,1.0\n3,0,0\n")
                f.flush()
                out = subprocess.run([replay, "--twist", f.name] + list(extra), capture_output=True, text=True,
                                     check=False)
            self.assertEqual(out.returncode, 0, out.stderr)
            rows = list(csv.DictReader(io.StringIO(out.stdout)))
            late = [float(r["yaw_true"]) for r in rows if 2.0 <= float(r["t"]) <= 3.0]
            self.assertGreater(len(late), 10, out.stdout[:500])
            return sum(late) / len(late)
        with_overlay, without = late_yaw_rate("--overlay", self.overlay), late_yaw_rate()
        self.assertAlmostEqual(with_overlay, 1.0 - 0.5, delta=0.1)
        self.assertAlmostEqual(without, 1.0, delta=0.1)


class BadBags(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def write_text(self, name, text):
        """A file `name` in the test's folder holding `text`; its path."""
        path = os.path.join(self.tmp.name, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def write(self, name, drive_mode=0, imu=True):
        import rosbag
        import rospy
        from jackal_msgs.msg import Drive
        from sensor_msgs.msg import Imu, JointState
        path = os.path.join(self.tmp.name, name)
        with rosbag.Bag(path, "w") as bag:
            for k in range(50):
                t = rospy.Time.from_sec(10.0 + 0.02 * k)
                d = Drive()
                d.mode = drive_mode
                bag.write(bi.CMD_DRIVE, d, t)
                js = JointState()
                js.header.stamp = t
                js.name = list(bi.WHEELS)
                js.velocity = [0.0] * 4
                bag.write(bi.JOINT_STATES, js, t)
                if imu:
                    m = Imu()
                    m.header.stamp = t
                    bag.write(bi.IMU, m, t)
        return path

    def test_errors_name_the_bag_and_the_problem(self):
        with self.assertRaisesRegex(ValueError, "no /imu/data"):
            bi.read_bag(self.write("no_imu.bag", imu=False))
        with self.assertRaisesRegex(ValueError, "mode 1"):
            bi.read_bag(self.write("pwm.bag", drive_mode=1))
        with self.assertRaisesRegex(ValueError, "cannot be read as a bag"):
            missing = os.path.join(self.tmp.name, "missing.bag")
            bi.read_bag(missing)
        out = run("plant_identify.py", "--bag", os.path.join(self.tmp.name, "no_imu.bag"))
        self.assertEqual(out.returncode, 1)
        self.assertIn("no /imu/data", out.stderr)

    def test_plant_replay_refuses_bad_input(self):
        replay = cli.find_executable("plant_replay", os.path.join(ROOT, "scripts", "plant_identify.py"), "test")
        pwm = os.path.join(self.tmp.name, "pwm.csv")
        with open(pwm, "w") as f:
            f.write("t,mode,left,right\n0,1,0.5,0.5\n")
        cases = [([], 2, "exactly one of --drive and --twist"),
                 (["--drive", pwm, "--twist", pwm], 2, "exactly one"),
                 (["--drive", pwm], 1, "no PWM or effort mode"),
                 (["--drive", self.write_text("cols.csv", "t,left,right\n0,1,1\n")], 1, "t, mode, left, right"),
                 (["--twist", pwm], 1, "must name the columns t and vx"),
                 (["--drive", os.path.join(self.tmp.name, "missing.csv")], 1, "cannot be opened"),
                 (["--drive", pwm, "--duration", "-1"], 2, "--duration")]
        for args, code, message in cases:
            out = subprocess.run([replay] + args, capture_output=True, text=True, check=False)
            self.assertEqual(out.returncode, code, args)
            self.assertIn(message, out.stderr, args)

    def test_sequences_are_bounded(self):
        for name in bi.SEQUENCES:
            p = bi.sequence_profile(name)
            self.assertLessEqual(p.max_abs("vx"), bi.MAX_LINEAR)
            self.assertLessEqual(p.max_abs("wz"), bi.MAX_ANGULAR)
        self.assertLessEqual(bi.sequence_profile("standard", 0.3, 0.7).max_abs("wz"), 0.7)
        with self.assertRaises(ValueError):
            bi.sequence_profile("standard", 1.5, 1.0)  # beyond the recorder's 1.0 m/s cap
        with self.assertRaises(ValueError):
            bi.sequence_profile("nonexistent")


class SensorNoise(unittest.TestCase):
    """sensor_noise on synthetic streams (no bag): rest segments with a settling tail and a gyro
    offset, quantized wheel speeds, too little rest."""

    @staticmethod
    def data(cmd_rows, wheel_fn, gyro_fn, duration, twist=False, seed=3):
        rng = np.random.default_rng(seed)
        t = np.arange(0.0, duration, 0.02)
        cmd = np.array(cmd_rows, dtype=float)
        wheels = np.column_stack([t] + [wheel_fn(t, rng) for _ in range(2)])
        gyro = np.column_stack([t, gyro_fn(t, rng)])
        return bi.BagData(cmd, twist, wheels, gyro, None, 0.0, "synthetic.bag")

    def test_rest_segments_give_the_noise_about_their_trend(self):
        # Rest 0-3 s, 4 rad/s 3-5 s, rest 5-9 s (the wheels decay from 4 rad/s with 0.15 s: still
        # 0.14 rad/s 0.5 s after the stop), then mode none 9-12 s, the same rest: two windows; wheel
        # noise 0.01, gyro 0.005 on a 0.03 rad/s offset drifting 0.01 rad/s/s (about each window's
        # mean alone the drift would read as 0.01 rad/s of noise).
        cmd = [(0, 0, 0, 0), (3, 0, 4, 4), (5, 0, 0, 0), (9, -1, 0, 0), (11.99, -1, 0, 0)]

        def wheel(t, rng):
            w = np.where((t >= 3) & (t < 5), 4.0, 0.0) + np.where(t >= 5, 4.0 * np.exp(-(t - 5) / 0.15), 0.0)
            return w + rng.normal(0, 0.01, t.size)
        d = self.data(cmd, wheel, lambda t, rng: 0.03 + 0.01 * t + rng.normal(0, 0.005, t.size), 12.0)
        noise = sn.sensor_noise(d)
        self.assertEqual((noise["encoder_source"], noise["encoder_windows"]), ("rest", 2))
        self.assertAlmostEqual(noise["encoder_noise"], 0.01, delta=0.001)
        self.assertAlmostEqual(noise["gyro_noise"], 0.005, delta=0.0005)

    def test_quantized_wheels_are_measured_on_straight_segments(self):
        # The wheels read exactly 0 at rest; on the straight segments (twist: 0.5 m/s, 0 rad/s)
        # they carry noise 0.02 on a slow ramp.
        cmd = [(0, 0, 0), (2, 0.5, 0), (6, 0, 0), (8, 0.5, 0), (11.99, 0.5, 0)]

        def wheel(t, rng):
            moving = ((t >= 2) & (t < 6)) | (t >= 8)
            return np.where(moving, 5.0 + 0.1 * t + rng.normal(0, 0.02, t.size), 0.0)
        d = self.data(cmd, wheel, lambda t, rng: rng.normal(0, 0.005, t.size), 12.0, twist=True)
        noise = sn.sensor_noise(d)
        self.assertEqual(noise["encoder_source"], "straight")
        self.assertAlmostEqual(noise["encoder_noise"], 0.02, delta=0.002)

    def test_a_bag_without_rest_is_an_error_naming_it(self):
        cmd = [(0, 0, 4, 4), (5.99, 0, 4, 4)]
        d = self.data(cmd, lambda t, rng: 4.0 + rng.normal(0, 0.01, t.size),
                      lambda t, rng: rng.normal(0, 0.005, t.size), 6.0)
        with self.assertRaisesRegex(ValueError, "synthetic.bag: 0 gyro samples at rest"):
            sn.sensor_noise(d)


class YawResponse(unittest.TestCase):
    """yaw_response on synthetic streams (no bag): a known lag, separation and offset come back;
    a bag without a turn in place is an error naming it."""

    @staticmethod
    def data(cmd_rows, difference_fn, time_constant, separation, offset, seed=5):
        rng = np.random.default_rng(seed)
        t = np.arange(0.0, 12.0, 0.02)
        difference = difference_fn(t)  # omega_R - omega_L [rad/s]
        grid, x = yr.lag(t, difference, time_constant)
        gyro = 0.098 / separation * np.interp(t, grid, x) + offset + rng.normal(0, 0.005, t.size)
        wheels = np.column_stack([t, -0.5 * difference + rng.normal(0, 0.007, t.size),
                                  0.5 * difference + rng.normal(0, 0.007, t.size)])
        return bi.BagData(np.array(cmd_rows, dtype=float), False, wheels, np.column_stack([t, gyro]), None, 0.0,
                          "synthetic.bag")

    def test_a_known_lag_separation_and_offset_come_back(self):
        # Two turns in place, the wheels ramping at 40 rad/s^2 to +-2.9 rad/s per side, the body
        # 0.02 s behind through 0.55 m, the gyro 0.01 rad/s off.
        cmd = [(0, 0, 0, 0), (1, 0, -2.9, 2.9), (3.5, 0, 0, 0), (5, 0, 2.9, -2.9), (7.5, 0, 0, 0), (11.99, 0, 0, 0)]

        def difference(t):
            up = np.clip((t - 1.1) * 80.0, 0, 5.8) - np.clip((t - 3.6) * 80.0, 0, 5.8)
            down = np.clip((t - 5.1) * 80.0, 0, 5.8) - np.clip((t - 7.6) * 80.0, 0, 5.8)
            return up - down
        r = yr.yaw_response(self.data(cmd, difference, 0.02, 0.55, 0.01))
        self.assertEqual(r["turns"], 2)
        self.assertAlmostEqual(r["yaw_time_constant"], 0.02, delta=0.002)
        self.assertAlmostEqual(r["wheel_separation"], 0.55, delta=0.002)
        self.assertAlmostEqual(r["gyro_offset"], 0.01, delta=0.001)

    def test_a_bag_without_a_turn_in_place_is_an_error_naming_it(self):
        cmd = [(0, 0, 0, 0), (1, 0, 4, 4), (5, 0, 0, 0), (11.99, 0, 0, 0)]
        with self.assertRaisesRegex(ValueError, "synthetic.bag: 0 gyro samples in 0 turns in place"):
            yr.yaw_response(self.data(cmd, lambda t: 0.0 * t, 0.02, 0.55, 0.0))

    def test_a_gyro_that_turns_against_the_wheels_is_an_error(self):
        cmd = [(0, 0, 0, 0), (1, 0, -2.9, 2.9), (3.5, 0, 0, 0), (11.99, 0, 0, 0)]
        d = self.data(cmd, lambda t: np.where((t > 1.1) & (t < 3.6), 5.8, 0.0), 0.02, 0.55, 0.0)
        d.gyro[:, 1] *= -1.0  # the IMU mounted upside down
        with self.assertRaisesRegex(ValueError, "does not turn with the wheels"):
            yr.yaw_response(d)


class RobotModelOverlay(unittest.TestCase):
    """What plant_identify.py --bag writes of a fit (jackal_aic_tools.identify.bag_fit, no bag): the
    robot model's overlay, the turn shortfalls' switch, the wheel loop's keys, and the warning when
    the identified plant does not reproduce the bag."""

    def test_the_robot_models_overlay_holds_what_the_bag_gave(self):
        from jackal_aic_tools.identify import bag_fit
        with tempfile.TemporaryDirectory() as tmp:
            response = {"yaw_time_constant": 0.01, "wheel_separation": 0.545, "turns": 2, "samples": 300,
                        "residual_rms": 0.016}
            out = os.path.join(tmp, "out.yaml")
            self.assertEqual(bag_fit.write_robot_model(out, None, response, "x.bag"),
                             ["yaw_time_constant", "wheel_separation"])
            with open(out) as f:
                self.assertEqual(yaml.safe_load(f), {"yaw_time_constant": 0.01, "wheel_separation": 0.545})
            self.assertEqual(bag_fit.write_robot_model(out, None, None, "x.bag"), [])
            with open(out) as f:
                self.assertIsNone(yaml.safe_load(f))  # comments only
            with self.assertRaises(OSError):
                bag_fit.write_robot_model(os.path.join(tmp, "no_dir", "out.yaml"), None, response, "x.bag")

    def test_the_turn_shortfalls_follow_the_identified_load_compensation(self):
        from jackal_aic_tools.identify import bag_fit
        # The default firmware's observer (24.4 1/s) holds a turn's load: nothing to write; a loop
        # with neither observer (the fit's 0, or below OBSERVER_OFF_BANDWIDTH) nor integral path
        # (below INTEGRAL_OFF_GAIN) does not; an integral path without observer (the slow
        # break-away's) winds it up within the turn: nothing; not fitted: nothing known.
        self.assertEqual(bag_fit.turn_load_lines({"load_observer_bandwidth": 24.36, "speed_ki": 0.0}), [])
        self.assertEqual(bag_fit.turn_load_lines({"load_observer_bandwidth": 0.0, "speed_ki": 0.4026}), [])
        self.assertEqual(bag_fit.turn_load_lines({"speed_kp": 2.0}), [])
        self.assertEqual(bag_fit.turn_load_lines({"load_observer_bandwidth": 0.0}), [])
        for bandwidth, ki in ((0.0, 0.0), (0.1, 0.005)):
            lines = bag_fit.turn_load_lines({"load_observer_bandwidth": bandwidth, "speed_ki": ki})
            self.assertEqual(yaml.safe_load("\n".join(lines)), {"turn_shortfall_noise": 0.3})
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out.yaml")
            keys = bag_fit.write_robot_model(out, None, None, "x.bag", bag_fit.turn_load_lines(
                {"load_observer_bandwidth": 0.0, "speed_ki": 0.0}))
            self.assertEqual(keys, ["turn_shortfall_noise"])
            with open(out) as f:
                self.assertEqual(yaml.safe_load(f), {"turn_shortfall_noise": 0.3})

    def test_the_wheel_loop_lines_hold_what_the_fit_moved(self):
        from jackal_aic_tools.identify import bag_fit
        base = identify.read_motor(PLANT)
        # The default firmware's own loop: nothing differs from config/default.yaml's.
        own = bi.motor_values(base)
        self.assertEqual(bag_fit.wheel_loop_lines(dict(base), own, base), [])
        # A gain a fifth of it without observer: T_w; the latency moved 10 %: L; A_w and the
        # feed-forward's keys are not written even where they differ (the clamp fitted, the
        # feed-forward not).
        moved = dict(base, speed_kp=2.0, command_delay=0.13, accel_feedforward=0.1, proportional_limit=3.0,
                     load_observer_time_constant=0.0)
        fitted = {"speed_kp": 2.0, "command_delay": 0.13, "proportional_limit": 3.0, "load_observer_bandwidth": 0.0}
        lines = bag_fit.wheel_loop_lines(moved, fitted, base)
        self.assertEqual(yaml.safe_load("\n".join(lines)),
                         {"latency": 0.13, "wheel_time_constant": float("%.4g" % (0.004661 + 0.0933 / 2.0))})
        self.assertIn("identified on the bag: speed_kp", "\n".join(lines))
        # With a load observer the gain is not identified: T_w is not written.
        observed = dict(fitted, load_observer_bandwidth=24.36)
        self.assertEqual(yaml.safe_load("\n".join(bag_fit.wheel_loop_lines(moved, observed, base))), {"latency": 0.13})
        # Within WHEEL_LOOP_UNCHANGED of the default: left out.
        near = dict(base, command_delay=base["command_delay"] * (1.0 + 0.5 * bag_fit.WHEEL_LOOP_UNCHANGED))
        self.assertEqual(bag_fit.wheel_loop_lines(near, {"command_delay": near["command_delay"]}, base), [])
        self.assertIn("T_w is identified only on a loop without load observer",
                      bag_fit.describe_wheel_loop([], observed))
        self.assertEqual(bag_fit.describe_wheel_loop(lines, fitted), "latency: 0.13, wheel_time_constant: 0.05131")
        # A loop the model cannot describe is an error naming the key.
        with self.assertRaisesRegex(ValueError, "motor.speed_kp"):
            bag_fit.wheel_loop_lines(dict(base, speed_kp=0.0), fitted, base)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out.yaml")
            self.assertEqual(bag_fit.write_robot_model(out, None, None, "x.bag", (), lines),
                             ["latency", "wheel_time_constant"])

    def test_an_integral_path_without_observer_bounds_the_compensation(self):
        from jackal_aic_tools.common import wheel_loop_model
        from jackal_aic_tools.identify import bag_fit
        base = identify.read_motor(PLANT)
        # The slow break-away's bag: an integral path, no observer; e_c = proportional_limit / speed_kp.
        motor = dict(base, speed_kp=6.987, proportional_limit=1.036, speed_ki=0.4026, load_observer_time_constant=0.0)
        values = {"speed_kp": 6.987, "proportional_limit": 1.036, "speed_ki": 0.4026, "load_observer_bandwidth": 0.0}
        lines = bag_fit.compensation_lines(motor, values)
        self.assertEqual(yaml.safe_load("\n".join(lines)), {"shortfall_compensation_limit": float("%.4g" % (1.036 / 6.987))})
        self.assertIn("proportional_limit / speed_kp = 1.036 / 6.987", "\n".join(lines))
        self.assertEqual(bi.load_compensation(values), "integral")
        self.assertEqual(bi.load_compensation(dict(values, speed_ki=0.005)), "none")
        self.assertEqual(bi.load_compensation({"load_observer_bandwidth": 24.36}), "observer")
        self.assertIsNone(bi.load_compensation({"load_observer_bandwidth": 0.0}))
        self.assertIsNone(bi.has_observer({"speed_kp": 6.987}))
        # A load observer takes loads up, a proportional-only loop has no integral to wind up, and an
        # unfitted structure tells nothing: no bound.
        self.assertEqual(bag_fit.compensation_lines(motor, dict(values, load_observer_bandwidth=24.36)), [])
        self.assertEqual(bag_fit.compensation_lines(motor, dict(values, speed_ki=0.005)), [])
        self.assertEqual(bag_fit.compensation_lines(motor, {"speed_kp": 6.987}), [])
        # A proportional path without clamp (0) saturates at the current limit.
        self.assertAlmostEqual(wheel_loop_model.compensation_limit(dict(motor, proportional_limit=0.0)),
                               float(base["max_torque"]) / 6.987)
        for key, bad in (("speed_kp", 0.0), ("proportional_limit", -1.0), ("max_torque", float("nan"))):
            with self.assertRaisesRegex(ValueError, "motor.%s" % key):
                bag_fit.compensation_lines(dict(motor, **{key: bad}), values)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out.yaml")
            self.assertEqual(bag_fit.write_robot_model(out, None, None, "x.bag", compensation=lines),
                             ["shortfall_compensation_limit"])

    def test_a_stream_the_fit_does_not_reproduce_is_named(self):
        from jackal_aic_tools.identify import bag_fit
        # The shares are fit_cost()'s terms: RMS error over max(the stream's RMS, 0.1).
        errors = {"left": 0.02, "left_rms": 2.0, "right": 0.3, "right_rms": 2.0, "yaw": 0.03, "yaw_rms": 0.05}
        shares = bi.stream_shares(errors)
        self.assertEqual(shares, {"left": 0.01, "right": 0.15, "yaw": 0.3})
        self.assertAlmostEqual(bi.fit_cost(errors), (0.01 ** 2 + 0.15 ** 2 + 0.3 ** 2) / 3.0)
        poor = bi.poorly_reproduced(errors)
        self.assertEqual(poor, {"right": 0.15, "yaw": 0.3})
        self.assertEqual(bi.poorly_reproduced(errors, share=0.5), {})
        self.assertEqual(bi.poorly_reproduced(dict(errors, left=float("nan"))).keys(), {"left", "right", "yaw"})
        for bad in (0.0, -0.1, float("nan"), float("inf")):
            with self.assertRaisesRegex(ValueError, "share"):
                bi.poorly_reproduced(errors, share=bad)
        warning = bag_fit.describe_poor_fit(poor)
        self.assertIn("right wheels (15.0 %), gyro yaw (30.0 %) poorly", warning)
        self.assertIn("--overlay", warning)
        self.assertIsNone(bag_fit.poor_fit_comment({}))
        # Both overlays carry it as a comment; nothing else changes.
        with tempfile.TemporaryDirectory() as tmp:
            base = identify.read_motor(PLANT)
            for given in (None, poor):
                loop = os.path.join(tmp, "loop.yaml")
                model = os.path.join(tmp, "model.yaml")
                self.assertEqual(bag_fit.write_overlay(loop, {"speed_kp": 2.0}, base, "x.bag", 0.01, given),
                                 ["speed_kp"])
                bag_fit.write_robot_model(model, None, None, "x.bag", bag_fit.turn_load_lines(
                    {"load_observer_bandwidth": 0.0, "speed_ki": 0.0}), (), given)
                for path, expected in ((loop, {"motor": {"speed_kp": 2.0}}), (model, {"turn_shortfall_noise": 0.3})):
                    with open(path) as f:
                        text = f.read()
                    self.assertEqual(yaml.safe_load(text), expected)
                    self.assertEqual("Poorly reproduced by the fit" in text, given is not None, path)
                    if given:
                        self.assertIn("right wheels 15.0 %, gyro yaw 30.0 %", text)


def suite():
    """The test cases (one JUnit result through rosunit)."""
    loader = unittest.TestLoader()
    return unittest.TestSuite([loader.loadTestsFromTestCase(BagRoundTrip), loader.loadTestsFromTestCase(BadBags),
                               loader.loadTestsFromTestCase(SensorNoise), loader.loadTestsFromTestCase(YawResponse),
                               loader.loadTestsFromTestCase(RobotModelOverlay)])


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(HERE))  # test/pyunit.py
    import pyunit  # noqa: E402  (the test folder is not a package)
    pyunit.main("bag_identification", BagRoundTrip, BadBags, SensorNoise, YawResponse, RobotModelOverlay)
