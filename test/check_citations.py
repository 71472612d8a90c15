#!/usr/bin/env python3
"""Check that no file of the repository cites a document its users do not have.

Comments and docs cite published sources (the thesis's equations and tables, the papers,
Clearpath's public repositories) or the repository's own files (doc/*.md, README.md).
This scan reports every line that cites something else instead:

- a path into a ``shared/`` or ``spec/`` folder;
- a "spec section" / "spec, section" / "spec §" citation, also as an identifier
  ("SpecSection10"), "(spec …" and "the spec";
- a document name used as a citation (design.md, COMMON.md, jackal.md,
  active_inference.md) that does not resolve to a file of the repository, relative to the
  citing file or to the repository root (``doc/jackal.md`` resolves, a bare ``jackal.md``
  in a header does not).

Files scanned: those git knows (tracked, and untracked but not ignored), or, without git,
every file under the repository root except .git/, .ws/ and results/. Binary files and
this check's own two files (they hold the patterns) are skipped.

Usage: check_citations.py [REPO_ROOT]   prints file:line: text per hit; exit 1 on any hit.
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
DEFAULT_ROOT = os.path.dirname(HERE)

# This check and its unittest spell the patterns out; they are not citations.
SELF = {"test/check_citations.py", "test/test_citations.py"}
# Skipped when walking the tree without git (git-ignored: workspace, experiment output).
SKIP_DIRS = {".git", ".ws", "results", "__pycache__"}

PATTERNS = [
    (re.compile(r"shared/", re.IGNORECASE), "path into shared/"),
    (re.compile(r"(?<![\w-])spec/", re.IGNORECASE), "path into spec/"),
    (re.compile(r"spec[ _-]?sections?", re.IGNORECASE), "spec section"),
    (re.compile(r"\bspec\s*,\s*sections?", re.IGNORECASE), "spec section"),
    (re.compile(r"\bspec\s*\u00a7", re.IGNORECASE), "spec section"),
    (re.compile(r"\(spec\b", re.IGNORECASE), "spec citation"),
    (re.compile(r"\bthe spec\b", re.IGNORECASE), "spec citation"),
]
# Document names that were never part of the repository, or that are only valid where
# they resolve to the repository's own copy (doc/jackal.md, doc/active_inference.md).
DOC_NAMES = ("design", "COMMON", "jackal", "active_inference")
DOC_REF = re.compile(r"(?<![\w./-])((?:[\w.-]+/)*)(" + "|".join(DOC_NAMES) + r")\.md\b")


def list_files(root):
    """Repository-relative paths of the files to scan."""
    try:
        out = subprocess.run(
            ["git", "-C", root, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, check=True).stdout
        files = [f for f in out.decode("utf-8", "replace").split("\0") if f]
        if files:
            return sorted(f for f in files if os.path.isfile(os.path.join(root, f)))
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS)
        for name in filenames:
            path = os.path.join(dirpath, name)
            if os.path.isfile(path):
                files.append(os.path.relpath(path, root).replace(os.sep, "/"))
    return sorted(files)


def read_text(path):
    """The file's text, or None for a binary file."""
    with open(path, "rb") as f:
        data = f.read()
    if b"\0" in data:
        return None
    return data.decode("utf-8", "replace")


def resolves(root, rel_file, ref):
    """Whether a cited document path names a file inside the repository."""
    real_root = os.path.realpath(root)
    for base in (os.path.join(root, os.path.dirname(rel_file)), root):
        target = os.path.realpath(os.path.join(base, ref))
        inside = target == real_root or target.startswith(real_root + os.sep)
        if inside and os.path.isfile(target):
            return True
    return False


def scan_text(root, rel_file, text):
    """Hits in one file: list of (line number, reason, line)."""
    hits = []
    for number, line in enumerate(text.splitlines(), start=1):
        for pattern, reason in PATTERNS:
            if pattern.search(line):
                hits.append((number, reason, line.strip()))
                break
        else:
            for m in DOC_REF.finditer(line):
                ref = m.group(1) + m.group(2) + ".md"
                if "shared/" in ref or "spec/" in ref or not resolves(root, rel_file, ref):
                    hits.append((number, "cites %s, not a file of this repository" % ref, line.strip()))
                    break
    return hits


def scan(root=DEFAULT_ROOT):
    """Every hit in the repository: list of "file:line: reason: text" strings."""
    report = []
    for rel in list_files(root):
        if rel in SELF:
            continue
        text = read_text(os.path.join(root, rel))
        if text is None:
            continue
        for number, reason, line in scan_text(root, rel, text):
            report.append("%s:%d: %s: %s" % (rel, number, reason, line))
    return report


def main(argv):
    root = os.path.abspath(argv[1]) if len(argv) > 1 else DEFAULT_ROOT
    report = scan(root)
    for entry in report:
        print(entry)
    if report:
        print("check_citations: %d reference(s) to documents outside the repository; cite the "
              "thesis (equation, table) or the repository's doc/ instead" % len(report), file=sys.stderr)
        return 1
    print("check_citations: no references to documents outside the repository")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
