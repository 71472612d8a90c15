#!/usr/bin/env python3
"""Run one step-response experiment of jackal_aic in the simulator.

Starts launch/sim.launch (the ODE plant + the AIC or the stock controller) under its own
ROS master on a free port, drives /jackal_AIC/set_point with a profile, records the set
point, /odom (ground-truth body twist), /jackal_AIC/belief and /cmd_drive with their
stamps, stops early if the loop diverges, then writes <out>/<name>.csv (+ .bag), .json,
.png and .pdf and prints the metrics (rise 10-90 %, settling +-5 %, overshoot, steady-state
error, computed by the core's aic_step_metrics) and the tracking of the whole profile (RMS and
max error of vx and wz, ground truth /odom and wheel odometry /joint_states, against the set
point; the /odom path's drift from the set point's ideal path; aic_track_metrics), with the x-y
path in the PNG. With the AIC the CSV and the bag also carry its stamped inference
(/jackal_AIC/inference, jackal_aic/InferenceState: F and its sensory and prior parts, the beliefs
and prediction errors of every order, the action, its prior, the attractor goal, the precisions,
b_hat, the gyro offset; columns named with their units as closed_loop_run --csv names them), and
the PNG has a panel of F(t) and its parts.

--headless runs the same profile on the headless closed loop instead (closed_loop_run: the
node's logic on the plant core, simulated time, no ROS master): <name>_trace.csv is its trace,
the PNG the same figure with F(t).

Examples:
  aic_experiment.py --v 0.5                               # default config, 0.5 m/s step
  aic_experiment.py --controller stock --v 1.0
  aic_experiment.py --config config/thesis_standard.yaml --set tau=0.01 --set k_a=10
  aic_experiment.py --profile square --low 0.1 --high 1.0 --period 4
  aic_experiment.py --profile csv --csv my_profile.csv --bag
  aic_experiment.py --headless --profile arc --v 0.5 --w 0.5     # the arc, headless, with F(t)

Exit status: 0 ran and stable, 2 unstable (diverged), 1 failed (error, node died, no data).
"""
import argparse
import logging
import sys

from jackal_aic_tools.common import cli, closed_loop, report
from jackal_aic_tools.experiment import experiment


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--controller", choices=("aic", "stock"), default="aic", help="default: %(default)s")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a controller parameter, e.g. --set tau=0.01 --set var_y=[2,1e5,1e5,1e5]")
    p.add_argument("--out", default=None, help="output directory (default: results/ of the source tree)")
    p.add_argument("--name", help="run name, used for the file names (default: <controller>_<profile>)")
    p.add_argument("--bag", action="store_true", help="also write a rosbag of the four topics")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG")
    p.add_argument("--headless", action="store_true",
                   help="run on the headless closed loop (closed_loop_run) instead of the nodes")
    cli.add_profile_args(p)
    cli.add_run_args(p)
    a = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
    try:
        cli.resolve_defaults(a)
        prof = cli.make_profile(a)
        overrides = dict(experiment.parse_override(s) for s in a.set)
        exp = experiment.Experiment(prof, controller=a.controller, config=a.config, overrides=overrides,
                                    launch_file=a.launch, launch_args=a.launch_arg,
                                    out_dir=a.out or cli.default_results_dir(), name=a.name, bag=a.bag,
                                    settle=a.settle, ready_timeout=a.ready_timeout, limits=cli.limits(a),
                                    verbose=a.verbose, plot=not a.no_plot)
    except (ValueError, OSError) as e:
        print("aic_experiment: %s" % e, file=sys.stderr)
        return 1
    try:
        res = experiment.run_headless(exp) if a.headless else experiment.run(exp)
    except (OSError, closed_loop.RunError) as e:
        print("aic_experiment: %s" % e, file=sys.stderr)
        return 1
    print(report.run_table([res]))
    if res.get("tracking") or res.get("tracking_error"):
        print(report.tracking_table([res]))
    if res["status"] != "ok":
        print("status: %s (%s)" % (res["status"], res["reason"]))
    for k in ("csv", "png", "pdf", "bag", "json", "track_csv", "ideal_csv"):
        if k in res["files"]:
            print("%-9s %s" % (k, res["files"][k]))
    return {"ok": 0, "unstable": 2}.get(res["status"], 1)


if __name__ == "__main__":
    sys.exit(main())
