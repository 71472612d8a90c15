"""aic_tune.py --driving --controller pi: tune the classical peer's gains (config/classical/pi.yaml,
include/jackal_aic/classical/pi_controller.hpp) on the AIC's driving cost.

The same search and the same cost as the AIC's --driving tuning (tune_driving): a bounded
Nelder-Mead (scipy) on the unit box of PI_SPACE (log scale), scored by
jackal_aic_tools.track.driving.cost of driving.evaluate on the plant variants --driving-variants,
with the peer in the AIC's place against the stock controller (driving.Runner's ``tuned``). Prints
each improvement and writes the winner (--write): the base YAML with the gains replaced in place
and the command that found them in a comment."""
import math
import os
import time

import numpy as np
import yaml
from scipy.optimize import minimize

from ..track import driving

#: The gains searched: name (the YAML's dotted key) -> (lower, upper), log scale.
PI_SPACE = {"wheel.kp": (0.003, 3.0), "wheel.ki": (0.03, 30.0), "yaw.kp": (0.003, 3.0), "yaw.ki": (0.03, 30.0)}
#: Comment line written above the gains by write_gains (replaced on the next write).
STAMP = "# tuned by aic_tune.py"


def base_gains(path):
    """The gains of PI_SPACE in the YAML ``path`` ({dotted key: value}; absent keys: None)."""
    with open(path) as f:
        d = yaml.safe_load(f) or {}
    out = {}
    for key in PI_SPACE:
        group, name = key.split(".")
        out[key] = (d.get(group) or {}).get(name)
    return out


def to_unit(gains):
    """The unit-box point of ``gains`` ({dotted key: value}; None or <= 0: the middle)."""
    u = []
    for key, (lo, hi) in PI_SPACE.items():
        v = gains.get(key)
        u.append(0.5 if v is None or v <= 0 else (math.log10(v) - math.log10(lo)) / (math.log10(hi) - math.log10(lo)))
    return np.clip(np.array(u), 0.0, 1.0)


def from_unit(u):
    """The gains {dotted key: value} of a point ``u`` of the unit box (clipped to it)."""
    return {key: 10.0 ** (math.log10(lo) + x * (math.log10(hi) - math.log10(lo)))
            for (key, (lo, hi)), x in zip(PI_SPACE.items(), np.clip(u, 0.0, 1.0))}


def to_sets(gains):
    """closed_loop_run --pi-set overrides of ``gains``: ["wheel.kp=0.3", ...]."""
    return ["%s=%.4g" % (k, v) for k, v in sorted(gains.items())]


def write_gains(path, base, gains, stamp):
    """Write the YAML ``base`` to ``path`` with each gain of ``gains`` ({"wheel.kp": value, ...})
    replaced in place (the line '  kp: ...' under 'wheel:'; comments kept) and the comment ``stamp``
    (one or more lines, each starting with '#') above the first tuned group's comment lines,
    replacing an earlier one.
    Raises KeyError when a gain's line is not in the file."""
    with open(base) as f:
        lines = f.read().splitlines()
    out, group, left, stamped, in_stamp = [], None, dict(gains), False, False
    for line in lines:
        in_stamp = line.startswith(STAMP) or (in_stamp and line.startswith("#   "))
        if in_stamp:  # an earlier stamp and its indented continuation lines
            continue
        if line and not line.startswith((" ", "#")):
            group = line.split(":", 1)[0].strip()
            if not stamped and any(k.startswith(group + ".") for k in gains):
                at = len(out)  # above the group's own comment lines
                while at > 0 and out[at - 1].startswith("#"):
                    at -= 1
                out[at:at] = stamp.splitlines()
                stamped = True
        key = "%s.%s" % (group, line.split(":", 1)[0].strip()) if line.startswith("  ") and ":" in line else None
        if key in left:
            indent = line[:len(line) - len(line.lstrip())]
            out.append("%s%s: %.4g" % (indent, key.split(".")[1], left.pop(key)))
            continue
        out.append(line)
    if left:
        raise KeyError("write_gains: no line for %s in %s" % (", ".join(sorted(left)), base))
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def run(a, tool, command):
    """--driving --controller pi: Nelder-Mead over PI_SPACE from the base YAML's gains (a.base),
    scored by driving.cost on a.driving_variants; writes the winner (a.write) with ``command`` (the
    command line) in its comment. a: parsed arguments of aic_tune.py, tool: cli.Tool. Returns the
    exit status."""
    t_start = time.time()
    exe = tool.exe("closed_loop_run")
    plant_config = tool.path("sim", "config", "plant.yaml")
    variants = [v if v == "default" else os.path.abspath(v) for v in a.driving_variants]
    best = {"cost": float("inf"), "gains": None}
    stock_cache = {}
    n = [0]

    def f(u):
        gains = from_unit(u)
        runner = driving.Runner(exe, a.base, plant_config, to_sets(gains), a.jobs, tuned="pi")
        runner._stock = stock_cache
        try:
            c = driving.cost(driving.evaluate(runner, tool.root, variants=variants, ideal=False,
                                              arc_prior_table=False))
        except RuntimeError as e:
            print("  run failed: %s" % str(e)[-200:])
            c = 50.0
        n[0] += 1
        if c < best["cost"]:
            best.update(cost=c, gains=gains)
            print("  [%4d, %5.0f s] cost %.4f: %s" % (n[0], time.time() - t_start, c, " ".join(to_sets(gains))),
                  flush=True)
        return c

    u0 = to_unit(base_gains(a.base))
    step = 0.15
    simplex = [u0] + [np.clip(u0 + np.eye(len(u0))[i] * (-step if u0[i] > 0.5 else step), 0, 1)
                      for i in range(len(u0))]
    minimize(f, u0, method="Nelder-Mead", options={"maxfev": a.refine_evals, "initial_simplex": np.array(simplex),
                                                     "xatol": 1e-3, "fatol": 1e-4})
    print("== winner (cost %.4f after %d evaluations): %s" % (best["cost"], n[0], " ".join(to_sets(best["gains"]))))
    if a.write:
        write_gains(a.write, a.base, best["gains"],
                    "%s (driving cost %.4f, %d evaluations, variants %s):\n#   %s" % (
                        STAMP, best["cost"], n[0], " ".join(os.path.basename(v) for v in a.driving_variants),
                        command))
        print("wrote %s (%.0f s)" % (a.write, time.time() - t_start))
    return 0
