#!/usr/bin/env python3
"""rostest: with invalid messages interleaved in every input (the fixture's `faults` mode:
NaN/+Inf/-Inf in every numeric field of JointState, Imu and Twist, mismatched arrays,
unknown and missing joint names, zero and backwards stamps, absurd set points), every
/cmd_drive command stays finite and within max_wheel_speed, the node keeps controlling,
and its diagnostics count the drops of every kind.

Parameters (~): duration [s] (recorded after the first command), max_wheel_speed [rad/s],
min_rate [Hz] (least /cmd_drive rate over the run: a rate check on the wall clock, receipt
times, as rostest's hztest; node_bad_input.test states the tolerance).
"""
import math
import sys
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistStamped
from jackal_msgs.msg import Drive

from aic_test_utils import Recorder, finite, rate_of, wait_for

# Diagnostic keys (node "jackal_AIC", task "sensors") that must have counted drops.
EXPECTED_DROPS = [
    "dropped: joint_states: unknown or missing joint name",
    "dropped: joint_states: array length mismatch",
    "dropped: joint_states: non-finite value",
    "dropped: joint_states: zero or backwards stamp",
    "dropped: imu: non-finite value",
    "dropped: imu: zero or backwards stamp",
    "dropped: set point non-finite",
    "set points clamped",
]


class BadInputTest(unittest.TestCase):
    def test_commands_stay_finite_and_bounded(self):
        duration = float(rospy.get_param("~duration", 6.0))
        limit = float(rospy.get_param("~max_wheel_speed", 20.0))
        min_rate = float(rospy.get_param("~min_rate", 40.0))
        cmd = Recorder("/cmd_drive", Drive)
        belief = Recorder("/jackal_AIC/belief", TwistStamped, use_stamp=True)
        diagnostics = Recorder("/diagnostics", DiagnosticArray)

        self.assertTrue(wait_for(lambda: cmd.span() >= duration, 3 * duration + 20), "too few /cmd_drive messages")
        items = cmd.snapshot()
        for _, m in items:
            self.assertEqual(m.mode, Drive.MODE_VELOCITY)
            self.assertTrue(finite(m.drivers), "non-finite command %s" % (m.drivers,))
            for d in m.drivers:
                self.assertLessEqual(abs(d), limit * (1 + 1e-6), "command %s beyond the limit" % (m.drivers,))
        self.assertGreater(max(max(abs(d) for d in m.drivers) for _, m in items), 1.0,
                           "the node never controlled (commands all ~0)")
        self.assertGreaterEqual(rate_of([t for t, _ in items]), min_rate)
        for _, b in belief.snapshot():
            self.assertTrue(finite([b.twist.linear.x, b.twist.linear.y, b.twist.angular.z]))

        def counters():
            values = {}
            for _, array in diagnostics.snapshot():
                for status in array.status:
                    if status.name.endswith(": sensors"):
                        values = {kv.key: kv.value for kv in status.values}
            return values

        self.assertTrue(wait_for(lambda: all(float(counters().get(k, 0)) > 0 for k in EXPECTED_DROPS), 10.0),
                        "diagnostics did not count every kind of bad input: %s" % counters())
        print("MEASURED drop counters: %s" % {k: counters().get(k) for k in EXPECTED_DROPS}, file=sys.stderr)


if __name__ == "__main__":
    rospy.init_node("test_bad_input")
    rostest.rosrun("jackal_aic", "test_bad_input", BadInputTest, sys.argv)
