#!/usr/bin/env python3
"""rostest: the ROS fuzz (jackal_aic_tools.robustness.ros_fuzz.fuzz, the generator and verdict of
scripts/aic_ros_fuzz.py) against the node of the .test: seeded random messages on every input
for ~seconds, then a plausible stretch; no finding (every /cmd_drive finite and within the
limit, commands during the final stretch), and the node drove (commands beyond 0.1 rad/s).

Parameters (~): seconds [s] of fuzz, seed, rate [1/s] of the fuzz stretches, limit [rad/s]
(default: the node's max_wheel_speed).
"""
import sys
import unittest

import rospy
import rostest

from aic_test_utils import wait_for
from jackal_aic_tools.robustness import ros_fuzz


class RosFuzzTest(unittest.TestCase):
    def test_fuzz_finds_nothing(self):
        self.assertTrue(wait_for(lambda: rospy.has_param("/jackal_AIC/max_wheel_speed"), 30.0), "node not up")
        res = ros_fuzz.fuzz(float(rospy.get_param("~seconds", 12.0)), int(rospy.get_param("~seed", 3)),
                            float(rospy.get_param("~rate", 1000.0)), rospy.get_param("~limit", None))
        findings = ros_fuzz.verdict(res["check"], True, res["final_commands"])
        for line in ros_fuzz.summary_lines(res, findings):
            rospy.loginfo(line)
        self.assertEqual(findings, [], "\n".join(ros_fuzz.summary_lines(res, findings)))
        self.assertGreater(res["moving_commands"], 0, "the node never drove")
        fuzzed = sum(n for k, n in res["sent"].items() if k.endswith("fuzzed"))
        self.assertGreater(fuzzed, 1000, "too few fuzzed messages")


if __name__ == "__main__":
    rospy.init_node("test_ros_fuzz")
    rostest.rosrun("jackal_aic", "node_ros_fuzz", RosFuzzTest, sys.argv)
