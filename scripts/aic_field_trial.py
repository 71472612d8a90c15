#!/usr/bin/env python3
"""Field trial on the Jackal that is running: a session plan's step responses, square waves and
tracking profiles, each for the AIC and the stock controller, out and back inside the plan's
corridor, with a bag per run and a session summary (jackal_aic_tools.field.field_trial; doc/field_trials.md).

Examples:
  aic_field_trial.py --plan config/field_trials/standard.yaml --dry-run     # paths, corridor, limits, time
  aic_field_trial.py --plan config/field_trials/standard.yaml --out ~/trial1  # asks for 'yes' first
  aic_field_trial.py --plan ... --out ~/trial1 --resume    # after a stop: the runs not yet completed
  roslaunch jackal_aic field_trial.launch out:=$HOME/trial1 yes:=true

Exit status: 0 completed (or dry run), 2 refused (bad plan or arguments, robot not ready, not
confirmed), 3 stopped (a safety stop or Ctrl-C; the completed runs stay usable).
"""
import argparse
import sys

import rospy

from jackal_aic_tools.field import field_trial


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--plan", required=True, help="session plan YAML (config/field_trials/standard.yaml)")
    p.add_argument("--dry-run", action="store_true", help="print each run's path, the corridor, the duration and "
                   "the speed limits; publish nothing")
    p.add_argument("--out", default="~/jackal_field_trial", help="output folder (default: %(default)s)")
    p.add_argument("--resume", action="store_true", help="continue the session in --out: skip its completed runs")
    p.add_argument("--yes", action="store_true", help="start without asking (after reading the dry run)")
    p.add_argument("--set-point-topic", default="/twist_mux/cmd_vel",
                   help="the AIC's set point (robot.launch: twist_mux's output; default %(default)s)")
    p.add_argument("--cmd-vel-topic", default="/jackal_velocity_controller/cmd_vel",
                   help="the stock diff drive's input (default %(default)s)")
    p.add_argument("--odom-topic", default="/odometry/filtered",
                   help="odometry for the geofence and the report (default %(default)s)")
    p.add_argument("--joystick-topic", action="append", default=[],
                   help="a joystick twist topic whose activity stops the session; repeatable "
                        "(default: %s)" % ", ".join(field_trial.Topics().joystick))
    p.add_argument("--aic-node", default="/jackal_AIC", help="the AIC node (its ~enable_output, ~sensor_health)")
    p.add_argument("--start-timeout", type=float, default=20.0,
                   help="[s] to wait for /status, the sensors and the AIC (default %(default)s)")
    a = p.parse_args(rospy.myargv(sys.argv)[1:])
    if not 0.0 < a.start_timeout <= 600.0:
        p.error("--start-timeout must be in (0, 600] s")
    return field_trial.main(a)


if __name__ == "__main__":
    sys.exit(main())
