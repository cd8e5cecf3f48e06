"""The parts of the package's build that pyproject.toml cannot state: the version is the source
tree's VERSION (one number for bin/swim, libswim and this package), and the built package records
the checkout it came from, so that it finds that checkout's `make lib` build when no libswim is
installed (swim/_lib.py, candidates())."""
import os

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
TREE = os.path.dirname(HERE)


def version():
    with open(os.path.join(TREE, "VERSION")) as f:
        return f.read().strip()


class build_py_recording_tree(build_py):
    """Writes swim/_checkout.py into the built package (never into the source folder)."""

    def run(self):
        super().run()
        target = os.path.join(self.build_lib, "swim", "_checkout.py")
        with open(target, "w") as f:
            f.write('"""Written by setup.py at build time: the source tree this package was built from."""\n')
            f.write("TREE = %r\n" % TREE)


setup(version=version(), cmdclass={"build_py": build_py_recording_tree})
