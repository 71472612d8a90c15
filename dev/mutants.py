#!/usr/bin/env python3
"""Fault seeding: does the test suite catch a broken guard or equation?

Each mutant of the list (default dev/mutants.txt) is one edit of one source file: a guard removed
or an equation broken. The tool copies the repository's files (git ls-files) into a scratch
catkin workspace, builds the gtest targets there once, then per mutant: applies the edit, rebuilds
only the targets the mutant names (default: the core gtests, test_core_*), runs them, records
which tests failed, and restores the file. A mutant is caught when at least one test fails (or a
test binary crashes or times out); a mutant that does not build is reported as such, not as
caught.

    dev/mutants.py [--list dev/mutants.txt] [--work DIR] [--only ID ...] [--markdown FILE]

--work: the scratch workspace (default .ws/mutants, git-ignored; kept between runs,
so the second run only rebuilds what the mutants touch). --markdown: write the table there
(doc/results/mutants.md). Exit 0 when every mutant was caught, 1 when one survived or did not
build, 2 on a usage or setup error.

List format: blocks separated by blank lines; '#' lines are comments. Keys, one 'KEY: value' line
each; a line starting with '|' continues the value before it on a new line (the text after '|'):
  id:      a short name (unique)
  what:    what the edit breaks, in words
  file:    the path in the repository
  find:    the exact text to replace (it must occur exactly once in the file)
  replace: its replacement
  tests:   (optional) space-separated gtest targets to build and run instead of the core gtests
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(HERE)


def core_tests(root=REPO):
    """The core gtest targets, test_core_<name>, as the core folders' CMakeLists.txt declare them
    (``jackal_aic_add_core_tests(<folder> <name>... [LINK ...])`` in src/*/CMakeLists.txt; a new
    core test is seeded against without an edit here). Raises ValueError if none is found."""
    names = []
    src = os.path.join(root, "src")
    for folder in sorted(os.listdir(src)) if os.path.isdir(src) else []:
        path = os.path.join(src, folder, "CMakeLists.txt")
        if not os.path.isfile(path):
            continue
        with open(path) as f:
            for m in re.finditer(r"jackal_aic_add_core_tests\(\s*\S+\s+([^)]*)\)", f.read()):
                names += m.group(1).split("LINK")[0].split()
    if not names:
        raise ValueError("%s: no jackal_aic_add_core_tests(...) in src/*/CMakeLists.txt" % root)
    return ["test_core_" + t for t in names]


KEYS = ("id", "what", "file", "find", "replace", "tests")
TEST_TIMEOUT = 600


class ListError(ValueError):
    """A malformed list of edits (mutants or ablations)."""


def mutant_defaults(block):
    """A mutant's 'tests' as a list (default: the core gtests)."""
    block["tests"] = block["tests"].split() if "tests" in block else core_tests()


def parse_list(text, name="mutants list", keys=KEYS, finish=mutant_defaults):
    """The edits of a list file's text (the format of the module docstring; dev/ablations.py's list
    has the same, with its own ``keys``): a list of dicts, each completed by ``finish(block)`` (for
    mutants: mutant_defaults). Raises ListError naming the line on an unknown key, a missing key
    (id, what, file, find, replace) or a repeated id."""
    mutants, block, start, last = [], {}, 0, None

    def close():
        if not block:
            return
        for key in ("id", "what", "file", "find", "replace"):
            if key not in block:
                raise ListError("%s line %d: entry without '%s:'" % (name, start, key))
        if any(m["id"] == block["id"] for m in mutants):
            raise ListError("%s line %d: repeated id '%s'" % (name, start, block["id"]))
        finish(block)
        mutants.append(dict(block))
        block.clear()

    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("#"):
            continue
        if not line.strip():
            close()
            continue
        if line.startswith("|"):
            if not block:
                raise ListError("%s line %d: a '|' continuation line without a key before it" % (name, number))
            block[last] += "\n" + line[1:]
            continue
        key, sep, value = line.partition(":")
        if not sep or key.strip() not in keys:
            raise ListError("%s line %d: expected 'KEY: value' with KEY one of %s, got %r"
                            % (name, number, ", ".join(keys), line))
        if not block:
            start = number
        last = key.strip()
        block[last] = value[1:] if value.startswith(" ") else value
    close()
    return mutants


def apply(text, mutant):
    """`text` with the mutant's edit applied. Raises ListError unless 'find' occurs exactly once."""
    count = text.count(mutant["find"])
    if count != 1:
        raise ListError("%s: 'find' occurs %d times in %s (must be once)" % (mutant["id"], count, mutant["file"]))
    return text.replace(mutant["find"], mutant["replace"])


def failed_tests(json_path):
    """'Suite.Name' of every failed test in a gtest JSON report (empty if it has none)."""
    try:
        with open(json_path) as f:
            report = json.load(f)
    except (OSError, ValueError):
        return []
    return ["%s.%s" % (s["name"], t["name"]) for s in report.get("testsuites", [])
            for t in s.get("testsuite", []) if t.get("failures")]


def markdown(rows):
    """The results table as Markdown: one row per mutant (id, what it breaks, the verdict, the
    tests that caught it)."""
    out = ["| mutant | what it breaks | verdict | caught by |", "|---|---|---|---|"]
    for r in rows:
        caught = ", ".join("`%s`" % t for t in r["caught_by"][:4])
        if len(r["caught_by"]) > 4:
            caught += " and %d more" % (len(r["caught_by"]) - 4)
        out.append("| `%s` | %s (`%s`) | %s | %s |" % (r["id"], r["what"], r["file"], r["verdict"], caught or "-"))
    return "\n".join(out) + "\n"


def add_list_args(ap, kind, list_name, work_name):
    """The options of a tool over a list of edits (this one and dev/ablations.py): --list (default
    dev/<list_name>), --work (default .ws/<work_name>), --only, --markdown, --jobs."""
    ap.add_argument("--list", default=os.path.join(HERE, list_name))
    ap.add_argument("--work", default=os.path.join(REPO, ".ws", work_name))
    ap.add_argument("--only", nargs="*", default=None, help="run only these %s ids" % kind)
    ap.add_argument("--markdown", default=None, help="write the results page there (Markdown)")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2")))


def load_list(path, only, parse, kind):
    """The entries of the list file ``path`` as ``parse(text, path)`` reads them, only those whose id
    is in ``only`` when it is given; each checked to apply to the tree (apply). Raises OSError, or
    ListError on a malformed list, an unknown id in ``only`` or an edit that does not apply."""
    with open(path) as f:
        entries = parse(f.read(), path)
    if only:
        unknown = set(only) - {e["id"] for e in entries}
        if unknown:
            raise ListError("unknown %s id(s): %s" % (kind, ", ".join(sorted(unknown))))
        entries = [e for e in entries if e["id"] in only]
    for e in entries:
        with open(os.path.join(REPO, e["file"])) as f:
            apply(f.read(), e)
    return entries


class Workspace:
    """The scratch catkin workspace holding a copy of the repository's files."""

    def __init__(self, root):
        self.root = os.path.abspath(root)
        self.src = os.path.join(self.root, "src", "jackal_aic")
        self.build = os.path.join(self.root, "build")
        self.bin = os.path.join(self.root, "devel", "lib", "jackal_aic")

    def sync(self):
        """Copies the repository's tracked and untracked-not-ignored files (unchanged files keep
        their times, so a rebuild stays incremental)."""
        files = subprocess.run(["git", "-C", REPO, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                               stdout=subprocess.PIPE, check=True).stdout.decode().split("\0")
        for rel in filter(None, files):
            src, dst = os.path.join(REPO, rel), os.path.join(self.src, rel)
            if not os.path.isfile(src):
                continue
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            with open(src, "rb") as f:
                data = f.read()
            if os.path.isfile(dst):
                with open(dst, "rb") as f:
                    if f.read() == data:
                        continue
            with open(dst, "wb") as f:
                f.write(data)
        msgs = os.path.join(self.root, "src", "jackal_msgs")
        if not os.path.exists(msgs) and not os.path.isfile("/opt/ros/noetic/share/jackal_msgs/package.xml"):
            os.symlink(os.path.join(self.src, "compat", "jackal_msgs"), msgs)

    def configure(self):
        """catkin_make's configure step in the scratch workspace (tests on, Release)."""
        cmd = ('source "%s" && cd "%s" && catkin_make "${catkin_args[@]}" cmake_check_build_system'
               % (os.path.join(HERE, "ws_env.sh"), self.root))
        return subprocess.run(["bash", "-c", cmd], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              universal_newlines=True)

    def prepare(self, targets, jobs):
        """sync(), configure() and make(targets): None when the targets built, else what failed (str,
        with the end of its output)."""
        self.sync()
        for what, proc in (("configuring the scratch workspace", self.configure),
                           ("building the tree", lambda: self.make(targets, jobs))):
            done = proc()
            if done.returncode != 0:
                return "%s failed:\n%s" % (what, done.stdout[-3000:])
        return None

    def make(self, targets, jobs):
        """Builds `targets` in the scratch workspace; the completed process."""
        return subprocess.run(["make", "-C", self.build, "-j%d" % jobs] + targets, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True)

    def run_test(self, target, report):
        """Runs one gtest binary with a JSON report; (exit code or 'timeout', failed test names)."""
        exe = os.path.join(self.bin, target)
        if os.path.exists(report):
            os.remove(report)
        # The scratch build's own libraries first: a shell that sourced another workspace's
        # setup.bash would otherwise load that workspace's unmutated core into every test.
        env = dict(os.environ)
        env["LD_LIBRARY_PATH"] = os.pathsep.join(
            filter(None, [os.path.join(self.root, "devel", "lib"), env.get("LD_LIBRARY_PATH")]))
        try:
            proc = subprocess.run([exe, "--gtest_output=json:" + report], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL, timeout=TEST_TIMEOUT, cwd=self.root, env=env)
            code = proc.returncode
        except subprocess.TimeoutExpired:
            code = "timeout"
        return code, failed_tests(report)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_list_args(ap, "mutant", "mutants.txt", "mutants")
    a = ap.parse_args(argv)
    try:
        mutants = load_list(a.list, a.only, parse_list, "mutant")
    except (OSError, ListError) as e:
        print("mutants: %s" % e, file=sys.stderr)
        return 2

    ws = Workspace(a.work)
    targets = sorted({t for m in mutants for t in m["tests"]})
    failure = ws.prepare(targets, a.jobs)
    if failure:
        print("mutants: %s" % failure, file=sys.stderr)
        return 2
    report = os.path.join(ws.root, "gtest_report.json")
    for t in targets:  # the unmutated tree must pass, or a 'caught' means nothing
        code, failed = ws.run_test(t, report)
        if code != 0:
            print("mutants: %s fails on the unmutated tree (%s): %s" % (t, code, failed), file=sys.stderr)
            return 2

    rows = []
    for m in mutants:
        path = os.path.join(ws.src, m["file"])
        with open(path) as f:
            original = f.read()
        start = time.monotonic()
        try:
            with open(path, "w") as f:
                f.write(apply(original, m))
            built = ws.make(m["tests"], a.jobs)
            caught = []
            if built.returncode == 0:
                for t in m["tests"]:
                    code, failed = ws.run_test(t, report)
                    if code != 0:
                        caught += failed or ["%s (exit %s)" % (t, code)]
        finally:
            with open(path, "w") as f:
                f.write(original)
        verdict = "does not build" if built.returncode != 0 else ("caught" if caught else "SURVIVED")
        rows.append(dict(m, caught_by=caught, verdict=verdict))
        print("mutant %-28s %-14s %5.0f s  %s" % (m["id"], verdict, time.monotonic() - start, ", ".join(caught[:3])),
              flush=True)
    ws.make(targets, a.jobs)  # leave the scratch build unmutated

    table = markdown(rows)
    print(table)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write("# Seeded faults\n\n"
                    "Written by `dev/mutants.py --markdown doc/results/mutants.md` from `dev/mutants.txt`: each mutant "
                    "is one guard removed or one equation broken, applied to a copy of the repository; the gtests it "
                    "names (default: the core gtests, `test_core_*`) are rebuilt and run. \"caught by\" lists the "
                    "tests that failed.\n\n" + table)
    survived = [r["id"] for r in rows if r["verdict"] != "caught"]
    print("mutants: %d of %d caught%s" % (len(rows) - len(survived), len(rows),
                                          "; not caught: " + ", ".join(survived) if survived else ""))
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
