#!/usr/bin/env python3
"""Fault-injection check of the closed loop (jackal_AIC + the ODE plant): drives a set-point
profile on /jackal_AIC/set_point, injects one fault into the plant through its ~faults
parameter (sim/README.md, 'Fault injection'), and asserts on /odom (ground truth, by stamp),
/joint_states and /jackal_AIC/sensor_health. Scenarios (~scenario):

  imu_loss      0 -> v step (healthy), back to 0, then the same step with the IMU dropping out
                ~fault_delay s after it: the faulty step settles (+-5 %) within
                ~settle_ratio x the healthy one, and sensor health reports the IMU missing.
  encoder_bias  drive v straight; a bias of ~bias rad/s steps onto the ~side (left) encoder: it is isolated
                within ~isolation_limit s of the bias's first sample, and the speed error over the
                last ~window s is <= ~speed_error_limit (fraction of v).
  gyro_freeze   turn at (v, ~turn_rate) for ~turn_time s (long enough for the plant's turn to break
                away and reach the set point, so the gyro freezes at about ~turn_rate); 1 s later the
                set point goes straight: the gyro is isolated and the yaw rate over the last ~window s
                is below ~yaw_rate_limit.
  payload       ~payload kg are added at rest, then a step to (v, ~turn_rate): it settles within
                ~settle_limit s, the speed error over the last ~window s is <= ~speed_error_limit,
                the yaw rate within ~yaw_rate_limit of the set point (no runaway: |v_x| < 3 m/s).
  friction      as payload, with the wheel-ground friction of ~side scaled by ~friction_scale.

~expect_worse true (with the node's fdi_enabled false): the same run must end OUTSIDE the limit
(showing what isolation buys) and must not isolate anything.
"""
import math
import sys
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

PKG = "jackal_aic"


def p(name, default):
    return rospy.get_param("~" + name, default)


class Streams:
    """Records (stamp, v_x, omega_z) from /odom, (receipt time, left, right wheel speed) from
    /joint_states and (receipt time, level, message, values) from /jackal_AIC/sensor_health."""

    def __init__(self):
        self.lock = threading.Lock()
        self.odom, self.joints, self.health = [], [], []
        rospy.Subscriber("/odom", Odometry, self._odom, queue_size=10000, tcp_nodelay=True)
        rospy.Subscriber("/joint_states", JointState, self._joints, queue_size=10000, tcp_nodelay=True)
        rospy.Subscriber("/jackal_AIC/sensor_health", DiagnosticStatus, self._health, queue_size=1000)

    def _odom(self, m):
        with self.lock:
            self.odom.append((m.header.stamp.to_sec(), m.twist.twist.linear.x, m.twist.twist.angular.z))

    def _joints(self, m):
        left = [v for n, v in zip(m.name, m.velocity) if "left" in n]
        right = [v for n, v in zip(m.name, m.velocity) if "right" in n]
        if left and right:
            with self.lock:
                # Receipt time: the node stamps its fault events with its own clock on receipt.
                self.joints.append((rospy.get_rostime().to_sec(), sum(left) / len(left), sum(right) / len(right)))

    def _health(self, m):
        values = {kv.key: kv.value for kv in m.values}
        with self.lock:
            self.health.append((rospy.get_rostime().to_sec(), m.level, m.message, values))

    def odom_between(self, t0, t1):
        with self.lock:
            return [o for o in self.odom if t0 <= o[0] <= t1]


class Driver:
    def __init__(self):
        self.pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
        self.v, self.w = 0.0, 0.0
        self.timer = rospy.Timer(rospy.Duration(0.05), self._tick)  # 20 Hz, within the set-point timeout

    def set(self, v, w=0.0):
        self.v, self.w = v, w
        self._tick(None)

    def _tick(self, _):
        msg = Twist()
        msg.linear.x, msg.angular.z = self.v, self.w
        self.pub.publish(msg)


def settling_time(samples, t_step, start, target, band=0.05):
    """Time from t_step until v_x stays within +-band x |target - start| of target (None if never)."""
    tol = band * abs(target - start)
    last_out = None
    for t, v, _ in samples:
        if t >= t_step and abs(v - target) > tol:
            last_out = t
    if not samples or samples[-1][0] - (last_out or t_step) < 0.3:
        return None
    return (last_out - t_step) if last_out is not None else 0.0


def fault_end(line):
    """When a timed ~faults line 'TARGET KIND [VALUE] START DURATION [PERIOD]' ends [s after it
    is read] (sim/README.md, 'Fault injection'): START + DURATION; VALUE is there for bias,
    spikes, delay and set, PERIOD only for spikes."""
    fields = line.split()
    numbers = [float(x) for x in fields[2:]]
    if fields[1] in ("bias", "spikes", "delay", "set"):
        numbers = numbers[1:]
    return numbers[0] + numbers[1]


def mean(xs):
    return sum(xs) / len(xs) if xs else float("nan")


class FaultCheck(unittest.TestCase):

    def setUp(self):
        self.s = Streams()
        self.d = Driver()
        ok = False
        deadline = rospy.Time.now() + rospy.Duration(float(p("ready_timeout", 30.0)))
        while not rospy.is_shutdown() and rospy.Time.now() < deadline:
            with self.s.lock:
                ok = len(self.s.odom) > 10 and len(self.s.health) > 0
            if ok:
                break
            rospy.sleep(0.1)
        self.assertTrue(ok, "no /odom or /jackal_AIC/sensor_health within the ready timeout")
        rospy.set_param("/jackal_plant/faults", [])
        rospy.sleep(1.0)

    def inject(self, line):
        rospy.loginfo("%s: injecting '%s'", rospy.get_name(), line)
        rospy.set_param("/jackal_plant/faults", [line])
        return rospy.get_rostime().to_sec()

    def events(self, t0, word):
        """(receipt time, values) of the health messages that first reported an event `word` that
        happened at or after t0 (the 'last event' value reads '<word> <channel> at <time>')."""
        out, seen = [], set()
        with self.s.lock:
            for t, _, _, v in self.s.health:
                ev = v.get("last event", "")
                if not ev.startswith(word) or ev in seen:
                    continue
                try:
                    when = float(ev.rsplit(" at ", 1)[1])
                except (IndexError, ValueError):
                    continue
                if when >= t0:
                    seen.add(ev)
                    out.append((when, v))
        return out

    def isolated_channels(self, t0):
        with self.s.lock:
            return sorted({k for t, _, _, v in self.s.health if t >= t0 for k, x in v.items()
                           if x.startswith("isolated")})

    def test_fault(self):
        scenario = p("scenario", "encoder_bias")
        expect_worse = bool(p("expect_worse", False))
        v = float(p("speed", 0.5))
        window = float(p("window", 1.0))
        getattr(self, "run_" + scenario)(v, window, expect_worse)
        with self.s.lock:
            odom = list(self.s.odom)
        self.assertTrue(all(math.isfinite(x) for o in odom for x in o), "non-finite /odom")
        self.assertLess(max(abs(o[1]) for o in odom), 3.0, "runaway: |v_x| >= 3 m/s")

    # ---- scenarios

    def run_imu_loss(self, v, window, expect_worse):
        ratio = float(p("settle_ratio", 1.5))
        delay = float(p("fault_delay", 0.2))
        t1 = rospy.get_rostime().to_sec()
        self.d.set(v)
        rospy.sleep(3.0)
        self.d.set(0.0)
        rospy.sleep(2.5)
        t2 = rospy.get_rostime().to_sec()
        self.d.set(v)
        rospy.sleep(delay)
        t_fault = self.inject("imu dropout")
        rospy.sleep(3.0)
        healthy = settling_time(self.s.odom_between(t1, t1 + 3.0), t1, 0.0, v)
        faulty = settling_time(self.s.odom_between(t2, t2 + 3.0), t2, 0.0, v)
        rospy.loginfo("imu_loss: settling %s s healthy, %s s with the IMU lost %.2f s into the step",
                      healthy, faulty, t_fault - t2)
        self.assertIsNotNone(healthy, "the healthy step never settled")
        self.assertIsNotNone(faulty, "the step with the IMU lost never settled")
        self.assertLessEqual(faulty, ratio * max(healthy, 0.1),
                             "settling %.3f s with the IMU lost > %.1f x healthy %.3f s" % (faulty, ratio, healthy))
        with self.s.lock:
            missing = [h for h in self.s.health if h[0] > t_fault + 0.5
                       and h[3].get("gyro_z", "").startswith("missing")]
        self.assertTrue(missing, "sensor health never reported the gyro missing")
        self.assertEqual(missing[-1][1], DiagnosticStatus.WARN)

    def run_encoder_bias(self, v, window, expect_worse):
        bias = float(p("bias", 2.0))
        limit = float(p("speed_error_limit", 0.05))
        self.d.set(v)
        rospy.sleep(3.0)
        side = p("side", "left")
        t_set = self.inject("%s_encoder bias %g" % (side, bias))
        # Onset: the first joint_states whose left-right difference jumped by more than half the bias.
        rospy.sleep(float(p("hold", 8.0)))
        with self.s.lock:
            before = [j for j in self.s.joints if t_set - 1.0 <= j[0] < t_set]
            sign = 1.0 if side == "left" else -1.0  # left - right moves by +bias (left) or -bias (right)
            base = mean([j[1] - j[2] for j in before])
            onset = next((j[0] for j in self.s.joints
                          if j[0] >= t_set and sign * ((j[1] - j[2]) - base) * (1 if bias > 0 else -1) > 0.5 * abs(bias)),
                         None)
        self.assertIsNotNone(onset, "the bias never showed on /joint_states")
        t_end = self.s.odom[-1][0]
        err = abs(mean([o[1] for o in self.s.odom_between(t_end - window, t_end)]) - v) / v
        iso = self.events(t_set, "isolated")
        rospy.loginfo("encoder_bias: onset %.3f s after injection; isolations %s; speed error %.2f %%",
                      onset - t_set, [(round(t - onset, 3), e.get("last event")) for t, e in iso[:1]], 100 * err)
        if expect_worse:
            self.assertEqual(self.isolated_channels(t_set), [], "isolated although fdi_enabled is false")
            self.assertGreater(err, limit, "without isolation the speed error %.2f %% is within the limit: the "
                               "isolation test shows nothing" % (100 * err))
            return
        self.assertTrue(iso, "the biased encoder was never isolated")
        self.assertIn("omega_" + side, iso[0][1].get("last event", ""))
        # Both times are receipt times on this host's clock (the node stamps an event when the sample
        # that caused it arrives), so plant lag does not enter.
        self.assertLessEqual(iso[0][0] - onset, float(p("isolation_limit", 0.5)),
                             "isolated %.3f s after the bias's first sample" % (iso[0][0] - onset))
        self.assertLessEqual(err, limit, "speed error %.2f %% after isolation" % (100 * err))

    def run_gyro_freeze(self, v, window, expect_worse):
        rate = float(p("turn_rate", 0.8))
        limit = float(p("yaw_rate_limit", 0.1))
        self.d.set(v, rate)
        rospy.sleep(float(p("turn_time", 3.0)))
        t_set = self.inject("gyro freeze")
        rospy.sleep(1.0)
        t_straight = rospy.get_rostime().to_sec()
        self.d.set(v, 0.0)
        rospy.sleep(float(p("hold", 5.0)))
        t_end = self.s.odom[-1][0]
        yaw = mean([o[2] for o in self.s.odom_between(t_end - window, t_end)])
        iso = self.events(t_set, "isolated")
        rospy.loginfo("gyro_freeze: isolations %s (%s s after the set point went straight); yaw rate %.3f rad/s "
                      "at the end", [e.get("last event") for _, e in iso[:1]],
                      ["%.3f" % (t - t_straight) for t, _ in iso[:1]], yaw)
        if expect_worse:
            self.assertEqual(self.isolated_channels(t_set), [], "isolated although fdi_enabled is false")
            self.assertGreater(abs(yaw), limit, "without isolation the yaw rate %.3f rad/s is within the limit"
                               % yaw)
            return
        self.assertTrue(iso, "the frozen gyro was never isolated")
        self.assertIn("gyro_z", iso[0][1].get("last event", ""))
        self.assertLess(abs(yaw), limit, "yaw rate %.3f rad/s with the gyro isolated" % yaw)

    def run_transients(self, v, window, expect_worse):
        """Transient sensor faults in a steady run at v: the ~faults lines (each 'TARGET KIND
        [VALUE] START DURATION [PERIOD]', START relative to injection) at once. While they last
        and 1 s after, the true speed stays within ~deviation_limit [m/s] of v and the yaw rate
        within ~yaw_rate_limit; over the last window the speed error is <= ~speed_error_limit."""
        lines = list(p("faults", ["gyro spikes 3 0 1 0.1", "joint_states delay 0.06 1.5 0.5",
                                  "joint_states dropout 2.5 0.15", "left_encoder spikes 5 3.5 0.5 0.1"]))
        limit = float(p("speed_error_limit", 0.05))
        self.d.set(v)
        rospy.sleep(3.0)
        rospy.loginfo("%s: injecting %s", rospy.get_name(), lines)
        rospy.set_param("/jackal_plant/faults", lines)
        t_set = rospy.get_rostime().to_sec()
        end = max(fault_end(l) for l in lines)
        rospy.sleep(end + 1.0 + float(p("hold", 3.0)))
        during = self.s.odom_between(t_set, t_set + end + 1.0)
        t_end = self.s.odom[-1][0]
        last = self.s.odom_between(t_end - window, t_end)
        dev = max(abs(o[1] - v) for o in during)
        yaw = max(abs(o[2]) for o in during)
        err = abs(mean([o[1] for o in last]) - v) / v
        rospy.loginfo("transients: max |v - %.2f| %.3f m/s and max |yaw rate| %.3f rad/s during the faults; "
                      "speed error %.2f %% over the last %.1f s; isolated during them: %s", v, dev, yaw, 100 * err,
                      window, self.isolated_channels(t_set))
        self.assertLessEqual(dev, float(p("deviation_limit", 0.1)), "speed off by %.3f m/s during the faults" % dev)
        self.assertLessEqual(yaw, float(p("yaw_rate_limit", 0.2)), "yaw rate %.3f rad/s during the faults" % yaw)
        self.assertLessEqual(err, limit, "speed error %.2f %% after the faults" % (100 * err))

    def run_payload(self, v, window, expect_worse):
        self.run_physical(v, window, "payload set %g" % float(p("payload", 10.0)))

    def run_friction(self, v, window, expect_worse):
        self.run_physical(v, window, "friction_%s set %g" % (p("side", "left"), float(p("friction_scale", 0.2))))

    def run_physical(self, v, window, line):
        """A physical fault injected at rest, then a step to (v, ~turn_rate): the step settles (+-5 %)
        within ~settle_limit s, the speed error over the last window is <= ~speed_error_limit and the
        yaw rate is within ~yaw_rate_limit of the set point."""
        limit = float(p("speed_error_limit", 0.05))
        w = float(p("turn_rate", 0.0))
        self.d.set(0.0)
        rospy.sleep(1.0)
        self.inject(line)
        rospy.sleep(1.0)
        t_step = rospy.get_rostime().to_sec()
        self.d.set(v, w)
        rospy.sleep(float(p("hold", 5.0)))
        t_end = self.s.odom[-1][0]
        last = self.s.odom_between(t_end - window, t_end)
        err = abs(mean([o[1] for o in last]) - v) / v
        settle = settling_time(self.s.odom_between(t_step, t_end), t_step, 0.0, v)
        yaw = mean([o[2] for o in last])
        rospy.loginfo("%s: step to (%.2f m/s, %.2f rad/s) settles in %s s; speed error %.2f %% over the last %.1f s; "
                      "yaw rate %.3f rad/s", p("scenario", ""), v, w, settle, 100 * err, window, yaw)
        self.assertIsNotNone(settle, "the step never settled after '%s'" % line)
        self.assertLessEqual(settle, float(p("settle_limit", 1.5)), "settling %.3f s after '%s'" % (settle, line))
        self.assertLessEqual(err, limit, "speed error %.2f %% after '%s'" % (100 * err, line))
        self.assertLess(abs(yaw - w), float(p("yaw_rate_limit", 0.1)), "yaw rate %.3f rad/s after '%s'" % (yaw, line))


if __name__ == "__main__":
    rospy.init_node("fault_check")
    rostest.rosrun(PKG, "fault_check", FaultCheck, sys.argv)
