#!/usr/bin/env python3
"""aic_node_load.py: measure what the jackal_AIC node costs on the simulated Jackal, in wall-clock
time. The command line of jackal_aic_tools.robustness.node_load; --help describes the table."""
import argparse
import os
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.experiment import experiment
from jackal_aic_tools.robustness import node_load


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and measure (or, with --one, measure one
    rate in this process). Returns the exit status."""
    p = argparse.ArgumentParser(description=node_load.__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=node_load.__doc__.split("\n\n", 1)[1])
    p.add_argument("--rates", default="1000,10000", help="belief rates [Hz], comma-separated (default %(default)s)")
    p.add_argument("--duration", type=float, default=30.0, help="measured window [s] (default %(default)s)")
    p.add_argument("--warmup", type=float, default=5.0, help="ignored start [s] (default %(default)s)")
    p.add_argument("--config", default=os.path.join(cli.package_path(), "config", "default.yaml"),
                   help="controller YAML (default: config/default.yaml)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a parameter of the configuration, e.g. --set action_trigger=sample")
    p.add_argument("--threads", action="store_true", help="also print the CPU share [%%] of each node thread")
    p.add_argument("--schedules", default="event",
                   help="belief_schedule values to measure, comma-separated: event, timer (default %(default)s)")
    p.add_argument("--bare", action="store_true",
                   help="also run aic_timing at each rate: its bare clock_nanosleep loop's CPU share beside")
    p.add_argument("--base", choices=("direct", "stock_diff_drive"), default="direct",
                   help="sim.launch's base: stock_diff_drive runs the Jackal's stock controller (stock_base) "
                        "between the node and the plant, and its CPU is measured in the same run (default %(default)s)")
    p.add_argument("--output", help="also write the table, the command and the host's load to this Markdown file")
    p.add_argument("--one", type=float, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.duration <= 0 or a.warmup < 0:
        p.error("--duration must be > 0 and --warmup >= 0")
    try:
        overrides = dict(experiment.parse_override(o) for o in a.set)
    except ValueError as e:
        p.error(str(e))
    if a.one is not None:
        node_load.measure_one(a.one, a.config, a.duration, a.warmup, overrides, a.base)
        return 0
    try:
        rates = [float(r) for r in a.rates.split(",")]
    except ValueError:
        p.error("--rates: not a list of numbers: %s" % a.rates)
    schedules = [x.strip() for x in a.schedules.split(",") if x.strip()]
    if not schedules or any(x not in ("event", "timer") for x in schedules):
        p.error("--schedules: a list of event, timer")
    return node_load.measure(a, rates, schedules, argv, __file__)


if __name__ == "__main__":
    sys.exit(main())
