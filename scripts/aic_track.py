#!/usr/bin/env python3
"""aic_track.py: the tracking benchmark of real driving, headless, in one command: the command
line of jackal_aic_tools.track.track_suite (the runs) and track_report (tables, plots, results page).
"""
import argparse
import os
import sys

from jackal_aic_tools.common import cli, profiles
from jackal_aic_tools.track import track_profiles, track_report, track_suite


def fail(message):
    """Print 'aic_track: message'; returns the exit status 1."""
    print("aic_track: %s" % message, file=sys.stderr)
    return 1


def write_mirrors(paths, directory):
    """Write profiles.mirror() of each profile CSV of ``paths`` to ``directory`` (created) as
    <stem>_mirror.csv and print each path. Returns the exit status (1, with the reason, for a
    profile that does not load)."""
    os.makedirs(directory, exist_ok=True)
    for path in paths:
        try:
            prof = profiles.from_csv(path)
        except ValueError as e:
            return fail(e)
        stem = os.path.splitext(os.path.basename(path))[0]
        print(profiles.mirror(prof).write_csv(os.path.join(directory, stem + "_mirror.csv")))
    return 0


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and run the benchmark or write the
    profiles. Returns the exit status."""
    tool = cli.Tool("aic_track", __file__)
    ROOT = tool.root
    p = argparse.ArgumentParser(description=track_suite.__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=track_suite.__doc__.split("\n\n", 1)[1])
    p.add_argument("--profiles", nargs="+", metavar="CSV", help="twist profiles (default: sim/profiles/*.csv)")
    p.add_argument("--variants", nargs="+", metavar="VARIANT",
                   help="'default' (the plant YAML alone) or overlay YAML files (default: default and "
                        "sim/config/variants/*.yaml)")
    p.add_argument("--aic-config", default=None, help="AIC YAML (default: config/default.yaml)")
    p.add_argument("--pi-config", default=None,
                   help="the classical peer's YAML (default: config/classical/pi.yaml)")
    p.add_argument("--plant-config", default=None, help="plant YAML (default: sim/config/plant.yaml)")
    p.add_argument("--jobs", type=int, default=2, help="closed_loop_run processes at once (default %(default)s)")
    p.add_argument("--out", default=None, help="output folder (default: <results>/tracking)")
    p.add_argument("--no-plots", action="store_true", help="skip the PNGs")
    p.add_argument("--results-md", metavar="FILE", help="write the results page (markdown) to FILE")
    p.add_argument("--doc", action="store_true",
                   help="write doc/results/tracking.md and the default plant's plots in doc/img/tracking/")
    p.add_argument("--write-profiles", metavar="DIR", help="write the benchmark's profiles to DIR and exit")
    p.add_argument("--write-random-profiles", metavar="DIR",
                   help="write --count seeded planner and joystick streams that are not the benchmark's to DIR "
                        "and exit (then: --profiles DIR/*.csv)")
    p.add_argument("--write-mirrored-profiles", metavar="DIR",
                   help="write the mirror of each profile of --profiles (time-reversed and negated, as "
                        "aic_field_trial.py drives every run back) to DIR as <name>_mirror.csv and exit "
                        "(then: --profiles DIR/*.csv)")
    p.add_argument("--count", type=int, default=4, help="--write-random-profiles: streams of each kind (default 4)")
    p.add_argument("--seed", type=int, default=1000, help="--write-random-profiles: first seed (default 1000)")
    a = p.parse_args(argv)
    if a.write_profiles:
        for path in track_profiles.write_all(a.write_profiles):
            print(path)
        return 0
    if a.write_random_profiles:
        if a.count < 1:
            p.error("--count must be >= 1")
        for path in track_profiles.write_random(a.write_random_profiles, a.count, a.seed):
            print(path)
        return 0
    if a.jobs < 1:
        p.error("--jobs must be >= 1")
    track_suite.complete_args(a, sys.argv[1:] if argv is None else list(argv), ROOT)
    if not a.profiles:
        return fail("no profiles (sim/profiles/*.csv is empty; write them with --write-profiles sim/profiles)")
    if a.write_mirrored_profiles:
        return write_mirrors(a.profiles, a.write_mirrored_profiles)
    if a.no_plots and a.doc:
        p.error("--doc needs the plots")
    try:
        data = track_suite.suite(a, tool)
    except track_suite.SuiteError as e:
        return fail(e)
    track_report.print_summary(data, a.out)
    if a.results_md:
        track_report.write_results(data, a.results_md, ROOT)
        print("results page: %s" % a.results_md)
    if a.doc:
        md = tool.path("doc", "results", "tracking.md")
        track_report.write_results(data, md, ROOT, tool.path("doc", "img", "tracking"))
        print("results page: %s" % md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
