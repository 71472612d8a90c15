#!/usr/bin/env python3
"""rostest: the node's stamped inference, ~inference (jackal_aic/InferenceState; doc/jackal_aic_node.md,
'Topics'), recorded beside the unstamped ~free_energy (std_msgs/Float64):

- header stamps strictly increase (one message per sensor sample), frame base_link;
- the belief model is the configured one (~expected_belief_model, the default's robot model);
- every value the model has is finite and every other is NaN (msg/InferenceState.msg: the robot
  model has mu's orders 0 and 1, eps_y's order 0 of gyro_z, omega_L, omega_R, and its slow states;
  no eps_mu, no action prior), the attractor goal settles on the set point, the arrays hold
  3 x orders, 5 x orders and 3 x orders values, orders as configured (~expected_orders),
  F = F_sensory + F_prior (to 1e-9 relative);
- F is what ~free_energy carries: the node publishes both from one snapshot, so every F of
  ~inference after both subscriptions are up is among the ~free_energy values (at least 90 % of
  them, the first ones may come before the second subscription connects).

Parameters (~): expected_orders [-], expected_belief_model, messages (how many ~inference messages to record).
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
        self.belief_model = rospy.get_param("~expected_belief_model")
        self.count = int(rospy.get_param("~messages", 150))
        self.free_energy = Recorder("/jackal_AIC/free_energy", Float64)
        self.inference = Recorder("/jackal_AIC/inference", InferenceState, use_stamp=True)

    def split(self, m):
        """The message's values the belief model has, and those it does not (NaN)."""
        n = self.orders
        finite = [m.free_energy, m.free_energy_sensory, m.free_energy_prior, m.wheel_separation, m.gyro_offset] + \
            list(m.action) + list(m.goal) + list(m.precision_y)
        robot_states = list(m.shortfall) + list(m.turn_shortfall) + [m.slip_ratio, m.gyro_offset_belief]
        if m.belief_model != "robot":
            return finite + list(m.mu) + list(m.eps_y) + list(m.eps_mu) + list(m.action_prior), robot_states
        mu = [m.mu[c * n + i] for c in range(3) for i in range(n) if i < 2]
        eps_y = [m.eps_y[c * n] for c in range(3)]
        absent = [m.mu[c * n + i] for c in range(3) for i in range(2, n)] + \
            [m.eps_y[c * n + i] for c in range(5) for i in range(n) if c >= 3 or i > 0] + list(m.eps_mu) + \
            list(m.action_prior)
        return finite + mu + eps_y + robot_states, absent

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
            self.assertEqual(m.belief_model, self.belief_model)
            finite, absent = self.split(m)
            self.assertTrue(all(math.isfinite(v) for v in finite), "non-finite value at %.6f" % m.header.stamp.to_sec())
            self.assertTrue(all(math.isnan(v) for v in absent),
                            "a value the %s model does not have at %.6f" % (m.belief_model, m.header.stamp.to_sec()))
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
