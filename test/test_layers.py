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
- no core folder includes a ROS header (the core is ROS-free);
- a folder is a namespace too: each header under include/jackal_aic/<folder>/ declares its
  names in jackal_aic::<folder> (NAMESPACE; the node's folder ros/ is jackal_aic::node, as
  jackal_aic::ros would hide ::ros inside jackal_aic), opens no using-directive, and declares
  nothing elsewhere but forward declarations of other namespaces' classes.

Each check is shown to fail on a seeded upward include or a seeded declaration.

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
# The namespace of each folder's names: jackal_aic::<NAMESPACE[folder]>.
NAMESPACE = dict({f: f for f in CORE + ("overrides",)}, ros="node")
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


def code_of(text):
    """``text`` (C++) without comments, string and character literals and preprocessor lines
    (each replaced by spaces, so braces and semicolons keep their places)."""
    pattern = re.compile(r'//[^\n]*|/\*.*?\*/|R"([^(\s]*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|'
                         r"'(?:\\.|[^'\\\n])*'|^[ \t]*#[^\n]*(?:\\\n[^\n]*)*", re.S | re.M)
    return pattern.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def namespace_scope_declarations(text):
    """The declarations of a C++ text at namespace scope: [(namespace, head), ...], namespace as
    "a::b" ("" global; anonymous namespaces as "(anonymous)"), head the declaration's text up
    to and with its first "{" or ";", whitespace collapsed. Namespace definitions themselves are not
    listed (their contents are)."""
    code = code_of(text)
    stack = []  # one entry per open brace: the namespace name it opens, or None for any other
    out = []
    start = 0
    opener = re.compile(r"(?:inline\s+)?namespace\s*([\w:]*)\s*$")
    for i, c in enumerate(code):
        if c not in "{};":
            continue
        head = " ".join(code[start:i].split())
        at_namespace_scope = all(e is not None for e in stack)
        if c == "{":
            m = opener.match(head) if at_namespace_scope else None
            if m:
                stack.extend(m.group(1).split("::") if m.group(1) else ["(anonymous)"])
                stack.append("::")  # marks the end of one namespace-definition's names
            else:
                if at_namespace_scope and head:
                    out.append((_namespace_of(stack), head + " {"))
                stack.append(None)
        elif c == "}":
            if stack and stack[-1] == "::":
                stack.pop()
                while stack and stack[-1] not in ("::", None):
                    stack.pop()
            elif stack:
                stack.pop()
        elif at_namespace_scope and head:
            out.append((_namespace_of(stack), head + ";"))
        start = i + 1
    return out


def _namespace_of(stack):
    return "::".join(e for e in stack if e not in ("::", None))


FORWARD_DECLARATION = re.compile(r"^(?:class|struct)\s+\w+;$")


def namespace_breaches(folder, files):
    """Declarations of one folder's headers outside jackal_aic::<NAMESPACE[folder]> (or a namespace
    inside it), and using-directives: "file: namespace: declaration" each. A forward declaration of
    a class of another namespace (``namespace params { struct AicParams; }``) is allowed, but not
    in jackal_aic itself, which holds only the folders' namespaces.
    ``files`` maps a file name to its text."""
    home = "jackal_aic::" + NAMESPACE[folder]
    out = []
    for name, text in sorted(files.items()):
        for ns, head in namespace_scope_declarations(text):
            inside = ns == home or ns.startswith(home + "::")
            forward = FORWARD_DECLARATION.match(head) and ns != "jackal_aic"
            if head.startswith("using namespace") or not (inside or forward):
                out.append("%s: %s: %s" % (name, ns or "(global)", head))
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

    def test_each_folder_is_a_namespace(self):
        for folder in LAYERS:
            headers = sources_of(os.path.join("include", "jackal_aic", folder))
            self.assertTrue(headers, folder)
            self.assertFalse(namespace_breaches(folder, headers),
                             "headers of %s declare names outside jackal_aic::%s" % (folder, NAMESPACE[folder]))

    def test_a_seeded_declaration_outside_the_folder_namespace_fails(self):
        good = ("#pragma once\n#include <string>  // std::string {\nnamespace jackal_aic\n{\nnamespace params\n{\n"
                "struct AicParams;\n}\nnamespace aic\n{\n/// a { brace; in a comment\nstruct Goal\n{\n  int n = 0;\n"
                "  void f() { const char* s = \"}\"; }\n};\nstd::string name(const Goal& g);\nnamespace detail\n{\n"
                "inline int twice(int x) { return 2 * x; }\n}  // namespace detail\n}  // namespace aic\n"
                "}  // namespace jackal_aic\n")
        self.assertEqual(namespace_breaches("aic", {"goal.hpp": good}), [])
        self.assertEqual(namespace_scope_declarations(good)[1:4],
                         [("jackal_aic::aic", "struct Goal {"), ("jackal_aic::aic", "std::string name(const Goal& g);"),
                          ("jackal_aic::aic::detail", "inline int twice(int x) {")])
        self.assertEqual(namespace_breaches("aic", {"flat.hpp": "namespace jackal_aic\n{\nstruct Goal\n{\n};\n}\n"}),
                         ["flat.hpp: jackal_aic: struct Goal {"])
        self.assertEqual(namespace_breaches("aic", {"side.hpp": "namespace jackal_aic::loop\n{\nint rate();\n}\n"}),
                         ["side.hpp: jackal_aic::loop: int rate();"])
        self.assertEqual(namespace_breaches("ros", {"n.hpp": "namespace jackal_aic::ros\n{\nclass AicNode\n{\n};\n}\n"}),
                         ["n.hpp: jackal_aic::ros: class AicNode {"])
        self.assertEqual(namespace_breaches("aic", {"f.hpp": "namespace jackal_aic\n{\nstruct AicParams;\n}\n"}),
                         ["f.hpp: jackal_aic: struct AicParams;"])
        self.assertEqual(namespace_breaches("base", {"g.hpp": "constexpr int kDim = 3;\n"}), ["g.hpp: (global): constexpr int kDim = 3;"])
        self.assertEqual(namespace_breaches("loop", {"u.hpp": "namespace jackal_aic::loop\n{\nusing namespace jackal_aic::aic;\n}\n"}),
                         ["u.hpp: jackal_aic::loop: using namespace jackal_aic::aic;"])

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
