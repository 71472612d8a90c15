#!/usr/bin/env python3
"""The report of a field-trial session (jackal_aic_tools.field.field_report; doc/field_trials.md): from
the session's bags, aic_experiment.py's step table and aic_track.py's tracking table, AIC against
stock, with a plot per run; whether the two controllers ever fed the diff drive in the same 50 Hz
period; with --sim, the runs replayed on the simulated Jackal beside the robot's numbers.

Examples:
  aic_field_report.py ~/trial1                      # tables, per-run JSON and PNG in ~/trial1/report
  aic_field_report.py ~/trial1 --sim                # + robot against simulator (closed_loop_run)
  aic_field_report.py ~/trial1 --sim --identify     # + a wheel loop identified from the session's bag
  aic_field_report.py ~/trial1 --sim --identify --markdown ~/trial1/session.md   # the figures as Markdown

Exit status: 0 reported, 1 a bad folder or bag, 2 the controllers overlapped in a 50 Hz period.
"""
import argparse
import os
import shlex
import sys

from jackal_aic_tools.common import cli
from jackal_aic_tools.field import field_report


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("session", help="the session's folder (session.json, runs/)")
    p.add_argument("--out", help="report folder (default: SESSION/report)")
    p.add_argument("--no-plot", action="store_true", help="skip the PNGs")
    p.add_argument("--sim", action="store_true", help="replay the runs on the simulated Jackal and compare")
    p.add_argument("--aic-config", nargs="+", help="AIC YAML(s) for the simulation, merged in order "
                   "(default: config/default.yaml config/robot.yaml, as robot.launch)")
    p.add_argument("--overlay", action="append", default=[], help="plant overlay for the simulation, repeatable")
    p.add_argument("--identify", action="store_true", help="identify the wheel loop from the session's "
                   "identification bag (plant_identify.py --bag) and simulate with it")
    p.add_argument("--markdown", metavar="PATH", help="also write the session's figures (summary, tables, "
                   "switch check, robot against simulator) as a Markdown file")
    a = p.parse_args()
    out = a.out or os.path.join(a.session, "report")
    try:
        results = field_report.analyse_session(a.session, out, plot=not a.no_plot)
    except field_report.ReportError as e:
        print("aic_field_report: %s" % e, file=sys.stderr)
        return 1
    summary = field_report.session_summary(a.session)
    print(field_report.summary_text(summary))
    print()
    print(field_report.step_table(results))
    print()
    print(field_report.tracking_table(results))
    overlaps = [(r["name"],) + o for r in results for o in r["overlaps"]]
    print("\ncontroller switch: %s" % field_report.switch_text(overlaps))
    rows, overlays = None, []
    if a.sim:
        try:
            rows, overlays = field_report.robot_vs_sim(results, a.session, out, cli.Tool("aic_field_report", __file__),
                                                       a.aic_config, a.overlay, a.identify)
        except field_report.ReportError as e:
            print("aic_field_report: %s" % e, file=sys.stderr)
            return 1
        print("\nrobot against simulator%s:" % "".join(" + " + o for o in overlays))
        print(field_report.compare_table(rows))
        print()
        print(field_report.compare_summary(rows))
    if a.markdown:
        command = " ".join(["aic_field_report.py"] + [shlex.quote(x) for x in sys.argv[1:]])
        with open(a.markdown, "w") as f:
            f.write(field_report.markdown_report(summary, results, overlaps, rows, overlays, command) + "\n")
        print("\nMarkdown: %s" % a.markdown)
    print("\nper-run JSON, CSV and PNG: %s" % out)
    return 2 if overlaps else 0


if __name__ == "__main__":
    sys.exit(main())
