#!/usr/bin/env python3
"""The identification recorder on the simulated Jackal (scripts/record_identification.py through
launch/record_identification.launch, the plant with ~plant_overlay, the stock base's diff drive
with its /status and stop): test/rostest/record_identification*.test.

~mode complete: the recorder's outcome (~outcome, latched) is "completed"; its bag (~bag) holds
  /cmd_drive, /jackal_velocity_controller/cmd_vel, /joint_states, /imu/data, /feedback and /status;
  no recorded twist exceeds ~max_linear / ~max_angular; the bag's steady turns in place show the
  overlay's yaw-rate deficit ~deficit +- ~deficit_tol rad/s (the plant node applied ~overlay).
~mode stop: ~trigger, ~stop_after s after the recorder starts moving:
  estop     the stock base's stop (/stock_base/set_stop): outcome "stopped: e-stop", every twist
            it publishes from ~stop_latency s after the stop on is zero;
  lock      twist_mux's lock (/e_stop true): outcome "stopped: e-stop lock", zero twists likewise;
  joystick  a twist on twist_mux's joystick input (/joy_teleop/cmd_vel): outcome
            "stopped: joystick", and no twist at all from the recorder ~stop_latency s after it
            (the joystick has the robot).

Runs on simulated time (the .test sets use_sim_time: the plant node publishes /clock): the
twists' times are this node's ROS time at receipt (geometry_msgs/Twist carries no stamp), the
stop's time its ROS time at publication, so ~stop_after and ~stop_latency are plant time; the
waits are conditions (the robot moving, plant time reached, the outcome published), with
~timeout s of wall time as the deadline of each.
"""
import os
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool, String

from jackal_aic_tools.identify import bag_identification as bi

PKG = "jackal_aic"


class RecorderTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.outcome = None
        self.twists = []
        rospy.Subscriber("/record_identification/outcome", String, self.on_outcome)
        rospy.Subscriber(bi.CMD_VEL, Twist, self.on_twist, queue_size=200)

    def on_outcome(self, msg):
        with self.lock:
            self.outcome = msg.data

    def on_twist(self, msg):
        t = rospy.get_rostime().to_sec()
        with self.lock:
            self.twists.append((t, msg.linear.x, msg.angular.z))

    def wait(self, predicate, timeout):
        """Poll predicate() until it is true or `timeout` s of wall time pass (a deadline only:
        nothing is judged on the wall clock); return its last value."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and not rospy.is_shutdown():
            if predicate():
                return True
            time.sleep(0.01)
        return predicate()

    def wait_outcome(self, timeout):
        def outcome():
            with self.lock:
                return self.outcome
        self.assertTrue(self.wait(lambda: outcome() is not None, timeout),
                        "no outcome from the recorder within %g s" % timeout)
        return outcome()

    def wait_until(self, t, timeout):
        """Wait until ROS (plant) time reaches t [s]."""
        self.assertTrue(self.wait(lambda: rospy.get_rostime().to_sec() >= t, timeout),
                        "plant time did not reach %.3f s" % t)

    def test_recorder(self):
        self.assertTrue(rospy.get_param("/use_sim_time", False), "the check runs on simulated time")
        mode = rospy.get_param("~mode")
        timeout = float(rospy.get_param("~timeout", 60.0))
        if mode == "complete":
            self.assertEqual(self.wait_outcome(timeout), "completed")
            data = bi.read_bag(rospy.get_param("~bag"))
            self.assertGreater(data.duration, 10.0)
            self.assertIsNotNone(data.feedback)
            import rosbag
            with rosbag.Bag(rospy.get_param("~bag")) as bag:
                topics = bag.get_type_and_topic_info().topics
                for t in (bi.CMD_DRIVE, bi.CMD_VEL, bi.JOINT_STATES, bi.IMU, bi.FEEDBACK, bi.STATUS):
                    self.assertIn(t, topics)
                twists = [(m.linear.x, m.angular.z) for _, m, _ in bag.read_messages(topics=[bi.CMD_VEL])]
            self.assertLessEqual(max(abs(v) for v, _ in twists), float(rospy.get_param("~max_linear")) + 1e-9)
            self.assertLessEqual(max(abs(w) for _, w in twists), float(rospy.get_param("~max_angular")) + 1e-9)
            deficits = bi.turn_deficits(data.gyro[:, 0], data.gyro[:, 1], data.cmd)
            self.assertEqual(len(deficits), 2, deficits)  # the short sequence's turns in place
            for w, d in deficits:
                self.assertAlmostEqual(d, float(rospy.get_param("~deficit")),
                                       delta=float(rospy.get_param("~deficit_tol")), msg="command %g" % w)
        elif mode == "stop":
            trigger = rospy.get_param("~trigger", "estop")
            expected = {"estop": "stopped: e-stop", "lock": "stopped: e-stop lock", "joystick": "stopped: joystick"}
            self.assertIn(trigger, expected)
            if trigger == "joystick":
                stop_pub = rospy.Publisher("/joy_teleop/cmd_vel", Twist, queue_size=1, latch=True)
                stop_msg = Twist()
                stop_msg.angular.z = 0.3  # the operator turns the robot away
            else:
                stop_pub = rospy.Publisher("/stock_base/set_stop" if trigger == "estop" else "/e_stop", Bool,
                                           queue_size=1, latch=True)
                stop_msg = Bool(data=True)
            def first_moving():
                with self.lock:
                    return next((t for t, v, w in self.twists if v != 0.0 or w != 0.0), None)
            self.assertTrue(self.wait(lambda: first_moving() is not None, timeout), "the recorder never moved the robot")
            self.wait_until(first_moving() + float(rospy.get_param("~stop_after")), timeout)
            t_stop = rospy.get_rostime().to_sec()
            stop_pub.publish(stop_msg)
            self.assertEqual(self.wait_outcome(timeout), expected[trigger])
            # The outcome comes after the recorder's last twist; twists still in flight arrive
            # within 0.5 s of plant time.
            self.wait_until(rospy.get_rostime().to_sec() + 0.5, timeout)
            latency = float(rospy.get_param("~stop_latency"))
            with self.lock:
                after = [(v, w) for t, v, w in self.twists if t > t_stop + latency]
                moving = [t - t_stop for t, v, w in self.twists if t > t_stop and (v != 0.0 or w != 0.0)]
            print("MEASURED %s: %s" % (trigger, "last moving twist %.3f s after the stop (plant time)" % moving[-1]
                                        if moving else "no moving twist after the stop"), file=sys.stderr)
            if trigger == "joystick":
                self.assertFalse(after, "the recorder kept publishing after the joystick: %s" % after[:5])
            else:
                self.assertTrue(after, "no zero twists after the stop")
                self.assertTrue(all(v == 0.0 and w == 0.0 for v, w in after), after[:5])
            self.assertTrue(os.path.isfile(rospy.get_param("~bag")))
        else:
            self.fail("~mode must be complete or stop")


if __name__ == "__main__":
    rospy.init_node("record_identification_check")
    rostest.rosrun(PKG, "record_identification_check", RecorderTest)
