#!/usr/bin/env python3
"""The AIC's start-up ERROR about another publisher on its output topic reaches /rosout.

This node advertises /cmd_drive (jackal_msgs/Drive) and publishes zero commands on it at
50 Hz and starts a rosout node (rostest starts none); once the master lists both, it stops
rosout (SIGSTOP), starts launch/jackal_aic.launch (the AIC on the direct path, output
/cmd_drive) with the node's stdout to a file, and lets rosout go on ~rosout_delay s (wall) after
the AIC has registered: rosout connects to the AIC late, as on a loaded machine or when
roslaunch starts the master, rosout and the nodes at once. The AIC finds this node at its first
check, in its start-up, before any command; it waits for rosout first (at most 2 s).

Checks: an ERROR of /jackal_AIC naming this node and /cmd_drive arrives on /rosout_agg (the
rosout node's aggregate: what it received on /rosout, what rqt_console and the log files show)
within ~limit s of rosout going on (wall time: the start-up itself); the same line is on the node's
stdout; the AIC publishes nothing on /cmd_drive (each message's publisher is its connection
header's callerid); its diagnostics report the state "blocked" naming this node. The start-up INFO
line (src/ros/aic_node.cpp: AicParams::summary() and the belief loop's schedule) reaches
/rosout_agg too (roslaunch keeps a node's INFO off the screen unless output="screen") and names
what config/default.yaml runs: the robot model, its latency learned, b_hat_0. Waits are on
conditions with deadlines.
"""
import os
import signal
import sys
import tempfile
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from jackal_msgs.msg import Drive
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from aic_test_utils import live_publishers  # noqa: E402
from jackal_aic_tools.common import ros_process  # noqa: E402

PKG = "jackal_aic"
NAME = "cmd_drive_publisher_first"


def wait_wall(predicate, timeout, period=0.05):
    """Poll predicate() until it is true or `timeout` s of wall time pass; return its last value
    (no simulated clock runs in this test)."""
    deadline = time.monotonic() + timeout
    while not rospy.is_shutdown() and time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return predicate()


def subscribers_of(topic):
    """Node names the master lists as subscribers of `topic`."""
    _, subs, _ = rosgraph.Master(rospy.get_name()).getSystemState()
    return sorted(n for t, ns in subs if t == topic for n in ns)


def read_text(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


class StartupConflict(unittest.TestCase):
    def setUp(self):
        rospy.init_node(NAME)
        self.me = rospy.get_name()
        self.lock = threading.Lock()
        self.errors = []     # texts of the AIC's ERROR lines on /rosout_agg
        self.infos = []      # texts of its INFO lines there
        self.aic_drive = 0   # /cmd_drive messages from /jackal_AIC
        self.state = ""
        rospy.Subscriber("/rosout_agg", Log, self.on_log, queue_size=500)
        rospy.Subscriber("/cmd_drive", Drive, self.on_drive, queue_size=500, tcp_nodelay=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)

    def on_log(self, msg):
        if msg.name == "/jackal_AIC" and msg.level >= Log.ERROR:
            with self.lock:
                self.errors.append(msg.msg)
        elif msg.name == "/jackal_AIC" and msg.level == Log.INFO:
            with self.lock:
                self.infos.append(msg.msg)

    def on_drive(self, msg):
        if msg._connection_header.get("callerid") == "/jackal_AIC":
            with self.lock:
                self.aic_drive += 1

    def on_diagnostics(self, msg):
        for s in msg.status:
            if "jackal_AIC" in s.name and s.name.endswith("controller"):
                with self.lock:
                    self.state = s.message

    def conflict_errors(self):
        with self.lock:
            return [e for e in self.errors if self.me in e and "/cmd_drive" in e]

    def test_startup_error_reaches_rosout(self):
        limit = rospy.get_param("~limit", 20.0)
        self.rosout_delay = rospy.get_param("~rosout_delay", 1.0)
        pub = rospy.Publisher("/cmd_drive", Drive, queue_size=1)
        stop = Drive()
        stop.mode = Drive.MODE_VELOCITY
        timer = rospy.Timer(rospy.Duration(0.02), lambda _e: pub.publish(stop))
        self.assertTrue(wait_wall(lambda: self.me in live_publishers("/cmd_drive"), 10.0),
                        "the master never listed this node on /cmd_drive")
        with tempfile.NamedTemporaryFile("w+", suffix=".log", prefix="jackal_aic_startup_") as out:
            # A rosout node, registered, then stopped: it connects to the AIC late (as on a loaded
            # machine, or when roslaunch starts the master, rosout and the nodes at once).
            rosout = ros_process.start(["rosrun", "rosout", "rosout", "__name:=rosout_aggregator"])
            proc = None
            try:
                self.assertTrue(wait_wall(lambda: "/rosout_aggregator" in subscribers_of("/rosout"), 30.0),
                                "rosout never registered")
                os.killpg(rosout.pid, signal.SIGSTOP)
                proc = ros_process.roslaunch("jackal_aic.launch", [], package=PKG, stdout=out)
                self.assertTrue(wait_wall(lambda: "/jackal_AIC" in live_publishers("/rosout"), 30.0),
                                "the AIC never registered")
                time.sleep(self.rosout_delay)  # wall time: rosout stays stopped this long
                os.killpg(rosout.pid, signal.SIGCONT)
                t0 = time.monotonic()
                found = wait_wall(lambda: self.conflict_errors() != [], limit)
                elapsed = time.monotonic() - t0
                with self.lock:
                    errors = list(self.errors)
                self.assertTrue(found, "no ERROR naming %s on /rosout_agg within %.0f s; the AIC's ERRORs there: %s"
                                % (self.me, limit, errors))
                rospy.loginfo("startup conflict: the ERROR reached /rosout_agg %.2f s after rosout went on: %s",
                              elapsed, self.conflict_errors()[0])
                self.assertTrue(wait_wall(lambda: self.state.startswith("blocked") and self.me in self.state, 10.0),
                                "diagnostics: %r" % self.state)
                self.assertTrue(wait_wall(lambda: self.conflict_errors()[0] in read_text(out.name), 10.0),
                                "the ERROR is not on the node's stdout")
                with self.lock:
                    self.assertEqual(self.aic_drive, 0, "the AIC published beside this node")
                self.assertEqual(len(self.conflict_errors()), 1, "more than one ERROR: %s" % self.conflict_errors())
                self.check_startup_line()
            finally:
                timer.shutdown()
                os.killpg(rosout.pid, signal.SIGCONT)
                if proc is not None:
                    ros_process.stop(proc, timeout=20.0)
                ros_process.stop(rosout, timeout=10.0)


    def startup_lines(self):
        with self.lock:
            return [i for i in self.infos if i.startswith("jackal_AIC: belief ") and "waiting for" in i]

    def check_startup_line(self):
        """The start-up INFO line is on /rosout_agg, once, and names config/default.yaml's model:
        belief and action rates, the robot model with its latency learned, b_hat_0."""
        self.assertTrue(wait_wall(lambda: self.startup_lines() != [], 10.0),
                        "no start-up INFO line on /rosout_agg; the AIC's INFO lines there: %s" % self.infos)
        lines = self.startup_lines()
        self.assertEqual(len(lines), 1, "start-up lines: %s" % lines)
        line = lines[0]
        rospy.loginfo("startup line: %s", line)
        for part in ("belief 1000 Hz, action 50 Hz, belief model robot, latency ", " s (learned), action_gain ",
                     "b_hat_0 0.5621 m; beliefs advanced on ", "; waiting for /joint_states, /imu/data and ~set_point"):
            self.assertIn(part, line)


if __name__ == "__main__":
    rostest.rosrun(PKG, "startup_conflict_check", StartupConflict, sys.argv)
