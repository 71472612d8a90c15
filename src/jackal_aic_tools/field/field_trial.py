"""The field-trial node (scripts/aic_field_trial.py, launch/field_trial.launch; doc/field_trials.md):
a session plan's runs on the robot that is running, the AIC and the stock controller alternating,
each run out and back, inside the plan's corridor, with a bag per run and a session summary.

Controllers (the robot path of an unmodified Jackal, README 'On the robot'): the node publishes
every set point itself.
  aic    the set point goes to the AIC (~set_point_topic, default /twist_mux/cmd_vel: robot.launch's
         AIC input); the AIC's output is enabled (<aic_node>/enable_output true) and drives the
         diff drive's cmd_vel.
  stock  the AIC's output is disabled first (enable_output false: it publishes nothing), then the
         node publishes the set point as the twist straight to the diff drive (~cmd_vel_topic,
         default /jackal_velocity_controller/cmd_vel), as robot.launch controller:=stock's relay does.
Between a switch and the first command of the new path the node waits switch_gap (0.1 s: five
cycles of 50 Hz), so the diff drive never gets both streams in one cycle; the bag records every
cmd_vel and /cmd_drive message's publisher (/field_trial/publishers) to check it.

Safety (jackal_aic_tools.field.field_safety, every cycle from the first check to the end): the session
starts only with /status showing the drivers active and no stop, fresh sensors and, when the plan
has the AIC, its sensor health OK, after an explicit confirmation (a typed 'yes', or --yes). It
stops at once on any stop condition: the AIC's output is disabled, zero twists go to the diff
drive for safety.stop_hold s, then the AIC's output is enabled again (the robot's normal state,
where twist_mux's output drives through it) and the robot is left at rest.

Files in the output folder: session.json (the summary, rewritten after every change of a run;
runs that completed stay usable whatever stops the session), runs/<NN_experiment_controller_dir>.bag
(rosbag Python API), plan.yaml (a copy of the plan). Each bag holds /field_trial/set_point (what
the controller was asked, Twist), /field_trial/event (String: run, profile_start, profile_end,
stop), /field_trial/publishers (String "topic callerid" per command message), the diff drive's
cmd_vel, /cmd_drive, the odometry, /joint_states, /imu/data, /status, /feedback and, with the AIC,
its belief.
"""
import json
import math
import os
import shutil
import signal
import sys
import threading
import time

from . import field_plan, field_safety

#: Topic names in each run's bag for what the node itself publishes and observes.
BAG_SET_POINT = "/field_trial/set_point"
BAG_EVENT = "/field_trial/event"
BAG_PUBLISHERS = "/field_trial/publishers"
#: Seconds between switching controllers and the first command on the new path.
SWITCH_GAP = 0.1
#: Exit statuses of main().
EXIT_COMPLETED, EXIT_REFUSED, EXIT_STOPPED = 0, 2, 3


class Topics(object):
    """The topic names a session uses (argparse values of scripts/aic_field_trial.py)."""

    def __init__(self, set_point="/twist_mux/cmd_vel", cmd_vel="/jackal_velocity_controller/cmd_vel",
                 odom="/odometry/filtered", joystick=("/bluetooth_teleop/cmd_vel", "/joy_teleop/cmd_vel"),
                 aic_node="/jackal_AIC"):
        self.set_point = set_point
        self.cmd_vel = cmd_vel
        self.odom = odom
        self.joystick = list(joystick)
        self.aic_node = aic_node.rstrip("/")

    def to_dict(self):
        """The names as the summary stores them."""
        return {"set_point": self.set_point, "cmd_vel": self.cmd_vel, "odom": self.odom,
                "joystick": list(self.joystick), "aic_node": self.aic_node}


def yaw_of(q):
    """Heading [rad] of a geometry_msgs/Quaternion."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def write_json(path, data):
    """Write ``data`` as JSON to ``path`` atomically (a temporary file renamed over it), so a
    summary on disk is always complete."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


class Session(object):
    """The session summary (session.json) and where the bags go. ``resume``: continue the summary
    found in ``out_dir`` (its completed runs are skipped); otherwise the folder must not hold one."""

    def __init__(self, out_dir, plan, topics, resume=False):
        self.out_dir = os.path.abspath(os.path.expanduser(out_dir))
        self.path = os.path.join(self.out_dir, "session.json")
        self.bag_dir = os.path.join(self.out_dir, "runs")
        exists = os.path.exists(self.path)
        if exists and not resume:
            raise ValueError("%s already holds a session: resume it with --resume or choose another --out"
                             % self.out_dir)
        if resume and not exists:
            raise ValueError("--resume: no session.json in %s" % self.out_dir)
        os.makedirs(self.bag_dir, exist_ok=True)
        if resume:
            with open(self.path) as f:
                self.data = json.load(f)
            known = [r["name"] for r in self.data.get("plan_runs", [])]
            if known != [r.name for r in plan.runs]:
                raise ValueError("--resume: the plan's runs differ from those of %s" % self.path)
            self.data["resumes"] = self.data.get("resumes", 0) + 1
        else:
            shutil.copyfile(plan.path, os.path.join(self.out_dir, "plan.yaml"))
            self.data = {"plan": plan.to_dict(), "plan_runs": [r.to_dict() for r in plan.runs],
                         "topics": topics.to_dict(), "runs": [], "status": "starting", "reason": "",
                         "max_distance_from_start": 0.0, "resumes": 0}
        self.save()

    def completed(self):
        """Names of the runs that completed (in this folder, any earlier attempt included)."""
        return {r["name"] for r in self.data["runs"] if r["status"] == "completed"}

    def record(self, entry):
        """Add or replace (by name and attempt) a run's entry and save."""
        runs = self.data["runs"]
        for k, r in enumerate(runs):
            if r["name"] == entry["name"] and r.get("attempt") == entry.get("attempt"):
                runs[k] = entry
                break
        else:
            runs.append(entry)
        self.save()

    def save(self):
        """Rewrite session.json (atomically)."""
        write_json(self.path, self.data)


class TrialNode(object):
    """The ROS side of a session (see the module's docstring). Make it after rospy.init_node();
    run() plays the plan and returns the exit status."""

    def __init__(self, plan, session, topics, start_timeout=20.0):
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
        from geometry_msgs.msg import Twist, TwistStamped
        from jackal_msgs.msg import Drive, Feedback, Status
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import Imu, JointState
        from std_msgs.msg import String

        self.rospy = rospy
        self.Twist = Twist
        self.String = String
        self.plan = plan
        self.session = session
        self.topics = topics
        self.start_timeout = start_timeout
        self.need_aic = "aic" in plan.controllers
        self.have_aic = self.need_aic  # an AIC node to silence during stock runs (found in run())
        self.lock = threading.Lock()
        self.snap = field_safety.Snapshot()
        self.world_pose = None     # newest odometry pose (x, y, heading), odometry frame
        self.start_world = None    # the session's start pose
        self.joystick_armed = False
        self.bag = None
        self.max_distance = 0.0
        self.run_max_distance = 0.0
        # how far the odometry's pose reached in the start frame [m] (field_plan.extents' sides)
        self.extent = dict.fromkeys(("ahead", "behind", "left", "right"), 0.0)
        self.extent.update(session.data.get("corridor_extent") or {})
        self.wall_start = None     # time.time() when the session was confirmed
        self.active = None         # controller whose path is live: 'aic', 'stock' or None
        self.aic_enabled = None    # what we last set on the AIC's gate (None: never set)
        self.sp_pub = rospy.Publisher(topics.set_point, Twist, queue_size=10)
        # The diff drive's input is advertised only while the stock path drives: the AIC refuses to
        # publish beside another publisher of its output topic (one publisher per command topic).
        self.cmd_pub = None
        self.outcome_pub = rospy.Publisher("~outcome", String, queue_size=1, latch=True)
        self.subs = [
            rospy.Subscriber("/status", Status, self._on_status, queue_size=10),
            rospy.Subscriber("/joint_states", JointState, self._on_joints, queue_size=100, tcp_nodelay=True),
            rospy.Subscriber(topics.odom, Odometry, self._on_odom, queue_size=100, tcp_nodelay=True),
            rospy.Subscriber(topics.cmd_vel, Twist, self._on_command, callback_args=topics.cmd_vel,
                             queue_size=100, tcp_nodelay=True),
            rospy.Subscriber("/cmd_drive", Drive, self._on_command, callback_args="/cmd_drive", queue_size=100,
                             tcp_nodelay=True),
            rospy.Subscriber("/imu/data", Imu, self._on_bag, callback_args="/imu/data", queue_size=100),
            rospy.Subscriber("/feedback", Feedback, self._on_bag, callback_args="/feedback", queue_size=20),
        ]
        if topics.odom != "/jackal_velocity_controller/odom":
            self.subs.append(rospy.Subscriber("/jackal_velocity_controller/odom", Odometry, self._on_bag,
                                              callback_args="/jackal_velocity_controller/odom", queue_size=100))
        for t in topics.joystick:
            self.subs.append(rospy.Subscriber(t, Twist, self._on_joystick, queue_size=10))
        if self.need_aic:
            self.subs += [
                rospy.Subscriber(topics.aic_node + "/sensor_health", DiagnosticStatus, self._on_health, queue_size=10),
                rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diagnostics, queue_size=10),
                rospy.Subscriber(topics.aic_node + "/belief", TwistStamped, self._on_bag,
                                 callback_args=topics.aic_node + "/belief", queue_size=200),
            ]
        self.enable_srv = None

    # ------------------------------------------------------------------ callbacks
    def _write(self, topic, msg, t=None):
        """Write to the current run's bag (if one is open); call with self.lock held."""
        if self.bag is not None:
            self.bag.write(topic, msg, t or self.rospy.Time.now())

    def _on_status(self, msg):
        with self.lock:
            self.snap.status = (bool(msg.drivers_active), bool(msg.driver_external_stop_stopped))
            self.snap.last_status = self.rospy.Time.now().to_sec()
            self._write("/status", msg)

    def _on_joints(self, msg):
        with self.lock:
            self.snap.last_joints = self.rospy.Time.now().to_sec()
            self.snap.wall_joints = time.monotonic()
            self._write("/joint_states", msg)

    def _on_odom(self, msg):
        p = msg.pose.pose
        pose = (p.position.x, p.position.y, yaw_of(p.orientation))
        with self.lock:
            self.world_pose = pose
            self.snap.last_odom = self.rospy.Time.now().to_sec()
            self.snap.wall_odom = time.monotonic()
            self.snap.twist = (msg.twist.twist.linear.x, msg.twist.twist.angular.z)
            if self.start_world is not None:
                xy = field_plan.in_frame([pose[:2]], self.start_world)[0]
                dth = pose[2] - self.start_world[2]
                self.snap.pose = (float(xy[0]), float(xy[1]), math.atan2(math.sin(dth), math.cos(dth)))
                d = math.hypot(xy[0], xy[1])
                self.max_distance = max(self.max_distance, d)
                for side, v in (("ahead", xy[0]), ("behind", -xy[0]), ("left", xy[1]), ("right", -xy[1])):
                    self.extent[side] = max(self.extent[side], float(v))
                self.run_max_distance = max(self.run_max_distance, d)
            self._write(self.topics.odom, msg)

    def _on_command(self, msg, topic):
        caller = msg._connection_header.get("callerid", "?") if hasattr(msg, "_connection_header") else "?"
        with self.lock:
            now = self.rospy.Time.now()
            self._write(topic, msg, now)
            self._write(BAG_PUBLISHERS, self.String(data="%s %s" % (topic, caller)), now)

    def _on_bag(self, msg, topic):
        with self.lock:
            self._write(topic, msg)

    def _on_joystick(self, msg):
        with self.lock:
            if self.joystick_armed:
                self.snap.last_joystick = self.rospy.Time.now().to_sec()

    def _on_health(self, msg):
        with self.lock:
            level = int(msg.level)
            if self.snap.aic_health is None or (self.snap.aic_health[0] >= field_safety.WARN) != (
                    level >= field_safety.WARN):
                self.snap.aic_health_since = self.rospy.Time.now().to_sec()
            self.snap.aic_health = (level, msg.message)

    def _on_diagnostics(self, msg):
        name = self.topics.aic_node.lstrip("/") + ": controller"
        for st in msg.status:
            if st.name == name:
                with self.lock:
                    self.snap.aic_controller = (int(st.level), st.message)

    # ------------------------------------------------------------------ helpers
    def snapshot(self):
        """The safety Snapshot now (a copy taken under the lock, times filled in)."""
        with self.lock:
            s = field_safety.Snapshot(self.rospy.Time.now().to_sec(), time.monotonic())
            s.__dict__.update({k: v for k, v in self.snap.__dict__.items() if k not in ("now", "wall")})
        s.aic_driving = self.active == "aic"
        if self.rospy.is_shutdown() and not s.interrupted:
            s.interrupted = "the node is shutting down"
        return s

    def interrupt(self, why):
        """Ask the session to stop (signal handler: Ctrl-C)."""
        self.snap.interrupted = why

    def event(self, text):
        """Log a line and write it into the current bag's /field_trial/event."""
        self.rospy.loginfo("field_trial: %s" % text)
        with self.lock:
            self._write(BAG_EVENT, self.String(data=text))

    def send(self, vx, wz):
        """Publish the set point (vx [m/s], wz [rad/s], clipped to the plan's limits) on the path of
        the active controller; record it as /field_trial/set_point."""
        vx = max(-self.plan.max_linear, min(self.plan.max_linear, vx))
        wz = max(-self.plan.max_angular, min(self.plan.max_angular, wz))
        m = self.Twist()
        m.linear.x, m.angular.z = vx, wz
        if self.active == "aic":
            self.sp_pub.publish(m)
        elif self.active == "stock" and self.cmd_pub is not None:
            self.cmd_pub.publish(m)
        with self.lock:
            self._write(BAG_SET_POINT, m)

    def set_aic_output(self, enabled, timeout=1.0):
        """Set the AIC's output gate through <aic_node>/enable_output; None on success, else why not."""
        if not self.have_aic:
            return None
        from std_srvs.srv import SetBool
        name = self.topics.aic_node + "/enable_output"
        try:
            if self.enable_srv is None:
                self.rospy.wait_for_service(name, timeout=timeout)
                self.enable_srv = self.rospy.ServiceProxy(name, SetBool)
            res = self.enable_srv(enabled)
        except Exception as e:  # rospy raises ROSException, ServiceException, ROSInterruptException
            return "%s: %s" % (name, e)
        self.aic_enabled = enabled
        self.rospy.loginfo("field_trial: %s %s: %s" % (name, enabled, res.message))
        return None

    def switch(self, controller):
        """Make ``controller`` the one that drives: silence the other path first, wait SWITCH_GAP;
        None on success, else why not."""
        if controller == self.active:
            return None
        self.active = None  # nobody publishes while switching
        if controller == "stock":
            why = self.set_aic_output(False)
            if not why and self.cmd_pub is None:
                self.cmd_pub = self.rospy.Publisher(self.topics.cmd_vel, self.Twist, queue_size=10)
        else:
            why = self.release_cmd_vel()
        if why:
            return why
        self._idle(SWITCH_GAP)
        if controller == "aic":
            why = self.set_aic_output(True)
            if why:
                return why
        self.active = controller
        return None

    def release_cmd_vel(self, timeout=2.0):
        """Stop advertising the diff drive's input and wait (wall clock) until the master no longer
        lists this node as its publisher, so the AIC sees itself alone on its output topic when it
        is enabled; None on success, else why not."""
        if self.cmd_pub is None:
            return None
        self.cmd_pub.unregister()
        self.cmd_pub = None
        import rosgraph
        me = self.rospy.get_name()
        master = rosgraph.Master(me)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                publishers = dict((t, n) for t, n in master.getSystemState()[0])
            except Exception as e:  # the master's XML-RPC errors
                return "listing the publishers of %s: %s" % (self.topics.cmd_vel, e)
            if me not in publishers.get(self.rospy.resolve_name(self.topics.cmd_vel), []):
                return None
            time.sleep(0.02)
        return "the master still lists %s as a publisher of %s after %g s" % (me, self.topics.cmd_vel, timeout)

    def _idle(self, seconds, interruptible=True):
        """Wait ``seconds`` of ROS time (at most 5 x that plus 1 s of wall time); with
        ``interruptible``, return early on a stop request (Ctrl-C)."""
        end = self.rospy.Time.now().to_sec() + seconds
        wall_end = time.monotonic() + 5.0 * seconds + 1.0
        while self.rospy.Time.now().to_sec() < end and time.monotonic() < wall_end:
            if interruptible and self.snap.interrupted:
                return
            time.sleep(0.005)

    # ------------------------------------------------------------------ the session
    def wait_ready(self):
        """Wait (start_timeout s, wall clock) until field_safety.ready(); None when ready, else why not."""
        deadline = time.monotonic() + self.start_timeout
        why = "not checked"
        while time.monotonic() < deadline and not self.snap.interrupted:
            why = field_safety.ready(self.snapshot(), self.plan, self.need_aic, self.topics.odom)
            if why is None:
                return None
            time.sleep(0.05)
        return "interrupted while waiting" if self.snap.interrupted else why

    def play(self, run, attempt):
        """Drive one run (settle, profile, rest) with its bag; returns (entry dict, Decision or None)."""
        import rosbag
        rospy = self.rospy
        bag_path = os.path.join(self.session.bag_dir, run.name + ("" if attempt == 0 else "_try%d" % attempt) + ".bag")
        entry = dict(run.to_dict(), attempt=attempt, status="running", reason="", bag=os.path.relpath(
            bag_path, self.session.out_dir))
        self.session.record(entry)
        stop = None
        wall0 = time.monotonic()
        with self.lock:
            self.bag = rosbag.Bag(bag_path, "w")
            self.run_max_distance = 0.0
        try:
            why = self.switch(run.controller)
            if why:
                stop = field_safety.Decision("switch_failed", why)
                return entry, stop
            self.event("run %s: controller %s, %s, %s (%.1f s)" % (run.name, run.controller, run.direction,
                                                                   run.profile.name, run.profile.duration))
            rate = rospy.Rate(self.plan.rate)
            t_begin = rospy.Time.now().to_sec()
            t0 = t_begin + self.plan.settle
            t_end = t0 + run.profile.duration + self.plan.rest
            wall_limit = wall0 + 3.0 * (t_end - t_begin) + 10.0
            entry["t_start"] = t_begin
            entry["t_profile"] = t0
            started = ended = False
            while True:
                now = rospy.Time.now().to_sec()
                stop = field_safety.check(self.snapshot(), self.plan, self.topics.odom)
                if stop is not None:
                    break
                if now >= t_end:
                    break
                if time.monotonic() > wall_limit:
                    stop = field_safety.Decision("sensor_lost", "time stalled: the run took %.0f s of wall time"
                                                 % (time.monotonic() - wall0))
                    break
                t = now - t0
                if t >= 0.0 and not started:
                    started = True
                    self.event("profile_start %.6f" % t0)
                if t >= run.profile.duration and not ended:
                    ended = True
                    self.event("profile_end %.6f" % (t0 + run.profile.duration))
                vx, wz = run.profile.value(t) if 0.0 <= t < run.profile.duration else (0.0, 0.0)
                self.send(vx, wz)
                rate.sleep()
            entry["t_end"] = rospy.Time.now().to_sec()
        except rospy.ROSInterruptException:
            stop = field_safety.Decision("interrupted", "ROS shut down during the run")
        finally:
            if stop is not None:
                self.halt(stop)
            with self.lock:
                bag, self.bag = self.bag, None
                entry["max_distance"] = self.run_max_distance
            bag.close()
        entry["wall_time"] = time.monotonic() - wall0
        entry["status"] = "completed" if stop is None else "stopped"
        entry["reason"] = "" if stop is None else str(stop)
        self.session.record(entry)
        return entry, stop

    def home(self):
        """Return slowly to the start pose through the stock path (plan.homing; the drift an out and
        back pair leaves), under the same safety checks. Returns a Decision if the session must
        stop, else None (also when homing is off, not needed or times out: the start check follows)."""
        h = self.plan.homing
        pose = self.snapshot().pose
        if not h["enabled"] or pose is None or (math.hypot(pose[0], pose[1]) <= h["tolerance"] and
                                                abs(pose[2]) <= h["heading_tolerance"]):
            return None
        rospy = self.rospy
        why = self.switch("stock")
        if why:
            return field_safety.Decision("switch_failed", why)
        rospy.loginfo("field_trial: homing from (%.2f m, %.2f m, %.2f rad) of the start pose" % pose)
        rate = rospy.Rate(self.plan.rate)
        t_end = rospy.Time.now().to_sec() + h["timeout"]
        wall_end = time.monotonic() + 3.0 * h["timeout"]
        approaching = None
        while True:
            snap = self.snapshot()
            stop = field_safety.check(snap, self.plan, self.topics.odom)
            if stop is not None:
                self.halt(stop)
                return stop
            vx, wz, done, approaching = field_safety.homing_command(snap.pose, h, approaching)
            if done or rospy.Time.now().to_sec() > t_end or time.monotonic() > wall_end:
                break
            self.send(vx, wz)
            rate.sleep()
        for _ in range(int(0.3 * self.plan.rate)):  # come to rest
            self.send(0.0, 0.0)
            rate.sleep()
        pose = self.snapshot().pose
        self.session.data.setdefault("homing", []).append([round(v, 4) for v in pose])
        rospy.loginfo("field_trial: homing %s at (%.2f m, %.2f m, %.2f rad)" % (
            "done" if done else "timed out", pose[0], pose[1], pose[2]))
        return None

    def halt(self, stop):
        """Stop now: silence the AIC, zero twists to the diff drive for safety.stop_hold s (wall
        clock, also when ROS time stalls), then the AIC's output back on; log the reason."""
        self.rospy.logwarn("field_trial: STOP (%s)" % stop)
        with self.lock:
            self._write(BAG_EVENT, self.String(data="stop %s" % stop))
        was = self.active
        self.active = "stock"  # the zero twists go straight to the diff drive
        if was == "aic" or self.aic_enabled:
            self.set_aic_output(False, timeout=0.2)
        if self.cmd_pub is None:  # the AIC drove: the diff drive's input is not advertised yet
            self.cmd_pub = self.rospy.Publisher(self.topics.cmd_vel, self.Twist, queue_size=10)
        end = time.monotonic() + self.plan.safety["stop_hold"]
        while time.monotonic() < end:
            self.send(0.0, 0.0)
            time.sleep(1.0 / self.plan.rate)
        self.active = None

    def finish(self, status, reason):
        """End the session: the robot at rest, the AIC's output enabled (the bringup's normal state),
        the summary written, the outcome published and logged."""
        if self.active is not None:  # after a completed run: already at rest; zero once more, briefly
            end = time.monotonic() + 0.2
            while time.monotonic() < end:
                self.send(0.0, 0.0)
                time.sleep(1.0 / self.plan.rate)
            self.active = None
        if self.aic_enabled is False:
            # as switch() does: the diff drive's input released and SWITCH_GAP of silence first
            why = self.release_cmd_vel()
            if not why:
                self._idle(SWITCH_GAP, interruptible=False)
                why = self.set_aic_output(True)
            if why:
                self.rospy.logerr("field_trial: could not enable the AIC's output again: %s" % why)
        self.session.data.update(status=status, reason=reason, max_distance_from_start=self.max_distance,
                                 corridor_extent=dict(self.extent))
        if self.wall_start is not None:
            self.session.data["wall_time"] = self.session.data.get("wall_time", 0.0) + time.time() - self.wall_start
        self.session.save()
        sides = ("ahead", "behind", "left", "right")
        text = "%s%s; max distance from the start pose %.2f m; reached %s (corridor %s) [m]; summary %s" % (
            status, (": " + reason) if reason else "", self.max_distance,
            " ".join("%s %.2f" % (k, self.extent[k]) for k in sides),
            " ".join("%g" % self.plan.corridor[k] for k in sides), self.session.path)
        self.outcome_pub.publish(self.String(data=text))
        (self.rospy.loginfo if status == "completed" else self.rospy.logwarn)("field_trial: " + text)

    def run(self, confirm):
        """The session: wait until ready, ``confirm()`` (True to start), then every run not yet
        completed; returns the exit status (EXIT_*)."""
        rospy = self.rospy
        why = self.wait_ready()
        if why is None and not self.need_aic:
            # a stock-only plan on a robot that runs the AIC: its (idle) output must be silenced too
            self.have_aic = True
            if self.set_aic_output(True, timeout=2.0) is not None:
                self.have_aic = False
                rospy.loginfo("field_trial: no %s/enable_output: no AIC to silence" % self.topics.aic_node)
        if why is None and self.need_aic:
            why = self.set_aic_output(True, timeout=self.start_timeout)
        if why is not None:
            self.session.data.update(status="refused", reason=why)
            self.session.save()
            self.outcome_pub.publish(self.String(data="refused: " + why))
            rospy.logerr("field_trial: not starting: %s" % why)
            return EXIT_REFUSED
        if not confirm():
            self.session.data.update(status="refused", reason="not confirmed")
            self.session.save()
            rospy.logwarn("field_trial: not confirmed; nothing moved")
            return EXIT_REFUSED
        with self.lock:
            self.start_world = self.world_pose
            self.snap.pose = (0.0, 0.0, 0.0)
            self.joystick_armed = True
            self.snap.last_joystick = None
        self.wall_start = time.time()
        self.session.data.update(status="running", start_pose=list(self.start_world))
        self.session.save()
        done = self.session.completed()
        attempts = {}
        for r in self.session.data["runs"]:
            attempts[r["name"]] = max(attempts.get(r["name"], -1), r.get("attempt", 0))
        rospy.loginfo("field_trial: session %s started at pose (%.2f, %.2f, %.2f) of %s; %d of %d runs to go" % (
            self.plan.name, self.start_world[0], self.start_world[1], self.start_world[2], self.topics.odom,
            len([r for r in self.plan.runs if r.name not in done]), len(self.plan.runs)))
        for run in self.plan.runs:
            if run.name in done:
                continue
            if run.direction == "out":
                stop = self.home()
                if stop is not None:
                    self.finish("interrupted" if stop.kind == "interrupted" else "stopped", str(stop))
                    return EXIT_STOPPED
                off = field_safety.start_offset(self.snapshot().pose, self.plan)
                if off:
                    self.finish("stopped", "off_start: " + off)
                    return EXIT_STOPPED
            entry, stop = self.play(run, attempts.get(run.name, -1) + 1)
            self.session.data.update(max_distance_from_start=self.max_distance, corridor_extent=dict(self.extent))
            self.session.save()
            if stop is not None:
                self.finish("interrupted" if stop.kind == "interrupted" else "stopped", str(stop))
                return EXIT_STOPPED
            rospy.loginfo("field_trial: %s completed (%.1f s wall, %.2f m max from the start)" % (
                run.name, entry["wall_time"], entry["max_distance"]))
        self.finish("completed", "")
        return EXIT_COMPLETED


def terminal_confirm(plan_text):
    """A confirm() for run(): on a terminal, ask for 'yes'; without one, refuse (use --yes)."""
    def confirm():
        if not sys.stdin.isatty():
            print("field_trial: no terminal to confirm on: start with --yes (yes:=true) after reading the dry run",
                  file=sys.stderr)
            return False
        print(plan_text)
        print("Space clear, e-stop in reach, robot at its start pose? Type yes to start: ", end="", flush=True)
        return sys.stdin.readline().strip().lower() == "yes"
    return confirm


def main(args):
    """Run a session from parsed arguments (scripts/aic_field_trial.py); returns the exit status."""
    try:
        plan = field_plan.load_plan(args.plan)
    except field_plan.PlanError as e:
        print("aic_field_trial: %s" % e, file=sys.stderr)
        return EXIT_REFUSED
    text = field_plan.dry_run_text(plan)
    if args.dry_run:
        print(text)
        print("dry run: nothing published")
        return EXIT_COMPLETED
    topics = Topics(args.set_point_topic, args.cmd_vel_topic, args.odom_topic, args.joystick_topic or
                    Topics().joystick, args.aic_node)
    try:
        session = Session(args.out, plan, topics, resume=args.resume)
    except (ValueError, OSError) as e:
        print("aic_field_trial: %s" % e, file=sys.stderr)
        return EXIT_REFUSED
    import rospy
    rospy.init_node("field_trial", disable_signals=True)
    node = TrialNode(plan, session, topics, start_timeout=args.start_timeout)

    def on_signal(signum, _frame):
        node.interrupt("Ctrl-C (signal %d)" % signum)
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    rospy.loginfo("field_trial: plan %s, %d runs, output %s" % (plan.name, len(plan.runs), session.out_dir))
    confirm = (lambda: True) if args.yes else terminal_confirm(text)
    try:
        return node.run(confirm)
    finally:
        rospy.signal_shutdown("session over")
