#!/usr/bin/env python3
"""unittest: the C++ tree's layers, without a build.

The core is one folder per library (include/jackal_aic/<folder>/ and src/<folder>/, built by
src/<folder>/CMakeLists.txt as jackal_aic_<folder>); each folder includes only the folders
below it (LAYERS, the order of CMakeLists.txt). Above the core:

- the YAML override parser (overrides) includes no other part of the package;
- the simulated Jackal's plant (sim/plant) includes no controller header, only the override
  parser, and links no controller library;
- the harness (sim/harness) and the nodes (sim/nodes) include the core and the plant, never
  the tools (tools/include/jackal_tools);
- the node (ros) includes the core (analysis for the stability check of its configuration),
  never the simulator, the tools or the override parser;
- no core folder includes a ROS header (the core is ROS-free).

Each check is shown to fail on a seeded upward include.

    /usr/bin/python3 test/test_layers.py
"""
import os
import re
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))

# What each part may include, by include root: "jackal_aic/<folder>/" for the core and the
# node, "jackal_sim/" for the simulator, "jackal_tools/" for the tools.
CORE = ("base", "params", "aic", "safety", "loop", "analysis", "classical", "os")
LAYERS = {
    "base": set(),
    "params": {"base"},
    "aic": {"base", "params"},
    "safety": {"base", "params"},
    "loop": {"base", "params", "aic", "safety"},
    "analysis": {"base", "params", "aic"},
    "classical": {"base", "params", "aic"},
    "os": {"base"},
    "overrides": set(),
    "ros": (set(CORE) - {"classical"}) | {"cfg", "msg"},
}
# The Python package under src/ (catkin_python_setup's layout) is not a C++ library.
NOT_A_LIBRARY = {"jackal_aic_tools"}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]((?:jackal_aic|jackal_sim|jackal_tools)/[^">]+)[">]', re.M)


ROS_INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]((?:ros|roscpp|rosbag|std_msgs|std_srvs|sensor_msgs|geometry_msgs|'
                         r'nav_msgs|diagnostic_msgs|diagnostic_updater|dynamic_reconfigure|jackal_msgs|tf2_ros)/[^">]+)'
                         r'[">]', re.M)


def ros_includes(files):
    """ROS headers included by ``files`` ({name: text}): "file: include" each."""
    return ["%s: %s" % (n, i) for n, t in sorted(files.items()) for i in ROS_INCLUDE.findall(t)]


def includes(text):
    """The package's own includes in a C++ source text: ["jackal_aic/aic/controller.hpp", ...]."""
    return INCLUDE.findall(text)


def target_of(include):
    """The part an include names: a core folder, "overrides", "ros", "sim" or "tools"."""
    root, rest = include.split("/", 1)
    if root == "jackal_sim":
        return "sim"
    if root == "jackal_tools":
        return "tools"
    if "/" not in rest:
        # dynamic_reconfigure's generated header of cfg/AIC.cfg: jackal_aic/AICConfig.h; a
        # message's generated header of msg/<Name>.msg: jackal_aic/<Name>.h
        if rest.endswith("Config.h"):
            return "cfg"
        return "msg" if os.path.isfile(os.path.join(ROOT, "msg", rest[:-2] + ".msg")) else "<flat>"
    return rest.split("/", 1)[0]


def breaches(folder, files):
    """Upward or sideways includes of one core folder (or overrides, ros): "file: include" each.
    ``files`` maps a file name to its text."""
    allowed = LAYERS[folder] | {folder}
    out = []
    for name, text in sorted(files.items()):
        for inc in includes(text):
            if target_of(inc) not in allowed:
                out.append("%s: %s" % (name, inc))
    return out


def sources_of(*dirs):
    """{relative path: text} of the C++ files below the given folders (relative to ROOT)."""
    out = {}
    for d in dirs:
        for base, _dirs, names in os.walk(os.path.join(ROOT, d)):
            for n in names:
                if n.endswith((".cpp", ".hpp", ".h")):
                    p = os.path.join(base, n)
                    with open(p, encoding="utf-8") as f:
                        out[os.path.relpath(p, ROOT)] = f.read()
    return out


def link_line(cmake, target):
    """The libraries of ``target_link_libraries(target ...)`` in a CMake text (empty if absent)."""
    m = re.search(r"target_link_libraries\(\s*%s\s+([^)]*)\)" % re.escape(target), cmake)
    return [w for w in m.group(1).split() if w not in ("PUBLIC", "PRIVATE", "INTERFACE")] if m else []


class LayersTest(unittest.TestCase):
    def test_each_folder_is_one_library(self):
        inc = sorted(d for d in os.listdir(os.path.join(ROOT, "include", "jackal_aic"))
                     if os.path.isdir(os.path.join(ROOT, "include", "jackal_aic", d)))
        src = sorted(d for d in os.listdir(os.path.join(ROOT, "src"))
                     if os.path.isdir(os.path.join(ROOT, "src", d)) and d not in NOT_A_LIBRARY)
        self.assertEqual(inc, src, "include/jackal_aic/ and src/ hold different folders")
        self.assertEqual(sorted(LAYERS), inc, "a folder without a layer rule here, or a rule without a folder")
        for d in src:
            with open(os.path.join(ROOT, "src", d, "CMakeLists.txt"), encoding="utf-8") as f:
                libs = re.findall(r"add_library\(\s*(\S+)", f.read())
            self.assertEqual(libs, ["jackal_aic_" + d], "src/%s/CMakeLists.txt must build one library" % d)
            headers = os.listdir(os.path.join(ROOT, "include", "jackal_aic", d))
            self.assertTrue(headers, "include/jackal_aic/%s/ is empty" % d)
        flat = [n for n in os.listdir(os.path.join(ROOT, "include", "jackal_aic")) if n.endswith(".hpp")]
        self.assertFalse(flat, "headers outside a folder: %s" % flat)

    def test_no_include_runs_upward_in_the_core_and_the_node(self):
        for folder in LAYERS:
            files = sources_of(os.path.join("include", "jackal_aic", folder), os.path.join("src", folder))
            self.assertTrue(files, folder)
            self.assertFalse(breaches(folder, files), "%s includes what it must not" % folder)

    def test_the_core_includes_no_ros_header(self):
        for folder in CORE + ("overrides",):
            files = sources_of(os.path.join("include", "jackal_aic", folder), os.path.join("src", folder))
            self.assertFalse(ros_includes(files), "the core folder %s includes ROS" % folder)
        self.assertTrue(ros_includes(sources_of("src/ros")), "the node's ROS includes were not found")
        self.assertEqual(ros_includes({"a.cpp": "#include <ros/ros.h>\n#include <Eigen/Core>\n",
                                       "b.hpp": '#include "sensor_msgs/Imu.h"'}),
                         ["a.cpp: ros/ros.h", "b.hpp: sensor_msgs/Imu.h"])

    def test_a_seeded_upward_include_fails(self):
        seeded = {"controller.cpp": '#include "jackal_aic/aic/controller.hpp"\n#include "jackal_aic/loop/control_loop.hpp"\n'}
        self.assertEqual(breaches("aic", seeded), ["controller.cpp: jackal_aic/loop/control_loop.hpp"])
        self.assertEqual(breaches("params", {"x.hpp": "#include <jackal_aic/safety/fault_monitor.hpp>"}),
                         ["x.hpp: jackal_aic/safety/fault_monitor.hpp"])
        self.assertEqual(breaches("ros", {"n.cpp": '#include "jackal_sim/plant/plant.hpp"'}),
                         ["n.cpp: jackal_sim/plant/plant.hpp"])
        self.assertEqual(breaches("loop", {"y.cpp": '  #  include "jackal_aic/analysis/step_metrics.hpp"'}),
                         ["y.cpp: jackal_aic/analysis/step_metrics.hpp"])

    def test_the_plant_knows_nothing_of_the_controller(self):
        """sim/plant includes only the override parser of this package's headers, and links no
        controller library."""
        offending = [n + ": " + i for n, t in sorted(sources_of("sim/plant").items()) for i in includes(t)
                     if i.startswith(("jackal_aic/", "jackal_tools/")) and target_of(i) != "overrides"]
        self.assertFalse(offending, "the plant includes the controller's or the tools' headers: %s" % offending)
        with open(os.path.join(ROOT, "sim", "CMakeLists.txt"), encoding="utf-8") as f:
            links = link_line(f.read(), "jackal_plant")
        self.assertIn("PkgConfig::ODE", links, "jackal_plant's link line was not found")
        core = sorted(l for l in links if l.startswith("jackal_aic") and l != "jackal_aic_overrides")
        self.assertFalse(core, "jackal_plant links the controller's libraries: %s" % core)

    def test_the_plant_link_check_can_fail(self):
        self.assertIn("jackal_aic_loop", link_line("target_link_libraries(jackal_plant PUBLIC jackal_aic_loop "
                                                   "PkgConfig::ODE)", "jackal_plant"))

    def test_the_simulator_does_not_include_the_tools(self):
        offending = [n + ": " + i for n, t in sorted(sources_of("sim").items()) for i in includes(t)
                     if target_of(i) == "tools"]
        self.assertFalse(offending, "the simulator includes the tools: %s" % offending)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("layers", LayersTest)
