"""aic_compare.py: named controller variants side by side, against the stock controller and the
latency floor, judged on the same runs and seeds, in one command.

Every variant (NAME=BASE[+OVERLAY][:KEY=VALUE,...], jackal_aic_tools.compare.variants) and the
stock controller run on the simulated Jackal's plant core (closed_loop_run: headless, simulated time,
the plant YAML's seeded sensor noise), the same runs for each:

  steps     the steps of the scorecard (aic_scorecard.py, criteria 1 and 3: 0.1, 0.3, 0.5, 1.0 m/s
            from rest with noise seed 42, the 1 rad/s turn in place held 8 s) and the 0.5 m/s +
            0.5 rad/s arc of the driving set (its first phase); rise 10-90 % [s], settling +-5 % [s],
            overshoot [%] of the measured speed (wheel odometry; the gyro on the yaw channel)
  tracking  the six profiles of sim/profiles on each plant of --plants (default: the plant YAML
            alone): RMS error of vx [m/s] and wz [rad/s] of the ground truth against the set point,
            beside the latency floor at the plant's latency (driving.floor_rms; doc/tools.md,
            'Latency floor')
  belief    the AIC's belief mu^(0) minus the ground truth, RMS over each tracking profile and the
            arc (tracking.belief_truth_rms, from the --csv trace), and closed_loop_run's steady mean
            |belief - truth| (the scorecard's honest belief) in the CSV

Every figure is closed_loop_run's (the scorecard's and the tracking benchmark's metrics: the
default configuration's column equals aic_scorecard.py's figures) or the floor's; this module only
arranges them.

Ratios and geometric means. Each variant's figure is shown with its ratio to the stock
controller's (belief rows: to the first variant's, the stock controller has no belief). A ratio
of two figures near zero is noise divided by noise, so every ratio's numerator and denominator
are floored at the metric's noise level NOISE (0.01 s for times, 1 % for overshoot, 0.002 m/s
and 0.002 rad/s for the RMS errors): a figure below it counts as the noise level. The geometric
means (plant_limits.gmean over the floored ratios) summarise: steps (rise and settling), tracking
against stock and against the floor, belief against the first variant; a figure that does not
exist (a step that never settled) is left out and counted in the cell ("2 missing").

A diverged run (closed_loop_run's divergence check: a runaway reset, non-finite values, a robot
that never moved) marks its cells with "!" and is listed under the table; aic_compare.py then
exits 3 unless --keep-going.

With --markdown FILE, also a results page: one row per variant with its base and overrides, the
geometric means (tracking / stock, tracking / floor, steps / stock) and the belief - truth RMS of the
arc and the mean over the tracking profiles, per channel (markdown_page); e.g. doc/results/who_tracks.md
of config/compare/who_tracks.txt.

Outputs in --out: compare.csv (one row per metric and column: value, ratio, reference),
compare.json (everything, with the command line), and the figures, each as PNG and PDF:
tracking_ratios (RMS / stock per profile and channel, the floor marked), steps (the 0.5 m/s step
and the arc, whole run and zoomed transient), belief_error (belief - truth on the arc).
"""
import json
import math
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from ..common import closed_loop, tracking
from ..common.tables import fmt, md_table, text_table
from ..track import driving, plant_limits
from ..tune import scorecard

#: Noise level of each unit: ratios are taken of max(figure, level) (module docstring).
NOISE = {"s": 0.01, "%": 1.0, "m/s": 0.002, "rad/s": 0.002}
#: Noise seed of the steps (the scorecard's first seed).
STEP_SEED = 42
#: Step cases: (name, closed_loop_run arguments, plant KEY=VALUE sets, result key of the segments,
#: unit of the speed). The scorecard's criteria 1 and 3 (scorecard.step_profile) and the driving
#: set's arc at its first phase (driving.STEP_CASES), so that their figures are the scorecard's.
STEPS = [("%g m/s" % v, scorecard.step_profile(v), ["sensors.seed=%d" % STEP_SEED], "segments", "m/s")
         for v in scorecard.STEPS] + [
    ("1 rad/s turn", scorecard.step_profile(1.0, "angular", 8.0), [], "segments", "rad/s"),
    ("arc speed", driving.STEP_CASES["arc, speed"][0] + ["--rest", "%.4f" % (1.0 + driving.STEP_PHASES[0])], [],
     "segments", "m/s"),
    ("arc yaw", None, [], "angular_segments", "rad/s"),  # the arc's run, its yaw channel
]
#: Steps whose traces the figures show.
TRACED_STEPS = ("0.5 m/s", "arc speed")
STEP_METRICS = (("rise", "s"), ("settling", "s"), ("overshoot", "%"))


def floored_ratio(value, ref, unit):
    """value / ref with both floored at NOISE[unit]; None when either is None or non-finite."""
    if value is None or ref is None or not (math.isfinite(value) and math.isfinite(ref)):
        return None
    n = NOISE[unit]
    return max(abs(value), n) / max(abs(ref), n)


def profile_args(profile=None, step=None, turn=None, channel="linear", hold=3.0, rest=None):
    """closed_loop_run's profile arguments: a twist profile CSV ``profile``, or a step to ``step``
    [m/s, or rad/s with channel angular] held ``hold`` s, with ``turn`` [rad/s] a combined step
    (the arc), after ``rest`` s at rest (None: the program's 1 s). Raises ValueError unless exactly
    one of profile and step is given."""
    if (profile is None) == (step is None):
        raise ValueError("profile_args: give exactly one of profile and step")
    args = ["--profile", profile] if profile is not None else scorecard.step_profile(step, channel, hold)
    if turn is not None:
        args += ["--turn", str(turn)]
    if rest is not None:
        args += ["--rest", str(rest)]
    return args


def run_variant(exe, config, sets=(), plant_config=None, plant_variant="default", profile=None, step=None, turn=None,
                channel="linear", hold=3.0, rest=None, plant_sets=(), controller="aic", trace=True,
                keep_going=False):
    """Run one configuration on one plant variant and profile (the Python API of the headless
    closed loop; a thin wrapper over closed_loop_run, jackal_aic_tools.common.closed_loop, for why).

    exe: closed_loop_run's path (cli.Tool.exe("closed_loop_run")); config: the controller YAML;
    sets: its KEY=VALUE overrides, in order; plant_config: the plant YAML (None: the package's);
    plant_variant: "default" or an overlay YAML (sim/config/variants/*.yaml); profile / step /
    turn / channel / hold / rest: the set point (profile_args); plant_sets: plant KEY=VALUE
    overrides (e.g. sensors.seed=1); controller: aic, stock, open or ideal; trace: read the trace;
    keep_going: a diverged run returns instead of raising.

    Returns a closed_loop.Run with ``metrics`` added: {"segments", "angular_segments": the step
    metrics of each transition ("measured", "truth", "belief", "drive": rise [s], settling [s],
    overshoot [%], sse, settled), "tracking": {"vx" [m/s], "wz" [rad/s]} RMS of the ground truth
    against the set point, "belief_rms": tracking.belief_truth_rms over the profile (AIC with a
    trace; else None), "belief_steady": closed_loop_run's steady mean |belief - truth| per channel
    (AIC; else None), "floor": driving.floor_rms at the plant's latency (a profile; else None)}.
    Raises closed_loop.Diverged (unless keep_going), closed_loop.RunError, ValueError."""
    overlays = [] if plant_variant in (None, "default") else [plant_variant]
    r = closed_loop.run(exe, controller, profile_args(profile, step, turn, channel, hold, rest), config, sets,
                        plant_config, overlays, plant_sets, noise=True, keep_going=keep_going, trace=trace)
    r.metrics = metrics_of(r.result, r.trace, profile)
    return r


def metrics_of(result, trace, profile=None, floor_cache=None):
    """run_variant()'s metrics dict of closed_loop_run's JSON ``result`` and its trace ``trace``
    (read_columns, or None) of ``profile`` (a CSV, or None for a step); ``floor_cache`` a dict
    reused across calls of driving.floor_rms."""
    truth = result["tracking"]["truth"]
    steady = result["tracking"].get("belief")
    belief_rms = None
    if trace is not None and tracking.BELIEF_COLUMNS["vx"][0] in trace:
        belief_rms = tracking.belief_truth_rms(trace, 0.0, result["duration"])
    return {"segments": result.get("segments") or [], "angular_segments": result.get("angular_segments") or [],
            "tracking": {ch: truth[ch]["rms"] for ch in ("vx", "wz")},
            "belief_rms": belief_rms,
            "belief_steady": {ch: steady[ch]["steady_mean_abs"] if steady[ch]["samples"] else None
                              for ch in ("vx", "wz")} if steady else None,
            "floor": driving.floor_rms(profile, result["command_delay"], floor_cache) if profile else None}


def plan(variants, profiles, plants):
    """Every run of a comparison: a list of (key, column, controller, args, plant_sets, overlay,
    trace). key: ("step", case, column) or ("track", profile, plant, column); column: a variant's
    name or "stock"."""
    columns = [(v.name, "aic") for v in variants] + [("stock", "stock")]
    jobs = []
    for name, args, sets, _, _ in STEPS:
        if args is None:
            continue
        for col, ctl in columns:
            jobs.append((("step", name, col), col, ctl, args, sets, None, name in TRACED_STEPS))
    for p in profiles:
        for plant in plants:
            for col, ctl in columns:
                jobs.append((("track", p, plant, col), col, ctl, ["--profile", p], [], plant, ctl == "aic"))
    return jobs


def run_all(exe, variants, profiles, plants, plant_config, jobs=2, keep_going=False):
    """Run plan()'s runs, ``jobs`` closed_loop_run processes at a time. Returns (runs, diverged):
    runs key -> closed_loop.Run (a diverged run's too); diverged a list of (key, cause). Raises
    closed_loop.RunError on a failed run (a bad file or argument)."""
    by_name = {v.name: v for v in variants}

    def one(job):
        key, col, ctl, args, sets, plant, want_trace = job
        v = by_name.get(col)
        overlays = [] if plant in (None, "default") else [plant]
        try:
            return key, closed_loop.run(exe, ctl, args, v.config if v else None, v.sets if v else (), plant_config,
                                        overlays, sets, noise=True, keep_going=keep_going, trace=want_trace), None
        except closed_loop.Diverged as e:
            return key, e.run, e.run.diverged

    runs, diverged = {}, []
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        for key, r, cause in pool.map(one, plan(variants, profiles, plants)):
            runs[key] = r
            if cause or r.diverged:
                diverged.append((key, cause or r.diverged))
    return runs, diverged


def _stem(path):
    return os.path.splitext(os.path.basename(path))[0]


def rows_of(runs, variants, profiles, plants):
    """The comparison's rows from the runs of run_all: a list of dicts {section, label, unit, ref
    ("stock" or the first variant's name), values {column: figure or None} (columns: "stock",
    "floor" on tracking rows, each variant), ratios {variant: floored ratio to ref}, diverged
    {column: True}}."""
    names = [v.name for v in variants]
    rows = []
    floors = {}

    def add(section, label, unit, values, diverged, ref="stock"):
        ratios = {n: floored_ratio(values.get(n), values.get(ref), unit) for n in names}
        if "floor" in values:
            ratios["floor"] = floored_ratio(values["floor"], values["stock"], unit)
        rows.append({"section": section, "label": label, "unit": unit, "ref": ref, "values": values,
                     "ratios": ratios, "diverged": diverged})

    for name, args, _, seg_key, unit in STEPS:
        run_name = name if args is not None else "arc speed"
        for metric, m_unit in STEP_METRICS:
            values, div = {}, {}
            for col in ["stock"] + names:
                r = runs[("step", run_name, col)]
                segs = r.result.get(seg_key) or []
                values[col] = segs[0]["measured"].get(metric) if segs else None
                div[col] = bool(r.diverged)
            add("steps", "%s %s" % (name, metric), m_unit, values, div)
    for plant in plants:
        tag = "" if plant in (None, "default") else " (%s)" % _stem(plant)
        for p in profiles:
            res = {col: runs[("track", p, plant, col)] for col in ["stock"] + names}
            floor = driving.floor_rms(p, res["stock"].result["command_delay"], floors)
            for ch, unit in (("vx", "m/s"), ("wz", "rad/s")):
                values = {col: r.result["tracking"]["truth"][ch]["rms"] for col, r in res.items()}
                values["floor"] = floor[ch]
                add("tracking", "%s%s %s RMS" % (_stem(p), tag, ch), unit, values,
                    {col: bool(r.diverged) for col, r in res.items()})
    belief_runs = [("arc", lambda col: runs[("step", "arc speed", col)])]
    for plant in plants:
        tag = "" if plant in (None, "default") else " (%s)" % _stem(plant)
        for p in profiles:
            belief_runs.append((_stem(p) + tag, lambda col, p=p, plant=plant: runs[("track", p, plant, col)]))
    for label, get in belief_runs:
        for ch, unit in (("vx", "m/s"), ("wz", "rad/s")):
            values, div = {}, {}
            for col in names:
                r = get(col)
                b = tracking.belief_truth_rms(r.trace, 0.0, r.result["duration"]) if r.trace is not None else None
                values[col] = b[ch] if b else None
                div[col] = bool(r.diverged)
            add("belief", "%s %s belief-truth RMS" % (label, ch), unit, values, div, ref=names[0])
    return rows


def summary(rows, variants):
    """The geometric means of the floored ratios, per variant: a list of (label, {column: (gmean or
    None, count, missing)}) for steps (rise and settling / stock), tracking / stock, tracking /
    floor (the floor's column: floor / stock) and belief / the first variant."""
    names = [v.name for v in variants]

    def gm(select, against="ratios", cols=names):
        out = {}
        for col in cols:
            vals, missing = [], 0
            for r in rows:
                if not select(r):
                    continue
                if against == "ratios":
                    x = r["ratios"].get(col)
                else:
                    x = floored_ratio(r["values"].get(col), r["values"].get("floor"), r["unit"])
                if x is None:
                    missing += 1
                else:
                    vals.append(x)
            g, n = plant_limits.gmean(vals)
            out[col] = (g, n, missing)
        return out

    def is_time(r):
        return r["section"] == "steps" and r["unit"] == "s"

    return [("steps: rise, settling / stock", gm(is_time)),
            ("tracking RMS / stock", gm(lambda r: r["section"] == "tracking", cols=names + ["floor"])),
            ("tracking RMS / floor", gm(lambda r: r["section"] == "tracking", against="floor")),
            ("belief RMS / %s" % names[0], gm(lambda r: r["section"] == "belief"))]


def cell(row, col):
    """The text of one table cell: figure (ratio), '!' after a diverged run's."""
    v = row["values"].get(col)
    spec = "%.1f" if row["unit"] == "%" else ("%.3f" if row["unit"] == "s" else "%.4f")
    text = fmt(v, spec)
    r = row["ratios"].get(col)
    if col != "stock" and col != row["ref"] and r is not None:
        text += " (%.2f)" % r
    return text + ("!" if row["diverged"].get(col) else "")


def table(rows, summ, variants):
    """The comparison as a fixed-width text table (one column per variant, beside stock and the
    floor)."""
    names = [v.name for v in variants]
    header = ["metric", "unit", "stock", "floor"] + names
    body = []
    section = None
    for r in rows:
        if r["section"] != section:
            section = r["section"]
            body.append(["[%s]" % section] + [""] * (len(header) - 1))
        body.append([r["label"], r["unit"], cell(r, "stock"), cell(r, "floor") if "floor" in r["values"] else ""] +
                    [cell(r, n) for n in names])
    body.append(["[geometric means of the floored ratios]"] + [""] * (len(header) - 1))
    for label, per in summ:
        line = [label, "-", "", ""]
        if "floor" in per:
            g, n, miss = per["floor"]
            line[3] = fmt(g, "%.3f")
        for n in names:
            g, k, miss = per[n]
            line.append(fmt(g, "%.3f") + (" (%d missing)" % miss if miss else ""))
        body.append(line)
    return text_table(header, body)


def write_csv(path, rows, summ, variants):
    """compare.csv: one line per row and column: section, metric, unit, column, value, ratio, ref,
    diverged; then the geometric means (section "gmean", value the mean, ratio empty)."""
    import csv
    names = [v.name for v in variants]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["section", "metric", "unit", "column", "value", "ratio", "ref", "diverged"])
        for r in rows:
            for col in ["stock", "floor"] + names:
                if col not in r["values"]:
                    continue
                ratio = r["ratios"].get(col)
                w.writerow([r["section"], r["label"], r["unit"], col, _num(r["values"][col]), _num(ratio),
                            r["ref"] if col != "stock" else "", int(bool(r["diverged"].get(col)))])
        for label, per in summ:
            for col, (g, n, miss) in per.items():
                w.writerow(["gmean", label, "-", col, _num(g), "", "n=%d missing=%d" % (n, miss), ""])


def belief_means(rows, name, plants_tag=""):
    """The belief - truth RMS of variant ``name`` from rows_of()'s belief rows: {"arc": {"vx", "wz"},
    "profiles": {"vx", "wz"} (the mean over the tracking profiles)}; None where missing."""
    out = {"arc": {}, "profiles": {}}
    for ch in ("vx", "wz"):
        arc = [r["values"].get(name) for r in rows if r["section"] == "belief" and r["label"].startswith("arc ") and
               r["label"].endswith(" %s belief-truth RMS" % ch)]
        prof = [r["values"].get(name) for r in rows if r["section"] == "belief" and not r["label"].startswith("arc ")
                and r["label"].endswith(" %s belief-truth RMS" % ch)]
        out["arc"][ch] = arc[0] if arc else None
        vals = [v for v in prof if v is not None]
        out["profiles"][ch] = sum(vals) / len(vals) if vals and len(vals) == len(prof) else None
    return out


def markdown_page(rows, summ, variants, command, root, title, diverged=(), plants=("default",)):
    """The --markdown results page (str): ``title``, the command, the plants (``plants``: "default"
    or overlay paths, named by their file's stem), and one row per variant: its base (relative to
    ``root``) and overrides, the geometric means of summary() (tracking RMS / stock and / floor,
    steps rise and settling / stock), the belief - truth RMS (belief_means: the arc, the mean over
    the profiles, vx [m/s] and wz [rad/s]) and its diverged runs (run_all's ``diverged``: a robot
    that never moved counts; its figures stay in the means)."""
    per = dict(summ)
    header = ["variant", "configuration", "tracking RMS / stock", "tracking RMS / floor", "steps / stock",
              "arc belief - truth vx [m/s]", "arc belief - truth wz [rad/s]",
              "profiles belief - truth vx [m/s]", "profiles belief - truth wz [rad/s]", "diverged runs"]
    body = []
    for v in variants:
        b = belief_means(rows, v.name)
        cfg = "`%s`%s" % (os.path.relpath(v.config, root), "".join(" `%s`" % x for x in v.sets))

        def g(label):
            value, n, miss = per[label][v.name]
            return fmt(value, "%.3f") + (" (%d missing)" % miss if miss else "")
        body.append([v.name, cfg, g("tracking RMS / stock"), g("tracking RMS / floor"),
                     g("steps: rise, settling / stock"), fmt(b["arc"]["vx"], "%.4f"), fmt(b["arc"]["wz"], "%.4f"),
                     fmt(b["profiles"]["vx"], "%.4f"), fmt(b["profiles"]["wz"], "%.4f"),
                     str(sum(1 for key, _ in diverged if key[-1] == v.name))])
    floor_stock = per["tracking RMS / stock"].get("floor", (None, 0, 0))[0]
    named = ["the default plant" if p in (None, "default") else "`%s`" % _stem(p) for p in plants]
    where = named[0] if len(named) == 1 else "each of %d plants (%s)" % (len(named), ", ".join(named))
    return "\n".join([
        "# %s" % title, "",
        "Generated by `%s`; do not edit. The runs and their figures: [tools.md](../tools.md), 'Comparing "
        "variants' (aic_compare.py): the scorecard's steps and the six profiles of `sim/profiles/` on %s, "
        "noisy sensors, fixed seeds, the same runs for every variant and the stock controller. Geometric "
        "means of the ratios over the %d tracking channels (vx, wz RMS of the ground truth against the set point) "
        "and the steps' rise and settling times; belief - truth: RMS of the belief mu^(0) against the ground truth "
        "over the whole run, transients included. The latency floor / stock over the same channels: %s." % (
            command, where, sum(1 for r in rows if r["section"] == "tracking"), fmt(floor_stock, "%.3f")), "",
        md_table(header, body), ""])


def _num(v):
    return "" if v is None else repr(float(v))


def compare(a, tool):
    """Run a comparison (a: parsed arguments of aic_compare.py: variants (list of Variant),
    profiles, plants, plant_config, jobs, keep_going, out, no_plot; tool: cli.Tool), print the
    table, write the CSV, the JSON and the figures. Returns the exit status: 0, or 3 when a run
    diverged without keep_going."""
    started = time.time()
    exe = tool.exe("closed_loop_run")
    runs, diverged = run_all(exe, a.variants, a.profiles, a.plants, a.plant_config, a.jobs, a.keep_going)
    rows = rows_of(runs, a.variants, a.profiles, a.plants)
    summ = summary(rows, a.variants)
    wall = time.time() - started
    print("aic_compare: %d variants against the stock controller and the latency floor; %d runs, %.0f s wall "
          "(%d at a time); figure (ratio to the row's reference: stock, belief rows the first variant; both "
          "floored at the noise level %s)" % (len(a.variants), len(runs), wall, a.jobs,
                                              ", ".join("%g %s" % (n, u) for u, n in NOISE.items())))
    for v in a.variants:
        print("  %s: %s%s" % (v.name, os.path.relpath(v.config, tool.root),
                               "".join(" --aic-set " + s for s in v.sets)))
    print(table(rows, summ, a.variants))
    for key, cause in diverged:
        print("DIVERGED %s: %s" % (" / ".join(str(_stem(k)) if isinstance(k, str) and os.sep in k else str(k)
                                              for k in key[1:]), cause))
    os.makedirs(a.out, exist_ok=True)
    write_csv(os.path.join(a.out, "compare.csv"), rows, summ, a.variants)
    with open(os.path.join(a.out, "compare.json"), "w") as f:
        json.dump({"command": " ".join(sys.argv), "wall_s": wall,
                   "variants": [{"name": v.name, "config": v.config, "sets": v.sets} for v in a.variants],
                   "rows": rows, "summary": [[label, per] for label, per in summ],
                   "diverged": [[list(map(str, k)), c] for k, c in diverged]}, f, indent=1)
    written = ["compare.csv", "compare.json"]
    if getattr(a, "markdown", None):
        with open(a.markdown, "w") as f:
            f.write(markdown_page(rows, summ, a.variants, a.command_shown, tool.root, a.title, diverged, a.plants))
        written.append(a.markdown)
    if not a.no_plot:
        from . import compare_plot
        written += compare_plot.plot_all(runs, rows, a.variants, a.out, NOISE)
    print("aic_compare: wrote %s in %s" % (", ".join(written), a.out))
    if diverged and not a.keep_going:
        print("aic_compare: %d run(s) diverged (marked '!'); --keep-going to exit 0" % len(diverged), file=sys.stderr)
        return closed_loop.EXIT_DIVERGED
    return 0
