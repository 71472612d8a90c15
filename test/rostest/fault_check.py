#!/usr/bin/env python3
"""A fault's ROS wiring, once per kind of fault: drives a set-point profile on
/jackal_AIC/set_point, injects one fault into the plant node through its ~faults parameter
(sim/README.md, 'Fault injection') and asserts that jackal_AIC's /jackal_AIC/sensor_health
reports it, in time. What the closed loop does after the fault (speed error, yaw rate,
settling) is judged headless in test/sim/test_closed_loop_acceptance.cpp (SensorFaults.*);
here only the path plant ~faults -> sensor streams -> node -> sensor_health is.

Runs on simulated time (use_sim_time: the plant node publishes /clock): every time below is
plant time, from message stamps or the node's event times; the waits are conditions with a
timeout, not sleeps. Scenarios (~scenario):

  sensor_loss   drive v straight; 'imu dropout': sensor health reports gyro_z missing (level
                WARN) within ~report_limit s of the last IMU sample.
  frozen_sensor turn at (v, ~turn_rate) until the yaw rate is there; 'gyro freeze'; the set point
                goes straight: gyro_z is isolated within ~isolation_limit s of that.
  bias          drive v straight; a bias of ~bias rad/s on the ~side encoder: omega_<side> is
                isolated within ~isolation_limit s of the first biased /joint_states sample.

In every scenario: /odom stays finite and |v_x| < 3 m/s, and no channel is reported before
the fault.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState

PKG = "jackal_aic"
SCENARIOS = ("sensor_loss", "frozen_sensor", "bias")


def p(name, default):
    return rospy.get_param("~" + name, default)


class Streams:
    """Records, by message stamp (plant time): (stamp, v_x, omega_z) from /odom, (stamp, left,
    right wheel speed) from /joint_states, the /imu/data stamps; and (plant time at receipt,
    level, values) from /jackal_AIC/sensor_health (a DiagnosticStatus has no stamp)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.odom, self.joints, self.imu, self.health = [], [], [], []
        rospy.Subscriber("/odom", Odometry, self._odom, queue_size=10000, tcp_nodelay=True)
        rospy.Subscriber("/joint_states", JointState, self._joints, queue_size=10000, tcp_nodelay=True)
        rospy.Subscriber("/imu/data", Imu, self._imu, queue_size=10000, tcp_nodelay=True)
        rospy.Subscriber("/jackal_AIC/sensor_health", DiagnosticStatus, self._health, queue_size=1000)

    def _odom(self, m):
        with self.lock:
            self.odom.append((m.header.stamp.to_sec(), m.twist.twist.linear.x, m.twist.twist.angular.z))

    def _joints(self, m):
        left = [v for n, v in zip(m.name, m.velocity) if "left" in n]
        right = [v for n, v in zip(m.name, m.velocity) if "right" in n]
        if left and right:
            with self.lock:
                self.joints.append((m.header.stamp.to_sec(), sum(left) / len(left), sum(right) / len(right)))

    def _imu(self, m):
        with self.lock:
            self.imu.append(m.header.stamp.to_sec())

    def _health(self, m):
        values = {kv.key: kv.value for kv in m.values}
        with self.lock:
            self.health.append((rospy.get_rostime().to_sec(), m.level, values))

    def snapshot(self, name):
        with self.lock:
            return list(getattr(self, name))


class Driver:
    """Publishes the set point at 20 Hz of plant time (within the node's set-point timeout)."""

    def __init__(self):
        self.pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
        self.v, self.w = 0.0, 0.0
        self.timer = rospy.Timer(rospy.Duration(0.05), self._tick)

    def set(self, v, w=0.0):
        """Sets the set point and publishes it at once; returns the plant time it was sent."""
        self.v, self.w = v, w
        self._tick(None)
        return rospy.get_rostime().to_sec()

    def _tick(self, _):
        msg = Twist()
        msg.linear.x, msg.angular.z = self.v, self.w
        self.pub.publish(msg)


def mean(xs):
    return sum(xs) / len(xs) if xs else float("nan")


def event_time(values, word, channel):
    """The time of a sensor-health 'last event' value '<word> <channel> at <time>', or None."""
    ev = values.get("last event", "")
    if not ev.startswith(word + " " + channel + " at "):
        return None
    try:
        return float(ev.rsplit(" at ", 1)[1])
    except ValueError:
        return None


class FaultCheck(unittest.TestCase):

    def setUp(self):
        self.s = Streams()
        self.d = Driver()
        # Plant time starts at 0 with the plant node: the readiness wait is on the wall clock.
        deadline = time.monotonic() + float(p("ready_timeout", 30.0))
        ok = False
        while not rospy.is_shutdown() and time.monotonic() < deadline:
            ok = len(self.s.snapshot("odom")) > 10 and len(self.s.snapshot("health")) > 0
            if ok:
                break
            time.sleep(0.05)
        self.assertTrue(ok, "no /odom or /jackal_AIC/sensor_health within the ready timeout")

    def wait(self, predicate, timeout, what):
        """Waits until predicate() holds, at most `timeout` s of plant time; fails naming `what`."""
        deadline = rospy.get_rostime().to_sec() + timeout
        while not rospy.is_shutdown() and rospy.get_rostime().to_sec() < deadline:
            if predicate():
                return
            rospy.sleep(0.02)
        self.assertTrue(predicate(), "%s: not within %.1f s of plant time" % (what, timeout))

    def steady(self, v, w, since, tol=0.05):
        """True when /odom's last 0.5 s (after `since`) is within tol x (|v| + |w|) of (v, w)."""
        odom = [o for o in self.s.snapshot("odom") if o[0] >= since]
        if len(odom) < 2 or odom[-1][0] - odom[0][0] < 0.5:
            return False
        last = [o for o in odom if o[0] >= odom[-1][0] - 0.5]
        band = tol * (abs(v) + abs(w))
        return all(abs(o[1] - v) <= band and abs(o[2] - w) <= band for o in last)

    def inject(self, line):
        rospy.loginfo("%s: injecting '%s'", rospy.get_name(), line)
        rospy.set_param("/jackal_plant/faults", [line])
        return rospy.get_rostime().to_sec()

    def first_event(self, word, channel, since):
        """(time, values) of the first sensor-health report of '<word> <channel>' at or after `since`."""
        for _, _, values in self.s.snapshot("health"):
            t = event_time(values, word, channel)
            if t is not None and t >= since:
                return t, values
        return None

    def reported_channels(self, until):
        """The channels sensor health reported anything but 'ok' for before plant time `until`."""
        return sorted({k for t, _, v in self.s.snapshot("health") if t < until for k, x in v.items()
                       if k in ("omega_left", "omega_right", "gyro_z") and not x.startswith("ok")})

    def test_fault(self):
        scenario = p("scenario", "")
        self.assertIn(scenario, SCENARIOS, "~scenario must be one of %s" % (SCENARIOS,))
        getattr(self, "run_" + scenario)(float(p("speed", 0.5)))
        odom = self.s.snapshot("odom")
        self.assertTrue(all(math.isfinite(x) for o in odom for x in o), "non-finite /odom")
        self.assertLess(max(abs(o[1]) for o in odom), 3.0, "runaway: |v_x| >= 3 m/s")

    # ---- scenarios

    def run_sensor_loss(self, v):
        limit = float(p("report_limit", 0.3))
        t0 = self.d.set(v)
        self.wait(lambda: self.steady(v, 0.0, t0), 10.0, "steady at %.2f m/s" % v)
        t_set = self.inject("imu dropout")
        self.assertEqual(self.reported_channels(t_set), [], "a channel reported before the fault")

        def missing():
            return [h for h in self.s.snapshot("health") if h[0] >= t_set
                    and h[2].get("gyro_z", "").startswith("missing")]
        self.wait(lambda: missing(), 5.0, "sensor health reports gyro_z missing")
        last_imu = max(s for s in self.s.snapshot("imu") if s <= missing()[0][0])
        report = missing()[0]
        rospy.loginfo("sensor_loss: gyro_z reported missing %.3f s after the last IMU sample", report[0] - last_imu)
        self.assertEqual(report[1], DiagnosticStatus.WARN)
        self.assertLessEqual(report[0] - last_imu, limit,
                             "gyro_z reported missing %.3f s after the last IMU sample" % (report[0] - last_imu))

    def run_frozen_sensor(self, v):
        rate = float(p("turn_rate", 0.8))
        t0 = self.d.set(v, rate)
        self.wait(lambda: self.steady(v, rate, t0, tol=0.1), 10.0, "turning at (%.2f, %.2f)" % (v, rate))
        t_set = self.inject("gyro freeze")
        # The frozen gyro agrees with the turn while it lasts: wait for the freeze to be in the
        # stream (IMU samples past it), then end the turn.
        self.wait(lambda: any(s >= t_set + 0.5 for s in self.s.snapshot("imu")), 5.0, "IMU samples after the freeze")
        self.assertEqual(self.reported_channels(t_set), [], "a channel reported before the turn ended")
        t_straight = self.d.set(v, 0.0)
        self.wait(lambda: self.first_event("isolated", "gyro_z", t_set) is not None, 10.0,
                  "gyro_z isolated after the set point went straight")
        t_iso, _ = self.first_event("isolated", "gyro_z", t_set)
        rospy.loginfo("frozen_sensor: gyro_z isolated %.3f s after the set point went straight", t_iso - t_straight)
        self.assertLessEqual(t_iso - t_straight, float(p("isolation_limit", 1.0)),
                             "gyro_z isolated %.3f s after the set point went straight" % (t_iso - t_straight))

    def run_bias(self, v):
        bias = float(p("bias", 2.5))
        side = p("side", "left")
        t0 = self.d.set(v)
        self.wait(lambda: self.steady(v, 0.0, t0), 10.0, "steady at %.2f m/s" % v)
        t_set = self.inject("%s_encoder bias %g" % (side, bias))
        self.assertEqual(self.reported_channels(t_set), [], "a channel reported before the fault")
        sign = 1.0 if side == "left" else -1.0  # left - right moves by +bias (left) or -bias (right)
        base = mean([j[1] - j[2] for j in self.s.snapshot("joints") if t_set - 1.0 <= j[0] < t_set])

        def onset():
            return next((j[0] for j in self.s.snapshot("joints") if j[0] >= t_set
                         and sign * math.copysign(1.0, bias) * ((j[1] - j[2]) - base) > 0.5 * abs(bias)), None)
        self.wait(lambda: onset() is not None, 5.0, "the bias on /joint_states")
        channel = "omega_" + side
        self.wait(lambda: self.first_event("isolated", channel, t_set) is not None, 5.0, channel + " isolated")
        t_iso, _ = self.first_event("isolated", channel, t_set)
        rospy.loginfo("bias: %s isolated %.3f s after the first biased sample", channel, t_iso - onset())
        self.assertLessEqual(t_iso - onset(), float(p("isolation_limit", 0.5)),
                             "%s isolated %.3f s after the first biased sample" % (channel, t_iso - onset()))


if __name__ == "__main__":
    rospy.init_node("fault_check")
    rostest.rosrun(PKG, "fault_check", FaultCheck, sys.argv)
