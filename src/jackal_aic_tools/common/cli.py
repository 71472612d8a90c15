"""Command-line helpers shared by the package's tools: where the package's folder and C++
programs are (repo_root, find_executable, Tool), the profile and run options of aic_experiment.py
and aic_sweep.py, and running a C++ tool that prints JSON."""
import os

from . import profiles, recording


def package_path():
    """Source path of jackal_aic (through rospack), or None."""
    try:
        import rospkg
        return rospkg.RosPack().get_path("jackal_aic")
    except Exception:  # rospkg raises several kinds; all mean "not found"
        return None


def default_results_dir():
    """$AIC_RESULTS_DIR, else <package source>/results (git-ignored) in a source checkout,
    else ./results."""
    env = os.environ.get("AIC_RESULTS_DIR")
    if env:
        return env
    pkg = package_path()
    if pkg and os.path.isdir(os.path.join(os.path.realpath(pkg), ".git")) or \
            (pkg and os.path.exists(os.path.join(os.path.realpath(pkg), ".git"))):
        return os.path.join(os.path.realpath(pkg), "results")
    return os.path.abspath("results")


def add_profile_args(p):
    g = p.add_argument_group("set-point profile")
    g.add_argument("--profile", choices=("step", "angular", "arc", "square", "csv"), default="step",
                   help="step: linear step to --v; angular: step to --w; arc: both at once; square: wave "
                        "between --low and --high; csv: --csv file (default: %(default)s)")
    g.add_argument("--v", type=float, default=0.5, help="linear step size [m/s] (default %(default)s)")
    g.add_argument("--w", type=float, default=1.0, help="angular step size [rad/s] (default %(default)s)")
    g.add_argument("--t-step", type=float, default=0.5, help="time of the step after the profile starts [s]")
    g.add_argument("--hold", type=float, default=3.0, help="how long the step is held [s] (default %(default)s)")
    g.add_argument("--low", type=float, default=0.1, help="square wave low level [m/s] (default %(default)s)")
    g.add_argument("--high", type=float, default=0.5, help="square wave high level [m/s] (default %(default)s)")
    g.add_argument("--period", type=float, default=4.0, help="square wave period [s] (default %(default)s)")
    g.add_argument("--cycles", type=int, default=2, help="square wave periods (default %(default)s)")
    g.add_argument("--csv", help="CSV profile with header t,vx[,wz]; the last row's t ends it")


def make_profile(a):
    if a.profile == "step":
        return profiles.step(v=a.v, t_step=a.t_step, hold=a.hold)
    if a.profile == "angular":
        return profiles.step(v=0.0, w=a.w, t_step=a.t_step, hold=a.hold)
    if a.profile == "arc":
        return profiles.step(v=a.v, w=a.w, t_step=a.t_step, hold=a.hold)
    if a.profile == "square":
        return profiles.square(a.low, a.high, a.period, a.cycles)
    if not a.csv:
        raise ValueError("--profile csv needs --csv FILE")
    return profiles.from_csv(a.csv)


def add_run_args(p):
    g = p.add_argument_group("simulator and controller")
    g.add_argument("--config", help="controller YAML (default: <jackal_aic>/config/default.yaml)")
    g.add_argument("--launch", help="launch file (default: <jackal_aic>/launch/sim.launch); it gets "
                                    "config:=<written YAML> controller:=<aic|stock>")
    g.add_argument("--launch-arg", action="append", default=[], metavar="NAME:=VALUE",
                   help="extra launch argument, e.g. plant_config:=/path.yaml or use_sim_time:=true (repeatable)")
    g.add_argument("--settle", type=float, default=1.0, help="rest time before the profile starts [s]")
    g.add_argument("--ready-timeout", type=float, default=60.0,
                   help="wall time to wait for /odom, /cmd_drive and the belief [s]")
    g.add_argument("--bound-v", type=float, default=3.0, help="|v| [m/s] beyond which a run is unstable")
    g.add_argument("--bound-w", type=float, default=8.0, help="|w| [rad/s] beyond which a run is unstable")
    g.add_argument("--verbose", action="store_true", help="show the nodes' output")


def resolve_defaults(a):
    pkg = package_path()
    if not a.config:
        if not pkg:
            raise ValueError("jackal_aic not found by rospack: source the workspace or pass --config")
        a.config = os.path.join(pkg, "config", "default.yaml")
    if not a.launch:
        if not pkg:
            raise ValueError("jackal_aic not found by rospack: source the workspace or pass --launch")
        a.launch = os.path.join(pkg, "launch", "sim.launch")
    for f in (a.config, a.launch):
        if not os.path.isfile(f):
            raise ValueError("no such file: %s" % f)
    for la in a.launch_arg:
        if ":=" not in la:
            raise ValueError("--launch-arg %r is not NAME:=VALUE" % la)


def limits(a):
    return recording.StabilityLimits(v_bound=a.bound_v, w_bound=a.bound_w)


def repo_root(script_file):
    """The package's folder for a script at ``script_file``: its source checkout (the script's
    parent folder when it holds sim/config/robot_steps.yaml), else the installed package's
    share folder through rospack, else the script's parent folder."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(script_file)))
    if os.path.isfile(os.path.join(here, "sim", "config", "robot_steps.yaml")):
        return here
    return package_path() or here


def run_json_tool(cmd):
    """Run one of the package's C++ tools that print a JSON object on stdout (closed_loop_run,
    aic_predict, plant_fit, ...): ``cmd`` is the argument list, the executable first. Returns the
    parsed object (a dict). Raises RuntimeError with the command and the end of the tool's stderr
    when it exits non-zero."""
    import json
    import subprocess
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(cmd), out.stderr.strip()[-400:]))
    return json.loads(out.stdout)


def find_executable(name, script_file, tool):
    """Path of the package's C++ tool ``name`` (closed_loop_run, plant_fit, aic_predict, ...): the
    source checkout's workspace (<root>/.ws/devel/lib/jackal_aic), the sourced workspaces
    ($CMAKE_PREFIX_PATH), then catkin_find. Exits with "<tool>: <name> not found (build ...)"."""
    import subprocess
    import sys
    dirs = [os.path.join(repo_root(script_file), ".ws", "devel", "lib", "jackal_aic")] + \
        [d for d in os.environ.get("CMAKE_PREFIX_PATH", "").split(":") if d]
    for d in dirs:
        for c in (os.path.join(d, name), os.path.join(d, "lib", "jackal_aic", name)):
            if os.path.isfile(c) and os.access(c, os.X_OK):
                return c
    try:
        out = subprocess.run(["catkin_find", "--first-only", "jackal_aic", name], capture_output=True,
                             text=True, check=False).stdout.strip()
        if out:
            return out
    except OSError:
        pass
    sys.exit("%s: %s not found (build the workspace: bash dev/build.sh)" % (tool, name))


def effective_config(paths, script_file, tool, warn=True):
    """Every parameter of the node as it reads the YAML files ``paths`` in order over the schema's
    defaults (config/default.yaml holds only what has no default): a dict key -> value, from
    ``aic_params --yaml --config PATH ...``. Exits with the tool's message on a bad file. Its
    warnings (a controller unstable on the linear model at its rates, with the spectral radius:
    doc/tuning.md, 'The stability check at load') go to stderr as "<tool>: <warning>" unless
    ``warn`` is false; the configuration is returned all the same."""
    import subprocess
    import sys
    import yaml
    cmd = [find_executable("aic_params", script_file, tool), "--yaml"]
    for p in paths:
        cmd += ["--config", p]
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        sys.exit("%s: %s" % (tool, out.stderr.strip()))
    for line in out.stderr.splitlines() if warn else ():
        if "warning:" in line:
            print("%s: %s" % (tool, line), file=sys.stderr)
    return yaml.safe_load(out.stdout)


class Tool(object):
    """One command-line tool of the package (aic_tune, aic_reproduce, ...): its name, the prefix
    of its messages, and where it finds the package's folder and C++ programs, both from the
    path of its script (see repo_root, find_executable).

    Attributes: name (str), script (the script's path), root (the package's folder)."""

    def __init__(self, name, script_file):
        self.name = name
        self.script = script_file
        self.root = repo_root(script_file)

    def exe(self, program):
        """Path of the package's C++ program ``program``; exits with a message when it is not built
        (find_executable)."""
        return find_executable(program, self.script, self.name)

    def config(self, paths):
        """Every node parameter as the YAML files ``paths`` set it (effective_config): a dict."""
        return effective_config(paths, self.script, self.name)

    def path(self, *parts):
        """A path inside the package's folder: root joined with ``parts``."""
        return os.path.join(self.root, *parts)
