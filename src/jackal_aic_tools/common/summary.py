"""Print the metrics table (step segments) and the tracking table (profiles) of the result JSONs
of aic_experiment runs, and their plots.

Usage: python3 -m jackal_aic_tools.common.summary [--tracking] RESULT.json [...]
  --tracking: the tracking table only (profile runs, whose every transition is a segment)
Exit status 0 when every run is ok, 2 when one is unstable, 1 when one failed.
"""
import json
import sys

from . import report


def main(argv):
    tracking_only = "--tracking" in argv
    argv = [a for a in argv if a != "--tracking"]
    if not argv:
        print(__doc__, file=sys.stderr)
        return 1
    results = []
    for p in argv:
        try:
            with open(p) as f:
                results.append(json.load(f))
        except (OSError, ValueError) as e:
            results.append({"name": p, "controller": "?", "status": "failed",
                            "reason": "no readable result (%s)" % e, "segments": [], "files": {}})
    if not tracking_only and any(r.get("segments") for r in results):
        print(report.run_table(results))
    if any(r.get("tracking") or r.get("tracking_error") for r in results):
        print(report.tracking_table(results))
    for r in results:
        if r["status"] != "ok":
            print("%s: %s (%s)" % (r["name"], r["status"], r["reason"]))
        if "png" in r.get("files", {}):
            print("plot (%s): %s" % (r["controller"], r["files"]["png"]))
    codes = [{"ok": 0, "unstable": 2}.get(r["status"], 1) for r in results]
    return 1 if 1 in codes else max(codes)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
