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


def unlisted(cases, module=None):
    """Names of the unittest.TestCase classes defined in ``module`` (default: the test file run,
    __main__) that are not among ``cases``, sorted: cases rosunit would never run."""
    module = module if module is not None else sys.modules["__main__"]
    defined = [v for v in vars(module).values()
               if isinstance(v, type) and issubclass(v, unittest.TestCase) and v.__module__ == module.__name__]
    return sorted(c.__name__ for c in defined if c not in cases)


def shadowing(cases):
    """Names of the ``cases`` (unittest.TestCase classes) that define an attribute ``run``, sorted: it
    hides unittest.TestCase.run, so none of their tests would run (each would count, silently, as
    passed)."""
    return sorted(c.__name__ for c in cases if "run" in vars(c))


def main(name, *cases):
    """Run ``cases`` (unittest.TestCase classes) of the calling test file: with a
    --gtest_output=xml:FILE argument through rosunit.unitrun as the result ``name`` of package
    jackal_aic, else with unittest.main() on the file. A test case class of the file that is not
    among ``cases`` (unlisted()) adds a failing test naming it, so no case is left unrun. Exits
    with the tests' status. A case that hides TestCase.run (shadowing()) stops the file with exit
    status 1 before anything runs."""
    hidden = shadowing(cases)
    if hidden:
        sys.stderr.write("pyunit: %s define 'run', which hides unittest.TestCase.run: their tests would not "
                         "run; rename it\n" % ", ".join(hidden))
        sys.exit(1)
    if any(arg.startswith("--gtest_output=xml:") for arg in sys.argv):
        import rosunit
        missing = unlisted(cases)
        if missing:
            class UnlistedCases(unittest.TestCase):
                """Fails: the file defines test cases that pyunit.main() was not given."""

                def test_every_case_of_the_file_runs(self):
                    self.fail("test case classes not given to pyunit.main(): %s" % ", ".join(missing))
            cases = cases + (UnlistedCases,)
        _CASES[:] = cases
        rosunit.unitrun(PACKAGE, name, __name__ + ".suite")
    else:
        unittest.main(module="__main__")
