#!/usr/bin/env python3
"""aic_scorecard.py: the tuning acceptance set, the AIC against the stock controller, in one command.

The command line of jackal_aic_tools.tune.scorecard (the runs and the criteria) and
jackal_aic_tools.tune.scorecard_print (the tables); --help lists the criteria.
"""
import argparse
import os
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.tune import scorecard, scorecard_print


def main():
    """Parse the arguments, run the scorecard, print it (and write --json). Returns the exit status."""
    tool = cli.Tool("aic_scorecard", __file__)
    ROOT = tool.root
    ap = argparse.ArgumentParser(description=scorecard.__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=scorecard.__doc__)
    ap.add_argument("--aic-config", default=os.path.join(ROOT, "config", "default.yaml"), help="controller YAML")
    ap.add_argument("--pi-config", default=os.path.join(ROOT, "config", "classical", "pi.yaml"),
                    help="the classical peer's YAML, beside the stock controller in the driving set (--driving)")
    ap.add_argument("--plant-config", default=os.path.join(ROOT, "sim", "config", "plant.yaml"), help="plant YAML")
    ap.add_argument("--plant-overlay", action="append", default=[], metavar="FILE",
                    help="plant overlay YAML applied after --plant-config (repeatable), e.g. "
                         "sim/config/variants/slow_breakaway.yaml")
    ap.add_argument("--seeds", type=int, nargs="+", default=[42, 1, 2, 3, 4],
                    help="noise seeds (sensors.seed) of the 0.5 m/s step; the first is used for every other run's "
                         "steps (default 42 1 2 3 4; 42 is the plant YAML's)")
    ap.add_argument("--jobs", type=int, default=2, help="parallel closed_loop_run processes")
    ap.add_argument("--driving", action="store_true",
                    help="also the driving acceptance set (criterion 6: steps, turn deficit, tracking over the variants)")
    ap.add_argument("--json", help="write the figures and verdicts as JSON here")
    ap.add_argument("--doc", action="store_true",
                    help="also write the printout to doc/results/scorecard.txt with the command that made it, and "
                         "with --driving the ideal controller's runs to doc/results/ideal_runs.json")
    a = ap.parse_args()
    a.aic_config = os.path.abspath(a.aic_config)
    a.pi_config = os.path.abspath(a.pi_config)
    a.plant_config = os.path.abspath(a.plant_config)
    a.plant_overlay = [os.path.abspath(o) for o in a.plant_overlay]
    try:
        crit, ok = scorecard.scorecard(a, tool)
    except (RuntimeError, ValueError, KeyError) as e:
        print("aic_scorecard: %s" % e, file=sys.stderr)
        return 2
    return scorecard_print.report(crit, ok, a, ROOT)


if __name__ == "__main__":
    sys.exit(main())
