"""aic_tune.py: model-based tuning of the active inference controller on the simulated Jackal.

Three stages, all reproducible from this command and the repository's plant:

1. Identify the wheel loop. Open-loop steps of the wheel commands on the plant core
   (`closed_loop_run --controller open`: the MCU model of sim/config/plant.yaml, no controller)
   around an operating point, and a least-squares fit (scipy.optimize.least_squares) of a
   first-order-plus-dead-time model  K exp(-d s) / (T_p s + 1)  to the wheel-odometry speed.
2. Search on the model. The dual-rate state-space model of the controller with that plant
   (`aic_predict`, jackal_aic::analysis::ClosedLoopModel; doc/active_inference.md, "State-space model for
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
defaults are the code's (recommendedAicParams(), src/params/aic_params.cpp); adopting a winner as the
default means writing its values there.

--driving: instead of the three stages, tune for real driving from the base config: a bounded
Nelder-Mead (on the unit box, scipy) over DRIVING_SPACE (the gains, the anti-windup lead, the
reference model, the action prior and the goal's look-ahead; generalized_goal on, the turn lead
off), scored by jackal_aic_tools.track.driving.cost: the tracking benchmark (sim/profiles/*.csv) over
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
import csv
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

from ..common import cli, closed_loop
from ..common.tables import fmt
from ..track import driving
from .tune_cost import model_cost, plant_corners, sim_cost, stock_reference
from .tune_space import REFINE_SPACE, SPACE, base_vector, candidate_overrides, log_bounds, model_stamp, \
    to_args, write_yaml, yaml_list

STEPS = [0.3, 0.5, 1.0]  # m/s: the verification's steps (0.1 reported too)


def fit_fopdt(t, u, y, h=1e-3):
    """Least-squares fit of a first-order-plus-dead-time model K exp(-d s) / (T_p s + 1) to a
    response: t [s] sample times (increasing), u the input (piecewise constant between samples),
    y the output, 1-D arrays of one length; h [s] the simulation step. The dead time is searched on
    a 2 ms grid from 0 to 0.25 s, gain (0.5 ... 1.5) and time constant (0.002 ... 1 s) by
    scipy.optimize.least_squares at each. Returns (gain, time_constant [s], delay [s], residuals
    at t)."""
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
    return k, tp, d, fun


def identify_plant(tool, low, high, period=2.0, plant_config=None):
    """FOPDT fit (fit_fopdt) of the open-loop wheel loop on a square wave low <-> high [m/s]
    (closed_loop_run --controller open; tool: cli.Tool). Returns dict gain, time_constant [s],
    delay [s], rms [m/s], square (low, high). Raises RuntimeError when the run fails."""
    tmp = tempfile.mkdtemp(prefix="aic_tune_")
    path = os.path.join(tmp, "open.csv")
    args = ["--controller", "open", "--square", str(low), str(high), "--period", str(period), "--cycles", "2",
            "--rest", "2.0", closed_loop.KEEP_GOING]
    if plant_config:
        args += ["--config", plant_config]
    cli.run_json_tool([tool.exe("closed_loop_run")] + args + ["--csv", path])
    with open(path) as f:
        rows = [r for r in csv.DictReader(f) if float(r["t"]) >= 0.0]
    t = np.array([float(r["t"]) for r in rows])
    u = np.array([float(r["command"]) for r in rows])
    y = np.array([float(r["v_odom"]) for r in rows])
    k, tp, d, fun = fit_fopdt(t, u, y)
    rms = float(np.sqrt(np.mean(fun ** 2)))
    return {"gain": float(k), "time_constant": float(tp), "delay": float(d), "rms": rms,
            "square": (low, high)}


class Predictor(object):
    """One aic_predict process (the state-space model's 0.5 m/s step of a candidate); one caller at
    a time. Call it with (overrides: KEY=VALUE strings, plant: dict gain, time_constant [s],
    delay [s]) for its JSON answer (dict ok, stable, rise, settling, overshoot, spectral_radius)."""

    def __init__(self, tool, base, target=0.5):
        self.p = subprocess.Popen([tool.exe("aic_predict"), base, "--target", str(target), "--duration", "3"],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    def __call__(self, overrides, plant):
        import json
        line = " ".join(overrides + ["plant.%s=%.6g" % (k, v) for k, v in plant.items()])
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        return json.loads(self.p.stdout.readline())

    def close(self):
        """End the process."""
        self.p.stdin.close()
        self.p.wait()


class StepRunner(object):
    """Steps on the plant core (closed_loop_run) with the controller YAML ``base`` as the AIC's."""

    def __init__(self, tool, base):
        self.exe = tool.exe("closed_loop_run")
        self.base = base

    def __call__(self, overrides, v, noise=False, channel="linear", controller="aic", plant_sets=(), hold=3.0):
        """One step from rest to v (m/s, or rad/s on the angular channel) on the plant core, held
        ``hold`` s: a dict of runaways, max |v|, and the measured metrics (rise, settling [s],
        overshoot [%], sse [m/s or rad/s], settled). overrides: the AIC's KEY=VALUE strings;
        plant_sets: plant KEY=VALUE overrides (e.g. sensors.seed=3 for another noise draw with
        noise=True). Raises RuntimeError when the tool fails."""
        # A diverging candidate is a cost (its runaways), not an error: KEEP_GOING.
        args = ["--controller", controller, "--step", str(v), "--hold", str(hold), "--channel", channel,
                closed_loop.KEEP_GOING]
        if controller == "aic":
            args += ["--aic-config", self.base]
            for o in overrides:
                args += ["--aic-set", o]
        for s in plant_sets:
            args += ["--set", s]
        if noise:
            args += ["--noise"]
        r = cli.run_json_tool([self.exe] + args)
        seg = r["segments"][0]
        return {"runaways": r["runaways"], "max": r["max_abs_speed"], **seg["measured"]}


def run(a, tool):
    """The three stages and the verification (a: parsed arguments of aic_tune.py, tool: cli.Tool).
    Returns the exit status."""
    t_start = time.time()
    bounds = log_bounds(SPACE)
    rbounds = bounds + log_bounds(REFINE_SPACE)
    base_x = base_vector(tool.config([a.base]))
    if a.skip_model:
        if base_x is None:
            print("aic_tune: --skip-model needs a base config inside the search space", file=sys.stderr)
            return 1
        plant = {"gain": float("nan"), "time_constant": float("nan"), "delay": float("nan")}
        found = [(float("nan"), base_x[0], base_x[1])]
    else:
        plant, found = model_stages(a, tool, bounds, base_x)
    return refine_and_verify(a, tool, plant, found, rbounds, base_x, t_start)


def model_stages(a, tool, bounds, base_x):
    """Stages 1 and 2: identify the wheel loop and search on the state-space model (a: parsed
    arguments, tool: cli.Tool, bounds: log10 bounds of SPACE, base_x: base_vector() of a.base). Returns (plant
    dict gain [-] / time_constant [s] / delay [s], list of (model cost, order, x) starts for the
    refinement, the base config last)."""
    print("== 1. wheel loop, open loop on the plant core (first order + dead time) ==")
    plants = [identify_plant(tool, 0.25, 0.35), identify_plant(tool, 0.45, 0.55)]
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
        pred = Predictor(tool, a.base)
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
    pred = Predictor(tool, a.base)
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


def refine_and_verify(a, tool, plant, found, rbounds, base_x, t_start):
    """Stage 3 and the verification: Nelder-Mead (scipy) on sim_cost from every start in found
    (model candidates get the base config's leads), the verification table with noisy sensors
    against the stock controller, the robustness table, and --write (a: parsed arguments, tool:
    cli.Tool). Returns the exit status."""
    step = StepRunner(tool, a.base)
    print("== 3. refinement on the simulated Jackal (Nelder-Mead on closed_loop_run) ==")
    ref = stock_reference(a, step)
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
            cost = sim_cost(to_args(candidate_overrides(x, order)), a, ref, step)
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
        m = step(args, v, noise=True)
        s = step([], v, noise=True, controller="stock")
        sse = 100.0 * abs(m["sse"] or 0.0) / v
        print("  %-10s %-22s %-22s %-8s %-8s" % (
            "%.1f m/s" % v, "%s/%s/%s/%.2f" % (fmt(m["rise"]), fmt(m["settling"]), fmt(m["overshoot"], "%.1f"), sse),
            "%s/%s/%s" % (fmt(s["rise"]), fmt(s["settling"]), fmt(s["overshoot"], "%.1f")),
            fmt(m["rise"] / s["rise"] if m["rise"] and s["rise"] else None, "%.2f"),
            fmt(m["settling"] / s["settling"] if m["settling"] and s["settling"] else None, "%.2f")))
        if not m["settled"] or m["runaways"]:
            ok = False
    m = step(args, 1.0, noise=True, channel="angular", hold=8.0)
    s = ref[("turn", 1.0)]
    print("  %-10s %-22s %-22s %-8s %-8s" % (
        "1 rad/s", "%s/%s/%s" % (fmt(m["rise"]), fmt(m["settling"]), fmt(m["overshoot"], "%.1f")),
        "%s/%s/%s" % (fmt(s["rise"]), fmt(s["settling"]), fmt(s["overshoot"], "%.1f")),
        fmt(m["rise"] / s["rise"] if m["rise"] and s["rise"] else None, "%.2f"),
        fmt(m["settling"] / s["settling"] if m["settling"] and s["settling"] else None, "%.2f")))
    print("  robustness (0.5 m/s step, ideal sensors): wheel-loop latency and torque +-20 %")
    for sets in ([], ["motor.command_delay=0.0939"], ["motor.command_delay=0.1409"],
                 driving.TORQUE_MINUS_20, driving.TORQUE_PLUS_20):
        m = step(args, 0.5, plant_sets=sets)
        print("    %-50s rise %s settle %s overshoot %s" % (" ".join(sets) or "identified plant", fmt(m["rise"]),
                                                            fmt(m["settling"]), fmt(m["overshoot"], "%.1f")))
        ok = ok and m["settled"] and not m["runaways"]

    if a.write:
        write_yaml(a.write, a.base, winner, model_stamp(plant, refined[0][0], a))
        print("wrote %s" % a.write)
    print("aic_tune: %.0f s" % (time.time() - t_start))
    return 0 if ok else 1
