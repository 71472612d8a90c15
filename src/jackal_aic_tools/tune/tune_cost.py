"""The costs aic_tune.py minimises: the state-space model's score of a candidate (model_cost)
and the simulator's score against the stock controller (sim_cost), lower is better.

Neither runs a tool itself: model_cost asks a predictor (an aic_predict process, or any callable
with its interface), sim_cost and stock_reference a step runner (closed_loop_run, or any callable
with the interface of jackal_aic_tools.tune.tune.StepRunner), so that both can be checked on figures
whose cost is known."""
from . import tune_space

COST_STEPS = [0.1, 0.3, 0.5, 1.0]  # m/s: the refinement's steps (overshoot bound on all)
# Plant latency varied by +-20 % of sim/config/plant.yaml's identified 0.1174 s.
ROBUST_DELAYS = ["motor.command_delay=0.0939", "motor.command_delay=0.1409"]


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
    for a candidate that is invalid or unstable at any corner.

    predictor(overrides, plant) -> dict ok, stable, rise [s], settling [s] (None: not settled,
    counted as 5 s), overshoot [%], spectral_radius (aic_predict's answer); corners:
    plant_corners(), the nominal plant first; a: .overshoot [%], .max_radius."""
    o = tune_space.to_args(tune_space.candidate_overrides(x, order))
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


def stock_reference(a, step):
    """The stock controller's figures the simulator cost is relative to, noisy sensors: dict
    ("step", v, seed) -> metrics of the COST_STEPS (first seed of a.seeds; 0.5 m/s for every
    seed) and ("turn", 1.0) -> the 1 rad/s yaw-rate step (8 s hold). step: the step runner
    (jackal_aic_tools.tune.tune.StepRunner's interface)."""
    ref = {}
    for v in COST_STEPS:
        ref[("step", v, a.seeds[0])] = step([], v, noise=True, controller="stock",
                                            plant_sets=["sensors.seed=%d" % a.seeds[0]])
    for seed in a.seeds[1:]:
        ref[("step", 0.5, seed)] = step([], 0.5, noise=True, controller="stock",
                                        plant_sets=["sensors.seed=%d" % seed])
    ref[("turn", 1.0)] = step([], 1.0, noise=True, controller="stock", channel="angular", hold=8.0)
    return ref


def settle_or_penalty(m, v):
    """Settling time [s] of metrics m of a step of size v, or, when it did not settle within the
    hold, 3 s + its final relative error (graded, so that the search can move)."""
    if m["settled"] and m["settling"] is not None:
        return m["settling"]
    return 3.0 + abs(m["sse"] if m["sse"] is not None else v) / abs(v)


def sim_cost(overrides, a, ref, step):
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
    search can cross it.

    overrides: KEY=VALUE strings; a: .seeds, .overshoot, .robust_overshoot, .turn_weight,
    .turn_ratio; step(overrides, v, noise=, channel=, plant_sets=, hold=) -> dict runaways,
    rise, settling [s], overshoot [%], sse, settled (jackal_aic_tools.tune.tune.StepRunner)."""
    s0 = a.seeds[0]
    m = {}
    for v in COST_STEPS:
        m[(v, s0)] = step(overrides, v, noise=True, plant_sets=["sensors.seed=%d" % s0])
    for seed in a.seeds[1:]:
        m[(0.5, seed)] = step(overrides, 0.5, noise=True, plant_sets=["sensors.seed=%d" % seed])
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
        r = step(overrides, 0.5, plant_sets=[sets])
        if r["runaways"]:
            return 10.0
        if not r["settled"]:
            total += 2.0
        total += 0.05 * max(0.0, (r["overshoot"] or 0.0) - a.robust_overshoot)
    if a.turn_weight > 0.0:
        r = step(overrides, 1.0, noise=True, channel="angular", hold=8.0)
        if r["runaways"]:
            return 10.0
        total += a.turn_weight * max(0.0, settle_or_penalty(r, 1.0) / ref[("turn", 1.0)]["settling"] - a.turn_ratio)
        total += 0.02 * max(0.0, (r["overshoot"] or 0.0) - 10.0)
    return total
