#!/usr/bin/env python3
"""Step-response check of the closed loop (the AIC + plant): test/rostest/step_response_default.test.
It plays a step from rest on /jackal_AIC/set_point, records /odom (ground truth), the belief
and /cmd_drive, and asserts on metrics computed from message stamps by the core's
aic_step_metrics (through jackal_aic_tools). Expectations are <param>s:

  ~step               step size [m/s]                                       [0.5]
  ~hold               how long the step is held [s]                         [3.0]
  ~settle_limit       the step settles (+-5 %) within this [s]              [1.0]
  ~overshoot_limit    overshoot below this [% of step]                      [20]
  ~sse_limit          |steady-state error| below this [% of the set point]  [2]
  ~bound_v            |measured/believed v| beyond this = unstable [m/s]    [3.0]
  ~ready_timeout      wall time to wait for the streams [s]                 [30]
  ~expect_param       "/name=value": fail unless that parameter is set so     [none]
"""
import math
import signal
import sys
import unittest

import rospy
import rostest

from jackal_aic_tools.common import profiles, recording
from jackal_aic_tools.experiment import experiment

PKG = "jackal_aic"

# Signals received. roslaunch interrupts the test when a required node (the controller,
# the plant) dies; the default handler would kill this process before it writes its
# result file, and rostest would then count 0 tests and report success. Instead the
# signal is recorded and the running check fails with a message.
_signals = []


def _on_signal(signum, _frame):
    _signals.append(signum)


def _stopped():
    if _signals:
        return ["the launch is shutting down (signal %d): did a required node (controller, plant) die? "
                "See its log" % _signals[0]]
    return []


class StepResponseCheck(unittest.TestCase):

    def test_step_response(self):
        p = lambda n, d: rospy.get_param("~" + n, d)
        controller = "aic"
        prof = profiles.step(v=float(p("step", 0.5)), t_step=0.5, hold=float(p("hold", 3.0)))
        settle_limit = float(p("settle_limit", 1.0))      # s
        overshoot_limit = float(p("overshoot_limit", 20.0))  # % of the step
        sse_limit = float(p("sse_limit", 2.0))            # % of the set point
        limits = recording.StabilityLimits(v_bound=float(p("bound_v", 3.0)))
        expected = p("expect_param", "")  # "/name=value": the launch file's setting reached the node
        if expected:
            name, value = expected.split("=", 1)
            self.assertEqual(str(rospy.get_param(name, None)), value, "parameter %s" % name)
        wheel_radius = float(rospy.get_param("/jackal_AIC/wheel_radius", 0.098))
        wheel_sep = float(rospy.get_param("/jackal_AIC/wheel_separation", 0.5621))

        rec = recording.Recorder()
        t0, status, reason = experiment.drive_profile(
            prof, rec, controller, settle=1.0, ready_timeout=float(p("ready_timeout", 30.0)), limits=limits,
            wheel_radius=wheel_radius, wheel_sep=wheel_sep, died=_stopped, name=rospy.get_name())
        self.assertIsNotNone(t0, "the run did not start: %s" % reason)
        self.assertEqual(status, "ok", "closed loop %s: %s" % (status, reason))
        arr = rec.arrays()
        segs = recording.actual_segments(prof, arr["setpoint"], t0)
        results = experiment.analyse(arr, segs, t0, wheel_radius, wheel_sep)
        self.assertEqual(len(results), len(prof.segments()))
        for seg in results:
            m = seg["metrics"].get("measured")
            what = "%s transition %g -> %g m/s at t=%.2f s" % (controller, seg["start"], seg["target"], seg["t_step"])
            self.assertIsNotNone(m, "%s: no /odom samples" % what)
            self.assertNotIn("error", m, "%s: metrics failed: %s" % (what, m.get("error")))
            rospy.loginfo("%s: rise %s s, settling %s s, overshoot %s %%, steady-state error %s m/s", what,
                          m["rise_time"], m["settling_time"], m["overshoot"], m["steady_state_error"])
            step = abs(seg["target"] - seg["start"])
            self.assertIsNotNone(m["settling_time"], "%s: never stayed within +-5 %%" % what)
            self.assertLessEqual(m["settling_time"], settle_limit,
                                 "%s: settling time %.3f s > %.3f s" % (what, m["settling_time"], settle_limit))
            self.assertIsNotNone(m["overshoot"], "%s: overshoot undefined" % what)
            self.assertLess(m["overshoot"], overshoot_limit,
                            "%s: overshoot %.1f %% >= %.1f %%" % (what, m["overshoot"], overshoot_limit))
            self.assertIsNotNone(m["steady_state_error"], "%s: steady-state error undefined" % what)
            sse_pct = 100.0 * abs(m["steady_state_error"]) / max(abs(seg["target"]), 1e-9)
            self.assertLess(sse_pct, sse_limit, "%s: steady-state error %.2f %% of the set point >= %.2f %%"
                            % (what, sse_pct, sse_limit))
            self.assertGreater(step, 0.0)
        for s in ("odom", "drive", "belief"):
            a = arr[s]
            self.assertTrue(a.size and all(map(math.isfinite, a.ravel())), "non-finite or no data on %s" % s)


if __name__ == "__main__":
    signal.signal(signal.SIGINT, _on_signal)
    signal.signal(signal.SIGTERM, _on_signal)
    rospy.init_node("step_response_check", disable_signals=True)
    rostest.rosrun(PKG, "step_response_check", StepResponseCheck, sys.argv)
