"""record_identification.py: drive a Jackal through the identification sequence and record the bag
that `plant_identify.py --bag` identifies its wheel loop from.

On the robot (a ROS node; `roslaunch jackal_aic record_identification.launch bag:=FILE`): the
sequence (jackal_aic_tools.identify.bag_identification.SEQUENCES: straight steps forward and back, turns in
place both ways, from rest, at bounded speeds) is published as geometry_msgs/Twist on ~cmd_vel_topic
(default /jackal_velocity_controller/cmd_vel, the input of the stock base's diff drive) at 50 Hz,
and the node records /cmd_drive, /jackal_velocity_controller/cmd_vel, /joint_states, /imu/data,
/feedback and /status into ~bag. Safety:
- every set point is clipped to ~max_linear / ~max_angular (at most 1.0 m/s and 2.0 rad/s);
- it starts only once /status (jackal_msgs/Status) reports the drivers active and no stop
  engaged (~require_status; false skips this), and /joint_states arrive, within ~start_timeout s;
- it stops, sending zero twists, as soon as /status reports a stop (driver_external_stop_stopped,
  or drivers_active false): the e-stop; as soon as twist_mux's lock engages (std_msgs/Bool true on
  ~lock_topic, default e_stop, the lock of jackal_control's twist_mux.yaml); when /joint_states
  stay away for ~data_timeout s; when the run exceeds the sequence's length by ~overrun s (wall
  clock too, if ROS time stalls); on Ctrl-C;
- it stops, and publishes nothing more, as soon as the joystick is used (any message on
  ~joy_topic, default joy_teleop/cmd_vel, twist_mux's highest-priority input): the joystick has
  the robot from then on, as twist_mux gives it over every other input, and the sequence never
  resumes. ~cmd_vel_topic bypasses twist_mux, so these two are the recorder's own: "" disables one;
- afterwards it publishes zero twists for 1 s (not after the joystick), closes the bag and exits.
Its outcome ("completed", "stopped: e-stop", "stopped: e-stop lock", "stopped: joystick",
"stopped: timeout ...", "aborted: ...") is published
(latched std_msgs/String) on ~outcome and logged; exit status 0 only when completed.

Leave 1.5 m free ahead of and behind the robot and 0.5 m beside it (standard sequence), keep the
e-stop in reach, and run it on the floor the robot works on.

Headless (no ROS master): `record_identification.py --headless OUT.bag [--sequence short]
[--overlay FILE]... [--set KEY=VALUE]... [--no-noise]` writes the bag the simulated Jackal records
for the same sequence (plant_replay: the stock controller's /cmd_drive stream, the plant and its
sensor models, the cores the plant node and the stock base run; stamped on plant time), e.g. with
sim/config/variants/turn_deficit.yaml to check what `plant_identify.py --bag` finds.
"""
import os
import threading
import time

from . import bag_identification as bi

RATE = 50.0  # Hz


class Recorder(object):
    """The ROS node (see the module's docstring); its parameters are read from the private
    namespace when it is made (ValueError: a bad ~sequence or limit)."""

    def __init__(self):
        import rosbag
        import rospy
        from geometry_msgs.msg import Twist
        from jackal_msgs.msg import Drive, Feedback, Status
        from sensor_msgs.msg import Imu, JointState
        from std_msgs.msg import String

        self.rospy = rospy
        self.Twist = Twist
        p = rospy.get_param
        self.cmd_vel_topic = p("~cmd_vel_topic", bi.CMD_VEL)
        self.profile = bi.sequence_profile(p("~sequence", "standard"), float(p("~max_linear", 0.8)),
                                           float(p("~max_angular", 1.5)))
        self.require_status = bool(p("~require_status", True))
        self.start_timeout = float(p("~start_timeout", 15.0))
        self.data_timeout = float(p("~data_timeout", 0.5))
        self.overrun = float(p("~overrun", 5.0))
        self.joy_topic = str(p("~joy_topic", "joy_teleop/cmd_vel"))
        self.lock_topic = str(p("~lock_topic", "e_stop"))
        self.joystick = False  # the joystick was used: it has the robot
        self.locked = False    # twist_mux's lock engaged
        bag_path = os.path.expanduser(p("~bag", "jackal_identification.bag"))
        self.lock = threading.Lock()
        self.bag = rosbag.Bag(bag_path, "w")
        self.bag_path = bag_path
        self.status = None
        self.last_joint_states = None
        self.pub = rospy.Publisher(self.cmd_vel_topic, Twist, queue_size=10)
        self.outcome_pub = rospy.Publisher("~outcome", String, queue_size=1, latch=True)
        self.String = String
        self.subs = []
        from std_msgs.msg import Bool
        if self.joy_topic:
            self.subs.append(rospy.Subscriber(self.joy_topic, Twist, self.on_joystick, queue_size=10,
                                              tcp_nodelay=True))
        if self.lock_topic:
            self.subs.append(rospy.Subscriber(self.lock_topic, Bool, self.on_lock, queue_size=10, tcp_nodelay=True))
        for topic, typ in ((bi.CMD_DRIVE, Drive), (self.cmd_vel_topic, Twist), (bi.JOINT_STATES, JointState),
                           (bi.IMU, Imu), (bi.FEEDBACK, Feedback), (bi.STATUS, Status)):
            self.subs.append(rospy.Subscriber(topic, typ, self.on_message, callback_args=topic, queue_size=100,
                                              tcp_nodelay=True))

    def on_message(self, msg, topic):
        """Write a message of ``topic`` into the bag; keep /status and the time of /joint_states."""
        now = self.rospy.Time.now()
        with self.lock:
            if self.bag is not None:
                self.bag.write(bi.CMD_VEL if topic == self.cmd_vel_topic else topic, msg, now)
            if topic == bi.STATUS:
                self.status = msg
            elif topic == bi.JOINT_STATES:
                self.last_joint_states = now

    def on_joystick(self, _msg):
        """Any message on ~joy_topic: the joystick takes the robot; the sequence stops for good."""
        with self.lock:
            self.joystick = True

    def on_lock(self, msg):
        """twist_mux's lock (std_msgs/Bool): true stops the sequence for good."""
        if msg.data:
            with self.lock:
                self.locked = True

    def overridden(self):
        """Why an operator took over ("stopped: joystick", "stopped: e-stop lock"), or None."""
        with self.lock:
            if self.joystick:
                return "stopped: joystick"
            if self.locked:
                return "stopped: e-stop lock"
        return None

    def stopped(self):
        """The e-stop (or the motor enable off) as /status reports it."""
        with self.lock:
            s = self.status
        return s is not None and (s.driver_external_stop_stopped or not s.drivers_active)

    def send(self, vx, wz):
        """Publish the twist vx [m/s], wz [rad/s] on ~cmd_vel_topic."""
        t = self.Twist()
        t.linear.x = vx
        t.angular.z = wz
        self.pub.publish(t)

    def wait_ready(self):
        """Wait for /status (drivers active, no stop) and /joint_states; None when ready, else why not."""
        deadline = time.monotonic() + self.start_timeout
        rate = self.rospy.Rate(10.0)
        while not self.rospy.is_shutdown():
            with self.lock:
                have_status = self.status is not None
                have_joints = self.last_joint_states is not None
            if have_joints and (have_status or not self.require_status) and not self.stopped():
                return None
            if self.overridden():
                return "aborted: " + self.overridden()[len("stopped: "):]
            if time.monotonic() > deadline:
                if self.stopped():
                    return "aborted: the stop is engaged"
                if not have_joints:
                    return "aborted: no %s within %g s" % (bi.JOINT_STATES, self.start_timeout)
                return "aborted: no %s with the drivers active within %g s (is the base running?)" % (
                    bi.STATUS, self.start_timeout)
            rate.sleep()
        return "aborted: shut down"

    def drive(self):
        """Play the sequence; returns the outcome."""
        rospy = self.rospy
        rate = rospy.Rate(RATE)
        t0 = rospy.Time.now()
        wall0 = time.monotonic()
        limit = self.profile.duration + self.overrun
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            t = (now - t0).to_sec()
            if self.stopped():
                return "stopped: e-stop"
            if self.overridden():
                return self.overridden()
            with self.lock:
                last = self.last_joint_states
            if last is not None and (now - last).to_sec() > self.data_timeout:
                return "stopped: timeout, no %s for %g s" % (bi.JOINT_STATES, self.data_timeout)
            if t > limit or time.monotonic() - wall0 > limit + 10.0:
                return "stopped: timeout, the run exceeded %.1f s" % limit
            if t >= self.profile.duration:
                return "completed"
            self.send(*self.profile.value(t))
            rate.sleep()
        return "stopped: shut down"

    def finish(self, outcome):
        """Send zero twists for 1 s (none when the joystick has the robot), close the bag, publish
        and log ``outcome``."""
        rospy = self.rospy
        end = time.monotonic() + (0.0 if outcome == "stopped: joystick" else 1.0)
        while time.monotonic() < end:  # zero twists for 1 s (wall clock: also when ROS time stalls)
            self.send(0.0, 0.0)
            time.sleep(1.0 / RATE)
        for s in self.subs:
            s.unregister()
        with self.lock:
            self.bag.close()
            self.bag = None
        self.outcome_pub.publish(self.String(data=outcome))
        (rospy.loginfo if outcome == "completed" else rospy.logwarn)(
            "record_identification: %s; bag %s" % (outcome, self.bag_path))

    def run(self):
        """Wait, drive, finish; returns the exit status (0 completed, 3 otherwise)."""
        self.rospy.loginfo("record_identification: sequence %s, %.1f s, on %s (|v| <= %g m/s, |w| <= %g rad/s); "
                           "recording %s" % (self.profile.name, self.profile.duration, self.cmd_vel_topic,
                                             self.profile.max_abs("vx"), self.profile.max_abs("wz"), self.bag_path))
        outcome = self.wait_ready() or self.drive()
        self.finish(outcome)
        return 0 if outcome == "completed" else 3
