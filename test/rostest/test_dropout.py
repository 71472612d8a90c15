#!/usr/bin/env python3
"""rostest: when an input stream stops, /cmd_drive goes to zero within a bound and stays
zero; when it returns, control resumes.

The fixture stops and resumes the stream (sensors or set point); this test finds the gap
in the stream it also records (joint_states stamps, or set point receipt times).

Runs on simulated time (/use_sim_time true, the fixture synthetic_sensors.py publishing
/clock): the latencies are judged between message stamps and this node's ROS time at
receipt (jackal_msgs/Drive and geometry_msgs/Twist carry no stamp), all on that clock; the
waits are conditions with a deadline.

Parameters (~): stream ("sensors" | "set_point"), max_zero_latency [s] (from the last input
to the first zero command), max_resume_latency [s] (from the first input after the gap to
the first non-zero command), min_gap [s] (what counts as the gap), moving [rad/s] (a
command magnitude that counts as "controlling"), receipt_margin [s] (default 0.1: the
command must stay zero from the first zero command until this long before this node
received the first input after the gap. The node and this test receive that input each on
its own; a set point has no stamp, so when this Python subscriber runs late the node's
resumed command can arrive here first. The margin is 5 % of the 2 s gap the fixtures make).
"""
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from jackal_msgs.msg import Drive
from sensor_msgs.msg import JointState

from aic_test_utils import Recorder, finite, wait_for


def find_gap(times, min_gap):
    for a, b in zip(times, times[1:]):
        if b - a >= min_gap:
            return a, b
    return None


class DropoutTest(unittest.TestCase):
    def test_zero_then_resume(self):
        stream = rospy.get_param("~stream")
        max_zero = float(rospy.get_param("~max_zero_latency"))
        max_resume = float(rospy.get_param("~max_resume_latency", 1.0))
        min_gap = float(rospy.get_param("~min_gap", 1.0))
        moving = float(rospy.get_param("~moving", 0.05))
        margin = float(rospy.get_param("~receipt_margin", 0.1))
        self.assertTrue(rospy.get_param("/use_sim_time", False), "the latencies are judged on simulated time")
        if stream == "sensors":
            inputs = Recorder("/joint_states", JointState, use_stamp=True)
        else:
            inputs = Recorder("/jackal_AIC/set_point", Twist)
        cmd = Recorder("/cmd_drive", Drive)

        def gap():
            return find_gap([t for t, _ in inputs.snapshot()], min_gap)

        self.assertTrue(wait_for(lambda: gap() is not None, 40.0), "the fixture never stopped the %s" % stream)
        t_last, t_back = gap()
        self.assertTrue(wait_for(lambda: cmd.snapshot() and cmd.snapshot()[-1][0] >= t_back + max_resume + 0.5, 30.0),
                        "no /cmd_drive %.1f s after the %s returned" % (max_resume + 0.5, stream))
        items = cmd.snapshot()
        for _, m in items:
            self.assertTrue(finite(m.drivers))

        def magnitude(m):
            return max(abs(d) for d in m.drivers)

        before = [magnitude(m) for t, m in items if t_last - 0.5 <= t <= t_last]
        self.assertTrue(before and max(before) > moving, "not controlling before the %s stopped" % stream)

        zeros = [t for t, m in items if t > t_last and magnitude(m) == 0.0]
        self.assertTrue(zeros, "no zero command after the %s stopped" % stream)
        latency = zeros[0] - t_last
        rospy.loginfo("%s stopped: first zero command after %.3f s", stream, latency)
        print("MEASURED %s stop -> zero command latency %.3f s" % (stream, latency), file=sys.stderr)
        self.assertLessEqual(latency, max_zero, "zero command only %.3f s after the %s stopped" % (latency, stream))
        during = [(t, magnitude(m)) for t, m in items if zeros[0] <= t < t_back - margin]
        self.assertTrue(during, "no command between the first zero and the %s's return" % stream)
        t_worst, worst = max(during, key=lambda x: x[1])
        self.assertEqual(worst, 0.0, "non-zero command %.3f while the %s were stopped, %.3f s before it returned"
                         % (worst, stream, t_back - t_worst))

        resumed = [t for t, m in items if t >= t_back and magnitude(m) > moving]
        self.assertTrue(resumed, "control did not resume after the %s returned" % stream)
        resume_latency = resumed[0] - t_back
        print("MEASURED %s back -> control latency %.3f s" % (stream, resume_latency), file=sys.stderr)
        self.assertLessEqual(resume_latency, max_resume)


if __name__ == "__main__":
    rospy.init_node("test_dropout")
    rostest.rosrun("jackal_aic", "test_dropout", DropoutTest, sys.argv)
