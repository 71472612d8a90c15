#!/usr/bin/env python3
"""unittest: the package's metadata, without a build.

- every dependency key of package.xml is a key rosdep resolves: a system key of rosdep's
  rule files or a released ROS Noetic package, as committed in test/data/rosdep_keys.txt
  (which names its source); `rosdep check --from-paths . --ignore-src` does the same where
  rosdep has a database;
- catkin_package(CATKIN_DEPENDS ...) in CMakeLists.txt names every ROS package whose
  headers the installed headers (include/jackal_aic/) include;
- every ROS package package.xml depends on is used somewhere (sources, launch files,
  tests, scripts, CMakeLists.txt).

    /usr/bin/python3 test/test_packaging.py          # plain unittest output
    /usr/bin/python3 test/test_packaging.py --gtest_output=xml:FILE   # JUnit XML via rosunit
"""
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
DEP_TAGS = ("depend", "build_depend", "build_export_depend", "exec_depend", "test_depend",
            "buildtool_depend", "doc_depend")
# Tools used by name only at build or test time (catkin macros, rostest's runner).
USED_BY_THE_BUILD = {"catkin", "rostest", "rosunit", "roslaunch"}
# Include folders named otherwise than their package.
INCLUDE_PACKAGE = {"ros": "roscpp"}


def read_keys(path):
    """{section: set(keys)} of test/data/rosdep_keys.txt."""
    sections, current = {}, None
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            m = re.fullmatch(r"\[(\w+)\]", line)
            if m:
                current = sections.setdefault(m.group(1), set())
            elif current is None:
                raise ValueError("%s: key %r before any [section]" % (path, line))
            else:
                current.add(line)
    return sections


def package_deps(path):
    """[(tag, key)] of a package.xml."""
    root = ET.parse(path).getroot()
    return [(el.tag, el.text.strip()) for el in root if el.tag in DEP_TAGS]


def catkin_depends(cmake_text):
    m = re.search(r"catkin_package\((.*?)\)", cmake_text, re.S)
    if not m:
        return set()
    body = re.sub(r"#.*", "", m.group(1))
    words = body.split()
    out, on = set(), False
    for w in words:
        if w in ("INCLUDE_DIRS", "LIBRARIES", "DEPENDS", "CFG_EXTRAS", "SKIP_CMAKE_CONFIG_GENERATION",
                 "SKIP_PKG_CONFIG_GENERATION", "EXPORTED_TARGETS"):
            on = False
        elif w == "CATKIN_DEPENDS":
            on = True
        elif on:
            out.add(w)
    return out


def header_includes(include_dir):
    """Top folders of every <pkg/...> include of the headers under include_dir."""
    pkgs = set()
    for base, _dirs, files in os.walk(include_dir):
        for name in files:
            if name.endswith((".h", ".hpp")):
                with open(os.path.join(base, name), encoding="utf-8") as f:
                    for m in re.finditer(r"#include\s*<([A-Za-z0-9_]+)/", f.read()):
                        pkgs.add(INCLUDE_PACKAGE.get(m.group(1), m.group(1)))
    return pkgs


def repository_text():
    chunks = []
    for sub in ("src", "sim", "include", "test", "launch", "scripts", "cfg"):
        for base, _dirs, files in os.walk(os.path.join(ROOT, sub)):
            for name in files:
                if name.endswith((".cpp", ".hpp", ".h", ".py", ".launch", ".test", ".sh", ".cfg")):
                    with open(os.path.join(base, name), encoding="utf-8", errors="replace") as f:
                        chunks.append(f.read())
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        chunks.append(f.read())
    return "\n".join(chunks)


class TestPackaging(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.keys = read_keys(os.path.join(ROOT, "test", "data", "rosdep_keys.txt"))
        cls.deps = package_deps(os.path.join(ROOT, "package.xml"))
        with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
            cls.cmake = f.read()

    def test_every_key_resolves(self):
        known = self.keys.get("system", set()) | self.keys.get("ros", set())
        unknown = sorted({k for _t, k in self.deps if k not in known})
        self.assertFalse(unknown, "package.xml keys rosdep does not know (see test/data/rosdep_keys.txt): %s"
                         % unknown)
        self.assertGreater(len(self.deps), 10)  # the parse saw the dependencies

    def test_ode_is_opende(self):
        keys = {k for _t, k in self.deps}
        self.assertIn("opende", keys)
        self.assertNotIn("libode-dev", keys, "ODE's rosdep key is opende; libode-dev is the Debian package")

    def test_catkin_depends_covers_the_installed_headers(self):
        ros = self.keys["ros"]
        needed = {p for p in header_includes(os.path.join(ROOT, "include")) if p in ros}
        exported = catkin_depends(self.cmake)
        self.assertIn("roscpp", needed)  # the scan saw the node's headers
        missing = sorted(needed - exported)
        self.assertFalse(missing, "installed headers include %s, missing from catkin_package(CATKIN_DEPENDS)"
                         % missing)
        declared = {k for _t, k in self.deps}
        self.assertFalse(sorted(exported - declared), "CATKIN_DEPENDS not in package.xml")

    def test_no_unused_ros_dependency(self):
        text = repository_text()
        unused = []
        for _tag, key in self.deps:
            if key in self.keys["ros"] and key not in USED_BY_THE_BUILD:
                if not re.search(r"(?<![A-Za-z0-9_])%s(?![A-Za-z0-9_])" % re.escape(key), text):
                    unused.append(key)
        self.assertFalse(unused, "package.xml depends on ROS packages nothing uses: %s" % unused)

    def test_the_parsers_can_fail(self):
        self.assertEqual(catkin_depends("catkin_package(\n CATKIN_DEPENDS a b # c\n DEPENDS X)"), {"a", "b"})
        self.assertEqual(catkin_depends("nothing"), set())


if __name__ == "__main__":
    if any(arg.startswith("--gtest_output=xml:") for arg in sys.argv):
        import rosunit
        rosunit.unitrun("jackal_aic", "packaging", TestPackaging)
    else:
        unittest.main()
