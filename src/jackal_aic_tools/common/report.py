"""Tables and plots of experiment results (matplotlib, Agg backend: headless; the style and the
files of jackal_aic_tools.common.figures)."""
import numpy as np

from . import figures, inference, profiles, recording
from .tables import fmt, text_table

SIGNAL_LABEL = {"measured": "measured (/odom)", "belief": "belief", "drive": "drive cmd"}
#: Where plot_run's signals come from: a run through the nodes (topics) and a headless run
#: (closed_loop_run's trace columns; result["backend"] == "headless").
SOURCES = {"ros": {"odom": "measured (/odom)", "belief": "belief (/jackal_AIC/belief)", "drive": "/cmd_drive",
                   "separation": "/jackal_AIC/wheel_separation", "pose": "measured (/odom pose)",
                   "truth": "/odom"},
           "headless": {"odom": "ground truth (v_true, yaw_true)", "belief": "belief mu^(0)",
                        "drive": "drive command", "separation": "model", "pose": "ground truth",
                        "truth": "truth"}}
#: The series of plot_run, each its figures.style() index (one style per series in the figure).
SERIES = {"odom": 0, "belief": 1, "drive": 2, "error_vx": 3, "error_wz": 4, "left": 5, "right": 6,
          "F_sensory": 9, "F_prior": 8, "separation": 10, "pose": 0}
#: The robot model's slow states in plot_run's panel, in inference.ROBOT_STATES's order: label and
#: series index (figures.style) of each.
ROBOT_STATE_SERIES = (("$d_L$ [rad/s]", 5), ("$d_R$ [rad/s]", 6), ("$e_L$ [rad/s]", 15), ("$e_R$ [rad/s]", 16),
                      ("slip ratio $s$ [-]", 3), ("gyro offset $\\beta$ [rad/s]", 4))
CHANNEL_NAME = {"vx": "linear velocity x", "wz": "angular velocity z"}


def _draw_set_point(ax, arr, t0, ci):
    """The published set point of channel column ``ci`` as a step line (the rest level before
    the first recorded one)."""
    sp = arr["setpoint"]
    if sp.size:
        ax.step(np.r_[min(0.0, sp[0, 0] - t0), sp[:, 0] - t0, sp[-1, 0] - t0 + 0.02],
                np.r_[0.0, sp[:, ci], sp[-1, ci]], where="post", label="set point", **figures.REFERENCE)


def belief_error(belief, truth):
    """belief - truth per channel at the belief's stamps: ``belief`` (n,3: stamp [s], vx [m/s],
    wz [rad/s]), ``truth`` (m,3, the same columns, stamps increasing; interpolated linearly at the
    belief's stamps). Returns (k,3) (stamp, vx error, wz error) over the belief rows inside the
    truth's time span; (0,3) when either is empty."""
    if not (belief.size and truth.size):
        return np.zeros((0, 3))
    b = belief[(belief[:, 0] >= truth[0, 0]) & (belief[:, 0] <= truth[-1, 0])]
    out = np.empty((b.shape[0], 3))
    out[:, 0] = b[:, 0]
    for ci in (1, 2):
        out[:, ci] = b[:, ci] - np.interp(b[:, 0], truth[:, 0], truth[:, ci])
    return out


def robot_states(inf):
    """The robot model's slow states of an "inference" stream (recording.Recorder: stamp, then
    inference.columns() and inference.LEARNED): {column: (n,) array} of inference.ROBOT_STATES,
    or {} when the stream has none or the belief model had none (all NaN: the goal and
    unbiased models)."""
    if inf is None or inf.ndim != 2 or inf.shape[0] == 0:
        return {}
    first = 1 + inference.columns(1).index(inference.ROBOT_STATES[0])  # before the orders' columns
    if inf.shape[1] < first + len(inference.ROBOT_STATES):
        return {}
    out = {c: inf[:, first + k] for k, c in enumerate(inference.ROBOT_STATES)}
    return out if any(np.any(np.isfinite(v)) for v in out.values()) else {}


def plot_run(path, arr, t0, profile, result, wheel_radius, wheel_sep, ideal=None):
    """PNG and PDF (figures.save) of one run: per channel, set point, measured velocity, belief
    and the drive command as the twist it asks for [m/s or rad/s] (recording.drive_twist: with
    the learned b_hat of the "separation" stream per command, the configured ``wheel_sep`` [m]
    without one; a command, not a response: no metrics of it are shown); with beliefs, belief -
    truth per channel (belief_error, the truth being the "odom" stream); the drive commands
    left/right [rad/s]; if ``arr`` has an "inference" stream with rows (recording.Recorder: stamp,
    then F, F_sensory, F_prior first), the free energy F and its sensory and prior parts against
    time, on a log scale; with the robot model's slow states in that stream (robot_states()),
    the shortfalls d, the turn shortfalls e, the slip ratio s and the gyro offset beta against
    time; if ``arr`` has a "separation" stream (the AIC's b_hat [m], learned with
    learn_wheel_separation), b_hat against time; with ``ideal`` ({"x", "y"} arrays [m], the
    profile's ideal path), last the x-y path of /odom against it. Beside every time axis, the
    first second after each set-point change (figures.zoom_events of the profile's segments). The
    legends name the topics, or for result["backend"] "headless" the trace's signals (SOURCES),
    and carry the measured step metrics. Returns ``path``."""
    plt = figures.pyplot()
    src = SOURCES["headless" if result.get("backend") == "headless" else "ros"]
    chans = profile.channels()
    sep = arr.get("separation")
    has_sep = sep is not None and sep.size > 0
    inf = arr.get("inference")
    has_f = inf is not None and inf.ndim == 2 and inf.shape[0] > 0 and inf.shape[1] >= 4
    states = robot_states(inf) if has_f else {}
    err = belief_error(arr["belief"], arr["odom"])
    kinds = ["channel"] * len(chans) + (["error"] if err.size else []) + ["drive"] + (["F"] if has_f else []) + \
        (["states"] if states else []) + (["separation"] if has_sep else [])
    starts = [a[0, 0] - t0 for a in (arr["odom"], arr["drive"], arr["setpoint"]) if a.size]
    span = profile.duration - min([0.0] + starts)
    events = figures.zoom_events([s.t0 for s in profile.segments()], span)
    fig = plt.figure(figsize=(9.0 + 2.4 * len(events), 2.8 * len(kinds) + (4.0 if ideal is not None else 0.0)))
    mains, zooms, extras = figures.grid(fig, len(kinds), len(events), 1 if ideal is not None else 0,
                                        [1.0] * len(kinds) + ([1.4] if ideal is not None else []))
    d = arr["drive"]
    twist = recording.drive_twist(d, wheel_radius, wheel_sep, sep if has_sep else np.zeros((0, 2))) if d.size else d
    b_label = "learned $\\hat{b}$" if has_sep else "configured $b$"
    for row, (kind, ax) in enumerate(zip(kinds, mains)):
        axs = [ax] + zooms[row]
        title = None
        if kind == "channel":
            ch = chans[row]
            ci = 1 + profiles.CHANNELS.index(ch)
            for a in axs:
                _draw_set_point(a, arr, t0, ci)
                for stream in ("odom", "belief"):
                    if arr[stream].size:
                        a.plot(arr[stream][:, 0] - t0, arr[stream][:, ci], label=src[stream],
                               **figures.style(SERIES[stream]))
                if d.size:
                    a.plot(twist[:, 0] - t0, twist[:, ci], label="drive cmd as twist (%s)" % b_label,
                           **figures.style(SERIES["drive"]))
            ax.set_ylabel("%s [%s]" % (CHANNEL_NAME[ch], profiles.UNITS[ch]))
            title = segment_summary(result, ch) or None
        elif kind == "error":
            for a in axs:
                a.axhline(0.0, **figures.REFERENCE)
                for ch in chans:
                    ci = 1 + profiles.CHANNELS.index(ch)
                    a.plot(err[:, 0] - t0, err[:, ci], label="%s [%s]" % (ch, profiles.UNITS[ch]),
                           **figures.style(SERIES["error_" + ch]))
            ax.set_ylabel("belief \u2212 %s\n[m/s or rad/s]" % src["truth"])
        elif kind == "drive":
            if d.size:
                for a in axs:
                    a.step(d[:, 0] - t0, d[:, 1], where="post", label="left wheels (%s)" % src["drive"],
                           **figures.style(SERIES["left"]))
                    a.step(d[:, 0] - t0, d[:, 2], where="post", label="right wheels (%s)" % src["drive"],
                           **figures.style(SERIES["right"]))
            ax.set_ylabel("drive command [rad/s]")
        elif kind == "F":
            for a in axs:
                draw_free_energy(a, inf[:, 0] - t0, inf[:, 1], inf[:, 2], inf[:, 3], text=a is ax)
        elif kind == "states":
            for a in axs:
                a.axhline(0.0, **figures.REFERENCE)
                for col, (label, k) in zip(inference.ROBOT_STATES, ROBOT_STATE_SERIES):
                    a.plot(inf[:, 0] - t0, states[col], label=label, **figures.style(k))
            ax.set_ylabel("robot model's\nslow states")
        else:
            for a in axs:
                a.step(sep[:, 0] - t0, sep[:, 1], where="post", label="$\\hat{b}$ (%s)" % src["separation"],
                       **figures.style(SERIES["separation"]))
            ax.set_ylabel("wheel separation [m]")
        for a in axs:
            a.grid(True, alpha=0.3, which="both" if kind == "F" else "major")
        for a, t in zip(zooms[row], events):
            figures.zoom(a, t)
            if row:
                a.set_title("")
        figures.legend_outside(axs[-1], *ax.get_legend_handles_labels(), title=title)
    mains[-1].set_xlabel("time since profile start [s]")
    for a, t in zip(zooms[-1], events):
        a.set_xlabel("time [s]")
    for col in [mains] + [[z[k] for z in zooms] for k in range(len(events))]:
        for a in col[:-1]:
            plt.setp(a.get_xticklabels(), visible=False)
    title = "%s: %s, %s" % (result["name"], result["controller"], result["profile"])
    if result["status"] != "ok":
        title += "  [%s: %s]" % (result["status"].upper(), result["reason"])
    figures.set_title(mains[0], title)
    if ideal is not None:
        pose = arr["pose"]
        pose = pose[pose[:, 0] >= t0] if pose.size else pose
        draw_paths(extras[0], ideal, [(src["pose"], figures.style(SERIES["pose"]), pose[:, 1] if pose.size else [],
                                       pose[:, 2] if pose.size else [])], path_summary(result.get("path")))
    fig.tight_layout()
    return figures.save(fig, path)


def draw_free_energy(ax, t, f, sensory, prior, text=True):
    """The free energy F (thesis eq. 3-10) and its sensory and prior sums [-] against ``t`` [s]
    (arrays of one length) on ``ax``, log scale (values <= 0 or non-finite are left out), with
    ``text`` the peak and the final F in a box."""
    # F last and thin: it lies on its larger part, which stays visible around it.
    for y, label, key, lw in ((sensory, "F sensory (sensor prediction errors)", "F_sensory", 3.0),
                              (prior, "F prior (state prediction errors)", "F_prior", None), (f, "F", "F", 0.8)):
        y = np.where(np.isfinite(y) & (y > 0), y, np.nan)
        if key == "F":
            kw = dict(figures.REFERENCE, ls="-", lw=lw)
        else:
            kw = figures.style(SERIES[key])
        if key == "F_sensory":  # wide and solid under F, which follows it closely
            kw.update(ls="-", lw=lw, alpha=0.6)
        ax.plot(t, y, label=label, **kw)
    ax.set_yscale("log")
    ax.set_ylabel("free energy [-]")
    ok = np.isfinite(f)
    if text and np.any(ok):
        ax.text(0.01, 0.05, "F peak %.3g at %.2f s, final %.3g" % (np.max(f[ok]), t[ok][np.argmax(f[ok])], f[ok][-1]),
                transform=ax.transAxes, fontsize=8, family="monospace", bbox=dict(boxstyle="round", fc="white", alpha=0.8))


def draw_paths(ax, ideal, paths, text=""):
    """x-y plot: the ideal path (``ideal``: {"x", "y"} [m], figures.REFERENCE) and every measured
    path of ``paths`` (label, style (plot() keywords, figures.style), x, y), with a start marker,
    equal axes, ``text`` in a box under the axes and the legend outside to the right."""
    ax.plot(ideal["x"], ideal["y"], label="ideal (set point integrated)", **figures.REFERENCE)
    if len(ideal["x"]):
        ax.plot(ideal["x"][:1], ideal["y"][:1], "ko", ms=4)
    for label, kw, x, y in paths:
        ax.plot(x, y, label=label, **kw)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, alpha=0.3)
    figures.legend_outside(ax, title=text or None)


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
