#!/usr/bin/env python3
"""plant_identify.py: identify the simulated Jackal's MCU wheel loop from the robot's step responses.

Fits the `motor:` parameters of sim/config/plant.yaml so that the ODE plant reproduces, at
once, the stock controller's steps (thesis table 3-1b) and the thesis-equivalent active
inference controller's steps (tables 3-1a, 5-1, 5-2), all listed in
sim/config/robot_steps.yaml. Each candidate is scored by `plant_fit --json` (the C++ tool
that runs every row on the plant core, headless and faster than real time); the search is
scipy.optimize's bounded Nelder-Mead, from several starts in parallel, in a normalised
(log for gains, linear for times) parameter space. The identified values are written into
the plant YAML in place (comments kept) with `--write`; nothing is typed in by hand.
Afterwards `plant_fit` prints the fit table and `plant_calibrate --check` the top-speed and
turning checks. doc/robot_data.md explains the model and the result.

Usage:
  plant_identify.py [--config sim/config/plant.yaml] [--fit KEY ...] [--samples N] [--starts N]
                    [--jobs N] [--max-evals N] [--seed S] [--write] [--plant-fit PATH]

Exit status: 0 on success (the fit is written only with --write), 1 if plant_fit fails.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy.optimize import minimize

from jackal_aic_tools import cli

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
}
# The model the identification settled on (doc/robot_data.md): a PI speed servo whose high-gain
# proportional path saturates, a slow integral path, a voltage (set-point) feedforward acting
# through back-EMF, an acceleration feedforward of the command, drivetrain friction and latency.
DEFAULT_FIT = ["speed_kp", "proportional_limit", "setpoint_feedforward", "speed_ki", "accel_feedforward",
               "command_delay", "coulomb_friction", "setpoint_time_constant", "integral_error_limit"]
# Held at these values unless fitted: the elements the data do not need (0 = off).
DEFAULT_FIXED = {"setpoint_slew_rate": 0.0, "integral_limit": 0.0}


def repo_root():
    return cli.source_root(__file__)


def find_plant_fit(explicit):
    return explicit or cli.find_executable("plant_fit", __file__, "plant_identify")


def to_value(key, u):
    lo, hi, scale = PARAMETERS[key]
    u = min(max(u, 0.0), 1.0)
    if scale == "log":
        return math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo)))
    return lo + u * (hi - lo)


def to_unit(key, v):
    lo, hi, scale = PARAMETERS[key]
    v = min(max(v, lo), hi)
    if scale == "log":
        return (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo))
    return (v - lo) / (hi - lo)


def read_motor(path):
    """The motor section's key: value pairs of a plant YAML (values as floats)."""
    import yaml
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    return {k: float(v) for k, v in (doc.get("motor") or {}).items() if isinstance(v, (int, float))}


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
    history = []

    def cost(u):
        # The search space is the unit box: Nelder-Mead's own bounds= needs scipy >= 1.7
        # (Ubuntu 20.04 has 1.3), so a vertex outside the box is evaluated at its projection.
        u = np.clip(u, 0.0, 1.0)
        values = dict(fixed)
        values.update({k: to_value(k, x) for k, x in zip(keys, u)})
        c, _ = evaluate((plant_fit, config, values, extra))
        history.append(c)
        if len(history) % 25 == 0:
            print("  search %d: %d evaluations, best cost %.4f" % (index, len(history), min(history)), flush=True)
        return c

    x0 = np.array(start)
    simplex = [x0]
    for i in range(len(keys)):  # an initial simplex of 15 % of each range, pointing inwards
        x = x0.copy()
        x[i] = x[i] + 0.15 if x[i] < 0.5 else x[i] - 0.15
        simplex.append(x)
    res = minimize(cost, x0, method="Nelder-Mead",
                   options={"maxfev": max_evals, "xatol": 1e-3, "fatol": 1e-4, "initial_simplex": np.array(simplex)})
    values = {k: to_value(k, x) for k, x in zip(keys, np.clip(res.x, 0.0, 1.0))}
    return float(res.fun), values, len(history)


def write_motor(path, values, note):
    """Replace the values of `values`' keys in the motor section of the YAML at path, keeping comments."""
    with open(path) as f:
        lines = f.readlines()
    in_motor = False
    done = set()
    for i, line in enumerate(lines):
        if re.match(r"^\S", line):
            in_motor = line.startswith("motor:")
            continue
        m = re.match(r"^(\s+)([a-z_]+):(\s*)([^#\n]*?)(\s*)(#.*)?$", line.rstrip("\n"))
        if in_motor and m and m.group(2) in values:
            key = m.group(2)
            new = "%.4g" % values[key]
            comment = m.group(6) or ""
            width = len(m.group(4)) + len(m.group(5))
            pad = " " * max(1, width - len(new))
            lines[i] = "%s%s:%s%s%s%s\n" % (m.group(1), key, m.group(3) or " ", new, pad if comment else "", comment)
            done.add(key)
        if in_motor and line.lstrip().startswith("# identified by plant_identify"):
            lines[i] = re.sub(r"# identified by plant_identify.*", "# identified by plant_identify: " + note,
                              line.rstrip("\n")) + "\n"
    missing = set(values) - done
    if missing:
        sys.exit("plant_identify: keys missing from %s's motor section: %s" % (path, ", ".join(sorted(missing))))
    with open(path, "w") as f:
        f.writelines(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default=os.path.join(repo_root(), "sim", "config", "plant.yaml"))
    ap.add_argument("--fit", nargs="+", default=DEFAULT_FIT, choices=sorted(PARAMETERS),
                    help="motor parameters to identify (others keep the YAML's values)")
    ap.add_argument("--starts", type=int, default=2, help="Nelder-Mead searches, from the best candidates")
    ap.add_argument("--jobs", type=int, default=2, help="parallel searches")
    ap.add_argument("--max-evals", type=int, default=150, help="evaluations per search")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="write the identified values into --config")
    ap.add_argument("--plant-fit", default=None, help="path of the plant_fit executable")
    ap.add_argument("--samples", type=int, default=40,
                    help="random candidates scored before the searches; the best start them")
    a = ap.parse_args()

    plant_fit = find_plant_fit(a.plant_fit)
    keys = list(a.fit)
    fixed = {k: v for k, v in DEFAULT_FIXED.items() if k not in keys}
    current = read_motor(a.config)
    rng = np.random.default_rng(a.seed)
    base_cost, _ = evaluate((plant_fit, a.config, {}, []))
    print("plant_identify: %s, fitting %s; cost of the YAML as it is: %.4f" % (a.config, ", ".join(keys), base_cost))
    # Stage 1: the YAML's values and random candidates, scored in parallel; the best start the searches.
    units = [[to_unit(k, current.get(k, PARAMETERS[k][0])) for k in keys]]
    units += [list(rng.uniform(0.02, 0.98, len(keys))) for _ in range(max(0, a.samples))]
    cands = [dict(fixed, **{k: to_value(k, x) for k, x in zip(keys, u)}) for u in units]
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
        write_motor(a.config, best, note)
        print("written into %s" % a.config)
        subprocess.run([plant_fit, "--config", a.config], check=False)
    else:
        print("(not written; --write updates %s)" % a.config)
    return 0


if __name__ == "__main__":
    sys.exit(main())
