#!/usr/bin/env python3
"""rostest: runaway beliefs are reset, the command is zero, diagnostics report ERROR.

With config/thesis_improved_euler_diverges.yaml (tau = 0.001 s, forward Euler at 1 kHz) the printed
belief update is unstable (order-0 gain k_mu Pi_mu / tau^2 ~ 6.7e3 1/s, h * gain ~ 6.7 > 2,
doc/active_inference.md, 'Analysis notes'): the node must catch every divergence.

The zero command: the reset zeroes the action and the supervisor holds a zero command for
runaway_hold_time after it; the restart after the hold stays on probation (zero command) until its
beliefs have run one action period without a runaway, which this controller never survives. So
after the first runaway every command is zero; only the first start's action step (before any
runaway) can read a belief part-way to divergence: at most max_leaked (1) non-zero commands, each
followed by at least min_zero_run zero commands. test_core_control_loop checks the same at every
phase of the timers on simulated time.
The control: the same test on config/default.yaml (no divergence) sees a stream of non-zero
commands and fails.

Parameters (~): duration [s] (recorded /cmd_drive span), max_wheel_speed [rad/s],
min_runaways (least "runaway resets" reported in diagnostics), min_commands (least /cmd_drive
messages to judge), min_zero_run (zero commands after a non-zero one), max_leaked (non-zero
commands allowed in the run).
"""
import sys
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import TwistStamped
from jackal_msgs.msg import Drive

from aic_test_utils import Recorder, finite, wait_for


class RunawayTest(unittest.TestCase):
    def test_runaway_is_caught(self):
        duration = float(rospy.get_param("~duration", 5.0))
        limit = float(rospy.get_param("~max_wheel_speed", 20.0))
        min_runaways = int(rospy.get_param("~min_runaways", 1))
        min_commands = int(rospy.get_param("~min_commands", 50))
        min_zero_run = int(rospy.get_param("~min_zero_run", 25))
        max_leaked = int(rospy.get_param("~max_leaked", 1))
        cmd = Recorder("/cmd_drive", Drive)
        belief = Recorder("/jackal_AIC/belief", TwistStamped, use_stamp=True)
        diagnostics = Recorder("/diagnostics", DiagnosticArray)

        def controller_status():
            found = None
            for _, array in diagnostics.snapshot():
                for status in array.status:
                    if status.name.endswith(": controller"):
                        found = status
            return found

        def runaway_reported():
            s = controller_status()
            if s is None:
                return False
            values = {kv.key: kv.value for kv in s.values}
            return s.level == DiagnosticStatus.ERROR and int(values.get("runaway resets", 0)) >= min_runaways

        self.assertTrue(wait_for(lambda: cmd.span() >= duration, 3 * duration + 20))
        for _, m in cmd.snapshot():
            self.assertTrue(finite(m.drivers))
            self.assertLessEqual(max(abs(d) for d in m.drivers), limit * (1 + 1e-6))
        # The zero command: after a non-zero command (a divergence that reached the action step
        # before the belief update caught it) the reset's hold sends zeros.
        drivers = [list(m.drivers) for _, m in cmd.snapshot()]
        moving = [i for i, d in enumerate(drivers) if any(x != 0.0 for x in d)]
        print("MEASURED %d of %d commands non-zero: %s" % (len(moving), len(drivers), [drivers[i] for i in moving[:5]]),
              file=sys.stderr)
        self.assertGreaterEqual(len(drivers), min_commands, "too few commands to judge")
        self.assertLessEqual(len(moving), max_leaked, "non-zero commands from a diverging controller")
        for i in moving:
            after = drivers[i + 1:i + 1 + min_zero_run]
            self.assertTrue(all(x == 0.0 for d in after for x in d),
                            "command %d (%s) is not followed by the zero command of the hold: %s"
                            % (i, drivers[i], after[:5]))
        self.assertTrue(wait_for(runaway_reported, 10.0), "no diagnostics ERROR with runaway resets: %s"
                        % controller_status())
        for _, b in belief.snapshot():
            self.assertTrue(finite([b.twist.linear.x, b.twist.linear.y, b.twist.angular.z]))
        s = controller_status()
        print("MEASURED controller diagnostics: level %d, %s" % (s.level, s.message), file=sys.stderr)


if __name__ == "__main__":
    rospy.init_node("test_runaway")
    rostest.rosrun("jackal_aic", "test_runaway", RunawayTest, sys.argv)
