#!/usr/bin/env python3
"""rostest: sensors that say the robot is slower than the set point make the wheel commands
rise; faster make them fall.

The fixture reports a constant wheel speed (open loop), so the commands should move
steadily in one direction. Compares the mean command of an early window right after
control starts with a later window.

Parameters (~): expect ("rise" | "fall"), margin [rad/s] (least change of the mean
command, each wheel), early [s] and late [s] (window starts after the first active
command), window [s] (window length).
"""
import math
import sys
import unittest

import rospy
import rostest
from jackal_msgs.msg import Drive

from aic_test_utils import Recorder, finite, wait_for


class ResponseTest(unittest.TestCase):
    def test_direction(self):
        expect = rospy.get_param("~expect")
        margin = float(rospy.get_param("~margin", 2.0))
        early = float(rospy.get_param("~early", 0.0))
        late = float(rospy.get_param("~late", 0.8))
        length = float(rospy.get_param("~window", 0.2))
        self.assertIn(expect, ("rise", "fall"))
        cmd = Recorder("/cmd_drive", Drive)

        def active_since():
            for t, m in cmd.snapshot():
                if any(abs(d) > 1e-6 for d in m.drivers):
                    return t
            return None

        self.assertTrue(wait_for(lambda: active_since() is not None, 30.0), "the controller never commanded motion")
        t0 = active_since()
        self.assertTrue(wait_for(lambda: cmd.snapshot()[-1][0] >= t0 + late + length, 30.0))
        items = cmd.snapshot()
        for _, m in items:
            self.assertTrue(finite(m.drivers))

        def mean(start, wheel):
            values = [m.drivers[wheel] for t, m in items if t0 + start <= t < t0 + start + length]
            self.assertGreater(len(values), 0)
            return sum(values) / len(values)

        for wheel, name in ((Drive.LEFT, "left"), (Drive.RIGHT, "right")):
            a, b = mean(early, wheel), mean(late, wheel)
            rospy.loginfo("%s wheel: mean command %.3f rad/s early, %.3f rad/s late", name, a, b)
            print("MEASURED %s %s: early %.3f late %.3f rad/s" % (expect, name, a, b), file=sys.stderr)
            if expect == "rise":
                self.assertGreater(b - a, margin, "%s command did not rise: %.3f -> %.3f" % (name, a, b))
            else:
                self.assertLess(b - a, -margin, "%s command did not fall: %.3f -> %.3f" % (name, a, b))


if __name__ == "__main__":
    rospy.init_node("test_response")
    rostest.rosrun("jackal_aic", "test_response", ResponseTest, sys.argv)
