"""aic_tune.py --driving: tune the controller for real driving from a base configuration.

A bounded Nelder-Mead (on the unit box, scipy) over tune_space.DRIVING_SPACE (UNBIASED_DRIVING_SPACE
from a base with belief_model: unbiased), scored by
jackal_aic_tools.track.driving.cost on the plant variants --driving-variants; prints each improvement
and the winner's acceptance figures over every variant, and writes the winner (--write)."""
import os
import time

import numpy as np
from scipy.optimize import minimize

from ..common.tables import fmt
from ..track import driving
from .tune_space import driving_space, driving_unit, driving_values, to_args, write_yaml


def run(a, tool):
    """--driving: Nelder-Mead over the base config's driving_space() from it, scored by
    jackal_aic_tools.track.driving.cost on a.driving_variants; writes the winner (a.write). a: parsed
    arguments of aic_tune.py, tool: cli.Tool. Returns the exit status."""
    t_start = time.time()
    base = tool.config([a.base])
    space = driving_space(base)
    exe = tool.exe("closed_loop_run")
    plant_config = tool.path("sim", "config", "plant.yaml")
    variants = [v if v == "default" else os.path.abspath(v) for v in a.driving_variants]
    best = {"cost": float("inf"), "values": None}

    def evaluate(values, variant_list, ideal=False):
        # The search's cost uses neither the ideal controller (only the winner's report runs it) nor
        # the scorecard's arc-prior table (driving.cost).
        runner = driving.Runner(exe, a.base, plant_config, to_args(values), a.jobs)
        runner._stock = stock_cache
        return driving.evaluate(runner, tool.root, variants=variant_list, ideal=ideal, arc_prior_table=False)

    stock_cache = {}
    n = [0]

    def f(u):
        values = driving_values(u, base["var_y"], space)
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

    u0 = driving_unit(base, space)
    step = np.full(len(u0), 0.15)
    simplex = [u0] + [np.clip(u0 + np.eye(len(u0))[i] * np.where(u0[i] > 0.5, -step[i], step[i]), 0, 1)
                      for i in range(len(u0))]
    minimize(f, u0, method="Nelder-Mead", options={"maxfev": a.refine_evals, "initial_simplex": np.array(simplex),
                                                     "xatol": 1e-3, "fatol": 1e-4})
    print("== winner (cost %.4f), acceptance over every variant ==" % best["cost"])
    ev = evaluate(best["values"], None, ideal=True)
    for r in ev["steps"]:
        print("  %-13s settling AIC / stock %s (bound %.2f), overshoot %s %%" % (
            r["case"], fmt(r["ratio"], "%.2f"), r["bound"], fmt(r["aic_overshoot"], "%.1f")))
    for r in ev["deficit"]:
        print("  turn deficit %.1f rad/s: AIC error %+.4f rad/s, stock %+.4f rad/s" % (
            r["command"], r["aic_error"], r["stock_error"]))
    print("  tracking (plant-following channels): geometric mean AIC / stock vx %.3f, wz %.3f; pairs above %.2f: "
          "%d of %d" % (
        ev["gmean"]["vx"], ev["gmean"]["wz"], driving.TRACK_PAIR_BOUND,
        sum(1 for r in ev["tracking"] if not r["pass"]), len(ev["tracking"])))
    print("  honest belief (steady |belief - truth| within %g, %g where plant-limited): %d of %d tracking runs" % (
        driving.BELIEF_BOUND, driving.BELIEF_LIMITED_BOUND, sum(1 for r in ev["tracking"] if r["belief_pass"]),
        len(ev["tracking"])))
    judged = [r for r in ev["tracking"] if r["heading_judged"]]
    print("  end-of-profile heading (|AIC| within the stock controller's + %g rad): %d of %d judged runs" % (
        driving.HEADING_MARGIN, sum(1 for r in judged if r["heading_pass"]), len(judged)))
    if a.write:
        write_yaml(a.write, a.base, best["values"],
                   "# tuned by aic_tune.py --driving (%d evaluations, variants %s): driving cost %.4f" % (
                       n[0], " ".join(os.path.basename(v) for v in a.driving_variants), best["cost"]))
        print("wrote %s (%.0f s)" % (a.write, time.time() - t_start))
    return 0
