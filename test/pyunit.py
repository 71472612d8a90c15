"""How the package's Python test files run: ``pyunit.main(NAME, Case, ...)`` at the end of a test
file runs its unittest cases

- as CMake runs them, ``python3 test/test_X.py --gtest_output=xml:FILE``: through rosunit, which
  writes the JUnit result to FILE (one result named NAME for all the cases given);
- on their own, ``python3 test/test_X.py [unittest options]``: unittest's own runner and output
  (every test case of the file).

A test file imports it with the test folder on sys.path (the folder of the file for
test/test_*.py; test/sim/ files add the parent folder)."""
import sys
import unittest

PACKAGE = "jackal_aic"
_CASES = []


def suite():
    """The test cases given to main(), as one suite (rosunit loads it by this function's name)."""
    loader = unittest.TestLoader()
    return unittest.TestSuite(loader.loadTestsFromTestCase(c) for c in _CASES)


def main(name, *cases):
    """Run ``cases`` (unittest.TestCase classes) of the calling test file: with a
    --gtest_output=xml:FILE argument through rosunit.unitrun as the result ``name`` of package
    jackal_aic, else with unittest.main() on the file. Exits with the tests' status."""
    if any(arg.startswith("--gtest_output=xml:") for arg in sys.argv):
        import rosunit
        _CASES[:] = cases
        rosunit.unitrun(PACKAGE, name, __name__ + ".suite")
    else:
        unittest.main(module="__main__")
