#!/usr/bin/env python3
"""unittest: every C++ file of the package is formatted as .clang-format says.

clang-format (Debian's package clang-format) formats each tracked .cpp/.hpp/.h file (the
jackal_msgs stand-in under compat/ excepted: generated-message style); a file it would change
fails the test, with the command that formats it. A seeded unformatted text is shown to fail.

    /usr/bin/python3 test/test_format.py
    clang-format -i FILE                     # format one file in place
"""
import os
import shutil
import subprocess
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
EXTENSIONS = (".cpp", ".hpp", ".h")
EXCLUDED = ("compat/",)


def clang_format():
    """The clang-format executable (clang-format, else the newest clang-format-N on PATH)."""
    found = shutil.which("clang-format")
    if found:
        return found
    for version in range(30, 9, -1):
        found = shutil.which("clang-format-%d" % version)
        if found:
            return found
    return None


def cpp_files():
    """The package's C++ files (relative paths): the tracked ones where git is at hand, else a walk."""
    try:
        out = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                             capture_output=True, text=True, check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        out = []
        for base, dirs, names in os.walk(ROOT):
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            out += [os.path.relpath(os.path.join(base, n), ROOT) for n in names]
    return sorted(f for f in out if f.endswith(EXTENSIONS) and not f.startswith(EXCLUDED)
                  and os.path.isfile(os.path.join(ROOT, f)))


def unformatted(exe, text, filename):
    """True if clang-format (the repository's .clang-format) would change ``text`` of ``filename``."""
    result = subprocess.run([exe, "--style=file", "--assume-filename=" + os.path.join(ROOT, filename)],
                            input=text, capture_output=True, text=True, cwd=ROOT)
    if result.returncode != 0:
        raise RuntimeError("%s failed on %s: %s" % (exe, filename, result.stderr.strip()))
    return result.stdout != text


class FormatTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.exe = clang_format()

    def test_clang_format_is_installed(self):
        self.assertIsNotNone(self.exe, "clang-format not found: apt-get install clang-format (dev/debian-packages.txt)")

    def test_every_cpp_file_is_formatted(self):
        if self.exe is None:
            self.fail("clang-format not found")
        files = cpp_files()
        self.assertGreater(len(files), 100, "the C++ files were not found")
        bad = []
        for f in files:
            with open(os.path.join(ROOT, f), encoding="utf-8") as h:
                if unformatted(self.exe, h.read(), f):
                    bad.append(f)
        self.assertFalse(bad, "not formatted as .clang-format says (clang-format -i FILE): %s" % bad)

    def test_an_unformatted_file_fails(self):
        if self.exe is None:
            self.fail("clang-format not found")
        self.assertTrue(unformatted(self.exe, "int f(){return 1;}\n", "src/aic/seeded.cpp"))
        self.assertFalse(unformatted(self.exe, "int f()\n{\n  return 1;\n}\n", "src/aic/seeded.cpp"))


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("format", FormatTest)
