#!/usr/bin/env python3
"""aic_tune.py: model-based tuning of the active inference controller on the simulated Jackal.

Three stages, all reproducible from this command and the repository's plant:

1. Identify the wheel loop. Open-loop steps of the wheel commands on the plant core
   (`closed_loop_run --controller open`: the MCU model of sim/config/plant.yaml, no controller)
   around an operating point, and a least-squares fit (scipy.optimize.least_squares) of a
   first-order-plus-dead-time model  K exp(-d s) / (T_p s + 1)  to the wheel-odometry speed.
2. Search on the model. The dual-rate state-space model of the controller with that plant
   (`aic_predict`, jackal_aic::ClosedLoopModel; doc/active_inference.md, "State-space model for
   analysis") scores each candidate (tau, k_mu, k_a, the order-0 belief variance, the order-1
   sensory variance, per embedding order p) by its predicted 0.5 m/s settling time, with penalties
   for overshoot above --overshoot and for a spectral radius above --max-radius at any corner of
   the plant's gain and delay varied by +-20 % (--robust). Search: scipy.optimize's
   differential_evolution on log parameters.
3. Refine and verify in the simulator. The wheel loop is not linear (its proportional path
   saturates: doc/robot_data.md), so the best model candidates and the base config are refined
   by a bounded Nelder-Mead (scipy) directly on the nonlinear plant core (`closed_loop_run`, the
   controller scheduled as the node), in the model's parameters plus the anti-windup leads
   max_action_lead and max_action_lead_turn (REFINE_SPACE). The cost (sim_cost) is relative to
   the stock controller on the same plant, noisy sensors: the worst 0.5 m/s settling ratio over
   the noise seeds --seeds, half the 0.5 m/s rise ratio, a quarter of the 0.3 / 1.0 m/s settling
   ratios, steep penalties for overshoot above --overshoot on the 0.1 / 0.3 / 0.5 / 1.0 m/s
   steps and steady-state error above 1 %, robustness (the 0.5 m/s step with the plant's
   command_delay -+20 %: settled, overshoot <= --robust-overshoot) and the 1 rad/s turn in place
   (settling <= --turn-ratio x stock). The winner is then run with noisy sensors next to the
   stock controller; scripts/aic_scorecard.py checks the whole acceptance set.

Prints the identified plant, the model's top candidates, the verification table, and writes
the winner as YAML (--write FILE): the base file with the tuned keys set in place or added. The
defaults are the code's (recommendedAicParams(), src/core/params.cpp); adopting a winner as the
default means writing its values there.

--driving: instead of the three stages, tune for real driving from the base config: a bounded
Nelder-Mead (on the unit box, scipy) over DRIVING_SPACE (the gains, the anti-windup lead, the
reference model, the action prior and the goal's look-ahead; generalized_goal on, the turn lead
off), scored by jackal_aic_tools.driving.cost: the tracking benchmark (sim/profiles/*.csv) over
the plant variants --driving-variants, the step cases and their overshoot against the stock
controller, the turn-deficit holds and the robustness runs (doc/experiments.md, 'Driving
acceptance'). Prints each improvement and the winner's acceptance figures over every variant.

Usage:
  aic_tune.py --driving [--base config/default.yaml] [--write FILE] [--refine-evals N]
              [--driving-variants default|OVERLAY.yaml ...] [--jobs N]
  aic_tune.py [--base config/default.yaml] [--write FILE] [--orders 2 3] [--popsize N]
              [--maxiter N] [--refine-evals N] [--top N] [--seed S] [--overshoot PCT]
              [--max-radius R] [--robust FRAC] [--robust-overshoot PCT] [--seeds S ...]
              [--turn-weight W] [--turn-ratio R] [--skip-model] [--jobs N]
  (~8 min on 2 busy cores: nice -n 10 aic_tune.py --refine-evals 150 --jobs 2)
Exit: 0 on success; 1 if a tool fails or no candidate meets the bounds in the simulator.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.optimize import differential_evolution, least_squares, minimize
from scipy.signal import lfilter

from jackal_aic_tools import cli

ROOT = cli.source_root(__file__)
RATES = {"belief_rate": 1000.0, "action_rate": 50.0, "integrator": "exact"}
# The straight-step stages tune the free-energy action alone: the state-space model has no
# set-point dynamics and no action prior (jackal_aic::ClosedLoopModel), so they are off in
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
    "reference_delay": (0.0, 0.25, False),          # s
    "action_prior_time_constant": (0.0, 0.3, False),  # s
    "goal_lead": (0.0, 0.3, False),         # s
}
DRIVING_FIXED = {"generalized_goal": "true", "max_action_lead_turn": 0.0}
STEPS = [0.3, 0.5, 1.0]  # m/s: the verification's steps (0.1 reported too)
COST_STEPS = [0.1, 0.3, 0.5, 1.0]  # m/s: the refinement's steps (overshoot bound on all)
# Plant latency varied by +-20 % of sim/config/plant.yaml's identified 0.1174 s.
ROBUST_DELAYS = ["motor.command_delay=0.0939", "motor.command_delay=0.1409"]


def find_exe(name):
    """Path of the package's C++ tool `name` (exits with a message when it is not built)."""
    return cli.find_executable(name, __file__, "aic_tune")


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


# --------------------------------------------------------------------------- 1. identification

def run_closed_loop(args, csv_path=None):
    """closed_loop_run with ``args`` (and --csv ``csv_path``): its JSON result as a dict.
    Raises RuntimeError with the tool's message when it fails."""
    cmd = [find_exe("closed_loop_run")] + args
    if csv_path:
        cmd += ["--csv", csv_path]
    return cli.run_json_tool(cmd)


def identify_plant(low, high, period=2.0, plant_config=None):
    """FOPDT fit of the open-loop wheel loop on a square wave low <-> high [m/s].
    Returns dict gain, time_constant [s], delay [s], rms [m/s]."""
    tmp = tempfile.mkdtemp(prefix="aic_tune_")
    path = os.path.join(tmp, "open.csv")
    args = ["--controller", "open", "--square", str(low), str(high), "--period", str(period), "--cycles", "2",
            "--rest", "2.0"]
    if plant_config:
        args += ["--config", plant_config]
    run_closed_loop(args, path)
    with open(path) as f:
        rows = [r for r in csv.DictReader(f) if float(r["t"]) >= 0.0]
    t = np.array([float(r["t"]) for r in rows])
    u = np.array([float(r["command"]) for r in rows])
    y = np.array([float(r["v_odom"]) for r in rows])
    h = 1e-3
    tf = np.arange(t[0], t[-1], h)
    # the command is piecewise constant: take the last sample's value (zero-order hold)
    idx = np.clip(np.searchsorted(t, tf, side="right") - 1, 0, len(u) - 1)
    uf = u[idx]

    def simulate(theta):
        k, tp, d = theta
        shift = int(round(d / h))
        ud = np.concatenate([np.full(shift, uf[0]), uf[:len(uf) - shift]]) if shift > 0 else uf
        a = math.exp(-h / tp)
        ys = lfilter([(1.0 - a) * k], [1.0, -a], ud, zi=[a * y[0]])[0]
        return np.interp(t, tf, ys)

    # The dead time moves the response by whole 1 ms steps (no gradient): a grid over it, and
    # least squares for gain and time constant at each.
    best = None
    for d in np.arange(0.0, 0.25, 0.002):
        res = least_squares(lambda th: simulate((th[0], th[1], d)) - y, x0=[1.0, 0.1],
                            bounds=([0.5, 0.002], [1.5, 1.0]))
        if best is None or res.cost < best[0]:
            best = (res.cost, res.x[0], res.x[1], d, res.fun)
    _, k, tp, d, fun = best
    rms = float(np.sqrt(np.mean(fun ** 2)))
    return {"gain": float(k), "time_constant": float(tp), "delay": float(d), "rms": rms,
            "square": (low, high)}


# --------------------------------------------------------------------------- 2. model search

class Predictor(object):
    """One aic_predict process; thread-safe enough for one caller at a time."""

    def __init__(self, base, target=0.5):
        self.p = subprocess.Popen([find_exe("aic_predict"), base, "--target", str(target), "--duration", "3"],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    def __call__(self, overrides, plant):
        line = " ".join(overrides + ["plant.%s=%.6g" % (k, v) for k, v in plant.items()])
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        return json.loads(self.p.stdout.readline())

    def close(self):
        self.p.stdin.close()
        self.p.wait()


def plant_corners(plant, frac):
    """The nominal plant dict (gain [-], time_constant [s], delay [s]) and its four corners with
    gain and delay scaled by 1 -+ frac."""
    base = {"time_constant": plant["time_constant"], "gain": plant["gain"], "delay": plant["delay"]}
    out = [base]
    for g in (1.0 - frac, 1.0 + frac):
        for d in (1.0 - frac, 1.0 + frac):
            out.append(dict(base, gain=base["gain"] * g, delay=base["delay"] * d))
    return out


def model_cost(x, order, predictor, corners, a):
    """Model score of search vector x (log10 of SPACE) at embedding order p [s-ish, lower is
    better]: the worst predicted 0.5 m/s settling time over the plant corners, + 0.05 per %
    of overshoot above a.overshoot, + 20 x the spectral radius above a.max_radius; 20-100
    for a candidate that is invalid or unstable at any corner."""
    o = to_args(candidate_overrides(x, order))
    r = predictor(o, corners[0])
    if not r.get("ok") or not r.get("stable"):
        return 100.0
    if r.get("rise") is None:
        return 50.0
    # Robust performance: the worst settling time and overshoot over the plant's corners, and the
    # worst spectral radius.
    worst = r["spectral_radius"]
    settle = r["settling"] if r.get("settling") is not None else 5.0
    overshoot = r.get("overshoot") or 0.0
    for c in corners[1:]:
        rc = predictor(o, c)
        if not rc.get("ok") or not rc.get("stable"):
            return 20.0
        worst = max(worst, rc["spectral_radius"])
        settle = max(settle, rc["settling"] if rc.get("settling") is not None else 5.0)
        overshoot = max(overshoot, rc.get("overshoot") or 0.0)
    return settle + 0.05 * max(0.0, overshoot - a.overshoot) + 20.0 * max(0.0, worst - a.max_radius)


# --------------------------------------------------------------------------- 3. simulator

def sim_step(overrides, v, base, noise=False, channel="linear", controller="aic", plant_sets=(), hold=3.0):
    """One step from rest to v (m/s, or rad/s on the angular channel) on the plant core, held
    `hold` s: a dict of runaways, max |v|, and the measured metrics (rise, settling [s],
    overshoot [%], sse [m/s or rad/s], settled). plant_sets: plant KEY=VALUE overrides (e.g.
    sensors.seed=3 for another noise draw with noise=True)."""
    args = ["--controller", controller, "--step", str(v), "--hold", str(hold), "--channel", channel]
    if controller == "aic":
        args += ["--aic-config", base]
        for o in overrides:
            args += ["--aic-set", o]
    for s in plant_sets:
        args += ["--set", s]
    if noise:
        args += ["--noise"]
    r = run_closed_loop(args)
    seg = r["segments"][0]
    return {"runaways": r["runaways"], "max": r["max_abs_speed"], **seg["measured"]}


def stock_reference(a):
    """The stock controller's figures the simulator cost is relative to, noisy sensors: dict
    ("step", v, seed) -> metrics of the COST_STEPS (first seed of a.seeds; 0.5 m/s for every
    seed) and ("turn", 1.0) -> the 1 rad/s yaw-rate step (8 s hold)."""
    ref = {}
    for v in COST_STEPS:
        ref[("step", v, a.seeds[0])] = sim_step([], v, a.base, noise=True, controller="stock",
                                                plant_sets=["sensors.seed=%d" % a.seeds[0]])
    for seed in a.seeds[1:]:
        ref[("step", 0.5, seed)] = sim_step([], 0.5, a.base, noise=True, controller="stock",
                                            plant_sets=["sensors.seed=%d" % seed])
    ref[("turn", 1.0)] = sim_step([], 1.0, a.base, noise=True, controller="stock", channel="angular", hold=8.0)
    return ref


def settle_or_penalty(m, v):
    """Settling time [s] of metrics m of a step of size v, or, when it did not settle within the
    hold, 3 s + its final relative error (graded, so that the search can move)."""
    if m["settled"] and m["settling"] is not None:
        return m["settling"]
    return 3.0 + abs(m["sse"] if m["sse"] is not None else v) / abs(v)


def sim_cost(overrides, base, a, ref):
    """Simulator score of the controller overrides [-, lower is better], noisy sensors, against
    the stock controller's figures ref (stock_reference()):
      the worst 0.5 m/s settling ratio AIC / stock over the noise seeds a.seeds
      + 0.5 x the 0.5 m/s rise ratio + 0.25 x the mean settling ratio of the 0.3 and 1.0 m/s steps
      + 0.2 per % of overshoot above a.overshoot on any of COST_STEPS (0.1 ... 1.0 m/s)
      + 0.2 per % of steady-state error above 1 %
      + robustness, 0.5 m/s step with the plant's command_delay -+20 % (ideal sensors): 2 if
        unsettled, + 0.05 per % of overshoot above a.robust_overshoot
      + the 1 rad/s turn in place (a.turn_weight > 0): a.turn_weight x (AIC / stock settling
        - a.turn_ratio) when above, + 0.02 per % of overshoot above 10 %;
    10 on a runaway. The overshoot bound is a steep penalty, not a constraint, so that the
    search can cross it."""
    s0 = a.seeds[0]
    m = {}
    for v in COST_STEPS:
        m[(v, s0)] = sim_step(overrides, v, base, noise=True, plant_sets=["sensors.seed=%d" % s0])
    for seed in a.seeds[1:]:
        m[(0.5, seed)] = sim_step(overrides, 0.5, base, noise=True, plant_sets=["sensors.seed=%d" % seed])
    if any(r["runaways"] for r in m.values()):
        return 10.0
    total = max(settle_or_penalty(m[(0.5, s)], 0.5) / ref[("step", 0.5, s)]["settling"] for s in a.seeds)
    rise = m[(0.5, s0)]["rise"]
    total += 0.5 * (rise / ref[("step", 0.5, s0)]["rise"] if rise else 3.0)
    total += 0.25 * sum(settle_or_penalty(m[(v, s0)], v) / ref[("step", v, s0)]["settling"]
                        for v in (0.3, 1.0)) / 2.0
    for (v, _), r in m.items():
        total += 0.2 * max(0.0, (r["overshoot"] or 0.0) - a.overshoot)
        total += 0.2 * max(0.0, 100.0 * abs(r["sse"] or 0.0) / v - 1.0)
    for sets in ROBUST_DELAYS:
        r = sim_step(overrides, 0.5, base, plant_sets=[sets])
        if r["runaways"]:
            return 10.0
        if not r["settled"]:
            total += 2.0
        total += 0.05 * max(0.0, (r["overshoot"] or 0.0) - a.robust_overshoot)
    if a.turn_weight > 0.0:
        r = sim_step(overrides, 1.0, base, noise=True, channel="angular", hold=8.0)
        if r["runaways"]:
            return 10.0
        total += a.turn_weight * max(0.0, settle_or_penalty(r, 1.0) / ref[("turn", 1.0)]["settling"] - a.turn_ratio)
        total += 0.02 * max(0.0, (r["overshoot"] or 0.0) - 10.0)
    return total


def base_vector(path):
    """(order, x) of a controller YAML in the refinement's space (log10 of SPACE's and
    REFINE_SPACE's parameters; an absent lead key counts as 3.0 / 1.0 rad/s), or None when it
    is outside it."""
    d = cli.effective_config([path], __file__, "aic_tune")
    try:
        order = int(d["embedding_order"])
        vals = {"tau": d["tau"], "k_mu": d["k_mu"], "k_a": d["k_a"], "var_mu0": d["var_mu"][0],
                "var_y1": d["var_y"][1], "max_action_lead": d.get("max_action_lead", 3.0),
                "max_action_lead_turn": d.get("max_action_lead_turn", 1.0)}
        x = tuple(math.log10(float(vals[k])) for k in list(SPACE) + list(REFINE_SPACE))
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return order, x


def fmt(v, spec="%.3f"):
    """v formatted with spec, '-' for None."""
    return "-" if v is None else spec % v


def driving_values(u, var_y):
    """Controller values (dict) of a point u of the unit box (DRIVING_SPACE; u is clipped to the
    box: Nelder-Mead's vertices outside it are evaluated at their projection). var_y: the base
    config's list, whose order-1 entry var_y1 replaces."""
    v = {}
    for (k, (lo, hi, log)), x in zip(DRIVING_SPACE.items(), np.clip(u, 0.0, 1.0)):
        v[k] = 10.0 ** (math.log10(lo) + x * (math.log10(hi) - math.log10(lo))) if log else lo + x * (hi - lo)
    vy = list(var_y)
    vy[1] = v.pop("var_y1")
    v["var_y"] = vy
    v.update(DRIVING_FIXED)
    return v


def driving_unit(d):
    """The unit-box point of a config dict d (absent keys: the middle of their range)."""
    u = []
    for k, (lo, hi, log) in DRIVING_SPACE.items():
        val = d["var_y"][1] if k == "var_y1" else d.get(k)
        if val is None or (log and float(val) <= 0.0):
            u.append(0.5)
        elif log:
            u.append((math.log10(float(val)) - math.log10(lo)) / (math.log10(hi) - math.log10(lo)))
        else:
            u.append((float(val) - lo) / (hi - lo))
    return np.clip(np.array(u), 0.0, 1.0)


def tune_driving(a):
    """--driving: Nelder-Mead over DRIVING_SPACE from the base config, scored by
    jackal_aic_tools.driving.cost on a.driving_variants; writes the winner (a.write). Returns the
    exit status."""
    from jackal_aic_tools import driving
    t_start = time.time()
    base = cli.effective_config([a.base], __file__, "aic_tune")
    exe = find_exe("closed_loop_run")
    plant_config = os.path.join(ROOT, "sim", "config", "plant.yaml")
    variants = [v if v == "default" else os.path.abspath(v) for v in a.driving_variants]
    best = {"cost": float("inf"), "values": None}

    def evaluate(values, variant_list):
        runner = driving.Runner(exe, a.base, plant_config, to_args(values), a.jobs)
        runner._stock = stock_cache
        return driving.evaluate(runner, ROOT, variants=variant_list)

    stock_cache = {}
    n = [0]

    def f(u):
        values = driving_values(u, base["var_y"])
        try:
            c = driving.cost(evaluate(values, variants))
        except RuntimeError as e:  # a run that fails (invalid combination) scores as a runaway
            print("  run failed: %s" % str(e)[-200:])
            c = 50.0
        n[0] += 1
        if c < best["cost"]:
            best.update(cost=c, values=values)
            print("  [%4d, %5.0f s] cost %.4f: %s" % (n[0], time.time() - t_start, c, " ".join(to_args(values))),
                  flush=True)
        return c

    u0 = driving_unit(base)
    step = np.full(len(u0), 0.15)
    simplex = [u0] + [np.clip(u0 + np.eye(len(u0))[i] * np.where(u0[i] > 0.5, -step[i], step[i]), 0, 1)
                      for i in range(len(u0))]
    minimize(f, u0, method="Nelder-Mead", options={"maxfev": a.refine_evals, "initial_simplex": np.array(simplex),
                                                     "xatol": 1e-3, "fatol": 1e-4})
    print("== winner (cost %.4f), acceptance over every variant ==" % best["cost"])
    ev = evaluate(best["values"], None)
    for r in ev["steps"]:
        print("  %-13s settling AIC / stock %s (bound %.2f), overshoot %s %%" % (
            r["case"], fmt(r["ratio"], "%.2f"), r["bound"], fmt(r["aic_overshoot"], "%.1f")))
    for r in ev["deficit"]:
        print("  turn deficit %.1f rad/s: AIC error %+.4f rad/s, stock %+.4f rad/s" % (
            r["command"], r["aic_error"], r["stock_error"]))
    print("  tracking: geometric mean AIC / stock vx %.3f, wz %.3f; pairs above %.2f: %d of %d" % (
        ev["gmean"]["vx"], ev["gmean"]["wz"], driving.TRACK_PAIR_BOUND,
        sum(1 for r in ev["tracking"] if not r["pass"]), len(ev["tracking"])))
    if a.write:
        write_yaml(a.write, a.base, best["values"], None, best["cost"], a,
                   stamp="# tuned by aic_tune.py --driving (%d evaluations, variants %s): driving cost %.4f" % (
                       n[0], " ".join(os.path.basename(v) for v in a.driving_variants), best["cost"]))
        print("wrote %s (%.0f s)" % (a.write, time.time() - t_start))
    return 0


def main():
    """Parse the arguments, run the three stages and the verification. Returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--base", default=os.path.join(ROOT, "config", "default.yaml"),
                    help="controller YAML whose node keys the result keeps")
    ap.add_argument("--write", help="write the winner as YAML here")
    ap.add_argument("--orders", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--popsize", type=int, default=12)
    ap.add_argument("--maxiter", type=int, default=40)
    ap.add_argument("--refine-evals", type=int, default=120,
                    help="simulator evaluations per Nelder-Mead start (each ~10 closed_loop_run runs)")
    ap.add_argument("--top", type=int, default=3, help="model candidates refined in the simulator")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--overshoot", type=float, default=4.0,
                    help="overshoot bound of the 0.1 / 0.3 / 0.5 / 1.0 m/s steps [%% of the step]")
    ap.add_argument("--robust-overshoot", type=float, default=10.0,
                    help="overshoot bound of the 0.5 m/s step with command_delay -+20 %% [%%]")
    ap.add_argument("--seeds", type=int, nargs="+", default=[42, 1, 2],
                    help="noise seeds (plant sensors.seed) of the 0.5 m/s step in the simulator cost")
    ap.add_argument("--turn-weight", type=float, default=1.0,
                    help="weight of the 1 rad/s turn's settling ratio above --turn-ratio; 0 = no turn in the cost")
    ap.add_argument("--turn-ratio", type=float, default=0.97, help="AIC / stock settling of the 1 rad/s turn")
    ap.add_argument("--skip-model", action="store_true",
                    help="skip stages 1-2: refine from the base config only")
    ap.add_argument("--max-radius", type=float, default=0.98)
    ap.add_argument("--robust", type=float, default=0.2, help="relative variation of plant gain and delay")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--driving", action="store_true",
                    help="tune for real driving from the base config (DRIVING_SPACE, jackal_aic_tools.driving)")
    ap.add_argument("--driving-variants", nargs="+", metavar="VARIANT",
                    default=["default"] + [os.path.join(ROOT, "sim", "config", "variants", v + ".yaml")
                                           for v in ("turn_deficit", "latency_plus_20", "payload_10kg")],
                    help="--driving: plant variants of the tracking cost ('default' or an overlay YAML)")
    a = ap.parse_args()
    t_start = time.time()
    if a.driving:
        return tune_driving(a)

    bounds = [(math.log10(lo), math.log10(hi)) for lo, hi in SPACE.values()]
    rbounds = bounds + [(math.log10(lo), math.log10(hi)) for lo, hi in REFINE_SPACE.values()]
    base_x = base_vector(a.base)
    if a.skip_model:
        if base_x is None:
            print("aic_tune: --skip-model needs a base config inside the search space", file=sys.stderr)
            return 1
        plant = {"gain": float("nan"), "time_constant": float("nan"), "delay": float("nan")}
        found = [(float("nan"), base_x[0], base_x[1])]
    else:
        plant, found = model_stages(a, bounds, base_x)
    return refine_and_verify(a, plant, found, rbounds, base_x, t_start)


def model_stages(a, bounds, base_x):
    """Stages 1 and 2: identify the wheel loop and search on the state-space model (a: parsed
    arguments, bounds: log10 bounds of SPACE, base_x: base_vector() of a.base). Returns (plant
    dict gain [-] / time_constant [s] / delay [s], list of (model cost, order, x) starts for the
    refinement, the base config last)."""
    print("== 1. wheel loop, open loop on the plant core (first order + dead time) ==")
    plants = [identify_plant(0.25, 0.35), identify_plant(0.45, 0.55)]
    for p in plants:
        print("  square %.2f <-> %.2f m/s: gain %.3f, time constant %.4f s, delay %.4f s (rms %.4f m/s)"
              % (p["square"] + (p["gain"], p["time_constant"], p["delay"], p["rms"])))
    # Nominal: the slower fit (the 0.5 m/s range, where the proportional path saturates); the
    # robust corners cover the rest.
    slow = max(plants, key=lambda p: p["time_constant"])
    plant = {k: slow[k] for k in ("gain", "time_constant", "delay")}
    print("  model: gain %.3f, time constant %.4f s, delay %.4f s" % (plant["gain"], plant["time_constant"],
                                                                      plant["delay"]))
    corners = plant_corners(plant, a.robust)

    print("== 2. search on the state-space model (differential evolution, per embedding order) ==")
    found = []

    def search(order):
        pred = Predictor(a.base)
        try:
            seen = []

            def f(x):
                c = model_cost(x, order, pred, corners, a)
                seen.append((c, tuple(x)))
                return c
            res = differential_evolution(f, bounds, seed=a.seed + order, popsize=a.popsize, maxiter=a.maxiter,
                                         tol=1e-6, polish=False, updating="immediate")
            seen.sort()
            # distinct good candidates: the best and others at least 0.2 decades away from it
            picks = []
            for c, x in seen:
                if all(np.max(np.abs(np.array(x) - np.array(px))) > 0.2 for _, px in picks):
                    picks.append((c, x))
                if len(picks) >= a.top:
                    break
            return [(c, order, x) for c, x in picks], res.nfev
        finally:
            pred.close()

    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for picks, nfev in pool.map(search, a.orders):
            found += picks
            print("  p = %d: %d model evaluations" % (picks[0][1], nfev))
    found.sort()
    found = found[:a.top]
    if base_x is not None:
        found.append((float("nan"), base_x[0], base_x[1]))  # the base config: a start that is known to work
    pred = Predictor(a.base)
    print("  %-4s %-8s %-9s %-9s %-7s %-8s %-9s | predicted: %-8s %-8s %-9s %-7s" % (
        "p", "cost", "tau", "k_mu", "k_a", "var_mu0", "var_y1", "rise", "settle", "overshoot", "rho"))
    for c, order, x in found:
        o = candidate_overrides(x, order)
        r = pred(to_args(o), plant)
        c = c if c == c else model_cost(np.array(x), order, pred, corners, a)
        print("  %-4d %-8.3f %-9.4g %-9.4g %-7.3g %-8.3g %-9.3g | %-18s %-8s %-9s %-7s" % (
            order, c, o["tau"], o["k_mu"], o["k_a"], o["var_mu"][0], o["var_y"][1], fmt(r.get("rise")),
            fmt(r.get("settling")), fmt(r.get("overshoot"), "%.1f"), fmt(r.get("spectral_radius"))))
    pred.close()
    return plant, found


def refine_and_verify(a, plant, found, rbounds, base_x, t_start):
    """Stage 3 and the verification: Nelder-Mead (scipy) on sim_cost from every start in found
    (model candidates get the base config's leads), the verification table with noisy sensors
    against the stock controller, the robustness table, and --write. Returns the exit status."""
    print("== 3. refinement on the simulated Jackal (Nelder-Mead on closed_loop_run) ==")
    ref = stock_reference(a)
    print("  stock controller (noisy sensors): 0.5 m/s rise %.3f s settling %.3f s; 1 rad/s settling %.2f s" % (
        ref[("step", 0.5, a.seeds[0])]["rise"], ref[("step", 0.5, a.seeds[0])]["settling"],
        ref[("turn", 1.0)]["settling"]))
    leads = list(base_x[1][len(SPACE):]) if base_x is not None else \
        [math.log10(3.0), math.log10(1.0)]
    starts = [(c, order, tuple(x) + tuple(leads[:len(REFINE_SPACE)]) if len(x) == len(SPACE) else tuple(x))
              for c, order, x in found]

    def refine(item):
        c, order, x0 = item
        best = {"cost": float("inf"), "x": x0}

        def f(x):
            x = np.clip(x, [b[0] for b in rbounds], [b[1] for b in rbounds])
            cost = sim_cost(to_args(candidate_overrides(x, order)), a.base, a, ref)
            if cost < best["cost"]:
                best.update(cost=cost, x=x)
            return cost
        minimize(f, np.array(x0), method="Nelder-Mead",
                 options={"maxfev": a.refine_evals, "xatol": 0.01, "fatol": 1e-3, "initial_simplex":
                          np.vstack([x0] + [np.array(x0) + 0.15 * np.eye(len(x0))[i] for i in range(len(x0))])})
        return best["cost"], order, tuple(best["x"])

    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        refined = sorted(pool.map(refine, starts), key=lambda r: r[0])
    for c, order, x in refined:
        o = candidate_overrides(x, order)
        print("  p %d sim cost %.3f: tau %.4g k_mu %.4g k_a %.4g var_mu %s var_y %s max_action_lead %.3g "
              "max_action_lead_turn %.3g" % (order, c, o["tau"], o["k_mu"], o["k_a"], yaml_list(o["var_mu"]),
                                             yaml_list(o["var_y"]), o["max_action_lead"], o["max_action_lead_turn"]))
    c, order, x = refined[0]
    winner = candidate_overrides(x, order)
    args = to_args(winner)

    print("== verification, noisy sensors, against the stock controller ==")
    print("  %-10s %-22s %-22s %-8s %-8s" % ("step", "AIC rise/settle/os%/sse%", "stock rise/settle/os%",
                                             "rise x", "settle x"))
    ok = True
    for v in [0.1] + STEPS:
        m = sim_step(args, v, a.base, noise=True)
        s = sim_step([], v, a.base, noise=True, controller="stock")
        sse = 100.0 * abs(m["sse"] or 0.0) / v
        print("  %-10s %-22s %-22s %-8s %-8s" % (
            "%.1f m/s" % v, "%s/%s/%s/%.2f" % (fmt(m["rise"]), fmt(m["settling"]), fmt(m["overshoot"], "%.1f"), sse),
            "%s/%s/%s" % (fmt(s["rise"]), fmt(s["settling"]), fmt(s["overshoot"], "%.1f")),
            fmt(m["rise"] / s["rise"] if m["rise"] and s["rise"] else None, "%.2f"),
            fmt(m["settling"] / s["settling"] if m["settling"] and s["settling"] else None, "%.2f")))
        if not m["settled"] or m["runaways"]:
            ok = False
    m = sim_step(args, 1.0, a.base, noise=True, channel="angular", hold=8.0)
    s = ref[("turn", 1.0)]
    print("  %-10s %-22s %-22s %-8s %-8s" % (
        "1 rad/s", "%s/%s/%s" % (fmt(m["rise"]), fmt(m["settling"]), fmt(m["overshoot"], "%.1f")),
        "%s/%s/%s" % (fmt(s["rise"]), fmt(s["settling"]), fmt(s["overshoot"], "%.1f")),
        fmt(m["rise"] / s["rise"] if m["rise"] and s["rise"] else None, "%.2f"),
        fmt(m["settling"] / s["settling"] if m["settling"] and s["settling"] else None, "%.2f")))
    print("  robustness (0.5 m/s step, ideal sensors): wheel-loop latency and torque +-20 %")
    for sets in ([], ["motor.command_delay=0.0939"], ["motor.command_delay=0.1409"],
                 ["motor.max_torque=3.2", "motor.proportional_limit=0.78"],
                 ["motor.max_torque=4.8", "motor.proportional_limit=1.17"]):
        m = sim_step(args, 0.5, a.base, plant_sets=sets)
        print("    %-50s rise %s settle %s overshoot %s" % (" ".join(sets) or "identified plant", fmt(m["rise"]),
                                                            fmt(m["settling"]), fmt(m["overshoot"], "%.1f")))
        ok = ok and m["settled"] and not m["runaways"]

    if a.write:
        write_yaml(a.write, a.base, winner, plant, refined[0][0], a)
        print("wrote %s" % a.write)
    print("aic_tune: %.0f s" % (time.time() - t_start))
    return 0 if ok else 1


def write_yaml(path, base, winner, plant, cost, a, stamp=None):
    """The base YAML with the tuned keys replaced in place (comments kept) and a derivation line
    (``stamp``, or the model stages' one)."""
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
    stamp = stamp or ("# tuned by aic_tune.py: wheel loop K %.3f, T_p %.4f s, delay %.4f s; overshoot <= %g %%, spectral "
             "radius <= %g at +-%d %% gain and delay; simulator cost %.3f" % (
                 plant["gain"], plant["time_constant"], plant["delay"], a.overshoot, a.max_radius,
                 round(100 * a.robust), cost))
    # after the header comment block
    i = 0
    while i < len(out) and out[i].startswith("#"):
        i += 1
    out.insert(i, stamp)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    sys.exit(main())
