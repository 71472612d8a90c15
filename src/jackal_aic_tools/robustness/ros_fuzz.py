"""ROS fuzz of the jackal_AIC node: the node alone (launch/jackal_aic.launch) under its own ROS
master, fed seeded, structure-aware random messages at a high rate on /joint_states, /imu/data,
/jackal_AIC/set_point, /status and /feedback: random joint names (unknown, missing, duplicated),
random array lengths, values drawn from a mixture (plausible, huge, tiny, NaN, +-Inf, -0.0),
random stamps (zero, backwards, far future, repeated), bursts and silences, with plausible
stretches in between so that the controller drives.

Verdict: every /cmd_drive command finite and |wheel| <= max_wheel_speed (the node's parameter,
compared in the message's float32), and the node still alive and publishing at the end. Prints
the messages sent per kind, the commands received, the non-finite and over-limit counts and
the node's drop counters from /diagnostics. Usage (in the workspace environment):

  scripts/aic_ros_fuzz.py --seconds 600 --seed 1 [--rate 1000] [--output doc/results/ros_fuzz.md]
"""
import math
import os
import tempfile

from ..common.ros_process import launched, wait_for_nodes
from .node_watch import CommandCheck, diagnostics_callback, drop_counters, loadavg

DRIVE_TOPIC = "/cmd_drive"


# ---- the generator (pure: a seeded random.Random and a clock passed in) ----------------------

KINDS = ("joint_states", "imu", "set_point", "status", "feedback")
KNOWN_JOINTS = ("front_left_wheel", "rear_left_wheel", "front_right_wheel", "rear_right_wheel")
OTHER_JOINTS = ("extra_caster_joint", "", "front_left_wheel ", "FRONT_LEFT_WHEEL", "wheel_0", "x" * 300,
                "rear_left_wheel/", "\u00e9l\u00e8ve")
WHEEL_RADIUS = 0.098      # [m] of the plausible wheel speeds (params.hpp default)
WHEEL_SEPARATION = 0.5621  # [m] idem
MAX_STAMP_NS = (2 ** 32 - 1) * 10 ** 9  # the largest ROS 1 time (uint32 seconds)
FLOAT32_MAX = 3.4028234663852886e38
PLAUSIBLE_RATE = 50.0  # [Hz] of the sensors in a plausible stretch (the Jackal's)
SET_POINT_RATE = 20.0  # [Hz] of the set point in a plausible stretch


class Message(object):
    """One generated message: ``kind`` (one of KINDS), ``fields`` (dict: the message's content in
    plain Python, see FuzzGenerator), ``tags`` (sorted tuple of what was made invalid or odd in it;
    empty for a plausible message) and ``gap`` [s] (wall time to wait before sending it)."""

    __slots__ = ("kind", "fields", "tags", "gap")

    def __init__(self, kind, fields, tags, gap):
        self.kind, self.fields, self.tags, self.gap = kind, fields, tuple(sorted(set(tags))), gap

    def __repr__(self):
        return "Message(%s, gap %.4f, tags %s, %r)" % (self.kind, self.gap, self.tags, self.fields)


class FuzzGenerator(object):
    """Seeded, structure-aware random messages for the node's inputs, as Message objects, in
    phases of random length:

      plausible  valid sensors at PLAUSIBLE_RATE and a set point at SET_POINT_RATE, stamped now,
                 a random drive (set point v in [-1, 1] m/s, w in [-1.5, 1.5] rad/s; wheels either
                 consistent with it or random within +-20 rad/s), a healthy MCU (/status drivers
                 active, /feedback MODE_VELOCITY); 0.5-3 s
      fuzz       messages of random kinds at ``rate`` [1/s], each field made odd with a
                 per-stretch probability (value() mixture, random joint names and array
                 lengths, random stamps: stamp()); 0.2-2 s
      burst      20-500 messages (fuzzed or plausible) with no gap
      silence    nothing for 0.1-2 s (the first message after it carries the gap)

    Stamps are integers [ns] drawn around the ``now_ns`` passed to next(); fields are plain Python
    (floats, lists, bools, ints) that to_ros() turns into messages. Everything is drawn from
    ``rng`` (random.Random), so a seed and the sequence of now_ns values fix the sequence."""

    PHASES = (("plausible", 0.45), ("fuzz", 0.35), ("burst", 0.1), ("silence", 0.1))

    def __init__(self, rng, rate=1000.0):
        if not rate > 0:
            raise ValueError("rate must be > 0, got %r" % (rate,))
        self.rng = rng
        self.rate = float(rate)
        self.phase = None
        self.phase_left = 0.0     # [s] of the stretch (plausible, fuzz) or messages (burst) left
        self.pending_gap = 0.0    # [s] of silence to add to the next message's gap
        self.last_stamp = {k: 0 for k in KINDS}
        self.drive = (0.0, 0.0, 0.0, 0.0)  # v, w, omega_L, omega_R of the plausible stretch
        self.p_odd = 0.3
        self.clock = 0.0          # [s] of the schedule so far (sum of the gaps)
        self.due = {}             # plausible stretch: kind -> time [s] of its next message
        self.phases = {name: 0 for name, _ in self.PHASES}

    # -- phases --
    def _new_phase(self):
        r, acc = self.rng.random(), 0.0
        for name, w in self.PHASES:
            acc += w
            if r < acc:
                break
        self.phase = name
        self.phases[name] += 1
        if name == "plausible":
            self.phase_left = self.rng.uniform(0.5, 3.0)
            v, w = self.rng.uniform(-1.0, 1.0), self.rng.uniform(-1.5, 1.5)
            if self.rng.random() < 0.7:
                wl = (v - w * WHEEL_SEPARATION / 2) / WHEEL_RADIUS
                wr = (v + w * WHEEL_SEPARATION / 2) / WHEEL_RADIUS
            else:
                wl, wr = self.rng.uniform(-20, 20), self.rng.uniform(-20, 20)
            self.drive = (v, w, wl, wr)
            self.due = {"joint_states": self.clock, "imu": self.clock + 0.005, "set_point": self.clock,
                        "status": self.clock, "feedback": self.clock}
        elif name == "fuzz":
            self.phase_left = self.rng.uniform(0.2, 2.0)
            self.p_odd = self.rng.choice((0.02, 0.1, 0.3, 1.0))
        elif name == "burst":
            self.phase_left = self.rng.randint(20, 500)
            self.p_odd = self.rng.choice((0.0, 0.1, 0.5))
        else:
            self.pending_gap += self.rng.uniform(0.1, 2.0)
            self.phase = None

    def hold_plausible(self, v, w):
        """From now on, only a plausible stretch that never ends: set point ``v`` [m/s], ``w``
        [rad/s], the wheels consistent with it; a silence under way is cut short."""
        self.phase, self.phase_left, self.pending_gap = "plausible", float("inf"), 0.0
        half = w * WHEEL_SEPARATION / 2
        self.drive = (v, w, (v - half) / WHEEL_RADIUS, (v + half) / WHEEL_RADIUS)
        self.due = {k: self.clock for k in KINDS}

    def next(self, now_ns):
        """The next Message; ``now_ns``: the current time [ns] (ROS time on the wall clock, or any
        clock in a test) against which its stamp is drawn. Its gap includes any silence."""
        while self.phase is None or self.phase_left <= 0:
            self._new_phase()
        if self.phase == "plausible":
            kind = min(self.due, key=lambda k: (self.due[k], KINDS.index(k)))
            gap = max(0.0, self.due[kind] - self.clock)
            period = {"joint_states": 1 / PLAUSIBLE_RATE, "imu": 1 / PLAUSIBLE_RATE,
                      "set_point": 1 / SET_POINT_RATE, "status": 1.0, "feedback": 0.1}[kind]
            self.due[kind] += period
            self.phase_left -= gap
            msg = self._plausible(kind, now_ns + int(gap * 1e9))
            tags = []
        elif self.phase == "fuzz":
            gap = self.rng.expovariate(self.rate)
            self.phase_left -= gap
            msg, tags = self._fuzzed(self.rng.choice(KINDS), now_ns + int(gap * 1e9), self.p_odd)
        else:  # burst
            gap = 0.0
            self.phase_left -= 1
            kind = self.rng.choice(KINDS)
            if self.rng.random() < self.p_odd:
                msg, tags = self._fuzzed(kind, now_ns, 0.3)
            else:
                msg, tags = self._plausible(kind, now_ns), []
        gap += self.pending_gap
        if self.pending_gap:
            tags = list(tags) + ["after silence"]
        self.pending_gap = 0.0
        self.clock += gap
        kind, fields = msg
        if "stamp" in fields:
            self.last_stamp[kind] = fields["stamp"]
        return Message(kind, fields, tags, gap)

    # -- plausible messages --
    def _plausible(self, kind, now_ns):
        v, w, wl, wr = self.drive
        n = lambda s: self.rng.gauss(0.0, s)
        if kind == "joint_states":
            names = list(KNOWN_JOINTS)
            self.rng.shuffle(names)
            vel = {"front_left_wheel": wl, "rear_left_wheel": wl, "front_right_wheel": wr, "rear_right_wheel": wr}
            return kind, {"stamp": now_ns, "name": names, "position": [self.rng.uniform(-100, 100) for _ in names],
                          "velocity": [vel[j] + n(0.05) for j in names], "effort": [n(1.0) for _ in names]}
        if kind == "imu":
            return kind, {"stamp": now_ns, "orientation": [0.0, 0.0, 0.0, 1.0],
                          "angular_velocity": [n(0.01), n(0.01), w + n(0.02)],
                          "linear_acceleration": [n(0.1), n(0.1), 9.81 + n(0.1)],
                          "covariance": [[0.0] * 9, [0.0] * 9, [0.0] * 9]}
        if kind == "set_point":
            return kind, {"linear": [v, 0.0, 0.0], "angular": [0.0, 0.0, w]}
        if kind == "status":
            return kind, {"stamp": now_ns, "drivers_active": True, "stop_present": False, "stop_stopped": False,
                          "floats": [self.rng.uniform(0, 30) for _ in range(9)]}
        return kind, {"stamp": now_ns, "actual_mode": 0, "commanded_mode": 0}

    # -- fuzzed messages --
    def value(self, plausible, tags, float32=False):
        """One number from the mixture: ``plausible`` (a float) 60 %, else huge (+-1e6 .. +-1e308,
        +-3.4e38 at most for a float32 field), tiny (+-1e-300 .. 1e-30, 5e-324), NaN, +Inf, -Inf,
        -0.0 or 0.0; appends what it chose (other than plausible) to ``tags``."""
        r = self.rng.random()
        if r < 0.6:
            return plausible
        choice = self.rng.choice(("huge", "tiny", "nan", "+inf", "-inf", "-0.0", "zero"))
        tags.append(choice)
        sign = self.rng.choice((-1.0, 1.0))
        if choice == "huge":
            mag = 10 ** self.rng.uniform(6.0, 38.5 if float32 else 308.0)
            return sign * (min(mag, FLOAT32_MAX) if float32 else mag)
        if choice == "tiny":
            if not float32 and self.rng.random() < 0.1:
                return sign * 5e-324
            return sign * 10 ** self.rng.uniform(-38.0 if float32 else -300.0, -30.0)
        return {"nan": float("nan"), "+inf": float("inf"), "-inf": float("-inf"), "-0.0": -0.0, "zero": 0.0}[choice]

    def _numbers(self, plausible, p, tags, float32=False):
        return [self.value(x, tags, float32) if self.rng.random() < p else x for x in plausible]

    def stamp(self, kind, now_ns, tags):
        """A stamp [ns] for a fuzzed ``kind`` message: now 50 %, else zero, backwards (1 ms to
        100 s), far future (1 s to 10^6 s, or the largest ROS time), repeated (the last one sent on
        ``kind``) or now +-1 ns; appends the choice to ``tags``. Always within [0, MAX_STAMP_NS]."""
        if self.rng.random() < 0.5:
            return now_ns
        choice = self.rng.choice(("stamp zero", "stamp backwards", "stamp future", "stamp repeated", "stamp jitter"))
        tags.append(choice)
        if choice == "stamp zero":
            s = 0
        elif choice == "stamp backwards":
            s = now_ns - int(10 ** self.rng.uniform(-3, 2) * 1e9)
        elif choice == "stamp future":
            s = MAX_STAMP_NS if self.rng.random() < 0.1 else now_ns + int(10 ** self.rng.uniform(0, 6) * 1e9)
        elif choice == "stamp repeated":
            s = self.last_stamp[kind]
        else:
            s = now_ns + self.rng.choice((-1, 1))
        return min(max(s, 0), MAX_STAMP_NS)

    def _names(self, tags):
        r = self.rng.random()
        names = list(KNOWN_JOINTS)
        self.rng.shuffle(names)
        if r < 0.5:
            return names
        if r < 0.65:
            tags.append("joint missing")
            for _ in range(self.rng.randint(1, 4)):
                names.pop(self.rng.randrange(len(names)))
            return names
        if r < 0.8:
            tags.append("joint duplicated")
            names.insert(self.rng.randrange(len(names) + 1), self.rng.choice(KNOWN_JOINTS))
            return names
        tags.append("joint unknown")
        pool = list(KNOWN_JOINTS) + list(OTHER_JOINTS)
        return [self.rng.choice(pool) for _ in range(self.rng.randint(0, 8))]

    def _length(self, n, tags, field):
        if self.rng.random() < 0.8:
            return n
        tags.append("length " + field)
        return self.rng.choice((0, max(0, n - 1), n + 1, self.rng.randint(0, 12)))

    def _fuzzed(self, kind, now_ns, p):
        base_kind, base = self._plausible(kind, now_ns)
        tags = []
        f = dict(base)
        if "stamp" in f:
            f["stamp"] = self.stamp(kind, now_ns, tags)
        if kind == "joint_states":
            f["name"] = self._names(tags)
            for field in ("position", "velocity", "effort"):
                vel = {"front_left_wheel": self.drive[2], "rear_left_wheel": self.drive[2],
                       "front_right_wheel": self.drive[3], "rear_right_wheel": self.drive[3]}
                vals = [vel.get(j, 0.0) if field == "velocity" else self.rng.uniform(-10, 10) for j in f["name"]]
                n = self._length(len(vals), tags, field)
                vals = (vals + [self.rng.uniform(-20, 20) for _ in range(n)])[:n]
                f[field] = self._numbers(vals, p, tags)
        elif kind == "imu":
            for field in ("orientation", "angular_velocity", "linear_acceleration"):
                f[field] = self._numbers(f[field], p, tags)
            f["covariance"] = [self._numbers(c, p / 3, tags) for c in f["covariance"]]
        elif kind == "set_point":
            plaus = [self.rng.uniform(-3, 3) for _ in range(3)]
            f["linear"] = self._numbers([f["linear"][0]] + plaus[1:], p, tags)
            f["angular"] = self._numbers(plaus[:2] + [f["angular"][2]], p, tags)
        elif kind == "status":
            for key in ("drivers_active", "stop_present", "stop_stopped"):
                if self.rng.random() < p:
                    f[key] = not f[key]
                    tags.append("status " + key)
            f["floats"] = self._numbers(f["floats"], p, tags, float32=True)
        else:
            if self.rng.random() < p:
                f["actual_mode"] = self.rng.choice((-1, 1, 2, 3, -128, 127))
                tags.append("feedback mode %d" % f["actual_mode"])
            if self.rng.random() < p:
                f["commanded_mode"] = self.rng.randint(-128, 127)
        return (base_kind, f), tags


# ---- the verdict ---------------------------------------------------------------------------

def verdict(check, alive, final_commands):
    """The fuzz run's findings as a list of text (empty: clean): every command finite and within
    the limit (``check``: CommandCheck), the node alive at the end (``alive``: bool) and still
    publishing (``final_commands``: /cmd_drive messages received during the final plausible
    stretch; 0 is a finding)."""
    out = []
    if check.non_finite:
        out.append("%d non-finite command(s)" % check.non_finite)
    if check.over_limit:
        out.append("%d command(s) beyond +-%g rad/s" % (check.over_limit, check.limit))
    out += check.findings if out else []
    if not alive:
        out.append("the node is not running at the end")
    elif final_commands == 0:
        out.append("no /cmd_drive during the final plausible stretch (the node stopped publishing)")
    return out


# ---- ROS: messages, the fuzz loop, the run under its own master -----------------------------

def message_type(kind):
    """The ROS message class of a generated ``kind`` (one of KINDS)."""
    from geometry_msgs.msg import Twist
    from jackal_msgs.msg import Feedback, Status
    from sensor_msgs.msg import Imu, JointState
    return {"joint_states": JointState, "imu": Imu, "set_point": Twist, "status": Status, "feedback": Feedback}[kind]


def to_ros(kind, fields):
    """The ROS message of a generated ``kind`` with ``fields`` (Message.kind, Message.fields):
    sensor_msgs/JointState, sensor_msgs/Imu, geometry_msgs/Twist, jackal_msgs/Status or
    jackal_msgs/Feedback; stamps [ns] become rospy.Time."""
    import rospy
    from geometry_msgs.msg import Twist
    from jackal_msgs.msg import Feedback, Status
    from sensor_msgs.msg import Imu, JointState

    def stamp(ns):
        return rospy.Time(ns // 10 ** 9, ns % 10 ** 9)

    if kind == "joint_states":
        m = JointState()
        m.header.stamp = stamp(fields["stamp"])
        m.name, m.position, m.velocity, m.effort = (fields[k] for k in ("name", "position", "velocity", "effort"))
    elif kind == "imu":
        m = Imu()
        m.header.stamp = stamp(fields["stamp"])
        o, g, a = fields["orientation"], fields["angular_velocity"], fields["linear_acceleration"]
        m.orientation.x, m.orientation.y, m.orientation.z, m.orientation.w = o
        m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = g
        m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = a
        m.orientation_covariance, m.angular_velocity_covariance, m.linear_acceleration_covariance = fields["covariance"]
    elif kind == "set_point":
        m = Twist()
        m.linear.x, m.linear.y, m.linear.z = fields["linear"]
        m.angular.x, m.angular.y, m.angular.z = fields["angular"]
    elif kind == "status":
        m = Status()
        m.header.stamp = stamp(fields["stamp"])
        m.drivers_active = fields["drivers_active"]
        m.driver_external_stop_present = fields["stop_present"]
        m.driver_external_stop_stopped = fields["stop_stopped"]
        (m.measured_battery, m.measured_12v, m.measured_5v, m.drive_current, m.user_current, m.computer_current,
         m.total_current, m.total_current_peak, m.total_power_consumed) = fields["floats"]
    else:
        m = Feedback()
        m.header.stamp = stamp(fields["stamp"])
        m.actual_mode, m.commanded_mode = fields["actual_mode"], fields["commanded_mode"]
    return m


TOPICS = {"joint_states": "/joint_states", "imu": "/imu/data", "set_point": "/jackal_AIC/set_point",
          "status": "/status", "feedback": "/feedback"}
FINAL_STRETCH = 3.0  # [s] of plausible messages after the fuzz: the node must still publish


def fuzz(seconds, seed, rate, limit=None, log=print):
    """Fuzz the running jackal_AIC node (rospy initialised, the node up) for ``seconds`` of wall
    time with FuzzGenerator(random.Random(seed), rate), checking every /cmd_drive against
    ``limit`` [rad/s] (default: the node's ~max_wheel_speed), then send FINAL_STRETCH s of
    plausible messages and count the commands meanwhile. Returns the result dict that verdict()
    judges and summary_lines()/markdown() print: sent per kind and per tag, commands, the
    CommandCheck, the drop counters from /diagnostics."""
    import collections
    import random
    import time

    import rospy
    from diagnostic_msgs.msg import DiagnosticArray
    from jackal_msgs.msg import Drive

    if limit is None:
        limit = rospy.get_param("/jackal_AIC/max_wheel_speed")
    check = CommandCheck(limit)
    diag = {}
    t_start = time.time()
    moving = {"n": 0}

    def on_cmd(m):
        check.add(m.drivers, "%.3f s" % (time.time() - t_start))
        if all(math.isfinite(d) for d in m.drivers) and max(abs(d) for d in m.drivers) > 0.1:
            moving["n"] += 1

    rospy.Subscriber("/cmd_drive", Drive, on_cmd, queue_size=10000)
    rospy.Subscriber("/diagnostics", DiagnosticArray, diagnostics_callback(diag), queue_size=100)
    pubs = {k: rospy.Publisher(t, message_type(k), queue_size=1000) for k, t in TOPICS.items()}
    deadline = time.time() + 10.0
    while time.time() < deadline and not all(p.get_num_connections() for p in pubs.values()):
        time.sleep(0.05)
    gen = FuzzGenerator(random.Random(seed), rate)
    sent, tags = collections.Counter(), collections.Counter()
    t_next = time.time()
    end = t_next + seconds
    while not rospy.is_shutdown():
        msg = gen.next(rospy.Time.now().to_nsec())
        t_next += msg.gap
        if t_next >= end:
            break
        delay = t_next - time.time()
        if delay > 0:
            time.sleep(delay)
        pubs[msg.kind].publish(to_ros(msg.kind, msg.fields))
        sent[msg.kind + (" fuzzed" if msg.tags and msg.tags != ("after silence",) else " plausible")] += 1
        tags.update(msg.tags)
    wall = time.time() - t_start
    # the final plausible stretch: a fresh generator held in its plausible phase
    final = FuzzGenerator(random.Random(seed + 1), rate)
    final.hold_plausible(0.5, 0.0)
    before = check.commands
    t_next = time.time()
    end = t_next + FINAL_STRETCH
    while time.time() < end and not rospy.is_shutdown():
        msg = final.next(rospy.Time.now().to_nsec())
        t_next += msg.gap
        delay = t_next - time.time()
        if delay > 0:
            time.sleep(delay)
        pubs[msg.kind].publish(to_ros(msg.kind, msg.fields))
    time.sleep(0.5)  # the last commands in flight
    final_commands = check.commands - before
    return {"seconds": wall, "seed": seed, "rate": rate, "sent": dict(sent), "tags": dict(tags),
            "phases": dict(gen.phases), "check": check, "final_commands": final_commands,
            "moving_commands": moving["n"], "drops": drop_counters(diag)}


def summary_lines(res, findings):
    """The fuzz figures (``res``: fuzz()'s result, ``findings``: verdict()) as printed lines."""
    c = res["check"]
    total = sum(res["sent"].values())
    out = ["ros fuzz: %.1f s, seed %d, %d messages sent (%.0f /s; fuzz stretches at %g /s)" %
           (res["seconds"], res["seed"], total, total / max(res["seconds"], 1e-9), res["rate"]),
           "  sent: " + ", ".join("%s %d" % kv for kv in sorted(res["sent"].items())),
           "  stretches: " + ", ".join("%s %d" % kv for kv in sorted(res["phases"].items())),
           "  odd fields (messages): " + ", ".join("%s %d" % kv for kv in sorted(res["tags"].items())),
           "  /cmd_drive commands %d (|wheel| > 0.1 rad/s: %d); non-finite %d; beyond +-%g rad/s %d; "
           "max |wheel| %.3f rad/s" % (c.commands, res["moving_commands"], c.non_finite, c.limit, c.over_limit,
                                       c.max_abs),
           "  commands in the final %.0f s plausible stretch: %d" % (FINAL_STRETCH, res["final_commands"]),
           "  node drop counters: " + (", ".join("%s %d" % kv for kv in sorted(res["drops"].items())) or "none seen")]
    out.append("  verdict: " + ("clean" if not findings else "FINDING: " + "; ".join(findings)))
    return out


def markdown(res, findings, argv=None):
    """The fuzz figures as a Markdown document: title, the command (``argv``: the script's
    arguments), a figure | value table, the messages sent per kind and per odd field, the node's
    drop counters and the verdict."""
    c = res["check"]
    total = sum(res["sent"].values())
    cmd = "scripts/aic_ros_fuzz.py " + " ".join(argv or [])
    lines = ["# ROS fuzz: random messages on the jackal_AIC node's inputs", "",
             "Written by `%s` (src/jackal_aic_tools/robustness/ros_fuzz.py; doc/tools.md, 'ROS fuzz'): "
             "launch/jackal_aic.launch alone under its own ROS master on the wall clock, fed seeded structure-aware "
             "random messages on "
             "/joint_states, /imu/data, /jackal_AIC/set_point, /status and /feedback in stretches "
             "(plausible, fuzz, burst, silence); every /cmd_drive judged, then %.0f s of plausible messages "
             "during which the node must still publish." % (cmd.strip(), FINAL_STRETCH), "",
             "| figure | value |", "|---|---|",
             "| wall time | %.1f s |" % res["seconds"],
             "| seed | %d |" % res["seed"],
             "| messages sent | %d (%.0f /s on average; fuzz stretches at %g /s) |" %
             (total, total / max(res["seconds"], 1e-9), res["rate"]),
             "| stretches | %s |" % ", ".join("%s %d" % kv for kv in sorted(res["phases"].items())),
             "| /cmd_drive commands | %d (with abs wheel > 0.1 rad/s: %d) |" % (c.commands, res["moving_commands"]),
             "| non-finite commands | %d |" % c.non_finite,
             "| commands beyond max_wheel_speed | %d (limit %g rad/s; max abs wheel %.3f rad/s) |" %
             (c.over_limit, c.limit, c.max_abs),
             "| commands in the final plausible stretch | %d |" % res["final_commands"],
             "| verdict | %s |" % ("clean" if not findings else "FINDING: " + "; ".join(findings).replace("|", "/")),
             ] + (["| host load average (1, 5, 15 min) | before %s, after %s; %d CPU(s) |" % res["load"]]
                  if res.get("load") else []) + [
             "", "| kind | plausible | fuzzed |", "|---|---|---|"]
    for k in KINDS:
        lines.append("| %s | %d | %d |" % (k, res["sent"].get(k + " plausible", 0), res["sent"].get(k + " fuzzed", 0)))
    lines += ["", "| odd field | messages |", "|---|---|"]
    lines += ["| %s | %d |" % kv for kv in sorted(res["tags"].items())]
    lines += ["", "| node drop counter (/diagnostics, at the end) | count |", "|---|---|"]
    lines += ["| %s | %d |" % kv for kv in sorted(res["drops"].items())]
    return "\n".join(lines) + "\n"


def run(args, argv=None):
    """Start launch/jackal_aic.launch alone under its own master (ros_process.launched), fuzz it for
    args.seconds (seed args.seed, rate args.rate), print the figures and, with args.output, write
    them as Markdown (``argv``: the command line). roslaunch's output (the node's) goes to
    aic_ros_fuzz.<pid>.roslaunch.log in the temporary folder, kept and named on a finding, else
    removed. Returns 0 when
    clean, 1 on a finding."""
    import rospy

    launch_log = os.path.join(tempfile.gettempdir(), "aic_ros_fuzz.%d.roslaunch.log" % os.getpid())
    with launched("jackal_aic.launch", log_path=launch_log) as launch:
        pids = wait_for_nodes(("jackal_AIC",), launch)
        if not pids:
            print("ros fuzz: the node did not start (roslaunch exit %s)" % launch.poll())
            return 1
        rospy.init_node("aic_ros_fuzz", disable_signals=True)
        load0 = loadavg()
        res = fuzz(args.seconds, args.seed, args.rate)
        res["load"] = (load0, loadavg(), os.cpu_count())
        alive = launch.poll() is None and os.path.exists("/proc/%d" % pids["jackal_AIC"])
    findings = verdict(res["check"], alive, res["final_commands"])
    for line in summary_lines(res, findings):
        print(line)
    if findings:
        print("ros fuzz: roslaunch's output (the node's included) in %s" % launch_log)
    else:
        os.remove(launch_log)
    if args.output:
        with open(args.output, "w") as f:
            f.write(markdown(res, findings, argv))
        print("ros fuzz: figures written to %s" % args.output)
    return 1 if findings else 0
