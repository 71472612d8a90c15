"""The field trial's safety rules as pure functions (doc/field_trials.md, 'Safety'): given a
snapshot of what the trial node has heard, whether the session may start and whether it must stop
now, with the reason. No ROS: the node fills a Snapshot from its subscriptions every cycle.

Stop conditions, in the order they are reported:
  interrupted   Ctrl-C (SIGINT) or the node shutting down
  estop         /status: the e-stop (driver_external_stop_stopped) or the drivers off
  status_lost   no /status for safety.status_timeout [s]
  sensor_lost   no /joint_states or no odometry for safety.data_timeout [s] (ROS time; or five
                times that on the wall clock, which catches a stalled simulated clock)
  geofence      the odometry's pose outside the corridor (start frame)
  overspeed     |measured vx| or |wz| beyond overspeed_factor x the plan's limits
  aic_fault     while the AIC drives: its ~sensor_health at WARN or worse for safety.fault_persistence
                [s] (a sensor isolated, the IMU missing, sensors disagreeing; a blip of one message
                is not a fault) or its "controller" diagnostics at ERROR (runaway)
  joystick      a message on a joystick twist topic (twist_mux's higher priority: someone took over)
"""
import math

#: Reasons a session stops (Decision.kind).
KINDS = ("interrupted", "estop", "status_lost", "sensor_lost", "geofence", "overspeed", "aic_fault", "joystick")
#: Wall-clock slack factor on the data timeout (a simulated clock that stops does not age ROS time).
WALL_FACTOR = 5.0
#: diagnostic_msgs/DiagnosticStatus levels.
OK, WARN, ERROR, STALE = 0, 1, 2, 3


class Decision(object):
    """A stop: ``kind`` (one of KINDS) and ``reason`` (a sentence for the log and the summary)."""

    def __init__(self, kind, reason):
        self.kind = kind
        self.reason = reason

    def __repr__(self):
        return "Decision(%r, %r)" % (self.kind, self.reason)

    def __str__(self):
        return "%s: %s" % (self.kind, self.reason)


class Snapshot(object):
    """What the trial node knows at one instant. Times are seconds on the ROS clock (``now``) and on
    the wall clock (``wall``); a ``last_*`` of None means never received.

    status: None or (drivers_active, external_stop_stopped); last_status, last_joints, last_odom
    (ROS receipt times [s]) and wall_joints, wall_odom (wall receipt times [s]); pose: None or (x,
    y, heading) in the session's start frame [m, m, rad]; twist: None or (vx [m/s], wz [rad/s])
    measured; aic_driving: the AIC is the controller of the current run; aic_health: None or
    (level, message) of ~sensor_health, aic_health_since: ROS time [s] it reached that level (None:
    unknown, counts as long ago); aic_controller: None or (level, message) of its "controller"
    diagnostics; last_joystick: ROS receipt time [s] of the newest joystick message since the
    session started (None: none); interrupted: None or why (Ctrl-C)."""

    def __init__(self, now=0.0, wall=0.0):
        self.now = now
        self.wall = wall
        self.status = None
        self.last_status = None
        self.last_joints = None
        self.wall_joints = None
        self.last_odom = None
        self.wall_odom = None
        self.pose = None
        self.twist = None
        self.aic_driving = False
        self.aic_health = None
        self.aic_health_since = None
        self.aic_controller = None
        self.last_joystick = None
        self.interrupted = None


def _stale(last, wall_last, now, wall, timeout):
    """Age [s] if a stream is stale (never received, ROS age > timeout or wall age > WALL_FACTOR x
    timeout), else None."""
    if last is None:
        return math.inf
    age = now - last
    if age > timeout:
        return age
    if wall_last is not None and wall - wall_last > WALL_FACTOR * timeout:
        return wall - wall_last
    return None


def _outside(pose, corridor):
    """How far (x, y) in the start frame lies beyond the corridor rectangle [m] (0 inside)."""
    x, y = pose[0], pose[1]
    return max(0.0, x - corridor["ahead"], -x - corridor["behind"], y - corridor["left"], -y - corridor["right"])


def check(snap, plan, odom_topic="odometry"):
    """The stop decision for ``snap`` (Snapshot) under ``plan`` (field_plan.Plan: limits, corridor,
    safety): a Decision, or None to go on."""
    s = plan.safety
    if snap.interrupted:
        return Decision("interrupted", snap.interrupted)
    if snap.status is not None:
        active, stopped = snap.status
        if stopped:
            return Decision("estop", "/status reports the e-stop engaged")
        if not active:
            return Decision("estop", "/status reports the drivers inactive")
    age = _stale(snap.last_status, None, snap.now, snap.wall, s["status_timeout"])
    if age is not None:
        return Decision("status_lost", "no /status for %s (status_timeout %g s)" % (_age(age), s["status_timeout"]))
    for name, last, wall_last in (("/joint_states", snap.last_joints, snap.wall_joints),
                                  (odom_topic, snap.last_odom, snap.wall_odom)):
        age = _stale(last, wall_last, snap.now, snap.wall, s["data_timeout"])
        if age is not None:
            return Decision("sensor_lost", "no %s for %s (data_timeout %g s)" % (name, _age(age), s["data_timeout"]))
    if snap.pose is not None:
        out = _outside(snap.pose, plan.corridor)
        if out > 0.0:
            return Decision("geofence", "the robot at x %+.2f m, y %+.2f m (start frame) is %.2f m outside the "
                            "corridor (ahead %g, behind %g, left %g, right %g m)" % (
                                snap.pose[0], snap.pose[1], out, plan.corridor["ahead"], plan.corridor["behind"],
                                plan.corridor["left"], plan.corridor["right"]))
    if snap.twist is not None:
        f = s["overspeed_factor"]
        vx, wz = snap.twist
        if abs(vx) > f * plan.max_linear or abs(wz) > f * plan.max_angular:
            return Decision("overspeed", "measured vx %.2f m/s, wz %.2f rad/s beyond %g x the limits (%g m/s, %g rad/s)"
                            % (vx, wz, f, plan.max_linear, plan.max_angular))
    if snap.aic_driving:
        if snap.aic_health is not None and snap.aic_health[0] >= WARN and (
                snap.aic_health_since is None or snap.now - snap.aic_health_since >= s["fault_persistence"]):
            return Decision("aic_fault", "the AIC's sensor health: %s" % snap.aic_health[1])
        if snap.aic_controller is not None and snap.aic_controller[0] >= ERROR:
            return Decision("aic_fault", "the AIC's controller diagnostics: %s" % snap.aic_controller[1])
    if snap.last_joystick is not None:
        return Decision("joystick", "joystick activity (a twist on the joystick's topic): the operator took over")
    return None


def ready(snap, plan, need_aic, odom_topic="odometry"):
    """Whether a session (or the next run) may start: None, or why not. Requires /status with the
    drivers active and no stop, fresh /joint_states and odometry, and (``need_aic``) the AIC's
    sensor health reported and OK; then every stop condition of check() must be clear."""
    if snap.status is None:
        return "no /status yet (is the base running?)"
    if not snap.status[0]:
        return "/status reports the drivers inactive"
    if snap.status[1]:
        return "/status reports the e-stop engaged"
    if snap.last_joints is None:
        return "no /joint_states yet"
    if snap.last_odom is None:
        return "no %s yet" % odom_topic
    if need_aic:
        if snap.aic_health is None:
            return "no sensor health from the AIC yet (is jackal_AIC running?)"
        if snap.aic_health[0] >= WARN:
            return "the AIC's sensor health is not OK: %s" % snap.aic_health[1]
    stop = check(snap, plan, odom_topic)
    return None if stop is None else str(stop)


def start_offset(pose, plan):
    """None if ``pose`` (x, y, heading in the session's start frame) is close enough to the start pose
    for the next run (safety.start_tolerance [m], heading_tolerance [rad]), else why not."""
    d = math.hypot(pose[0], pose[1])
    h = abs(math.atan2(math.sin(pose[2]), math.cos(pose[2])))
    s = plan.safety
    if d > s["start_tolerance"] or h > s["heading_tolerance"]:
        return ("the robot is %.2f m and %.2f rad from the start pose (tolerance %g m, %g rad): put it back and "
                "resume the session (--resume)" % (d, h, s["start_tolerance"], s["heading_tolerance"]))
    return None


def _age(age):
    return "ever" if math.isinf(age) else "%.2f s" % age


def _wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


#: Homing drives to within this fraction of homing.tolerance before it turns to the start heading:
#: turning in place moves the odometry's point (a skid-steer base turns about a point that is not
#: base_link; 1-2 cm on the simulated Jackal), which must not take it back out of the tolerance.
HOMING_GOAL = 0.5


def homing_command(pose, homing, approaching=None):
    """One step of the slow return to the start pose between runs (out-and-back leaves some drift:
    skid, a turn the wheel loop cannot hold). ``pose``: (x, y, heading) in the start frame [m, m,
    rad]; ``homing``: dict max_linear [m/s], max_angular [rad/s], min_angular [rad/s] (below it a
    skid-steer turn may not break away), tolerance [m], heading_tolerance [rad]; ``approaching``:
    the phase the previous step returned (None on the first step). Returns (vx [m/s], wz [rad/s],
    done, approaching): turn toward the start (backwards if it lies behind) and drive there, from
    beyond ``tolerance`` to within HOMING_GOAL x tolerance (hysteresis: without it, each turn in
    place moving the point across the tolerance alternates the two phases, turning one way and
    the other for good), then turn to the start heading; done when within both tolerances."""
    x, y, th = pose
    d = math.hypot(x, y)
    if approaching:
        approaching = d > HOMING_GOAL * homing["tolerance"]
    else:
        approaching = d > homing["tolerance"]
    if approaching:
        err = _wrap(math.atan2(-y, -x) - th)
        back = abs(err) > math.pi / 2
        if back:
            err = _wrap(err - math.pi)
        vx = 0.0
        if abs(err) < 0.3:
            vx = min(homing["max_linear"], 0.8 * d) * math.cos(err) * (-1.0 if back else 1.0)
        return vx, _turn(err, homing, moving=vx != 0.0), False, True
    err = _wrap(-th)
    if abs(err) <= homing["heading_tolerance"]:
        return 0.0, 0.0, True, False
    return 0.0, _turn(err, homing, moving=False), False, False


def _turn(err, homing, moving):
    """Yaw rate toward a heading error ``err`` [rad]: proportional, at least min_angular in place."""
    w = min(homing["max_angular"], 1.5 * abs(err))
    if not moving:
        w = max(w, homing["min_angular"])
    return math.copysign(w, err)
