#!/usr/bin/env python3
"""plant_identify.py: identify the simulated Jackal's MCU wheel loop from the robot's step responses.

Fits the `motor:` parameters of sim/config/plant.yaml so that the ODE plant reproduces, at
once, the stock controller's steps (thesis table 3-1b) and the thesis-equivalent active
inference controller's steps (tables 3-1a, 5-1, 5-2), all listed in
sim/config/robot_steps.yaml, while meeting the turning targets (a 1 rad/s turn in place and a
0.5 m/s + 0.5 rad/s arc within the time scale of a straight step; no robot yaw data exist, the
targets are the assumption of doc/robot_data.md, 'Turning'). Each candidate is scored by `plant_fit --json` (the C++ tool
that runs every row on the plant core, headless and faster than real time); the search is
scipy.optimize's bounded Nelder-Mead, from several starts in parallel, in a normalised
(log for gains, linear for times) parameter space. The identified values are written into
the plant YAML in place (comments kept) with `--write`; nothing is typed in by hand.
Afterwards `plant_fit` prints the fit table and `plant_calibrate --check` the top-speed and
turning checks. doc/robot_data.md explains the model and the result.

With --bag FILE it identifies the wheel loop of the robot that recorded the bag instead
(jackal_aic_tools.bag_identification; record one with scripts/record_identification.py): the
bag's /cmd_drive stream (or the stock diff drive's cmd_vel) is replayed on the plant
(plant_replay) and the straight and turning parameters of the motor section (BAG_PARAMETERS:
speed_kp, proportional_limit, speed_ki, the load observer's bandwidth, command_delay) are fitted
to the bag's /joint_states wheel speeds and /imu/data yaw rate; /feedback, when present, is
compared with /joint_states. It prints the fit table (each parameter from the plant's value to
the identified one, each stream's RMS error before and after, the steady turn-in-place deficits
of the bag and of the identified plant) and writes an overlay YAML of the keys that differ from
--config (--overlay-out; default: next to the bag, <bag>_wheel_loop.yaml).

Usage:
  plant_identify.py [--config sim/config/plant.yaml] [--fit KEY ...] [--samples N] [--starts N]
                    [--jobs N] [--max-evals N] [--seed S] [--write] [--plant-fit PATH]
  plant_identify.py --bag FILE [--config PLANT.yaml] [--overlay FILE]... [--fit KEY ...]
                    [--starts N] [--jobs N] [--max-evals N] [--overlay-out FILE] [--json FILE]
                    [--plant-replay PATH]

Exit status: 0 on success (the fit is written only with --write), 1 if plant_fit fails or the bag
cannot be used (the message says why), 2 on bad arguments.
"""
import argparse
import json
import os
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from jackal_aic_tools import bag_identification, cli, identify

# Identified parameters: key -> (lower, upper, scale). "log": searched on log(value).
PARAMETERS = {
    "speed_kp": (0.5, 20.0, "log"),             # N m / (rad/s)
    "proportional_limit": (0.3, 3.0, "lin"),    # N m
    "setpoint_feedforward": (0.0, 0.5, "lin"),  # N m / (rad/s)
    "speed_ki": (0.05, 50.0, "log"),            # N m / rad
    "accel_feedforward": (0.0, 0.15, "lin"),    # N m s^2 / rad
    "command_delay": (0.02, 0.15, "lin"),       # s
    "coulomb_friction": (0.0, 0.3, "lin"),      # N m per wheel
    "integral_limit": (1.0, 4.0, "lin"),        # N m
    "integral_error_limit": (0.2, 5.0, "log"),  # rad/s
    "setpoint_time_constant": (0.0, 0.2, "lin"),  # s
    "max_torque": (3.5, 8.0, "lin"),            # N m (>= 3.5: the robot turns in place)
    "setpoint_slew_rate": (5.0, 60.0, "log"),   # rad/s^2
    "load_observer_time_constant": (0.005, 0.3, "log"),  # s
}
# The model the identification settled on (doc/robot_data.md): a PI speed servo whose high-gain
# proportional path saturates, an integral path, a voltage (set-point) feedforward acting
# through back-EMF, an acceleration feedforward of the command, a load-torque observer (the
# turning targets), drivetrain friction and latency.
DEFAULT_FIT = ["speed_kp", "proportional_limit", "setpoint_feedforward", "speed_ki", "accel_feedforward",
               "command_delay", "coulomb_friction", "setpoint_time_constant", "integral_error_limit",
               "load_observer_time_constant"]
# Held at these values unless fitted: the elements the data do not need (0 = off).
DEFAULT_FIXED = {"setpoint_slew_rate": 0.0, "integral_limit": 0.0}


SPACE = identify.Space(PARAMETERS)


def repo_root():
    return cli.source_root(__file__)


def find_plant_fit(explicit):
    return explicit or cli.find_executable("plant_fit", __file__, "plant_identify")


def evaluate(args):
    """Cost of one candidate (a dict key -> value); returns (cost, report dict)."""
    plant_fit, config, values, extra = args
    cmd = [plant_fit, "--config", config, "--json"] + extra
    for k, v in values.items():
        cmd += ["--set", "motor.%s=%.6g" % (k, v)]
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        return float("inf"), {"error": out.stderr.strip()}
    report = json.loads(out.stdout)
    return float(report["cost"]), report


def search(args):
    """One bounded Nelder-Mead search from a start point (unit coordinates)."""
    plant_fit, config, keys, fixed, start, max_evals, extra, index = args

    def cost(u):
        values = dict(fixed)
        values.update(SPACE.values(keys, u))
        return evaluate((plant_fit, config, values, extra))[0]

    def progress(n, best):
        print("  search %d: %d evaluations, best cost %.4f" % (index, n, best), flush=True)

    best, u, n = identify.nelder_mead(cost, start, max_evals, progress)
    return best, SPACE.values(keys, u), n


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


def write_overlay(path, values, base, bag, cost):
    """Write the identified motor values that differ from ``base`` (the plant YAML's motor section)
    as an overlay YAML, commented key by key; returns the keys written."""
    keys = [k for k, v in values.items()
            if k not in base or abs(v - base[k]) > 1e-3 * max(abs(base[k]), 1e-6)]
    with open(path, "w") as f:
        f.write("# Wheel loop identified by plant_identify.py --bag from %s (replay cost %.4f).\n"
                "# Overlay of sim/config/plant.yaml: only the keys that differ. Use it with --overlay FILE\n"
                "# (closed_loop_run, plant_fit, plant_calibrate, plant_replay) or the launch argument\n"
                "# plant_overlay (sim.launch, plant.launch).\n" % (os.path.basename(bag), cost))
        if keys:
            f.write("motor:\n")
            for k in keys:
                f.write("  %s: %.4g  # %s\n" % (k, values[k], OVERLAY_COMMENTS.get(k, "")))
        else:
            f.write("{}  # the bag's wheel loop is the plant's\n")
    return keys


def identify_bag(a):
    """The --bag mode (see the module's docstring); returns the exit status."""
    keys = list(a.fit) if a.fit else list(bag_identification.BAG_PARAMETERS)
    unknown = [k for k in keys if k not in bag_identification.BAG_PARAMETERS]
    if unknown:
        print("plant_identify: --bag fits %s, not %s" % (", ".join(bag_identification.BAG_PARAMETERS),
                                                         ", ".join(unknown)), file=sys.stderr)
        return 2
    plant_replay = a.plant_replay or cli.find_executable("plant_replay", __file__, "plant_identify")
    try:
        data = bag_identification.read_bag(a.bag)
    except ValueError as e:
        print("plant_identify: %s" % e, file=sys.stderr)
        return 1
    base = identify.read_motor(a.config)
    for o in a.overlay:
        import yaml
        with open(o) as f:
            base.update({k: float(v) for k, v in ((yaml.safe_load(f) or {}).get("motor") or {}).items()})
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
    print("\n%-24s | %10s | %10s | %10s" % ("stream (RMS error)", "plant", "identified", "bag's RMS"))
    for name, label in (("left", "left wheels [rad/s]"), ("right", "right wheels [rad/s]"), ("yaw", "gyro yaw [rad/s]")):
        print("%-24s | %10.4f | %10.4f | %10.4f" % (label, r["start_errors"][name], r["errors"][name],
                                                   r["errors"][name + "_rms"]))
    print("%-24s | %10.4f | %10.4f |" % ("cost", r["start_cost"], r["cost"]))
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
    written = write_overlay(out, overlay_values(r["values"]), base, a.bag, r["cost"])
    print("\noverlay written: %s (%s)" % (out, ", ".join("motor." + k for k in written) or "no key differs"))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"bag": a.bag, "duration": data.duration, "keys": keys, "start": r["start"],
                       "values": r["values"], "start_cost": r["start_cost"], "cost": r["cost"],
                       "start_errors": r["start_errors"], "errors": r["errors"], "evaluations": r["evaluations"],
                       "deficits": deficits, "overlay": out}, f, indent=1)
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=os.path.join(repo_root(), "sim", "config", "plant.yaml"))
    ap.add_argument("--fit", nargs="+", default=None,
                    choices=sorted(set(PARAMETERS) | set(bag_identification.BAG_PARAMETERS)),
                    help="motor parameters to identify (others keep the YAML's values); default: %s; with "
                         "--bag: %s" % (", ".join(DEFAULT_FIT), ", ".join(bag_identification.BAG_PARAMETERS)))
    ap.add_argument("--starts", type=int, default=2, help="Nelder-Mead searches, from the best candidates")
    ap.add_argument("--jobs", type=int, default=2, help="parallel searches")
    ap.add_argument("--max-evals", type=int, default=150, help="evaluations per search")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="write the identified values into --config")
    ap.add_argument("--plant-fit", default=None, help="path of the plant_fit executable")
    ap.add_argument("--samples", type=int, default=40,
                    help="random candidates scored before the searches; the best start them")
    g = ap.add_argument_group("identification from a robot's bag")
    g.add_argument("--bag", help="the bag (see the module's docstring)")
    g.add_argument("--overlay", action="append", default=[],
                   help="plant overlay the fit starts from and keeps (e.g. the floor's), repeatable")
    g.add_argument("--overlay-out", help="the identified overlay (default: <bag>_wheel_loop.yaml)")
    g.add_argument("--json", help="also write the results as JSON")
    g.add_argument("--plant-replay", default=None, help="path of the plant_replay executable")
    a = ap.parse_args()
    if a.bag:
        return identify_bag(a)
    if a.overlay or a.overlay_out or a.json:
        ap.error("--overlay, --overlay-out and --json go with --bag")
    if a.fit and any(k not in PARAMETERS for k in a.fit):
        ap.error("without --bag --fit takes %s" % ", ".join(sorted(PARAMETERS)))

    plant_fit = find_plant_fit(a.plant_fit)
    keys = list(a.fit or DEFAULT_FIT)
    fixed = {k: v for k, v in DEFAULT_FIXED.items() if k not in keys}
    current = identify.read_motor(a.config)
    rng = np.random.default_rng(a.seed)
    base_cost, _ = evaluate((plant_fit, a.config, {}, []))
    print("plant_identify: %s, fitting %s; cost of the YAML as it is: %.4f" % (a.config, ", ".join(keys), base_cost))
    # Stage 1: the YAML's values and random candidates, scored in parallel; the best start the searches.
    units = [[SPACE.to_unit(k, current.get(k, PARAMETERS[k][0])) for k in keys]]
    units += [list(rng.uniform(0.02, 0.98, len(keys))) for _ in range(max(0, a.samples))]
    cands = [dict(fixed, **SPACE.values(keys, u)) for u in units]
    with ProcessPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        scored = list(pool.map(evaluate, [(plant_fit, a.config, c, []) for c in cands]))
    order = sorted(range(len(units)), key=lambda i: scored[i][0])
    print("  %d candidates scored; best %s" % (len(units), ", ".join("%.3f" % scored[i][0] for i in order[:5])))
    starts = [units[i] for i in order[:max(1, a.starts)]]
    sys.stdout.reconfigure(line_buffering=True)
    print("  %d Nelder-Mead searches of <= %d evaluations, %d in parallel (each evaluation: plant_fit --json)"
          % (len(starts), a.max_evals, a.jobs))
    jobs = [(plant_fit, a.config, keys, fixed, s, a.max_evals, [], i) for i, s in enumerate(starts)]
    with ProcessPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        results = list(pool.map(search, jobs))
    results.sort(key=lambda r: r[0])
    print("\n%-6s %-9s %-6s %s" % ("search", "cost", "evals", "values"))
    for i, (c, values, n) in enumerate(results):
        print("%-6d %-9.4f %-6d %s" % (i, c, n, ", ".join("%s=%.4g" % kv for kv in values.items())))
    best_cost, best, _ = results[0]
    best.update(fixed)
    print("\nbest: cost %.4f (was %.4f)" % (best_cost, base_cost))
    for k, v in best.items():
        print("  motor.%s: %.4g" % (k, v))
    if a.write:
        note = "cost %.4f, searched %s" % (best_cost, ", ".join(keys))
        try:
            identify.write_motor(a.config, best, note)
            # The file holds 4 significant digits: note the cost of what was written.
            written, _ = evaluate((plant_fit, a.config, {}, []))
            identify.write_motor(a.config, {}, "cost %.4f, searched %s" % (written, ", ".join(keys)))
        except ValueError as e:
            sys.exit("plant_identify: %s" % e)
        print("written into %s" % a.config)
        subprocess.run([plant_fit, "--config", a.config], check=False)
    else:
        print("(not written; --write updates %s)" % a.config)
    return 0


if __name__ == "__main__":
    sys.exit(main())
