"""The figures of aic_compare.py, each written as PNG and PDF (figures.save): every series its own
colour and line style (figures.style), legends outside the axes."""
import os

import numpy as np

from ..common import figures


def _style(i, name):
    """plot() keywords of column ``i`` named ``name``: figures.style(i), the stock controller in
    black (the reference all variants are judged against)."""
    kw = figures.style(i)
    if name == "stock":
        kw["color"] = "k"
    return kw


def _save(fig, out_dir, name):
    """Write ``fig`` as <name>.png and its vector sibling into ``out_dir`` (figures.save); returns
    the two file names."""
    png = figures.save(fig, os.path.join(out_dir, name + ".png"), dpi=130)
    return [os.path.basename(png), os.path.basename(figures.vector_path(png))]


def plot_tracking(rows, names, out_dir):
    """tracking_ratios: per tracking row (profile and channel), each variant's RMS error / stock
    (floored at the noise level, log scale), the floor / stock as a black bar marker."""
    plt = figures.pyplot()
    track = [r for r in rows if r["section"] == "tracking"]
    x = np.arange(len(track))
    width = 0.8 / max(1, len(names))
    fig, ax = plt.subplots(figsize=(max(8.0, 0.75 * len(track) + 2.0), 4.2))
    for i, n in enumerate(names):
        vals = [r["ratios"].get(n) or np.nan for r in track]
        ax.bar(x - 0.4 + width * (i + 0.5), vals, width, color=figures.style(i)["color"], label=n,
               hatch=None if i < len(figures.COLOURS) else "//")
    ax.scatter(x, [r["ratios"].get("floor") or np.nan for r in track], marker="_", s=400, color="black",
               linewidths=2.5, label="latency floor", zorder=3)
    ax.axhline(1.0, color="0.3", lw=0.8)
    ax.set_yscale("log")
    from matplotlib.ticker import FuncFormatter
    for axis_formatter in (ax.yaxis.set_major_formatter, ax.yaxis.set_minor_formatter):
        axis_formatter(FuncFormatter(lambda y, _: "%.2g" % y))
    ax.set_xticks(x)
    ax.set_xticklabels([r["label"].replace(" RMS", "") for r in track], rotation=45, ha="right", fontsize=8)
    ax.set_ylabel("RMS error / stock controller's")
    figures.set_title(ax, "Tracking error against the stock controller (< 1: better)")
    ax.grid(True, axis="y", which="both", alpha=0.3)
    figures.legend_outside(ax)
    return _save(fig, out_dir, "tracking_ratios")


def plot_steps(runs, names, out_dir):
    """steps: the 0.5 m/s step's measured speed and the arc's gyro yaw rate of every column, whole
    run (left) and the first second zoomed (right, figures.zoom)."""
    plt = figures.pyplot()
    cols = names + ["stock"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), gridspec_kw={"width_ratios": [1.6, 1.0]})
    for row, (case, column, ylabel, target) in enumerate((("0.5 m/s", "v_odom", "speed (wheel odometry) [m/s]", 0.5),
                                                          ("arc speed", "yaw_true", "yaw rate (ground truth) [rad/s]",
                                                           0.5))):
        for i, col in enumerate(cols):
            r = runs[("step", case, col)]
            if r.trace is None:
                continue
            t, y = r.trace["t"], r.trace[column]
            label = col + (" (diverged)" if r.diverged else "")
            for ax in axes[row]:
                ax.plot(t, y, label=label, **_style(i, col))
        for ax in axes[row]:
            ax.axhline(target, color="0.5", lw=0.6, ls=":")
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(ylabel, fontsize=8)
        axes[row][0].set_title("%s: whole run" % ("0.5 m/s step" if row == 0 else "0.5 m/s + 0.5 rad/s arc"),
                               fontsize=9)
        figures.zoom(axes[row][1], 0.0)
        axes[row][1].set_ylim(-0.05, target * 1.3)  # a diverged variant must not flatten the others
    for ax in axes[1]:
        ax.set_xlabel("time from the step [s]")
    figures.legend_outside(axes[0][1], *axes[0][0].get_legend_handles_labels())
    fig.tight_layout()
    return _save(fig, out_dir, "steps")


def plot_belief(runs, names, out_dir, noise):
    """belief_error: belief mu^(0) minus the ground truth on the arc, vx and wz, the first 2 s,
    every variant; ``noise`` {unit: level} shaded."""
    plt = figures.pyplot()
    from ..common import tracking
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for i, n in enumerate(names):
        r = runs[("step", "arc speed", n)]
        if r.trace is None:
            continue
        t = r.trace["t"]
        for ax, ch in zip(axes, ("vx", "wz")):
            belief, truth = tracking.BELIEF_COLUMNS[ch]
            ax.plot(t, r.trace[belief] - r.trace[truth], label=n + (" (diverged)" if r.diverged else ""),
                    **_style(i, n))
    for ax, ch, unit in zip(axes, ("vx", "wz"), ("m/s", "rad/s")):
        ax.axhspan(-noise[unit], noise[unit], color="0.85", lw=0)
        ax.set_ylabel("belief \u2212 truth, %s [%s]" % (ch, unit), fontsize=8)
        ax.grid(True, alpha=0.3)
    figures.set_title(axes[0], "0.5 m/s + 0.5 rad/s arc: belief mu(0) \u2212 ground truth (grey: the noise level)",
                      fontsize=9)
    axes[1].set_xlabel("time from the step [s]")
    axes[1].set_xlim(-0.2, 2.0)
    figures.legend_outside(axes[0])
    fig.tight_layout()
    return _save(fig, out_dir, "belief_error")


def plot_all(runs, rows, variants, out_dir, noise):
    """Every figure of the runs ``runs`` and rows ``rows`` (compare.run_all, compare.rows_of) of
    ``variants`` into ``out_dir``; ``noise``: compare.NOISE. Returns the file names written."""
    names = [v.name for v in variants]
    return plot_tracking(rows, names, out_dir) + plot_steps(runs, names, out_dir) + plot_belief(runs, names, out_dir, noise)
