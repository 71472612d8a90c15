#!/usr/bin/env python3
"""aic_reproduce.py: reproduce the thesis's experiments on the simulated Jackal, one command.

The command line of jackal_aic_tools.reproduce.reproduce (the runs: reproduce_runs, the tables:
reproduce_tables); --help describes the tables and the backends.
"""
import argparse
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.reproduce import reproduce, reproduce_tables


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and run the reproduction. Returns the
    exit status."""
    tool = cli.Tool("aic_reproduce", __file__)
    ap = argparse.ArgumentParser(description=reproduce.__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=reproduce.__doc__.split("\n", 2)[2])
    ap.add_argument("--tables", nargs="+", default=reproduce_tables.ALL_TABLES, choices=reproduce_tables.ALL_TABLES)
    ap.add_argument("--backend", choices=("core", "ros"), default="core")
    ap.add_argument("--out", default=tool.path("results", "reproduction"))
    ap.add_argument("--config", default=tool.path("config", "thesis_equivalent.yaml"),
                    help="the thesis-equivalent controller YAML (default: %(default)s)")
    ap.add_argument("--improved-config", default=tool.path("config", "thesis_improved_exact.yaml"),
                    help="the improved controller's YAML, tables 5-9 and 5-10 (default: %(default)s)")
    ap.add_argument("--plant-config", default=None, help="plant YAML (default: the package's sim/config/plant.yaml)")
    ap.add_argument("--jobs", type=int, default=2, help="runs in parallel (core backend)")
    ap.add_argument("--rows", type=int, default=0, help="only the first N rows of each step table (0 = all)")
    ap.add_argument("--bisections", type=int, default=6, help="bisection steps per stability limit")
    ap.add_argument("--real-time-factor", type=float, default=2.0, help="ros backend: plant speed-up")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--doc", action="store_true",
                    help="also write the tables into doc/reproduction.md (every table, core backend, defaults)")
    a = ap.parse_args(argv)

    return reproduce.run(a, tool)


if __name__ == "__main__":
    sys.exit(main())
