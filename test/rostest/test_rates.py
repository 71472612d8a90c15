#!/usr/bin/env python3
"""rostest: /cmd_drive arrives at the action rate with the real jackal_msgs/Drive type and
MD5; the belief topic arrives at the belief rate (measured from its stamps).

Parameters (~): expected_action_rate [Hz], expected_belief_rate [Hz], rate_tolerance [-]
(relative, 0.1), warmup [s] (ignored first part), duration [s] (measured window).
"""
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import TwistStamped
from jackal_msgs.msg import Drive

from aic_test_utils import Recorder, rate_of, wait_for

DRIVE_MD5 = "601cf097cd47c174590c366c6ddd5fb3"


class RatesTest(unittest.TestCase):
    def setUp(self):
        self.action_rate = float(rospy.get_param("~expected_action_rate"))
        self.belief_rate = float(rospy.get_param("~expected_belief_rate"))
        self.tolerance = float(rospy.get_param("~rate_tolerance", 0.1))
        self.warmup = float(rospy.get_param("~warmup", 1.0))
        self.duration = float(rospy.get_param("~duration", 5.0))
        self.cmd = Recorder("/cmd_drive", rospy.AnyMsg)
        self.belief = Recorder("/jackal_AIC/belief", TwistStamped, use_stamp=True)

    def test_rates_type_and_md5(self):
        needed = self.warmup + self.duration
        self.assertTrue(wait_for(lambda: self.cmd.span() >= needed and self.belief.span() >= needed, 3 * needed + 20),
                        "not enough /cmd_drive or belief messages (spans %.2f s, %.2f s)"
                        % (self.cmd.span(), self.belief.span()))
        cmds = self.cmd.snapshot()
        header = cmds[0][1]._connection_header
        self.assertEqual(header["type"], "jackal_msgs/Drive")
        self.assertEqual(header["md5sum"], DRIVE_MD5)
        self.assertEqual(Drive._md5sum, DRIVE_MD5)
        for _, raw in cmds:
            msg = Drive().deserialize(raw._buff)
            self.assertEqual(msg.mode, Drive.MODE_VELOCITY)

        def window(items):
            start = items[0][0] + self.warmup
            return [t for t, _ in items if start <= t <= start + self.duration]

        action = rate_of(window(cmds))
        belief = rate_of(window(self.belief.snapshot()))
        rospy.loginfo("measured: /cmd_drive %.2f Hz (expected %.1f), belief %.2f Hz (expected %.1f)",
                      action, self.action_rate, belief, self.belief_rate)
        print("MEASURED cmd_drive_rate=%.2f Hz belief_rate=%.2f Hz" % (action, belief), file=sys.stderr)
        self.assertAlmostEqual(action, self.action_rate, delta=self.tolerance * self.action_rate,
                               msg="/cmd_drive at %.2f Hz" % action)
        self.assertAlmostEqual(belief, self.belief_rate, delta=self.tolerance * self.belief_rate,
                               msg="belief at %.2f Hz" % belief)


if __name__ == "__main__":
    rospy.init_node("test_rates")
    rostest.rosrun("jackal_aic", "test_rates", RatesTest, sys.argv)
