"""The headless closed loop from Python: one `closed_loop_run` (the node's logic, ControlLoop, on the
plant core, simulated time) with a controller configuration and its overrides, a plant variant and
a set-point profile; its JSON metrics and its trace as arrays.

A thin wrapper over the program, not a binding of the C++ core: the program is the one
implementation of the run, of its metrics (jackal_aic/analysis/step_metrics.hpp,
tracking_metrics.hpp) and of its divergence check, and the Python tools already run it; a binding
would be a second entry point to keep equal, and a second build (a Python extension module per
interpreter) on the robot's and CI's systems. A process costs a few milliseconds against the
0.1-2 s of a run.

    from jackal_aic_tools.common import closed_loop
    r = closed_loop.run(exe, "aic", ["--step", "0.5", "--turn", "0.5"], aic_config="config/default.yaml",
                        aic_sets=["k_a=4"], plant_config="sim/config/plant.yaml", trace=True)
    r.result["segments"][0]["measured"]["rise"]     # s
    r.trace["t"], r.trace["v_true"]                 # arrays, one per CSV column

Exit statuses of the program: 0 ran, 1 bad file or parameter, 2 bad argument, EXIT_DIVERGED a
diverged run (a runaway reset, non-finite values, a robot that never moved) unless KEEP_GOING.
"""
import json
import os
import shutil
import subprocess
import tempfile

from . import tracking

#: closed_loop_run's flag that reports a diverged run in its JSON ("diverged") and exits 0.
KEEP_GOING = "--keep-going"
#: closed_loop_run's exit status of a diverged run without KEEP_GOING.
EXIT_DIVERGED = 3


class RunError(RuntimeError):
    """closed_loop_run failed: ``command`` (the argument list), ``returncode``, ``message`` (its
    first line on stderr that names the program, else its last line)."""

    def __init__(self, command, returncode, stderr):
        lines = stderr.strip().splitlines()
        own = [l for l in lines if l.startswith("closed_loop_run")]
        self.command = list(command)
        self.returncode = returncode
        self.message = (own or lines[-1:] or ["exit %d" % returncode])[0]
        RuntimeError.__init__(self, "%s (exit %d): %s" % (" ".join(command), returncode, self.message))


class Diverged(RunError):
    """A diverged run (exit EXIT_DIVERGED): RunError's attributes and ``run``, the Run with its JSON
    (whose "diverged" names the cause) and its trace."""

    def __init__(self, command, returncode, stderr, run):
        RunError.__init__(self, command, returncode, stderr)
        self.run = run


class Run(object):
    """One finished run: ``command`` (argument list), ``result`` (closed_loop_run's JSON as a dict:
    "segments", "tracking", "path", "runaways", "diverged", ...; units in doc/tools.md) and
    ``trace`` ({column: float array}, NaN for empty cells; None without a trace). Column names
    carry their units in brackets where the program writes them (e.g. "mu0_x_dot[m/s]")."""

    def __init__(self, command, result, trace=None):
        self.command = command
        self.result = result
        self.trace = trace

    @property
    def diverged(self):
        """The cause of a divergence (str), or None."""
        return self.result.get("diverged")


def command(exe, controller, args, aic_config=None, aic_sets=(), plant_config=None, overlays=(), plant_sets=(),
            noise=True, keep_going=False):
    """closed_loop_run's argument list: the executable ``exe``, ``controller`` (aic, stock, open,
    ideal or pi), the seeded sensor noise of the plant YAML (``noise``), the plant YAML ``plant_config``
    (None: the package's), the profile arguments ``args`` (e.g. ["--step", "0.5"] or ["--profile",
    CSV]), with the AIC its YAML ``aic_config`` and KEY=VALUE overrides ``aic_sets`` (applied in
    order, as --aic-set; with the classical peer, pi, its YAML and overrides: --pi-config, --pi-set), plant overlay files ``overlays`` and plant KEY=VALUE overrides
    ``plant_sets``; KEEP_GOING with ``keep_going``. The order is the one every tool uses, so equal
    runs give equal command lines."""
    cmd = [exe, "--controller", controller]
    if noise:
        cmd.append("--noise")
    if plant_config:
        cmd += ["--config", plant_config]
    cmd += list(args)
    if controller in ("aic", "pi"):
        if aic_config:
            cmd += ["--%s-config" % controller, aic_config]
        for s in aic_sets:
            cmd += ["--%s-set" % controller, s]
    for o in overlays:
        cmd += ["--overlay", o]
    for s in plant_sets:
        cmd += ["--set", s]
    if keep_going:
        cmd.append(KEEP_GOING)
    return cmd


def plant_motor(plant_config, overlays=()):
    """The motor section of a plant as ``closed_loop_run --config PLANT --overlay O...`` reads it:
    the plant YAML ``plant_config``'s numeric motor keys, each overlay file of ``overlays`` (in
    order) replacing the keys it gives (sim/config/plant.yaml, 'motor'; e.g. "command_delay" [s],
    "proportional_limit" [N m]). Returns {key: float}; a key absent from every file is absent (the
    plant's default, plant_params.hpp, applies). Raises OSError when a file cannot be read,
    ValueError naming the file when it is not a YAML mapping."""
    import yaml
    motor = {}
    for path in [plant_config] + list(overlays):
        with open(path) as f:
            try:
                doc = yaml.safe_load(f) or {}
            except yaml.YAMLError as e:
                raise ValueError("%s: not YAML (%s)" % (path, str(e).splitlines()[0]))
        section = doc.get("motor") if isinstance(doc, dict) else None
        if not isinstance(doc, dict) or not isinstance(section or {}, dict):
            raise ValueError("%s: not a plant YAML (a mapping with a motor mapping)" % path)
        motor.update({k: float(v) for k, v in (section or {}).items() if isinstance(v, (int, float))})
    return motor


def execute(cmd, trace=False, timeout=600):
    """Run the argument list ``cmd`` (command()); with ``trace`` its trace is read into arrays
    (a temporary --csv file, removed after). Returns a Run. Raises Diverged on a diverged run
    without KEEP_GOING, RunError on any other failure (subprocess.TimeoutExpired after
    ``timeout`` s)."""
    tmp = tempfile.mkdtemp(prefix="closed_loop_") if trace else None
    try:
        full = list(cmd) + (["--csv", os.path.join(tmp, "trace.csv")] if trace else [])
        out = subprocess.run(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                             timeout=timeout)
        if out.returncode not in (0, EXIT_DIVERGED):
            raise RunError(cmd, out.returncode, out.stderr)
        columns = tracking.read_columns(os.path.join(tmp, "trace.csv")) if trace else None
        done = Run(list(cmd), json.loads(out.stdout), columns)
        if out.returncode == EXIT_DIVERGED:
            raise Diverged(cmd, out.returncode, out.stderr, done)
        return done
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)


def run(exe, controller, args, aic_config=None, aic_sets=(), plant_config=None, overlays=(), plant_sets=(),
        noise=True, keep_going=False, trace=False, timeout=600):
    """One run: command() then execute() (arguments as theirs). Returns a Run; raises Diverged or
    RunError."""
    return execute(command(exe, controller, args, aic_config, aic_sets, plant_config, overlays, plant_sets, noise,
                           keep_going), trace, timeout)
