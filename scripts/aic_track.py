#!/usr/bin/env python3
"""aic_track.py: the tracking benchmark of real driving, headless: the AIC against the stock
controller on command streams a Jackal actually receives, over plant variants, in one command.

Plays every twist profile (default: sim/profiles/*.csv, written by --write-profiles from
jackal_aic_tools/track_profiles.py: joystick teleop, a 10 Hz planner, S-curves, stop-and-go,
creeping, fast driving) with `closed_loop_run --profile` on the simulated Jackal's plant core
(headless, faster than real time, the plant YAML's seeded sensor noise: the same figures on every
machine), once with the AIC (--aic-config) and once with the stock controller, on the default
plant and on every plant variant (an overlay YAML of sim/config/variants/). Per run, against the
set point: the RMS and maximum error of vx [m/s] and wz [rad/s] (ground truth; wheel odometry in
the JSON and CSV) and the path drift (ground-truth pose against the ideal path, the commanded
twist integrated from the same start: final and maximum position error [m], final heading error
[rad]); all computed by the core (jackal_aic/tracking_metrics.hpp). Then the AIC / stock ratio of
every metric and its geometric mean over profiles x variants (< 1: the AIC tracks better).

Writes to --out: tracking.json (everything), tracking.csv (one row per run), ratios.csv,
traces/<profile>__<variant>__<controller>.csv (closed_loop_run's traces) and
plots/<profile>__<variant>.png (set point and both controllers' velocities; both x-y paths
against the ideal one); --results-md FILE a results page; --doc writes doc/results/tracking.md
and the default plant's plots to doc/img/tracking/.

Usage:
  aic_track.py [--profiles CSV ...] [--variants default|OVERLAY.yaml ...] [--aic-config FILE]
               [--plant-config FILE] [--jobs N] [--out DIR] [--no-plots] [--results-md FILE] [--doc]
  aic_track.py --write-profiles DIR      # regenerate the benchmark's profiles
  aic_track.py --write-random-profiles DIR [--count N] [--seed S]
                                         # seeded streams outside the benchmark (planner, joystick)

  e.g.  scripts/aic_track.py --doc
        scripts/aic_track.py --profiles my_log.csv --variants default sim/config/variants/payload_10kg.yaml

Exit: 0 done, 1 a bad profile or overlay file or a failed run (the message names it), 2 bad
arguments.
"""
import argparse
import csv
import glob
import json
import math
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from jackal_aic_tools import cli, tracking, track_profiles

ROOT = cli.source_root(__file__)
CONTROLLERS = ("aic", "stock")
#: Metrics of the printed table and of the ratios (truth velocity errors and the drift).
TABLE_METRICS = ("vx_rms", "vx_max", "wz_rms", "wz_max", "drift_final", "drift_max", "heading_final")
HEADERS = {"vx_rms": "vx RMS", "vx_max": "vx max", "wz_rms": "wz RMS", "wz_max": "wz max",
           "drift_final": "drift end", "drift_max": "drift max", "heading_final": "heading end",
           "odom_vx_rms": "odom vx RMS", "odom_vx_max": "odom vx max", "odom_wz_rms": "odom wz RMS",
           "odom_wz_max": "odom wz max"}
UNITS = {name: unit for name, unit, _ in tracking.FLAT_METRICS}


def fail(message):
    """Print 'aic_track: message' and exit 1."""
    print("aic_track: %s" % message, file=sys.stderr)
    sys.exit(1)


def default_profiles():
    """sim/profiles/*.csv: the benchmark's profiles in the order of track_profiles.NAMES, then any
    other CSV there, alphabetically."""
    found = sorted(glob.glob(os.path.join(ROOT, "sim", "profiles", "*.csv")))
    order = {n: k for k, n in enumerate(track_profiles.NAMES)}
    return sorted(found, key=lambda p: (order.get(_stem(p), len(order)), _stem(p)))


def default_variants():
    """'default' (the plant YAML alone) and every overlay sim/config/variants/*.yaml."""
    return ["default"] + sorted(glob.glob(os.path.join(ROOT, "sim", "config", "variants", "*.yaml")))


def _stem(path):
    """File name without folder and extension."""
    return os.path.splitext(os.path.basename(path))[0]


def run_job(exe, controller, profile, variant, aic_config, plant_config, trace):
    """One closed_loop_run of ``controller`` on ``profile`` (CSV) with the plant ``variant``
    ('default' or an overlay file), seeded sensor noise, the trace written to ``trace``. Returns
    (result dict or None, error message or None)."""
    cmd = [exe, "--controller", controller, "--noise", "--config", plant_config, "--profile", profile,
           "--csv", trace]
    if variant != "default":
        cmd += ["--overlay", variant]
    if controller == "aic":
        cmd += ["--aic-config", aic_config]
    out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if out.returncode != 0:
        # The tool's own message (the plant's ODE library may print notices as well).
        lines = [l for l in out.stderr.splitlines() if l.startswith("closed_loop_run")] or \
            out.stderr.strip().splitlines()[-1:]
        return None, "%s (exit %d): %s" % (" ".join(cmd), out.returncode, " ".join(lines))
    return json.loads(out.stdout), None


def ratio(a, b):
    """|a| / |b| or None when either is missing or b is 0."""
    if a is None or b is None or b == 0.0:
        return None
    return abs(a) / abs(b)


def geometric_mean(values):
    """Geometric mean of the positive values (None if there is none), and how many."""
    vals = [v for v in values if v is not None and v > 0.0]
    if not vals:
        return None, 0
    return math.exp(sum(math.log(v) for v in vals) / len(vals)), len(vals)


def fmt(v, spec="%.3f"):
    """v formatted with spec, '-' for None."""
    return "-" if v is None else spec % v


def text_table(header, rows):
    """Fixed-width text table."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    return "\n".join("  ".join(str(c).ljust(w) for c, w in zip(r, widths)).rstrip() for r in [header] + rows)


def md_table(header, rows):
    """Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def run_rows(runs):
    """Rows (lists of strings) of the per-run table: profile, variant, controller, TABLE_METRICS."""
    return [[r["profile"], r["variant"], r["controller"]] + [fmt(r["metrics"][m]) for m in TABLE_METRICS]
            for r in runs]


def ratio_rows(ratios, gmean):
    """Rows of the ratio table (AIC / stock per profile and variant, 2 decimals) and the geometric
    mean row; gmean: metric -> (value, count)."""
    rows = [[q["profile"], q["variant"]] + [fmt(q["ratios"][m], "%.2f") for m in TABLE_METRICS] for q in ratios]
    rows.append(["geometric mean", "(n = %d)" % max(n for _, n in gmean.values())] +
                [fmt(gmean[m][0], "%.2f") for m in TABLE_METRICS])
    return rows


def metric_header(names):
    """Column titles with units of the flat metrics ``names``."""
    return ["%s [%s]" % (HEADERS[m], UNITS[m]) for m in names]


def plot_pair(path, profile, traces, title, metrics):
    """PNG: vx and wz over time (set point, ground truth of each controller), then the x-y paths
    against the ideal one. ``profile``: aic_track_metrics' profile dict; ``traces``: controller ->
    columns of its closed_loop_run trace; ``metrics``: controller -> flat metrics."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from jackal_aic_tools import report
    colors = {"aic": "C1", "stock": "C0"}
    fig = plt.figure(figsize=(10, 11))
    ax_v = fig.add_subplot(3, 1, 1)
    ax_w = fig.add_subplot(3, 1, 2, sharex=ax_v)
    pts = profile["points"]
    t0 = min(c["t"][0] for c in traces.values())
    ts = [t0] + [p[0] for p in pts] + [profile["duration"]]
    for ax, ci, col, unit, name in ((ax_v, 1, "v_true", "m/s", "vx"), (ax_w, 2, "yaw_true", "rad/s", "wz")):
        ax.step(ts, [0.0] + [p[ci] for p in pts] + [pts[-1][ci]], where="post", color="k", lw=1.2, ls="--",
                label="set point")
        for c in CONTROLLERS:
            if c in traces:
                ax.plot(traces[c]["t"], traces[c][col], color=colors[c], lw=1.1,
                        label="%s (RMS %s %s)" % (c.upper() if c == "aic" else c, fmt(metrics[c][name + "_rms"]), unit))
        ax.set_ylabel("%s [%s]" % (name, unit))
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    plt.setp(ax_v.get_xticklabels(), visible=False)
    ax_w.set_xlabel("time since profile start [s]")
    ax_v.set_title(title, fontsize=10)
    ref = traces.get("stock") or next(iter(traces.values()))
    keep = ref["x_ideal"] == ref["x_ideal"]  # not NaN: the analysed span
    ideal = {"x": ref["x_ideal"][keep], "y": ref["y_ideal"][keep]}
    paths = []
    for c in CONTROLLERS:
        if c in traces:
            k = traces[c]["x_ideal"] == traces[c]["x_ideal"]
            paths.append(("%s (drift end %s m)" % (c.upper() if c == "aic" else c, fmt(metrics[c]["drift_final"])),
                          colors[c], traces[c]["x"][k], traces[c]["y"][k]))
    report.draw_paths(fig.add_subplot(3, 1, 3), ideal, paths)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def shown(path):
    """``path`` relative to the package's folder when it is inside it (for the results page)."""
    rel = os.path.relpath(os.path.abspath(path), ROOT)
    return path if rel.startswith("..") else rel


def results_md(report_data, plots_rel):
    """The results page (markdown) of a suite run; plots_rel: profile -> image path relative to
    the page (the default plant's plots)."""
    d = report_data
    out = ["# Tracking benchmark: results", "",
           "Generated by `%s` (%d runs, %.0f s of simulated driving, wall time %.1f s with --jobs %d); "
           "do not edit. What the benchmark is: [tools.md](../tools.md), 'Tracking benchmark'." % (
               d["command"], len(d["runs"]), d["simulated_time"], d["wall_time"], d["jobs"]), "",
           "- AIC configuration: `%s`; plant: `%s`; sensor noise of the plant YAML (seeded)." % (
               d["aic_config"], d["plant_config"]),
           "- Variants: %s." % ", ".join(
               "`%s`%s" % (v["name"], "" if v["overlay"] is None else " (`%s`)" % shown(v["overlay"])) for v in d["variants"]),
           "- Profiles: %s." % ", ".join("`%s` (%.1f s)" % (p["name"], p["duration"]) for p in d["profiles"]),
           "", "## AIC / stock (ratios of the ground-truth figures; < 1: the AIC tracks better)", "",
           md_table(["profile", "variant"] + [HEADERS[m] for m in TABLE_METRICS],
                    ratio_rows(d["ratios"], {m: tuple(v) for m, v in d["geometric_mean"].items()})),
           "", "## Every run (ground truth against the set point; heading end is signed)", "",
           md_table(["profile", "variant", "controller"] + metric_header(TABLE_METRICS), run_rows(d["runs"])),
           "", "## Wheel odometry against the set point", "",
           md_table(["profile", "variant", "controller"] +
                    metric_header(("odom_vx_rms", "odom_vx_max", "odom_wz_rms", "odom_wz_max")),
                    [[r["profile"], r["variant"], r["controller"]] +
                     [fmt(r["metrics"][m]) for m in ("odom_vx_rms", "odom_vx_max", "odom_wz_rms", "odom_wz_max")]
                     for r in d["runs"]])]
    if plots_rel:
        out += ["", "## Plots (default plant)", ""]
        for name, rel in plots_rel.items():
            out += ["### %s" % name, "", "![%s](%s)" % (name, rel), ""]
    return "\n".join(out).rstrip() + "\n"


def suite(a):
    """Run the suite (a: parsed arguments); returns the report dict (also written to
    <out>/tracking.json)."""
    exe = cli.find_executable("closed_loop_run", __file__, "aic_track")
    metrics_cli = cli.find_executable("aic_track_metrics", __file__, "aic_track")
    for f in (a.aic_config, a.plant_config):
        if not os.path.isfile(f):
            fail("no such file: %s" % f)
    profiles = []
    for p in a.profiles:
        try:
            profiles.append(dict(tracking.load_profile(p, cli=metrics_cli), path=p))
        except tracking.TrackingError as e:
            fail("bad profile: %s" % e)
    names = [p["name"] for p in profiles]
    if len(set(names)) != len(names):
        fail("two profiles with the same name: %s" % ", ".join(names))
    variants = []
    for v in a.variants:
        if v != "default" and not os.path.isfile(v):
            fail("no such overlay file: %s (a variant is 'default' or an overlay YAML)" % v)
        variants.append({"name": "default" if v == "default" else _stem(v), "overlay": None if v == "default" else v})
    if len({v["name"] for v in variants}) != len(variants):
        fail("two variants with the same name")
    for sub in ("traces", "plots"):
        os.makedirs(os.path.join(a.out, sub), exist_ok=True)

    jobs = [(p, v, c) for p in profiles for v in variants for c in CONTROLLERS]
    start = time.time()

    def one(job):
        p, v, c = job
        trace = os.path.join(a.out, "traces", "%s__%s__%s.csv" % (p["name"], v["name"], c))
        res, err = run_job(exe, c, p["path"], v["overlay"] or "default", a.aic_config, a.plant_config, trace)
        return job, trace, res, err

    runs = []
    errors = []
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for (p, v, c), trace, res, err in pool.map(one, jobs):
            if err:
                errors.append(err)
                continue
            runs.append({"profile": p["name"], "variant": v["name"], "controller": c, "trace": trace,
                         "runaways": res["runaways"], "tracking": res["tracking"], "path": res["path"],
                         "metrics": tracking.flat(res)})
    if errors:
        fail("%d run(s) failed:\n  %s" % (len(errors), "\n  ".join(errors)))

    by_key = {(r["profile"], r["variant"], r["controller"]): r for r in runs}
    ratios = []
    for p in profiles:
        for v in variants:
            aic = by_key[(p["name"], v["name"], "aic")]["metrics"]
            stock = by_key[(p["name"], v["name"], "stock")]["metrics"]
            ratios.append({"profile": p["name"], "variant": v["name"],
                           "ratios": {m: ratio(aic[m], stock[m]) for m in TABLE_METRICS}})
    gmean = {m: geometric_mean([q["ratios"][m] for q in ratios]) for m in TABLE_METRICS}

    plots = {}
    if not a.no_plots:
        for p in profiles:
            for v in variants:
                traces = {c: tracking.read_columns(by_key[(p["name"], v["name"], c)]["trace"]) for c in CONTROLLERS}
                mets = {c: by_key[(p["name"], v["name"], c)]["metrics"] for c in CONTROLLERS}
                path = os.path.join(a.out, "plots", "%s__%s.png" % (p["name"], v["name"]))
                plot_pair(path, p, traces, "%s on the %s plant: AIC (%s) and the stock controller" % (
                    p["name"], v["name"], os.path.basename(a.aic_config)), mets)
                plots[(p["name"], v["name"])] = path
    wall = time.time() - start

    data = {"command": a.command, "wall_time": wall, "jobs": a.jobs, "aic_config": a.aic_config_shown,
            "plant_config": a.plant_config_shown,
            "simulated_time": sum(p["duration"] for p in profiles) * len(variants) * len(CONTROLLERS),
            "profiles": [{"name": p["name"], "file": p["path"], "duration": p["duration"]} for p in profiles],
            "variants": variants, "runs": runs, "ratios": ratios,
            "geometric_mean": {m: list(g) for m, g in gmean.items()},
            "plots": {"%s__%s" % k: v for k, v in plots.items()}}
    with open(os.path.join(a.out, "tracking.json"), "w") as f:
        json.dump(data, f, indent=1)
    with open(os.path.join(a.out, "tracking.csv"), "w") as f:
        w = csv.writer(f)
        names = [n for n, _, _ in tracking.FLAT_METRICS]
        w.writerow(["profile", "variant", "controller"] + ["%s [%s]" % (n, UNITS[n]) for n in names] +
                   ["ideal_length [m]", "runaways", "trace"])
        for r in runs:
            w.writerow([r["profile"], r["variant"], r["controller"]] +
                       ["" if r["metrics"][n] is None else "%.6g" % r["metrics"][n] for n in names] +
                       ["%.6g" % r["path"]["ideal_length"], r["runaways"], os.path.relpath(r["trace"], a.out)])
    with open(os.path.join(a.out, "ratios.csv"), "w") as f:
        w = csv.writer(f)
        w.writerow(["profile", "variant"] + ["%s aic/stock" % m for m in TABLE_METRICS])
        for q in ratios:
            w.writerow([q["profile"], q["variant"]] + ["" if q["ratios"][m] is None else "%.6g" % q["ratios"][m]
                                                       for m in TABLE_METRICS])
        w.writerow(["geometric mean", ""] + ["" if gmean[m][0] is None else "%.6g" % gmean[m][0]
                                             for m in TABLE_METRICS])
    return data


def write_results(data, md_path, img_dir=None):
    """The results page at md_path; with img_dir, the default plant's plots copied there and
    linked (relative paths)."""
    plots_rel = {}
    if img_dir:
        os.makedirs(img_dir, exist_ok=True)
        for key, src in data["plots"].items():
            profile, variant = key.split("__", 1)
            if variant == "default":
                dst = os.path.join(img_dir, profile + ".png")
                shutil.copyfile(src, dst)
                plots_rel[profile] = os.path.relpath(dst, os.path.dirname(os.path.abspath(md_path)))
    os.makedirs(os.path.dirname(os.path.abspath(md_path)), exist_ok=True)
    with open(md_path, "w") as f:
        f.write(results_md(data, plots_rel))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--profiles", nargs="+", metavar="CSV", help="twist profiles (default: sim/profiles/*.csv)")
    p.add_argument("--variants", nargs="+", metavar="VARIANT",
                   help="'default' (the plant YAML alone) or overlay YAML files (default: default and "
                        "sim/config/variants/*.yaml)")
    p.add_argument("--aic-config", default=None, help="AIC YAML (default: config/default.yaml)")
    p.add_argument("--plant-config", default=None, help="plant YAML (default: sim/config/plant.yaml)")
    p.add_argument("--jobs", type=int, default=2, help="closed_loop_run processes at once (default %(default)s)")
    p.add_argument("--out", default=None, help="output folder (default: <results>/tracking)")
    p.add_argument("--no-plots", action="store_true", help="skip the PNGs")
    p.add_argument("--results-md", metavar="FILE", help="write the results page (markdown) to FILE")
    p.add_argument("--doc", action="store_true",
                   help="write doc/results/tracking.md and the default plant's plots in doc/img/tracking/")
    p.add_argument("--write-profiles", metavar="DIR", help="write the benchmark's profiles to DIR and exit")
    p.add_argument("--write-random-profiles", metavar="DIR",
                   help="write --count seeded planner and joystick streams that are not the benchmark's to DIR "
                        "and exit (then: --profiles DIR/*.csv)")
    p.add_argument("--count", type=int, default=4, help="--write-random-profiles: streams of each kind (default 4)")
    p.add_argument("--seed", type=int, default=1000, help="--write-random-profiles: first seed (default 1000)")
    a = p.parse_args(argv)
    if a.write_profiles:
        for path in track_profiles.write_all(a.write_profiles):
            print(path)
        return 0
    if a.write_random_profiles:
        if a.count < 1:
            p.error("--count must be >= 1")
        for path in track_profiles.write_random(a.write_random_profiles, a.count, a.seed):
            print(path)
        return 0
    if a.jobs < 1:
        p.error("--jobs must be >= 1")
    a.command = " ".join(["aic_track.py"] + (sys.argv[1:] if argv is None else list(argv)))
    a.aic_config_shown = a.aic_config or "config/default.yaml"
    a.plant_config_shown = a.plant_config or "sim/config/plant.yaml"
    a.aic_config = a.aic_config or os.path.join(ROOT, "config", "default.yaml")
    a.plant_config = a.plant_config or os.path.join(ROOT, "sim", "config", "plant.yaml")
    a.profiles = a.profiles or default_profiles()
    a.variants = a.variants or default_variants()
    a.out = a.out or os.path.join(cli.default_results_dir(), "tracking")
    if not a.profiles:
        fail("no profiles (sim/profiles/*.csv is empty; write them with --write-profiles sim/profiles)")
    if a.no_plots and a.doc:
        p.error("--doc needs the plots")

    data = suite(a)
    gm = {m: tuple(v) for m, v in data["geometric_mean"].items()}
    print(text_table(["profile", "variant", "controller"] + metric_header(TABLE_METRICS), run_rows(data["runs"])))
    print("\nAIC / stock (< 1: the AIC tracks better; heading end compared by magnitude)")
    print(text_table(["profile", "variant"] + [HEADERS[m] for m in TABLE_METRICS], ratio_rows(data["ratios"], gm)))
    print("\n%d runs, %.0f s simulated, wall time %.1f s (--jobs %d); results in %s" % (
        len(data["runs"]), data["simulated_time"], data["wall_time"], data["jobs"], a.out))
    if a.results_md:
        write_results(data, a.results_md)
        print("results page: %s" % a.results_md)
    if a.doc:
        md = os.path.join(ROOT, "doc", "results", "tracking.md")
        write_results(data, md, os.path.join(ROOT, "doc", "img", "tracking"))
        print("results page: %s" % md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
