#!/usr/bin/env python3
"""aic_compare.py: named controller variants side by side against the stock controller and the
latency floor, in one command: the command line of jackal_aic_tools.compare (variants: the variant
lines; compare: the runs, table, CSV and JSON; compare_plot: the figures).
"""
import argparse
import os
import shlex
import sys

from jackal_aic_tools.common import cli, closed_loop
from jackal_aic_tools.compare import compare, variants
from jackal_aic_tools.track import driving


def main(argv=None):
    """Parse the arguments (``argv``, default sys.argv[1:]) and run the comparison. Returns the exit
    status: 0 done, 1 a bad variant, file or a failed run, 2 bad arguments, 3 a diverged run
    (without --keep-going)."""
    tool = cli.Tool("aic_compare", __file__)
    ap = argparse.ArgumentParser(description=compare.__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=compare.__doc__.split("\n\n", 1)[1] + "\n" + variants.__doc__)
    ap.add_argument("--variant", action="append", default=[], metavar="NAME=BASE[+OVERLAY][:K=V,...]",
                    help="a variant (repeatable; after those of --variants)")
    ap.add_argument("--variants", metavar="FILE", help="a file of variant lines, e.g. config/compare/ablation.txt")
    ap.add_argument("--profiles", nargs="+", metavar="CSV", help="twist profiles (default: sim/profiles/*.csv)")
    ap.add_argument("--plants", nargs="+", metavar="VARIANT", default=["default"],
                    help="plants of the tracking runs: 'default' (the plant YAML alone) or overlay YAML files "
                         "(default: default)")
    ap.add_argument("--plant-config", default=tool.path("sim", "config", "plant.yaml"), help="plant YAML")
    ap.add_argument("--jobs", type=int, default=2, help="closed_loop_run processes at once (default %(default)s)")
    ap.add_argument("--out", default=os.path.join(cli.default_results_dir(), "compare"), help="output folder")
    ap.add_argument("--keep-going", action="store_true", help="a diverged run is marked, exit 0")
    ap.add_argument("--no-plot", action="store_true", help="no figures")
    ap.add_argument("--markdown", metavar="FILE",
                    help="also write a results page: one row per variant (e.g. doc/results/who_tracks.md)")
    ap.add_argument("--title", default="Variants against the stock controller and the latency floor",
                    help="--markdown: the page's title")
    a = ap.parse_args(argv)
    a.command_shown = " ".join(shlex.quote(x) for x in ["aic_compare.py"] + list(sys.argv[1:] if argv is None else argv))
    try:
        def effective(config):
            return tool.config([config])
        found = variants.read_file(a.variants, tool.root, effective) if a.variants else []
        found += [variants.parse(v, tool.root, effective) for v in a.variant]
        variants.check_names(found)
    except (variants.VariantError, OSError) as e:
        print("aic_compare: %s" % e, file=sys.stderr)
        return 1
    a.variants = found
    a.profiles = [os.path.abspath(p) for p in a.profiles] if a.profiles else driving.default_profiles(tool.root)
    a.plants = [p if p == "default" else os.path.abspath(p) for p in a.plants]
    for f in a.profiles + [p for p in a.plants if p != "default"] + [a.plant_config]:
        if not os.path.isfile(f):
            print("aic_compare: no such file: %s" % f, file=sys.stderr)
            return 1
    try:
        return compare.compare(a, tool)
    except closed_loop.RunError as e:
        print("aic_compare: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
