"""The parameter search of the wheel-loop identification, shared by plant_identify.py's two
modes (the robot's step tables through plant_fit, a robot's bag through plant_replay).

A search space maps each parameter to the unit interval (log scale for gains, linear for times
and limits); scipy.optimize's Nelder-Mead searches the unit box, a vertex outside the box being
evaluated at its projection (Nelder-Mead's own bounds= needs scipy >= 1.7; Ubuntu 20.04 has 1.3).
Also the in-place writer of a plant YAML's motor section and the reader of its values.
"""
import math
import re

import numpy as np
from scipy.optimize import minimize

from ..common import closed_loop


class Space(object):
    """Bounds of the searched parameters: ``bounds`` maps key -> (lower, upper, scale), scale
    "log" (searched on log(value), lower > 0) or "lin"."""

    def __init__(self, bounds):
        for key, (lo, hi, scale) in bounds.items():
            if not (hi > lo) or scale not in ("log", "lin") or (scale == "log" and lo <= 0.0):
                raise ValueError("parameter %s: bounds (%r, %r, %r) need lower < upper, scale log (lower > 0) "
                                 "or lin" % (key, lo, hi, scale))
        self.bounds = dict(bounds)

    def to_value(self, key, u):
        """The value of ``key`` at unit coordinate ``u`` (clipped to [0, 1])."""
        lo, hi, scale = self.bounds[key]
        u = min(max(u, 0.0), 1.0)
        if scale == "log":
            return math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo)))
        return lo + u * (hi - lo)

    def to_unit(self, key, v):
        """The unit coordinate of value ``v`` of ``key`` (clipped to the bounds)."""
        lo, hi, scale = self.bounds[key]
        v = min(max(v, lo), hi)
        if scale == "log":
            return (math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo))
        return (v - lo) / (hi - lo)

    def values(self, keys, units):
        """dict key -> value of the unit coordinates ``units`` (same order as ``keys``)."""
        return {k: self.to_value(k, float(x)) for k, x in zip(keys, units)}


def nelder_mead(cost, start, max_evals, progress=None):
    """Minimise ``cost`` (a function of a unit-box point, a numpy array) with Nelder-Mead from
    ``start`` (unit coordinates), at most ``max_evals`` evaluations; the initial simplex steps 15 %
    of each range, inwards. ``progress(n, best)`` is called every 25 evaluations.
    Returns (best cost, best point clipped to the box, number of evaluations)."""
    history = []

    def f(u):
        c = cost(np.clip(u, 0.0, 1.0))
        history.append(c)
        if progress is not None and len(history) % 25 == 0:
            progress(len(history), min(history))
        return c

    x0 = np.array(start, dtype=float)
    simplex = [x0]
    for i in range(len(x0)):
        x = x0.copy()
        x[i] = x[i] + 0.15 if x[i] < 0.5 else x[i] - 0.15
        simplex.append(x)
    res = minimize(f, x0, method="Nelder-Mead",
                   options={"maxfev": max_evals, "xatol": 1e-3, "fatol": 1e-4, "initial_simplex": np.array(simplex)})
    return float(res.fun), np.clip(res.x, 0.0, 1.0), len(history)


def read_motor(path, overlays=()):
    """The motor section's key: value pairs of a plant YAML (numbers as floats), each overlay file
    of ``overlays`` over it (closed_loop.plant_motor)."""
    return closed_loop.plant_motor(path, overlays)


def write_motor(path, values, note):
    """Replace the values of ``values``' keys in the motor section of the plant YAML at ``path``,
    keeping comments and layout (a trailing "default X" in a key's comment becomes the new value:
    update the C++ defaults in plant_params.hpp to match); the line '# identified by
    plant_identify...' gets ``note``.
    Raises ValueError naming the keys the section does not have."""
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
            # "default X" in the comment names the C++ default (plant_params.hpp), which holds the
            # identified values too: it follows the written value.
            comment = re.sub(r"default [-+0-9.eE]+$", "default " + new, m.group(6) or "")
            width = len(m.group(4)) + len(m.group(5))
            pad = " " * max(1, width - len(new))
            lines[i] = "%s%s:%s%s%s%s\n" % (m.group(1), key, m.group(3) or " ", new, pad if comment else "", comment)
            done.add(key)
        if in_motor and line.lstrip().startswith("# identified by plant_identify"):
            lines[i] = re.sub(r"# identified by plant_identify.*", "# identified by plant_identify: " + note,
                              line.rstrip("\n")) + "\n"
    missing = set(values) - done
    if missing:
        raise ValueError("keys missing from %s's motor section: %s" % (path, ", ".join(sorted(missing))))
    with open(path, "w") as f:
        f.writelines(lines)
