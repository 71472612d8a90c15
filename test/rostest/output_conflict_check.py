#!/usr/bin/env python3
"""One publisher per command topic (launch/sim.launch, simulated time; the AIC publishes
/cmd_drive). The AIC drives at ~speed m/s; then this node advertises /cmd_drive itself and
publishes zero commands on it at 50 Hz for ~conflict_time s, then unregisters.

Checks: within ~detect_limit s of advertising, the AIC logs exactly one ERROR (/rosout) that
names this node; from that ERROR until this node leaves, no /cmd_drive message comes from the
AIC (each message's publisher is its connection header's callerid); diagnostics report the
state "blocked" naming this node; after it leaves the AIC publishes again within
~resume_limit s and the robot drives at ~speed (mean /odom over 1 s within ~speed_tol).
Times are ROS (simulated) times of receipt in this node; waits are on conditions.
"""
import os
import statistics
import sys
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from jackal_msgs.msg import Drive
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from aic_test_utils import wait_for  # noqa: E402

PKG = "jackal_aic"
NAME = "second_cmd_drive_publisher"


class OutputConflict(unittest.TestCase):
    def setUp(self):
        rospy.init_node(NAME)
        self.me = rospy.get_name()
        self.lock = threading.Lock()
        self.aic_drive = []   # receipt times of /cmd_drive messages from /jackal_AIC
        self.errors = []      # (time, text) of the AIC's ERROR lines
        self.odom = []
        self.state = ""
        rospy.Subscriber("/cmd_drive", Drive, self.on_drive, queue_size=500, tcp_nodelay=True)
        rospy.Subscriber("/rosout", Log, self.on_log, queue_size=500)
        rospy.Subscriber("/odom", Odometry, self.on_odom, queue_size=500)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)
        self.set_point = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=1)
        self.speed = rospy.get_param("~speed", 0.5)
        rospy.Timer(rospy.Duration(0.05), self.publish_set_point)

    def publish_set_point(self, _event):
        msg = Twist()
        msg.linear.x = self.speed
        self.set_point.publish(msg)

    def on_drive(self, msg):
        if msg._connection_header.get("callerid") == "/jackal_AIC":
            with self.lock:
                self.aic_drive.append(rospy.get_rostime().to_sec())

    def on_log(self, msg):
        if msg.name == "/jackal_AIC" and msg.level >= Log.ERROR:
            with self.lock:
                self.errors.append((rospy.get_rostime().to_sec(), msg.msg))

    def on_odom(self, msg):
        with self.lock:
            self.odom.append((msg.header.stamp.to_sec(), msg.twist.twist.linear.x))

    def on_diagnostics(self, msg):
        for s in msg.status:
            if "jackal_AIC" in s.name and s.name.endswith("controller"):
                with self.lock:
                    self.state = s.message

    def steady(self, tol):
        with self.lock:
            if not self.odom:
                return False
            rows = [v for t, v in self.odom if t >= self.odom[-1][0] - 1.0]
        return len(rows) > 20 and abs(statistics.mean(rows) - self.speed) <= tol

    def aic_between(self, t0, t1):
        with self.lock:
            return [t for t in self.aic_drive if t0 <= t <= t1]

    def test_second_publisher(self):
        detect_limit = rospy.get_param("~detect_limit", 1.0)
        conflict_time = rospy.get_param("~conflict_time", 3.0)
        resume_limit = rospy.get_param("~resume_limit", 1.0)
        tol = rospy.get_param("~speed_tol", 0.05)
        self.assertTrue(wait_for(lambda: self.steady(tol), 30.0), "the AIC never drove at %.2f m/s" % self.speed)
        self.assertEqual(self.errors, [])

        # A second publisher on /cmd_drive.
        t_adv = rospy.get_rostime().to_sec()
        intruder = rospy.Publisher("/cmd_drive", Drive, queue_size=1)
        stop = Drive()
        stop.mode = Drive.MODE_VELOCITY
        timer = rospy.Timer(rospy.Duration(0.02), lambda _e: intruder.publish(stop))
        self.assertTrue(wait_for(lambda: len(self.errors) > 0, detect_limit + 1.0), "no ERROR from the AIC")
        t_err, text = self.errors[0]
        rospy.loginfo("output conflict: ERROR %.3f s after advertising: %s", t_err - t_adv, text)
        self.assertLessEqual(t_err - t_adv, detect_limit)
        self.assertIn(self.me, text)
        self.assertTrue(wait_for(lambda: self.state.startswith("blocked") and self.me in self.state, 3.0),
                        "diagnostics: %r" % self.state)
        # Stay for conflict_time s (a condition on simulated time, not a sleep).
        wait_for(lambda: rospy.get_rostime().to_sec() >= t_adv + conflict_time, conflict_time + 30.0)
        t_leave = rospy.get_rostime().to_sec()
        timer.shutdown()
        intruder.unregister()
        # Nothing from the AIC between its ERROR and this node leaving (one message may have
        # been on the wire when it logged).
        during = self.aic_between(t_err + 0.05, t_leave)
        self.assertEqual(during, [], "the AIC published %d commands during the conflict" % len(during))
        self.assertEqual(len(self.errors), 1, "more than one ERROR: %s" % self.errors)
        # Driving resumes.
        self.assertTrue(wait_for(lambda: self.aic_between(t_leave, 1e12) != [], resume_limit + 1.0),
                        "the AIC did not publish again")
        t_resume = self.aic_between(t_leave, 1e12)[0]
        rospy.loginfo("output conflict: the AIC publishes again %.3f s after the other left", t_resume - t_leave)
        self.assertLessEqual(t_resume - t_leave, resume_limit)
        self.assertTrue(wait_for(lambda: self.steady(tol), 15.0), "the robot did not drive again")
        self.assertEqual(len(self.errors), 1, "ERRORs after the conflict: %s" % self.errors)


if __name__ == "__main__":
    rostest.rosrun(PKG, "output_conflict_check", OutputConflict, sys.argv)
