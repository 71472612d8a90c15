#!/usr/bin/env python3
"""The robot's command path on the simulated stock base (test/rostest/robot_path_sim.launch:
plant on simulated time, the stock diff drive, the twist_mux stand-in) with launch/robot.launch.
Times are ROS (simulated) times: the receipt time of each message in this node; every wait is
on a condition with a deadline, never a fixed sleep.

~mode drive (robot.launch started by the .test): navigation (/cmd_vel) at ~speed m/s; the mean
  /odom speed over ~steady_window s comes within ~speed_tol; /jackal_velocity_controller/cmd_vel
  has one publisher (/jackal_AIC), /cmd_drive one (/stock_base); the joystick
  (joy_teleop/cmd_vel, ~joystick_speed) outranks navigation and, after it stops, navigation
  drives again once the joystick's input times out (0.5 s); the e-stop lock (/e_stop true)
  stops the wheel commands within ~stop_limit s while navigation keeps publishing; released,
  the robot drives at ~speed again.
~mode stop_path (this node starts robot.launch itself, twice, on the same simulation):
  `roslaunch jackal_aic robot.launch` (the AIC) and then `robot.launch controller:=stock` (the
  stock relay); for each, once at 0.5 m/s and once at 1.0 m/s + 0.5 rad/s: drive until
  steady, engage the lock with navigation still publishing, and take the time from the last
  set point twist_mux forwarded (/twist_mux/cmd_vel; the lock silences it) to the last
  /cmd_drive with a wheel above ~wheel_threshold rad/s. At each speed the AIC's time is no
  longer than the stock path's. Timed from the path's last input, not from the lock: between
  the lock and twist_mux's last output lies up to one period of navigation's 20 Hz stream,
  whose phase differs between engagements and is the same for both paths; from the last
  input the AIC stops within set_point_timeout 0.2 s + two 20 ms cycles, the stock path after
  its diff drive's cmd_vel_timeout of 0.25 s (config/robot.yaml), whatever the phases, so one
  engagement per case decides. The times from the lock are printed too.
~mode first_message (this node starts `robot.launch controller:=stock` itself): the relay
  advertises the diff drive's input at start-up (it is listed as its publisher before any
  twist), and once its connections are up (twist_mux -> relay -> diff drive), the first and only
  set point navigation sends (~speed m/s, one message) reaches the relay's output
  (/jackal_velocity_controller/cmd_vel, from /jackal_AIC_bypass, this value) and the diff drive
  turns the wheels for it (a /cmd_drive wheel above ~wheel_threshold rad/s).
"""
import os
import statistics
import sys
import threading
import unittest

import rosgraph
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from jackal_msgs.msg import Drive
from nav_msgs.msg import Odometry
from std_msgs.msg import Bool

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from aic_test_utils import connections, live_publishers, wait_for, write_section  # noqa: E402
from jackal_aic_tools.common import ros_process  # noqa: E402

PKG = "jackal_aic"
CMD_VEL = "/jackal_velocity_controller/cmd_vel"
SET_POINT = "/twist_mux/cmd_vel"


def publishers_of(topic):
    """Node names the master lists as publishers of `topic`."""
    pubs, _, _ = rosgraph.Master("/robot_path_check").getSystemState()
    for name, nodes in pubs:
        if name == topic:
            return sorted(nodes)
    return []


STOP_PATHS_TITLE = "# Stop paths on the robot's path: the e-stop lock, AIC against the stock relay\n"


def plant_real_time_factor():
    """The plant node's node.real_time_factor as its ~overrides set it (launch/plant.launch), or
    None where they do not (the plant YAML's own value)."""
    for item in rospy.get_param("/jackal_plant/overrides", []) or []:
        key, _, value = str(item).partition("=")
        if key.strip() == "node.real_time_factor":
            try:
                return float(value)
            except ValueError:
                return None
    return None


def write_stop_paths(path, sim_time, engagements, threshold, speeds, runs, results, load, base="stock_diff_drive",
                     real_time_factor=None):
    """Write this clock's and base's section of the stop-path results file `path` (Markdown),
    keeping the other sections the file has. runs: (controller, v, w) -> [(from the last
    input, from the lock)] [s] per engagement; results: the same key -> the median engagement;
    load: the host's load averages (1, 5, 15 min) before and after; base: the stock base of
    launch/stock_base.launch (stock_diff_drive, the stand-in: sections keyed by the clock alone;
    jackal_node: keyed "jackal_node <clock>"); real_time_factor: on simulated time, the plant's
    pace against the wall clock where it is known (named in the heading)."""
    key = "sim_time" if sim_time else "real_time"
    if base != "stock_diff_drive":
        key = "%s %s" % (base, key)
    rel, full = "doc/results/", os.path.abspath(path)
    where = "$PWD/" + full[full.index(rel):] if rel in full else path
    command = "rostest jackal_aic robot_stop_path.test %s%sengagements:=%d output:=%s" % (
        "" if base == "stock_diff_drive" else "base:=%s " % base,
        "" if sim_time else "use_sim_time:=false ", engagements, where)
    fmt = lambda r: "%.3f (%.3f)" % r  # noqa: E731
    pace = "" if real_time_factor is None else ", %g x real time" % real_time_factor
    clock = ("Simulated time (the plant's /clock%s)" % pace if sim_time else
             "Real time (every node on the wall clock, the plant paced at real time)")
    body = ["## %s" % (clock if base == "stock_diff_drive" else "%s: %s" % (base, clock)),
            "",
            "Written by `%s` (test/rostest/robot_path_check.py, mode stop_path): %d lock engagement(s) per case, "
            "the median; host load average (1, 5, 15 min) before %s, after %s; %d CPU(s)."
            % (command, engagements, " ".join("%.2f" % x for x in load[0]), " ".join("%.2f" % x for x in load[1]),
               os.cpu_count() or 0),
            "",
            "| set point | AIC (`robot.launch`) [s] | stock relay (`controller:=stock`) [s] | AIC <= stock | "
            "AIC, each engagement | stock, each engagement |",
            "|---|---|---|---|---|---|"]
    for v, w in speeds:
        a, s = results[("aic", v, w)], results[("stock", v, w)]
        body.append("| %.1f m/s, %.1f rad/s | %s | %s | %s | %s | %s |" % (
            v, w, fmt(a), fmt(s), "yes" if a[0] <= s[0] else "**no**",
            ", ".join(fmt(r) for r in runs[("aic", v, w)]), ", ".join(fmt(r) for r in runs[("stock", v, w)])))
    body += ["", "Times from twist_mux's last output before the lock silences it to the last /cmd_drive with a "
             "wheel above %.2f rad/s; in brackets, from the lock's engagement." % threshold, ""]
    write_section(path, "<!-- stop paths: %s -->" % key, "<!-- end of stop paths: %s -->" % key, body,
                  STOP_PATHS_TITLE)


class Stream:
    """Publishes a Twist at `rate` Hz on a topic (ROS time) while set; None: silent."""

    def __init__(self, topic, rate=20.0):
        self.pub = rospy.Publisher(topic, Twist, queue_size=1, tcp_nodelay=True)
        self.value = None
        self.lock = threading.Lock()
        self.timer = rospy.Timer(rospy.Duration(1.0 / rate), self.tick)

    def set(self, v, w=0.0):
        with self.lock:
            self.value = None if v is None else (v, w)

    def tick(self, _event):
        with self.lock:
            value = self.value
        if value is not None:
            msg = Twist()
            msg.linear.x, msg.angular.z = value
            self.pub.publish(msg)


class Path:
    """Recordings: /odom (stamp, vx, wz), /cmd_drive (receipt time, max |wheel|), the AIC's state."""

    def __init__(self):
        self.lock = threading.Lock()
        self.odom = []
        self.drive = []
        self.mux = []  # ROS time at receipt of each /twist_mux/cmd_vel (the controller's input)
        self.aic_state = ""
        rospy.Subscriber("/odom", Odometry, self.on_odom, queue_size=200, tcp_nodelay=True)
        rospy.Subscriber("/cmd_drive", Drive, self.on_drive, queue_size=200, tcp_nodelay=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)
        rospy.Subscriber(SET_POINT, Twist, self.on_mux, queue_size=200, tcp_nodelay=True)

    def on_mux(self, _m):
        t = rospy.get_rostime().to_sec()
        with self.lock:
            self.mux.append(t)

    def last_input(self, before):
        """Receipt time of the last /twist_mux/cmd_vel at or before `before`; None if none."""
        with self.lock:
            times = [t for t in self.mux if t <= before]
        return times[-1] if times else None

    def on_odom(self, m):
        with self.lock:
            self.odom.append((m.header.stamp.to_sec(), m.twist.twist.linear.x, m.twist.twist.angular.z))

    def on_drive(self, m):
        t = rospy.get_rostime().to_sec()
        with self.lock:
            self.drive.append((t, max(abs(m.drivers[0]), abs(m.drivers[1]))))

    def on_diagnostics(self, m):
        for s in m.status:
            if s.name.endswith("controller") and "jackal_AIC" in s.name:
                with self.lock:
                    self.aic_state = s.message

    def odom_window(self, window):
        """/odom rows of the last `window` s; None if they span less than 80 % of it."""
        with self.lock:
            if not self.odom:
                return None
            t_end = self.odom[-1][0]
            rows = [r for r in self.odom if r[0] >= t_end - window]
        if not rows or rows[-1][0] - rows[0][0] < 0.8 * window:
            return None
        return rows

    def mean_odom(self, window):
        """Mean (vx, wz) over the last `window` s of /odom; None without data."""
        rows = self.odom_window(window)
        if rows is None:
            return None
        return (statistics.mean(r[1] for r in rows), statistics.mean(r[2] for r in rows))

    def steady_at(self, v, w, tol, window):
        """Over the last `window` s the mean vx is within tol of v and its spread within 2 tol
        (settled, not passing through); the mean wz within max(tol, 10 % of |w|) of w."""
        rows = self.odom_window(window)
        if rows is None:
            return False
        vx = [r[1] for r in rows]
        wz = statistics.mean(r[2] for r in rows)
        return (abs(statistics.mean(vx) - v) <= tol and max(vx) - min(vx) <= 2.0 * tol
                and abs(wz - w) <= max(tol, 0.1 * abs(w)))

    def last_turning(self, after, threshold):
        """Receipt time of the last /cmd_drive after `after` with a wheel above threshold; None if none."""
        with self.lock:
            turning = [t for t, a in self.drive if t >= after and a > threshold]
        return turning[-1] if turning else None

    def quiet_since(self, threshold):
        """How long [s] every /cmd_drive has been at or below threshold (0 if the newest is not)."""
        with self.lock:
            if not self.drive or self.drive[-1][1] > threshold:
                return 0.0
            last_turning = max((t for t, a in self.drive if a > threshold), default=self.drive[0][0])
            return self.drive[-1][0] - last_turning


class RobotPath(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("robot_path_check")
        cls.path = Path()
        cls.nav = Stream("/cmd_vel")
        cls.joy = Stream("/joy_teleop/cmd_vel")
        cls.lock_pub = rospy.Publisher("/e_stop", Bool, queue_size=1, latch=True)
        ok = wait_for(lambda: cls.path.mean_odom(0.5) is not None, 30.0)
        assert ok, "no /odom from the simulated Jackal"

    def engage_lock(self, engaged):
        self.lock_pub.publish(Bool(data=engaged))
        return rospy.get_rostime().to_sec()

    def drive_until_steady(self, v, w, tol, window, timeout=20.0):
        self.nav.set(v, w)
        return wait_for(lambda: self.path.steady_at(v, w, tol, window), timeout)

    def stop_and_rest(self, threshold):
        """Navigation silent, lock released; wait until the wheel commands are quiet and the robot rests."""
        self.nav.set(None)
        self.joy.set(None)
        ok = wait_for(lambda: self.path.quiet_since(threshold) > 0.5 and self.path.steady_at(0.0, 0.0, 0.02, 0.3),
                      15.0)
        self.engage_lock(False)
        return ok

    def lock_stop_time(self, v, w, threshold):
        """Drive at (v, w), engage the lock with navigation still publishing; seconds from the lock
        and from twist_mux's last output to the last turning command."""
        self.assertTrue(self.drive_until_steady(v, w, 0.05 + 0.05 * v, 0.5), "never steady at %.2f m/s" % v)
        t_lock = self.engage_lock(True)
        self.assertTrue(wait_for(lambda: self.path.quiet_since(threshold) > 0.5, 10.0),
                        "the wheels never stopped after the lock")
        last = self.path.last_turning(t_lock, threshold)
        t_input = self.path.last_input(rospy.get_rostime().to_sec())
        self.assertIsNotNone(t_input, "no /twist_mux/cmd_vel recorded")
        self.assertLess(t_input, t_lock + 0.1, "twist_mux kept forwarding after the lock")
        self.stop_and_rest(threshold)
        last = t_lock if last is None else last
        return last - t_input, last - t_lock

    # ---- mode drive -------------------------------------------------------------------
    def run_drive(self):
        speed = rospy.get_param("~speed", 0.5)
        joy_speed = rospy.get_param("~joystick_speed", 0.2)
        tol = rospy.get_param("~speed_tol", 0.05)
        window = rospy.get_param("~steady_window", 1.0)
        stop_limit = rospy.get_param("~stop_limit", 0.35)
        self.engage_lock(False)
        self.assertTrue(self.drive_until_steady(speed, 0.0, tol, window),
                        "navigation at %.2f m/s through robot.launch: /odom never settled (AIC: %s)"
                        % (speed, self.path.aic_state))
        rospy.loginfo("robot_launch: steady at %s m/s (mean vx, wz over %.1f s)", self.path.mean_odom(window), window)
        # One publisher per command topic.
        self.assertEqual(publishers_of(CMD_VEL), ["/jackal_AIC"])
        self.assertEqual(publishers_of("/cmd_drive"), ["/stock_base"])
        self.assertEqual(publishers_of(SET_POINT), ["/twist_mux"])
        self.assertEqual(self.path.aic_state, "running")
        # The joystick outranks navigation; navigation drives again after its 0.5 s timeout.
        self.joy.set(joy_speed)
        self.assertTrue(wait_for(lambda: self.path.steady_at(joy_speed, 0.0, tol, window), 15.0),
                        "the joystick did not take over")
        self.joy.set(None)
        self.assertTrue(wait_for(lambda: self.path.steady_at(speed, 0.0, tol, window), 15.0),
                        "navigation did not drive again after the joystick stopped")
        # The lock stops the wheels while navigation keeps publishing.
        threshold = 0.05
        t_lock = self.engage_lock(True)
        self.assertTrue(wait_for(lambda: self.path.quiet_since(threshold) > 0.5, 10.0), "the lock did not stop")
        last = self.path.last_turning(t_lock, threshold)
        delay = (last - t_lock) if last is not None else 0.0
        rospy.loginfo("robot_launch: lock to the last turning wheel command: %.3f s", delay)
        self.assertLessEqual(delay, stop_limit)
        self.assertTrue(wait_for(lambda: self.path.aic_state.startswith("stale"), 5.0), self.path.aic_state)
        # Released: drives again.
        self.engage_lock(False)
        self.assertTrue(wait_for(lambda: self.path.steady_at(speed, 0.0, tol, window), 15.0),
                        "did not drive again after the lock was released")
        self.nav.set(None)

    # ---- mode stop_path ---------------------------------------------------------------
    def start_robot_launch(self, controller):
        proc = ros_process.roslaunch("robot.launch", ["controller:=" + controller], package=PKG)
        node = "/jackal_AIC" if controller == "aic" else "/jackal_AIC_bypass"
        # Both advertise their output at start-up.
        up = wait_for(lambda: node in publishers_of(CMD_VEL), 60.0)
        self.assertTrue(up, "robot.launch controller:=%s did not come up" % controller)
        return proc

    def stop_robot_launch(self, proc):
        ros_process.stop(proc, timeout=30.0)
        self.assertTrue(wait_for(lambda: live_publishers(CMD_VEL) == [], 30.0),
                        "a publisher stayed on %s: %s" % (CMD_VEL, publishers_of(CMD_VEL)))

    def run_stop_path(self):
        threshold = rospy.get_param("~wheel_threshold", 0.05)
        engagements = int(rospy.get_param("~engagements", 1))
        output = rospy.get_param("~output", "")
        self.assertGreaterEqual(engagements, 1, "~engagements must be >= 1")
        speeds = [(0.5, 0.0), (1.0, 0.5)]
        runs = {}
        load_before = os.getloadavg()
        for controller in ("aic", "stock"):
            self.engage_lock(False)
            proc = self.start_robot_launch(controller)
            try:
                for v, w in speeds:
                    runs[(controller, v, w)] = [self.lock_stop_time(v, w, threshold) for _ in range(engagements)]
            finally:
                self.nav.set(None)
                self.stop_robot_launch(proc)
        load_after = os.getloadavg()
        # Each case's median engagement (by the time from the last input), and its time from the lock.
        results = {k: sorted(r)[(len(r) - 1) // 2] for k, r in runs.items()}
        sim_time = rospy.get_param("/use_sim_time", False)
        clock = "simulated time" if sim_time else "real time"
        lines = ["last input (/twist_mux/cmd_vel) -> last /cmd_drive with a wheel above %.2f rad/s "
                 "[s, %s] (from the lock's engagement); median of %d" % (threshold, clock, engagements),
                 "%-22s %-20s %-20s" % ("set point", "AIC (robot.launch)", "stock relay (controller:=stock)")]
        for v, w in speeds:
            a, s = results[("aic", v, w)], results[("stock", v, w)]
            lines.append("%-22s %-20s %-20s" % ("%.1f m/s %.1f rad/s" % (v, w), "%.3f (%.3f)" % a, "%.3f (%.3f)" % s))
        text = "\n".join(lines)
        print(text)
        rospy.loginfo("robot_stop_path:\n%s", text)
        if output:
            write_stop_paths(output, sim_time, engagements, threshold, speeds, runs, results, (load_before, load_after),
                             rospy.get_param("~base", "stock_diff_drive"), plant_real_time_factor())
        for v, w in speeds:
            (a, a_lock), (s, s_lock) = results[("aic", v, w)], results[("stock", v, w)]
            print("MEASURED %.1f m/s %.1f rad/s (%s): from the last input AIC %.3f s, stock %.3f s; from the lock AIC "
                  "%.3f s, stock %.3f s" % (v, w, clock, a, s, a_lock, s_lock), file=sys.stderr)
            self.assertGreater(s, 0.2, "the stock path stopped before its timeout?")
            self.assertLessEqual(a, s, "at %.1f m/s %.1f rad/s the AIC stops later than the stock path\n%s"
                                 % (v, w, text))

    # ---- mode first_message -----------------------------------------------------------
    def run_first_message(self):
        speed = rospy.get_param("~speed", 0.3)
        threshold = rospy.get_param("~wheel_threshold", 0.05)
        relay = "/jackal_AIC_bypass"
        received = []  # (callerid, linear.x) of every twist on the diff drive's input
        lock = threading.Lock()

        def on_cmd_vel(m):
            with lock:
                received.append((m._connection_header.get("callerid"), m.linear.x))

        sub = rospy.Subscriber(CMD_VEL, Twist, on_cmd_vel, queue_size=100, tcp_nodelay=True)
        once = rospy.Publisher("/cmd_vel", Twist, queue_size=1, tcp_nodelay=True)
        self.engage_lock(False)
        proc = self.start_robot_launch("stock")
        try:
            self.assertIn(relay, publishers_of(CMD_VEL), "the relay did not advertise at start-up")
            me = rospy.get_name()
            up = wait_for(lambda: (SET_POINT, "o", relay) in connections("/twist_mux") and
                          (CMD_VEL, "o", "/stock_base") in connections(relay) and
                          (CMD_VEL, "o", me) in connections(relay) and once.get_num_connections() > 0, 30.0)
            self.assertTrue(up, "connections: twist_mux %s, relay %s" % (connections("/twist_mux"), connections(relay)))
            with lock:
                self.assertEqual(received, [], "a twist before the first set point")
            t_sent = rospy.get_rostime().to_sec()
            msg = Twist()
            msg.linear.x = speed
            once.publish(msg)
            self.assertTrue(wait_for(lambda: received != [], 5.0), "the first set point never left the relay")
            with lock:
                self.assertEqual(received[0], (relay, speed))
            self.assertTrue(wait_for(lambda: self.path.last_turning(t_sent, threshold) is not None, 5.0),
                            "the diff drive never turned the wheels for the first set point")
            with self.path.lock:
                first = min(t for t, a in self.path.drive if t >= t_sent and a > threshold)
            rospy.loginfo("robot_stock_first_message: the first set point left the relay and the diff drive "
                          "commanded the wheels %.3f s after it was sent", first - t_sent)
        finally:
            sub.unregister()
            self.stop_robot_launch(proc)

    def test_robot_path(self):
        mode = rospy.get_param("~mode")
        {"drive": self.run_drive, "stop_path": self.run_stop_path, "first_message": self.run_first_message}[mode]()


if __name__ == "__main__":
    rostest.rosrun(PKG, "robot_path_check", RobotPath, sys.argv)
