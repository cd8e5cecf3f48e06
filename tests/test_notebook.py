#!/usr/bin/env python3
"""docs/examples/family.ipynb runs: executed with nbconvert (Debian's jupyter-nbconvert,
python3-nbclient, python3-ipykernel: `make deps`) into a temporary folder, no cell raises, and its
printed results say what the notebook claims (a family computed on threads, a converged periodic
orbit with its multipliers, sensitivities with the events). Prints "test_notebook: P passed, F failed"."""
import json
import os
import shutil
import subprocess
import sys

import swimtest
from swimtest import ROOT, TMP, check

NOTEBOOK = os.path.join(ROOT, "docs", "examples", "family.ipynb")


def test_family_notebook_executes():
    jupyter = shutil.which("jupyter", path="/usr/bin") or shutil.which("jupyter")
    check(jupyter is not None, "jupyter (Debian's jupyter-nbconvert) is installed: make deps")
    if not jupyter:
        return
    env = dict(os.environ, PATH="/usr/bin:" + os.environ.get("PATH", ""), PYDEVD_DISABLE_FILE_VALIDATION="1")
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    out = os.path.join(TMP, "notebook")
    p = subprocess.run([jupyter, "nbconvert", "--to", "notebook", "--execute", "--output-dir", out,
                        "--ExecutePreprocessor.timeout=300", NOTEBOOK], capture_output=True, text=True, env=env)
    check(p.returncode == 0, "nbconvert --execute: exit %d: %s" % (p.returncode, p.stderr[-800:]))
    path = os.path.join(out, "family.ipynb")
    if not os.path.exists(path):
        return
    with open(path) as f:
        nb = json.load(f)
    outputs = [o for c in nb["cells"] if c["cell_type"] == "code" for o in c.get("outputs", [])]
    errors = [o for o in outputs if o.get("output_type") == "error"]
    check(not errors, "no cell raised: %s" % [(o.get("ename"), o.get("evalue")) for o in errors])
    text = "".join("".join(o.get("text", "")) for o in outputs if o.get("output_type") == "stream")
    images = sum(1 for o in outputs if "image/png" in o.get("data", {}))
    check(images == 2, "two figures (the family, the sensitivities): %d" % images)
    check("converged True" in text and "multipliers at 1: 3 - time shift along the orbit; energy" in text
          and "|other multipliers| [1. 1.] stable True" in text,
          "a converged orbit, its multipliers at 1 named and the others on the unit circle: %r" % text)
    check("y(t = 10) from" in text and "maxima of am1; dy/drho0" in text, "the family and the sensitivities: %r" % text)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_notebook"))
