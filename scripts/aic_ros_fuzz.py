#!/usr/bin/env python3
"""aic_ros_fuzz.py: fuzz the jackal_AIC node through ROS with seeded random messages on its
inputs; the command line of jackal_aic_tools.robustness.ros_fuzz (--help describes the verdict)."""
import argparse
import sys

from jackal_aic_tools.robustness import ros_fuzz


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and run the fuzz. Returns the exit
    status: 0 clean, 1 on a finding."""
    ap = argparse.ArgumentParser(description=ros_fuzz.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=60.0, help="wall time of the fuzz [s] (default %(default)s)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the generator (default %(default)s)")
    ap.add_argument("--rate", type=float, default=1000.0,
                    help="messages per second in the fuzz stretches (default %(default)s)")
    ap.add_argument("--output", help="also write the figures and the command to this Markdown file")
    args = ap.parse_args(argv)
    if args.seconds <= 0 or args.rate <= 0:
        ap.error("--seconds and --rate must be > 0")
    return ros_fuzz.run(args, sys.argv[1:] if argv is None else argv)


if __name__ == "__main__":
    sys.exit(main())
