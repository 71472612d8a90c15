#!/usr/bin/env python3
"""rostest: the jackal_AIC node's learned model round trip on the simulated Jackal, on simulated
time (node_learned_model.test; doc/jackal_aic_node.md, 'Learned model').

1. The node started from the saved overlay: ~wheel_separation reads ~start_separation.
2. An arc (0.5 m/s, 0.5 rad/s) for ~drive_time s: b_hat moves by more than ~min_change
   (relative), so the node learns (the control: without the arc it would not move).
3. At rest (learning frozen) ~save_learned_model answers success and the file it names holds
   `wheel_separation:` equal to the published b_hat (within the model's 1e-3 relative apply
   tolerance), as YAML.
4. ~reset_learned_model answers success, ~wheel_separation reads ~start_separation again and
   ~gyro_offset (the gyro offset learned at standstill, published finite and within
   gyro_bias_max) reads 0.

With ~start_latency (node_learned_model.test: the robot model with learn_latency, started
from an overlay with `latency:` ~start_latency) also:

0. Before the first start from rest ~save_learned_model writes `wheel_separation:` only and says
   the latency is not learned yet.
3. The saved file holds `latency:` too, the value the answer names, within [0.5, 2] x
   ~start_latency and more than ~min_latency_change [s] from it (the plant's latency differs).
4. The reset's answer names the learned latency forgotten and L back to ~start_latency (the
   loaded overlay's latency is the configured one); a save after it writes no `latency:` again.
5. Diagnostics "controller" shows the L in use (`model latency L [s]`, 4 decimals): ~start_latency
   with "0 starts" in `latency learning` before the first start, the saved L after it, and
   ~start_latency again after the reset.
6. After the arc, diagnostics "controller" counts the robot model's shortfall jumps
   (`shortfall jumps (robot model)`) and shows no side stalled.
"""
import math
import os
import re
import sys
import threading
import unittest

import rospy
import rostest
import yaml
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from std_msgs.msg import Float64
from std_srvs.srv import Trigger

from aic_test_utils import wait_for


class LearnedModelTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.b_hat = None
        self.beta = None
        rospy.Subscriber("/jackal_AIC/wheel_separation", Float64, self.on_b, queue_size=10)
        rospy.Subscriber("/jackal_AIC/gyro_offset", Float64, self.on_beta, queue_size=10)
        self.diagnostics = (None, {})  # (stamp, key -> value) of jackal_AIC's controller task
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)
        self.pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
        self.twist = Twist()
        rospy.Timer(rospy.Duration(0.02), lambda _: self.pub.publish(self.twist))

    def on_b(self, msg):
        with self.lock:
            self.b_hat = msg.data

    def b(self):
        with self.lock:
            return self.b_hat

    def on_beta(self, msg):
        with self.lock:
            self.beta = msg.data

    def gyro_offset(self):
        with self.lock:
            return self.beta

    def on_diagnostics(self, msg):
        for st in msg.status:
            if "jackal_AIC" in st.name and st.name.endswith("controller"):
                with self.lock:
                    self.diagnostics = (msg.header.stamp.to_sec(), {kv.key: kv.value for kv in st.values})

    def controller_diagnostics(self, after):
        """The key -> value of the first controller diagnostics stamped after ROS time `after`."""
        def fresh():
            with self.lock:
                return self.diagnostics[0] is not None and self.diagnostics[0] > after
        self.assertTrue(wait_for(fresh, 10.0), "no controller diagnostics after %.3f s" % after)
        with self.lock:
            return dict(self.diagnostics[1])

    def latency_shown(self, after):
        """(L, its learning) from the first controller diagnostics stamped after ROS time `after`."""
        kv = self.controller_diagnostics(after)
        return float(kv["model latency L [s]"]), kv["latency learning"]

    def save(self):
        """Call ~save_learned_model; assert success; return (answer, the file's YAML)."""
        rospy.wait_for_service("/jackal_AIC/save_learned_model", 10.0)
        res = rospy.ServiceProxy("/jackal_AIC/save_learned_model", Trigger)()
        self.assertTrue(res.success, res.message)
        path = re.search(r"written to (\S+)", res.message).group(1)
        self.assertEqual(path, rospy.get_param("/jackal_AIC/learned_model_file"))
        with open(path) as f:
            return res.message, yaml.safe_load(f)

    def test_save_and_reset(self):
        start = float(rospy.get_param("~start_separation"))
        start_latency = rospy.get_param("~start_latency", None)
        drive_time = float(rospy.get_param("~drive_time", 8.0))
        min_change = float(rospy.get_param("~min_change", 0.01))
        self.assertTrue(wait_for(lambda: self.b() is not None, 30.0), "no ~wheel_separation")
        self.assertAlmostEqual(self.b(), start, delta=1e-6, msg="the node did not start from the saved overlay")
        if start_latency is not None:
            message, saved = self.save()
            self.assertEqual(set(saved), {"wheel_separation"}, message)
            self.assertIn("latency not learned yet", message)
            shown, learning = self.latency_shown(rospy.Time.now().to_sec())
            self.assertAlmostEqual(shown, start_latency, delta=5e-5)
            self.assertTrue(learning.startswith("0 starts"), learning)

        self.twist.linear.x, self.twist.angular.z = 0.5, 0.5
        rospy.sleep(drive_time)
        self.twist.linear.x, self.twist.angular.z = 0.0, 0.0
        learned = self.b()
        rospy.loginfo("learned_model_check: b_hat %.4f m after %.1f s of arc (start %.4f m)", learned, drive_time, start)
        if start_latency is not None:
            # The robot model's shortfall jumps: counted, and no side stalled on a free arc.
            jumps = self.controller_diagnostics(rospy.Time.now().to_sec()).get("shortfall jumps (robot model)", "")
            self.assertRegex(jumps, r"^\d+ taken, \d+ released, \d+ unanswered, \d+ stalls; stalled: none; saturated: none$")
        self.assertGreater(abs(learned - start) / start, min_change, "b_hat did not learn on the arc")
        rospy.sleep(2.0)  # at rest: learning frozen, b_hat steady
        steady = self.b()
        beta = self.gyro_offset()
        self.assertIsNotNone(beta, "no ~gyro_offset")
        self.assertTrue(math.isfinite(beta) and abs(beta) <= rospy.get_param("/jackal_AIC/gyro_bias_max", 0.1),
                        "~gyro_offset %r" % beta)
        self.assertNotEqual(beta, 0.0, "gyro_bias_min_rest 0: the noisy gyro's offset is learned at the first rest")

        message, saved = self.save()
        path = rospy.get_param("/jackal_AIC/learned_model_file")
        # ~wheel_separation is the model's b_hat, which takes the learner's value whenever it moved by
        # more than ActiveInferenceController::kSeparationApplyTolerance (1e-3 relative); the file holds the learner's.
        self.assertAlmostEqual(saved["wheel_separation"], steady, delta=1e-3 * steady)
        if start_latency is None:
            self.assertEqual(set(saved), {"wheel_separation"}, message)
        else:
            self.assertEqual(set(saved), {"wheel_separation", "latency"}, message)
            latency = saved["latency"]
            rospy.loginfo("learned_model_check: latency %.4f s learned (start %.4f s)", latency, start_latency)
            print("MEASURED latency %.4f s learned (start %.4f s)" % (latency, start_latency), file=sys.stderr)
            self.assertAlmostEqual(latency, float(re.search(r"latency (\S+) s", message).group(1)), delta=1e-9)
            self.assertTrue(0.5 * start_latency <= latency <= 2.0 * start_latency, "latency %r" % latency)
            self.assertGreater(abs(latency - start_latency), float(rospy.get_param("~min_latency_change", 0.005)),
                               "the latency did not learn at the start from rest")
            shown, learning = self.latency_shown(rospy.Time.now().to_sec())
            self.assertAlmostEqual(shown, latency, delta=5e-5, msg=learning)

        res = rospy.ServiceProxy("/jackal_AIC/reset_learned_model", Trigger)()
        self.assertTrue(res.success, res.message)
        if start_latency is not None:
            self.assertIn("learned latency %g s forgotten" % latency, res.message)
            back = float(re.search(r"; L (\S+) s \(latency\)", res.message).group(1))
            self.assertAlmostEqual(back, start_latency, delta=1e-9, msg=res.message)
            message, saved = self.save()
            self.assertEqual(set(saved), {"wheel_separation"}, message)
            self.assertIn("latency not learned yet", message)
        self.assertTrue(wait_for(lambda: abs(self.b() - start) < 1e-6, 5.0),
                        "b_hat %.4f after the reset, expected %.4f" % (self.b(), start))
        self.assertTrue(wait_for(lambda: self.gyro_offset() == 0.0, 5.0),
                        "~gyro_offset %r after the reset, expected 0" % self.gyro_offset())
        if start_latency is not None:
            # Read after the offset's check: the offset is learned again at rest meanwhile.
            shown, _ = self.latency_shown(rospy.Time.now().to_sec())
            self.assertAlmostEqual(shown, start_latency, delta=5e-5)
        os.remove(path)


if __name__ == "__main__":
    rospy.init_node("learned_model_check")
    rostest.rosrun("jackal_aic", "node_learned_model", LearnedModelTest, sys.argv)
