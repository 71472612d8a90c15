#!/usr/bin/env python3
"""rostest: the node's stamped inference, ~inference (jackal_aic/InferenceState; doc/jackal_aic_node.md,
'Topics'), recorded beside the unstamped ~free_energy (std_msgs/Float64):

- header stamps strictly increase (one message per sensor sample), frame base_link;
- every value is finite, the attractor goal settles on the set point, the arrays hold 3 x orders, 5 x orders and 3 x orders values, orders as
  configured (~expected_orders), F = F_sensory + F_prior (to 1e-9 relative);
- F is what ~free_energy carries: the node publishes both from one snapshot, so every F of
  ~inference after both subscriptions are up is among the ~free_energy values (at least 90 % of
  them, the first ones may come before the second subscription connects).

Parameters (~): expected_orders [-], messages (how many ~inference messages to record).
"""
import math
import sys
import unittest

import rospy
import rostest
from std_msgs.msg import Float64

from jackal_aic.msg import InferenceState

from aic_test_utils import Recorder, wait_for


class InferenceTest(unittest.TestCase):
    def setUp(self):
        self.orders = int(rospy.get_param("~expected_orders"))
        self.count = int(rospy.get_param("~messages", 150))
        self.free_energy = Recorder("/jackal_AIC/free_energy", Float64)
        self.inference = Recorder("/jackal_AIC/inference", InferenceState, use_stamp=True)

    def test_stamped_finite_and_equal_to_free_energy(self):
        self.assertTrue(wait_for(lambda: len(self.inference.snapshot()) >= self.count, 60.0),
                        "only %d ~inference messages" % len(self.inference.snapshot()))
        msgs = [m for _t, m in self.inference.snapshot()]
        stamps = [m.header.stamp.to_sec() for m in msgs]
        for a, b in zip(stamps, stamps[1:]):
            self.assertGreater(b, a, "stamps do not increase: %.6f then %.6f" % (a, b))
        self.assertGreater(stamps[0], 0.0)
        for m in msgs:
            self.assertEqual(m.header.frame_id, "base_link")
            self.assertEqual(m.orders, self.orders)
            self.assertEqual((len(m.mu), len(m.eps_y), len(m.eps_mu)), (3 * self.orders, 5 * self.orders,
                                                                        3 * self.orders))
            values = [m.free_energy, m.free_energy_sensory, m.free_energy_prior, m.wheel_separation,
                      m.gyro_offset] + list(m.mu) + list(m.eps_y) + list(m.eps_mu) + list(m.action) + \
                list(m.action_prior) + list(m.goal) + list(m.precision_y)
            self.assertTrue(all(math.isfinite(v) for v in values), "non-finite value at %.6f" % m.header.stamp.to_sec())
            self.assertGreaterEqual(m.free_energy, 0.0)
            self.assertAlmostEqual(m.free_energy, m.free_energy_sensory + m.free_energy_prior,
                                   delta=1e-9 * max(1.0, m.free_energy))
        self.assertTrue(any(m.free_energy > 0.0 for m in msgs), "F is zero throughout")
        # the attractor's goal: the reference path, settled on the 0.5 m/s set point by the end
        self.assertAlmostEqual(msgs[-1].goal[0], 0.5, delta=0.02)
        self.assertTrue(wait_for(lambda: len(self.free_energy.snapshot()) > 0, 10.0), "no ~free_energy")
        published = {m.data for _t, m in self.free_energy.snapshot()}
        matched = sum(1 for m in msgs if m.free_energy in published)
        self.assertGreaterEqual(matched, 0.9 * len(msgs),
                                "%d of %d ~inference F values are not on ~free_energy" % (len(msgs) - matched,
                                                                                           len(msgs)))


if __name__ == "__main__":
    rospy.init_node("test_inference")
    rostest.rosrun("jackal_aic", "node_inference", InferenceTest, sys.argv)
