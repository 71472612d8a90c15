"""Tables and plots of experiment results (matplotlib, Agg backend: headless)."""
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import profiles, recording  # noqa: E402
from .tables import fmt, text_table  # noqa: E402

SIGNAL_LABEL = {"measured": "measured (/odom)", "belief": "belief", "drive": "drive cmd"}
#: Where plot_run's signals come from: a run through the nodes (topics) and a headless run
#: (closed_loop_run's trace columns; result["backend"] == "headless").
SOURCES = {"ros": {"odom": "measured (/odom)", "belief": "belief (/jackal_AIC/belief)", "drive": "/cmd_drive",
                   "separation": "/jackal_AIC/wheel_separation", "pose": "measured (/odom pose)"},
           "headless": {"odom": "ground truth (v_true, yaw_true)", "belief": "belief mu^(0)",
                        "drive": "drive command", "separation": "model", "pose": "ground truth"}}


def plot_run(path, arr, t0, profile, result, wheel_radius, wheel_sep, ideal=None):
    """PNG of one run: per channel, set point, measured velocity and belief [m/s or rad/s];
    below, the drive commands left/right [rad/s]; if ``arr`` has an "inference" stream with rows
    (recording.Recorder: stamp, then F, F_sensory, F_prior first), the free energy F and its
    sensory and prior parts against time, on a log scale; if ``arr`` has a "separation" stream
    (the AIC's b_hat [m], learned with learn_wheel_separation), b_hat against time; with ``ideal``
    ({"x", "y"} arrays [m], the profile's ideal path), last the x-y path of /odom against it.
    The legends name the topics, or for result["backend"] "headless" the trace's signals (SOURCES).
    Returns ``path``."""
    src = SOURCES["headless" if result.get("backend") == "headless" else "ros"]
    chans = profile.channels()
    sep = arr.get("separation")
    has_sep = sep is not None and sep.size > 0
    inf = arr.get("inference")
    has_f = inf is not None and inf.ndim == 2 and inf.shape[0] > 0 and inf.shape[1] >= 4
    timed = len(chans) + 1 + (1 if has_f else 0) + (1 if has_sep else 0)
    rows = timed + (1 if ideal is not None else 0)
    fig = plt.figure(figsize=(9, 3.0 * rows))
    axes = []
    for k in range(timed):
        axes.append(fig.add_subplot(rows, 1, k + 1, sharex=axes[0] if axes else None))
    for ax, ch in zip(axes, chans):
        ci = 1 + profiles.CHANNELS.index(ch)
        sp = arr["setpoint"]
        if sp.size:
            # the set point before the first recorded one is the rest level
            ax.step(np.r_[min(0.0, sp[0, 0] - t0), sp[:, 0] - t0, sp[-1, 0] - t0 + 0.02],
                    np.r_[0.0, sp[:, ci], sp[-1, ci]], where="post",
                    color="k", lw=1.2, ls="--", label="set point")
        for stream, label, color in (("odom", src["odom"], "C0"), ("belief", src["belief"], "C1")):
            a = arr[stream]
            if a.size:
                ax.plot(a[:, 0] - t0, a[:, ci], color=color, lw=1.2, label=label)
        d = arr["drive"]
        if d.size:
            eq = recording.drive_equivalent(d, wheel_radius, wheel_sep)
            ax.plot(eq[:, 0] - t0, eq[:, ci], color="C2", lw=0.9, alpha=0.7,
                    label="drive cmd as twist")
        name = "linear velocity x" if ch == "vx" else "angular velocity z"
        ax.set_ylabel("%s [%s]" % (name, profiles.UNITS[ch]))
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
        txt = segment_summary(result, ch)
        if txt:
            ax.text(0.99, 0.5, txt, transform=ax.transAxes, va="center", ha="right", fontsize=8,
                    family="monospace",
                    bbox=dict(boxstyle="round", fc="white", alpha=0.8))
    ax = axes[len(chans)]
    d = arr["drive"]
    if d.size:
        ax.step(d[:, 0] - t0, d[:, 1], where="post", color="C2", lw=1.0, label="left wheels (%s)" % src["drive"])
        ax.step(d[:, 0] - t0, d[:, 2], where="post", color="C3", lw=1.0, ls=":", label="right wheels (%s)" % src["drive"])
    ax.set_ylabel("drive command [rad/s]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    if has_f:
        draw_free_energy(axes[len(chans) + 1], inf[:, 0] - t0, inf[:, 1], inf[:, 2], inf[:, 3])
    if has_sep:
        ax = axes[-1]
        ax.step(sep[:, 0] - t0, sep[:, 1], where="post", color="C4", lw=1.2,
                label="b_hat (%s)" % src["separation"])
        ax.set_ylabel("wheel separation [m]")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    axes[-1].set_xlabel("time since profile start [s]")
    title = "%s: %s, %s" % (result["name"], result["controller"], result["profile"])
    if result["status"] != "ok":
        title += "  [%s: %s]" % (result["status"].upper(), result["reason"])
    axes[0].set_title(title, fontsize=10)
    for ax in axes[:-1]:
        plt.setp(ax.get_xticklabels(), visible=False)
    if ideal is not None:
        pose = arr["pose"]
        pose = pose[pose[:, 0] >= t0] if pose.size else pose
        ax = fig.add_subplot(rows, 1, rows)
        draw_paths(ax, ideal, [(src["pose"], "C0", pose[:, 1] if pose.size else [],
                                pose[:, 2] if pose.size else [])], path_summary(result.get("path")))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def draw_free_energy(ax, t, f, sensory, prior):
    """The free energy F (thesis eq. 3-10) and its sensory and prior sums [-] against ``t`` [s]
    (arrays of one length) on ``ax``, log scale (values <= 0 or non-finite are left out), with the
    peak and the final F in a box."""
    # F last and thin: it lies on its larger part, which stays visible around it.
    for y, label, color, lw in ((sensory, "F sensory (sensor prediction errors)", "C0", 2.4),
                                (prior, "F prior (state prediction errors)", "C3", 1.0), (f, "F", "k", 0.8)):
        y = np.where(np.isfinite(y) & (y > 0), y, np.nan)
        ax.plot(t, y, color=color, lw=lw, label=label, alpha=0.6 if lw > 2 else 1.0)
    ax.set_yscale("log")
    ax.set_ylabel("free energy [-]")
    ax.grid(True, alpha=0.3, which="both")
    ax.legend(loc="upper right", fontsize=8)
    ok = np.isfinite(f)
    if np.any(ok):
        ax.text(0.01, 0.05, "F peak %.3g at %.2f s, final %.3g" % (np.max(f[ok]), t[ok][np.argmax(f[ok])], f[ok][-1]),
                transform=ax.transAxes, fontsize=8, family="monospace", bbox=dict(boxstyle="round", fc="white", alpha=0.8))


def draw_paths(ax, ideal, paths, text=""):
    """x-y plot: the ideal path (``ideal``: {"x", "y"} [m], dashed black) and every measured path
    of ``paths`` (label, colour, x, y), with a start marker, equal axes and ``text`` in a box."""
    ax.plot(ideal["x"], ideal["y"], color="k", ls="--", lw=1.2, label="ideal (set point integrated)")
    if len(ideal["x"]):
        ax.plot(ideal["x"][:1], ideal["y"][:1], "ko", ms=4)
    for label, color, x, y in paths:
        ax.plot(x, y, color=color, lw=1.2, label=label)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if text:
        ax.text(0.01, 0.02, text, transform=ax.transAxes, va="bottom", ha="left", fontsize=8, family="monospace",
                bbox=dict(boxstyle="round", fc="white", alpha=0.8))


def path_summary(path):
    """One line of a path drift dict (aic_track_metrics' "path"), '' for None."""
    if not path:
        return ""
    return "drift: end %s m, max %s m, heading end %s rad" % (
        fmt(path.get("final_position_error")), fmt(path.get("max_position_error")),
        fmt(path.get("final_heading_error")))


def tracking_table(results):
    """Tracking table of one or more runs (result dicts with "tracking" and "path"): per run and
    measured twist, the RMS / max error of vx and wz and the path drift."""
    headers = ["run", "signal", "vx RMS [m/s]", "vx max [m/s]", "wz RMS [rad/s]", "wz max [rad/s]",
               "drift end [m]", "drift max [m]", "heading end [rad]"]
    rows = []
    for r in results:
        path = r.get("path") or {}
        for sig, m in sorted((r.get("tracking") or {}).items()):
            if not m:
                continue
            rows.append([r.get("name", "-"), sig, fmt(m["vx"]["rms"]), fmt(m["vx"]["max"]), fmt(m["wz"]["rms"]),
                         fmt(m["wz"]["max"]), fmt(path.get("final_position_error")),
                         fmt(path.get("max_position_error")), fmt(path.get("final_heading_error"))])
        if r.get("tracking_error"):
            rows.append([r.get("name", "-"), "error: " + r["tracking_error"][:80]] + [""] * 7)
    return format_table(headers, rows)


def segment_summary(result, ch):
    lines = []
    for seg in result.get("segments", [])[:3]:
        if seg["channel"] != ch:
            continue
        m = seg["metrics"].get("measured") or {}
        lines.append("%g->%g: rise %s s, settle %s s, OS %s %%" % (
            seg["start"], seg["target"], fmt(m.get("rise_time")), fmt(m.get("settling_time")),
            fmt(m.get("overshoot"), "%.1f")))
    return "\n".join(lines)


def format_table(headers, rows):
    """Fixed-width text table with a rule under the header (tables.text_table); every cell is a
    string."""
    return text_table(headers, rows, rule=True, rstrip=False)


def run_table(results, signals=("measured", "belief", "drive")):
    """Metrics table of one or more runs: one row per run, transition and signal."""
    headers = ["run", "controller", "status", "transition", "signal", "rise [s]", "settling [s]",
               "overshoot [%]", "ss error"]
    rows = []
    for r in results:
        if not r.get("segments"):
            rows.append([r["name"], r["controller"], r["status"], "-", "-", "-", "-", "-", "-"])
            continue
        for seg in r["segments"]:
            unit = profiles.UNITS[seg["channel"]]
            tr = "%s %g->%g %s" % (seg["channel"], seg["start"], seg["target"], unit)
            for sig in signals:
                m = seg["metrics"].get(sig)
                if m is None:
                    continue
                if "error" in m:
                    rows.append([r["name"], r["controller"], r["status"], tr, SIGNAL_LABEL[sig],
                                 "error: " + m["error"][:60], "", "", ""])
                    continue
                rows.append([r["name"], r["controller"], r["status"], tr, SIGNAL_LABEL[sig],
                             fmt(m["rise_time"]), fmt(m["settling_time"]), fmt(m["overshoot"], "%.1f"),
                             fmt(m["steady_state_error"], "%.4f") + " " + unit])
    return format_table(headers, rows)
