"""plant_identify.py --bag: identify a robot's wheel loop from its bag (the fit:
jackal_aic_tools.identify.bag_identification), print the fit and write the overlay YAML of the keys that
differ from the plant's; and measure the robot model's sensor noises on the bag's rest segments
(jackal_aic_tools.identify.sensor_noise) and fit its yaw response on the bag's turns in place
(jackal_aic_tools.identify.yaw_response), and write them, with the robot model's wheel loop of the
identified motor keys (jackal_aic_tools.common.wheel_loop_model), as the robot model's controller
overlay (over config/default.yaml, whose belief model is the robot model)."""
import json
import os
import sys

import numpy as np

from ..common import wheel_loop_model
from . import bag_identification, identify, sensor_noise, yaw_response

# Comments of the overlay keys --bag writes (unit, meaning).
OVERLAY_COMMENTS = {
    "speed_kp": "proportional gain [N m / (rad/s)]",
    "proportional_limit": "clamp of the proportional path [N m]",
    "speed_ki": "integral gain [N m / rad]",
    "load_observer_time_constant": "load-torque observer's filter [s] (0 = no observer)",
    "command_delay": "lumped latency /cmd_drive -> MCU [s]",
}


def overlay_values(values):
    """motor key -> value of fitted values (the observer's bandwidth as its time constant)."""
    out = {}
    for s in bag_identification.motor_sets(values):
        key, value = s.split("=", 1)
        out[key.split(".", 1)[1]] = float(value)
    return out


def _streams(poor, form):
    """The streams of ``poor`` ({stream: share}) as a list for a message, each by ``form`` % (its
    label, its share in %)."""
    return ", ".join(form % (bag_identification.STREAMS[k], 100.0 * v) for k, v in poor.items())


def poor_fit_comment(poor):
    """The overlays' comment line naming the streams ``poor`` ({stream: share},
    bag_identification.poorly_reproduced()) the identified plant reproduces poorly; None when empty."""
    if not poor:
        return None
    return "# Poorly reproduced by the fit (RMS error / the stream's RMS above %g %%): %s." % (
        100.0 * bag_identification.POOR_FIT_SHARE, _streams(poor, "%s %.1f %%"))


def describe_poor_fit(poor):
    """The warning for the streams ``poor`` ({stream: share}, bag_identification.poorly_reproduced(),
    not empty) the identified plant does not reproduce: what differs and what to do."""
    return ("plant_identify: warning: the identified plant reproduces the bag's %s poorly (RMS error above "
            "%g %% of the stream's RMS): something the fit does not search differs (the floor's friction, a "
            "payload's mass or position, the MCU's feed-forwards or the integral's error clamp; give those known "
            "with --overlay and identify again). The overlays written from this fit are doubtful: compare the "
            "robot model's with config/default.yaml in simulation (aic_compare.py, doc/tuning.md) before the robot."
            % (_streams(poor, "%s (%.1f %%)"), 100.0 * bag_identification.POOR_FIT_SHARE))


def write_overlay(path, values, base, bag, cost, poor=None):
    """Write the identified motor values that differ from ``base`` (the plant YAML's motor section)
    as an overlay YAML, commented key by key, with a comment naming the streams the fit reproduces
    poorly (``poor``, bag_identification.poorly_reproduced(); None or empty: none); returns the keys
    written. Raises OSError if ``path`` cannot be written."""
    keys = [k for k, v in values.items()
            if k not in base or abs(v - base[k]) > 1e-3 * max(abs(base[k]), 1e-6)]
    with open(path, "w") as f:
        f.write("# Wheel loop identified by plant_identify.py --bag from %s (replay cost %.4f).\n"
                "# Overlay of sim/config/plant.yaml: only the keys that differ. Use it with --overlay FILE\n"
                "# (closed_loop_run, plant_fit, plant_calibrate, plant_replay) or the launch argument\n"
                "# plant_overlay (sim.launch, plant.launch).\n" % (os.path.basename(bag), cost))
        if poor:
            f.write(poor_fit_comment(poor) + "\n")
        if keys:
            f.write("motor:\n")
            for k in keys:
                f.write("  %s: %.4g  # %s\n" % (k, values[k], OVERLAY_COMMENTS.get(k, "")))
        else:
            f.write("{}  # the bag's wheel loop is the plant's\n")
    return keys


#: [rad/s^0.5] The robot model's turn-shortfall drift (turn_shortfall_noise, a named filter gain;
#: doc/active_inference.md, 'The robot model') for a wheel loop that leaves a turn's load as a speed
#: error: the value the turn-deficit firmware's tracking was measured with.
TURN_SHORTFALL_NOISE = 0.3


def turn_load_lines(values):
    """Controller-overlay lines that switch the robot model's turn shortfalls on (turn_shortfall_noise
    TURN_SHORTFALL_NOISE) when the identified wheel loop ``values`` (fit_bag()'s fitted values) is
    proportional only: no load observer (load_observer_bandwidth below
    bag_identification.OBSERVER_OFF_BANDWIDTH) and no integral path (speed_ki below
    bag_identification.INTEGRAL_OFF_GAIN). Such a loop leaves a turn's scrub load as a steady speed
    error for the turn, the same at each turn, as the turn-deficit firmware does; the turn shortfalls
    learn it and carry it, with the turn's sign, into the next (doc/active_inference.md, 'The robot
    model'). An integral path winds a turn's load up within the turn, so the error is a transient
    that the carried shortfall mistakes for a deficit (on the slow break-away firmware they cost its
    tracking 13 %: doc/robot_data.md). Returns [] otherwise, or when either was not fitted."""
    if bag_identification.load_compensation(values) != "none":
        return []
    bandwidth, ki = values["load_observer_bandwidth"], values["speed_ki"]
    return ["# [rad/s^0.5] q_e: the identified wheel loop is proportional only (no load observer: bandwidth",
            "# %.3g 1/s; no integral path: speed_ki %.3g N m/rad), so a turn's scrub load stays a speed error:"
            % (bandwidth, ki),
            "# the turn shortfalls learn it.",
            "turn_shortfall_noise: %.4g" % TURN_SHORTFALL_NOISE]


def compensation_lines(motor, values):
    """Controller-overlay lines of the robot model's shortfall_compensation_limit e_c
    (common.wheel_loop_model.compensation_limit() of the identified wheel loop ``motor``: the plant's
    motor keys with the bag's fitted values, overlay_values()) when that loop (``values``: fit_bag()'s
    fitted values) has an integral path (speed_ki at least bag_identification.INTEGRAL_OFF_GAIN) and
    no load observer (load_observer_bandwidth below bag_identification.OBSERVER_OFF_BANDWIDTH): its
    proportional path saturates at e_c of speed error and the integral path takes a larger load up
    over seconds, so a command raised beyond e_c winds that integral up for an overshoot (the slow
    break-away firmware, doc/active_inference.md, 'The robot model'). Returns [] otherwise, or when
    either was not fitted. Raises ValueError (compensation_limit()) when a motor key it needs is
    missing or invalid."""
    if bag_identification.load_compensation(values) != "integral":
        return []
    bandwidth, ki = values["load_observer_bandwidth"], values["speed_ki"]
    limit = wheel_loop_model.compensation_limit(motor)
    return ["# [rad/s] e_c: the identified wheel loop has an integral path (speed_ki %.3g N m/rad) and no load"
            % ki,
            "# observer (bandwidth %.3g 1/s): the action makes a shortfall up only to where its proportional" % bandwidth,
            "# path saturates, %s = %.4g / %.4g." % (wheel_loop_model.COMPENSATION_EQUATION,
                                                     float(motor["proportional_limit"]), float(motor["speed_kp"])),
            "shortfall_compensation_limit: %.4g" % limit]


#: [-] A robot-model key the bag's fit moved by less than this share of config/default.yaml's value
#: (the plant's identified loop) is left out of the overlay: the default already holds it.
WHEEL_LOOP_UNCHANGED = 0.01
#: The robot model's wheel-loop keys a bag identifies (common.wheel_loop_model), with their meaning
#: for the comment: the latency, and T_w, the fitted proportional gain's lag, where the
#: identified loop has no load observer. With an observer the proportional gain acts on small errors
#: only and a bag hardly constrains it (a bag of the default plant identified from slow_breakaway.yaml:
#: speed_kp 1.952 against 10.38; its T_w took the 0.5 m/s step's overshoot from 0.4 to 2.0 %), so
#: T_w stays the default's. A_w is not among them: of its three torques the fit searches only the
#: proportional clamp, which a proportional-only loop's bag hardly constrains, and the feed-forward's
#: bound and the current limit stay the plant's (on the slow break-away's bag, A_w 45.87 against its
#: 42.87 cost its tracking 6.5 %). doc/robot_data.md has the measurements.
WHEEL_LOOP_KEYS = {
    "latency": "[s] L, the command's latency to the wheels",
    "wheel_time_constant": "[s] T_w, the wheel loop's proportional lag",
}


def wheel_loop_lines(motor, fitted, base):
    """Controller-overlay lines of the robot model's wheel loop (WHEEL_LOOP_KEYS, by
    common.wheel_loop_model.model_key) on the identified wheel loop ``motor`` (the plant's motor keys
    with the bag's fitted values, overlay_values()), for the keys that depend on a fitted motor key
    (``fitted``: fit_bag()'s fitted values by name) and differ by more than WHEEL_LOOP_UNCHANGED from
    those of ``base`` (the plant's motor keys the fit started from: sim/config/plant.yaml's model is
    config/default.yaml's); T_w only where the fitted loop has no load observer (its
    load_observer_bandwidth fitted and below bag_identification.OBSERVER_OFF_BANDWIDTH). Each is
    commented with its equation and the motor values. Returns [] when none is written. Raises
    ValueError (model_key) when a motor key it needs is missing or invalid."""
    lines = []
    for key, meaning in WHEEL_LOOP_KEYS.items():
        if key == "wheel_time_constant" and bag_identification.has_observer(fitted) is not False:
            continue
        value = wheel_loop_model.model_key(motor, key)
        ref = wheel_loop_model.model_key(base, key)
        sources = wheel_loop_model.DEPENDS_ON[key]
        moved = [k for k in sources if k in fitted]
        if not moved or abs(value - ref) <= WHEEL_LOOP_UNCHANGED * abs(ref):
            continue
        lines += ["# %s: %s" % (meaning, wheel_loop_model.EQUATIONS[key]),
                  "#   = f(%s); identified on the bag: %s" % (
                      ", ".join("%s %.4g" % (k, float(motor[k])) for k in sources), ", ".join(moved)),
                  "%s: %.4g" % (key, value)]
    return lines


def describe_wheel_loop(lines, fitted):
    """One line for the log: the keys of wheel_loop_lines()'s ``lines`` with their values, or why
    none is written (``fitted``: fit_bag()'s fitted values by name)."""
    written = [line for line in lines if not line.startswith("#")]
    if written:
        return ", ".join(written)
    observer = bag_identification.has_observer(fitted) is not False
    return "config/default.yaml's (L within %g %%%s)" % (
        100 * WHEEL_LOOP_UNCHANGED, "; T_w is identified only on a loop without load observer" if observer else "")


def write_robot_model(path, noise, yaw, bag, turn_load=(), wheel_loop=(), poor=None, compensation=()):
    """Write what ``bag`` identified of the robot model as one controller overlay at ``path``: the
    bag's sensor noises (``noise``, sensor_noise(); None: not measured), yaw response (``yaw``,
    yaw_response(); None: not fitted), the turn shortfalls' switch (``turn_load``,
    turn_load_lines()) and the wheel loop's keys (``wheel_loop``, wheel_loop_lines()), each
    commented with its source, the shortfall compensation's bound (``compensation``,
    compensation_lines()), and the streams the wheel loop's fit reproduces poorly (``poor``,
    poor_fit_comment()). Load it alone after config/default.yaml,
    whose belief model is the robot model (the launch files' one overlay). Returns the keys the bag
    gave (an empty list writes a file of comments only). Raises OSError if ``path`` cannot be
    written."""
    lines = (sensor_noise.overlay_lines(noise) if noise is not None else []) + (
        yaw_response.overlay_lines(yaw) if yaw is not None else []) + list(turn_load) + list(compensation) + \
        list(wheel_loop)
    keys = [line.split(":", 1)[0] for line in lines if not line.startswith("#")]
    with open(path, "w") as f:
        f.write("# The robot model's keys identified on %s by plant_identify.py --bag, over\n"
                "# config/default.yaml. Load it as the one controller overlay, e.g.\n"
                "#   roslaunch jackal_aic robot.launch overlay:=%s\n\n# ---- measured on %s\n"
                % (bag, os.path.abspath(path), bag))
        if poor:
            f.write(poor_fit_comment(poor) + "\n")
        f.write("\n".join(lines) + "\n")
    return keys


def robot_model_part(name, verb, measure, describe):
    """Print and return one part of the robot model measured on the bag: measure() (its result) and
    describe(result) (a line); a ValueError from measure() is printed as "not <verb>: <reason>" and
    the part is None."""
    try:
        result = measure()
    except ValueError as e:
        print("  the robot model's %s: not %s: %s" % (name, verb, e))
        return None
    print("  the robot model's %s: %s" % (name, describe(result)))
    return result


def run(a, tool):
    """The --bag mode of plant_identify.py (a: its parsed arguments, tool: cli.Tool): read the bag,
    fit BAG_PARAMETERS by replaying it on the plant, print the fit table and the turn deficits,
    write the overlay, the robot model's controller overlay with the bag's sensor noises and yaw
    response (a.model_out; a part the bag cannot give is left out, with the reason printed) and
    a.json. Returns the exit status."""
    keys = list(a.fit) if a.fit else list(bag_identification.BAG_PARAMETERS)
    unknown = [k for k in keys if k not in bag_identification.BAG_PARAMETERS]
    if unknown:
        print("plant_identify: --bag fits %s, not %s" % (", ".join(bag_identification.BAG_PARAMETERS),
                                                         ", ".join(unknown)), file=sys.stderr)
        return 2
    plant_replay = a.plant_replay or tool.exe("plant_replay")
    try:
        data = bag_identification.read_bag(a.bag)
    except ValueError as e:
        print("plant_identify: %s" % e, file=sys.stderr)
        return 1
    base = identify.read_motor(a.config, a.overlay)
    sys.stdout.reconfigure(line_buffering=True)
    print("plant_identify: bag %s, %.1f s, %d commands (%s), %d joint states, %d IMU samples%s"
          % (a.bag, data.duration, len(data.cmd), "cmd_vel through the stock mapping" if data.cmd_is_twist else
             "/cmd_drive", len(data.wheels), len(data.gyro),
             ", %d /feedback" % len(data.feedback) if data.feedback is not None else ", no /feedback"))
    if data.feedback is not None and not np.any(data.feedback[:, 1:]):
        print("  /feedback carries no measured_velocity (all zero): not compared")
    elif data.feedback is not None:
        fb_l = np.interp(data.wheels[:, 0], data.feedback[:, 0], data.feedback[:, 1])
        fb_r = np.interp(data.wheels[:, 0], data.feedback[:, 0], data.feedback[:, 2])
        diff = np.sqrt(np.mean(np.concatenate([fb_l - data.wheels[:, 1], fb_r - data.wheels[:, 2]]) ** 2))
        print("  /feedback measured_velocity vs /joint_states: RMS difference %.3f rad/s" % diff)
    noise = robot_model_part("sensor noises", "measured", lambda: sensor_noise.sensor_noise(data),
                             lambda n: "encoder_noise %.4g rad/s (%d samples, %s), gyro_noise %.4g rad/s (%d samples, "
                                       "rest)" % (n["encoder_noise"], n["encoder_samples"], n["encoder_source"],
                                                  n["gyro_noise"], n["gyro_samples"]))
    yaw = robot_model_part("yaw response", "fitted", lambda: yaw_response.yaw_response(data),
                           lambda y: "yaw_time_constant %.4g s, wheel_separation %.4g m (%d turns in place, %d gyro "
                                     "samples, residual %.4f rad/s)" % (y["yaw_time_constant"], y["wheel_separation"],
                                                                        y["turns"], y["samples"], y["residual_rms"]))
    print("  fitting %s on the plant %s%s" % (", ".join(keys), a.config,
                                              "".join(" + " + o for o in a.overlay)))
    try:
        r = bag_identification.fit_bag(data, plant_replay, base, keys, a.config, a.overlay, a.jobs, a.max_evals,
                                       a.starts, a.samples, a.seed, log=lambda m: print(m, flush=True))
    except RuntimeError as e:
        print("plant_identify: %s" % e, file=sys.stderr)
        return 1
    print("\n%-24s | %10s | %10s" % ("parameter", "plant", "identified"))
    for k in keys:
        print("%-24s | %10.4g | %10.4g%s" % (k, r["start"][k], r["values"][k],
                                             "  (turning)" if k in bag_identification.TURNING else ""))
    print("\n%-24s | %10s | %10s | %10s | %16s" % ("stream (RMS error)", "plant", "identified", "bag's RMS",
                                                   "identified / RMS"))
    shares = bag_identification.stream_shares(r["errors"])
    for name, label in bag_identification.STREAMS.items():
        print("%-24s | %10.4f | %10.4f | %10.4f | %14.1f %%" % (label + " [rad/s]", r["start_errors"][name],
                                                              r["errors"][name], r["errors"][name + "_rms"],
                                                              100.0 * shares[name]))
    print("%-24s | %10.4f | %10.4f |" % ("cost", r["start_cost"], r["cost"]))
    poor = bag_identification.poorly_reproduced(r["errors"])
    if poor:
        print(describe_poor_fit(poor), file=sys.stderr)
    cmd = data.cmd if not data.cmd_is_twist else None
    deficits = {}
    if cmd is not None:
        deficits["bag"] = bag_identification.turn_deficits(data.gyro[:, 0], data.gyro[:, 1], cmd)
        for key in ("start_replay", "replay"):
            sim = r[key]
            deficits[key] = bag_identification.turn_deficits(sim["t"], sim["gyro_z"], cmd)
        if deficits["bag"]:
            print("\nsteady turns in place: commanded yaw rate -> deficit (commanded - gyro) [rad/s]")
            print("%-10s | %8s | %8s | %10s" % ("command", "bag", "plant", "identified"))
            for i, (w, d) in enumerate(deficits["bag"]):
                print("%-10.2f | %8.3f | %8.3f | %10.3f" % (w, d, deficits["start_replay"][i][1], deficits["replay"][i][1]))
    out = a.overlay_out or os.path.splitext(a.bag)[0] + "_wheel_loop.yaml"
    written = write_overlay(out, overlay_values(r["values"]), base, a.bag, r["cost"], poor)
    print("\noverlay written: %s (%s)" % (out, ", ".join("motor." + k for k in written) or "no key differs"))
    model_out = None
    turn_load = turn_load_lines(r["values"])
    identified = dict(base, **overlay_values(r["values"]))
    compensation = robot_model_part(
        "shortfall compensation", "derived", lambda: compensation_lines(identified, r["values"]),
        lambda lines: ", ".join(line for line in lines if not line.startswith("#")) or
        "unbounded (a load observer, or no integral path)") or []
    wheel_loop = robot_model_part("wheel loop", "derived", lambda: wheel_loop_lines(identified, r["values"], base),
                                  lambda lines: describe_wheel_loop(lines, r["values"])) or []
    if noise is not None or yaw is not None or turn_load or wheel_loop or compensation:
        model_out = a.model_out or os.path.splitext(a.bag)[0] + "_robot_model.yaml"
        try:
            measured = write_robot_model(model_out, noise, yaw, os.path.basename(a.bag), turn_load, wheel_loop, poor,
                                         compensation)
        except OSError as e:
            print("plant_identify: the robot model's overlay: %s" % e, file=sys.stderr)
            return 1
        print("robot model written: %s (controller overlay over config/default.yaml: %s)"
              % (model_out, ", ".join(measured)))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"bag": a.bag, "duration": data.duration, "keys": keys, "start": r["start"],
                       "values": r["values"], "start_cost": r["start_cost"], "cost": r["cost"],
                       "start_errors": r["start_errors"], "errors": r["errors"], "evaluations": r["evaluations"],
                       "stream_shares": shares, "poorly_reproduced": poor,
                       "deficits": deficits, "overlay": out, "sensor_noise": noise, "yaw_response": yaw,
                       "robot_model": model_out},
                      f, indent=1)
    return 0
