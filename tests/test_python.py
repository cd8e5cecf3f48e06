"""The Python package swim (python/swim over libswim): pytest on python/tests/, counted.

tests/run_tests.sh reads a test's last line "NAME: P passed, F failed"; pytest's own report is
printed above it (its FAILED lines name each failing test). Needs Debian's python3-pytest
(make deps) and libswim (make lib; make test builds it first), or $SWIM_LIB.
"""
import os
import shutil
import sys
import tempfile

sys.dont_write_bytecode = True   # no __pycache__ in python/swim: make install copies that folder

import pytest  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Counts:
    """Passed and failed tests (a failure in setup or teardown counts as a failed test)."""

    def __init__(self):
        self.passed = self.failed = 0

    def pytest_runtest_logreport(self, report):
        if report.failed:
            self.failed += 1
        elif report.passed and report.when == "call":
            self.passed += 1

    def pytest_collectreport(self, report):
        if report.failed:
            self.failed += 1


def main():
    os.environ.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    counts = Counts()
    tmp = tempfile.mkdtemp(prefix="swim-test-python-")   # the tests' tmp_path, removed after
    try:
        rc = pytest.main(["-q", "-rf", "-p", "no:cacheprovider", "--rootdir", ROOT, "--basetemp", tmp,
                          os.path.join(ROOT, "python", "tests")], plugins=[counts])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if rc != 0 and counts.failed == 0:   # nothing collected, an internal error, an interrupt
        counts.failed = 1
    print("test_python: %d passed, %d failed" % (counts.passed, counts.failed))
    return 0 if counts.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
