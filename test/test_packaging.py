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
  tests, scripts, CMakeLists.txt);
- the robot's install (TestRobotInstall): package.xml's REP 149 conditions evaluated as
  rosdep evaluates them, by catkin_pkg (catkin_pkg.package.parse_package and
  Package.evaluate_conditions, what `rosdep install --from-paths` calls with its environment;
  the rosdep library itself is not used), each key resolved on focal through the rules
  snapshot above. With JACKAL_AIC_NODE_ONLY=1 the keys are exactly those of the node-only
  build (CMakeLists.txt's _node_components, catkin, eigen, boost) and what robot.launch runs
  (roslaunch): no ODE, urdfdom, yaml-cpp, scipy, matplotlib, psutil; unset,
  every key, those included. dev/resolve_deps.py's own reading of the conditions agrees;
- LICENSE (TestLicense) is the text of package.xml's <license> and names its maintainer.

    /usr/bin/python3 test/test_packaging.py          # plain unittest output
    /usr/bin/python3 test/test_packaging.py --gtest_output=xml:FILE   # JUnit XML via rosunit
"""
import os
import re
import sys
import unittest
import ast
import xml.etree.ElementTree as ET

from catkin_pkg.package import parse_package, parse_package_string


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


# ---- the robot's install ---------------------------------------------------------------------
# The environment variable of the robot's install and the one condition that marks a
# dependency only the simulated Jackal, the tools or the tests need (package.xml).
NODE_ONLY_VAR = "JACKAL_AIC_NODE_ONLY"
ROBOT_ENV = {NODE_ONLY_VAR: "1"}
NOT_ON_THE_ROBOT = "$%s != 1" % NODE_ONLY_VAR
# Keys of the robot besides CMakeLists.txt's _node_components: the build tool, the node's system
# libraries, the run-time side of its message (message_runtime; message_generation is a component),
# and what launch/robot.launch runs (roslaunch; its nodes, controller:=stock's relay included, are
# the package's own).
ROBOT_EXTRA_KEYS = {"catkin", "eigen", "boost", "message_runtime", "roslaunch"}
# Focal apt packages (name prefixes) of the simulator and the tools: never in the robot's
# install, always in the default one.
SIM_AND_TOOLS_APT = ("libode", "liburdfdom", "libyaml-cpp", "python3-scipy", "python3-matplotlib",
                     "python3-psutil")


def rosdep_keys(package, env):
    """Keys `rosdep install --from-paths` installs for a catkin_pkg Package in environment env:
    every dependency type (rosdep's default), each dependency whose condition holds in env
    (Package.evaluate_conditions, as rosdep calls it with os.environ), in order."""
    package.evaluate_conditions(env)
    keys = []
    for dep in (package.buildtool_depends + package.build_depends + package.build_export_depends
                + package.buildtool_export_depends + package.exec_depends + package.test_depends
                + package.doc_depends):
        if dep.evaluated_condition and dep.name not in keys:
            keys.append(dep.name)
    return keys


def focal_install(package, env, data):
    """{key: [focal apt packages]} of rosdep_keys(package, env) (dev/resolve_deps.py's resolve());
    a key without a focal package fails the calling test through the second value."""
    return resolve_deps.resolve(rosdep_keys(package, env), "focal", *data)


def sim_and_tools_packages(packages):
    """[(key, apt package)] of a {key: [apt packages]} resolution that are the simulator's or the tools'."""
    return sorted((key, pkg) for key, pkgs in packages.items() for pkg in pkgs
                  if pkg.startswith(SIM_AND_TOOLS_APT))


def missing_sim_and_tools(packages):
    """The SIM_AND_TOOLS_APT prefixes no apt package of a resolution starts with."""
    names = [pkg for pkgs in packages.values() for pkg in pkgs]
    return [p for p in SIM_AND_TOOLS_APT if not any(n.startswith(p) for n in names)]


def node_components(cmake_text):
    """The words of CMakeLists.txt's set(_node_components ...): the node-only build's ROS packages."""
    m = re.search(r"set\(\s*_node_components\s+(.*?)\)", cmake_text, re.S)
    return set(re.sub(r"#.*", "", m.group(1)).split()) if m else set()


# ---- the license -----------------------------------------------------------------------------
# The title line of each license text package.xml may name (SPDX identifier), and phrases of it.
LICENSE_TEXTS = {
    "BSD-3-Clause": ("BSD 3-Clause License",
                     "Redistributions of source code must retain the above copyright notice",
                     "Redistributions in binary form must reproduce the above copyright notice",
                     "Neither the name of the copyright holder nor the names of its",
                     "contributors may be used to endorse or promote products derived from"),
}


def license_problems(package, text):
    """What does not match between a catkin_pkg Package's <license> tags and its LICENSE text."""
    problems = []
    if not package.licenses:
        problems.append("package.xml names no license")
    for lic in package.licenses:
        phrases = LICENSE_TEXTS.get(str(lic))
        if phrases is None:
            problems.append("no known text for license %s" % lic)
            continue
        if text.splitlines()[:1] != [phrases[0]]:
            problems.append("LICENSE does not start with %r" % phrases[0])
        problems.extend("LICENSE lacks %r" % p for p in phrases[1:] if p not in " ".join(text.split()))
        if getattr(lic, "file", None) != "LICENSE":
            problems.append("<license> of %s does not name file=\"LICENSE\"" % lic)
    for person in package.maintainers:
        if not re.search(r"^Copyright \(c\) \d{4}, %s$" % re.escape(person.name), text, re.M):
            problems.append("LICENSE has no 'Copyright (c) YEAR, %s' line" % person.name)
    return problems


SEEDED_PACKAGE = """<?xml version="1.0"?>
<package format="3">
  <name>seeded</name>
  <version>0.0.0</version>
  <description>a package.xml with a simulator key the robot would install</description>
  <maintainer email="dev@jackal-aic.invalid">jackal_aic developers</maintainer>
  <license file="LICENSE">BSD-3-Clause</license>
  <buildtool_depend>catkin</buildtool_depend>
  <depend>roscpp</depend>
  <depend>opende</depend>
  <exec_depend condition="$JACKAL_AIC_NODE_ONLY != 1">python3-scipy</exec_depend>
</package>
"""


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


def _data():
    data = os.path.join(ROOT, "test", "data")
    return (resolve_deps.read_yaml_map(os.path.join(data, "rosdep_apt_rules.yaml")),
            resolve_deps.read_ros_keys(os.path.join(data, "rosdep_keys.txt")),
            resolve_deps.read_yaml_map(os.path.join(data, "debian_ros_packages.yaml")))


class TestRobotInstall(unittest.TestCase):
    """`JACKAL_AIC_NODE_ONLY=1 rosdep install --from-paths src --ignore-src` on focal: package.xml's
    conditions evaluated by catkin_pkg (as rosdep does), keys resolved through
    test/data/rosdep_apt_rules.yaml and rosdep_keys.txt by dev/resolve_deps.py."""

    @classmethod
    def setUpClass(cls):
        cls.data = _data()
        cls.path = os.path.join(ROOT, "package.xml")
        with open(cls.path, encoding="utf-8") as f:
            cls.xml = f.read()
        with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
            cls.cmake = f.read()

    def install(self, xml, env):
        packages, missing = focal_install(parse_package_string(xml), env, self.data)
        self.assertFalse(missing, "keys without a focal package: %s" % missing)
        return packages

    def test_the_robot_installs_the_node_only_builds_keys(self):
        components = node_components(self.cmake)
        self.assertIn("roscpp", components, "set(_node_components ...) not found in CMakeLists.txt")
        robot = rosdep_keys(parse_package(self.path), ROBOT_ENV)
        self.assertEqual(sorted(robot), sorted(components | ROBOT_EXTRA_KEYS),
                         "with %s=1 package.xml's keys should be the node-only build's (CMakeLists.txt "
                         "_node_components) and robot.launch's" % NODE_ONLY_VAR)

    def test_the_robot_installs_nothing_of_the_simulator_or_the_tools(self):
        robot = self.install(self.xml, ROBOT_ENV)
        self.assertFalse(sim_and_tools_packages(robot),
                         "%s=1 rosdep install would still install these (add condition=\"%s\")"
                         % (NODE_ONLY_VAR, NOT_ON_THE_ROBOT))
        self.assertEqual(robot["eigen"], ["libeigen3-dev"])  # the resolution ran
        self.assertEqual(robot["roscpp"], ["ros-noetic-roscpp"])

    def test_the_default_install_has_everything(self):
        default = self.install(self.xml, {})
        self.assertFalse(missing_sim_and_tools(default), "the default install lacks these")
        self.assertEqual(set(default), {k for _t, k in package_deps(self.path)},
                         "without %s some dependency is left out" % NODE_ONLY_VAR)
        other = self.install(self.xml, {NODE_ONLY_VAR: "0"})
        self.assertEqual(set(other), set(default), "%s=0 is the default" % NODE_ONLY_VAR)

    def test_every_condition_is_the_robots(self):
        root = ET.parse(self.path).getroot()
        conditions = {el.get("condition") for el in root if el.tag in DEP_TAGS} - {None}
        self.assertEqual(conditions, {NOT_ON_THE_ROBOT}, "one condition, one variable")

    def test_resolve_deps_reads_the_conditions_as_catkin_pkg(self):
        for env in ({}, ROBOT_ENV, {NODE_ONLY_VAR: "0"}):
            self.assertEqual(set(resolve_deps.package_keys(self.path, env)),
                             set(rosdep_keys(parse_package(self.path), env)), env)
        from catkin_pkg.condition import evaluate_condition
        env = {"A": "1", "B": "x"}
        for expr in ("$A == 1", "$A != 1", "$C == ''", '$C == ""', "$B == x and $A == 1",
                     "$B == y or $A == 1", "$B == y or $A == 1 and $B == z", "($B == y or $A == 1) and $B == z",
                     "1 == $A", "$A < 2", "$B >= y", "$A=='1'"):
            self.assertEqual(resolve_deps.evaluate_condition(expr, env), evaluate_condition(expr, env), expr)
        for bad in ("$A", "$A == ", "($A == 1", "$A == 1 and", "$A ~ 1"):
            with self.assertRaises(ValueError, msg=bad):
                resolve_deps.evaluate_condition(bad, env)

    def test_a_key_without_the_condition_is_reported(self):
        # A seeded package.xml: opende without the condition reaches the robot, scipy (with it) does not.
        robot = self.install(SEEDED_PACKAGE, ROBOT_ENV)
        self.assertEqual(sim_and_tools_packages(robot), [("opende", "libode-dev")])
        self.assertEqual(sim_and_tools_packages(self.install(SEEDED_PACKAGE, {})),
                         [("opende", "libode-dev"), ("python3-scipy", "python3-scipy")])
        # package.xml with one condition dropped, or naming another variable: the robot gets it.
        line = '<exec_depend condition="%s">python3-matplotlib</exec_depend>' % NOT_ON_THE_ROBOT
        self.assertIn(line, self.xml)
        before = set(sim_and_tools_packages(self.install(self.xml, ROBOT_ENV)))
        for seeded in (self.xml.replace(line, "<exec_depend>python3-matplotlib</exec_depend>"),
                       self.xml.replace(line, line.replace(NODE_ONLY_VAR, "JACKAL_AIC_ROBOT"))):
            self.assertEqual(set(sim_and_tools_packages(self.install(seeded, ROBOT_ENV))) - before,
                             {("python3-matplotlib", "python3-matplotlib")})

    def test_a_key_the_default_install_lacks_is_reported(self):
        line = '<depend condition="%s">yaml-cpp</depend>' % NOT_ON_THE_ROBOT
        self.assertIn(line, self.xml)
        seeded = self.xml.replace(line, line.replace("!=", "=="))
        self.assertEqual(missing_sim_and_tools(self.install(seeded, {})), ["libyaml-cpp"])
        self.assertEqual(missing_sim_and_tools({"eigen": ["libeigen3-dev"]}), list(SIM_AND_TOOLS_APT))


class TestLicense(unittest.TestCase):
    """LICENSE at the repository's root is the text of package.xml's <license> (SPDX identifier)."""

    def test_license_matches_package_xml(self):
        package = parse_package(os.path.join(ROOT, "package.xml"))
        self.assertEqual([str(l) for l in package.licenses], ["BSD-3-Clause"])
        path = os.path.join(ROOT, "LICENSE")
        self.assertTrue(os.path.isfile(path), "no LICENSE at the repository's root")
        with open(path, encoding="utf-8") as f:
            self.assertEqual(license_problems(package, f.read()), [])

    def test_a_mismatch_is_reported(self):
        package = parse_package_string(SEEDED_PACKAGE)
        mit = ("MIT License\n\nCopyright (c) 2026 someone else\n\nPermission is hereby granted, free of "
               "charge, to any person obtaining a copy\n")
        problems = license_problems(package, mit)
        self.assertIn("LICENSE does not start with 'BSD 3-Clause License'", problems)
        self.assertIn("LICENSE has no 'Copyright (c) YEAR, jackal_aic developers' line", problems)
        other = parse_package_string(SEEDED_PACKAGE.replace('<license file="LICENSE">BSD-3-Clause',
                                                            "<license>MIT"))
        self.assertEqual(license_problems(other, mit)[:1], ["no known text for license MIT"])


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("packaging", TestPackaging, TestRobotInstall, TestLicense)
