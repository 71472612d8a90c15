"""The figures of aic_compare.py, each written as PNG and PDF: every series its own colour and
line style, legends outside the axes."""
import os

import numpy as np

STYLES = ["-", "--", "-.", ":"]


def _styles(n):
    """(colour, line style) of ``n`` series: tab10's colours, the line styles cycling with them."""
    import matplotlib.pyplot as plt
    colours = plt.get_cmap("tab10").colors
    return [(colours[i % len(colours)], STYLES[(i // 2) % len(STYLES)] if i else "-") for i in range(n)]


def _save(fig, out_dir, name):
    """Write ``fig`` as <name>.png and <name>.pdf into ``out_dir``; returns the two file names."""
    files = []
    for ext in ("png", "pdf"):
        fig.savefig(os.path.join(out_dir, "%s.%s" % (name, ext)), dpi=130, bbox_inches="tight")
        files.append("%s.%s" % (name, ext))
    return files


def plot_tracking(rows, names, out_dir):
    """tracking_ratios: per tracking row (profile and channel), each variant's RMS error / stock
    (floored at the noise level, log scale), the floor / stock as a black bar marker."""
    import matplotlib.pyplot as plt
    track = [r for r in rows if r["section"] == "tracking"]
    x = np.arange(len(track))
    width = 0.8 / max(1, len(names))
    fig, ax = plt.subplots(figsize=(max(8.0, 0.75 * len(track) + 2.0), 4.2))
    for i, ((colour, _), n) in enumerate(zip(_styles(len(names)), names)):
        vals = [r["ratios"].get(n) or np.nan for r in track]
        ax.bar(x - 0.4 + width * (i + 0.5), vals, width, color=colour, label=n,
               hatch=None if i < 10 else "//")
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
    ax.set_title("Tracking error against the stock controller (< 1: better)", fontsize=10)
    ax.grid(True, axis="y", which="both", alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    files = _save(fig, out_dir, "tracking_ratios")
    plt.close(fig)
    return files


def plot_steps(runs, names, out_dir):
    """steps: the 0.5 m/s step's measured speed and the arc's gyro yaw rate of every column, whole
    run (left) and the first 0.8 s zoomed (right)."""
    import matplotlib.pyplot as plt
    cols = names + ["stock"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), gridspec_kw={"width_ratios": [1.6, 1.0]})
    for row, (case, column, ylabel, target) in enumerate((("0.5 m/s", "v_odom", "speed (wheel odometry) [m/s]", 0.5),
                                                          ("arc speed", "yaw_true", "yaw rate (ground truth) [rad/s]",
                                                           0.5))):
        for (colour, style), col in zip(_styles(len(cols)), cols):
            r = runs[("step", case, col)]
            if r.trace is None:
                continue
            t, y = r.trace["t"], r.trace[column]
            label = col + (" (diverged)" if r.diverged else "")
            for ax in axes[row]:
                ax.plot(t, y, color=colour if col != "stock" else "black", ls=style, lw=1.2, label=label)
        for ax in axes[row]:
            ax.axhline(target, color="0.5", lw=0.6, ls=":")
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(ylabel, fontsize=8)
        axes[row][0].set_title("%s: whole run" % ("0.5 m/s step" if row == 0 else "0.5 m/s + 0.5 rad/s arc"),
                               fontsize=9)
        axes[row][1].set_title("transient (zoomed)", fontsize=9)
        axes[row][1].set_xlim(-0.05, 0.8)
        axes[row][1].set_ylim(-0.05, target * 1.3)
    for ax in axes[1]:
        ax.set_xlabel("time from the step [s]")
    axes[0][1].legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
    fig.tight_layout()
    files = _save(fig, out_dir, "steps")
    plt.close(fig)
    return files


def plot_belief(runs, names, out_dir, noise):
    """belief_error: belief mu^(0) minus the ground truth on the arc, vx and wz, the first 2 s,
    every variant; ``noise`` {unit: level} shaded."""
    import matplotlib.pyplot as plt
    from ..common import tracking
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for (colour, style), n in zip(_styles(len(names)), names):
        r = runs[("step", "arc speed", n)]
        if r.trace is None:
            continue
        t = r.trace["t"]
        for ax, ch in zip(axes, ("vx", "wz")):
            belief, truth = tracking.BELIEF_COLUMNS[ch]
            ax.plot(t, r.trace[belief] - r.trace[truth], color=colour, ls=style, lw=1.2,
                    label=n + (" (diverged)" if r.diverged else ""))
    for ax, ch, unit in zip(axes, ("vx", "wz"), ("m/s", "rad/s")):
        ax.axhspan(-noise[unit], noise[unit], color="0.85", lw=0)
        ax.set_ylabel("belief - truth, %s [%s]" % (ch, unit), fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[0].set_title("0.5 m/s + 0.5 rad/s arc: belief mu(0) - ground truth (grey: the noise level)", fontsize=9)
    axes[1].set_xlabel("time from the step [s]")
    axes[1].set_xlim(-0.2, 2.0)
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    files = _save(fig, out_dir, "belief_error")
    plt.close(fig)
    return files


def plot_all(runs, rows, variants, out_dir, noise):
    """Every figure of the runs ``runs`` and rows ``rows`` (compare.run_all, compare.rows_of) of
    ``variants`` into ``out_dir``; ``noise``: compare.NOISE. Returns the file names written."""
    import matplotlib
    matplotlib.use("Agg")
    names = [v.name for v in variants]
    return plot_tracking(rows, names, out_dir) + plot_steps(runs, names, out_dir) + plot_belief(runs, names, out_dir, noise)
