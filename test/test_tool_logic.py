#!/usr/bin/env python3
"""Python unit test (no roscore, no build): the logic of the experiment tools that run ROS
(aic_sweep.py, aic_node_load.py, aic_ros_soak.py, aic_experiment.py: jackal_aic_tools.experiment.sweep,
.experiment, jackal_aic_tools.robustness.node_watch, .soak), the launcher and stop routine of
ROS processes (jackal_aic_tools.common.ros_process), of the report and summary printers
(jackal_aic_tools.common.report, .summary), of dev/failure_summary.py, dev/mutants.py's list and
dev/ablations.py's list and page, and the
plant-limited pairs of the tracking benchmark (jackal_aic_tools.track.plant_limits, driving.judge_tracking,
track_suite.metric_limited) and the classical peer beside them (driving.evaluate's peer, the scorecard's
table 6j), on inputs made up here.
"""
import argparse
import contextlib
import glob
import io
import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from unittest import mock

import numpy as np

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "src"))
from jackal_aic_tools.common import report, ros_process, summary  # noqa: E402
from jackal_aic_tools.experiment import experiment, sweep  # noqa: E402
from jackal_aic_tools.robustness import node_watch, soak  # noqa: E402
from jackal_aic_tools.track import driving, ideal_cache, plant_limits, track_suite  # noqa: E402


def step_result(name, status="ok", rise=0.1, settle=0.3, overshoot=2.0):
    """A result dict of aic_experiment with one linear 0 -> 0.5 m/s segment."""
    measured = {"rise_time": rise, "settling_time": settle, "overshoot": overshoot, "steady_state_error": 0.001}
    return {"name": name, "controller": "aic", "status": status, "reason": "made up", "files": {},
            "segments": [{"channel": "vx", "start": 0.0, "target": 0.5, "metrics": {"measured": measured}}]}


def proc_stat_cpu(pid):
    """utime + stime [s] of /proc/<pid>/stat read here (fields 14 and 15, counted after the name's
    last ')'), to hold psutil's figures against."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / float(os.sysconf("SC_CLK_TCK"))


class NodeWatchTest(unittest.TestCase):
    """robustness.node_watch's resource use (psutil) against /proc read directly."""

    def test_this_process_cpu_time_and_memory(self):
        pid = os.getpid()
        before = node_watch.cpu_seconds(pid)
        spin_until = time.process_time() + 0.2  # CPU time, whatever the host's load
        while time.process_time() < spin_until:
            pass
        after = node_watch.cpu_seconds(pid)
        self.assertGreater(after, before + 0.1)
        self.assertAlmostEqual(after, proc_stat_cpu(pid), delta=0.05)
        rss, cpu = node_watch.rss_and_cpu(pid)
        with open("/proc/self/status") as f:
            vm_rss = int([l for l in f if l.startswith("VmRSS:")][0].split()[1])
        self.assertGreater(rss, 1000)  # KiB: a Python interpreter
        self.assertAlmostEqual(rss, vm_rss, delta=512)  # VmRSS [KiB], the same count of pages
        self.assertAlmostEqual(cpu, proc_stat_cpu(pid), delta=0.05)
        self.assertEqual(len(node_watch.loadavg().split()), 3)

    def test_threads_by_the_name_they_set(self):
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        ready, done, tid = threading.Event(), threading.Event(), []

        def named():  # the name as the node's threads set it (pthread_setname_np: PR_SET_NAME)
            libc.prctl(15, b"aic_probe", 0, 0, 0)
            tid.append(threading.get_native_id())
            spin_until = time.thread_time() + 0.1  # this thread's CPU time, whatever the host's load
            while time.thread_time() < spin_until:
                pass
            ready.set()
            done.wait()

        worker = threading.Thread(target=named)
        worker.start()
        try:
            self.assertTrue(ready.wait(30.0))
            names = node_watch.thread_times(os.getpid())
        finally:
            done.set()
            worker.join()
        with open("/proc/self/comm") as f:
            self.assertIn("%s:%d" % (f.read().strip(), os.getpid()), names)
        self.assertIn("aic_probe:%d" % tid[0], names)
        self.assertGreater(names["aic_probe:%d" % tid[0]], 0.05)  # its 0.1 s, in clock ticks
        self.assertGreaterEqual(len(names), 2)


class RosProcessTest(unittest.TestCase):
    """common.ros_process's launcher and stop routine on plain child processes (no ROS): the whole
    process group gets SIGINT, SIGKILL follows after the timeout, an ended group is no error; the
    nodes of a launch are found among its descendants."""

    CHILD = ("import signal, subprocess, sys, time\n"
             "if sys.argv[1] == 'ignore':\n"
             "    signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
             "else:  # a shell's background job inherits SIGINT ignored: Python then raises nothing\n"
             "    signal.signal(signal.SIGINT, signal.default_int_handler)\n"
             "grandchild = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)', '__name:=probe'])\n"
             "try:\n"
             "    print(grandchild.pid, flush=True)\n"
             "    time.sleep(60)\n"
             "except KeyboardInterrupt:\n"
             "    grandchild.wait()\n"
             "    sys.exit(7)\n")

    def start(self, mode):
        proc = ros_process.start([sys.executable, "-c", self.CHILD, mode], stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL)
        self.addCleanup(lambda: proc.poll() is None and ros_process.stop(proc, 1.0))
        self.addCleanup(proc.stdout.close)
        grandchild = int(proc.stdout.readline())
        return proc, grandchild

    @staticmethod
    def gone(pid, timeout=5.0):
        """True once ``pid`` no longer runs (or is a zombie) within ``timeout`` [s]."""
        import psutil
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if psutil.Process(pid).status() == psutil.STATUS_ZOMBIE:
                    return True
            except psutil.NoSuchProcess:
                return True
            time.sleep(0.02)
        return False

    def test_sigint_reaches_the_whole_group(self):
        proc, grandchild = self.start("interrupt")
        self.assertNotEqual(os.getpgid(proc.pid), os.getpgid(0))  # a group of its own
        self.assertEqual(os.getpgid(grandchild), proc.pid)
        # (its __name:= argument is there once it has exec'd: wait_for_nodes polls, find_node looks once)
        self.assertEqual(ros_process.wait_for_nodes(("probe",), proc, timeout=5.0), {"probe": grandchild})
        self.assertEqual(ros_process.find_node("probe", proc.pid), grandchild)
        self.assertIsNone(ros_process.find_node("other", proc.pid))
        t = time.monotonic()
        self.assertEqual(ros_process.stop(proc, timeout=10.0), 7)  # its KeyboardInterrupt handler ran
        self.assertLess(time.monotonic() - t, 5.0)
        self.assertTrue(self.gone(grandchild))

    def test_sigkill_after_the_timeout(self):
        proc, grandchild = self.start("ignore")
        t = time.monotonic()
        self.assertEqual(ros_process.stop(proc, timeout=0.5), -9)
        self.assertGreaterEqual(time.monotonic() - t, 0.5)
        self.assertTrue(self.gone(grandchild))  # the grandchild (SIGINT ended it) or SIGKILL

    def test_an_ended_process_is_no_error(self):
        proc = ros_process.start([sys.executable, "-c", "import sys; sys.exit(3)"])
        proc.wait()
        self.assertEqual(ros_process.stop(proc), 3)
        self.assertFalse(ros_process.interrupt(proc))

    def test_command_line_and_free_port(self):
        self.assertEqual(ros_process.roslaunch_command("sim.launch", ["base:=direct"], port=11411),
                         ["roslaunch", "-p", "11411", "jackal_aic", "sim.launch", "base:=direct"])
        self.assertEqual(ros_process.roslaunch_command("robot.launch"), ["roslaunch", "jackal_aic", "robot.launch"])
        port = ros_process.free_port()
        self.assertTrue(1024 <= port <= 65535)


class SweepTest(unittest.TestCase):

    def args(self, **kw):
        a = argparse.Namespace(belief_rate=None, action_rate=None, tau=None, k_mu=None, k_a=None, integrator=None,
                               param=[], controller=["aic"], step=None, profile="step")
        for k, v in kw.items():
            setattr(a, k, v)
        return a

    def test_dimensions_in_order_with_parsed_param_values(self):
        dims = sweep.dimensions(self.args(tau=[0.03, 0.01], param=[["var_y", "[2,2,1e5,1e5]"]],
                                          controller=["aic", "stock"], step=[0.1, 0.5]))
        self.assertEqual([d for d, _ in dims], ["tau", "var_y", "controller", "step"])
        self.assertEqual(dims[1][1], [[2, 2, 1e5, 1e5]])  # 1e5 a number, not YAML 1.1's string
        with self.assertRaises(ValueError):
            sweep.dimensions(self.args(param=[["k_a"]]))
        with self.assertRaises(ValueError):
            sweep.dimensions(self.args(step=[0.5], profile="square"))

    def test_labels_and_the_stock_controller_ignores_aic_settings(self):
        self.assertEqual(sweep.label("belief_rate", 50), "belief 50 Hz")
        self.assertEqual(sweep.label("var_mu", 2.0), "var_mu=2")
        a = {"controller": "stock", "tau": 0.03, "step": 0.5}
        b = {"controller": "stock", "tau": 0.01, "step": 0.5}
        self.assertEqual(sweep.run_key(a), sweep.run_key(b))
        self.assertNotEqual(sweep.run_key(dict(a, controller="aic")), sweep.run_key(dict(b, controller="aic")))

    def test_combined_plot_styles_zoom_and_pdf(self):
        # two rows x two columns of made-up runs (experiment CSV layout), a step at 0.5 s zoomed
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from jackal_aic_tools.common import figures
        seen = {}
        real_savefig = plt.Figure.savefig

        def keep(fig, path, **kw):
            seen[os.path.basename(path)] = [(a.get_xlim(), [(ln.get_label(), ln.get_color()) for ln in a.get_lines()])
                                            for a in fig.axes]
            return real_savefig(fig, path, **kw)
        plt.Figure.savefig = keep
        try:
            with tempfile.TemporaryDirectory() as tmp:
                grid = {}
                for r in ("0.03", "0.01"):
                    for c in ("aic", "stock"):
                        csvp = os.path.join(tmp, "%s_%s.csv" % (r, c))
                        with open(csvp, "w") as f:
                            f.write("t,stamp,source,setpoint_vx,setpoint_wz,odom_vx,odom_wz\n")
                            for k in range(-50, 200):
                                t = 0.02 * k
                                f.write("%g,0,odom,,,%g,0\n" % (t, 0.5 * (t > 0.6)))
                                if k >= 0:
                                    f.write("%g,0,setpoint,%g,0,,\n" % (t, 0.5 * (t >= 0.5)))
                        grid[(r, "[%s]" % c)] = {"status": "ok", "files": {"csv": csvp},
                                                 "segments": [{"channel": "vx"}]}
                path = os.path.join(tmp, "sweep.png")
                self.assertEqual(sweep.combined_plot(path, [0.03, 0.01], "tau", [("aic",), ("stock",)], ["controller"],
                                                     grid, "a sweep title " * 20, [0.5]), path)
                self.assertGreater(os.path.getsize(os.path.join(tmp, "sweep.pdf")), 1000)
        finally:
            plt.Figure.savefig = real_savefig
        axes = seen["sweep.png"]
        self.assertEqual(len(axes), 4)  # per row the whole run and the zoom
        main, zoom = axes[0], axes[1]
        self.assertEqual(main[1], [("aic", figures.style(0)["color"]), ("set point", "k"),
                                   ("stock", figures.style(1)["color"])])
        self.assertEqual(zoom[1], main[1])
        np.testing.assert_allclose(zoom[0], (0.5 - figures.ZOOM_LEAD, 0.5 + figures.ZOOM_WINDOW))

    def test_headline_is_the_worst_transition_or_none(self):
        res = {"segments": [step_result("a", rise=0.1, settle=0.3)["segments"][0],
                            step_result("b", rise=0.2, settle=0.25)["segments"][0]]}
        self.assertEqual(sweep.headline(res), (0.2, 0.3))
        res["segments"][1]["metrics"]["measured"]["settling_time"] = None  # one never settled
        self.assertEqual(sweep.headline(res), (0.2, None))
        self.assertEqual(sweep.headline({"segments": []}), (None, None))


class ExperimentTest(unittest.TestCase):

    def test_parse_override(self):
        self.assertEqual(experiment.parse_override("k_a=10"), ("k_a", 10))
        self.assertEqual(experiment.parse_override(" var_y = [2, 1e5] "), ("var_y", [2, 1e5]))
        self.assertEqual(experiment.parse_override("integrator=exact"), ("integrator", "exact"))
        for bad in ("k_a", "=3"):
            with self.assertRaises(ValueError):
                experiment.parse_override(bad)


class SoakTest(unittest.TestCase):

    def test_belief_steps_from_the_loops_status(self):
        self.assertIsNone(soak.belief_steps({}))
        self.assertIsNone(soak.belief_steps({"jackal_AIC: loops": {"_stamp": 3.0}}))
        self.assertEqual(soak.belief_steps({"jackal_AIC: loops": {"_stamp": 3.0, "belief steps": "1500"}}),
                         (3.0, 1500))

    @staticmethod
    def figures(**changes):
        """A made-up figures dict as soak.soak() builds it."""
        fig = {"minutes": 30.02, "seed": 1, "fault_every": 20.0, "alive": True, "faults": 90,
               "injected": ["gyro freeze 0 4", "imu dropout 0 3"],
               "nodes": {"jackal_AIC": {"rss_start": 14236, "rss_end": 14300, "cpu": 1.83},
                         "jackal_plant": {"rss_start": 15004, "rss_end": 15012, "cpu": 4.5}},
               "cmd_rate": 49.9, "js_rate": 48.0, "commands": 90000, "non_finite": 0, "over_limit": 0,
               "max_abs_wheel": 12.4781, "limit": 20.0, "findings": [], "belief_rate": 1066.4,
               "belief_nominal": 1000.0, "events": ["isolated omega_left"], "runaway_resets": "0", "dropped": 102,
               "no_imu": 102, "stale_events": 0, "belief_overruns": "0", "action_overruns": "1"}
        fig.update(changes)
        return fig

    def test_markdown_figures(self):
        md = soak.markdown(self.figures(), ["--minutes", "30", "--seed", "1", "--output", "x.md"])
        self.assertTrue(md.startswith("# ROS soak"))
        self.assertIn("`scripts/aic_ros_soak.py --minutes 30 --seed 1 --output x.md`", md)
        self.assertIn("| wall time | 30.0 min (real time, after the warm-up) |", md)
        self.assertIn("| jackal_AIC resident memory | 14236 KiB at start, 14300 KiB at the end; growth +64 KiB |", md)
        self.assertIn("| jackal_plant CPU | 4.5 % of one core |", md)
        self.assertIn("| /cmd_drive rate | 49.90 Hz (nominal 50: -0.20 %) |", md)
        self.assertIn("| commands beyond max_wheel_speed | 0 (limit 20 rad/s; max abs wheel 12.478 rad/s) |", md)
        self.assertIn("| belief steps | 1066.40 Hz (nominal 1000: +6.640 %) |", md)
        self.assertIn("| belief / action overruns | 0 / 1 |", md)
        self.assertIn("`gyro freeze 0 4`; `imu dropout 0 3`", md)
        self.assertIn("| node alive at the end | yes |", md)
        self.assertNotIn("Findings", md)
        for line in md.splitlines():
            if line.startswith("|"):
                self.assertEqual(line.count("|"), 3, line)  # two columns, no stray bar

    def test_findings_and_missing_figures(self):
        fig = self.figures(alive=False, non_finite=1, findings=["non-finite command [nan, 0.0] at 5.0 s"],
                           belief_rate=None)
        md = soak.markdown(fig)
        self.assertIn("`scripts/aic_ros_soak.py --seed 1`", md)
        self.assertIn("| node alive at the end | no |", md)
        self.assertIn("- non-finite command [nan, 0.0] at 5.0 s", md)
        self.assertNotIn("belief steps", md)
        lines = soak.summary_lines(fig)
        self.assertIn("  FINDING: the launch ended before the soak did", lines)
        self.assertEqual(lines[-1], "  FINDING: non-finite command [nan, 0.0] at 5.0 s")
        self.assertTrue(lines[0].startswith("soak: 30.0 min, seed 1, 90 faults injected (every 20 s)"))


class ReportAndSummaryTest(unittest.TestCase):

    def test_run_table_rows(self):
        text = report.run_table([step_result("run_a", overshoot=2.5), dict(step_result("run_b"), segments=[])])
        lines = text.splitlines()
        self.assertIn("rise [s]", lines[0])
        row_a = [l for l in lines if l.startswith("run_a")]
        self.assertEqual(len(row_a), 1)
        self.assertIn("vx 0->0.5 m/s", row_a[0])
        self.assertIn("2.5", row_a[0])
        self.assertTrue(any(l.startswith("run_b") for l in lines))

    def test_tracking_table_and_path_summary(self):
        r = {"name": "track", "tracking": {"truth": {"vx": {"rms": 0.0123, "max": 0.05},
                                                     "wz": {"rms": 0.0456, "max": 0.2}}},
             "path": {"final_position_error": 0.31, "max_position_error": 0.42, "final_heading_error": 0.05}}
        text = report.tracking_table([r, {"name": "broken", "tracking_error": "no odometry"}])
        row = [l for l in text.splitlines() if l.startswith("track")][0].split()
        self.assertEqual(row[1:8], ["truth", "0.012", "0.050", "0.046", "0.200", "0.310", "0.420"])
        self.assertIn("error: no odometry", text)
        self.assertEqual(report.path_summary(None), "")
        self.assertEqual(report.path_summary(r["path"]), "drift: end 0.310 m, max 0.420 m, heading end 0.050 rad")

    def run_summary(self, results):
        with tempfile.TemporaryDirectory() as tmp:
            paths = []
            for i, r in enumerate(results):
                paths.append(os.path.join(tmp, "r%d.json" % i))
                if r is not None:
                    with open(paths[-1], "w") as f:
                        json.dump(r, f)
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                code = summary.main(paths)
        return code, out.getvalue()

    def test_summary_exit_status_follows_the_worst_run(self):
        self.assertEqual(self.run_summary([step_result("a")])[0], 0)
        code, text = self.run_summary([step_result("a"), step_result("b", status="unstable")])
        self.assertEqual(code, 2)
        self.assertIn("b: unstable", text)
        code, text = self.run_summary([step_result("a", status="unstable"), None])  # an unreadable file
        self.assertEqual(code, 1)
        self.assertIn("no readable result", text)


def plant(torque_limited=0.0, lag=(0.1, 0.2), slip=(0.01, 0.02)):
    """closed_loop_run's "plant" figures: torque share, wheel-loop lag and slip (vx, wz) RMS."""
    return {"torque_limited": torque_limited, "wheel_loop": {"vx": lag[0], "wz": lag[1]},
            "slip": {"vx": slip[0], "wz": slip[1]}}


def track_result(vx, wz, command_delay=0.12, ideal=None, plant_figures=None):
    """A closed_loop_run --profile result with the ground truth's RMS errors vx, wz (and, for an
    ideal run, its "ideal" and "plant" figures)."""
    r = {"command_delay": command_delay, "tracking": {"truth": {"vx": {"rms": vx}, "wz": {"rms": wz}}}}
    if ideal:
        r["ideal"] = {"runs": 8, "best": 5}
        r["plant"] = plant_figures or plant()
    return r


def judge_one_pair(aic, stock):
    """driving.judge_tracking on one pair (profile a.csv, the default plant, no ideal run, a floor of
    0.1 on both channels) whose AIC and stock results are ``aic``, ``stock``: (its verdict, its rows)."""
    res = {("track", "a.csv", "default", "aic"): (aic, None),
           ("track", "a.csv", "default", "stock"): (stock, None)}
    out = {"tracking": []}
    ok = driving.judge_tracking(res, ["a.csv"], ["default"], False, out,
                                floor_of=lambda p, latency, cache: {"vx": 0.1, "wz": 0.1})
    return ok, out["tracking"]


class PlantLimitsTest(unittest.TestCase):
    """plant_limits.classify / reason, and the judged set of driving.judge_tracking: plant-limited
    channels are reported apart, the others judged."""

    def test_a_channel_is_limited_above_the_ratio_only(self):
        floor = {"vx": 0.01, "wz": 0.02}
        ideal = {"vx": 0.02, "wz": 0.01, "plant": plant()}
        out = plant_limits.classify(ideal, floor)
        self.assertIsNone(out["wz"])
        self.assertTrue(out["vx"].startswith("ideal 2.0 x floor on vx: "), out["vx"])
        # The control: just below and just above PLANT_LIMIT_RATIO flips the verdict.
        below = dict(ideal, vx=0.99 * plant_limits.PLANT_LIMIT_RATIO * floor["vx"])
        above = dict(ideal, vx=1.01 * plant_limits.PLANT_LIMIT_RATIO * floor["vx"])
        self.assertIsNone(plant_limits.classify(below, floor)["vx"])
        self.assertIsNotNone(plant_limits.classify(above, floor)["vx"])
        self.assertIsNone(plant_limits.classify(ideal, floor, limit=2.5)["vx"])
        # A zero floor: limited when the ideal misses at all.
        self.assertIsNone(plant_limits.classify(dict(ideal, vx=0.0), dict(floor, vx=0.0))["vx"])
        self.assertIsNotNone(plant_limits.classify(ideal, dict(floor, vx=0.0))["vx"])
        for bad in (-0.01, float("nan"), float("inf")):
            with self.assertRaises(ValueError):
                plant_limits.classify(dict(ideal, wz=bad), floor)

    def test_the_reason_is_the_largest_measured_part(self):
        # Slip above the wheel loop's lag: the wheels slip.
        r = plant_limits.reason("vx", 2.8, plant(lag=(0.19, 0.03), slip=(0.27, 0.1)))
        self.assertIn("the wheels slip against the body (RMS 0.27 m/s", r)
        # The lag above the slip: the torque limit when the torque is at its limit often enough ...
        share = plant_limits.TORQUE_LIMITED_SHARE
        r = plant_limits.reason("wz", 2.4, plant(torque_limited=share, lag=(0.1, 0.9), slip=(0.01, 0.02)))
        self.assertIn("the wheel loop lags its set point (RMS 0.9 rad/s)", r)
        self.assertTrue(r.endswith("the motor's torque limit"), r)
        # ... else the MCU's loop (the control: a share just below flips the cause).
        r = plant_limits.reason("wz", 2.4, plant(torque_limited=0.99 * share, lag=(0.1, 0.9), slip=(0.01, 0.02)))
        self.assertTrue(r.endswith("the MCU's loop, not the motor"), r)
        self.assertTrue(r.startswith("ideal 2.4 x floor on wz: "), r)
        with self.assertRaises(KeyError):
            plant_limits.reason("vy", 2.0, plant())

    def test_gmean_split_and_metric_kinds(self):
        self.assertEqual(plant_limits.split([(1.0, False), (2.0, True), (3.0, None)]), ([1.0, 3.0], [2.0]))
        g, n = plant_limits.gmean([2.0, 8.0, None])
        self.assertAlmostEqual(g, 4.0)
        self.assertEqual(n, 2)
        self.assertEqual(plant_limits.gmean([]), (None, 0))
        self.assertFalse(track_suite.metric_limited("vx_rms", ["wz"]))
        self.assertTrue(track_suite.metric_limited("wz_max", ["wz"]))
        self.assertTrue(track_suite.metric_limited("drift_final", ["vx"]))
        self.assertFalse(track_suite.metric_limited("heading_final", []))

    def judge(self, ideal_wz):
        """driving.judge_tracking on two made-up pairs: pair a follows (AIC / stock 0.5 on both
        channels), pair b's wz has AIC / stock 1.5 and the ideal controller's wz RMS ``ideal_wz``
        against a floor of 0.1 rad/s."""
        res = {("track", "a.csv", "default", "aic"): (track_result(0.05, 0.05), None),
               ("track", "a.csv", "default", "stock"): (track_result(0.1, 0.1), None),
               ("track", "a.csv", "default", "ideal"): (track_result(0.01, 0.01, ideal=True), None),
               ("track", "b.csv", "default", "aic"): (track_result(0.05, 0.3), None),
               ("track", "b.csv", "default", "stock"): (track_result(0.1, 0.2), None),
               ("track", "b.csv", "default", "ideal"): (track_result(0.01, ideal_wz, ideal=True), None)}
        out = {"tracking": []}
        ok = driving.judge_tracking(res, ["a.csv", "b.csv"], ["default"], True, out,
                                    floor_of=lambda p, latency, cache: {"vx": 0.1, "wz": 0.1})
        return ok, out

    def test_judged_set_leaves_out_the_plant_limited_channels(self):
        ok, out = self.judge(ideal_wz=0.25)  # 2.5 x the floor: b's wz is plant-limited
        a, b = out["tracking"]
        self.assertIsNone(a["limited_wz"])
        self.assertIn("ideal 2.5 x floor on wz", b["limited_wz"])
        self.assertAlmostEqual(b["ideal_wz_ratio"], 2.5)
        self.assertTrue(b["pass"], "a plant-limited channel is not judged")
        self.assertAlmostEqual(out["gmean"]["wz"], 0.5)     # a's wz only
        self.assertAlmostEqual(out["gmean"]["all"], 0.5)    # a's two, b's vx: all 0.5
        self.assertAlmostEqual(out["aic_floor_gmean"]["wz"], 0.5)
        self.assertAlmostEqual(out["limited_gmean"]["aic_stock"], 1.5)
        self.assertAlmostEqual(out["limited_gmean"]["aic_ideal"], 0.3 / 0.25)
        self.assertEqual(out["limited_gmean"]["n"], 1)
        self.assertTrue(ok, "every judged channel passes, their geometric mean 0.5 within TRACK_GMEAN_BOUND")
        # The control: the ideal controller follows b's wz (0.5 x the floor): judged, and it fails.
        ok, out = self.judge(ideal_wz=0.05)
        b = out["tracking"][1]
        self.assertIsNone(b["limited_wz"])
        self.assertFalse(b["pass"])
        self.assertFalse(ok)
        self.assertAlmostEqual(out["gmean"]["wz"], math.sqrt(0.5 * 1.5))
        self.assertEqual(out["limited_gmean"]["n"], 0)
        self.assertIsNone(out["limited_gmean"]["aic_stock"])


class PeerTest(unittest.TestCase):
    """The classical peer in the driving set: driving.evaluate(peer=True) runs it on every tracking
    pair (job controller "pi", the runner's peer_config), judge_tracking reports its errors and
    geometric means without judging them, and the scorecard prints them as table 6j."""

    FLOOR = staticmethod(lambda p, latency, cache: {"vx": 0.1, "wz": 0.1})

    @staticmethod
    def res(peer_wz_b=0.25):
        """Two pairs as PlantLimitsTest.judge's (b's wz plant-limited: ideal 2.5 x the floor), with the
        peer's runs: on a vx 0.04, wz 0.1; on b vx 0.05, wz ``peer_wz_b``."""
        return {("track", "a.csv", "default", "aic"): (track_result(0.05, 0.05), None),
                ("track", "a.csv", "default", "stock"): (track_result(0.1, 0.1), None),
                ("track", "a.csv", "default", "ideal"): (track_result(0.01, 0.01, ideal=True), None),
                ("track", "a.csv", "default", "pi"): (track_result(0.04, 0.1), None),
                ("track", "b.csv", "default", "aic"): (track_result(0.05, 0.3), None),
                ("track", "b.csv", "default", "stock"): (track_result(0.1, 0.2), None),
                ("track", "b.csv", "default", "ideal"): (track_result(0.01, 0.25, ideal=True), None),
                ("track", "b.csv", "default", "pi"): (track_result(0.05, peer_wz_b), None)}

    def judge(self, res):
        out = {"tracking": []}
        ok = driving.judge_tracking(res, ["a.csv", "b.csv"], ["default"], True, out, floor_of=self.FLOOR)
        return ok, out

    def test_peer_ratios_over_the_plant_following_channels(self):
        ok, out = self.judge(self.res())
        a, b = out["tracking"]
        self.assertEqual((a["peer_vx"], a["peer_wz"], b["peer_vx"], b["peer_wz"]), (0.04, 0.1, 0.05, 0.25))
        # Plant-following: a's vx, a's wz, b's vx (b's wz is plant-limited and left out).
        self.assertAlmostEqual(out["aic_peer_gmean"]["vx"], math.sqrt(0.05 / 0.04 * 0.05 / 0.05))
        self.assertAlmostEqual(out["aic_peer_gmean"]["wz"], 0.5)
        self.assertAlmostEqual(out["aic_peer_gmean"]["all"], (0.05 / 0.04 * 1.0 * 0.5) ** (1.0 / 3.0))
        self.assertAlmostEqual(out["peer_floor_gmean"]["vx"], math.sqrt(0.4 * 0.5))
        self.assertAlmostEqual(out["peer_floor_gmean"]["wz"], 1.0)
        self.assertAlmostEqual(out["peer_stock_gmean"]["all"], (0.4 * 1.0 * 0.5) ** (1.0 / 3.0))
        self.assertTrue(ok)
        # The control: without the peer's runs no peer figure, and the rest is the same.
        bare = {k: v for k, v in self.res().items() if k[3] != "pi"}
        ok_bare, out_bare = self.judge(bare)
        self.assertNotIn("aic_peer_gmean", out_bare)
        self.assertNotIn("peer_vx", out_bare["tracking"][0])
        self.assertEqual(ok_bare, ok)
        self.assertEqual(out_bare["gmean"], out["gmean"])
        self.assertEqual([dict((k, v) for k, v in r.items() if not k.startswith("peer_")) for r in out["tracking"]],
                         out_bare["tracking"])

    def test_a_bad_peer_is_not_judged(self):
        good_ok, good = self.judge(self.res())
        res = self.res(peer_wz_b=50.0)
        res[("track", "a.csv", "default", "pi")] = (track_result(10.0, 10.0), None)
        ok, out = self.judge(res)
        self.assertEqual(ok, good_ok)
        self.assertTrue(ok)
        self.assertEqual([r["pass"] for r in out["tracking"]], [r["pass"] for r in good["tracking"]])
        self.assertLess(out["aic_peer_gmean"]["all"], 0.05)
        self.assertEqual(driving.cost(out), driving.cost(good))

    def test_evaluate_runs_the_peer_only_when_asked(self):
        class Runner:
            def __init__(self):
                self.jobs = []

            def run_all(self, jobs):
                self.jobs += jobs
                rms = {"aic": 0.05, "stock": 0.1, "pi": 0.04}
                return {j[0]: (track_result(rms[j[1]], rms[j[1]]), None) for j in jobs}

        for peer in (False, True):
            runner = Runner()
            with mock.patch.object(driving, "floor_rms", self.FLOOR):
                ev = driving.evaluate(runner, ROOT, profiles=["a.csv"], variants=["default", "v.yaml"],
                                      steps=False, ideal=False, peer=peer)
            peer_jobs = [j for j in runner.jobs if j[1] == "pi"]
            self.assertEqual(len(peer_jobs), 2 if peer else 0)
            self.assertEqual(len(runner.jobs), 6 if peer else 4)
            self.assertEqual("aic_peer_gmean" in ev, peer)
            self.assertTrue(ev["pass"])
        self.assertEqual(sorted(j[3] or "" for j in peer_jobs), ["", "v.yaml"])
        self.assertAlmostEqual(ev["aic_peer_gmean"]["all"], 0.05 / 0.04)

    def test_the_runner_runs_the_peer_with_its_own_yaml(self):
        runner = driving.Runner("closed_loop_run", "aic.yaml", "plant.yaml", aic_sets=["k=1"],
                                peer_config="pi.yaml")
        cmd = runner.command("pi", ["--profile", "a.csv"])
        self.assertEqual(cmd[cmd.index("--controller") + 1], "pi")
        self.assertEqual(cmd[cmd.index("--pi-config") + 1], "pi.yaml")
        self.assertNotIn("aic.yaml", cmd)
        self.assertNotIn("--pi-set", cmd)
        # The tuned peer in the AIC's part keeps the runner's settings.
        tuned = driving.Runner("closed_loop_run", "tuned_pi.yaml", "plant.yaml", aic_sets=["k=1"], tuned="pi",
                               peer_config="pi.yaml")
        cmd = tuned.command("aic", ["--profile", "a.csv"])
        self.assertEqual(cmd[cmd.index("--pi-config") + 1], "tuned_pi.yaml")
        self.assertEqual(cmd[cmd.index("--pi-set") + 1], "k=1")
        self.assertNotIn("--pi-config", driving.Runner("closed_loop_run", "aic.yaml", "plant.yaml").command(
            "pi", ["--profile", "a.csv"]))

    def test_table_6j_prints(self):
        from jackal_aic_tools.tune import scorecard, scorecard_print
        ok, out = self.judge(self.res())
        out.update({"steps": [], "deficit": [], "robust": []})
        crit = {}
        scorecard.judge_driving(out, crit)
        self.assertIn("driving_aic_peer_gmean", crit)
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_peer(crit, "config/classical/pi.yaml")
        text = buf.getvalue()
        self.assertIn("6j. The classical peer (reported, not judged)", text)
        self.assertIn("config/classical/pi.yaml", text)
        self.assertIn("over the 3 plant-following channels: AIC / peer %.3f" % out["aic_peer_gmean"]["all"], text)
        self.assertRegex(text, r"a\s+default\s+0\.0400\s+1\.25\s+0\.40\s+0\.1000\s+0\.50\s+1\.00\n")
        self.assertRegex(text, r"b\s+default\s+0\.0500\s+1\.00\s+0\.50\s+0\.2500\s+1\.20 \*\s+2\.50 \*\n")
        # After 6i in the driving tables, and not there without the peer's runs.
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_driving(crit, "config/classical/pi.yaml")
        self.assertIn("\n6j. ", buf.getvalue())
        bare = {k: v for k, v in crit.items() if "peer" not in k}
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_driving(bare, "config/classical/pi.yaml")
        self.assertNotIn("6j.", buf.getvalue())


class EndHeadingTest(unittest.TestCase):
    """driving.judge_heading and its part in judge_tracking: the AIC's end-of-profile |heading error|
    within the stock controller's + HEADING_MARGIN, judged where the plant follows both channels."""

    @staticmethod
    def result(heading):
        return {"path": {"final_heading_error": heading}}

    def test_bound_is_the_stock_error_plus_the_margin(self):
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_heading(row, self.result(-0.11), self.result(0.1)))
        self.assertTrue(row["heading_judged"])
        self.assertAlmostEqual(row["heading_bound"], 0.1 + driving.HEADING_MARGIN, places=12)
        self.assertEqual((row["heading_aic"], row["heading_stock"]), (-0.11, 0.1))
        self.assertFalse(driving.judge_heading(row, self.result(0.1 + driving.HEADING_MARGIN + 1e-6), self.result(-0.1)))
        # A robot that ended facing the other way (tipped over) fails by a wide margin.
        self.assertFalse(driving.judge_heading(row, self.result(-3.0), self.result(-0.14)))

    def test_plant_limited_pairs_and_runs_without_a_path_are_reported_not_judged(self):
        row = {"limited_vx": "ideal 3.0 x floor on vx", "limited_wz": None}
        self.assertTrue(driving.judge_heading(row, self.result(-3.0), self.result(0.0)))
        self.assertFalse(row["heading_judged"])
        self.assertEqual(row["heading_aic"], -3.0)
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_heading(row, {"tracking": {}}, self.result(0.0)))
        self.assertIsNone(row["heading_aic"])
        self.assertTrue(driving.judge_heading(row, self.result(float("nan")), self.result(0.0)))
        self.assertFalse(row["heading_judged"])

    def test_judge_tracking_fails_on_the_heading(self):
        def judge(heading):
            aic = track_result(0.05, 0.05)
            aic.update(self.result(heading))
            stock = track_result(0.1, 0.1)
            stock.update(self.result(0.05))
            return judge_one_pair(aic, stock)
        ok, rows = judge(0.06)
        self.assertTrue(ok)
        ok, rows = judge(0.08)
        self.assertFalse(ok)
        self.assertFalse(rows[0]["heading_pass"])


class StopReversalTest(unittest.TestCase):
    """driving.judge_stop and its part in judge_tracking and the printout: the AIC's largest speed
    against the direction before a stop within the stock controller's + STOP_MARGIN, judged where the
    profile has a stop and the plant follows the speed."""

    @staticmethod
    def stops(reverse, n=2):
        return {"tracking": {"stops": {"stops": n, "reverse_speed_max": reverse, "reverse_travel_max": 0.0,
                                       "window": 1.0}}}

    def test_bound_is_the_stock_reversal_plus_the_margin(self):
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_stop(row, self.stops(0.021), self.stops(0.001)))
        self.assertTrue(row["stop_judged"])
        self.assertEqual((row["stops"], row["stop_aic"], row["stop_stock"]), (2, 0.021, 0.001))
        self.assertAlmostEqual(row["stop_bound"], 0.001 + driving.STOP_MARGIN, places=12)
        # The robot backing up 0.24 m/s after a stop, the stock controller not at all: a fail.
        self.assertFalse(driving.judge_stop(row, self.stops(0.237), self.stops(0.001)))
        self.assertFalse(row["stop_pass"])

    def test_no_stop_a_limited_speed_or_no_figure_is_not_judged(self):
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_stop(row, self.stops(0.5, n=0), self.stops(0.0, n=0)))
        self.assertFalse(row["stop_judged"])
        row = {"limited_vx": "ideal 5.0 x floor on vx", "limited_wz": None}
        self.assertTrue(driving.judge_stop(row, self.stops(0.5), self.stops(0.0)))
        self.assertFalse(row["stop_judged"])
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_stop(row, {"tracking": {}}, self.stops(0.0)))
        self.assertIsNone(row["stop_aic"])
        self.assertTrue(driving.judge_stop(row, self.stops(float("nan")), self.stops(0.0)))
        self.assertFalse(row["stop_judged"])

    def test_judge_tracking_fails_on_a_stop_and_table_6k_shows_it(self):
        def judge(reverse):
            aic = track_result(0.05, 0.05)
            aic["tracking"].update(self.stops(reverse)["tracking"])
            stock = track_result(0.1, 0.1)
            stock["tracking"].update(self.stops(0.001)["tracking"])
            return judge_one_pair(aic, stock)
        ok, rows = judge(0.01)
        self.assertTrue(ok)
        ok, rows = judge(0.2)
        self.assertFalse(ok)
        from jackal_aic_tools.tune import scorecard_print
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_stops(rows)
        text = buf.getvalue()
        self.assertIn("6k. Stops", text)
        self.assertIn("0 of 1 judged runs pass", text)
        self.assertIn("0.200", text)


class PyunitTest(unittest.TestCase):
    """pyunit.shadowing: a test case class that defines ``run`` hides unittest.TestCase.run, and its
    tests would count as passed without running; pyunit.main refuses such a file."""

    def test_a_case_defining_run_is_named(self):
        import pyunit  # test/pyunit.py, beside this file
        class Hides(unittest.TestCase):
            @staticmethod
            def run(x):
                return x

            def test_never_runs(self):
                self.fail("unreachable")

        class Fine(unittest.TestCase):
            def test_runs(self):
                pass

        self.assertEqual(pyunit.shadowing((Fine, Hides)), ["Hides"])
        self.assertEqual(pyunit.shadowing((Fine,)), [])
        # What it guards against: the hidden run executes nothing and reports nothing.
        result = unittest.TestResult()
        unittest.TestLoader().loadTestsFromTestCase(Hides).run(result)
        self.assertEqual((result.testsRun, len(result.failures)), (0, 0))


class HonestBeliefTest(unittest.TestCase):
    """driving.judge_belief and its part in judge_tracking: the steady |belief - truth| of a run is
    judged against BELIEF_BOUND where the plant follows the channel and BELIEF_LIMITED_BOUND where
    it cannot."""

    @staticmethod
    def belief(vx, wz, samples=100):
        return {"belief_settle": 0.5,
                "belief": {"vx": {"steady_mean_abs": vx, "steady_max_abs": 2 * vx, "samples": samples},
                           "wz": {"steady_mean_abs": wz, "steady_max_abs": 2 * wz, "samples": samples}}}

    def test_bounds_follow_the_plant_limits(self):
        row = {"limited_vx": None, "limited_wz": None}
        self.assertTrue(driving.judge_belief(row, self.belief(0.005, 0.009)))
        self.assertEqual((row["belief_vx"], row["belief_max_wz"], row["belief_settle"]), (0.005, 0.018, 0.5))
        self.assertFalse(driving.judge_belief(row, self.belief(0.005, 0.02)))
        # The same belief error on a channel the plant cannot follow (a stall) is within its bound.
        row = {"limited_vx": None, "limited_wz": "ideal 3.0 x floor on wz"}
        self.assertTrue(driving.judge_belief(row, self.belief(0.005, 0.02)))
        self.assertEqual(row["belief_bound_wz"], driving.BELIEF_LIMITED_BOUND)
        self.assertFalse(driving.judge_belief(row, self.belief(0.005, 0.04)))

    def test_a_run_without_a_belief_passes_and_no_sample_is_no_figure(self):
        row = {}
        self.assertTrue(driving.judge_belief(row, {"truth": {}}))
        self.assertIsNone(row["belief_vx"])
        self.assertTrue(driving.judge_belief(row, self.belief(0.5, 0.5, samples=0)))
        self.assertIsNone(row["belief_wz"])

    def test_a_run_that_turned_the_robot_over_is_judged_up_to_the_turnover(self):
        # The whole run carries the tumble (0.04 m/s, above the plant-limited bound); up to the
        # turnover the belief is honest. The judged figures are the upright ones, the whole run's
        # reported beside them.
        tracking = self.belief(0.04, 0.003)
        tracking["turned_over_at"] = 14.23
        tracking["belief_upright"] = self.belief(0.002, 0.0025)["belief"]
        row = {"limited_vx": "ideal 2.9 x floor on vx", "limited_wz": None}
        self.assertTrue(driving.judge_belief(row, tracking))
        self.assertEqual((row["belief_vx"], row["belief_whole_vx"], row["turned_over_at"]), (0.002, 0.04, 14.23))
        # The control: without the turnover the whole run is judged, and fails.
        del tracking["belief_upright"], tracking["turned_over_at"]
        row = {"limited_vx": "ideal 2.9 x floor on vx", "limited_wz": None}
        self.assertFalse(driving.judge_belief(row, tracking))
        self.assertEqual((row["belief_vx"], row["belief_whole_vx"], row["turned_over_at"]), (0.04, 0.04, None))

    def test_judge_tracking_fails_on_a_dishonest_belief_and_the_cost_rises(self):
        def judge(wz_belief):
            aic = track_result(0.05, 0.05)
            aic["tracking"].update(self.belief(0.001, wz_belief))
            res = {("track", "a.csv", "default", "aic"): (aic, None),
                   ("track", "a.csv", "default", "stock"): (track_result(0.1, 0.1), None)}
            out = {"tracking": []}
            ok = driving.judge_tracking(res, ["a.csv"], ["default"], False, out,
                                        floor_of=lambda p, latency, cache: {"vx": 0.1, "wz": 0.1})
            return ok, out
        ok, out = judge(0.002)
        self.assertTrue(ok)
        honest = driving.cost(out)
        ok, out = judge(0.1)  # 10 x the bound
        self.assertFalse(ok)
        self.assertFalse(out["tracking"][0]["belief_pass"])
        self.assertAlmostEqual(driving.cost(out) - honest, driving.BELIEF_WEIGHT * math.log(10.0), places=9)


class IdealCacheTest(unittest.TestCase):
    """jackal_aic_tools.track.ideal_cache: kept ideal runs are used only for the sources, plant, overlay
    and profile that made them; driving.Runner takes them instead of running the ideal controller."""

    def make_tree(self, root):
        for rel in ideal_cache.IDEAL_SOURCES:
            path = os.path.join(root, rel)
            if rel.endswith((".cpp", ".hpp", ".py")):
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w") as f:
                    f.write("// %s\n" % rel)
            else:
                os.makedirs(path, exist_ok=True)
                with open(os.path.join(path, "a.txt"), "w") as f:
                    f.write(rel)
        for name, text in (("plant.yaml", "a: 1\n"), ("profile.csv", "t,vx,wz\n0,0,0\n"), ("copy.csv", "t,vx,wz\n0,0,0\n")):
            with open(os.path.join(root, name), "w") as f:
                f.write(text)

    def test_kept_runs_follow_their_sources_and_inputs(self):
        with tempfile.TemporaryDirectory() as root:
            self.make_tree(root)
            cmd = ["/x/closed_loop_run", "--controller", "ideal", "--config", os.path.join(root, "plant.yaml"),
                   "--profile", os.path.join(root, "profile.csv")]
            kept = ideal_cache.IdealCache(root)
            self.assertEqual(kept.status, "no kept runs")
            self.assertIsNone(kept.get(cmd))
            kept.put(cmd, {"rms": 1.0})
            kept.save()
            again = ideal_cache.IdealCache(root)
            self.assertEqual(again.get(cmd), {"rms": 1.0})
            # The same bytes under another path or executable: the same run.
            moved = ["/y/other"] + cmd[1:-1] + [os.path.join(root, "copy.csv")]
            self.assertEqual(again.get(moved), {"rms": 1.0})
            self.assertEqual((again.hits, again.misses), (2, 0))
            # The control: another profile content, or another argument, misses.
            with open(os.path.join(root, "copy.csv"), "a") as f:
                f.write("1,0.5,0\n")
            self.assertIsNone(again.get(moved))
            self.assertIsNone(again.get(cmd + ["--set", "motor.command_delay=0.2"]))
            # A changed source makes every kept run a miss; so does a missing one.
            with open(os.path.join(root, "sim", "plant", "a.txt"), "a") as f:
                f.write("changed")
            stale = ideal_cache.IdealCache(root)
            self.assertIn("other sources", stale.status)
            self.assertIsNone(stale.get(cmd))
            os.remove(os.path.join(root, "src", "jackal_aic_tools", "track", "plant_limits.py"))
            gone = ideal_cache.IdealCache(root)
            self.assertIsNone(gone.sources)
            gone.put(cmd, {"rms": 2.0})
            self.assertIsNone(gone.get(cmd))
            with self.assertRaises(RuntimeError):
                gone.save()

    def test_an_unreadable_file_is_no_kept_run(self):
        with tempfile.TemporaryDirectory() as root:
            self.make_tree(root)
            path = os.path.join(root, "runs.json")
            with open(path, "w") as f:
                f.write("{not json")
            kept = ideal_cache.IdealCache(root, path)
            self.assertIn("unreadable", kept.status)
            self.assertEqual(kept.entries, {})

    def test_the_runner_takes_kept_ideal_runs(self):
        with tempfile.TemporaryDirectory() as root:
            self.make_tree(root)
            plant_yaml, profile = os.path.join(root, "plant.yaml"), os.path.join(root, "profile.csv")
            # An executable that does not exist: any run would fail, so a result proves the kept one.
            runner = driving.Runner(os.path.join(root, "no_such_tool"), "aic.yaml", plant_yaml,
                                    ideal_cache=ideal_cache.IdealCache(root))
            cmd = runner.command("ideal", ["--profile", profile])
            runner.ideal_cache.put(cmd, {"kept": True})
            out = runner.run_all([("k", "ideal", ["--profile", profile], None, (), False)])
            self.assertEqual(out["k"], ({"kept": True}, None))
            # The control: without the kept run the (missing) tool is run, and fails.
            bare = driving.Runner(os.path.join(root, "no_such_tool"), "aic.yaml", plant_yaml)
            with self.assertRaises(Exception):
                bare.run_all([("k", "ideal", ["--profile", profile], None, (), False)])


class FailureSummaryTest(unittest.TestCase):
    SCRIPT = os.path.join(ROOT, "dev", "failure_summary.py")

    def run_on(self, files):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "jackal_aic"))
            for name, text in files.items():
                with open(os.path.join(tmp, "jackal_aic", name), "w") as f:
                    f.write(text)
            return subprocess.run([sys.executable, self.SCRIPT, tmp, "--lines", "3"], stdout=subprocess.PIPE,
                                  universal_newlines=True, check=True).stdout

    def test_names_each_failure_and_error_and_is_silent_when_all_pass(self):
        passing = '<testsuite tests="1"><testcase classname="A" name="ok"/></testsuite>'
        failing = ('<testsuite tests="3"><testcase classname="Suite" name="bad" >'
                   '<failure message="expected 1, got 2">line 1\nline 2\nline 3\nline 4</failure></testcase>'
                   '<testcase classname="Suite" name="broken"><error message="boom"/></testcase>'
                   '<testcase classname="Suite" name="fine"/></testsuite>')
        self.assertEqual(self.run_on({"pass.xml": passing}), "")
        out = self.run_on({"pass.xml": passing, "fail.xml": failing, "junk.xml": "<testsuite"})
        self.assertIn("---- failures (3) ----", out)
        self.assertIn("fail.xml: Suite.bad [failure]", out)
        self.assertIn("expected 1, got 2", out)
        self.assertNotIn("line 3", out)  # --lines 3: the message and two lines
        self.assertIn("fail.xml: Suite.broken [error]", out)
        self.assertIn("junk.xml: unreadable", out)
        self.assertNotIn("Suite.fine", out)


class MutantsListTest(unittest.TestCase):
    """dev/mutants.py's list (dev/mutants.txt) against the tree: each mutant applies (its 'find'
    occurs once in its file) and names gtest targets that the CMakeLists.txt files declare."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ROOT, "dev"))
        import mutants  # noqa: E402 (dev/mutants.py)
        cls.m = mutants
        with open(os.path.join(ROOT, "dev", "mutants.txt")) as f:
            cls.mutants = mutants.parse_list(f.read(), "dev/mutants.txt")
        cls.cmake = ""
        for path in [os.path.join(ROOT, "CMakeLists.txt")] + glob.glob(os.path.join(ROOT, "*", "CMakeLists.txt")) + \
                glob.glob(os.path.join(ROOT, "src", "*", "CMakeLists.txt")):
            with open(path) as f:
                cls.cmake += f.read()

    def test_every_mutant_applies_to_the_tree(self):
        self.assertGreater(len(self.mutants), 10)
        for mutant in self.mutants:
            with open(os.path.join(ROOT, mutant["file"])) as f:
                text = f.read()
            self.assertNotEqual(self.m.apply(text, mutant), text, mutant["id"])

    def test_a_find_text_that_moved_away_is_an_error(self):
        mutant = dict(self.mutants[0], find="no such line in any file")
        with self.assertRaises(self.m.ListError):
            self.m.apply("some source", mutant)

    def test_the_core_gtests_are_the_ones_cmake_declares(self):
        core = self.m.core_tests()
        self.assertIn("test_core_controller", core)
        for target in core:
            name = target[len("test_core_"):]
            self.assertTrue(glob.glob(os.path.join(ROOT, "test", "unit", "*", "test_%s.cpp" % name)), target)
        for mutant in self.mutants:
            for target in mutant["tests"]:
                self.assertIn(target[len("test_core_"):] if target.startswith("test_core_") else target, self.cmake,
                              "%s names %s, which CMakeLists.txt does not declare" % (mutant["id"], target))
        with tempfile.TemporaryDirectory() as d:
            os.makedirs(os.path.join(d, "src", "x"))
            with open(os.path.join(d, "src", "x", "CMakeLists.txt"), "w") as f:
                f.write("add_library(jackal_aic_x x.cpp)\n")
            with self.assertRaises(ValueError):
                self.m.core_tests(d)


class AblationsListTest(unittest.TestCase):
    """dev/ablations.py: its list (dev/ablations.txt) applies to the tree and names existing plants,
    and its per-plant figures and page, on a compare.json made up here."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, os.path.join(ROOT, "dev"))
        import ablations  # noqa: E402 (dev/ablations.py)
        import mutants  # noqa: E402 (dev/mutants.py)
        cls.a, cls.m = ablations, mutants
        with open(os.path.join(ROOT, "dev", "ablations.txt")) as f:
            cls.entries = ablations.parse_list(f.read(), "dev/ablations.txt")

    def test_every_ablation_applies_to_the_tree(self):
        self.assertGreater(len(self.entries), 2)
        for e in self.entries:
            with open(os.path.join(ROOT, e["file"])) as f:
                text = f.read()
            self.assertNotEqual(self.m.apply(text, e), text, e["id"])
            for p in e["plants"]:
                self.assertTrue(p == "default" or os.path.isfile(os.path.join(ROOT, p)), "%s: %s" % (e["id"], p))

    def test_defaults_and_a_malformed_entry(self):
        e = self.a.parse_list("id: x\nwhat: w\nfile: f\nfind: a\nreplace: b\n")[0]
        self.assertEqual(e["variant"], "default")
        self.assertEqual(e["plants"], self.a.PLANTS)
        e = self.a.parse_list("id: x\nwhat: w\nfile: f\nfind: a\nreplace: b\nvariant: default:k=1\nplants: default\n")[0]
        self.assertEqual((e["variant"], e["plants"]), ("default:k=1", ["default"]))
        with self.assertRaisesRegex(self.m.ListError, "KEY one of"):
            self.a.parse_list("id: x\ntests: t\n")  # a mutant's key is not an ablation's
        with self.assertRaisesRegex(self.m.ListError, "without 'replace:'"):
            self.a.parse_list("id: x\nwhat: w\nfile: f\nfind: a\n")

    @staticmethod
    def result(name, rms, floor=0.1, stock=0.2, belief=0.01):
        """A compare.json of variant ``name``: two profiles on the default plant and on 'td', RMS
        ``rms`` (or rms(label)) against the floor and the stock controller; one step row."""
        rows = [{"section": "steps", "label": "0.5 m/s rise", "unit": "s", "values": {name: 0.2, "stock": 0.4},
                 "ratios": {name: 0.5}}]
        for tag in ("", " (td)"):
            for prof in ("a", "b"):
                for ch, unit in (("vx", "m/s"), ("wz", "rad/s")):
                    label = "%s%s %s" % (prof, tag, ch)
                    value = rms(label) if callable(rms) else rms
                    rows.append({"section": "tracking", "label": label + " RMS", "unit": unit,
                                 "values": {name: value, "stock": stock, "floor": floor},
                                 "ratios": {name: value / stock}})
                    rows.append({"section": "belief", "label": "%s%s %s belief-truth RMS" % (prof, tag, ch),
                                 "unit": unit, "values": {name: belief}, "ratios": {}})
        rows.append({"section": "belief", "label": "arc vx belief-truth RMS", "unit": "m/s", "values": {name: 9.0},
                     "ratios": {}})
        return {"variants": [{"name": name}], "rows": rows}

    def test_figures_per_plant_and_the_page(self):
        plants = ["default", "sim/config/variants/td.yaml"]
        w = self.a.per_plant(self.result("with", 0.12), plants)
        self.assertAlmostEqual(w["default"]["floor"], 1.2)
        self.assertAlmostEqual(w["default"]["stock"], 0.6)
        self.assertAlmostEqual(w["default"]["belief_vx"], 0.01)  # the arc's belief is not a profile's
        self.assertAlmostEqual(w["steps"], 0.5)
        self.assertAlmostEqual(w["default"]["floor_stock"], 0.5)
        self.assertEqual(sorted(w["default"]["channels"]), ["a vx", "a wz", "b vx", "b wz"])
        self.assertEqual(w["default"]["channels"]["a wz"], (0.12, "rad/s"))
        self.assertAlmostEqual(w["default"]["worst_belief"][0], 0.01 / 0.12)  # the arc's 9.0 is no channel
        self.assertEqual(sorted(w[plants[1]]["channels"]), ["a (td) vx", "a (td) wz", "b (td) vx", "b (td) wz"])
        # Without the rule, one channel of the second plant doubles: only that plant and channel move.
        wo = self.a.per_plant(self.result("x", lambda label: 0.24 if label == "b (td) wz" else 0.12), plants)
        self.assertAlmostEqual(wo["default"]["floor"], 1.2)
        self.assertAlmostEqual(wo[plants[1]]["floor"], 1.2 * 2 ** 0.25)
        entry = {"id": "x", "what": "a rule is out", "variant": "default", "file": "src/f.cpp", "plants": plants,
                 "with": w, "without": wo, "verdict": "ran"}
        page = self.a.markdown([entry, dict(entry, id="y", without=None, verdict="the edit does not build")],
                               "dev/ablations.py", 0.05)
        self.assertIn("| `td` | 1.200 → 1.427 | 0.600 → 0.714 | 0.500 |", page)
        self.assertIn("| 0.083 (b wz) → 0.083 (b vx) |", page)  # b (td) wz: its error doubled
        self.assertIn("Channels whose RMS moved: b (td) wz 0.1200 → 0.2400 rad/s.", page)
        self.assertIn("**the edit does not build**", page)
        with self.assertRaisesRegex(ValueError, "no tracking rows"):
            self.a.per_plant(self.result("with", 0.12), ["sim/config/variants/none.yaml"])


class ArcPriorTest(unittest.TestCase):
    """driving.arc_effective_separation and driving.arc_prior (the scorecard's table 6i), on made-up
    arc traces and a runner that returns made-up runs."""

    @staticmethod
    def trace(b0, b_eff, yaw=0.5, n=300, dt=0.01):
        """An arc run's trace: the true yaw rate ``yaw`` and the wheels' yaw rate through b0, of wheels
        that turn the body with the separation b_eff (r (omega_R - omega_L) = yaw b_eff)."""
        t = np.arange(n) * dt
        sep = np.full(n, float("nan"))
        sep[50:] = b0 - 0.01 * np.arange(n - 50) / n  # the learned b_hat moves; b0 is its start
        return {"t": t, "yaw_true": np.full(n, yaw), "yaw_odom": np.full(n, yaw * b_eff / b0), "separation": sep}

    def test_effective_separation_from_the_wheels_and_the_gyro(self):
        b0, b_eff = driving.arc_effective_separation(self.trace(0.5621, 0.5355))
        self.assertAlmostEqual(b0, 0.5621, places=12)
        self.assertAlmostEqual(b_eff, 0.5355, places=9)
        # Only the last window counts: a transient before it does not move b_eff.
        tr = self.trace(0.5621, 0.5355)
        tr["yaw_odom"][:100] = 0.0
        self.assertAlmostEqual(driving.arc_effective_separation(tr, window=1.0)[1], 0.5355, places=9)

    def test_no_separation_or_no_turn_is_an_error(self):
        tr = self.trace(0.5621, 0.5355)
        tr["separation"][:] = float("nan")
        with self.assertRaisesRegex(ValueError, "no finite separation"):
            driving.arc_effective_separation(tr)
        with self.assertRaisesRegex(ValueError, "no turn to measure"):
            driving.arc_effective_separation(self.trace(0.5621, 0.5355, yaw=0.01))

    def test_rows_rerun_the_arc_at_each_factor_of_b_eff(self):
        key = driving.STEP_CASES["arc, yaw"][1]

        def run(overshoot):
            return {key: [{"measured": {"overshoot": overshoot}}]}

        def result(overshoot):
            return dict(run(overshoot), command_delay=0.1187)

        res = {("step", "arc, speed", ph, "aic"): (result(7.0 + i), self.trace(0.5621, 0.5355) if i == 0 else None)
               for i, ph in enumerate(driving.STEP_PHASES)}
        seen = []
        trace = self.trace

        class Runner:
            def run_all(self, jobs):
                out = {}
                for key_, controller, args, overlay, sets, want_trace in jobs:
                    self_sets = [a for a in args if a.startswith("wheel_separation=")]
                    seen.append((controller, self_sets[0], overlay, want_trace, key_[2]))
                    factor = key_[1]
                    # The factor's trace: its ratio reaches the steady value from 0.3 s.
                    tr = trace(factor * 0.5355, 0.5355) if want_trace else None
                    if tr is not None:
                        tr["yaw_true"][tr["t"] < 0.3] *= 0.9
                    out[key_] = (result(100.0 * (factor - 1.0) + 2.0), tr)
                return out

        arc = driving.arc_prior(Runner(), res)
        self.assertAlmostEqual(arc["b_eff"], 0.5355, places=9)
        self.assertAlmostEqual(arc["b_hat_0"], 0.5621, places=12)
        rows = arc["rows"]
        self.assertEqual(len(rows), 1 + len(driving.ARC_PRIOR_FACTORS))
        # The configured row is the worst phase of the runs it was given.
        self.assertTrue(rows[0]["configured"])
        self.assertEqual(rows[0]["overshoot"], 7.0 + len(driving.STEP_PHASES) - 1)
        self.assertFalse(rows[0]["within"])
        for row, f in zip(rows[1:], driving.ARC_PRIOR_FACTORS):
            self.assertAlmostEqual(row["separation"], f * 0.5355, places=9)
            self.assertAlmostEqual(row["overshoot"], 100.0 * (f - 1.0) + 2.0, places=9)
            self.assertEqual(row["within"], row["overshoot"] <= driving.STEP_OVERSHOOT)
            # When the error shows: the made-up rise ends at 0.3 s; the peak is the run's largest yaw.
            self.assertAlmostEqual(row["seen"], 0.3, places=9)
            self.assertAlmostEqual(row["peak"], 0.3, places=9)
            self.assertEqual(row["latency"], 0.1187)
        # The configured row's timing is its first phase's trace: a constant turn, seen from the start.
        self.assertEqual((rows[0]["seen"], rows[0]["peak"], rows[0]["latency"]), (0.0, 0.0, 0.1187))
        # Every factor at every phase, on the AIC, with the separation set; the first phase's trace.
        self.assertEqual(len(seen), len(driving.ARC_PRIOR_FACTORS) * len(driving.STEP_PHASES))
        self.assertTrue(all(c == "aic" and o is None and w == (ph == driving.STEP_PHASES[0])
                            for c, _, o, w, ph in seen))
        self.assertIn("wheel_separation=%.5f" % (1.05 * 0.5355), [s for _, s, _, _, _ in seen])

    def test_the_prior_error_is_seen_once_the_ratio_holds_its_steady_value(self):
        tr = self.trace(0.5621, 0.5355)
        t = tr["t"]
        # A rise: no turn until 0.1 s, then the body turns 10 % short of the wheels' steady ratio until
        # 0.45 s (the tyres' grip at a speed change), then at its steady ratio; its peak at 0.6 s.
        tr["yaw_odom"][t < 0.1] = 0.0
        tr["yaw_true"][t < 0.1] = 0.0
        tr["yaw_true"][(t >= 0.1) & (t < 0.45)] *= 0.9
        tr["yaw_true"][np.isclose(t, 0.6)] *= 1.01
        tr["yaw_odom"][np.isclose(t, 0.6)] *= 1.01
        got = driving.prior_error_seen(tr)
        self.assertAlmostEqual(got["seen"], 0.45, places=9)
        self.assertAlmostEqual(got["peak"], 0.6, places=9)
        # One sample beyond the tolerance later (before the steady window) moves it past that sample.
        tr["yaw_true"][np.isclose(t, 1.2)] *= 1.0 + 1.5 * driving.ARC_RATIO_TOLERANCE
        self.assertAlmostEqual(driving.prior_error_seen(tr)["seen"], 1.21, places=9)
        # Within the tolerance it does not.
        tr["yaw_true"][np.isclose(t, 1.2)] /= 1.0 + 1.5 * driving.ARC_RATIO_TOLERANCE
        tr["yaw_true"][np.isclose(t, 1.2)] *= 1.0 + 0.5 * driving.ARC_RATIO_TOLERANCE
        self.assertAlmostEqual(driving.prior_error_seen(tr)["seen"], 0.45, places=9)
        # Samples before the step (t < 0) are not read: a larger yaw there is not the peak.
        tr["t"] = t - 0.05
        tr["yaw_true"][0] = tr["yaw_odom"][0] = 5.0
        got = driving.prior_error_seen(tr)
        self.assertAlmostEqual(got["seen"], 0.40, places=9)
        self.assertAlmostEqual(got["peak"], 0.55, places=9)

    def test_no_turn_has_no_prior_error_to_see(self):
        with self.assertRaisesRegex(ValueError, "no turn to measure"):
            driving.prior_error_seen(self.trace(0.5621, 0.5355, yaw=0.01))

    def test_table_and_its_error_form_print(self):
        from jackal_aic_tools.tune import scorecard_print
        arc = {"b_eff": 0.5355, "b_hat_0": 0.5621,
               "rows": [{"separation": 0.5621, "factor": 0.5621 / 0.5355, "configured": True, "overshoot": 7.8,
                         "within": False, "seen": 0.47, "peak": 0.59, "latency": 0.1187},
                        {"separation": 0.5355, "factor": 1.0, "configured": False, "overshoot": 2.8, "within": True,
                         "seen": 0.47, "peak": 0.77, "latency": 0.1187}]}
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_arc_prior(arc)
        text = buf.getvalue()
        self.assertIn("6i.", text)
        self.assertIn("is 0.5355 m; the configured b_hat_0 0.5621 m is 1.050 x b_eff", text)
        self.assertIn("0.5621 m (configured)", text)
        self.assertRegex(text, r"0\.5355 m\s+1\.000\s+2\.8 %\s+yes\s+0\.47 s\s+0\.59 s\s+0\.77 s")
        self.assertIn("within 2 % of its steady value", text)
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            scorecard_print.print_arc_prior({"error": "arc_effective_separation: no turn to measure"})
        self.assertIn("not measured (arc_effective_separation: no turn to measure)", buf.getvalue())


class ScriptHelpTest(unittest.TestCase):
    """Every command of scripts/ answers -h / --help with its usage and exit status 0, without a ROS
    master (one that starts a node must not wait for a master to print its usage)."""

    def test_every_script_prints_its_usage_without_a_master(self):
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:9", PYTHONPATH=os.pathsep.join(
            p for p in (os.path.join(ROOT, "src"), os.environ.get("PYTHONPATH", "")) if p))
        scripts = sorted(glob.glob(os.path.join(ROOT, "scripts", "*.py")))
        self.assertGreater(len(scripts), 10)
        for path in scripts:
            name = os.path.basename(path)
            try:
                run = subprocess.run([sys.executable, path, "--help"], env=env, capture_output=True, text=True,
                                     timeout=60)
            except subprocess.TimeoutExpired:
                self.fail("%s --help did not exit within 60 s" % name)
            self.assertEqual(run.returncode, 0, "%s --help: %s" % (name, run.stderr[-500:]))
            self.assertIn("usage", run.stdout.lower(), name)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("tool_logic", NodeWatchTest, RosProcessTest, SweepTest, ExperimentTest, SoakTest, ReportAndSummaryTest,
                FailureSummaryTest, PlantLimitsTest, PeerTest, EndHeadingTest, PyunitTest, HonestBeliefTest, ArcPriorTest,
                IdealCacheTest, MutantsListTest, AblationsListTest, StopReversalTest, ScriptHelpTest)
