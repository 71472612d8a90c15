#!/usr/bin/env python3
"""aic_sweep.py: sweep step-response experiments of jackal_aic across parameters; one table, one
plot. The command line of jackal_aic_tools.experiment.sweep; --help shows examples."""
import argparse
import os
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.experiment import experiment, sweep


def parse(argv):
    """The parsed arguments of ``argv`` (default sys.argv[1:])."""
    p = argparse.ArgumentParser(description=sweep.__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=sweep.__doc__.split("\n\n", 1)[1])
    g = p.add_argument_group("swept dimensions (each takes one or more values)")
    g.add_argument("--belief-rate", nargs="+", type=float, metavar="HZ")
    g.add_argument("--action-rate", nargs="+", type=float, metavar="HZ")
    g.add_argument("--tau", nargs="+", type=float, metavar="S")
    g.add_argument("--k-mu", nargs="+", type=float, metavar="K")
    g.add_argument("--k-a", nargs="+", type=float, metavar="K")
    g.add_argument("--integrator", nargs="+", choices=("euler", "exact"))
    g.add_argument("--controller", nargs="+", choices=("aic", "stock"), default=["aic"])
    g.add_argument("--step", nargs="+", type=float, metavar="M_S",
                   help="linear step sizes [m/s] (step profile; default: --v)")
    g.add_argument("--param", nargs="+", action="append", default=[], metavar=("KEY", "VALUE"),
                   help="any other controller parameter and its values (repeatable)")
    p.add_argument("--rows", help="dimension shown as rows (default: step if swept, else the first swept one)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="fixed override for every AIC run")
    p.add_argument("--name", help="sweep name (default: from the swept dimensions)")
    p.add_argument("--out", help="output directory (default: results/sweep_<name>)")
    p.add_argument("--run-timeout", type=float, default=None,
                   help="wall-time limit per run [s] (default: 4x the profile + 120 s)")
    p.add_argument("--run-plots", action="store_true", help="also save a PNG per run")
    cli.add_profile_args(p)
    cli.add_run_args(p)
    return p.parse_args(argv)


def main(argv=None):
    """Parse and check the arguments, run the sweep. Returns the exit status."""
    a = parse(argv)
    try:
        cli.resolve_defaults(a)
        cli.make_profile(a)
        dims = sweep.dimensions(a)
        for s in a.set:
            experiment.parse_override(s)
    except ValueError as e:
        print("aic_sweep: %s" % e, file=sys.stderr)
        return 1
    return sweep.run(a, dims, os.path.dirname(os.path.realpath(__file__)))


if __name__ == "__main__":
    sys.exit(main())
