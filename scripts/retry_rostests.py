#!/usr/bin/env python3
"""Run each failed rostest of jackal_aic once more (scripts/run_tests.sh calls this between
`catkin_make run_tests` and the summary).

The rostests run the controller against the plant in real time (wall clock). On a shared VM
the host can take 40-70 % of the CPU for seconds (vmstat `st`; doc/jackal_aic_node.md,
'Timing figures'), and a step measured across such a stall is the machine's, not the code's.
So a rostest that failed is run a second time, through the same catkin target (same command,
same result files, which the second run overwrites); if it fails again, it fails the suite.
gtests are never retried. Every retry is printed, and the names of the rostests that passed
only on the second run are written to RESULTS/retried.txt for the summary.

Usage: retry_rostests.py RESULTS_DIR BUILD_DIR [--max N]
  RESULTS_DIR  catkin's test_results directory (holds jackal_aic/*.xml)
  BUILD_DIR    the catkin build directory (holds the run_tests_* make targets)
  --max N      retry at most N rostests (default 6; more failures than that are not the
               machine's hiccup)
Exit: 0 always (the verdict is catkin_test_results' reading of the result files).
"""
import argparse
import glob
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

PKG = "jackal_aic"


def failed(path):
    """True if the JUnit file at `path` records a failure or an error (or cannot be read)."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError):
        return True
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    for s in suites:
        if int(s.get("failures", "0") or 0) + int(s.get("errors", "0") or 0) > 0:
            return True
        if s.findall(".//failure") or s.findall(".//error"):
            return True
    return False


def failed_rostests(results):
    """Names (test file stems) of the rostests whose rostest or rosunit result failed."""
    names = set()
    for path in glob.glob(os.path.join(results, PKG, "rostest-test_rostest_*.xml")):
        name = re.sub(r"^rostest-test_rostest_|\.xml$", "", os.path.basename(path))
        rosunit = os.path.join(results, PKG, "rosunit-%s.xml" % name)
        if failed(path) or (os.path.exists(rosunit) and failed(rosunit)):
            names.add(name)
    return sorted(names)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results")
    ap.add_argument("build")
    ap.add_argument("--max", type=int, default=6)
    args = ap.parse_args()
    names = failed_rostests(args.results)
    retried_ok = []
    if not names:
        return 0
    if len(names) > args.max:
        print("retry: %d rostests failed (more than %d): not retried" % (len(names), args.max))
        return 0
    print("retry: %d rostest(s) failed, running each once more: %s" % (len(names), ", ".join(names)))
    for name in names:
        target = "run_tests_%s_rostest_test_rostest_%s.test" % (PKG, name)
        log = os.path.join(args.results, "retry_%s.log" % name)
        with open(log, "w") as f:
            subprocess.call(["make", "-C", args.build, target], stdout=f, stderr=subprocess.STDOUT)
        if name in failed_rostests(args.results):
            print("retry: %s failed again (log: %s)" % (name, log))
        else:
            print("retry: %s passed on the second run (the first failed; flaky on this machine?)" % name)
            retried_ok.append(name)
    with open(os.path.join(args.results, "retried.txt"), "w") as f:
        f.write("".join(n + "\n" for n in retried_ok))
    return 0


if __name__ == "__main__":
    sys.exit(main())
