#!/usr/bin/env python3
"""unittest: no comment, doc or string of the repository cites a document outside it.

Runs test/check_citations.py's scan over the repository this file lives in. Registered
with catkin_add_nosetests (CMakeLists.txt); also runs on its own:

    /usr/bin/python3 test/test_citations.py          # plain unittest output
    /usr/bin/python3 test/test_citations.py --gtest_output=xml:FILE   # JUnit XML via rosunit
"""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
import check_citations  # noqa: E402  (the test directory is not a package)


class TestCitations(unittest.TestCase):
    def test_cites_only_published_sources_and_the_repository(self):
        report = check_citations.scan()
        if report:
            self.fail("%d reference(s) to documents outside the repository; cite the thesis "
                      "(equation, table) or the repository's doc/ instead:\n  %s"
                      % (len(report), "\n  ".join(report)))

    def test_the_scan_reports_each_kind_of_citation_and_passes_a_clean_tree(self):
        # Positive control: a tree (no git) with one file per kind of citation the scan must report,
        # beside a file citing only what resolves; the scan names each offending file, once per
        # line, and nothing else.
        offending = {
            "a.cpp": "// see shared/notes.txt\n",
            "b.py": "# as in spec section 4.2\n",
            "c.md": "Follows the spec, section 3.\n",
            "d.hpp": "/// (spec 5.1) the limit\n",
            "e.txt": "the spec says so\n",
            "f.cpp": "// design.md explains it\n",
            "sub/g.hpp": "// active_inference.md, 'Update rules'\n",
        }
        clean = {"doc/active_inference.md": "# the doc\n",
                 "ok.cpp": "// doc/active_inference.md, 'Update rules'; thesis eq. 3-22\n"}
        with tempfile.TemporaryDirectory() as tmp:
            for rel, text in list(offending.items()) + list(clean.items()):
                os.makedirs(os.path.dirname(os.path.join(tmp, rel)), exist_ok=True)
                with open(os.path.join(tmp, rel), "w") as f:
                    f.write(text)
            report = check_citations.scan(tmp)
            self.assertEqual(sorted(r.split(":", 1)[0] for r in report), sorted(offending), report)
            for rel in offending:
                os.remove(os.path.join(tmp, rel))
            self.assertEqual(check_citations.scan(tmp), [])

    def test_the_scan_sees_the_repository(self):
        # Guards against a vacuous pass: the file list must include this package's sources.
        files = check_citations.list_files(check_citations.DEFAULT_ROOT)
        self.assertIn("package.xml", files)
        self.assertIn("doc/active_inference.md", files)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("citations", TestCitations)
