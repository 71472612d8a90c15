#!/usr/bin/env python3
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
  6. Driving (--driving, jackal_aic_tools.driving; doc/experiments.md, 'Driving acceptance'):
     the step table (0.1 and 0.5 m/s, the 1 rad/s turn, both channels of the 0.5 m/s + 0.5 rad/s
     arc: settling AIC / stock and overshoot against their bounds), the turn-deficit holds,
     stability on the varied plants, and the tracking table over every profile x plant variant
     (RMS error of vx and wz, AIC / stock) with its geometric mean. Judged with the rest.

Usage:
  aic_scorecard.py [--aic-config FILE] [--plant-config FILE] [--seeds S ...] [--jobs N]
                   [--driving] [--json FILE]

  e.g.  scripts/aic_scorecard.py --aic-config config/default.yaml --jobs 2 --json /tmp/score.json

Takes ~3 s on 2 cores, ~40 s with --driving. Exit: 0 when every criterion passes, 1 when one fails, 2 when a run
fails (bad file, tool error).
"""
import argparse
import json
import os
import sys
from concurrent.futures import ThreadPoolExecutor

from jackal_aic_tools import cli

ROOT = cli.source_root(__file__)
_EXE = {}

SETTLE_RATIO = 0.8   # AIC / stock settling, 0.5 m/s step
RISE_RATIO = 0.7     # AIC / stock rise, 0.5 m/s step
STEP_OVERSHOOT = 5.0  # [%] 0.5 m/s step
SSE_PCT = 1.0        # [% of the set point] 0.5 m/s step
SQUARE_OVERSHOOT = 10.0  # [%] every square-wave transition
ROBUST_OVERSHOOT = 10.0  # [%] 0.5 m/s step on the varied plant
STEPS = [0.1, 0.3, 0.5, 1.0]  # m/s
TURNS = [0.5, 1.0, 2.0]  # rad/s
SQUARES = [(0.1, 0.5), (0.1, 1.0), (0.2, 1.2)]  # m/s
# Plant variations: +-20 % of sim/config/plant.yaml's wheel loop (command_delay 0.1187 s,
# max_torque 4 N m, proportional_limit 0.7571 N m).
ROBUST = [
    ("identified plant", []),
    ("command_delay -20 % (0.0950 s)", ["motor.command_delay=0.09496"]),
    ("command_delay +20 % (0.1424 s)", ["motor.command_delay=0.1424"]),
    ("max_torque, proportional_limit -20 %", ["motor.max_torque=3.2", "motor.proportional_limit=0.6057"]),
    ("max_torque, proportional_limit +20 %", ["motor.max_torque=4.8", "motor.proportional_limit=0.9085"]),
]


def closed_loop(controller, profile, aic_config, plant_config, plant_sets=(), overlays=()):
    """One `closed_loop_run` of `controller` (aic or stock) with the profile arguments `profile`
    (list of strings), noisy sensors, plant overlay files `overlays`, then plant KEY=VALUE
    overrides `plant_sets`.
    Returns the tool's JSON result as a dict; raises RuntimeError when the tool fails."""
    if "closed_loop_run" not in _EXE:
        _EXE["closed_loop_run"] = cli.find_executable("closed_loop_run", __file__, "aic_scorecard")
    cmd = [_EXE["closed_loop_run"], "--controller", controller,
           "--noise", "--config", plant_config] + list(profile)
    if controller == "aic":
        cmd += ["--aic-config", aic_config]
    for o in overlays:
        cmd += ["--overlay", o]
    for s in plant_sets:
        cmd += ["--set", s]
    return cli.run_json_tool(cmd)


def step_profile(v, channel="linear", hold=3.0):
    """closed_loop_run arguments of a step from rest to v [m/s, or rad/s on the angular channel]."""
    return ["--step", str(v), "--channel", channel, "--hold", str(hold)]


def ratio(a, b):
    """a / b, or None when either is missing (a step that never rose or settled)."""
    return a / b if a is not None and b else None


def fmt(v, spec="%.3f"):
    """v formatted with spec, '-' for None."""
    return "-" if v is None else spec % v


def verdict(ok):
    """PASS / FAIL for a bool, '' (reported, not judged) for None."""
    return "" if ok is None else ("PASS" if ok else "FAIL")


def table(title, header, rows):
    """Print one criterion's table: title, a header row and rows (lists of strings)."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    print("\n" + title)
    for r in [header] + rows:
        print("  " + "  ".join(str(c).ljust(w) for c, w in zip(r, widths)).rstrip())


def scorecard(a):
    """Run every profile (a: parsed arguments) and return (criteria, ok): criteria is a dict of
    criterion name -> list of row dicts (figures in s, %, and verdicts), ok True when every
    judged row passes."""
    jobs = []  # (key, controller, profile, plant_sets)
    seeds = list(dict.fromkeys(a.seeds))
    for v in STEPS:
        for c in ("aic", "stock"):
            jobs.append((("step", v, seeds[0], c), c, step_profile(v), ["sensors.seed=%d" % seeds[0]]))
    for s in seeds[1:]:
        for c in ("aic", "stock"):
            jobs.append((("step", 0.5, s, c), c, step_profile(0.5), ["sensors.seed=%d" % s]))
    for w in TURNS:
        for c in ("aic", "stock"):
            jobs.append((("turn", w, c), c, step_profile(w, "angular", 8.0), []))
    for lo, hi in SQUARES:
        for c in ("aic", "stock"):
            jobs.append((("square", lo, hi, c), c, ["--square", str(lo), str(hi), "--period", "5", "--cycles", "2"],
                         []))
    for name, sets in ROBUST:
        for c in ("aic", "stock"):
            jobs.append((("robust", name, c), c, step_profile(0.5), sets))
    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        results = dict(zip([j[0] for j in jobs],
                           pool.map(lambda j: closed_loop(j[1], j[2], a.aic_config, a.plant_config, j[3],
                                                          a.plant_overlay), jobs)))

    def seg(key, i=0):
        return results[key]["segments"][i]["measured"]

    crit = {}
    all_ok = True

    def judge(ok):
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
            ok = judge(bool(m["settled"] and not runaway and rr is not None and sr is not None and rr <= RISE_RATIO
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
            ok = judge(bool(m["settled"] and m["settling"] is not None and s["settling"] is not None
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
            ok = judge(bool(m["settled"] and r["runaways"] == 0 and (m["overshoot"] or 0.0) <= SQUARE_OVERSHOOT))
            squares.append({"square": [lo, hi], "from": sg["initial"], "to": sg["target"], "aic_rise": m["rise"],
                            "aic_settling": m["settling"], "aic_overshoot": m["overshoot"],
                            "stock_settling": ms["settling"], "stock_overshoot": ms["overshoot"], "pass": ok})
    crit["squares"] = squares
    robust = []
    for name, sets in ROBUST:
        r = results[("robust", name, "aic")]
        m, s = r["segments"][0]["measured"], seg(("robust", name, "stock"))
        ok = judge(bool(m["settled"] and r["runaways"] == 0 and (m["overshoot"] or 0.0) <= ROBUST_OVERSHOOT))
        robust.append({"plant": name, "set": sets, "aic_rise": m["rise"], "aic_settling": m["settling"],
                       "aic_overshoot": m["overshoot"], "stock_settling": s["settling"], "pass": ok})
    crit["robustness"] = robust
    if a.driving:
        from jackal_aic_tools import driving
        runner = driving.Runner(_EXE["closed_loop_run"], a.aic_config, a.plant_config, jobs=a.jobs)
        ev = driving.evaluate(runner, ROOT)
        for part in ("steps", "deficit", "robust", "tracking"):
            crit["driving_" + part] = ev[part]
        gm = dict(ev["gmean"], bound=driving.TRACK_GMEAN_BOUND)
        gm["pass"] = judge(gm["all"] <= driving.TRACK_GMEAN_BOUND)
        crit["driving_gmean"] = gm
        crit["driving_floor_gmean"] = ev["floor_gmean"]
        for part in ("steps", "deficit", "robust", "tracking"):
            for r in ev[part]:
                judge(r["pass"])
    return crit, all_ok


def print_scorecard(crit, a):
    """Print the tables of scorecard()'s criteria (a: parsed arguments)."""
    print("aic_scorecard: %s against the stock controller, plant %s, noisy sensors (closed_loop_run)"
          % (os.path.relpath(a.aic_config, ROOT) if a.aic_config.startswith(ROOT) else a.aic_config,
             " + ".join(os.path.relpath(f, ROOT) if f.startswith(ROOT) else f
                        for f in [a.plant_config] + a.plant_overlay)))
    hdr = ["step", "seed", "AIC rise/settle/os/sse", "stock rise/settle/os", "rise x", "settle x", "verdict"]

    def step_cells(r):
        return ["%.1f m/s" % r["step"], str(r["seed"]),
                "%s s / %s s / %s %% / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]),
                                                 fmt(r["aic_overshoot"], "%.1f"), fmt(r["aic_sse_pct"], "%.2f")),
                "%s s / %s s / %s %%" % (fmt(r["stock_rise"]), fmt(r["stock_settling"]),
                                         fmt(r["stock_overshoot"], "%.1f")),
                fmt(r["rise_ratio"], "%.2f"), fmt(r["settling_ratio"], "%.2f"), verdict(r["pass"]) or "(reported)"]
    table("1. Steps from rest (0.5 m/s judged: rise x <= %.2f, settle x <= %.2f, overshoot <= %g %%, sse <= %g %%)"
          % (RISE_RATIO, SETTLE_RATIO, STEP_OVERSHOOT, SSE_PCT), hdr, [step_cells(r) for r in crit["steps"]])
    table("2. 0.5 m/s step per noise seed (sensors.seed; same bounds)", hdr, [step_cells(r) for r in crit["seeds"]])
    table("3. Yaw-rate steps from rest, 8 s hold (1 rad/s judged: AIC settle <= stock settle)",
          ["step", "AIC rise/settle/os", "stock rise/settle/os", "settle x", "verdict"],
          [["%.1f rad/s" % r["step"], "%s s / %s s / %s %%" % (fmt(r["aic_rise"], "%.2f"), fmt(r["aic_settling"], "%.2f"),
                                                               fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s s / %s %%" % (fmt(r["stock_rise"], "%.2f"), fmt(r["stock_settling"], "%.2f"),
                                     fmt(r["stock_overshoot"], "%.1f")),
            fmt(ratio(r["aic_settling"], r["stock_settling"]), "%.2f"), verdict(r["pass"]) or "(reported)"]
           for r in crit["turns"]])
    table("4. Square waves, period 5 s, 2 cycles (every transition: settled, overshoot <= %g %%)" % SQUARE_OVERSHOOT,
          ["square", "transition", "AIC rise/settle/os", "stock settle/os", "verdict"],
          [["%.1f <-> %.1f" % tuple(r["square"]), "%.1f -> %.1f m/s" % (r["from"], r["to"]),
            "%s s / %s s / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]), fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s %%" % (fmt(r["stock_settling"]), fmt(r["stock_overshoot"], "%.1f")), verdict(r["pass"])]
           for r in crit["squares"]])
    table("5. Robustness, 0.5 m/s step, plant varied +-20 %% (no runaway, settled, overshoot <= %g %%)"
          % ROBUST_OVERSHOOT,
          ["plant", "AIC rise/settle/os", "stock settle", "verdict"],
          [[r["plant"], "%s s / %s s / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]),
                                                fmt(r["aic_overshoot"], "%.1f")),
            "%s s" % fmt(r["stock_settling"]), verdict(r["pass"])] for r in crit["robustness"]])
    if "driving_steps" in crit:
        print_driving(crit)


def print_driving(crit):
    """Print the driving tables (criterion 6) of scorecard()'s criteria."""
    from jackal_aic_tools import driving
    table("6a. Driving steps at %d phases of the 50 Hz clocks (step %s ms after the rest; the worst phase "
          "judged: settling AIC / stock <= bound, overshoot <= %g %%)"
          % (len(driving.STEP_PHASES), ", ".join("%g" % (1e3 * p) for p in driving.STEP_PHASES),
             driving.STEP_OVERSHOOT),
          ["case", "AIC settle/os (worst)", "stock settle/os", "settle x per phase", "worst", "bound", "verdict"],
          [[r["case"], "%s s / %s %%" % (fmt(r["aic_settling"]), fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s %%" % (fmt(r["stock_settling"]), fmt(r["stock_overshoot"], "%.1f")),
            " ".join(fmt(x, "%.3f") for x in r["ratios"]), fmt(r["ratio"], "%.3f"), "%.2f" % r["bound"],
            verdict(r["pass"])] for r in crit["driving_steps"]])
    table("6b. Turn deficit (variants/turn_deficit.yaml): mean yaw-rate error over the last 1 s of a %g s hold "
          "(|AIC| <= %g %% of the command)" % (driving.DEFICIT_HOLD, 100 * driving.DEFICIT_ERROR),
          ["command", "AIC error", "stock error", "verdict"],
          [["%.1f rad/s" % r["command"], "%+.4f rad/s" % r["aic_error"], "%+.4f rad/s" % r["stock_error"],
            verdict(r["pass"])] for r in crit["driving_deficit"]])
    table("6c. Stability on varied plants (no runaway; settled wherever the stock controller settles)",
          ["plant", "case", "AIC settle/os", "stock settled", "verdict"],
          [[r["plant"], r["case"], "%s s / %s %%" % (fmt(r["settling"]), fmt(r["overshoot"], "%.1f")),
            "yes" if r["stock_settled"] else "no", verdict(r["pass"])] for r in crit["driving_robust"]])
    g = crit["driving_gmean"]
    table("6d. Tracking, RMS error against the set point (ground truth), AIC / stock <= %.2f per pair; geometric "
          "mean %.3f (vx %.3f, wz %.3f; bound %.2f) %s" % (driving.TRACK_PAIR_BOUND, g["all"], g["vx"], g["wz"],
                                                          g["bound"], verdict(g["pass"])),
          ["profile", "variant", "vx AIC / stock [m/s]", "x", "wz AIC / stock [rad/s]", "x", "verdict"],
          [[r["profile"], r["variant"], "%.4f / %.4f" % (r["aic_vx"], r["stock_vx"]), "%.2f" % r["vx_ratio"],
            "%.4f / %.4f" % (r["aic_wz"], r["stock_wz"]), "%.2f" % r["wz_ratio"], verdict(r["pass"])]
           for r in crit["driving_tracking"]])
    fg = crit["driving_floor_gmean"]
    table("6e. Latency floor (reported): RMS error of an ideal servo that moves the variant's latency "
          "(motor.command_delay) after it is commanded, unlimited acceleration, holding or predicting the set "
          "point, whichever is lower (doc/tools.md, 'Latency floor'); no controller with that latency and "
          "predictor goes below it. Geometric mean floor / stock %.3f (vx %.3f, wz %.3f)" % (fg["all"], fg["vx"],
                                                                                            fg["wz"]),
          ["profile", "variant", "vx floor [m/s]", "floor / stock", "AIC / floor", "wz floor [rad/s]",
           "floor / stock", "AIC / floor"],
          [[r["profile"], r["variant"], "%.4f" % r["floor_vx"], "%.2f" % r["floor_vx_ratio"],
            "%.2f" % (r["aic_vx"] / r["floor_vx"]), "%.4f" % r["floor_wz"], "%.2f" % r["floor_wz_ratio"],
            "%.2f" % (r["aic_wz"] / r["floor_wz"])] for r in crit["driving_tracking"]])


def main():
    """Parse the arguments, run the scorecard, print it (and write --json). Returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--aic-config", default=os.path.join(ROOT, "config", "default.yaml"), help="controller YAML")
    ap.add_argument("--plant-config", default=os.path.join(ROOT, "sim", "config", "plant.yaml"), help="plant YAML")
    ap.add_argument("--plant-overlay", action="append", default=[], metavar="FILE",
                    help="plant overlay YAML applied after --plant-config (repeatable), e.g. "
                         "sim/config/variants/slow_breakaway.yaml")
    ap.add_argument("--seeds", type=int, nargs="+", default=[42, 1, 2, 3, 4],
                    help="noise seeds (sensors.seed) of the 0.5 m/s step; the first is used for every other run's "
                         "steps (default 42 1 2 3 4; 42 is the plant YAML's)")
    ap.add_argument("--jobs", type=int, default=2, help="parallel closed_loop_run processes")
    ap.add_argument("--driving", action="store_true",
                    help="also the driving acceptance set (criterion 6: steps, turn deficit, tracking over the variants)")
    ap.add_argument("--json", help="write the figures and verdicts as JSON here")
    ap.add_argument("--doc", action="store_true",
                    help="also write the printout to doc/results/scorecard.txt with the command that made it")
    a = ap.parse_args()
    a.aic_config = os.path.abspath(a.aic_config)
    a.plant_config = os.path.abspath(a.plant_config)
    a.plant_overlay = [os.path.abspath(o) for o in a.plant_overlay]
    try:
        crit, ok = scorecard(a)
    except (RuntimeError, ValueError, KeyError) as e:
        print("aic_scorecard: %s" % e, file=sys.stderr)
        return 2
    if a.doc:
        import contextlib
        import io
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            print_scorecard(crit, a)
            print("\n%s" % ("ALL PASS" if ok else "FAIL: at least one criterion is not met"))
        text = buf.getvalue().replace(ROOT + os.sep, "")
        sys.stdout.write(text)
        path = os.path.join(ROOT, "doc", "results", "scorecard.txt")
        with open(path, "w") as f:
            f.write("# Written by: scripts/aic_scorecard.py %s--doc (closed_loop_run on the plant core, noisy "
                    "sensors, fixed seeds); do not edit.\n" % ("--driving " if a.driving else ""))
            f.write(text)
        print("aic_scorecard: wrote %s" % os.path.relpath(path, ROOT))
    else:
        print_scorecard(crit, a)
        print("\n%s" % ("ALL PASS" if ok else "FAIL: at least one criterion is not met"))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"aic_config": a.aic_config, "plant_config": a.plant_config, "pass": ok, "criteria": crit}, f,
                      indent=1)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
