#!/usr/bin/env python3
"""Resolve package.xml's dependency keys to apt packages for one OS, as rosdep would.

System keys (Eigen, ODE, Boost, Python libraries, ...) resolve through the committed
snapshot of rosdep's apt rules (test/data/rosdep_apt_rules.yaml, columns focal, bullseye,
bookworm); ROS package keys resolve, on Debian, to Debian's own ROS 1 packages
(test/data/debian_ros_packages.yaml) and, on Ubuntu focal, to ROS Noetic's released
packages (test/data/rosdep_keys.txt: ros-noetic-<key>). A key with no package on the OS is
an error: rosdep could not install it there, and neither can this script.

A dependency with a REP 149 condition counts only where its condition holds in this
process's environment, as in rosdep: JACKAL_AIC_NODE_ONLY=1 leaves out what only the
simulated Jackal, the tools and the tests need (doc/platforms.md, "The robot's build").

    dev/resolve_deps.py --os bullseye            # one apt package per line
    dev/resolve_deps.py --os focal --keys        # key -> packages, one key per line
    JACKAL_AIC_NODE_ONLY=1 dev/resolve_deps.py --os focal   # the robot's packages

Exit status: 0 every key resolved; 1 some key did not (each named on stderr, with its OS);
2 bad arguments or unreadable data files. Runs on Python 3.8 with PyYAML.
"""
import argparse
import operator
import os
import re
import sys
import xml.etree.ElementTree as ET

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
DATA = os.path.join(ROOT, "test", "data")
DEP_TAGS = ("depend", "build_depend", "build_export_depend", "exec_depend", "test_depend",
            "buildtool_depend")
OSES = ("focal", "bullseye", "bookworm")


_COMPARISONS = {"==": operator.eq, "!=": operator.ne, "<=": operator.le, "<": operator.lt,
                ">=": operator.ge, ">": operator.gt}
_CONDITION_TOKEN = re.compile(r"\s*(?:(\(|\)|==|!=|<=|>=|<|>)|\$(\w+)|\"([^\"]*)\"|'([^']*)'|([\w-]+))")


def evaluate_condition(condition, env):
    """The value of a REP 149 condition attribute in the environment env (a mapping).

    The grammar of catkin_pkg.condition, which rosdep and catkin use: comparisons
    `TERM OP TERM` (OP one of == != < <= > >=; a TERM is $VARIABLE, a bare word or a quoted
    string; an unset variable is the empty string) joined by `and` (binds first) and `or`,
    with parentheses. None (no condition) is true. Raises ValueError on a malformed condition.
    """
    if condition is None:
        return True
    tokens, pos = [], 0
    while pos < len(condition):
        m = _CONDITION_TOKEN.match(condition, pos)
        if not m or m.end() == pos:
            if condition[pos:].strip():
                raise ValueError("condition %r: cannot read %r" % (condition, condition[pos:]))
            break
        pos = m.end()
        op, var, dq, sq, word = m.groups()
        if op:
            tokens.append(("op", op))
        elif var is not None:
            tokens.append(("term", env.get(var, "")))
        elif word in ("and", "or"):
            tokens.append(("op", word))
        else:
            tokens.append(("term", next(t for t in (dq, sq, word) if t is not None)))
    at = [0]

    def take(kind, value=None):
        if at[0] < len(tokens) and tokens[at[0]][0] == kind and value in (None, tokens[at[0]][1]):
            at[0] += 1
            return tokens[at[0] - 1][1]
        return None

    def expected(what):
        return ValueError("condition %r: %s expected" % (condition, what))

    def either():
        value = both()
        while take("op", "or") is not None:
            value = both() or value
        return value

    def both():
        value = single()
        while take("op", "and") is not None:
            value = single() and value
        return value

    def single():
        if take("op", "(") is not None:
            value = either()
            if take("op", ")") is None:
                raise expected("')'")
            return value
        left = take("term")
        op = take("op")
        right = take("term")
        if left is None or op not in _COMPARISONS or right is None:
            raise expected("TERM OP TERM")
        return _COMPARISONS[op](left, right)

    value = either()
    if at[0] != len(tokens):
        raise expected("the end")
    return value


def package_keys(path, env=None):
    """Dependency keys of a package.xml (format 2 or 3), in order of first appearance.

    A dependency whose condition attribute is false in env (default: os.environ, as rosdep
    reads it) is left out.
    """
    env = os.environ if env is None else env
    root = ET.parse(path).getroot()
    keys = []
    for el in root:
        if el.tag in DEP_TAGS and el.text and el.text.strip() not in keys:
            if evaluate_condition(el.get("condition"), env):
                keys.append(el.text.strip())
    return keys


def read_ros_keys(path):
    """The [ros] section of test/data/rosdep_keys.txt: released ROS Noetic package keys."""
    keys, on = set(), False
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            m = re.fullmatch(r"\[(\w+)\]", line)
            if m:
                on = m.group(1) == "ros"
            elif on:
                keys.add(line)
    return keys


def read_yaml_map(path):
    with open(path, encoding="utf-8") as f:
        data = yaml.safe_load(f)
    if not isinstance(data, dict) or not data:
        raise ValueError("%s: expected a non-empty map" % path)
    return data


def resolve(keys, os_name, apt_rules, ros_keys, debian_ros):
    """Resolve keys for os_name.

    Returns (packages: {key: [apt packages]}, missing: [(key, reason)]). A system key resolves
    through apt_rules[key][os_name] (null: no rule there); a ROS key through debian_ros on
    Debian (an empty list: built from source in the workspace, e.g. jackal_msgs) or
    ros-noetic-<key> on focal.
    """
    if os_name not in OSES:
        raise ValueError("unknown OS %r (one of %s)" % (os_name, ", ".join(OSES)))
    packages, missing = {}, []
    for key in keys:
        if key in ros_keys:
            if os_name == "focal":
                packages[key] = ["ros-noetic-" + key.replace("_", "-")]
            elif key in debian_ros:
                packages[key] = list(debian_ros[key] or [])
            else:
                missing.append((key, "ROS package without a Debian package "
                                     "(test/data/debian_ros_packages.yaml)"))
            continue
        rule = apt_rules.get(key)
        if rule is None:
            missing.append((key, "no rosdep rule (test/data/rosdep_apt_rules.yaml)"))
        elif not rule.get(os_name):
            missing.append((key, "rosdep's rule has no apt package on %s" % os_name))
        else:
            packages[key] = list(rule[os_name])
    return packages, missing


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 1)[1])
    p.add_argument("--os", required=True, choices=OSES, help="target OS")
    p.add_argument("--package", default=os.path.join(ROOT, "package.xml"), help="package.xml to read")
    p.add_argument("--keys", action="store_true", help="print 'key: packages' per key instead")
    a = p.parse_args(argv)
    try:
        keys = package_keys(a.package)
        packages, missing = resolve(keys, a.os,
                                    read_yaml_map(os.path.join(DATA, "rosdep_apt_rules.yaml")),
                                    read_ros_keys(os.path.join(DATA, "rosdep_keys.txt")),
                                    read_yaml_map(os.path.join(DATA, "debian_ros_packages.yaml")))
    except (OSError, ValueError, ET.ParseError, yaml.YAMLError) as e:
        print("resolve_deps: %s" % e, file=sys.stderr)
        return 2
    for key, reason in missing:
        print("resolve_deps: %s on %s: %s" % (key, a.os, reason), file=sys.stderr)
    if missing:
        return 1
    if a.keys:
        for key in keys:
            print("%s: %s" % (key, " ".join(packages[key]) or "(source, in the workspace)"))
    else:
        seen = []
        for key in keys:
            seen.extend(pkg for pkg in packages[key] if pkg not in seen)
        print("\n".join(seen))
    return 0


if __name__ == "__main__":
    sys.exit(main())
