#!/usr/bin/env python3
"""rostest: /cmd_drive arrives at the action rate with the real jackal_msgs/Drive type and
MD5; the beliefs keep up with time (in /diagnostics "loops", over the diagnostics' stamps:
"belief time integrated [s]" grows at 1 s per second, "belief steps" at least at the belief
rate); ~belief arrives at min(debug_rate, belief_rate) (measured from its stamps).

Rate checks on the wall clock, as rostest's hztest (expected rate, relative tolerance, window):
/cmd_drive by receipt time, ~belief and the diagnostics by their stamps; each within
rate_tolerance of the expected rate (the belief steps: at least 1 - rate_tolerance of it).

Parameters (~): expected_action_rate [Hz], expected_belief_rate [Hz], expected_debug_rate
[Hz] (the ~belief topic), rate_tolerance [-] (relative, 0.1), warmup [s] (ignored first
part), duration [s] (measured window).
"""
import sys
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import TwistStamped
from jackal_msgs.msg import Drive, DriveFeedback, Feedback, Status

from aic_test_utils import Recorder, rate_of, wait_for

DRIVE_MD5 = "601cf097cd47c174590c366c6ddd5fb3"
# The MCU state the node subscribes (/status, /feedback): the MD5 sums of Clearpath's
# jackal_msgs (noetic-devel), which the robot's publishers send; compat/jackal_msgs must match.
STATUS_MD5 = "c851ebcf9a6e20b196bc7894e285b4f6"
FEEDBACK_MD5 = "3bdabb0ef46338ee5672d1b82220ab49"
DRIVE_FEEDBACK_MD5 = "8dd0b7a3cfa20cfc5c054ddd9763609b"


class RatesTest(unittest.TestCase):
    def setUp(self):
        self.action_rate = float(rospy.get_param("~expected_action_rate"))
        self.belief_rate = float(rospy.get_param("~expected_belief_rate"))
        self.debug_rate = float(rospy.get_param("~expected_debug_rate"))
        self.tolerance = float(rospy.get_param("~rate_tolerance", 0.1))
        self.warmup = float(rospy.get_param("~warmup", 1.0))
        self.duration = float(rospy.get_param("~duration", 5.0))
        self.cmd = Recorder("/cmd_drive", rospy.AnyMsg)
        self.belief = Recorder("/jackal_AIC/belief", TwistStamped, use_stamp=True)
        self.diagnostics = Recorder("/diagnostics", DiagnosticArray, use_stamp=True)

    def belief_steps(self):
        """(stamp, belief steps, belief time integrated [s]) from each diagnostics publication."""
        out = []
        for t, msg in self.diagnostics.snapshot():
            for status in msg.status:
                if status.name.endswith("loops"):
                    values = {kv.key: kv.value for kv in status.values}
                    if "belief steps" in values:
                        out.append((t, int(values["belief steps"]), float(values["belief time integrated [s]"])))
        return out

    def test_mcu_state_md5(self):
        self.assertEqual(Status._md5sum, STATUS_MD5)
        self.assertEqual(Feedback._md5sum, FEEDBACK_MD5)
        self.assertEqual(DriveFeedback._md5sum, DRIVE_FEEDBACK_MD5)
        # The node subscribes both with these types (its subscriptions as the master lists them).
        import rosgraph
        state = rosgraph.Master(rospy.get_name()).getSystemState()
        topics = dict(rosgraph.Master(rospy.get_name()).getTopicTypes())
        for topic, typ in (("/status", "jackal_msgs/Status"), ("/feedback", "jackal_msgs/Feedback")):
            subs = [nodes for t, nodes in state[1] if t == topic]
            self.assertTrue(subs and "/jackal_AIC" in subs[0], "jackal_AIC does not subscribe %s" % topic)
            self.assertEqual(topics.get(topic), typ)

    def test_rates_type_and_md5(self):
        needed = self.warmup + self.duration
        def steps_span():
            steps = self.belief_steps()
            return steps[-1][0] - steps[0][0] if len(steps) > 1 else 0.0
        self.assertTrue(wait_for(lambda: self.cmd.span() >= needed and self.belief.span() >= needed
                                 and steps_span() >= needed, 3 * needed + 20),
                        "not enough /cmd_drive, belief or diagnostics messages (spans %.2f s, %.2f s, %.2f s)"
                        % (self.cmd.span(), self.belief.span(), steps_span()))
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
        topic = rate_of(window(self.belief.snapshot()))
        steps = self.belief_steps()
        start = steps[0][0] + self.warmup
        steps = [s for s in steps if s[0] >= start]
        self.assertGreaterEqual(len(steps), 2, "too few diagnostics after the warm-up")
        span = steps[-1][0] - steps[0][0]
        belief = (steps[-1][1] - steps[0][1]) / span
        integrated = (steps[-1][2] - steps[0][2]) / span
        expected_topic = min(self.debug_rate, self.belief_rate)
        rospy.loginfo("measured: /cmd_drive %.2f Hz (expected %.1f), belief steps %.2f Hz (expected %.1f), "
                      "~belief %.2f Hz (expected %.1f)", action, self.action_rate, belief, self.belief_rate,
                      topic, expected_topic)
        print("MEASURED cmd_drive_rate=%.2f Hz belief_steps=%.2f Hz belief_time=%.4f s/s belief_topic=%.2f Hz"
              % (action, belief, integrated, topic), file=sys.stderr)
        self.assertAlmostEqual(action, self.action_rate, delta=self.tolerance * self.action_rate,
                               msg="/cmd_drive at %.2f Hz" % action)
        self.assertAlmostEqual(integrated, 1.0, delta=self.tolerance,
                               msg="beliefs integrated over %.4f s per second" % integrated)
        self.assertGreaterEqual(belief, (1.0 - self.tolerance) * self.belief_rate,
                                msg="belief steps at %.2f Hz" % belief)
        self.assertAlmostEqual(topic, expected_topic, delta=self.tolerance * expected_topic,
                               msg="~belief at %.2f Hz" % topic)


if __name__ == "__main__":
    rospy.init_node("test_rates")
    rostest.rosrun("jackal_aic", "test_rates", RatesTest, sys.argv)
