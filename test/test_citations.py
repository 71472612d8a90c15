#!/usr/bin/env python3
"""unittest: no comment, doc or string of the repository cites a document outside it.

Runs test/check_citations.py's scan over the repository this file lives in. Registered
with catkin_add_nosetests (CMakeLists.txt); also runs on its own:

    /usr/bin/python3 test/test_citations.py          # plain unittest output
    /usr/bin/python3 test/test_citations.py --gtest_output=xml:FILE   # JUnit XML via rosunit
"""
import os
import sys
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

    def test_the_scan_sees_the_repository(self):
        # Guards against a vacuous pass: the file list must include this package's sources.
        files = check_citations.list_files(check_citations.DEFAULT_ROOT)
        self.assertIn("package.xml", files)
        self.assertIn("doc/active_inference.md", files)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("citations", TestCitations)
