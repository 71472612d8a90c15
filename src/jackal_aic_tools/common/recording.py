"""Recording of an experiment's streams and the stability monitor.

Streams (topics as in README.md, 'Topics', and doc/jackal_aic_node.md), each kept as a list of
(stamp [s], a, b):
  set point  /jackal_AIC/set_point  geometry_msgs/Twist     (publication time, vx, wz)
  measured   /odom                  nav_msgs/Odometry       (header stamp, twist.linear.x, twist.angular.z; base_link)
  belief     /jackal_AIC/belief     geometry_msgs/TwistStamped (header stamp, linear.x, angular.z)
  drive      /cmd_drive             jackal_msgs/Drive       (receipt time, left, right [rad/s])
and, kept beside them (not in the merged CSV of experiment.write_csv):
  pose       /odom                  nav_msgs/Odometry       (header stamp, x [m], y [m], yaw [rad]; ground truth
                                                             on the simulator)
  wheels     /joint_states          sensor_msgs/JointState  (header stamp, mean left, mean right wheel velocity
                                                             [rad/s]; joints named *left* / *right*)
and the AIC's stamped inference (write_csv merges it in with its own columns):
  inference  /jackal_AIC/inference  jackal_aic/InferenceState (header stamp = the sensor sample's, then
                                                             inference.values(): F, its parts, ..., b_hat,
                                                             gyro offset; columns inference.columns(orders))
"""
import math
import threading

import numpy as np

from . import inference, profiles

STREAMS = ("setpoint", "odom", "belief", "drive")
#: Columns of each stream's array (the stamp first).
WIDTH = dict({s: 3 for s in STREAMS}, pose=4, wheels=3, separation=2, gyro_offset=2)


class Recorder(object):
    """Thread-safe store of the four streams; callbacks are safe to pass to rospy."""

    def __init__(self, bag=None):
        self.lock = threading.Lock()
        self.data = {s: [] for s in WIDTH}
        self.data["inference"] = []
        #: generalized orders of the inference messages (None before the first)
        self.inference_orders = None
        self.bad_stamps = 0
        self.bag = bag

    def _add(self, stream, stamp, a, b, topic=None, msg=None, now=None, c=None):
        with self.lock:
            self.data[stream].append((stamp, float(a), float(b)) + (() if c is None else (float(c),)))
            if self.bag is not None and msg is not None:
                self.bag.write(topic, msg, now)

    def _stamp(self, msg):
        import rospy
        now = rospy.Time.now()
        st = msg.header.stamp
        if st.is_zero():
            self.bad_stamps += 1
            st = now
        return st.to_sec(), now

    def on_odom(self, msg):
        st, now = self._stamp(msg)
        tw = msg.twist.twist
        self._add("odom", st, tw.linear.x, tw.angular.z, "/odom", msg, now)
        p = msg.pose.pose
        q = p.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        self._add("pose", st, p.position.x, p.position.y, c=yaw)

    def on_joint_states(self, msg):
        """Mean wheel velocity of the joints named *left* and of those named *right*."""
        st, now = self._stamp(msg)
        left = [v for n, v in zip(msg.name, msg.velocity) if "left" in n]
        right = [v for n, v in zip(msg.name, msg.velocity) if "right" in n]
        if left and right:
            self._add("wheels", st, sum(left) / len(left), sum(right) / len(right), "/joint_states", msg, now)

    def on_belief(self, msg):
        st, now = self._stamp(msg)
        self._add("belief", st, msg.twist.linear.x, msg.twist.angular.z, "/jackal_AIC/belief", msg, now)

    def _scalar(self, stream, topic, msg):
        """Append the std_msgs/Float64 ``msg`` of ``topic`` to ``stream`` at receipt time."""
        import rospy
        now = rospy.Time.now()
        with self.lock:
            self.data[stream].append((now.to_sec(), float(msg.data)))
            if self.bag is not None:
                self.bag.write(topic, msg, now)

    def on_separation(self, msg):
        """The generative model's wheel separation b_hat [m] (std_msgs/Float64 on
        /jackal_AIC/wheel_separation; learned with learn_wheel_separation), at receipt time."""
        self._scalar("separation", "/jackal_AIC/wheel_separation", msg)

    def on_gyro_offset(self, msg):
        """The gyro offset beta_hat the node removes from the gyro [rad/s] (std_msgs/Float64 on
        /jackal_AIC/gyro_offset; learned at standstill with learn_gyro_bias), at receipt time."""
        self._scalar("gyro_offset", "/jackal_AIC/gyro_offset", msg)

    def on_inference(self, msg):
        """The AIC's stamped inference (jackal_aic/InferenceState on /jackal_AIC/inference): a row
        (header stamp, *inference.values(msg)). A message of another embedding order than the first
        is dropped (the columns are those of the first)."""
        st, now = self._stamp(msg)
        row = (st,) + tuple(inference.values(msg))
        with self.lock:
            if self.inference_orders is None:
                self.inference_orders = int(msg.orders)
            if int(msg.orders) == self.inference_orders:
                self.data["inference"].append(row)
            if self.bag is not None:
                self.bag.write("/jackal_AIC/inference", msg, now)

    def inference_columns(self):
        """Column names of the inference array after its stamp (inference.columns + LEARNED), or []
        before the first message."""
        with self.lock:
            n = self.inference_orders
        return [] if n is None else inference.columns(n) + list(inference.LEARNED)

    def on_drive(self, msg):
        import rospy
        now = rospy.Time.now()
        self._add("drive", now.to_sec(), msg.drivers[0], msg.drivers[1], "/cmd_drive", msg, now)

    def on_setpoint(self, stamp, msg):
        """Record a set point we published at ``stamp`` (rospy.Time)."""
        self._add("setpoint", stamp.to_sec(), msg.linear.x, msg.angular.z,
                  "/jackal_AIC/set_point", msg, stamp)

    def arrays(self):
        """Copy of every stream as an (n, WIDTH) numpy array [stamp, a, b(, c)]; "inference" as an
        (n, 1 + len(inference_columns())) array [stamp, values...]."""
        with self.lock:
            out = {s: np.array(self.data[s], dtype=float).reshape(-1, w) for s, w in WIDTH.items()}
            width = 1 if self.inference_orders is None else \
                1 + len(inference.columns(self.inference_orders)) + len(inference.LEARNED)
            out["inference"] = np.array(self.data["inference"], dtype=float).reshape(-1, width)
            return out

    def count(self, stream):
        with self.lock:
            return len(self.data[stream])


def drive_equivalent(drive, wheel_radius, wheel_separation):
    """Wheel speeds (n,3: stamp, left, right [rad/s]; drive commands or measured wheels) as the
    body twist (n,3: stamp, vx [m/s], wz [rad/s]) with the kinematics G of thesis eq. 3-1
    (doc/active_inference.md); ``wheel_separation`` [m]: one value or one per row (n,)."""
    out = np.empty_like(drive)
    out[:, 0] = drive[:, 0]
    out[:, 1] = wheel_radius * 0.5 * (drive[:, 1] + drive[:, 2])
    out[:, 2] = wheel_radius * (drive[:, 2] - drive[:, 1]) / wheel_separation
    return out



def separation_at(stamps, separation, default):
    """The wheel separation b_hat [m] in force at each of ``stamps`` ((n,) [s]): the last sample
    of ``separation`` ((m,2): stamp [s], b_hat [m], stamps non-decreasing; the AIC's
    /jackal_AIC/wheel_separation or a closed_loop_run trace's separation column) at or before it,
    ``default`` [m] (the configured wheel_separation) before the first sample or with none.
    Returns an (n,) array. Raises ValueError when a sample is not finite and > 0 or the stamps
    decrease."""
    stamps = np.asarray(stamps, dtype=float)
    separation = np.asarray(separation, dtype=float).reshape(-1, 2) if np.size(separation) else np.zeros((0, 2))
    if not (np.all(np.isfinite(separation[:, 1])) and np.all(separation[:, 1] > 0.0)):
        raise ValueError("separation_at: b_hat samples must be finite and > 0 (got %s)" % separation[:, 1])
    if np.any(np.diff(separation[:, 0]) < 0.0):
        raise ValueError("separation_at: the b_hat stamps decrease")
    out = np.full(stamps.shape, float(default))
    if separation.shape[0]:
        k = np.searchsorted(separation[:, 0], stamps, side="right") - 1
        out[k >= 0] = separation[k[k >= 0], 1]
    return out


def drive_twist(drive, wheel_radius, wheel_separation, separation):
    """The drive commands (n,3: stamp, left, right [rad/s]) as the body twist (n,3: stamp, vx
    [m/s], wz [rad/s]) they ask for in the controller's model: drive_equivalent() with the
    learned b_hat in force at each command (separation_at(): ``separation`` (m,2) stamp, b_hat
    [m]; the configured ``wheel_separation`` [m] before the first sample or without any). Raises
    ValueError as separation_at()."""
    return drive_equivalent(drive, wheel_radius, separation_at(drive[:, 0], separation, wheel_separation))

class StabilityLimits(object):
    """When a run counts as diverged.

    v_bound [m/s], w_bound [rad/s]: |measured or believed twist| beyond these; any
    non-finite value; or oscillation: once a set-point level has been held ``osc_after``
    [s], the measured or commanded velocity in the last ``osc_window`` [s] spans more than
    ``osc_frac`` of max(|step|, ``osc_floor``) and crosses the set point (with that
    hysteresis) at least ``osc_crossings`` times.
    """

    def __init__(self, v_bound=3.0, w_bound=8.0, osc_after=1.5, osc_window=1.0, osc_frac=0.5,
                 osc_floor=0.1, osc_crossings=3):
        self.v_bound = v_bound
        self.w_bound = w_bound
        self.osc_after = osc_after
        self.osc_window = osc_window
        self.osc_frac = osc_frac
        self.osc_floor = osc_floor
        self.osc_crossings = osc_crossings


def _crossings(err, hyst):
    """Number of sign changes of err with hysteresis ``hyst`` (noise does not count)."""
    state = 0
    n = 0
    for e in err:
        s = 1 if e > hyst else (-1 if e < -hyst else 0)
        if s != 0:
            if state != 0 and s != state:
                n += 1
            state = s
    return n


def oscillation(values, start, target, limits):
    """The span [units of values] if ``values`` (1-D, the last ``limits.osc_window`` seconds of
    one held set-point level ``target``, reached from ``start``) oscillate by the rule of
    :class:`StabilityLimits`, else None. Fewer than 4 samples never count."""
    w = np.asarray(values, dtype=float)
    if w.size < 4:
        return None
    scale = max(abs(target - start), limits.osc_floor)
    span = float(np.max(w) - np.min(w))
    if span > limits.osc_frac * scale and \
            _crossings(w - target, 0.25 * limits.osc_frac * scale) >= limits.osc_crossings:
        return span
    return None


def check_stability(arr, segments_abs, now, limits, wheel_radius, wheel_separation):
    """None if the run looks sane at time ``now`` [s], else the reason it diverged.

    arr: Recorder.arrays(); segments_abs: list of Segment with absolute t0/t1 [s].
    """
    for s in ("odom", "belief", "drive"):
        a = arr[s]
        if a.size and not np.all(np.isfinite(a)):
            return "non-finite value on %s" % s
    for s in ("odom", "belief"):
        a = arr[s]
        if a.size:
            if np.max(np.abs(a[:, 1])) > limits.v_bound:
                return "|%s linear.x| %.3g m/s beyond %.3g m/s" % (s, np.max(np.abs(a[:, 1])), limits.v_bound)
            if np.max(np.abs(a[:, 2])) > limits.w_bound:
                return "|%s angular.z| %.3g rad/s beyond %.3g rad/s" % (s, np.max(np.abs(a[:, 2])), limits.w_bound)
    # oscillation on the level currently held
    drive = drive_equivalent(arr["drive"], wheel_radius, wheel_separation) if arr["drive"].size else arr["drive"]
    for seg in segments_abs:
        if not (seg.t0 + limits.osc_after <= now <= seg.t1 + 0.05):
            continue
        ci = 1 + profiles.CHANNELS.index(seg.channel)
        lo = max(seg.t0 + limits.osc_after - limits.osc_window, now - limits.osc_window)
        for name, a in (("measured velocity", arr["odom"]), ("drive command", drive)):
            if not a.size:
                continue
            span = oscillation(a[(a[:, 0] >= lo) & (a[:, 0] <= now), ci], seg.start, seg.target, limits)
            if span is not None:
                return "oscillation: %s spans %.3g %s around %.3g in the last %.2g s" % (
                    name, span, profiles.UNITS[seg.channel], seg.target, limits.osc_window)
    return None


def actual_segments(profile, setpoints, t0):
    """Profile segments with absolute times [s]: each transition starts at the stamp of the
    first published set point carrying the new value (not the nominal profile time).

    setpoints: (n,3) array [stamp, vx, wz] of what was published; t0: profile start [s].
    """
    segs = profile.segments()
    out = []
    for seg in segs:
        ci = 1 + profiles.CHANNELS.index(seg.channel)
        t_nom = t0 + seg.t0
        ts = t_nom
        if setpoints.size:
            idx = np.nonzero((setpoints[:, 0] >= t_nom - 1e-6) & (setpoints[:, ci] == seg.target))[0]
            if idx.size:
                ts = setpoints[idx[0], 0]
        out.append(profiles.Segment(ts, t0 + seg.t1, seg.channel, seg.start, seg.target))
    # a segment ends where the next one on the same channel starts
    fixed = []
    for k, s in enumerate(out):
        nxt = [o.t0 for o in out[k + 1:] if o.channel == s.channel]
        fixed.append(s._replace(t1=nxt[0] if nxt else s.t1))
    return fixed
