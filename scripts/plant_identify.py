#!/usr/bin/env python3
"""plant_identify.py: identify the simulated Jackal's MCU wheel loop from the robot's step responses
(jackal_aic_tools.identify.plant_identification) or from a robot's bag (--bag: jackal_aic_tools.identify.bag_fit)."""
import argparse
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.identify import bag_fit, bag_identification, plant_identification


def main():
    """Parse the arguments and identify (from the robot's steps, or --bag). Returns the exit status."""
    tool = cli.Tool("plant_identify", __file__)
    ap = argparse.ArgumentParser(description=plant_identification.__doc__.split("\n")[0])
    ap.add_argument("--config", default=tool.path("sim", "config", "plant.yaml"))
    ap.add_argument("--fit", nargs="+", default=None,
                    choices=sorted(set(plant_identification.PARAMETERS) | set(bag_identification.BAG_PARAMETERS)),
                    help="motor parameters to identify (others keep the YAML's values); default: %s; with "
                         "--bag: %s" % (", ".join(plant_identification.DEFAULT_FIT), ", ".join(bag_identification.BAG_PARAMETERS)))
    ap.add_argument("--starts", type=int, default=2, help="Nelder-Mead searches, from the best candidates")
    ap.add_argument("--jobs", type=int, default=2, help="parallel searches")
    ap.add_argument("--max-evals", type=int, default=150, help="evaluations per search")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--write", action="store_true", help="write the identified values into --config")
    ap.add_argument("--plant-fit", default=None, help="path of the plant_fit executable")
    ap.add_argument("--samples", type=int, default=40,
                    help="random candidates scored before the searches; the best start them")
    g = ap.add_argument_group("identification from a robot's bag")
    g.add_argument("--bag", help="the bag (see the module's docstring)")
    g.add_argument("--overlay", action="append", default=[],
                   help="plant overlay the fit starts from and keeps (e.g. the floor's), repeatable")
    g.add_argument("--overlay-out", help="the identified overlay (default: <bag>_wheel_loop.yaml)")
    g.add_argument("--model-out", help="the robot model's identified keys as one controller overlay: the "
                                       "sensor noises measured on the bag's rest segments, the yaw response fitted "
                                       "on its turns in place and the wheel loop's keys the fit moved "
                                       "(default: <bag>_robot_model.yaml)")
    g.add_argument("--json", help="also write the results as JSON")
    g.add_argument("--plant-replay", default=None, help="path of the plant_replay executable")
    a = ap.parse_args()
    if a.bag:
        return bag_fit.run(a, tool)
    if a.overlay or a.overlay_out or a.model_out or a.json:
        ap.error("--overlay, --overlay-out, --model-out and --json go with --bag")
    if a.fit and any(k not in plant_identification.PARAMETERS for k in a.fit):
        ap.error("without --bag --fit takes %s" % ", ".join(sorted(plant_identification.PARAMETERS)))
    return plant_identification.run(a, a.plant_fit or tool.exe("plant_fit"))


if __name__ == "__main__":
    sys.exit(main())
