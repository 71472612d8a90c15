"""Numbers and tables as text: the one formatter of figures, fixed-width and Markdown tables.

Used by every tool that prints or writes a table (aic_tune.py, aic_scorecard.py, aic_track.py,
aic_sweep.py, aic_reproduce.py, jackal_aic_tools.common.report)."""
import math


def fmt(v, spec="%.3f"):
    """``v`` formatted with the %-format ``spec``; '-' for None or a non-finite float.

    Args: v: a number or None; spec: e.g. "%.3f", "%.1f". Returns a string."""
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else spec % v


def fmt_value(v):
    """A parameter value as a command line and a file name take it: a float as %g, a list as
    [a,b,...] of its values (no spaces), anything else (int, str) as str()."""
    if isinstance(v, float):
        return "%g" % v
    if isinstance(v, list):
        return "[" + ",".join(fmt_value(x) for x in v) + "]"
    return str(v)


def text_table(header, rows, rule=False, rstrip=True, indent=""):
    """A fixed-width text table: every column as wide as its widest cell, cells left-aligned and
    two spaces apart.

    Args: header: the column titles; rows: lists of cells (any value, shown with str()); rule: a
    line of dashes under the header; rstrip: strip each line's trailing blanks; indent: prefixed to
    every line. Returns the lines joined by newlines (no final newline)."""
    widths = [max(len(str(r[i])) for r in [header] + list(rows)) for i in range(len(header))]
    lines = ["  ".join(str(c).ljust(w) for c, w in zip(header, widths))]
    if rule:
        lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(str(c).ljust(w) for c, w in zip(r, widths)) for r in rows]
    return "\n".join(indent + (line.rstrip() if rstrip else line) for line in lines)


def md_table(header, rows):
    """A Markdown table of ``header`` (column titles) and ``rows`` (lists of cells, str() each);
    the lines joined by newlines, no final newline."""
    lines = ["| " + " | ".join(str(h) for h in header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)
