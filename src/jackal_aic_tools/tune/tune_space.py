"""The search spaces of aic_tune.py and the controller values of a point in them.

SPACE (+ REFINE_SPACE) are the straight-step stages' parameters, searched on log10; a point
``x`` of them and an embedding order make one candidate (candidate_overrides). DRIVING_SPACE is
--driving's, searched on the unit box (driving_values, driving_unit). to_args gives the tools'
KEY=VALUE overrides of a candidate, write_yaml the tuned configuration file."""
import math

import numpy as np

RATES = {"belief_rate": 1000.0, "action_rate": 50.0, "integrator": "exact"}
# The straight-step stages tune the free-energy action alone: the state-space model has no
# set-point dynamics and no action prior (jackal_aic::analysis::ClosedLoopModel), so they are off in
# every candidate of those stages (--driving tunes them).
FREE_ENERGY_ONLY = {"generalized_goal": "false", "reference_time_constant": 0.0, "action_prior_gain": 0.0}
# Searched parameters: name -> (lower, upper), searched on log10.
SPACE = {
    "tau": (1e-3, 0.1),          # s
    "k_mu": (1e-3, 1.0),         # -
    "k_a": (1.0, 60.0),          # -
    "var_mu0": (0.1, 20.0),      # sigma^2_mu order 0 (higher orders scale with it as in table C-1)
    "var_y1": (1.0, 1e5),        # sigma^2_y order 1 (derivative action); order 0 fixed at 2
}
# Refined in the simulator too (not in the model, which has no wheel-speed clamp): name ->
# (lower, upper), searched on log10, appended to SPACE's vector.
REFINE_SPACE = {
    "max_action_lead": (1.0, 10.0),       # rad/s, anti-windup lead of each wheel
    "max_action_lead_turn": (0.25, 4.0),  # rad/s, anti-windup lead of the wheel differential
}
# --driving: name -> (lower, upper, log scale); mapped from the unit box.
DRIVING_SPACE = {
    "k_a": (1.0, 60.0, True),
    "var_y1": (1.0, 1e4, True),            # sigma^2_y of order 1
    "tau": (1e-3, 0.2, True),              # s
    "k_mu": (1e-3, 1.0, True),
    "max_action_lead": (0.5, 10.0, True),  # rad/s
    "action_prior_gain": (0.0, 1.5, False),
    "reference_time_constant": (0.005, 0.3, True),  # s
    "max_reference_acceleration_linear": (1.0, 20.0, True),   # m/s^2
    "max_reference_acceleration_angular": (2.0, 60.0, True),  # rad/s^2
    "max_reference_acceleration_wheel": (2.0, 20.0, True),  # m/s^2
    "reference_delay": (0.0, 0.25, False),          # s
    "action_prior_time_constant": (0.0, 0.3, False),  # s
    "goal_lead": (0.0, 0.3, False),         # s
    "goal_lead_angular": (0.0, 0.3, False),  # s
}
DRIVING_FIXED = {"generalized_goal": "true", "max_action_lead_turn": 0.0}
# --driving from a base with belief_model: unbiased: the beliefs follow the sensors (a larger k_mu),
# tau is the robot's response time, and the goal prior's expected response T_g is searched too
# (doc/active_inference.md, 'Unbiased beliefs').
UNBIASED_DRIVING_SPACE = dict(DRIVING_SPACE, tau=(0.02, 0.3, True), k_mu=(0.5, 50.0, True),
                              goal_response_time_constant=(0.005, 0.3, True))


def driving_space(d):
    """The --driving search space of a base config dict d: UNBIASED_DRIVING_SPACE when its
    belief_model is unbiased, else DRIVING_SPACE (name -> (lower, upper, log scale))."""
    return UNBIASED_DRIVING_SPACE if d.get("belief_model") == "unbiased" else DRIVING_SPACE


def log_bounds(space):
    """[(log10 lower, log10 upper)] of a space's (lower, upper) entries, in its order."""
    return [(math.log10(lo), math.log10(hi)) for lo, hi in space.values()]


def yaml_float(x):
    """A float YAML reads back as a float (1000.0, not 1000: rosparam would make that an int)."""
    t = "%.4g" % x
    if "e" in t:
        return "%.1f" % x if abs(x) < 1e9 else "%.3e" % x  # PyYAML (rosparam) needs a '.' in a float
    return t if any(c in t for c in ".n") else t + ".0"


def yaml_list(xs):
    """A YAML flow list of floats (yaml_float each)."""
    return "[" + ", ".join(yaml_float(x) for x in xs) + "]"


def candidate_overrides(x, order):
    """Controller values (dict key -> value) for the search vector x and embedding order p: x is
    log10 of SPACE's parameters, optionally followed by log10 of REFINE_SPACE's (the refinement's
    vector; the model search leaves them at the base config's values)."""
    v = {k: 10.0 ** xi for k, xi in zip(list(SPACE) + list(REFINE_SPACE), x)}
    # sigma^2_mu per order: table C-1's shape (1.5, 2, 4, 8) scaled to var_mu0.
    shape = [1.0, 4.0 / 3.0, 8.0 / 3.0, 16.0 / 3.0, 32.0 / 3.0, 64.0 / 3.0][:order + 1]
    var_mu = [v["var_mu0"] * s for s in shape]
    var_y = [2.0, v["var_y1"]] + [1e5] * (order - 1)
    o = {"tau": v["tau"], "k_mu": v["k_mu"], "k_a": v["k_a"], "embedding_order": order,
         "var_mu": var_mu, "var_y": var_y}
    for k in REFINE_SPACE:
        if k in v:
            o[k] = v[k]
    o.update(RATES)
    o.update(FREE_ENERGY_ONLY)
    return o


def to_args(o):
    """KEY=VALUE strings (the tools' override syntax) of a dict of controller values. Lists have no
    spaces: aic_predict reads a candidate as one line of space-separated overrides."""
    return ["%s=%s" % (k, yaml_list(v).replace(" ", "") if isinstance(v, list)
                       else ("%.6g" % v if isinstance(v, float) else v))
            for k, v in sorted(o.items())]


def base_vector(d):
    """(order, x) of a controller configuration in the refinement's space (log10 of SPACE's and
    REFINE_SPACE's parameters; an absent lead key counts as 3.0 / 1.0 rad/s), or None when it is
    outside it. d: every node parameter (jackal_aic_tools.common.cli.effective_config's dict)."""
    try:
        order = int(d["embedding_order"])
        vals = {"tau": d["tau"], "k_mu": d["k_mu"], "k_a": d["k_a"], "var_mu0": d["var_mu"][0],
                "var_y1": d["var_y"][1], "max_action_lead": d.get("max_action_lead", 3.0),
                "max_action_lead_turn": d.get("max_action_lead_turn", 1.0)}
        x = tuple(math.log10(float(vals[k])) for k in list(SPACE) + list(REFINE_SPACE))
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return order, x


def driving_values(u, var_y, space=None):
    """Controller values (dict) of a point u of the unit box (``space``, default DRIVING_SPACE; u
    is clipped to the box: Nelder-Mead's vertices outside it are evaluated at their projection).
    var_y: the base config's list, whose order-1 entry var_y1 replaces."""
    v = {}
    for (k, (lo, hi, log)), x in zip((space or DRIVING_SPACE).items(), np.clip(u, 0.0, 1.0)):
        v[k] = 10.0 ** (math.log10(lo) + x * (math.log10(hi) - math.log10(lo))) if log else lo + x * (hi - lo)
    vy = list(var_y)
    vy[1] = v.pop("var_y1")
    v["var_y"] = vy
    v.update(DRIVING_FIXED)
    return v


def driving_unit(d, space=None):
    """The unit-box point of a config dict d in ``space`` (default DRIVING_SPACE; absent keys: the
    middle of their range)."""
    u = []
    for k, (lo, hi, log) in (space or DRIVING_SPACE).items():
        val = d["var_y"][1] if k == "var_y1" else d.get(k)
        if val is None or (log and float(val) <= 0.0):
            u.append(0.5)
        elif log:
            u.append((math.log10(float(val)) - math.log10(lo)) / (math.log10(hi) - math.log10(lo)))
        else:
            u.append((float(val) - lo) / (hi - lo))
    return np.clip(np.array(u), 0.0, 1.0)


def model_stamp(plant, cost, a):
    """The derivation line write_yaml puts under the header of a straight-step winner: the wheel
    loop (plant: gain, time_constant [s], delay [s]), the bounds of ``a`` (overshoot [%],
    max_radius, robust fraction) and the simulator cost."""
    return ("# tuned by aic_tune.py: wheel loop K %.3f, T_p %.4f s, delay %.4f s; overshoot <= %g %%, spectral "
            "radius <= %g at +-%d %% gain and delay; simulator cost %.3f" % (
                plant["gain"], plant["time_constant"], plant["delay"], a.overshoot, a.max_radius,
                round(100 * a.robust), cost))


def write_yaml(path, base, winner, stamp):
    """Write the base YAML (file ``base``) to ``path`` with the tuned keys of ``winner`` (dict key
    -> value) replaced in place (comments kept) or appended, and the derivation line ``stamp``
    after the header comment block (an earlier "# tuned by aic_tune" line is dropped)."""
    with open(base) as f:
        lines = f.read().splitlines()
    values = dict(winner)
    out = []
    for line in lines:
        key = line.split(":", 1)[0].strip() if ":" in line and not line.lstrip().startswith("#") else None
        if key in values and not line.startswith(" "):
            v = values.pop(key)
            comment = line.split("#", 1)[1] if "#" in line else ""
            text = yaml_list(v) if isinstance(v, list) else (yaml_float(v) if isinstance(v, float) else str(v))
            line = "%s: %s" % (key, text) + ("  #" + comment if comment else "")
        if line.startswith("# tuned by aic_tune"):
            continue
        out.append(line)
    for k, v in values.items():
        out.append("%s: %s" % (k, yaml_list(v) if isinstance(v, list) else v))
    i = 0
    while i < len(out) and out[i].startswith("#"):
        i += 1
    out.insert(i, stamp)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
