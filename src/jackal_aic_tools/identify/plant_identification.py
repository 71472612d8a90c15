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
(jackal_aic_tools.identify.bag_identification; record one with scripts/record_identification.py): the
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
import json
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from . import identify

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


def run(a, plant_fit):
    """Identify the wheel loop from the robot's step responses (a: parsed arguments of
    plant_identify.py without --bag; plant_fit: the plant_fit executable): score random
    candidates, run the Nelder-Mead searches from the best, print the result and, with a.write,
    write it into a.config. Returns the exit status."""
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
