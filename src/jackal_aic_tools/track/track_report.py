"""The tables, plots and results page of the tracking benchmark (aic_track.py): per run, the
AIC / stock ratios and their geometric mean, the AIC against the classical peer and the latency
floor, as text, Markdown and figures (PNG and PDF)."""
import os
import shutil

from ..common import figures, tracking
from ..common.tables import fmt, md_table, text_table
from . import plant_limits

#: The controllers of every pair: the AIC, the stock controller and the classical peer
#: (closed_loop_run --controller pi).
CONTROLLERS = ("aic", "stock", "pi")
#: Their names in plots.
LABELS = {"aic": "AIC", "stock": "stock", "pi": "classical peer"}
#: Metrics of the printed table and of the ratios (truth velocity errors and the drift).
TABLE_METRICS = ("vx_rms", "vx_max", "wz_rms", "wz_max", "drift_final", "drift_max", "heading_final")
HEADERS = {"vx_rms": "vx RMS", "vx_max": "vx max", "wz_rms": "wz RMS", "wz_max": "wz max",
           "drift_final": "drift end", "drift_max": "drift max", "heading_final": "heading end",
           "odom_vx_rms": "odom vx RMS", "odom_vx_max": "odom vx max", "odom_wz_rms": "odom wz RMS",
           "odom_wz_max": "odom wz max"}
UNITS = {name: unit for name, unit, _ in tracking.FLAT_METRICS}


def run_rows(runs):
    """Rows (lists of strings) of the per-run table: profile, variant, controller, TABLE_METRICS."""
    return [[r["profile"], r["variant"], r["controller"]] + [fmt(r["metrics"][m]) for m in TABLE_METRICS]
            for r in runs]


def ratio_rows(ratios, gmean, gmean_limited=None):
    """Rows of the ratio table (AIC / stock per profile and variant, 2 decimals, and the pair's
    plant-limited channels, '-' for none), the geometric mean row of the plant-following channels
    and, when ``gmean_limited`` has any, that of the plant-limited ones; gmean, gmean_limited:
    metric -> (value, count)."""
    rows = [[q["profile"], q["variant"]] + [fmt(q["ratios"][m], "%.2f") for m in TABLE_METRICS] +
            [", ".join(q.get("limited", [])) or "-"] for q in ratios]
    rows.append(["geometric mean, plant-following", "(n = %s)" % "/".join(str(gmean[m][1]) for m in TABLE_METRICS)] +
                [fmt(gmean[m][0], "%.2f") for m in TABLE_METRICS] + [""])
    if gmean_limited and any(n for _, n in gmean_limited.values()):
        rows.append(["geometric mean, plant-limited",
                     "(n = %s)" % "/".join(str(gmean_limited[m][1]) for m in TABLE_METRICS)] +
                    [fmt(gmean_limited[m][0], "%.2f") for m in TABLE_METRICS] + [""])
    return rows


RATIO_HEADER = ["profile", "variant"] + [HEADERS[m] for m in TABLE_METRICS] + ["plant limits"]


def limited_rows(limits):
    """Rows of the plant-limited table: one per plant-limited channel of ``limits``
    (track_suite's plant_limits list): profile, variant, channel, ideal / floor, AIC / ideal,
    stock / ideal, AIC / stock, the reason."""
    rows = []
    for q in limits:
        for ch in plant_limits.CHANNELS:
            if q["limited"][ch]:
                i = q["ideal"][ch]
                rows.append([q["profile"], q["variant"], ch, fmt(q["ideal_floor"][ch], "%.2f"),
                             fmt(q["aic"][ch] / i if i else None, "%.2f"), fmt(q["stock"][ch] / i if i else None, "%.2f"),
                             fmt(q["aic"][ch] / q["stock"][ch] if q["stock"][ch] else None, "%.2f"), q["limited"][ch]])
    return rows


LIMITED_HEADER = ["profile", "variant", "channel", "ideal / floor", "AIC / ideal", "stock / ideal", "AIC / stock",
                  "reason"]


def ideal_rows(limits):
    """Rows of the ideal-controller table: per pair the latency floor, the ideal controller's RMS
    error and their ratio, vx then wz, and the ideal's best run of its learning."""
    return [[q["profile"], q["variant"]] +
            [c for ch in plant_limits.CHANNELS for c in (fmt(q["floor"][ch], "%.4f"), fmt(q["ideal"][ch], "%.4f"),
                                                        fmt(q["ideal_floor"][ch], "%.2f") +
                                                        (" *" if q["limited"][ch] else ""))] +
            ["%d / %d" % (q["ideal"]["best"] + 1, q["ideal"]["runs"])] for q in limits]


IDEAL_HEADER = ["profile", "variant", "vx floor [m/s]", "vx ideal [m/s]", "ideal / floor", "wz floor [rad/s]",
                "wz ideal [rad/s]", "ideal / floor", "best run"]


#: The geometric-mean rows of the classical peer's table: (label suffix, track_suite.peer_means
#: names, their cells' format), against the latency floor, against the acceleration-bounded one, and
#: the AIC's error taken apart there: its wheels (the wheel odometry) against that floor, and its
#: body (the ground truth) against its wheels.
PEER_MEANS = (("", ("aic_floor", "pi_floor", "aic_pi"), "AIC / floor %s, peer / floor %s, AIC / peer %s"),
              (", acceleration-bounded floor", ("aic_floor_accel", "pi_floor_accel", "stock_floor_accel",
                                                "floor_accel_floor"),
               "AIC / it %s, peer / it %s, stock / it %s, it / floor %s"),
              (", the AIC's wheels and body", ("wheels_floor_accel", "truth_wheels"),
               "wheel odometry / acceleration-bounded floor %s, ground truth / wheel odometry %s"))


def peer_rows(limits, peer):
    """Rows of the classical peer's table: per pair and channel (vx, wz) the RMS error of the AIC,
    the peer and the latency floor, AIC / peer (a '*' where the channel is plant-limited), then the
    geometric means of track_suite.peer_means ``peer`` (PEER_MEANS: against the latency floor,
    against the acceleration-bounded floor, and the AIC's wheels and body apart) over the
    plant-following channels and over the default plant's, each whole and per channel."""
    rows = []
    for q in limits:
        row = [q["profile"], q["variant"]]
        for ch in plant_limits.CHANNELS:
            a, b, f = q["aic"][ch], q["pi"][ch], q["floor"][ch]
            row += [fmt(a, "%.4f"), fmt(b, "%.4f"), fmt(f, "%.4f"),
                    fmt(a / b if b else None, "%.2f") + (" *" if q["limited"][ch] else "")]
        rows.append(row)
    for suffix, names, text in PEER_MEANS:
        for label, key in (("geometric mean, plant-following", None), ("geometric mean, default plant", "default")):
            cells = []
            for name in names:
                mean = peer[name]
                whole, vx, wz = ((mean["default"], mean["default_vx"], mean["default_wz"]) if key
                                 else (mean["all"], mean["vx"], mean["wz"]))
                cells.append("%s (vx %s, wz %s; n = %d)" % (fmt(whole[0], "%.3f"), fmt(vx[0], "%.3f"),
                                                            fmt(wz[0], "%.3f"), whole[1]))
            rows.append([label + suffix, text % tuple(cells)] + [""] * 8)
    return rows


PEER_HEADER = ["profile", "variant", "vx AIC [m/s]", "vx peer [m/s]", "vx floor [m/s]", "AIC / peer",
               "wz AIC [rad/s]", "wz peer [rad/s]", "wz floor [rad/s]", "AIC / peer"]


def metric_header(names):
    """Column titles with units of the flat metrics ``names``."""
    return ["%s [%s]" % (HEADERS[m], UNITS[m]) for m in names]


def plot_pair(path, profile, traces, title, metrics):
    """PNG and PDF (figures.save): vx and wz over time (set point, ground truth of each
    controller, each its own colour and dash pattern), then the x-y paths against the ideal one;
    the legends outside the data, the title wrapped. ``profile``: aic_track_metrics' profile dict;
    ``traces``: controller -> columns of its closed_loop_run trace; ``metrics``: controller -> flat
    metrics. Returns ``path``."""
    from ..common import report
    plt = figures.pyplot()
    fig = plt.figure(figsize=(12, 11))
    (ax_v, ax_w), _, (ax_p,) = figures.grid(fig, 2, 0, 1)
    pts = profile["points"]
    t0 = min(c["t"][0] for c in traces.values())
    ts = [t0] + [p[0] for p in pts] + [profile["duration"]]
    for ax, ci, col, unit, name in ((ax_v, 1, "v_true", "m/s", "vx"), (ax_w, 2, "yaw_true", "rad/s", "wz")):
        ax.step(ts, [0.0] + [p[ci] for p in pts] + [pts[-1][ci]], where="post", label="set point",
                **figures.REFERENCE)
        for c in CONTROLLERS:
            if c in traces:
                ax.plot(traces[c]["t"], traces[c][col], label="%s (RMS %s %s)" % (LABELS[c], fmt(metrics[c][name + "_rms"]), unit),
                        **figures.style(CONTROLLERS.index(c)))
        ax.set_ylabel("%s [%s]" % (name, unit))
        ax.grid(True, alpha=0.3)
        figures.legend_outside(ax)
    plt.setp(ax_v.get_xticklabels(), visible=False)
    ax_w.set_xlabel("time since profile start [s]")
    figures.set_title(ax_v, title)
    ref = traces.get("stock") or next(iter(traces.values()))
    keep = ref["x_ideal"] == ref["x_ideal"]  # not NaN: the analysed span
    ideal = {"x": ref["x_ideal"][keep], "y": ref["y_ideal"][keep]}
    paths = []
    for c in CONTROLLERS:
        if c in traces:
            k = traces[c]["x_ideal"] == traces[c]["x_ideal"]
            paths.append(("%s (drift end %s m)" % (LABELS[c], fmt(metrics[c]["drift_final"])),
                          figures.style(CONTROLLERS.index(c)), traces[c]["x"][k], traces[c]["y"][k]))
    report.draw_paths(ax_p, ideal, paths)
    fig.tight_layout()
    return figures.save(fig, path, dpi=90)


def shown(path, root):
    """``path`` relative to the package's folder ``root`` when it is inside it (for the results
    page)."""
    rel = os.path.relpath(os.path.abspath(path), root)
    return path if rel.startswith("..") else rel


def floor_accelerations(variants):
    """The acceleration-bounded floor's limits of ``variants`` (track_suite.suite's variants, each
    with "floor_accelerations"), as text: variants with equal limits grouped, e.g. "4.20 m/s^2, 22.4
    rad/s^2 (A_w 42.87 rad/s^2) on default, payload_10kg"."""
    groups = {}
    for v in variants:
        acc = v.get("floor_accelerations")
        if acc:
            key = "%.2f m/s^2, %.1f rad/s^2 (A_w %.2f rad/s^2)" % (acc["linear"], acc["angular"],
                                                                  acc["wheel_acceleration"])
            groups.setdefault(key, []).append(v["name"])
    return "; ".join("%s on %s" % (k, ", ".join(names)) for k, names in groups.items()) or "none"


def results_md(report_data, plots_rel, root):
    """The results page (markdown) of a suite run (report_data: track_suite.suite's dict);
    plots_rel: profile -> image path relative to the page (the default plant's plots); root: the
    package's folder, which overlay paths are shown relative to."""
    d = report_data
    out = ["# Tracking benchmark: results", "",
           "Generated by `%s` (%d runs, %.0f s of simulated driving, and the ideal controller's learning on "
           "each of the %d pairs; wall time %.1f s with --jobs %d); do not edit. What the benchmark is: "
           "[tools.md](../tools.md), 'Tracking benchmark'." % (
               d["command"], len(d["runs"]), d["simulated_time"], len(d.get("plant_limits", [])), d["wall_time"],
               d["jobs"]), "",
           "- AIC configuration: `%s`; classical peer: `%s`; plant: `%s`; sensor noise of the plant YAML "
           "(seeded)." % (d["aic_config"], d.get("pi_config"), d["plant_config"]),
           "- Variants: %s." % ", ".join(
               "`%s`%s" % (v["name"], "" if v["overlay"] is None else " (`%s`)" % shown(v["overlay"], root)) for v in d["variants"]),
           "- Profiles: %s." % ", ".join("`%s` (%.1f s)" % (p["name"], p["duration"]) for p in d["profiles"]),
           "", "## AIC / stock (ratios of the ground-truth figures; < 1: the AIC tracks better)", "",
           "The geometric means are over the plant-following channels (a drift or heading figure: pairs that "
           "follow on both); the plant-limited ones (column 'plant limits', next section) apart.", "",
           md_table(RATIO_HEADER, ratio_rows(d["ratios"], {m: tuple(v) for m, v in d["geometric_mean"].items()},
                                             {m: tuple(v) for m, v in d.get("geometric_mean_limited", {}).items()})),
           "", "## AIC / classical peer and latency floor (RMS of the ground truth against the set point)", "",
           "The classical peer: PI loops on the wheel speeds and the yaw rate around the robot model's "
           "feed-forward through the latency, tuned on the AIC's driving cost (`closed_loop_run --controller pi`, "
           "`config/classical/pi.yaml`; `doc/active_inference.md`, 'A classical peer'). "
           "AIC / peer < 1: the AIC tracks better; * plant-limited (not in the geometric means). "
           "The acceleration-bounded floor is the latency floor's ideal servo on two wheels, each accelerating "
           "at most the wheel loop's A_w (a speed change and a turn share it; alone, vx: A_w r, wz: 2 A_w r / "
           "track; per variant: %s), taking its aim every %s (the AIC's action period) and holding it, "
           "reported beside the floor and not judged "
           "([tools.md](../tools.md), 'Latency floor'). The AIC's wheels and body take its error apart: its "
           "wheel odometry (the stock diff drive's, on its calibrated separation) against that floor, and its "
           "ground truth against its wheel odometry, the body's lag and slip behind the wheels." % (
               floor_accelerations(d["variants"]),
               "%g s" % d["floor_period"] if d.get("floor_period") else "sample"), "",
           md_table(PEER_HEADER, peer_rows(d.get("plant_limits", []), d["peer_geometric_mean"])),
           "", "## Plant-limited pairs", "",
           "A channel is plant-limited where the ideal controller (`closed_loop_run --controller ideal`: the "
           "command learned over repeated runs, knowing the profile in advance and the ground truth) ends above "
           "%.2f x the latency floor: the plant, not the controller, decides (what and why: "
           "[tools.md](../tools.md), 'Plant-limited pairs'). The reason is measured in the ideal run." % d.get(
               "plant_limit_ratio", plant_limits.PLANT_LIMIT_RATIO), "",
           md_table(LIMITED_HEADER, limited_rows(d.get("plant_limits", [])) or [["(none)"] + [""] * 7]),
           "", "## Ideal controller and latency floor (RMS error against the set point; * plant-limited)", "",
           md_table(IDEAL_HEADER, ideal_rows(d.get("plant_limits", []))),
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


def write_results(data, md_path, root, img_dir=None):
    """The results page (results_md; root: the package's folder) at md_path; with img_dir, the
    default plant's plots copied there (each PNG and its vector sibling, figures.vector_path) and
    linked (relative paths)."""
    plots_rel = {}
    if img_dir:
        os.makedirs(img_dir, exist_ok=True)
        for key, src in data["plots"].items():
            profile, variant = key.split("__", 1)
            if variant == "default":
                dst = os.path.join(img_dir, profile + ".png")
                shutil.copyfile(src, dst)
                if os.path.isfile(figures.vector_path(src)):
                    shutil.copyfile(figures.vector_path(src), figures.vector_path(dst))
                plots_rel[profile] = os.path.relpath(dst, os.path.dirname(os.path.abspath(md_path)))
    os.makedirs(os.path.dirname(os.path.abspath(md_path)), exist_ok=True)
    with open(md_path, "w") as f:
        f.write(results_md(data, plots_rel, root))


def print_summary(data, out):
    """Print the per-run table, the AIC / stock ratio table and a summary line of a suite run
    (``data``: track_suite.suite's dict; ``out``: its output folder)."""
    gm = {m: tuple(v) for m, v in data["geometric_mean"].items()}
    gl = {m: tuple(v) for m, v in data["geometric_mean_limited"].items()}
    print(text_table(["profile", "variant", "controller"] + metric_header(TABLE_METRICS), run_rows(data["runs"])))
    print("\nAIC / stock (< 1: the AIC tracks better; heading end compared by magnitude; geometric means over the "
          "plant-following channels, the plant-limited ones apart)")
    print(text_table(RATIO_HEADER, ratio_rows(data["ratios"], gm, gl)))
    print("\nAIC / classical peer and the latency floor (RMS; * plant-limited)")
    print(text_table(PEER_HEADER, peer_rows(data["plant_limits"], data["peer_geometric_mean"])))
    print("\nPlant-limited channels (the ideal controller > %.2f x the latency floor)" % data["plant_limit_ratio"])
    print(text_table(LIMITED_HEADER, limited_rows(data["plant_limits"]) or [["(none)"] + [""] * 7]))
    print("\n%d runs, %.0f s simulated, and the ideal controller's learning on %d pairs; wall time %.1f s "
          "(--jobs %d); results in %s" % (len(data["runs"]), data["simulated_time"], len(data["plant_limits"]),
                                          data["wall_time"], data["jobs"], out))
