#!/usr/bin/env python3
"""aic_ros_soak.py: the ROS soak: the simulated Jackal and jackal_AIC as ROS nodes (launch/sim.launch)
on the wall clock with random faults; the command line of jackal_aic_tools.robustness.soak (--help
describes what it prints). The headless soak of the closed loop, hours of driving faster than real
time, is the C++ tool aic_soak (doc/tools.md, 'Soak')."""
import argparse
import sys

from jackal_aic_tools.robustness import soak


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and run the soak test. Returns the exit
    status."""
    ap = argparse.ArgumentParser(description=soak.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--fault-every", type=float, default=20.0, help="seconds between injected faults")
    ap.add_argument("--config", default=None, help="controller YAML (default: config/default.yaml)")
    ap.add_argument("--warmup", type=float, default=10.0, help="seconds before the start sample")
    ap.add_argument("--output", help="also write the figures and the command to this Markdown file")
    args = ap.parse_args(argv)
    if args.minutes <= 0 or args.fault_every <= 0:
        ap.error("--minutes and --fault-every must be > 0")
    return soak.run(args, sys.argv[1:] if argv is None else argv)


if __name__ == "__main__":
    sys.exit(main())
