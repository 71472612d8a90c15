#!/usr/bin/env python3
"""record_identification.py: drive a Jackal through the identification sequence and record the bag
that `plant_identify.py --bag` identifies its wheel loop from: on the robot a ROS node
(jackal_aic_tools.identify.identification_recorder, whose docstring gives its parameters and safety rules),
or --headless the bag of the simulated Jackal (plant_replay)."""
import argparse
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.identify import bag_identification as bi
from jackal_aic_tools.identify import identification_recorder


def headless(argv):
    """The --headless mode; returns the exit status."""
    ap = argparse.ArgumentParser(prog="record_identification.py --headless",
                                 description="write the bag of the simulated Jackal driven through the sequence")
    ap.add_argument("--headless", metavar="OUT.bag", required=True)
    ap.add_argument("--sequence", default="standard", choices=sorted(bi.SEQUENCES))
    ap.add_argument("--max-linear", type=float, default=bi.MAX_LINEAR, help="[m/s], <= %g" % bi.MAX_LINEAR)
    ap.add_argument("--max-angular", type=float, default=bi.MAX_ANGULAR, help="[rad/s], <= %g" % bi.MAX_ANGULAR)
    ap.add_argument("--config", help="plant YAML (default: the package's sim/config/plant.yaml)")
    ap.add_argument("--overlay", action="append", default=[], help="plant overlay, repeatable")
    ap.add_argument("--set", action="append", default=[], help="plant KEY=VALUE, repeatable")
    ap.add_argument("--no-noise", action="store_true", help="ideal sensors (default: the plant YAML's noise)")
    ap.add_argument("--plant-replay", help="path of the plant_replay executable")
    a = ap.parse_args(argv)
    try:
        profile = bi.sequence_profile(a.sequence, a.max_linear, a.max_angular)
    except ValueError as e:
        ap.error(str(e))
    plant_replay = a.plant_replay or cli.find_executable("plant_replay", __file__, "record_identification")
    try:
        n = bi.write_simulated_bag(a.headless, plant_replay, profile, a.config, a.overlay, a.set, not a.no_noise)
    except (RuntimeError, OSError) as e:
        print("record_identification: %s" % e, file=sys.stderr)
        return 1
    print("record_identification: %s: sequence %s (%.1f s), %d joint-state samples, simulated Jackal%s"
          % (a.headless, a.sequence, profile.duration, n, "".join(" + " + o for o in a.overlay)))
    return 0


def main():
    """The ROS node, or --headless; -h / --help prints both usages without a ROS master. Returns the
    exit status."""
    if any(a == "--headless" or a.startswith("--headless=") for a in sys.argv[1:]):
        return headless(sys.argv[1:])
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print(__doc__.strip())
        print("\nOn the robot: rosrun jackal_aic record_identification.py [_PARAM:=VALUE ...] (the node's "
              "parameters: jackal_aic_tools.identify.identification_recorder).\n")
        return headless(["--help"])
    import rospy
    rospy.init_node("record_identification")
    try:
        rec = identification_recorder.Recorder()
    except ValueError as e:
        rospy.logfatal("record_identification: %s" % e)
        return 2
    rospy.on_shutdown(lambda: rec.send(0.0, 0.0))
    return rec.run()


if __name__ == "__main__":
    sys.exit(main())
