#!/usr/bin/env python3
"""Python unit test (no build, no ROS): the import graph of the Python tools
(src/jackal_aic_tools) has no cycle.

Every module of the package is read with ``ast``, nothing is imported: each import of another
module of the package is an edge, at module level and inside functions and methods alike,
absolute (``import jackal_aic_tools.common.cli``, ``from jackal_aic_tools.common import cli``) or
relative (``from ..common import cli``, ``from .node_watch import CommandCheck``).
``from PKG import NAME`` is an import of the submodule PKG.NAME where there is one, else of PKG
itself (its __init__.py). A cycle, of two modules or more or a module importing itself, fails
the test with its modules in the order they import each other. Seeded packages show that the
walker resolves every form of import and reports a cycle closed by a function-level import.

    /usr/bin/python3 test/test_imports.py
    /usr/bin/python3 test/test_imports.py --gtest_output=xml:FILE   # JUnit XML via rosunit
"""
import ast
import os
import tempfile
import textwrap
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
PACKAGE_DIR = os.path.join(ROOT, "src", "jackal_aic_tools")


def package_modules(package_dir):
    """{dotted name: file path} of every module of the package in ``package_dir`` (named after the
    folder) and of its subpackages (folders with an __init__.py); an __init__.py under its
    package's name."""
    package = os.path.basename(os.path.normpath(package_dir))
    out = {}
    for base, dirs, files in os.walk(package_dir):
        dirs[:] = sorted(d for d in dirs if os.path.isfile(os.path.join(base, d, "__init__.py")))
        rel = os.path.relpath(base, package_dir)
        prefix = package if rel == "." else package + "." + rel.replace(os.sep, ".")
        for name in sorted(files):
            if name.endswith(".py"):
                out[prefix if name == "__init__.py" else prefix + "." + name[:-3]] = os.path.join(base, name)
    return out


def imported_modules(name, path, known):
    """The modules of ``known`` (dotted names) that module ``name`` (its file ``path``) imports,
    anywhere in the file, as a sorted list. Imports of other packages are left out."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), filename=path)
    is_package = os.path.basename(path) == "__init__.py"
    here = name if is_package else name.rpartition(".")[0]  # the package relative imports start from
    root = name.partition(".")[0]
    out = set()

    def add(target):
        """``target`` or, when it is not a module, its longest prefix that is."""
        while target and target not in known:
            target = target.rpartition(".")[0]
        if target:
            out.add(target)

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == root or alias.name.startswith(root + "."):
                    add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = here.split(".")
                if node.level - 1 >= len(parts):
                    raise ValueError("%s: relative import beyond the top package (line %d)" % (path, node.lineno))
                base = ".".join(parts[:len(parts) - (node.level - 1)])
                if node.module:
                    base += "." + node.module
            else:
                base = node.module or ""
                if not (base == root or base.startswith(root + ".")):
                    continue
            for alias in node.names:
                sub = base + "." + alias.name
                add(sub if alias.name != "*" and sub in known else base)
    return sorted(out)


def import_graph(package_dir):
    """{module: [modules of the package it imports]} of the package in ``package_dir``."""
    modules = package_modules(package_dir)
    return {name: imported_modules(name, path, modules) for name, path in modules.items()}


def cycles(graph):
    """The import cycles of ``graph`` ({module: [modules it imports]}), each a list of modules in
    the order they import each other, starting from the smallest name (the first imports the
    second, ..., the last the first); one cycle per strongly connected component of two modules
    or more, and every module that imports itself. Sorted."""
    index, low, stack, on_stack, components = {}, {}, [], set(), []

    def connect(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            components.append(set(component))

    for v in sorted(graph):
        if v not in index:
            connect(v)
    out = []
    for component in components:
        start = min(component)
        if len(component) == 1 and start not in graph.get(start, ()):
            continue
        # The shortest way from start back to itself inside the component (breadth first).
        previous, frontier, found = {}, [start], None
        while frontier and found is None:
            nxt = []
            for v in frontier:
                for w in sorted(graph.get(v, ())):
                    if w == start:
                        found = v
                        break
                    if w in component and w not in previous:
                        previous[w] = v
                        nxt.append(w)
                if found is not None:
                    break
            frontier = nxt
        path = [found]
        while path[-1] != start:
            path.append(previous[path[-1]])
        out.append(path[::-1])
    return sorted(out)


def describe(found):
    """The cycles as text, one line each: a -> b -> a."""
    return "\n".join(" -> ".join(c + [c[0]]) for c in found)


def write_package(root, files):
    """Write ``files`` ({relative path: source}) under the folder ``root``; returns ``root``."""
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(textwrap.dedent(text))
    return root


# A package with every form of import; seeded.a -> seeded.sub.c -> seeded.b -> seeded.a is its one
# cycle, closed by the function-level import in b.py (seeded.sub.d imports much, but nothing imports it).
SEEDED = {
    "__init__.py": '"""seeded"""\n',
    "a.py": """
        import os
        from .sub import c
        def g():
            return os.sep
        """,
    "b.py": """
        def f():
            from .a import g
            return g()
        """,
    "sub/__init__.py": "",
    "sub/c.py": """
        import json
        from .. import b
        from . import e as e_module
        """,
    "sub/d.py": """
        import seeded.sub.e
        from seeded import sub
        from seeded.b import f
        class K:
            def m(self):
                import seeded.a
                from .e import *
                return seeded.a
        """,
    "sub/e.py": "from numpy import array\n",
}


class ImportGraphTest(unittest.TestCase):

    def test_the_package_has_no_import_cycle(self):
        graph = import_graph(PACKAGE_DIR)
        self.assertIn("jackal_aic_tools.common.cli", graph)  # the walk saw the package
        self.assertGreater(len(graph), 40)
        self.assertGreater(sum(len(v) for v in graph.values()), 40)  # and its imports
        found = cycles(graph)
        self.assertFalse(found, "import cycles in src/jackal_aic_tools (move what both sides need into a "
                                "module both import):\n%s" % describe(found))

    def test_every_form_of_import_is_an_edge(self):
        with tempfile.TemporaryDirectory() as tmp:
            graph = import_graph(write_package(os.path.join(tmp, "seeded"), SEEDED))
        self.assertEqual(sorted(graph), ["seeded", "seeded.a", "seeded.b", "seeded.sub", "seeded.sub.c",
                                         "seeded.sub.d", "seeded.sub.e"])
        self.assertEqual(graph["seeded.a"], ["seeded.sub.c"])
        self.assertEqual(graph["seeded.b"], ["seeded.a"])  # inside a function
        self.assertEqual(graph["seeded.sub.c"], ["seeded.b", "seeded.sub.e"])  # from .. / from . as
        # absolute, a package, a name of a module, inside a method, from .e import *
        self.assertEqual(graph["seeded.sub.d"], ["seeded.a", "seeded.b", "seeded.sub", "seeded.sub.e"])
        self.assertEqual(graph["seeded.sub.e"], [])  # numpy is not the package

    def test_a_seeded_cycle_is_reported(self):
        with tempfile.TemporaryDirectory() as tmp:
            graph = import_graph(write_package(os.path.join(tmp, "seeded"), SEEDED))
            found = cycles(graph)
            self.assertEqual(found, [["seeded.a", "seeded.sub.c", "seeded.b"]], describe(found))
            self.assertEqual(describe(found), "seeded.a -> seeded.sub.c -> seeded.b -> seeded.a")
            # The control: without the function-level import the same package has no cycle.
            fixed = dict(SEEDED, **{"b.py": "def f():\n    return 1\n"})
            self.assertEqual(cycles(import_graph(write_package(os.path.join(tmp, "control", "seeded"), fixed))), [])

    def test_cycles_of_two_and_of_one(self):
        self.assertEqual(cycles({"p.x": ["p.y"], "p.y": ["p.x", "p.z"], "p.z": []}), [["p.x", "p.y"]])
        self.assertEqual(cycles({"p.x": ["p.x"]}), [["p.x"]])
        self.assertEqual(cycles({"p.a": ["p.b"], "p.b": ["p.c"], "p.c": ["p.a", "p.b"], "p.d": ["p.d", "p.a"]}),
                         [["p.a", "p.b", "p.c"], ["p.d"]])
        self.assertEqual(cycles({"p.a": ["p.b"], "p.b": [], "p.c": ["p.a", "p.b"]}), [])


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("imports", ImportGraphTest)
