#!/usr/bin/env python3
"""unittest: the package's metadata, without a build.

- every dependency key of package.xml resolves on the robot's OS and here: a system key to
  apt packages for ubuntu focal (Noetic's Ubuntu) and debian bookworm in the committed
  snapshot of rosdep's rules (test/data/rosdep_apt_rules.yaml, which names its source), or a
  released ROS Noetic package (test/data/rosdep_keys.txt); a key whose rule is null there
  (cli11 on focal) fails; `rosdep check --from-paths . --ignore-src` does the same where
  rosdep has a database;
- every Python file parses as Python 3.8 (Ubuntu 20.04's interpreter);
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
import ast
import xml.etree.ElementTree as ET


ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
DEP_TAGS = ("depend", "build_depend", "build_export_depend", "exec_depend", "test_depend",
            "buildtool_depend", "doc_depend")
# Tools used by name only at build or test time (catkin macros, rostest's runner).
USED_BY_THE_BUILD = {"catkin", "rostest", "rosunit", "roslaunch"}
# Include folders named otherwise than their package.
INCLUDE_PACKAGE = {"ros": "roscpp"}


sys.path.insert(0, os.path.join(ROOT, "dev"))
import resolve_deps  # noqa: E402  (dev/resolve_deps.py: the one resolver, also check_bullseye.sh's)

# The OSes every key must resolve on: the robot's (Ubuntu 20.04) and the one CI builds on.
CHECKED_OSES = ("focal", "bookworm")


def unresolved(keys, data, oses=CHECKED_OSES):
    """[(key, os)] of the keys resolve_deps.resolve() finds no apt package for on each OS."""
    out = []
    for os_name in oses:
        _packages, missing = resolve_deps.resolve(keys, os_name, *data)
        out.extend((key, os_name) for key, _reason in missing)
    return sorted(out)


def python_files():
    """Every Python file of the repository (scripts without the .py ending too)."""
    out = []
    for sub in ("src", "sim", "test", "scripts", "dev", "tools", "cfg"):
        for base, _dirs, files in os.walk(os.path.join(ROOT, sub)):
            for name in files:
                path = os.path.join(base, name)
                if name.endswith(".py") or name.endswith(".cfg"):
                    out.append(path)
    out.append(os.path.join(ROOT, "setup.py"))
    return out


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
    for sub in ("src", "sim", "include", "tools", "test", "launch", "scripts", "dev", "cfg"):
        for base, _dirs, files in os.walk(os.path.join(ROOT, sub)):
            for name in files:
                if name.endswith((".cpp", ".hpp", ".h", ".py", ".launch", ".test", ".sh", ".cfg")):
                    with open(os.path.join(base, name), encoding="utf-8", errors="replace") as f:
                        chunks.append(f.read())
    chunks.append(cmake_text())
    return "\n".join(chunks)


def cmake_text():
    """Every CMakeLists.txt of the package (the root's and its folders'), joined."""
    chunks = []
    for base, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith(".")]
        if "CMakeLists.txt" in files:
            with open(os.path.join(base, "CMakeLists.txt"), encoding="utf-8") as f:
                chunks.append(f.read())
    return "\n".join(chunks)


class TestPackaging(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        data = os.path.join(ROOT, "test", "data")
        cls.ros_keys = resolve_deps.read_ros_keys(os.path.join(data, "rosdep_keys.txt"))
        cls.data = (resolve_deps.read_yaml_map(os.path.join(data, "rosdep_apt_rules.yaml")), cls.ros_keys,
                    resolve_deps.read_yaml_map(os.path.join(data, "debian_ros_packages.yaml")))
        cls.deps = package_deps(os.path.join(ROOT, "package.xml"))
        cls.cmake = cmake_text()

    def test_every_key_resolves_on_focal_and_bookworm(self):
        missing = unresolved([k for _t, k in self.deps], self.data)
        self.assertFalse(missing, "package.xml keys without an apt package (dev/resolve_deps.py): %s"
                         % ", ".join("%s on %s" % m for m in missing))
        self.assertGreater(len(self.deps), 10)  # the parse saw the dependencies

    def test_a_key_without_a_focal_rule_fails(self):
        # cli11 has no apt package on Ubuntu 20.04 (null rule): adding it back must fail.
        keys = [k for _t, k in self.deps] + ["cli11"]
        self.assertEqual(unresolved(keys, self.data), [("cli11", "focal")])
        self.assertEqual(unresolved(["no-such-key"], self.data),
                         [("no-such-key", "bookworm"), ("no-such-key", "focal")])

    def test_every_ros_key_has_a_debian_package_entry(self):
        # dev/check_bullseye.sh installs Debian's ROS packages: a new ROS dependency needs its entry.
        missing = unresolved([k for _t, k in self.deps], self.data, oses=("bullseye",))
        self.assertFalse(missing, "no bullseye package (test/data/debian_ros_packages.yaml): %s" % missing)
        _packages, gone = resolve_deps.resolve(["roscpp", "not_a_ros_pkg_xyz"], "bullseye",
                                               self.data[0], self.ros_keys | {"not_a_ros_pkg_xyz"}, self.data[2])
        self.assertEqual([k for k, _r in gone], ["not_a_ros_pkg_xyz"])

    def test_python_parses_as_3_8(self):
        files = python_files()
        self.assertGreater(len(files), 10)
        bad = []
        for path in files:
            with open(path, encoding="utf-8") as f:
                text = f.read()
            try:
                ast.parse(text, filename=path, feature_version=(3, 8))
            except SyntaxError as e:
                bad.append("%s:%s: %s" % (os.path.relpath(path, ROOT), e.lineno, e.msg))
        self.assertFalse(bad, "not Python 3.8: %s" % bad)

    def test_ode_is_opende(self):
        keys = {k for _t, k in self.deps}
        self.assertIn("opende", keys)
        self.assertNotIn("libode-dev", keys, "ODE's rosdep key is opende; libode-dev is the Debian package")

    def test_catkin_depends_covers_the_installed_headers(self):
        ros = self.ros_keys
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
            if key in self.ros_keys and key not in USED_BY_THE_BUILD:
                if not re.search(r"(?<![A-Za-z0-9_])%s(?![A-Za-z0-9_])" % re.escape(key), text):
                    unused.append(key)
        self.assertFalse(unused, "package.xml depends on ROS packages nothing uses: %s" % unused)

    def test_the_parsers_can_fail(self):
        self.assertEqual(catkin_depends("catkin_package(\n CATKIN_DEPENDS a b # c\n DEPENDS X)"), {"a", "b"})
        self.assertEqual(catkin_depends("nothing"), set())


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("packaging", TestPackaging)
