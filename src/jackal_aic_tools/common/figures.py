"""The style and the files of every figure the tools draw (one implementation, matplotlib >= 3.1
with the Agg backend, headless).

- series: a colour-blind-safe cycle, matplotlib's 'tab10' colours each with a dash pattern, so
  that two series never share both (:func:`style`); the set point and other references in black
  (:data:`REFERENCE`);
- titles wrapped to the width they have (:func:`wrap`, :func:`set_title`, :func:`suptitle`) and
  legends outside the data, to the right of a row (:func:`legend_outside`);
- a zoomed transient: beside each time axis, axes over the first :data:`ZOOM_WINDOW` seconds after
  each set-point change when those are few and short against the axis (:func:`zoom_events`,
  :func:`grid`, :func:`zoom`);
- one save call that writes the PNG and its vector sibling (PDF, same basename; :func:`save`).

Used by jackal_aic_tools.common.report (aic_experiment.py, aic_field_report.py, demo.sh),
reproduce (aic_reproduce.py), track.track_report (aic_track.py), compare.compare_plot
(aic_compare.py) and experiment.sweep (aic_sweep.py)."""
import math
import os
import textwrap

import numpy as np

#: matplotlib's 'tab10' colours (Vega's category10; colour-blind-safe as a qualitative cycle).
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
           "#bcbd22", "#17becf")
#: Dash patterns (matplotlib line styles: solid, dashed, dotted, dash-dot, dash-dot-dot [points]).
DASHES = ("-", (0, (5.0, 2.0)), (0, (1.2, 1.6)), (0, (6.0, 2.0, 1.2, 2.0)), (0, (3.5, 1.5, 1.2, 1.5, 1.2, 1.5)))
#: The style of the set point and of other references (black, dashed).
REFERENCE = {"color": "k", "ls": (0, (4.0, 2.0)), "lw": 1.1}
#: Line width of a series [points].
LINE_WIDTH = 1.3
#: The zoomed window: the first ZOOM_WINDOW [s] after a change, from ZOOM_LEAD [s] before it.
ZOOM_WINDOW = 1.0
ZOOM_LEAD = 0.1
#: A zoom is drawn when the time axis spans at least ZOOM_MIN_SPAN zoom windows and the changes
#: are at most MAX_ZOOMS (a step, an arc, a short square wave; not a tracking profile).
ZOOM_MIN_SPAN = 4.0
MAX_ZOOMS = 3
#: Width of a time axis against a zoom axis beside it.
MAIN_RATIO = 3.0
#: The vector format written beside every PNG.
VECTOR_FORMAT = "pdf"


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def style(i):
    """Colour and line style of series ``i`` (>= 0) as plot() keywords {"color", "ls", "lw"}:
    colour i mod 10 of COLOURS, dash pattern (i + i // 10) mod 5 of DASHES, so that the first 50
    series differ pairwise in colour or dash pattern and the first 5 in both. Raises ValueError
    for i < 0."""
    if i < 0:
        raise ValueError("style: series index %r < 0" % i)
    return {"color": COLOURS[i % len(COLOURS)], "ls": DASHES[(i + i // len(COLOURS)) % len(DASHES)],
            "lw": LINE_WIDTH}


def styles(n):
    """style(i) of i = 0 .. n - 1 (a list of ``n`` dicts)."""
    return [style(i) for i in range(n)]


def wrap(text, width_in, fontsize):
    """``text`` with its lines wrapped to fit ``width_in`` [inches] at ``fontsize`` [points]
    (an average glyph of 0.55 em; existing line breaks kept)."""
    chars = max(20, int(width_in * 72.0 / (0.55 * fontsize)))
    return "\n".join(textwrap.fill(line, chars, break_on_hyphens=False) for line in text.split("\n"))


def set_title(ax, text, fontsize=10, width_in=None):
    """``text`` as the title of ``ax``, wrapped to ``width_in`` [inches] (default the axes'
    width in its figure)."""
    if width_in is None:
        width_in = ax.get_position().width * ax.figure.get_figwidth()
    ax.set_title(wrap(text, width_in, fontsize), fontsize=fontsize)


def suptitle(fig, text, fontsize=10):
    """``text`` as the figure's title, wrapped to the figure's width. Returns the top of the
    room left for the axes as a fraction of the figure's height, for
    ``fig.tight_layout(rect=(0, 0, 1, top))`` (which leaves a figure title out of its layout)."""
    text = wrap(text, 0.95 * fig.get_figwidth(), fontsize)
    fig.suptitle(text, fontsize=fontsize)
    lines = text.count("\n") + 1
    return 1.0 - (1.4 * fontsize * lines / 72.0 + 0.1) / fig.get_figheight()


def legend_outside(ax, handles=None, labels=None, title=None, fontsize=8):
    """A legend to the right of ``ax`` (outside its data), top-aligned, of ``handles``/``labels``
    (default those of ``ax``), with ``title`` (e.g. the metrics of the row) above its entries.
    Returns the Legend, or None when there is nothing to show."""
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    if not handles and not title:
        return None
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                     fontsize=fontsize, title=title, title_fontsize=fontsize - 1)


def zoom_events(times, span):
    """The times [s] worth a zoomed transient: the distinct values of ``times`` (set-point
    changes), sorted, when there are 1 .. MAX_ZOOMS of them and ``span`` [s] (the time axis) is
    at least ZOOM_MIN_SPAN zoom windows; else []."""
    events = sorted(set(float(t) for t in times))
    if not events or len(events) > MAX_ZOOMS or span < ZOOM_MIN_SPAN * ZOOM_WINDOW:
        return []
    return events


def grid(fig, rows, n_zooms, extra_rows=0, height_ratios=None):
    """Axes of ``fig`` on one grid: ``rows`` time axes stacked in the left column (sharing x),
    beside each of them ``n_zooms`` zoom axes (one column per zoomed change, sharing x down the
    column), and below, ``extra_rows`` axes across the whole width (e.g. an x-y path).
    ``height_ratios``: rows + extra_rows relative heights (default equal). Returns (mains,
    zooms, extras): mains a list of ``rows`` axes, zooms a list per row of ``n_zooms`` axes,
    extras a list of ``extra_rows`` axes. Raises ValueError for rows < 1 or n_zooms < 0."""
    from matplotlib.gridspec import GridSpec
    if rows < 1 or n_zooms < 0 or extra_rows < 0:
        raise ValueError("grid: rows %r must be >= 1, n_zooms %r and extra_rows %r >= 0" % (rows, n_zooms, extra_rows))
    gs = GridSpec(rows + extra_rows, 1 + n_zooms, figure=fig, width_ratios=[MAIN_RATIO] + [1.0] * n_zooms,
                  height_ratios=height_ratios)
    mains, zooms = [], []
    for r in range(rows):
        mains.append(fig.add_subplot(gs[r, 0], sharex=mains[0] if mains else None))
        zooms.append([fig.add_subplot(gs[r, 1 + k], sharex=zooms[0][k] if zooms else None) for k in range(n_zooms)])
    extras = [fig.add_subplot(gs[rows + r, :]) for r in range(extra_rows)]
    return mains, zooms, extras


def zoom(ax, t_event, margin=0.08):
    """Limit ``ax`` (whose lines span a longer time) to [t_event - ZOOM_LEAD, t_event +
    ZOOM_WINDOW] [s] and its y range to the finite data of its lines inside that window, with
    ``margin`` (a fraction of the range, a factor on a log scale); titles it with the window."""
    t0, t1 = t_event - ZOOM_LEAD, t_event + ZOOM_WINDOW
    ax.set_xlim(t0, t1)
    log = ax.get_yscale() == "log"
    lo, hi = math.inf, -math.inf
    for line in ax.get_lines():
        x = np.asarray(line.get_xdata(), dtype=float)
        y = np.asarray(line.get_ydata(), dtype=float)
        if x.size == 0 or x.size != y.size:
            continue
        # a step line holds its value from the last sample before the window
        inside = (x >= t0) & (x <= t1)
        before = np.nonzero(x < t0)[0]
        if before.size:
            inside[before[-1]] = True
        v = y[inside & np.isfinite(y) & ((y > 0) if log else True)]
        if v.size:
            lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
    if lo <= hi:
        if log:
            ax.set_ylim(lo / (1.0 + 10 * margin), hi * (1.0 + 10 * margin))
        else:
            pad = margin * (hi - lo) if hi > lo else max(abs(hi), 1e-3) * margin
            ax.set_ylim(lo - pad, hi + pad)
    ax.set_title("first %g s after %.2f s" % (ZOOM_WINDOW, t_event), fontsize=8)


def vector_path(png_path):
    """The vector sibling of ``png_path`` (same basename, VECTOR_FORMAT)."""
    return os.path.splitext(png_path)[0] + "." + VECTOR_FORMAT


def save(fig, png_path, dpi=110):
    """Write ``fig`` as ``png_path`` (must end in .png) and as its vector sibling
    (vector_path()), both cropped to what is drawn (bbox_inches="tight": no title or legend
    cut), then close it. Returns ``png_path``. Raises ValueError when the name does not end in
    .png (nothing written)."""
    if not png_path.lower().endswith(".png"):
        raise ValueError("figures.save: %r does not end in .png" % png_path)
    try:
        for path in (png_path, vector_path(png_path)):
            fig.savefig(path, dpi=dpi, bbox_inches="tight", pad_inches=0.05)
    finally:
        pyplot().close(fig)
    return png_path
