#!/usr/bin/env python3
"""rostest: a robot's ordinary day on simulated time: after an operation around the node the
commanded body speed is back within a band of the set point soon after the first new sensor
sample, and no command in between rises above the previous one by more than the action limit.

Scenarios (~scenario):
  plant_restart  the plant node (use_sim_time, respawn in the .test) is killed while the robot
                 drives; roslaunch restarts it, /clock and the stamps begin again at 0
  loop_replay    `rosbag play --clock --loop` of a bag of the robot driving at the set point
                 (written here): at every loop /clock and the stamps go back
  driver_pause   the sensor driver stops for ~pause s (the plant's ~faults drop /joint_states and
                 /imu/data, /status reports the drivers inactive) and comes back
  node_respawn   the jackal_AIC node (respawn in the .test) is killed while the robot drives at
                 the set point; roslaunch restarts it
The test publishes the set point itself (~set_point [m/s], 20 Hz on the wall clock, so it
streams while /clock stands still during a restart).

Judged on message stamps and on simulated receipt times: t0 = the stamp of the first sensor
sample of the new timeline (plant_restart, loop_replay: the first stamp below its predecessor),
after the pause (driver_pause: the first after a gap of half the pause), or the first the new
node received (node_respawn: the sample before the newest one received when the new node's first
/cmd_drive arrives; the node commands nothing before its first sample). Recovery = the receipt
time of the first /cmd_drive at or after t0 whose body speed r (left + right) / 2 is within
~band (5 %) of the set point, minus t0; it must be <= ~max_recovery (0.5 s). Every /cmd_drive
from the last one before the operation to 1 s after t0: the rise of |wheel command| over the
previous command <= ~max_rise [rad/s] (the node's max_action_lead); and a ~belief stamped within
~max_recovery of t0 (the controller runs on the new samples). Prints "MEASURED ..." lines.
"""
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import rosgraph
import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist, TwistStamped
from jackal_msgs.msg import Drive, Status
from sensor_msgs.msg import Imu, JointState

from jackal_aic_tools.common import ros_process

WHEEL_RADIUS = 0.098  # m (the Jackal's, sim/urdf/jackal.urdf)


class Log:
    """Every message of a topic with its wall arrival time and simulated receipt time."""

    def __init__(self, topic, msg_type):
        self.items = []  # (wall, ros time, msg)
        self.lock = threading.Lock()
        self.sub = rospy.Subscriber(topic, msg_type, self.callback, queue_size=100000, tcp_nodelay=True)

    def callback(self, msg):
        with self.lock:
            self.items.append((time.monotonic(), rospy.get_rostime().to_sec(), msg))

    def snapshot(self):
        with self.lock:
            return list(self.items)


def wait_wall(predicate, timeout, period=0.05):
    """Poll predicate() on the wall clock (simulated time stands still during a restart)."""
    deadline = time.monotonic() + timeout
    while not rospy.is_shutdown() and time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return predicate()


def body_speed(msg):
    return WHEEL_RADIUS * 0.5 * (msg.drivers[0] + msg.drivers[1])


class RestartTest(unittest.TestCase):
    def setUp(self):
        self.scenario = rospy.get_param("~scenario")
        self.set_point = float(rospy.get_param("~set_point", 0.5))
        self.band = float(rospy.get_param("~band", 0.05))
        self.max_recovery = float(rospy.get_param("~max_recovery", 0.5))
        self.max_rise = float(rospy.get_param("~max_rise", 1.606))
        self.pause = float(rospy.get_param("~pause", 5.0))
        self.drive_time = float(rospy.get_param("~drive_time", 4.0))
        self.joints = Log("/joint_states", JointState)
        self.cmd = Log("/cmd_drive", Drive)
        self.belief = Log("/jackal_AIC/belief", TwistStamped)
        self.status_pub = rospy.Publisher("/status", Status, queue_size=10, latch=True)
        self.drivers_active = True
        self.stop = False
        threading.Thread(target=self.set_point_loop, daemon=True).start()

    def tearDown(self):
        self.stop = True

    def set_point_loop(self):
        pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
        msg = Twist()
        msg.linear.x = self.set_point
        while not self.stop and not rospy.is_shutdown():
            pub.publish(msg)
            time.sleep(0.05)

    def publish_status(self, active):
        s = Status()
        s.header.stamp = rospy.get_rostime()
        s.drivers_active = active
        self.status_pub.publish(s)

    # ---- the steps ----------------------------------------------------------------------
    def newest_stamp(self):
        items = self.joints.snapshot()
        return items[-1][2].header.stamp.to_sec() if items else -1.0

    def driving(self):
        """At the set point: the last 0.5 s of commands within the band, after drive_time."""
        items = self.cmd.snapshot()
        if not items or items[-1][1] < self.drive_time:
            return False
        recent = [body_speed(m) for w, t, m in items if t >= items[-1][1] - 0.5]
        return len(recent) > 10 and all(abs(v - self.set_point) <= self.band * self.set_point for v in recent)

    def first_back_stamp(self, since_index):
        """Index and stamp of the first joint state (from since_index) stamped below its predecessor."""
        items = self.joints.snapshot()
        for i in range(max(since_index, 1), len(items)):
            if items[i][2].header.stamp < items[i - 1][2].header.stamp:
                return i, items[i][2].header.stamp.to_sec()
        return None

    def first_after_gap(self, since_index, min_gap):
        items = self.joints.snapshot()
        for i in range(max(since_index, 1), len(items)):
            if (items[i][2].header.stamp - items[i - 1][2].header.stamp).to_sec() >= min_gap:
                return i, items[i][2].header.stamp.to_sec()
        return None

    def judge(self, t0, t0_wall, cmd_index_before, label):
        """Recovery and command rises after the operation (see the module docstring)."""
        self.assertTrue(wait_wall(lambda: self.cmd.snapshot()[-1][1] >= t0 + 1.5 and
                                  self.cmd.snapshot()[-1][0] > t0_wall, 30.0),
                        "%s: no /cmd_drive 1.5 s after the first new sample" % label)
        items = self.cmd.snapshot()
        after = [(w, t, m) for w, t, m in items[cmd_index_before:] if w >= t0_wall - 0.02]
        # On the new timeline: a command received just after the jump may still carry the old
        # timeline's receipt time; simulated time runs at about the wall clock's pace here.
        after = [(w, t, m) for w, t, m in after if t >= t0 - 1e-6 and t - t0 <= (w - t0_wall) + 0.2]
        recovered = [t for w, t, m in after if abs(body_speed(m) - self.set_point) <= self.band * self.set_point]
        self.assertTrue(recovered, "%s: the commanded speed never came back within %.0f %% of %.2f m/s" %
                        (label, 100 * self.band, self.set_point))
        recovery = recovered[0] - t0
        # From the last command before the operation (not earlier: the node's first start, from
        # the idle command, is no restart) to 1 s into the new timeline.
        last_before = max([i for i in range(max(cmd_index_before - 1, 0), len(items))
                           if items[i][0] < t0_wall - 0.02] or [max(cmd_index_before - 1, 0)])
        window = [m for w, t, m in items[last_before:] if w < t0_wall - 0.02 or t <= t0 + 1.0]
        rise = 0.0
        for a, b in zip(window, window[1:]):
            for k in (0, 1):
                rise = max(rise, abs(b.drivers[k]) - abs(a.drivers[k]))
        for m in window:
            self.assertTrue(all(math.isfinite(d) for d in m.drivers))
        print("MEASURED %s: recovery %.3f s after the first new sample (t0 %.3f s); largest command rise "
              "%.3f rad/s over %d commands" % (label, recovery, t0, rise, len(window)), file=sys.stderr)
        rospy.loginfo("%s: recovery %.3f s, largest rise %.3f rad/s", label, recovery, rise)
        self.assertLessEqual(recovery, self.max_recovery, "%s: recovery %.3f s" % (label, recovery))
        beliefs = [m.header.stamp.to_sec() for w, t, m in self.belief.snapshot()
                   if w >= t0_wall - 0.02 and t0 <= m.header.stamp.to_sec() <= t0 + self.max_recovery]
        self.assertTrue(beliefs, "%s: the controller did not run on the new samples within %.2f s (no ~belief "
                        "stamped then)" % (label, self.max_recovery))
        self.assertLessEqual(rise, self.max_rise + 1e-3, "%s: a command rose %.3f rad/s over the previous one" %
                             (label, rise))

    # ---- scenarios ----------------------------------------------------------------------
    def test_recovers(self):
        getattr(self, "run_" + self.scenario)()

    def run_plant_restart(self):
        self.assertTrue(wait_wall(self.driving, 60.0), "never drove at the set point")
        n_joints = len(self.joints.snapshot())
        n_cmd = len(self.cmd.snapshot())
        rosnode.kill_nodes(["/jackal_plant"])
        self.assertTrue(wait_wall(lambda: self.first_back_stamp(n_joints) is not None, 60.0),
                        "the restarted plant's stamps never began again")
        i, t0 = self.first_back_stamp(n_joints)
        self.judge(t0, self.joints.snapshot()[i][0], n_cmd, "plant restart")

    def run_loop_replay(self):
        bag = self.write_bag()
        player = ros_process.start(["rosbag", "play", "--clock", "--loop", "-q", bag], stderr=subprocess.DEVNULL)
        try:
            since = 0
            for loop in (1, 2):
                n_cmd = len(self.cmd.snapshot())
                self.assertTrue(wait_wall(lambda: self.first_back_stamp(since) is not None, 60.0),
                                "the replay never looped")
                i, t0 = self.first_back_stamp(since)
                self.judge(t0, self.joints.snapshot()[i][0], n_cmd, "replay loop %d" % loop)
                since = i + 1
        finally:
            ros_process.stop(player)
            os.unlink(bag)

    def write_bag(self):
        """A 3 s bag of the robot driving at the set point: joint states and IMU at 50 Hz."""
        import rosbag
        fd, path = tempfile.mkstemp(suffix=".bag")
        os.close(fd)
        omega = self.set_point / WHEEL_RADIUS
        names = ["front_left_wheel", "front_right_wheel", "rear_left_wheel", "rear_right_wheel"]
        with rosbag.Bag(path, "w") as bag:
            for k in range(150):
                stamp = rospy.Time.from_sec(10.0 + 0.02 * k)
                js = JointState()
                js.header.stamp = stamp
                js.name = names
                js.position = [omega * 0.02 * k] * 4
                js.velocity = [omega] * 4
                bag.write("/joint_states", js, stamp)
                imu = Imu()
                imu.header.stamp = stamp + rospy.Duration(0.002)
                imu.orientation.w = 1.0
                imu.linear_acceleration.z = 9.81
                bag.write("/imu/data", imu, imu.header.stamp)
        return path

    def run_driver_pause(self):
        self.publish_status(True)
        self.assertTrue(wait_wall(self.driving, 60.0), "never drove at the set point")
        n_joints = len(self.joints.snapshot())
        n_cmd = len(self.cmd.snapshot())
        rospy.set_param("/jackal_plant/faults", ["joint_states dropout 0 %g" % self.pause,
                                                 "imu dropout 0 %g" % self.pause])
        self.publish_status(False)
        self.assertTrue(wait_wall(lambda: self.first_after_gap(n_joints, 0.5 * self.pause) is not None,
                                  self.pause * 3 + 30.0), "the sensors never came back")
        i, t0 = self.first_after_gap(n_joints, 0.5 * self.pause)
        self.publish_status(True)  # the driver is back
        self.judge(t0, self.joints.snapshot()[i][0], n_cmd, "driver pause %.1f s" % self.pause)

    def run_node_respawn(self):
        self.assertTrue(wait_wall(self.driving, 60.0), "never drove at the set point")
        master = rosgraph.Master(rospy.get_name())

        def subscribed():
            return any(t == "/joint_states" and "/jackal_AIC" in nodes for t, nodes in master.getSystemState()[1])

        n_cmd = len(self.cmd.snapshot())
        rosnode.kill_nodes(["/jackal_AIC"])
        self.assertTrue(wait_wall(lambda: not subscribed(), 20.0), "the node did not die")
        self.assertTrue(wait_wall(subscribed, 30.0, 0.01), "the node was not respawned")
        t_sub = time.monotonic()
        # The new node's first command follows its first sample (it commands nothing before one):
        # the sample before the newest one received by then is no later than the node's first.
        self.assertTrue(wait_wall(lambda: any(w > t_sub for w, t, m in self.cmd.snapshot()), 10.0),
                        "the respawned node never commanded")
        w_cmd = [w for w, t, m in self.cmd.snapshot() if w > t_sub][0]
        before = [(w, m) for w, t, m in self.joints.snapshot() if w <= w_cmd]
        w0, first = before[-2] if len(before) > 1 else before[-1]
        self.judge(first.header.stamp.to_sec(), w0, n_cmd, "node respawn")


if __name__ == "__main__":
    rospy.init_node("restart_check")
    rostest.rosrun("jackal_aic", "restart_check", RestartTest, sys.argv)
