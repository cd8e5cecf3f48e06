#!/usr/bin/env python3
"""`[run] jacobian` end to end: swim run with the kernel's exact Jacobian and with difference
quotients, on a stiff scene (models/hard/stiff_n7.toml, shortened to t = 3) and both BDF methods.

Asserts: the setting reaches the integrator (summary stats: "jacobian", exact_jacobian_calls > 0
only when exact; the integrator's Jacobian count equals the exact calls); the two trajectories
agree on every output row to a few tolerances; the exact Jacobian saves RHS evaluations;
`--set run.jacobian=...` and the scene key are read the same way; a bad value is one line on
stderr naming the file and key, exit status 2, nothing written.
Prints "test_jacobian_run: P passed, F failed"."""

import os
import sys

import numpy as np

from swimtest import ROOT, TMP, check, main, run

SCENE = "models/hard/stiff_n7.toml"
COLS = ["x", "y", "theta", "energy"]


def test_exact_and_differences_agree():
    for integ in ("cvode-bdf", "msbdf"):
        res = {}
        for jac in ("exact", "differences"):
            p, d, s = run(SCENE, "%s_%s" % (integ, jac), "--integrator", integ, "--t-end", "3",
                          "--rtol", "1e-9", "--atol", "1e-11", "--set", "run.jacobian=" + jac)
            check(p.returncode == 0 and s is not None and s["status"] == "completed",
                  "%s %s: %s" % (integ, jac, p.stderr.strip()))
            if s is None or d is None:
                return
            st = s["stats"]
            check(st["jacobian"] == jac, "%s: asked %s, used %s" % (integ, jac, st["jacobian"]))
            if jac == "exact":
                check(st["exact_jacobian_calls"] > 0 and st["exact_jacobian_calls"] == st["jacobian_evaluations"],
                      "%s: exact calls %d, integrator's Jacobians %d" % (integ, st["exact_jacobian_calls"],
                                                                         st["jacobian_evaluations"]))
            else:
                check(st["exact_jacobian_calls"] == 0, "%s: differences, yet %d exact calls" % (integ, st["exact_jacobian_calls"]))
            res[jac] = (d, st)
        (de, se), (dd, sd) = res["exact"], res["differences"]
        check(len(de) == len(dd), "%s: %d vs %d rows" % (integ, len(de), len(dd)))
        for c in COLS:
            diff = np.max(np.abs(de[c] - dd[c]))
            scale = max(1.0, np.max(np.abs(dd[c])))
            check(diff <= 1e-6 * scale, "%s: column %s differs by %.3g" % (integ, c, diff))
        check(se["rhs_evaluations"] < sd["rhs_evaluations"],
              "%s: RHS evaluations exact %d vs differences %d" % (integ, se["rhs_evaluations"], sd["rhs_evaluations"]))


def test_scene_key_and_errors():
    with open(os.path.join(ROOT, SCENE), encoding="utf-8") as fh:
        text = fh.read()
    path = os.path.join(TMP, "differences.toml")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text.replace("[run]\n", '[run]\njacobian = "differences"\n', 1))
    p, d, s = run(path, "key_differences", "--integrator", "cvode-bdf", "--t-end", "0.5")
    check(p.returncode == 0 and s["stats"]["jacobian"] == "differences", "scene key: %s" % p.stderr.strip())
    p, d, s = run(path, "key_override", "--integrator", "cvode-bdf", "--t-end", "0.5", "--set", "run.jacobian=exact")
    check(p.returncode == 0 and s["stats"]["jacobian"] == "exact", "--set over the key: %s" % p.stderr.strip())
    bad = os.path.join(TMP, "bad.toml")
    with open(bad, "w", encoding="utf-8") as fh:
        fh.write(text.replace("[run]\n", '[run]\njacobian = "analytic"\n', 1))
    for name, scene, args in (("bad_key", bad, []), ("bad_set", SCENE, ["--set", "run.jacobian=analytic"]),
                              ("bad_type", SCENE, ["--set", "run.jacobian=1"])):
        p, d, s = run(scene, name, *args)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(lines) == 1 and "jacobian" in lines[0],
              "%s: exit %d, stderr %r" % (name, p.returncode, p.stderr))
        check(not os.path.exists(os.path.join(TMP, name)), "%s: wrote output" % name)


if __name__ == "__main__":
    sys.exit(main(globals(), "test_jacobian_run"))
