#!/usr/bin/env python3
"""aic_tune.py: model-based tuning of the active inference controller on the simulated Jackal.

The command line of jackal_aic_tools.tune.tune (the three stages: identify, search on the model,
refine in the simulator) and jackal_aic_tools.tune.tune_driving (--driving); --help describes both.
"""
import argparse
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.tune import tune, tune_driving, tune_pi


def main():
    """Parse the arguments, run the three stages and the verification (or --driving). Returns the
    exit status."""
    tool = cli.Tool("aic_tune", __file__)
    ap = argparse.ArgumentParser(description=tune.__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=tune.__doc__)
    ap.add_argument("--base", default=tool.path("config", "default.yaml"),
                    help="controller YAML whose node keys the result keeps: the goal or unbiased model's effective file "
                         "(aic_params --yaml; the robot model of config/default.yaml is identified, not tuned)")
    ap.add_argument("--write", help="write the winner as YAML here")
    ap.add_argument("--orders", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--popsize", type=int, default=12)
    ap.add_argument("--maxiter", type=int, default=40)
    ap.add_argument("--refine-evals", type=int, default=120,
                    help="simulator evaluations per Nelder-Mead start (each ~10 closed_loop_run runs)")
    ap.add_argument("--top", type=int, default=3, help="model candidates refined in the simulator")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--overshoot", type=float, default=4.0,
                    help="overshoot bound of the 0.1 / 0.3 / 0.5 / 1.0 m/s steps [%% of the step]")
    ap.add_argument("--robust-overshoot", type=float, default=10.0,
                    help="overshoot bound of the 0.5 m/s step with command_delay -+20 %% [%%]")
    ap.add_argument("--seeds", type=int, nargs="+", default=[42, 1, 2],
                    help="noise seeds (plant sensors.seed) of the 0.5 m/s step in the simulator cost")
    ap.add_argument("--turn-weight", type=float, default=1.0,
                    help="weight of the 1 rad/s turn's settling ratio above --turn-ratio; 0 = no turn in the cost")
    ap.add_argument("--turn-ratio", type=float, default=0.97, help="AIC / stock settling of the 1 rad/s turn")
    ap.add_argument("--skip-model", action="store_true",
                    help="skip stages 1-2: refine from the base config only")
    ap.add_argument("--max-radius", type=float, default=0.98)
    ap.add_argument("--robust", type=float, default=0.2, help="relative variation of plant gain and delay")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--driving", action="store_true",
                    help="tune for real driving from the base config (DRIVING_SPACE, jackal_aic_tools.track.driving)")
    ap.add_argument("--driving-variants", nargs="+", metavar="VARIANT",
                    default=["default"] + [tool.path("sim", "config", "variants", v + ".yaml")
                                           for v in ("turn_deficit", "latency_plus_20", "payload_10kg")],
                    help="--driving: plant variants of the tracking cost ('default' or an overlay YAML)")
    ap.add_argument("--controller", choices=("aic", "pi"), default="aic",
                    help="--driving: the controller tuned, aic or pi (the classical peer, config/classical/pi.yaml as "
                         "--base: its gains, jackal_aic_tools.tune.tune_pi)")
    a = ap.parse_args()
    if a.controller == "aic" and tool.config([a.base]).get("belief_model") == "robot":
        ap.error("--base %s drives with the robot model, whose parameters are identified, not tuned "
                 "(doc/active_inference.md, 'The robot model'); the tuner tunes the goal and unbiased models' "
                 "gains: give it that model's effective file, e.g. aic_params --yaml --config config/default.yaml "
                 "--config config/goal_model.yaml > base.yaml, then --base base.yaml" % a.base)
    if a.controller == "pi":
        if not a.driving:
            ap.error("--controller pi goes with --driving")
        if a.base == tool.path("config", "default.yaml"):
            a.base = tool.path("config", "classical/pi.yaml")
        return tune_pi.run(a, tool, " ".join(["aic_tune.py"] + sys.argv[1:]))
    return tune_driving.run(a, tool) if a.driving else tune.run(a, tool)


if __name__ == "__main__":
    sys.exit(main())
