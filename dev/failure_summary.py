#!/usr/bin/env python3
"""Print the message of every failed or erroring test case under a catkin test-results folder.

Usage: failure_summary.py RESULTS_DIR [--lines N]

Reads the JUnit XML files that gtest, rostest and rosunit write (RESULTS_DIR/<pkg>/*.xml)
and prints, for each <failure> or <error>, the file, the test case and the first N lines
(default 8) of its message. Prints nothing when every test passed. Exit 0 always: the verdict
is catkin_test_results'; this is the explanation, printed last so a log cut to its tail keeps it.
"""
import argparse
import glob
import os
import xml.etree.ElementTree as ET


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--lines", type=int, default=8)
    a = ap.parse_args()
    out = []
    for path in sorted(glob.glob(os.path.join(a.results, "**", "*.xml"), recursive=True)):
        try:
            root = ET.parse(path).getroot()
        except (ET.ParseError, OSError) as e:
            out.append("%s: unreadable (%s)" % (os.path.basename(path), e))
            continue
        for case in root.iter("testcase"):
            for bad in list(case.findall("failure")) + list(case.findall("error")):
                text = (bad.get("message") or "") + "\n" + (bad.text or "")
                lines = [l for l in text.strip().splitlines() if l.strip()]
                # A Python traceback: keep the message and the innermost frame of the test itself.
                frames = [i for i, l in enumerate(lines) if l.lstrip().startswith('File "')]
                if frames:
                    own = [i for i in frames if "/unittest/" not in lines[i]]
                    lines = lines[:frames[0]] + (lines[own[-1]:own[-1] + 2] if own else [])
                lines = lines[:a.lines]
                out.append("%s: %s.%s [%s]\n    %s" % (os.path.basename(path), case.get("classname", ""),
                                                      case.get("name", ""), bad.tag, "\n    ".join(lines)))
    if out:
        print("---- failures (%d) ----" % len(out))
        print("\n".join(out))


if __name__ == "__main__":
    main()
