"""The robot model's wheel loop from the MCU's identified motor keys (doc/active_inference.md, 'The
robot model'; the plant's wheel loop: doc/robot_data.md).

The robot model's wheel (its side's mean wheel speed omega) follows the command u sent one latency
L earlier through a first-order lag T_w, the MCU's acceleration feed-forward K_ff of the command's
rate bounded by A_ff, and the bound A_w on the whole acceleration:

    d omega / dt = clamp((u - d - omega) / T_w, +-(A_w - A_ff)) + clamp(K_ff du/dt, +-A_ff)

Each of its five keys follows from the plant's motor keys (the MCU's wheel loop that plant_identify
fits, on the simulator's steps or on a robot's bag), J_n the loop's nominal inertia
(load_observer_inertia):

    latency                         L    = command_delay
    wheel_time_constant             T_w  = setpoint_time_constant + J_n / speed_kp
    wheel_acceleration              A_w  = min(accel_feedforward_limit + proportional_limit, max_torque) / J_n
    wheel_feedforward               K_ff = accel_feedforward / J_n
    wheel_feedforward_acceleration  A_ff = min(accel_feedforward_limit, max_torque) / J_n

T_w is the proportional path's own lag: the set point's filter plus the inertia over the gain (the
feed-forward, in the model, does the rest). A clamp of 0 (none) counts as max_torque, the loop's
current limit, and A_w stays within it. config/default.yaml holds these of sim/config/plant.yaml
(test/test_track.py checks that they agree); plant_identify.py --bag writes those its fit moves into
the robot model's overlay (jackal_aic_tools.identify.bag_fit).
"""
import math

#: Each robot-model key's equation in the motor keys (the module's equations, as text for the
#: comments of the YAML a tool writes; model_key() computes them).
EQUATIONS = {
    "latency": "command_delay",
    "wheel_time_constant": "setpoint_time_constant + load_observer_inertia / speed_kp",
    "wheel_acceleration": "min(accel_feedforward_limit + proportional_limit, max_torque) / load_observer_inertia",
    "wheel_feedforward": "accel_feedforward / load_observer_inertia",
    "wheel_feedforward_acceleration": "min(accel_feedforward_limit, max_torque) / load_observer_inertia",
}
#: Each robot-model key -> the motor keys it depends on.
DEPENDS_ON = {
    "latency": ("command_delay",),
    "wheel_time_constant": ("setpoint_time_constant", "load_observer_inertia", "speed_kp"),
    "wheel_acceleration": ("accel_feedforward_limit", "proportional_limit", "max_torque", "load_observer_inertia"),
    "wheel_feedforward": ("accel_feedforward", "load_observer_inertia"),
    "wheel_feedforward_acceleration": ("accel_feedforward_limit", "max_torque", "load_observer_inertia"),
}
_POSITIVE = ("load_observer_inertia", "max_torque", "speed_kp")


def _values(motor, keys):
    """{key: float} of ``keys`` of ``motor``; raises ValueError naming the first key missing, not
    finite, negative, or (load_observer_inertia, max_torque, speed_kp) not > 0."""
    out = {}
    for key in keys:
        if key not in motor:
            raise ValueError("wheel loop model: motor.%s missing from the plant's motor keys" % key)
        try:
            v = float(motor[key])
        except (TypeError, ValueError):
            raise ValueError("wheel loop model: motor.%s = %r is not a number" % (key, motor[key]))
        ok = v > 0.0 if key in _POSITIVE else v >= 0.0
        if not (math.isfinite(v) and ok):
            raise ValueError("wheel loop model: motor.%s = %r, need %s" % (
                key, v, "> 0 and finite" if key in _POSITIVE else ">= 0 and finite"))
        out[key] = v
    return out


def wheel_acceleration(motor):
    """A_w [rad/s^2], the largest wheel acceleration the MCU's wheel loop gives, from a plant's motor
    keys ``motor`` (closed_loop.plant_motor: the plant YAML and a variant's overlay):

        A_w = min(accel_feedforward_limit + proportional_limit, max_torque) / load_observer_inertia

    the clamps of the loop's acceleration feed-forward and proportional path [N m] over its nominal
    inertia J_n [kg m^2] (42.87 rad/s^2 on sim/config/plant.yaml). A clamp of 0 (none) counts as
    max_torque [N m], and the sum is at most max_torque (the loop's torque limit), so that A_w stays
    an upper bound. Raises ValueError naming the key when a key is missing, a limit is negative or
    not finite, or load_observer_inertia or max_torque is not > 0."""
    return _wheel_acceleration(_values(motor, DEPENDS_ON["wheel_acceleration"]))


def _wheel_acceleration(v):
    """A_w [rad/s^2] of the validated motor values ``v`` (_values() of its DEPENDS_ON keys)."""
    limit = v["max_torque"]
    torque = sum(v[k] or limit for k in ("accel_feedforward_limit", "proportional_limit"))
    return min(torque, limit) / v["load_observer_inertia"]


#: The compensation limit's equation (compensation_limit()), as text for the YAML a tool writes.
COMPENSATION_EQUATION = "proportional_limit / speed_kp"


def compensation_limit(motor):
    """e_c [rad/s], the robot model's shortfall_compensation_limit of the motor keys ``motor``: the
    speed error at which the MCU's proportional path saturates,

        e_c = proportional_limit / speed_kp

    (a proportional_limit of 0, none, counts as max_torque [N m]). Beyond it a raised command adds
    no torque at once; on a loop whose integral path takes the rest up (no load observer) it only
    winds that integral up (doc/active_inference.md, 'The robot model'). Raises ValueError naming the
    key when proportional_limit, max_torque or speed_kp is missing, negative or not finite, or
    speed_kp or max_torque is not > 0."""
    v = _values(motor, ("proportional_limit", "max_torque", "speed_kp"))
    return (v["proportional_limit"] or v["max_torque"]) / v["speed_kp"]


def model_key(motor, key):
    """One robot-model key (DEPENDS_ON's names) of the motor keys ``motor``, by the module's
    equations, read from the motor keys it depends on only. Raises ValueError naming the motor key
    when one it needs is missing, negative or not finite, or load_observer_inertia, max_torque or
    speed_kp is not > 0; KeyError for a name not in DEPENDS_ON."""
    v = _values(motor, DEPENDS_ON[key])
    if key == "latency":
        return v["command_delay"]
    if key == "wheel_time_constant":
        return v["setpoint_time_constant"] + v["load_observer_inertia"] / v["speed_kp"]
    if key == "wheel_acceleration":
        return _wheel_acceleration(v)
    if key == "wheel_feedforward":
        return v["accel_feedforward"] / v["load_observer_inertia"]
    return min(v["accel_feedforward_limit"] or v["max_torque"], v["max_torque"]) / v["load_observer_inertia"]


def robot_model_keys(motor):
    """The robot model's wheel-loop keys {latency [s], wheel_time_constant [s], wheel_acceleration
    [rad/s^2], wheel_feedforward [-], wheel_feedforward_acceleration [rad/s^2]} of the MCU's motor
    keys ``motor`` (those of DEPENDS_ON; the module's equations, model_key()). Raises ValueError naming the
    key when one is missing, negative or not finite, when load_observer_inertia, max_torque or
    speed_kp is not > 0 (a loop without a proportional path has no lag of its own to model), or when
    the feed-forward's bound reaches A_w (the model needs a proportional path beyond it)."""
    keys = {key: model_key(motor, key) for key in DEPENDS_ON}
    if keys["wheel_feedforward_acceleration"] >= keys["wheel_acceleration"]:
        raise ValueError("wheel loop model: the feed-forward's bound %.4g rad/s^2 (motor.accel_feedforward_limit) "
                         "reaches the loop's A_w %.4g rad/s^2: no proportional path beyond it (motor.proportional_limit, "
                         "motor.max_torque)" % (keys["wheel_feedforward_acceleration"], keys["wheel_acceleration"]))
    return keys
