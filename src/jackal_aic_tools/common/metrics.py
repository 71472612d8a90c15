"""Step metrics through the core's ``aic_step_metrics`` CLI (the one implementation of the
metric definitions of thesis ch. 5, doc/active_inference.md: rise 10-90 %, settling +-5 %,
overshoot % of the step, steady-state error over the last 0.5 s, integral of the absolute error). This module only prepares
its input and parses its JSON output; it computes nothing itself.
"""
import json
import math
import os
import shutil
import subprocess
import tempfile

_cli_paths = {}

#: Keys of the dict returned by :func:`step_metrics` (units in brackets).
METRIC_KEYS = ("rise_time", "settling_time", "overshoot", "steady_state_error", "iae")
METRIC_UNITS = {"rise_time": "s", "settling_time": "s", "overshoot": "%", "steady_state_error": "", "iae": "s"}


class MetricsError(RuntimeError):
    """The metrics CLI is missing or failed."""


def find_tool(name, env_var):
    """Path of the package's C++ tool ``name`` (aic_step_metrics, aic_track_metrics): $<env_var>,
    else catkin_find in the sourced workspace, else PATH. Raises MetricsError with what to do
    when it is not found."""
    if name in _cli_paths:
        return _cli_paths[name]
    cand = os.environ.get(env_var)
    if not cand:
        try:
            out = subprocess.run(["catkin_find", "--first-only", "jackal_aic", name],
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, universal_newlines=True,
                                 timeout=30)
            cand = out.stdout.strip().splitlines()[0] if out.returncode == 0 and out.stdout.strip() else None
        except (OSError, subprocess.SubprocessError):
            cand = None
    if not cand:
        cand = shutil.which(name)
    if not cand or not os.access(cand, os.X_OK):
        raise MetricsError("%s not found: build the workspace (bash dev/build.sh) and "
                           "source .ws/devel/setup.bash, or set %s" % (name, env_var))
    _cli_paths[name] = cand
    return cand


def find_cli():
    """Path of ``aic_step_metrics`` (:func:`find_tool`; $AIC_STEP_METRICS overrides)."""
    return find_tool("aic_step_metrics", "AIC_STEP_METRICS")


def step_metrics(t, y, t_step, initial, target):
    """Metrics of one step response.

    \\param t        sample stamps [s], increasing (uneven spacing allowed)
    \\param y        samples (same length as t), in the unit of the step
    \\param t_step   time of the set-point change [s]
    \\param initial  level before the step
    \\param target   set point after the step
    \\return dict with METRIC_KEYS: rise_time [s], settling_time [s], overshoot [% of the
            step], steady_state_error [same unit as y; target - value, mean over the
            last 0.5 s], iae [unit of y * s; integral of |target - value| from the
            step]; a value is None (NaN from the
            CLI) when undefined, e.g. never settled.
    Raises MetricsError when the CLI fails.
    """
    if len(t) != len(y):
        raise ValueError("step_metrics: %d stamps but %d samples" % (len(t), len(y)))
    if len(t) < 2:
        raise MetricsError("step_metrics: fewer than two samples after the step")
    cli = find_cli()
    # the CLI wants strictly increasing stamps: keep the first of equal stamps
    keep_t, keep_y = [], []
    for a, b in zip(t, y):
        if not keep_t or a > keep_t[-1]:
            keep_t.append(a)
            keep_y.append(b)
    if len(keep_t) < 2:
        raise MetricsError("step_metrics: fewer than two distinct stamps after the step")
    t, y = keep_t, keep_y
    fd, path = tempfile.mkstemp(prefix="aic_metrics_", suffix=".csv")
    try:
        with os.fdopen(fd, "w") as f:
            f.write("time,value\n")
            for a, b in zip(t, y):
                f.write("%.9f,%.9g\n" % (a, b))
        cmd = _command(cli, path, t_step, initial, target)
        out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             universal_newlines=True, timeout=60)
        if out.returncode != 0:
            raise MetricsError("%s failed (exit %d): %s" % (" ".join(cmd), out.returncode, out.stderr.strip()))
        return _parse(out.stdout)
    finally:
        os.unlink(path)


def _command(cli, path, t_step, initial, target):
    return [cli, path, "--step-time", repr(float(t_step)), "--initial", repr(float(initial)),
            "--target", repr(float(target))]


def _parse(stdout):
    line = [l for l in stdout.strip().splitlines() if l.strip().startswith("{")]
    if not line:
        raise MetricsError("aic_step_metrics printed no JSON: %r" % stdout[:200])
    d = json.loads(line[-1])
    res = {}
    for k in METRIC_KEYS:
        v = d.get({"overshoot": "overshoot_percent"}.get(k, k))
        res[k] = float(v) if v is not None and math.isfinite(float(v)) else None
    return res
