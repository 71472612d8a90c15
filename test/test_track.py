#!/usr/bin/env python3
"""Python unit test: the tracking benchmark (scripts/aic_track.py) and its profiles.

- sim/profiles/*.csv are the generator's output (jackal_aic_tools/track/track_profiles.py), and each
  profile is what it claims (rates, the J100 ramps, turns in place, reversing, creeping, 1.5 m/s);
- one short profile on the default plant and on an overlay of this test's own, AIC and stock
  (closed_loop_run, seeded noise: deterministic): every output is written and consistent (the
  figures of tracking.json are closed_loop_run's, the path drift is the one aic_track_metrics
  computes from the trace, the ratios are AIC / stock, the results page has the table, the AIC's
  traces carry F and its parts);
- bad profile CSVs and a missing overlay are refused with exit 1 and a message naming them;
- the acceleration-bounded latency floor: the wheel loop's A_w and the body's accelerations from
  the plant's motor keys (a variant's overlay over them) and the URDF, bad keys refused, and the
  floor it gives never below the unlimited one.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import yaml

from jackal_aic_tools.common import cli, profiles
from jackal_aic_tools.track import track_profiles

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), ".."))
SCRIPT = os.path.join(ROOT, "scripts", "aic_track.py")
SHORT = "t,vx,wz\n0,0.5,0\n1.5,0.5,0.4\n3.0,0,0\n"  # straight, then an arc


def rows_of(name):
    return track_profiles.profile_rows(name)


def run_suite(args):
    return subprocess.run([sys.executable, SCRIPT] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          universal_newlines=True, timeout=240)


class TrackCheck(unittest.TestCase):

    def test_committed_profiles_are_the_generators_output(self):
        with tempfile.TemporaryDirectory(prefix="track_profiles_") as tmp:
            for path in track_profiles.write_all(tmp):
                name = os.path.basename(path)
                with open(path) as f, open(os.path.join(ROOT, "sim", "profiles", name)) as g:
                    self.assertEqual(f.read(), g.read(), "sim/profiles/%s differs from the generator's output "
                                                         "(aic_track.py --write-profiles sim/profiles)" % name)

    def _steps(self, rows):
        dt = {round(b[0] - a[0], 9) for a, b in zip(rows, rows[1:])}
        self.assertEqual(len(dt), 1, "uneven rate")
        return dt.pop()

    def test_teleop_is_a_joystick(self):
        rows = rows_of("teleop_joystick")
        self.assertAlmostEqual(self._steps(rows), 0.05)  # 20 Hz
        self.assertLessEqual(max(abs(v) for _, v, _ in rows), track_profiles.SCALE_LINEAR + 1e-9)
        self.assertLessEqual(max(abs(w) for _, _, w in rows), track_profiles.SCALE_ANGULAR + 1e-9)
        self.assertTrue(any(v == 0.0 and abs(w) > 1.0 for _, v, w in rows), "no turn in place")
        self.assertTrue(any(v < -0.25 for _, v, _ in rows), "no reversing")
        # The stick is smoothed: no jump from rest to full speed in one message.
        self.assertLess(max(abs(b[1] - a[1]) for a, b in zip(rows, rows[1:])), 0.5 * track_profiles.SCALE_LINEAR)

    def test_planner_profiles_ramp_at_the_j100_limits(self):
        for name in ("planner_10hz", "s_curves", "stop_and_go", "creep", "fast"):
            rows = rows_of(name)[:-1]
            dt = self._steps(rows)
            self.assertAlmostEqual(dt, 0.1, msg=name)  # 10 Hz
            dv = max(abs(b[1] - a[1]) for a, b in zip(rows, rows[1:])) / dt
            dw = max(abs(b[2] - a[2]) for a, b in zip(rows, rows[1:])) / dt
            self.assertLessEqual(dv, track_profiles.LINEAR_ACCEL + 1e-9, name)
            self.assertLessEqual(dw, track_profiles.ANGULAR_ACCEL + 1e-9, name)
            self.assertEqual(rows[0][1:], (0.0, 0.0), name)
            self.assertEqual(rows[-1][1:], (0.0, 0.0), name)
        planner = rows_of("planner_10hz")
        self.assertTrue(any(v > 0.5 and abs(w) > 0.3 for _, v, w in planner), "no arc")
        last_turn = [k for k, (_, v, w) in enumerate(planner) if v == 0.0 and abs(w) >= 0.9]
        last_drive = [k for k, (_, v, _) in enumerate(planner) if v > 0.0]
        self.assertTrue(last_turn and last_turn[-1] > last_drive[-1], "no final turn in place")
        s = rows_of("s_curves")
        self.assertGreaterEqual(sum(1 for a, b in zip(s, s[1:]) if a[2] * b[2] < 0.0), 5, "not an S-curve")
        go = rows_of("stop_and_go")
        stops = sum(1 for a, b in zip(go, go[1:]) if a[1] > 0.0 and b[1] == 0.0)
        self.assertGreaterEqual(stops, 4)
        creep = [abs(v) for _, v, _ in rows_of("creep") if v != 0.0]
        held = [v for v in creep if creep.count(v) >= 10]  # the levels held, not the ramps between them
        self.assertAlmostEqual(min(held), 0.05)
        self.assertAlmostEqual(max(creep), 0.2)
        fast = rows_of("fast")
        self.assertAlmostEqual(max(v for _, v, _ in fast), 1.5)
        self.assertTrue(any(v == 1.5 and abs(w) >= 0.6 for _, v, w in fast), "no turn at 1.5 m/s")

    def test_short_profile_two_variants(self):
        with tempfile.TemporaryDirectory(prefix="track_suite_") as tmp:
            profile = os.path.join(tmp, "short.csv")
            with open(profile, "w") as f:
                f.write(SHORT)
            overlay = os.path.join(tmp, "slow_latency.yaml")
            with open(overlay, "w") as f:
                f.write("motor:\n  command_delay: 0.2   # [s], longer than the plant's\n")
            out = os.path.join(tmp, "out")
            md = os.path.join(tmp, "tracking.md")
            proc = run_suite(["--profiles", profile, "--variants", "default", overlay, "--out", out,
                              "--results-md", md, "--jobs", "2"])
            self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
            self.assertIn("geometric mean", proc.stdout)
            with open(os.path.join(out, "tracking.json")) as f:
                data = json.load(f)
            runs = {(r["variant"], r["controller"]): r for r in data["runs"]}
            self.assertEqual(set(runs), {(v, c) for v in ("default", "slow_latency") for c in ("aic", "stock", "pi")})
            for key, r in runs.items():
                for name, value in r["metrics"].items():
                    self.assertTrue(value is not None and math.isfinite(value), "%s %s: %r" % (key, name, value))
                # A real run: it moved and tracked the 0.5 m/s roughly, not exactly.
                self.assertGreater(r["path"]["ideal_length"], 1.0)
                self.assertGreater(r["metrics"]["vx_rms"], 0.0)
                self.assertLess(r["metrics"]["vx_rms"], 0.5)
                self.assertEqual(r["metrics"]["vx_rms"], r["tracking"]["truth"]["vx"]["rms"])
                self.assertTrue(os.path.isfile(r["trace"]))
                # The AIC's traces carry its inference on the trace's time base: F and its parts.
                if key[1] == "aic":
                    from jackal_aic_tools.common import tracking
                    cols = tracking.read_columns(r["trace"])
                    for c in ("F[-]", "F_sensory[-]", "F_prior[-]", "mu0_x_dot[m/s]", "eps_y0_gyro_z[rad/s]"):
                        self.assertIn(c, cols)
                    f = cols["F[-]"]
                    ok = np.isfinite(f)
                    self.assertGreater(np.count_nonzero(ok), 100)
                    np.testing.assert_allclose(f[ok], cols["F_sensory[-]"][ok] + cols["F_prior[-]"][ok],
                                               rtol=1e-5, atol=1e-9)
            # The figures are closed_loop_run's (deterministic: the same run again).
            exe = cli.find_executable("closed_loop_run", SCRIPT, "track_check")
            direct = json.loads(subprocess.run(
                [exe, "--controller", "stock", "--noise", "--config", os.path.join(ROOT, "sim", "config", "plant.yaml"),
                 "--profile", profile, "--overlay", overlay], stdout=subprocess.PIPE, universal_newlines=True,
                check=True).stdout)
            self.assertEqual(direct["tracking"], runs[("slow_latency", "stock")]["tracking"])
            self.assertEqual(direct["path"], runs[("slow_latency", "stock")]["path"])
            # The latency floor at the plant's latency (the run reports the overlay's 0.2 s) is below
            # both controllers' errors on both plants: no controller moves before its command arrives.
            from jackal_aic_tools.track import driving
            self.assertEqual(direct["command_delay"], 0.2)
            with open(os.path.join(ROOT, "sim", "config", "plant.yaml")) as f:
                plant_latency = yaml.safe_load(f)["motor"]["command_delay"]
            for v, latency in (("default", plant_latency), ("slow_latency", 0.2)):
                floor = driving.floor_rms(profile, latency)
                self.assertGreater(floor["vx"], 0.01)
                for c in ("aic", "stock", "pi"):
                    for ch in ("vx", "wz"):
                        self.assertLess(floor[ch], runs[(v, c)]["tracking"]["truth"][ch]["rms"], (v, c, ch))
            # The path drift from the trace through aic_track_metrics is the same.
            metrics_cli = cli.find_executable("aic_track_metrics", SCRIPT, "track_check")
            again = json.loads(subprocess.run(
                [metrics_cli, "--profile", profile, "--trace", runs[("default", "aic")]["trace"]],
                stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout)
            for k in ("final_position_error", "max_position_error", "final_heading_error"):
                self.assertAlmostEqual(again["path"][k], runs[("default", "aic")]["path"][k], places=5)
            # Ratios are AIC / stock; the geometric mean is over both variants.
            for q in data["ratios"]:
                a = runs[(q["variant"], "aic")]["metrics"]["vx_rms"]
                s = runs[(q["variant"], "stock")]["metrics"]["vx_rms"]
                self.assertAlmostEqual(q["ratios"]["vx_rms"], a / s)
            # The classical peer's table: AIC / peer per pair, and its geometric mean.
            peer = data["peer_geometric_mean"]["aic_pi"]
            ratios = [runs[(v, "aic")]["metrics"][ch + "_rms"] / runs[(v, "pi")]["metrics"][ch + "_rms"]
                      for v in ("default", "slow_latency") for ch in ("vx", "wz")]
            self.assertEqual(peer["all"][1], 4)
            self.assertAlmostEqual(peer["all"][0], math.exp(sum(math.log(x) for x in ratios) / 4))
            with open(md) as f:
                self.assertIn("AIC / classical peer", f.read())
            gm, n = data["geometric_mean"]["vx_rms"]
            self.assertEqual(n, 2, "both pairs follow on vx")
            self.assertAlmostEqual(gm, math.sqrt(data["ratios"][0]["ratios"]["vx_rms"] *
                                                 data["ratios"][1]["ratios"]["vx_rms"]))
            # The ideal controller per pair against the floor; on the default plant it follows the short
            # profile (the ideal knows it in advance: below the floor), so no channel is plant-limited there.
            limits = {q["variant"]: q for q in data["plant_limits"]}
            self.assertEqual(set(limits), {"default", "slow_latency"})
            for v, q in limits.items():
                for ch in ("vx", "wz"):
                    self.assertAlmostEqual(q["ideal_floor"][ch], q["ideal"][ch] / q["floor"][ch])
                    self.assertEqual(q["limited"][ch] is not None,
                                     q["ideal_floor"][ch] > data["plant_limit_ratio"], (v, ch))
                self.assertGreaterEqual(q["ideal"]["runs"], 2)
            self.assertLess(limits["default"]["ideal_floor"]["vx"], 1.0)
            # The acceleration-bounded floor beside it: the variant's wheel-loop limits (the overlay
            # changes only the latency), never below the floor, and the geometric means against it.
            acc = {v["name"]: v["floor_accelerations"] for v in data["variants"]}
            self.assertEqual(acc["default"], acc["slow_latency"])
            self.assertAlmostEqual(acc["default"]["wheel_acceleration"], 42.87, places=2)
            self.assertEqual(data["floor_period"], 0.02)  # the AIC's 50 Hz action period
            for q in data["plant_limits"]:
                for ch in ("vx", "wz"):
                    self.assertGreaterEqual(q["floor_accel"][ch], q["floor"][ch], (q["variant"], ch))
            for name in ("aic_floor_accel", "pi_floor_accel", "stock_floor_accel", "floor_accel_floor",
                         "wheels_floor_accel", "truth_wheels"):
                self.assertEqual(data["peer_geometric_mean"][name]["default"][1], 2, name)
                self.assertEqual(data["peer_geometric_mean"][name]["default_vx"][1], 1, name)
            q = limits["default"]
            self.assertAlmostEqual(data["peer_geometric_mean"]["aic_floor_accel"]["default"][0],
                                   math.sqrt(q["aic"]["vx"] / q["floor_accel"]["vx"] *
                                             q["aic"]["wz"] / q["floor_accel"]["wz"]))
            # The AIC's error taken apart: its wheels against the floor, its body against its wheels;
            # the two multiply to the AIC against the floor, per channel.
            run = [r for r in data["runs"] if (r["variant"], r["controller"]) == ("default", "aic")][0]
            mean = data["peer_geometric_mean"]
            for ch in ("vx", "wz"):
                self.assertEqual(q["aic_wheels"][ch], run["metrics"]["odom_%s_rms" % ch])
                self.assertAlmostEqual(mean["wheels_floor_accel"]["default_" + ch][0] *
                                       mean["truth_wheels"]["default_" + ch][0],
                                       mean["aic_floor_accel"]["default_" + ch][0])
            self.assertEqual([q["limited"] for q in data["ratios"] if q["variant"] == "default"], [[]])
            with open(os.path.join(out, "tracking.csv")) as f:
                self.assertEqual(len(list(csv.DictReader(f))), 6)  # 2 variants x 3 controllers
            with open(os.path.join(out, "ratios.csv")) as f:
                self.assertEqual(len(list(csv.DictReader(f))), 3)  # two variants and the geometric mean
            for v in ("default", "slow_latency"):
                png = os.path.join(out, "plots", "short__%s.png" % v)
                self.assertGreater(os.path.getsize(png), 10000, png)
                self.assertGreater(os.path.getsize(os.path.join(out, "plots", "short__%s.pdf" % v)), 5000, v)
            with open(md) as f:
                page = f.read()
            self.assertIn("| short | slow_latency | aic |", page)
            self.assertIn("geometric mean, default plant, acceleration-bounded floor", page)
            self.assertIn("(A_w 42.87 rad/s^2) on default, slow_latency", page)
            self.assertIn("geometric mean", page)

    def test_random_streams_are_seeded_bounded_and_new(self):
        """track_profiles.write_random: the same files for the same seed, other streams for
        another, from rest to rest within the J100 ramps and the teleop scales, and none of
        them a benchmark profile."""
        bench = {n: track_profiles.profile_rows(n) for n in track_profiles.NAMES}
        with tempfile.TemporaryDirectory() as tmp:
            first = track_profiles.write_random(os.path.join(tmp, "a"), 2, 7)
            again = track_profiles.write_random(os.path.join(tmp, "b"), 2, 7)
            other = track_profiles.write_random(os.path.join(tmp, "c"), 2, 8)
            self.assertEqual([os.path.basename(x) for x in first],
                             ["random_planner_7.csv", "random_teleop_7.csv", "random_planner_8.csv",
                              "random_teleop_8.csv"])
            for x, y in zip(first, again):
                with open(x) as f, open(y) as g:
                    self.assertEqual(f.read(), g.read())
            with open(first[0]) as f, open(other[0]) as g:
                self.assertNotEqual(f.read(), g.read())
            for path in first:
                rows = np.array(profiles.from_csv(path).points)
                self.assertEqual(tuple(rows[0][1:]), (0.0, 0.0), path)
                self.assertEqual(tuple(rows[-1][1:]), (0.0, 0.0), path)
                self.assertLessEqual(np.abs(rows[:, 1]).max(), 1.2 + 1e-9, path)
                self.assertLessEqual(np.abs(rows[:, 2]).max(), track_profiles.SCALE_ANGULAR + 1e-9, path)
                self.assertGreater(np.abs(rows[:, 1]).max(), 0.1, path)  # it drives
                if "planner" in path:  # the J100 ramps at 10 Hz, to the CSV's 0.1 mm/s
                    self.assertLessEqual(np.abs(np.diff(rows[:, 1])).max(),
                                         track_profiles.LINEAR_ACCEL / track_profiles.PLANNER_RATE + 1e-4)
                    self.assertLessEqual(np.abs(np.diff(rows[:, 2])).max(),
                                         track_profiles.ANGULAR_ACCEL / track_profiles.PLANNER_RATE + 1e-4)
                for name, b in bench.items():
                    self.assertFalse(len(b) == len(rows) and np.allclose(np.array(b), rows, atol=1e-4),
                                     "%s is the benchmark's %s" % (path, name))
        with self.assertRaises(ValueError):
            track_profiles.write_random(tempfile.gettempdir(), 0, 1)
        with self.assertRaises(ValueError):
            track_profiles.random_planner_script(1, segments=0)
        with tempfile.TemporaryDirectory(prefix="track_random_") as tmp:
            proc = run_suite(["--write-random-profiles", tmp, "--count", "0"])
            self.assertEqual(proc.returncode, 2, proc.stdout + proc.stderr)
            self.assertIn("--count must be >= 1", proc.stderr)
            self.assertEqual(os.listdir(tmp), [])
            proc = run_suite(["--write-random-profiles", tmp, "--count", "1", "--seed", "5"])
            self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
            self.assertEqual(sorted(os.listdir(tmp)), ["random_planner_5.csv", "random_teleop_5.csv"])

    def test_mirrored_profiles_are_the_field_trials_drive_back(self):
        """--write-mirrored-profiles: one <stem>_mirror.csv per profile, each profiles.mirror() of
        its source (the run aic_field_trial.py drives back); the teleop turn's stick eased off
        becomes a stick pushed to its stop, its largest step at the ramp's end; a profile that
        does not load is refused with its reason."""
        with tempfile.TemporaryDirectory(prefix="track_mirror_") as tmp:
            src = os.path.join(ROOT, "sim", "profiles", "teleop_joystick.csv")
            proc = run_suite(["--write-mirrored-profiles", tmp, "--profiles", src])
            self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
            self.assertEqual(os.listdir(tmp), ["teleop_joystick_mirror.csv"])
            out = profiles.from_csv(os.path.join(tmp, "teleop_joystick_mirror.csv"))
            want = profiles.mirror(profiles.from_csv(src))
            self.assertAlmostEqual(out.duration, want.duration)
            np.testing.assert_allclose(np.array(out.points), np.array(want.points), atol=1e-9)
            wz = np.array([p[2] for p in out.points])
            rise = np.flatnonzero(wz >= 1.4 - 1e-9)[0]  # the first time the stick is at its stop
            steps = np.diff(wz[rise - 4:rise + 1])
            self.assertTrue(np.all(steps > 0.0) and steps[-1] == steps.max(), steps)
            bad = os.path.join(tmp, "bad.csv")
            with open(bad, "w") as f:
                f.write("t,vx,wz\n0,nan,0\n1,0,0\n")
            proc = run_suite(["--write-mirrored-profiles", os.path.join(tmp, "out"), "--profiles", bad])
            self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
            self.assertTrue(proc.stderr.startswith("aic_track: ") and "bad.csv" in proc.stderr, proc.stderr)
            self.assertNotIn("Traceback", proc.stderr)

    def test_latency_floor(self):
        """tracking.latency_floor through aic_track_metrics and driving.floor_rms: a step held 0.1 s
        late, the lower of holding and predicting per channel, bad settings refused."""
        from jackal_aic_tools.common import tracking
        from jackal_aic_tools.track import driving
        with tempfile.TemporaryDirectory(prefix="track_floor_") as tmp:
            path = os.path.join(tmp, "step.csv")
            with open(path, "w") as f:
                f.write("t,vx,wz\n0,0,0\n1,0.5,-1\n3,0,0\n")
            f = tracking.latency_floor(path, 0.1)
            self.assertAlmostEqual(f["hold"]["vx"]["rms"], 0.5 * math.sqrt(100.0 / 3001.0), places=6)
            self.assertAlmostEqual(f["hold"]["wz"]["rms"], 1.0 * math.sqrt(100.0 / 3001.0), places=6)
            self.assertEqual(f["latency"], 0.1)
            cache = {}
            self.assertEqual(driving.floor_rms(path, 0.1, cache),
                             {ch: min(f["hold"][ch]["rms"], f["predict"][ch]["rms"]) for ch in ("vx", "wz")})
            self.assertEqual(len(cache), 1)
            slow = tracking.latency_floor(path, 0.1, accel_linear=2.0)  # 0.25 s more to reach 0.5 m/s
            self.assertGreater(slow["hold"]["vx"]["rms"], f["hold"]["vx"]["rms"] * 1.2)
            self.assertEqual(slow["hold"]["wz"], f["hold"]["wz"])
            # The wheel bound (A_w 10 rad/s^2, r 0.1 m, track 0.4 m) and a 20 ms hold reach the CLI:
            # the turn waits for the speed change, and a held aim costs nothing on a step at 1 s.
            both = os.path.join(tmp, "both.csv")
            with open(both, "w") as f:
                f.write("t,vx,wz\n0,0,0\n1,1,1\n3,1,1\n")
            wheels = tracking.latency_floor(both, 0.0, period=0.02, wheels=(10.0, 0.1, 0.4))
            self.assertEqual(wheels["period"], 0.02)
            self.assertAlmostEqual(wheels["hold"]["wz"]["rms"], math.sqrt((800.0 + 400.0 / 3.0) / 3001.0), places=2)
            self.assertEqual(driving.floor_rms(both, 0.0, cache, period=0.02, wheels=(10.0, 0.1, 0.4)),
                             {ch: min(wheels["hold"][ch]["rms"], wheels["predict"][ch]["rms"]) for ch in ("vx", "wz")})
            self.assertEqual(len(cache), 2)
            for bad in ((-0.1, 0.0), (0.1, -1.0), (float("nan"), 0.0)):
                with self.assertRaises(tracking.TrackingError):
                    tracking.latency_floor(path, bad[0], accel_linear=bad[1])
            with self.assertRaises(tracking.TrackingError):
                tracking.latency_floor(path, 0.1, period=-0.02)
            with self.assertRaises(tracking.TrackingError):
                tracking.latency_floor(path, 0.1, wheels=(10.0, 0.0, 0.4))
            with self.assertRaises(tracking.TrackingError):
                tracking.latency_floor(os.path.join(tmp, "missing.csv"), 0.1)

    def test_bad_profiles_and_overlays_are_refused(self):
        with tempfile.TemporaryDirectory(prefix="track_bad_") as tmp:
            cases = {"nan.csv": ("t,vx,wz\n0,0.5,0\n1,nan,0\n2,0,0\n", "nan.csv line 3: vx 'nan' is not finite"),
                     "back.csv": ("t,vx,wz\n0,0.5,0\n1,0.2,0\n0.5,0,0\n", "back.csv line 4: t must increase"),
                     "word.csv": ("t,vx,wz\n0,fast,0\n1,0,0\n", "word.csv line 2: vx 'fast' is not a number"),
                     "one.csv": ("t,vx,wz\n0,0.5,0\n", "need at least two rows"),
                     "cols.csv": ("time,speed\n0,0.5\n1,0\n", "must name the columns t and vx")}
            for name, (text, message) in cases.items():
                path = os.path.join(tmp, name)
                with open(path, "w") as f:
                    f.write(text)
                proc = run_suite(["--profiles", path, "--variants", "default", "--out", os.path.join(tmp, "o"),
                                  "--no-plots"])
                self.assertEqual(proc.returncode, 1, name + ": " + proc.stdout + proc.stderr)
                self.assertIn(message, proc.stderr, name)
            good = os.path.join(tmp, "good.csv")
            with open(good, "w") as f:
                f.write(SHORT)
            proc = run_suite(["--profiles", good, "--variants", os.path.join(tmp, "missing.yaml"),
                              "--out", os.path.join(tmp, "o"), "--no-plots"])
            self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
            self.assertIn("no such overlay file", proc.stderr)
            bad_overlay = os.path.join(tmp, "bad.yaml")
            with open(bad_overlay, "w") as f:
                f.write("motor:\n  no_such_key: 1\n")
            proc = run_suite(["--profiles", good, "--variants", bad_overlay, "--out", os.path.join(tmp, "o"),
                              "--no-plots"])
            self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
            self.assertIn("run(s) failed", proc.stderr)


class FloorAccelCheck(unittest.TestCase):
    """The acceleration-bounded latency floor's limits (plant_limits.wheel_acceleration,
    floor_accelerations, urdf_geometry; closed_loop.plant_motor) and the floor itself."""

    PLANT = os.path.join(ROOT, "sim", "config", "plant.yaml")

    def limits(self, overlays=()):
        from jackal_aic_tools.common import closed_loop
        from jackal_aic_tools.track import plant_limits
        radius, track = plant_limits.urdf_geometry(os.path.join(ROOT, "sim", "urdf", "jackal.urdf"))
        return plant_limits.floor_accelerations(closed_loop.plant_motor(self.PLANT, overlays), radius, track)

    def test_committed_plant(self):
        """A_w = (3.243 + 0.7571) / 0.0933 = 42.87 rad/s^2 (the robot model's wheel_acceleration),
        r = 0.098 m and track 0.37559 m from the URDF."""
        from jackal_aic_tools.track import plant_limits
        radius, track = plant_limits.urdf_geometry(os.path.join(ROOT, "sim", "urdf", "jackal.urdf"))
        self.assertAlmostEqual(radius, 0.098)
        self.assertAlmostEqual(track, 0.37559)
        acc = self.limits()
        self.assertAlmostEqual(acc["wheel_acceleration"], (3.243 + 0.7571) / 0.0933)
        self.assertAlmostEqual(acc["wheel_acceleration"], 42.87, places=2)
        self.assertAlmostEqual(acc["linear"], acc["wheel_acceleration"] * 0.098)
        self.assertAlmostEqual(acc["angular"], 2.0 * acc["wheel_acceleration"] * 0.098 / 0.37559)

    def test_overlay_changes_the_limits(self):
        """A variant's overlay is read over the plant YAML: its proportional_limit changes A_w; a limit
        of 0 (none) counts as max_torque, and the sum stays within it."""
        from jackal_aic_tools.track import plant_limits
        with tempfile.TemporaryDirectory(prefix="track_accel_") as tmp:
            overlay = os.path.join(tmp, "strong.yaml")
            with open(overlay, "w") as f:
                f.write("motor:\n  proportional_limit: 1.5\n")
            acc = self.limits([overlay])
            self.assertAlmostEqual(acc["wheel_acceleration"], (3.243 + 1.5) / 0.0933)
            self.assertAlmostEqual(acc["linear"], acc["wheel_acceleration"] * 0.098)
            self.assertGreater(acc["angular"], self.limits()["angular"])
            with open(overlay, "w") as f:
                f.write("motor:\n  proportional_limit: 0\n")
            self.assertAlmostEqual(self.limits([overlay])["wheel_acceleration"], 8.0 / 0.0933)
        motor = {"accel_feedforward_limit": 0.0, "proportional_limit": 0.5, "load_observer_inertia": 0.1,
                 "max_torque": 2.0}
        self.assertAlmostEqual(plant_limits.wheel_acceleration(motor), 20.0)

    def test_bad_motor_keys_are_refused(self):
        from jackal_aic_tools.common import closed_loop
        from jackal_aic_tools.track import plant_limits
        good = closed_loop.plant_motor(self.PLANT)
        for key, value in (("load_observer_inertia", 0.0), ("load_observer_inertia", None),
                           ("proportional_limit", -1.0), ("accel_feedforward_limit", float("nan")),
                           ("max_torque", 0.0)):
            motor = dict(good)
            if value is None:
                del motor[key]
            else:
                motor[key] = value
            with self.assertRaises(ValueError) as e:
                plant_limits.wheel_acceleration(motor)
            self.assertIn("motor." + key, str(e.exception))
        with self.assertRaises(ValueError):
            plant_limits.floor_accelerations(good, 0.098, 0.0)
        with tempfile.TemporaryDirectory(prefix="track_accel_") as tmp:
            bad = os.path.join(tmp, "bad.yaml")
            with open(bad, "w") as f:
                f.write("motor: [1, 2\n")
            with self.assertRaises(ValueError) as e:
                closed_loop.plant_motor(self.PLANT, [bad])
            self.assertIn("bad.yaml", str(e.exception))
            urdf = os.path.join(tmp, "robot.urdf")
            with open(urdf, "w") as f:
                f.write("<robot name='r'><link name='base_link'/></robot>")
            with self.assertRaises(ValueError) as e:
                plant_limits.urdf_geometry(urdf)
            self.assertIn("front_left_wheel", str(e.exception))

    def test_bounded_floor_is_above_the_floor(self):
        """On a short profile (aic_track_metrics) the acceleration-bounded floor is >= the unlimited
        one on both channels, and > on the step's vx (4.2 m/s^2: 0.12 s more to reach 0.5 m/s)."""
        from jackal_aic_tools.track import driving
        acc = self.limits()
        with tempfile.TemporaryDirectory(prefix="track_accel_") as tmp:
            profile = os.path.join(tmp, "short.csv")
            with open(profile, "w") as f:
                f.write(SHORT)
            cache = {}
            floor = driving.floor_rms(profile, 0.1187, cache)
            bounded = driving.floor_rms(profile, 0.1187, cache, acc["linear"], acc["angular"])
            # As aic_track.py takes it: each wheel bounded, the aim held for the 50 Hz action period.
            wheels = driving.floor_rms(profile, 0.1187, cache, period=0.02,
                                       wheels=(acc["wheel_acceleration"], 0.098, 0.37559))
            self.assertEqual(len(cache), 3)
            for ch in ("vx", "wz"):
                self.assertGreaterEqual(bounded[ch], floor[ch], ch)
                self.assertGreaterEqual(wheels[ch], floor[ch], ch)
            self.assertGreater(bounded["vx"], floor["vx"] * 1.01)
            self.assertGreater(wheels["vx"], floor["vx"] * 1.01)


class RobotModelWheelLoopCheck(unittest.TestCase):
    """The robot model's wheel loop from the MCU's motor keys (common.wheel_loop_model): its
    equations, its refusals, and config/default.yaml holding sim/config/plant.yaml's."""

    PLANT = os.path.join(ROOT, "sim", "config", "plant.yaml")
    KEYS = ("latency", "wheel_time_constant", "wheel_acceleration", "wheel_feedforward",
            "wheel_feedforward_acceleration")

    def test_the_default_configuration_holds_the_plants_wheel_loop(self):
        """aic_params' effective values of config/default.yaml (its own keys and the schema's
        defaults) are the model of the plant's identified loop, to their 4 written digits."""
        from jackal_aic_tools.common import closed_loop, wheel_loop_model
        keys = wheel_loop_model.robot_model_keys(closed_loop.plant_motor(self.PLANT))
        aic_params = cli.find_executable("aic_params", SCRIPT, "test")
        out = subprocess.run([aic_params, "--yaml", "--config", os.path.join(ROOT, "config", "default.yaml")],
                             capture_output=True, text=True, check=False)
        self.assertEqual(out.returncode, 0, out.stderr)
        effective = yaml.safe_load(out.stdout)
        self.assertEqual(sorted(keys), sorted(self.KEYS))
        for key in self.KEYS:
            self.assertAlmostEqual(effective[key], keys[key], delta=5e-4 * keys[key], msg=key)

    def test_the_equations(self):
        from jackal_aic_tools.common import wheel_loop_model
        motor = {"command_delay": 0.1, "setpoint_time_constant": 0.01, "speed_kp": 2.0, "proportional_limit": 0.0,
                 "accel_feedforward": 0.05, "accel_feedforward_limit": 1.0, "load_observer_inertia": 0.1,
                 "max_torque": 4.0}
        keys = wheel_loop_model.robot_model_keys(motor)
        self.assertAlmostEqual(keys["latency"], 0.1)
        self.assertAlmostEqual(keys["wheel_time_constant"], 0.01 + 0.1 / 2.0)
        self.assertAlmostEqual(keys["wheel_acceleration"], 4.0 / 0.1)  # no clamp: the current limit
        self.assertAlmostEqual(keys["wheel_feedforward"], 0.5)
        self.assertAlmostEqual(keys["wheel_feedforward_acceleration"], 10.0)
        # The equations written into YAML comments name the keys each is computed from.
        self.assertEqual(sorted(wheel_loop_model.EQUATIONS), sorted(wheel_loop_model.DEPENDS_ON))
        for key, depends_on in wheel_loop_model.DEPENDS_ON.items():
            for motor_key in depends_on:
                self.assertIn(motor_key, wheel_loop_model.EQUATIONS[key], key)
        # A feed-forward without its own clamp reaches the current limit: no proportional path
        # beyond it, no model.
        with self.assertRaisesRegex(ValueError, "no proportional path"):
            wheel_loop_model.robot_model_keys(dict(motor, accel_feedforward_limit=0.0))
        for key, value in (("speed_kp", 0.0), ("command_delay", -0.1), ("accel_feedforward", float("inf")),
                           ("setpoint_time_constant", "fast"), ("load_observer_inertia", None)):
            bad = dict(motor)
            if value is None:
                del bad[key]
            else:
                bad[key] = value
            with self.assertRaisesRegex(ValueError, "motor." + key):
                wheel_loop_model.robot_model_keys(bad)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("track", TrackCheck, FloorAccelCheck, RobotModelWheelLoopCheck)
