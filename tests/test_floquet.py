#!/usr/bin/env python3
"""swim floquet: monodromy and Floquet multipliers of the periodic strokes of Examples 1 and 3.

One column of M against central differences of whole swim runs over one period.

Checks the structure a conservative system imposes, on the multipliers of the motion on the
constraint manifold: the flow direction is an eigenvector and the energy gradient a left
eigenvector with multiplier 1, the multipliers come in reciprocal pairs, det M_t = 1; the period
agrees with the events of swim run; the orbit closes. Example 1 has no potential, so a change of
beta'0 only rescales time: the period scales as 1/|beta'0| and the multipliers do not change.
Both strokes are linearly stable (all |lambda| = 1). Bad --event: exit 2, one line.
Prints "test_floquet: P passed, F failed".
"""

import json
import os
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main


def floquet(scene, name, *args):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "floquet", scene, "--out", out, "--quiet", *args], capture_output=True,
                       text=True, cwd=ROOT)
    data = None
    if p.returncode == 0:
        with open(os.path.join(out, "floquet.json")) as fh:
            data = json.load(fh)
    return p, data


def multipliers(d):
    return np.array([m["re"] + 1j * m["im"] for m in d["multipliers_tangent"]])


def structure(d, what):
    c = d["checks"]
    lam = multipliers(d)
    check(d["tangent_dimension"] == d["dimension"] - 3,
          "%s: the tangent space loses the volume, G1 and G2 directions (%d of %d)"
          % (what, d["tangent_dimension"], d["dimension"]))
    check(d["closure"] < 1e-8, "%s: the orbit closes after one period (%.2g)" % (what, d["closure"]))
    check(c["flow_residual"] < 1e-6, "%s: M f = f (%.2g)" % (what, c["flow_residual"]))
    check(c["energy_residual"] < 1e-6, "%s: grad E M = grad E on the manifold (%.2g)" % (what, c["energy_residual"]))
    check(c["reciprocal_residual"] < 1e-6, "%s: multipliers in reciprocal pairs (%.2g)" % (what, c["reciprocal_residual"]))
    check(abs(c["det_tangent"] - 1) < 1e-6, "%s: det M_t = 1 (%.12g)" % (what, c["det_tangent"]))
    check(np.sum(np.abs(lam - 1) < 1e-3) >= 2, "%s: at least two multipliers at 1 (flow, energy)" % what)
    check(np.max(np.abs(np.abs(lam) - 1)) < 1e-6 and d["stable"], "%s: all |lambda| = 1: stable" % what)
    check(d["base"].startswith("t = 0"), "%s: floquet.json states its base point (%r)" % (what, d["base"]))
    comp = np.array([m["re"] + 1j * m["im"] for m in c["multipliers_complement"]])
    check(c["exact_ones"] >= 2 and len(comp) == d["tangent_dimension"] - c["exact_ones"]
          and np.max(np.abs(np.abs(comp) - 1)) < 1e-9,
          "%s: time shift and energy taken out, the complement on the unit circle to 1e-9 (%s)" % (what, np.abs(comp)))
    nontrivial = lam[np.abs(lam - 1) > 1e-3]
    check(len(nontrivial) == 2 and abs(nontrivial[0] - np.conj(nontrivial[1])) < 1e-9,
          "%s: one complex-conjugate pair off 1 (%s)" % (what, nontrivial))
    return nontrivial


def test_example1_several_betadot():
    ex1 = os.path.join("models", "example1.toml")
    res = {}
    for bd in (-1.0, -2.0, 0.5):
        p, d = floquet(ex1, "ex1_%g" % bd, "--set", "shape.dc0.bm2=%r" % (0.5 * bd / 2 ** 0.5), "--t-max", "60")
        check(p.returncode == 0, "Example 1, beta'0 = %g: %s" % (bd, p.stderr))
        if d:
            res[bd] = (d["period"], structure(d, "Example 1, beta'0 = %g" % bd))
    if len(res) == 3:
        T1 = res[-1.0][0]
        check(abs(T1 - 8.334630955) < 1e-6, "Example 1: period 8.334630955 as the events of swim run (%r)" % T1)
        for bd in (-2.0, 0.5):
            check(abs(res[bd][0] * abs(bd) - T1) < 1e-7, "Example 1: T scales as 1/|beta'0| (%g)" % bd)
            a, b = np.sort_complex(res[bd][1]), np.sort_complex(res[-1.0][1])
            check(np.max(np.abs(a - b)) < 1e-7, "Example 1: the multipliers do not depend on beta'0 (%g: %s vs %s)"
                  % (bd, a, b))


def test_example3():
    p, d = floquet(os.path.join("models", "example3.toml"), "ex3", "--event", "am1:max")
    check(p.returncode == 0, "Example 3: %s" % p.stderr)
    if d:
        check(abs(d["period"] - 3.698497902) < 1e-6, "Example 3: period 3.698497902 (%r)" % d["period"])
        structure(d, "Example 3")


def test_monodromy_against_runs():
    """M applied to a scaling of the initial velocity (which keeps G1, G2: no projection) against
    central differences of whole swim runs over one period (Richardson of h and h/2)."""
    ex3 = os.path.join("models", "example3.toml")
    p, d = floquet(ex3, "ex3_m", "--event", "am1:max")
    if not d:
        check(False, "Example 3 floquet for the monodromy check")
        return
    M = np.array(d["monodromy"])
    T = d["period"]
    cols = ["am1", "bm1", "am2", "bm2", "dam1", "dbm1", "dam2", "dbm2"]
    v0 = np.array([0, 0, 0, 0, 0.6, 0.0, 0.0, -0.6])   # Example 3's dc0 on the moving coordinates

    def final(scale, tag):
        _, r, _ = swimtest.run(ex3, "mono_" + tag, "--t-end", repr(T), "--rtol", "1e-12", "--atol", "1e-14",
                               "--set", "shape.dc0.am1=%r" % (0.6 * scale), "--set", "shape.dc0.bm2=%r" % (-0.6 * scale))
        return np.array([r[c][-1] for c in cols])
    h = 1e-4
    d1 = (final(1 + h, "p1") - final(1 - h, "m1")) / (2 * h)
    d2 = (final(1 + h / 2, "p2") - final(1 - h / 2, "m2")) / h
    fd = d2 + (d2 - d1) / 3
    mv = M @ v0
    err = np.max(np.abs(fd - mv))
    check(err < 1e-6, "Example 3: M (0, dc0) = differences of whole runs over T (max diff %.2g)" % err)
    check(np.max(np.abs(mv)) > 0.1, "the column is not trivial")


def test_bad_event():
    ex3 = os.path.join("models", "example3.toml")
    for spec, want in (("a1:max", "not a moving coordinate"), ("am1:top", "COLUMN:KIND"), ("am1", "COLUMN:KIND")):
        out = os.path.join(TMP, "bad_%s" % spec.replace(":", "_"))
        p = subprocess.run([SWIM, "floquet", ex3, "--out", out, "--quiet", "--event", spec], capture_output=True,
                           text=True, cwd=ROOT)
        lines = [l for l in p.stderr.splitlines() if l.strip() and not l.startswith("swim: ")]
        check(p.returncode == 2 and len(lines) == 1 and want in lines[0], "--event %s: exit 2, '%s' (%r)" % (spec, want, p.stderr))
        check(not os.path.exists(out), "--event %s: nothing written" % spec)
    p = subprocess.run([SWIM, "floquet", ex3, "--out", os.path.join(TMP, "short"), "--quiet", "--t-max", "2"],
                       capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 1 and "fewer than two events" in p.stderr, "no period before --t-max: exit 1 saying so (%r)" % p.stderr)


def test_scene_integrator():
    """The period and the monodromy are integrated by the scene's own integrator (its [run] settings,
    as swim run has them); one that cannot locate events is refused with one line, before any output."""
    ex3 = os.path.join("models", "example3.toml")
    pa, da = floquet(ex3, "int_abm")
    pb, db = floquet(ex3, "int_bdf", "--set", "run.integrator=cvode-bdf")
    check(pa.returncode == 0 and pb.returncode == 0, "abm and cvode-bdf: %s %s" % (pa.stderr, pb.stderr))
    if da and db:
        check(da["period"] != db["period"] and abs(da["period"] - db["period"]) < 1e-6,
              "cvode-bdf's period is its own (%r vs abm %r), within the tolerance" % (db["period"], da["period"]))
    out = os.path.join(TMP, "int_rk8pd")
    p = subprocess.run([SWIM, "floquet", ex3, "--out", out, "--set", "run.integrator=rk8pd"], capture_output=True,
                       text=True, cwd=ROOT)
    check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "rk8pd" in p.stderr
          and "events" in p.stderr, "rk8pd refused in one line naming it (%r)" % p.stderr)
    check(not os.path.exists(out), "nothing written for a refused integrator")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_floquet"))
