"""The AIC's inference as table columns: the names (units in brackets) and values of the
inference columns of `closed_loop_run --csv` (tools/src/closed_loop_run.cpp, inferenceCsvHeader),
read from the node's stamped jackal_aic/InferenceState messages (~inference, msg/InferenceState.msg),
so that the experiment's CSV (jackal_aic_tools.experiment.experiment.write_csv) and the headless
trace carry the same columns on one time base.

    cols = inference.columns(3)                  # ["F[-]", "F_sensory[-]", ..., "eps_mu2_theta_dot[rad/s^3]"]
    row = inference.values(msg)                  # floats in the order of columns(msg.orders)

test/test_exp_tools.py checks columns() against closed_loop_run's header.
"""

#: Belief channels (rows of mu and eps_mu) and the unit of their order 0.
BELIEF_CHANNELS = (("x_dot", "m/s"), ("y_dot", "m/s"), ("theta_dot", "rad/s"))
#: Sensor channels (rows of eps_y and precision_y, SensorIndex) and the unit of their order 0.
SENSOR_CHANNELS = (("gyro_z", "rad/s"), ("omega_L", "rad/s"), ("omega_R", "rad/s"), ("accel_x", "m/s^2"),
                   ("accel_y", "m/s^2"))
#: The free energy's columns: F and its sensory and prior sums (thesis eq. 3-10).
FREE_ENERGY = ("F[-]", "F_sensory[-]", "F_prior[-]")
#: The robot model's slow states (closed_loop_run's order): shortfalls d, turn shortfalls e, slip
#: ratio s, gyro offset beta; NaN (an empty cell) under the goal and unbiased models.
ROBOT_STATES = ("shortfall_L[rad/s]", "shortfall_R[rad/s]", "turn_shortfall_L[rad/s]", "turn_shortfall_R[rad/s]",
                "slip_ratio[-]", "gyro_offset_belief[rad/s]")
#: Columns the experiment adds after the inference columns (closed_loop_run has them as
#: "separation" and "gyro_offset" among its first columns).
LEARNED = ("wheel_separation[m]", "gyro_offset[rad/s]")


def order_unit(unit, i):
    """The unit of order ``i`` (>= 0) of a signal whose order 0 is in ``unit``: one "/s" more per
    order, e.g. order_unit("m/s", 2) == "m/s^3", order_unit("m", 1) == "m/s"
    (jackal_aic/aic/inference_sample.hpp, orderUnit)."""
    if i == 0:
        return unit
    base, slash, rest = unit.partition("/s")
    power = i
    if slash:
        power += int(rest[1:]) if rest.startswith("^") else 1
    return base + "/s" + ("" if power == 1 else "^%d" % power)


def columns(orders):
    """The inference column names for ``orders`` (= p + 1 >= 1) generalized orders, in
    closed_loop_run's order: F and its parts, the action a_L, a_R, its prior a_ff_L, a_ff_R, the
    attractor goal goal_*, the precisions Pi_y0_*, ROBOT_STATES, then per order i mu<i>_*,
    eps_y<i>_*, eps_mu<i>_*. Raises ValueError for orders < 1."""
    if orders < 1:
        raise ValueError("orders must be >= 1, not %r" % (orders,))
    out = list(FREE_ENERGY) + ["a_L[rad/s]", "a_R[rad/s]", "a_ff_L[rad/s]", "a_ff_R[rad/s]"]
    out += ["goal_%s[%s]" % (n, u) for n, u in BELIEF_CHANNELS]
    out += ["Pi_y0_%s[1/(%s)^2]" % (n, u) for n, u in SENSOR_CHANNELS]
    out += list(ROBOT_STATES)
    for i in range(orders):
        out += ["mu%d_%s[%s]" % (i, n, order_unit(u, i)) for n, u in BELIEF_CHANNELS]
        out += ["eps_y%d_%s[%s]" % (i, n, order_unit(u, i)) for n, u in SENSOR_CHANNELS]
        out += ["eps_mu%d_%s[%s]" % (i, n, order_unit(u, i + 1)) for n, u in BELIEF_CHANNELS]
    return out


#: The fields of jackal_aic/InferenceState that values() reads (msg/InferenceState.msg).
FIELDS = ("orders", "free_energy", "free_energy_sensory", "free_energy_prior", "action", "action_prior", "goal",
          "precision_y", "shortfall", "turn_shortfall", "slip_ratio", "gyro_offset_belief", "mu", "eps_y", "eps_mu",
          "wheel_separation", "gyro_offset")


def values(msg):
    """The values of one jackal_aic/InferenceState message in the order of columns(msg.orders)
    (its matrices are channel-major: element (c, i) at c * orders + i), then LEARNED's
    (b_hat [m], gyro offset [rad/s]). Raises ValueError if the message lacks one of FIELDS (a
    message of another definition, e.g. read from a bag another version of jackal_aic recorded:
    rosbag builds it from the definition stored in the bag) or if an array's length does not match
    msg.orders."""
    missing = [f for f in FIELDS if not hasattr(msg, f)]
    if missing:
        raise ValueError("InferenceState of another definition than msg/InferenceState.msg (md5sum %s): no %s"
                         % (getattr(msg, "_md5sum", "unknown"), ", ".join(missing)))
    n = int(msg.orders)
    for name, rows in (("mu", 3), ("eps_y", 5), ("eps_mu", 3)):
        if len(getattr(msg, name)) != rows * n:
            raise ValueError("InferenceState.%s has %d values, not %d x %d" % (name, len(getattr(msg, name)), rows, n))
    out = [msg.free_energy, msg.free_energy_sensory, msg.free_energy_prior]
    out += list(msg.action) + list(msg.action_prior) + list(msg.goal) + list(msg.precision_y)
    out += list(msg.shortfall) + list(msg.turn_shortfall) + [msg.slip_ratio, msg.gyro_offset_belief]
    for i in range(n):
        out += [msg.mu[c * n + i] for c in range(3)]
        out += [msg.eps_y[c * n + i] for c in range(5)]
        out += [msg.eps_mu[c * n + i] for c in range(3)]
    return [float(v) for v in out] + [float(msg.wheel_separation), float(msg.gyro_offset)]
