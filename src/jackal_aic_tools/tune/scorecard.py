"""aic_scorecard.py: the tuning acceptance set, the AIC against the stock controller, in one command.

Runs every profile on the simulated Jackal's plant core with `closed_loop_run` (headless, faster
than real time, the plant YAML sim/config/plant.yaml, noisy sensors), once with the AIC
(--aic-config) and once with the stock controller, and prints one table per criterion with the
figures, the bound and PASS / FAIL. All metrics are of the measured velocity (wheel odometry, or
the gyro on the angular channel; thesis ch. 5: rise 10-90 %, settling into +-5 % for good,
overshoot in % of the step, steady-state error the mean over the last 0.5 s).

Criteria (doc/experiments.md, 'Tuning'):
  1. 0.5 m/s step from rest: AIC settling <= 0.8 x stock, AIC rise <= 0.7 x stock,
     overshoot <= 5 %, steady-state error <= 1 % (0.1, 0.3 and 1.0 m/s reported, not judged).
  2. The same 0.5 m/s criterion for every noise seed of --seeds (plant key sensors.seed).
  3. 1 rad/s yaw-rate step from rest (turn in place, 8 s hold): AIC settling <= stock
     (0.5 and 2 rad/s reported, not judged).
  4. Square waves 0.1 <-> 0.5, 0.1 <-> 1.0, 0.2 <-> 1.2 m/s (period 5 s, 2 cycles): every
     transition, the lead-in from rest included, overshoots <= 10 % and settles.
  5. Robustness: the 0.5 m/s step with the plant's latency (motor.command_delay) and motor
     torque (motor.max_torque with motor.proportional_limit) each varied by +-20 %: no runaway,
     settled within the 3 s hold, overshoot <= 10 %.
  6. Driving (--driving, jackal_aic_tools.track.driving; doc/experiments.md, 'Driving acceptance'):
     the step table (0.1 and 0.5 m/s, the 1 rad/s turn, both channels of the 0.5 m/s + 0.5 rad/s
     arc: settling AIC / stock and overshoot against their bounds), the turn-deficit holds,
     stability on the varied plants, and the tracking table over every profile x plant variant
     (RMS error of vx and wz, AIC / stock) with its geometric mean; beside it the latency floor
     and the ideal controller, and the plant-limited channels (the ideal controller above
     plant_limits.PLANT_LIMIT_RATIO x the floor) apart, with their reasons: the per-pair bound and
     the geometric mean judge the plant-following channels; and the honest belief of every
     tracking run (the AIC's steady mean |belief - truth| per channel within
     driving.BELIEF_BOUND, BELIEF_LIMITED_BOUND on a plant-limited channel). Judged with the rest;
     beside stock and the floor the classical peer (closed_loop_run --controller pi, --pi-config)
     on every tracking pair, reported, not judged.

Usage:
  aic_scorecard.py [--aic-config FILE] [--pi-config FILE] [--plant-config FILE] [--seeds S ...]
                   [--jobs N] [--driving] [--json FILE]

  e.g.  scripts/aic_scorecard.py --aic-config config/default.yaml --jobs 2 --json /tmp/score.json

Takes ~3 s on 2 cores; with --driving about a minute, or minutes where the ideal controller runs (2.6
min of CPU: it learns each tracking pair over 8 runs): its results are kept in doc/results/ideal_runs.json
(written with --doc; jackal_aic_tools.track.ideal_cache) and used while the plant's and the tool's sources are
unchanged; stderr says how many were kept and how many run. Exit: 0 when every criterion passes, 1 when one fails, 2 when a run
fails (bad file, tool error).
"""
import os
import sys
from concurrent.futures import ThreadPoolExecutor

from ..common import closed_loop as loop_api
from ..track import driving, ideal_cache

SETTLE_RATIO = 0.8   # AIC / stock settling, 0.5 m/s step
RISE_RATIO = 0.7     # AIC / stock rise, 0.5 m/s step
STEP_OVERSHOOT = 5.0  # [%] 0.5 m/s step
SSE_PCT = 1.0        # [% of the set point] 0.5 m/s step
SQUARE_OVERSHOOT = 10.0  # [%] every square-wave transition
ROBUST_OVERSHOOT = 10.0  # [%] 0.5 m/s step on the varied plant
STEPS = [0.1, 0.3, 0.5, 1.0]  # m/s
TURNS = [0.5, 1.0, 2.0]  # rad/s
SQUARES = [(0.1, 0.5), (0.1, 1.0), (0.2, 1.2)]  # m/s
# Plant variations: +-20 % of sim/config/plant.yaml's wheel loop (command_delay 0.1187 s; the
# torques: driving.TORQUE_MINUS_20 / TORQUE_PLUS_20).
ROBUST = [
    ("identified plant", []),
    ("command_delay -20 % (0.0950 s)", ["motor.command_delay=0.09496"]),
    ("command_delay +20 % (0.1424 s)", ["motor.command_delay=0.1424"]),
    ("torques -20 %", driving.TORQUE_MINUS_20),
    ("torques +20 %", driving.TORQUE_PLUS_20),
]


def closed_loop(exe, controller, profile, aic_config, plant_config, plant_sets=(), overlays=()):
    """One `closed_loop_run` (the executable ``exe``) of `controller` (aic or stock) with the
    profile arguments `profile` (list of strings), noisy sensors, plant overlay files `overlays`,
    then plant KEY=VALUE overrides `plant_sets`.
    A diverged run is judged by the criteria, not an error (loop_api.KEEP_GOING).
    Returns the tool's JSON result as a dict; raises RuntimeError when the tool fails."""
    return loop_api.run(exe, controller, profile, aic_config, (), plant_config, overlays, plant_sets, noise=True,
                           keep_going=True).result


def step_profile(v, channel="linear", hold=3.0):
    """closed_loop_run arguments of a step from rest to v [m/s, or rad/s on the angular channel]."""
    return ["--step", str(v), "--channel", channel, "--hold", str(hold)]


def ratio(a, b):
    """a / b, or None when either is missing (a step that never rose or settled)."""
    return a / b if a is not None and b else None


def verdict(ok):
    """PASS / FAIL for a bool, '' (reported, not judged) for None."""
    return "" if ok is None else ("PASS" if ok else "FAIL")


def jobs(seeds):
    """The runs of criteria 1-5: a list of (key, controller, profile arguments, plant KEY=VALUE
    sets); seeds: the noise seeds, without repeats, the first the one of every other run."""
    out = []
    for v in STEPS:
        for c in ("aic", "stock"):
            out.append((("step", v, seeds[0], c), c, step_profile(v), ["sensors.seed=%d" % seeds[0]]))
    for s in seeds[1:]:
        for c in ("aic", "stock"):
            out.append((("step", 0.5, s, c), c, step_profile(0.5), ["sensors.seed=%d" % s]))
    for w in TURNS:
        for c in ("aic", "stock"):
            out.append((("turn", w, c), c, step_profile(w, "angular", 8.0), []))
    for lo, hi in SQUARES:
        for c in ("aic", "stock"):
            out.append((("square", lo, hi, c), c, ["--square", str(lo), str(hi), "--period", "5", "--cycles", "2"],
                        []))
    for name, sets in ROBUST:
        for c in ("aic", "stock"):
            out.append((("robust", name, c), c, step_profile(0.5), sets))
    return out


def judge(results, seeds):
    """Criteria 1-5 of the results of jobs(seeds) (``results``: key -> closed_loop_run's JSON
    dict). Returns (criteria, ok): criteria a dict of criterion name (steps, seeds, turns,
    squares, robustness) -> list of row dicts (figures in s and %, the verdict "pass": True,
    False, or None when reported, not judged), ok True when every judged row passes."""

    def seg(key, i=0):
        return results[key]["segments"][i]["measured"]

    crit = {}
    all_ok = True

    def mark(ok):
        nonlocal all_ok
        if ok is False:
            all_ok = False
        return ok

    def step_row(v, seed, judged):
        m, s = seg(("step", v, seed, "aic")), seg(("step", v, seed, "stock"))
        runaway = results[("step", v, seed, "aic")]["runaways"] > 0
        sse = 100.0 * abs(m["sse"]) / v if m["sse"] is not None else None
        rr, sr = ratio(m["rise"], s["rise"]), ratio(m["settling"], s["settling"])
        ok = None
        if judged:
            ok = mark(bool(m["settled"] and not runaway and rr is not None and sr is not None and rr <= RISE_RATIO
                            and sr <= SETTLE_RATIO and (m["overshoot"] or 0.0) <= STEP_OVERSHOOT
                            and sse is not None and sse <= SSE_PCT))
        return {"step": v, "seed": seed, "aic_rise": m["rise"], "aic_settling": m["settling"],
                "aic_overshoot": m["overshoot"], "aic_sse_pct": sse, "stock_rise": s["rise"],
                "stock_settling": s["settling"], "stock_overshoot": s["overshoot"], "rise_ratio": rr,
                "settling_ratio": sr, "pass": ok}

    crit["steps"] = [step_row(v, seeds[0], v == 0.5) for v in STEPS]
    crit["seeds"] = [step_row(0.5, s, True) for s in seeds]
    turns = []
    for w in TURNS:
        m, s = seg(("turn", w, "aic")), seg(("turn", w, "stock"))
        ok = None
        if w == 1.0:
            ok = mark(bool(m["settled"] and m["settling"] is not None and s["settling"] is not None
                            and m["settling"] <= s["settling"]))
        turns.append({"step": w, "aic_rise": m["rise"], "aic_settling": m["settling"], "aic_overshoot": m["overshoot"],
                      "stock_rise": s["rise"], "stock_settling": s["settling"], "stock_overshoot": s["overshoot"],
                      "pass": ok})
    crit["turns"] = turns
    squares = []
    for lo, hi in SQUARES:
        r, rs = results[("square", lo, hi, "aic")], results[("square", lo, hi, "stock")]
        for i, sg in enumerate(r["segments"]):
            m = sg["measured"]
            ms = rs["segments"][i]["measured"]
            ok = mark(bool(m["settled"] and r["runaways"] == 0 and (m["overshoot"] or 0.0) <= SQUARE_OVERSHOOT))
            squares.append({"square": [lo, hi], "from": sg["initial"], "to": sg["target"], "aic_rise": m["rise"],
                            "aic_settling": m["settling"], "aic_overshoot": m["overshoot"],
                            "stock_settling": ms["settling"], "stock_overshoot": ms["overshoot"], "pass": ok})
    crit["squares"] = squares
    robust = []
    for name, sets in ROBUST:
        r = results[("robust", name, "aic")]
        m, s = r["segments"][0]["measured"], seg(("robust", name, "stock"))
        ok = mark(bool(m["settled"] and r["runaways"] == 0 and (m["overshoot"] or 0.0) <= ROBUST_OVERSHOOT))
        robust.append({"plant": name, "set": sets, "aic_rise": m["rise"], "aic_settling": m["settling"],
                       "aic_overshoot": m["overshoot"], "stock_settling": s["settling"], "pass": ok})
    crit["robustness"] = robust
    return crit, all_ok


def judge_driving(ev, crit):
    """Criterion 6: the driving set's evaluation ``ev`` (jackal_aic_tools.track.driving.evaluate) added
    to ``crit`` as driving_steps, driving_deficit, driving_robust, driving_tracking, driving_gmean
    (over the plant-following channels, judged against driving.TRACK_GMEAN_BOUND),
    driving_floor_gmean, driving_aic_floor_gmean, driving_stock_floor_gmean (over the same),
    driving_limited_gmean (over the plant-limited channels; reported), driving_arc_prior (the
    arc's yaw overshoot against the model's initial separation; reported) and, where the classical
    peer ran, driving_aic_peer_gmean, driving_peer_floor_gmean, driving_peer_stock_gmean (over the
    plant-following channels; reported). Returns True when every
    judged row passes (the tracking rows' honest belief, belief_pass, end-of-profile heading,
    heading_pass, and stops, stop_pass, included)."""
    for part in ("steps", "deficit", "robust", "tracking"):
        crit["driving_" + part] = ev[part]
    gm = dict(ev["gmean"], bound=driving.TRACK_GMEAN_BOUND)
    gm["pass"] = gm["all"] <= driving.TRACK_GMEAN_BOUND
    crit["driving_gmean"] = gm
    for name in ("floor_gmean", "aic_floor_gmean", "stock_floor_gmean", "limited_gmean", "arc_prior",
                 "aic_peer_gmean", "peer_floor_gmean", "peer_stock_gmean"):
        if name in ev:
            crit["driving_" + name] = ev[name]
    verdicts = [gm["pass"]] + [r["pass"] for part in ("steps", "deficit", "robust", "tracking") for r in ev[part]]
    verdicts += [r.get("belief_pass") for r in ev["tracking"]] + [r.get("heading_pass") for r in ev["tracking"]]
    verdicts += [r.get("stop_pass") for r in ev["tracking"]]
    all_ok = not any(ok is False for ok in verdicts)
    return all_ok


def scorecard(a, tool):
    """Run every profile (a: parsed arguments of aic_scorecard.py, tool: cli.Tool) and return
    (criteria, ok): criteria is a dict of criterion name -> list of row dicts (figures in s, %,
    and verdicts), ok True when every judged row passes; with a.driving the classical peer runs
    beside the stock controller with a.pi_config (its YAML). Raises RuntimeError when a run fails."""
    seeds = list(dict.fromkeys(a.seeds))
    exe = tool.exe("closed_loop_run")
    job_list = jobs(seeds)
    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        results = dict(zip([j[0] for j in job_list],
                           pool.map(lambda j: closed_loop(exe, j[1], j[2], a.aic_config, a.plant_config, j[3],
                                                          a.plant_overlay), job_list)))
    crit, ok = judge(results, seeds)
    if a.driving:
        kept = ideal_cache.IdealCache(tool.root)
        runner = driving.Runner(exe, a.aic_config, a.plant_config, jobs=a.jobs, ideal_cache=kept,
                                peer_config=a.pi_config)
        ok = judge_driving(driving.evaluate(runner, tool.root, peer=True), crit) and ok
        print("aic_scorecard: ideal controller: %s (%s): %d kept, %d run"
              % (os.path.relpath(kept.path, tool.root), kept.status, kept.hits, kept.misses), file=sys.stderr)
        if getattr(a, "doc", False):
            kept.save()
    return crit, ok
