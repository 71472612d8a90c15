#!/usr/bin/env python3
"""The AIC through the stock base's path (launch/sim.launch base:=stock_diff_drive):
output_mode cmd_vel -> stock diff drive (stock_controller_node) -> /cmd_drive -> plant.
Metrics from /odom message stamps by the core's aic_step_metrics (jackal_aic_tools.common.metrics).

Runs on simulated time (use_sim_time: the plant node publishes /clock): every time below is
plant time, from /odom stamps or this node's ROS time at receipt (jackal_msgs/Drive and
geometry_msgs/Twist carry no stamp); every wait is on a condition with a deadline, never a
fixed sleep. The set points stream at RATE Hz on a ROS-time timer.

~mode steps: one plant (started by the .test); this node starts `sim.launch plant:=false`
  on it twice, one after the other: base:=direct (the AIC publishing /cmd_drive, config
  default.yaml) and base:=stock_diff_drive (the stock path, default.yaml + robot.yaml), both
  with the AIC's overlay ~overlay (a path relative to the package, e.g.
  config/goal_model.yaml; none if empty). On each, from rest, one linear step (~step_v m/s,
  ~hold_v s of /odom judged) and one angular step (~step_w rad/s, ~hold_w s), back to rest
  between them. Every step settles (+-5 % of ground-truth /odom), and the stock path's integral
  of the absolute error (IAE, over the judged hold) exceeds the direct path's by at most |step|
  x ~excess_delay_max s: a dead time d added to the loop shifts the response by d once the robot
  model has learned it (learn_latency), so it adds d x |step| to the IAE (closed_loop_run --set
  motor.command_delay=0.1187 + d, d up to 0.08 s: the settling time moves by d, the overshoot by
  under 0.4 points). The stock path adds one 50 Hz cycle by construction (the diff drive runs on
  the next /joint_states; the L the AIC learns there from its first start comes out 0.118-0.138
  s across runs, the direct path's 0.118 s); simulated time paces the plant alone, so the four
  processes' scheduling on a loaded host adds the rest (on an idle host the excess is 10-35 ms,
  on a loaded one 40-70 ms). The bound catches a path that loses commands (the diff drive's
  cmd_vel_timeout, a stalled cycle), not the host's timing: this path's deterministic figures
  are sim_jackal_node_closed_loop_test's. The settling times, the IAE's excess as a dead time
  and the model latency L each path's AIC reports (its diagnostics) are printed, not bounded: a
  response entering the band slowly moves the settling time by the time it lingers at the band's
  edge, the IAE only by the lingering's area. In the last ~steady_window s of each stock step
  every wheel command on /cmd_drive equals the wheel speeds the stock mapping gives for one of
  the AIC's last three cmd_vel messages before it or those received within 60 ms of it, within
  ~wheel_tol rad/s. The stock path's /cmd_drive has one publisher, the diff drive, and its
  cmd_vel one, the AIC.
~mode compare (dev/rehearsal.sh): one plant (started by the .test for ~base: stock_diff_drive
  or jackal_node); for each of ~repeats rounds, for each controller of ~controllers (aic,
  stock), this node starts `sim.launch plant:=false base:=<~base> controller:=<controller>`,
  takes one linear step from rest (~step_v m/s, ~hold_v s of /odom judged) and stops it. It
  prints each step's settling time (+-5 % of ground-truth /odom) and overshoot, and their
  medians per controller, and writes them as a Markdown section (keyed by base and clock) to
  ~output (if set). It fails only when a run never comes up or a step never settles.
  Simulated or real time (/use_sim_time).
~mode stop: one simulation (base:=stock_diff_drive, started by the .test): steady at ~step_v,
  the stop engaged (/stock_base/set_stop) for ~stop_time s: the AIC's command never grows
  while stopped (~growth_tol) and its diagnostics say why ("held: the MCU reports ...");
  released: the first command is within ~bumpless_tol of the measured speed (bumpless) and
  the resumed step overshoots by at most ~overshoot_limit %. With ~plant_stall > 0 the plant
  node is stopped (SIGSTOP) for that many wall seconds, ~plant_stall_delay wall seconds after
  the release, in the resumed step's rise: a host stalling the simulator. On simulated time the
  whole system pauses with it (the plant drops the lag rather than catching it up in a burst),
  so the same bounds hold.
"""
import os
import signal
import statistics
import sys
import threading
import time
import unittest

import rosgraph
import rospkg
import rospy
import rostest
from geometry_msgs.msg import Twist
from jackal_msgs.msg import Drive
from nav_msgs.msg import Odometry
from diagnostic_msgs.msg import DiagnosticArray
from std_msgs.msg import Bool

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from aic_test_utils import live_publishers, wait_for, write_section  # noqa: E402
from jackal_aic_tools.common import metrics, ros_process  # noqa: E402

PKG = "jackal_aic"
R = 0.098                 # m, the stock controller's wheel radius (control.yaml)
S = 1.5 * 0.37559         # m, its effective wheel separation
RATE = 50.0               # Hz, set-point rate
CMD_VEL = "/jackal_velocity_controller/cmd_vel"
WHEEL_ODOM = "/jackal_velocity_controller/odom"
# The one /cmd_drive publisher of each base of launch/sim.launch (direct: the controller's node).
DRIVE_PUBLISHER = {"stock_diff_drive": "/stock_base", "jackal_node": "/jackal_node"}
DIRECT_PUBLISHER = {"aic": "/jackal_AIC", "stock": "/stock_controller"}


def wheels(lin, ang):
    """diff_drive_controller's mapping (doc/jackal.md, 'The stock velocity controller')."""
    return ((lin - ang * S / 2.0) / R, (lin + ang * S / 2.0) / R)


def publishers_of(topic):
    """Node names the master lists as publishers of `topic`."""
    for name, nodes in rosgraph.Master(rospy.get_name()).getSystemState()[0]:
        if name == topic:
            return sorted(nodes)
    return []


class Tape:
    """Thread-safe (time, a, b) records of one topic."""

    def __init__(self):
        self.lock = threading.Lock()
        self.rows = []

    def add(self, t, a, b):
        with self.lock:
            self.rows.append((t, a, b))

    def between(self, t0, t1):
        with self.lock:
            return [r for r in self.rows if t0 <= r[0] <= t1]

    def last_time(self):
        with self.lock:
            return self.rows[-1][0] if self.rows else None


class Path:
    """Set-point stream (RATE Hz on ROS time) and recordings: /odom (stamp, vx, wz), /cmd_drive
    and cmd_vel (ROS time at receipt, the two wheels / linear, angular)."""

    def __init__(self):
        self.odom, self.drive, self.cmd_vel = Tape(), Tape(), Tape()
        now = lambda: rospy.Time.now().to_sec()
        self.subs = [
            rospy.Subscriber("/odom", Odometry,
                             lambda m: self.odom.add(m.header.stamp.to_sec(), m.twist.twist.linear.x,
                                                     m.twist.twist.angular.z), queue_size=200, tcp_nodelay=True),
            rospy.Subscriber("/cmd_drive", Drive,
                             lambda m: self.drive.add(now(), m.drivers[0], m.drivers[1]) if m.mode == 0 else None,
                             queue_size=200, tcp_nodelay=True),
            rospy.Subscriber(CMD_VEL, Twist, lambda m: self.cmd_vel.add(now(), m.linear.x, m.angular.z),
                             queue_size=200, tcp_nodelay=True)]
        self.pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=10)
        self.lock = threading.Lock()
        self.aic_state = (None, "")  # (stamp, message) of jackal_AIC's controller diagnostics
        self.aic_latency = (None, "")  # its "model latency L [s]" and "latency learning" values
        self.subs.append(rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20))
        self.value = (0.0, 0.0)
        self.timer = rospy.Timer(rospy.Duration(1.0 / RATE), lambda _e: self.publish())

    def on_diagnostics(self, m):
        for st in m.status:
            if "jackal_AIC" in st.name and st.name.endswith("controller"):
                values = {kv.key: kv.value for kv in st.values}
                with self.lock:
                    self.aic_state = (m.header.stamp.to_sec(), st.message)
                    self.aic_latency = (values.get("model latency L [s]"), values.get("latency learning", ""))

    def running_since(self, t):
        """True once jackal_AIC's controller diagnostics stamped after t say "running"."""
        with self.lock:
            stamp, message = self.aic_state
        return stamp is not None and stamp > t and message == "running"

    def publish(self):
        with self.lock:
            v, w = self.value
        m = Twist()
        m.linear.x, m.angular.z = v, w
        self.pub.publish(m)

    def set(self, v, w):
        """Set point (v, w) from now on, published at once; return the ROS time of the change [s]."""
        with self.lock:
            self.value = (v, w)
        t = rospy.Time.now().to_sec()
        self.publish()
        return t

    def odom_covers(self, t):
        """True once /odom has a sample stamped at or after t."""
        last = self.odom.last_time()
        return last is not None and last >= t

    def at(self, v, w, tol, window):
        """The last `window` s of /odom (spanning at least 80 % of it) all within tol of (v, w)."""
        last = self.odom.last_time()
        if last is None:
            return False
        rows = self.odom.between(last - window, last)
        return (len(rows) > 1 and rows[-1][0] - rows[0][0] >= 0.8 * window
                and all(abs(a - v) <= tol and abs(b - w) <= tol for _, a, b in rows))


def settling(tape, t_step, t_end, channel, initial, target):
    """Step metrics of /odom over [t_step, t_end]; fewer than two samples after the step report
    settling_time None (never settled), not an error."""
    rows = tape.between(t_step, t_end)
    if len([r for r in rows if r[0] > t_step]) < 2:
        rospy.logwarn("step at %.3f s: fewer than two /odom samples after it", t_step)
        return {"settling_time": None, "overshoot": None, "iae": None}
    return metrics.step_metrics([r[0] for r in rows], [r[1 + channel] for r in rows], t_step, initial, target)


COMPARE_TITLE = "# The stock base's path: Clearpath's jackal_node against the stand-in\n"


def lines_of(rows):
    """'settling s (overshoot %)' of each (settling_time, overshoot) row, comma-separated."""
    fmt = lambda x, f: "never" if x is None else f % x  # noqa: E731
    return ", ".join("%s (%s)" % (fmt(s, "%.3f s"), fmt(o, "%.1f %%")) for s, o in rows)


def median_or_none(values):
    """Median of the values; None if any is None (a step that never settled)."""
    return None if any(x is None for x in values) or not values else statistics.median(values)


def compare_table(base, controllers, results, v, sim_time, repeats, load, command):
    """Markdown lines of mode compare on `base`: per controller the median settling time [s] and
    overshoot [%] of `repeats` steps of v [m/s], and each step's; results: controller ->
    [(settling_time, overshoot)]; load: load averages before and after; command: the command line
    that wrote them."""
    fmt = lambda x, f: "never" if x is None else f % x  # noqa: E731
    clock = "simulated time (the plant's /clock)" if sim_time else "real time (every node on the wall clock)"
    lines = ["## base:=%s, %.1f m/s step from rest, %s" % (base, v, clock), ""]
    lines.append("Written by `%s` (test/rostest/stock_base_check.py, mode compare): settling time (+-5 %% of the "
                 "plant's /odom) and overshoot, median of %d; host load average (1, 5, 15 min) before %s, after %s; "
                 "%d CPU(s)." % (command, repeats,
                                 " ".join("%.2f" % x for x in load[0]), " ".join("%.2f" % x for x in load[1]),
                                 os.cpu_count() or 0))
    lines += ["", "| controller | settling [s] | overshoot [%] | each step: settling (overshoot) |",
              "|---|---|---|---|"]
    for c in controllers:
        rows = results[c]
        lines.append("| %s | %s | %s | %s |" % (
            c, fmt(median_or_none([st for st, _ in rows]), "%.3f"),
            fmt(median_or_none([o for _, o in rows]), "%.1f"), lines_of(rows)))
    return lines + [""]


class StockBaseCheck(unittest.TestCase):

    def p(self, name, default):
        return rospy.get_param("~" + name, default)

    def test_stock_base(self):
        mode = self.p("mode", "steps")
        if mode != "compare":
            self.assertTrue(rospy.get_param("/use_sim_time", False), "the check runs on simulated time")
        if mode == "steps":
            self.check_steps()
        elif mode == "stop":
            self.check_stop()
        elif mode == "compare":
            self.check_compare()
        else:
            self.fail("~mode must be steps, stop or compare, not %r" % mode)

    def wait_ready(self, path, timeout, controller="aic", base="stock_diff_drive"):
        """Wait until the plant's /odom and the path's /cmd_drive stream (set point zero) and, for
        the AIC, its diagnostics, published after that, say "running" (not held: the stock base's
        /status has reached it); on a base, until its wheel odometry streams (the diff drive runs)."""
        path.set(0.0, 0.0)
        t0 = rospy.Time.now().to_sec()
        ok = wait_for(lambda: path.odom_covers(t0) and (path.drive.last_time() or -1.0) > t0, timeout)
        self.assertTrue(ok, "no /odom or /cmd_drive within %.0f s" % timeout)
        if base != "direct":
            try:
                rospy.wait_for_message(WHEEL_ODOM, Odometry, timeout)
            except rospy.ROSException:
                self.fail("no %s within %.0f s: the diff drive does not run" % (WHEEL_ODOM, timeout))
        if controller != "aic":
            return
        t1 = rospy.Time.now().to_sec()
        self.assertTrue(wait_for(lambda: path.running_since(t1), timeout),
                        "jackal_AIC not running: %s" % (path.aic_state,))

    def rest(self, path, timeout=15.0):
        """Set point zero; wait until /odom has been at rest for 0.5 s."""
        path.set(0.0, 0.0)
        self.assertTrue(wait_for(lambda: path.at(0.0, 0.0, 0.01, 0.5), timeout), "the robot did not come to rest")

    # ---- mode steps -------------------------------------------------------------------
    def start_sim(self, base, controller="aic"):
        """Start `sim.launch plant:=false base:=<base> controller:=<controller>` (with
        overlay:=<~overlay> if set); wait until
        /cmd_drive has its one publisher (the base's, or the controller's on base direct) and,
        with the AIC on a base, the AIC publishes the base's cmd_vel. Returns the roslaunch process."""
        args = ["plant:=false", "base:=" + base, "controller:=" + controller]
        overlay = str(self.p("overlay", ""))
        if overlay:
            args.append("overlay:=" + os.path.join(rospkg.RosPack().get_path(PKG), overlay))
        proc = ros_process.roslaunch("sim.launch", args, package=PKG)
        expected = DRIVE_PUBLISHER.get(base, DIRECT_PUBLISHER[controller])
        up = wait_for(lambda: publishers_of("/cmd_drive") == [expected] and (
            controller != "aic" or base == "direct" or "/jackal_AIC" in publishers_of(CMD_VEL)), 60.0)
        self.assertTrue(up, "sim.launch base:=%s controller:=%s did not come up (/cmd_drive: %s)"
                        % (base, controller, publishers_of("/cmd_drive")))
        return proc

    def stop_sim(self, proc):
        ros_process.stop(proc, timeout=30.0)
        self.assertTrue(wait_for(lambda: live_publishers("/cmd_drive") == [], 30.0),
                        "a publisher stayed on /cmd_drive: %s" % publishers_of("/cmd_drive"))

    def run_steps(self, base, path, steps):
        """One step per channel on `base`; return {channel: its step metrics (settling_time [s]
        or None, iae [unit * s] or None)} and {"latency": (L [s] as text or None, the latency
        learning's state)} from the AIC's last controller diagnostics."""
        proc = self.start_sim(base)
        try:
            self.wait_ready(path, float(self.p("ready_timeout", 60.0)), base=base)
            if base == "stock_diff_drive":
                # Only one node publishes the stock path's /cmd_drive: the diff drive (as jackal_node on the robot).
                self.assertEqual(publishers_of("/cmd_drive"), ["/stock_base"])
                self.assertEqual(publishers_of(CMD_VEL), ["/jackal_AIC"])
            self.rest(path)
            window = float(self.p("steady_window", 1.0))
            wheel_tol = float(self.p("wheel_tol", 1e-3))
            result = {}
            for channel, target, hold_time in steps:
                what = "%s, %s step %g" % (base, "linear" if channel == 0 else "angular", target)
                t_step = path.set(*((target, 0.0) if channel == 0 else (0.0, target)))
                t_end = t_step + hold_time
                self.assertTrue(wait_for(lambda: path.odom_covers(t_end), hold_time + 30.0), "%s: /odom stopped" % what)
                self.rest(path)
                m = settling(path.odom, t_step, t_end, channel, 0.0, target)
                rospy.loginfo("%s: settling %s s, overshoot %s %%", what, m["settling_time"], m["overshoot"])
                result[channel] = m
                if base != "stock_diff_drive":
                    continue
                # Steady state: /cmd_drive = the stock mapping of one of the AIC's last cmd_vel commands.
                cmds = path.cmd_vel.between(t_step, t_end)
                drives = path.drive.between(t_end - window, t_end)
                self.assertTrue(cmds and drives, "%s: no cmd_vel or cmd_drive in steady state" % what)
                worst = 0.0
                for (t, l, r) in drives:
                    # The last three commands received before this drive, and those received
                    # within 60 ms of it (the diff drive uses the one it received before the
                    # cycle's joint states; this node's receipt order of the two topics may differ
                    # by a message).
                    before = [c for c in cmds if c[0] <= t][-3:] + [c for c in cmds if abs(c[0] - t) <= 0.06]
                    if before:
                        worst = max(worst, min(max(abs(l - a), abs(r - b))
                                               for a, b in (wheels(c[1], c[2]) for c in before)))
                rospy.loginfo("%s: %d /cmd_drive messages in steady state, largest |drive - action| %.2e rad/s",
                              what, len(drives), worst)
                self.assertLessEqual(worst, wheel_tol, "%s: /cmd_drive differs from the AIC's action by %.2e rad/s"
                                     % (what, worst))
            with path.lock:
                result["latency"] = path.aic_latency
            return result
        finally:
            path.set(0.0, 0.0)
            self.stop_sim(proc)

    def check_steps(self):
        path = Path()
        excess_max = float(self.p("excess_delay_max", 0.1))
        steps = ((0, float(self.p("step_v", 0.5)), float(self.p("hold_v", 2.5))),
                 (1, float(self.p("step_w", 1.0)), float(self.p("hold_w", 3.0))))
        direct = self.run_steps("direct", path, steps)
        stock = self.run_steps("stock_diff_drive", path, steps)
        latency = "model latency L: direct %s s, stock %s s (%s)" % (
            direct["latency"][0], stock["latency"][0], stock["latency"][1])
        rospy.loginfo(latency)
        print("MEASURED " + latency, file=sys.stderr)
        for channel, target, _ in steps:
            what = "%s step %g" % ("linear" if channel == 0 else "angular", target)
            md, ms = direct[channel], stock[channel]
            self.assertIsNotNone(md["settling_time"], "%s: the direct path never settled" % what)
            self.assertIsNotNone(ms["settling_time"], "%s: the stock path never settled" % what)
            excess = (ms["iae"] - md["iae"]) / abs(target)  # s: the dead time that explains the excess
            line = ("%s: settling direct %.3f s, stock %.3f s (ratio %.2f); IAE direct %.4f, stock %.4f "
                    "(ratio %.3f, excess %.1f ms x |step|)" % (
                        what, md["settling_time"], ms["settling_time"], ms["settling_time"] / md["settling_time"],
                        md["iae"], ms["iae"], ms["iae"] / md["iae"], 1e3 * excess))
            rospy.loginfo(line)
            print("MEASURED " + line, file=sys.stderr)
            self.assertLessEqual(excess, excess_max, "%s: the stock path's IAE %.4f exceeds the direct path's %.4f "
                                 "by %.1f ms x |step| (bound %.0f ms: one diff drive cycle and the host's scheduling)"
                                 % (what, ms["iae"], md["iae"], 1e3 * excess, 1e3 * excess_max))

    # ---- mode compare -----------------------------------------------------------------
    def compare_step(self, base, controller, path, v, hold):
        """One linear step of v [m/s] from rest on sim.launch base:=<base> controller:=<controller>,
        /odom judged for `hold` s; returns its step metrics (settling_time [s], overshoot [%])."""
        proc = self.start_sim(base, controller)
        try:
            self.wait_ready(path, float(self.p("ready_timeout", 60.0)), controller, base)
            self.rest(path)
            t_step = path.set(v, 0.0)
            t_end = t_step + hold
            self.assertTrue(wait_for(lambda: path.odom_covers(t_end), hold + 30.0), "%s/%s: /odom stopped"
                            % (base, controller))
            self.rest(path)
            return settling(path.odom, t_step, t_end, 0, 0.0, v)
        finally:
            path.set(0.0, 0.0)
            self.stop_sim(proc)

    def check_compare(self):
        base = str(self.p("base", "stock_diff_drive"))
        self.assertIn(base, ("stock_diff_drive", "jackal_node"), "~base must be stock_diff_drive or jackal_node")
        controllers = [c.strip() for c in str(self.p("controllers", "aic,stock")).split(",")]
        for c in controllers:
            self.assertIn(c, ("aic", "stock"), "~controllers: %r is neither aic nor stock" % c)
        repeats = int(self.p("repeats", 3))
        self.assertGreaterEqual(repeats, 1, "~repeats must be >= 1")
        v, hold = float(self.p("step_v", 0.5)), float(self.p("hold_v", 2.5))
        path = Path()
        load_before = os.getloadavg()
        results = {c: [] for c in controllers}
        for _ in range(repeats):
            for c in controllers:
                m = self.compare_step(base, c, path, v, hold)
                rospy.loginfo("%s/%s: settling %s s, overshoot %s %%", base, c, m["settling_time"], m["overshoot"])
                results[c].append((m["settling_time"], m["overshoot"]))
        load_after = os.getloadavg()
        sim_time = rospy.get_param("/use_sim_time", False)
        output = self.p("output", "")
        rel, full = "doc/results/", os.path.abspath(output)
        command = "rostest jackal_aic stock_base_compare.test base:=%s %s%s%s%s" % (
            base, "" if controllers == ["aic", "stock"] else "controllers:=%s " % ",".join(controllers),
            "" if repeats == 3 else "repeats:=%d " % repeats, "" if sim_time else "use_sim_time:=false ",
            "output:=" + ("$PWD/" + full[full.index(rel):] if rel in full else output) if output else "")
        lines = compare_table(base, controllers, results, v, sim_time, repeats, (load_before, load_after),
                              command.strip())
        print("\n".join(lines))
        for c in controllers:
            print("MEASURED %.2f m/s step, %s/%s (%s): %s" % (v, base, c, "sim time" if sim_time else "real time",
                                                            lines_of(results[c])), file=sys.stderr)
        if output:
            key = "steps: %s %s" % (base, "sim_time" if sim_time else "real_time")
            write_section(output, "<!-- %s -->" % key, "<!-- end of %s -->" % key, lines, COMPARE_TITLE)
        for c in controllers:
            self.assertTrue(all(st is not None for st, _ in results[c]), "%s/%s: a step never settled" % (base, c))

    # ---- mode stop --------------------------------------------------------------------
    def check_stop(self):
        path = Path()
        stop_pub = rospy.Publisher("/stock_base/set_stop", Bool, queue_size=1, latch=True)
        lock = threading.Lock()
        held = []  # diagnostics summaries of jackal_AIC's controller task saying why it holds

        latency = []  # (stamp, the robot model's L, its learning) from the controller's diagnostics

        def on_diagnostics(m):
            with lock:
                held.extend(st.message for st in m.status
                            if "controller" in st.name and st.message.startswith("held:"))
                for st in m.status:
                    if "jackal_AIC" in st.name and st.name.endswith("controller"):
                        kv = {x.key: x.value for x in st.values}
                        latency.append((m.header.stamp.to_sec(), kv.get("model latency L [s]"),
                                        kv.get("latency learning")))
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
        self.wait_ready(path, float(self.p("ready_timeout", 60.0)))
        v = float(self.p("step_v", 0.5))
        stop_time = float(self.p("stop_time", 2.5))
        growth_tol = float(self.p("growth_tol", 0.02))     # m/s
        bumpless_tol = float(self.p("bumpless_tol", 0.1))  # m/s
        overshoot_limit = float(self.p("overshoot_limit", 10.0))  # % of the step
        resume_hold = float(self.p("resume_hold", 3.0))  # s of /odom judged after the release
        self.rest(path)
        path.set(v, 0.0)
        self.assertTrue(wait_for(lambda: path.at(v, 0.0, 0.05 * v, 0.5), 15.0), "never steady at %.2f m/s" % v)
        stop_pub.publish(Bool(data=True))
        t_stop = rospy.Time.now().to_sec()
        # Stopped for stop_time s of plant time, and a diagnostics message saying why.
        ok = wait_for(lambda: rospy.Time.now().to_sec() >= t_stop + stop_time and bool(held), stop_time + 30.0)
        self.assertTrue(ok, "no diagnostics 'held: ...' from jackal_AIC while stopped")
        stall = float(self.p("plant_stall", 0.0))  # s of wall time
        plant = ros_process.node_pid("/jackal_plant", rospy.get_name()) if stall > 0 else None
        self.assertTrue(stall <= 0 or plant, "~plant_stall: no PID for /jackal_plant")
        stop_pub.publish(Bool(data=False))
        t_release = rospy.Time.now().to_sec()
        if plant:
            time.sleep(float(self.p("plant_stall_delay", 0.1)))
            os.kill(plant, signal.SIGSTOP)
            try:
                time.sleep(stall)
            finally:
                os.kill(plant, signal.SIGCONT)
            rospy.loginfo("the plant stopped for %.3f s of wall time in the resumed step", stall)
        t_end = t_release + resume_hold
        self.assertTrue(wait_for(lambda: path.odom_covers(t_end), resume_hold + 30.0), "/odom stopped")
        path.set(0.0, 0.0)
        rospy.loginfo("stop engaged at %.3f s, released at %.3f s, judged until %.3f s (plant time)",
                      t_stop, t_release, t_end)
        # Stopped: no growth of the command (the status reaches the AIC within a few ticks).
        during = path.cmd_vel.between(t_stop + 0.1, t_release)
        self.assertTrue(during, "no command while stopped")
        first = during[0][1]
        peak = max(c[1] for c in during)
        rospy.loginfo("stopped: command %.3f m/s at the start, peak %.3f, end %.3f", first, peak, during[-1][1])
        self.assertLessEqual(peak, first + growth_tol, "the command grew while stopped: %.3f -> %.3f m/s"
                             % (first, peak))
        with lock:
            rospy.loginfo("diagnostics while stopped: %s", held[0])
            self.assertIn("the MCU reports", held[0])
        # Released: bumpless (the first running command near the measured speed), then the step.
        odom = path.odom.between(t_release - 0.1, t_release + 0.05)
        after = path.cmd_vel.between(t_release, t_end)
        self.assertTrue(odom and after)
        v_meas = odom[-1][1]
        rospy.loginfo("released at %.3f m/s measured; first command %.3f m/s", v_meas, after[0][1])
        print("MEASURED stop: peak growth %.4f m/s, resume |command - measured| %.3f m/s"
              % (peak - first, abs(after[0][1] - v_meas)), file=sys.stderr)
        self.assertLessEqual(abs(after[0][1] - v_meas), bumpless_tol, "resume not bumpless: command %.3f m/s, "
                             "measured %.3f m/s" % (after[0][1], v_meas))
        m = settling(path.odom, t_release, t_end, 0, v_meas, v)
        rospy.loginfo("resumed: settling %s s, overshoot %s %%", m["settling_time"], m["overshoot"])
        print("MEASURED stop: resumed overshoot %s %%" % m["overshoot"], file=sys.stderr)
        with lock:
            before = [x for x in latency if x[0] <= t_release]
            after_release = [x for x in latency if x[0] > t_release]
        for name, rows in (("at the release", before), ("after it", after_release)):
            if rows:
                print("MEASURED stop: model latency %s: L %s s (%s)" % (name, rows[-1][1], rows[-1][2]),
                      file=sys.stderr)
        self.assertIsNotNone(m["overshoot"])
        self.assertLessEqual(m["overshoot"], overshoot_limit)


if __name__ == "__main__":
    rospy.init_node("stock_base_check")
    rostest.rosrun(PKG, "stock_base_check", StockBaseCheck, sys.argv)
