"""swim continue: branches of periodic orbits. Example 1 has no potential energy, so its equations
are invariant under a rescaling of time (c(t; s v) = c(s t; v)): along its family by energy the
period times sqrt(E) and the displacement per period are constants, to 1e-9 (test); the symmetry
of its parametrization is found (a multiplier at 1 whose generator M fixes) and held by a phase
condition, so the branch does not turn the swimmer. A branch in a run-time key passes through the
scene's own orbit (the point at the scene's value equals swim periodic's). Example 3's librations
stay in the mirror plane their first orbit lies in: periods independent of the number of points
and equal to in-plane orbits solved on their own, to 1e-9. Bad input: one line,
exit 2."""

import csv
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import swimtest  # noqa: E402
from swimtest import TMP, check, swim  # noqa: E402


def branch(scene, name, *args):
    out = os.path.join(TMP, name)
    p = swim("continue", scene, "--out", out, "--quiet", *args)
    path = os.path.join(out, "branch.csv")
    rows = list(csv.DictReader(open(path))) if os.path.exists(path) else []
    return p, rows, out


def test_example1_time_scaling():
    p, rows, out = branch("models/example1.toml", "ex1", "--param", "energy=0.05:0.3", "--max-points", "6")
    check(p.returncode == 0 and len(rows) == 6, "six points: %d %r" % (p.returncode, p.stderr[-300:]))
    if len(rows) != 6:
        return
    inv = [float(r["period"]) * math.sqrt(float(r["energy"])) for r in rows]
    dy = [float(r["dy"]) for r in rows]
    check(max(inv) - min(inv) <= 1e-9 * inv[0], "period sqrt(E) constant to 1e-9: %s" % inv)
    check(max(dy) - min(dy) <= 1e-9 * abs(dy[0]), "dy per period constant to 1e-9: %s" % dy)
    check(all(abs(float(r["dx"])) < 1e-8 for r in rows), "the swimmer is not turned along the branch: dx %s"
          % [r["dx"] for r in rows])
    check(all(abs(float(r["energy"]) - float(r["energy_target"])) <= 1e-9 * float(r["energy_target"]) for r in rows),
          "each point has its target energy")
    check(all(r["stable"] == "yes" for r in rows), "linearly stable along the branch")
    d = json.load(open(os.path.join(out, "branch.json")))
    check(d["special_points"] == [] and len(d["points"]) == 6, "no special points on an elliptic branch")


def test_symmetry_found():
    out = os.path.join(TMP, "p1")
    swim("periodic", "models/example1.toml", "--out", out, "--quiet")
    at1 = json.load(open(os.path.join(out, "periodic.json")))["floquet"]["at_1"]
    sym = [a for a in at1 if a.get("symmetry")]
    check(len(sym) == 1 and "parametrization" in sym[0]["reason"] and sym[0]["residual"] < 1e-8,
          "Example 1: the parametrization turned against the body is a symmetry: %s" % at1)
    check(at1[0]["residual"] < 1e-7 and at1[1]["residual"] < 1e-7, "time shift and energy are eigen-directions")


def test_key_branch_through_the_scene():
    p, rows, _ = branch("models/example3.toml", "ex3", "--param", "model.rho0=0.9:1.1", "--max-points", "3")
    check(p.returncode == 0 and len(rows) == 3, "three points in model.rho0: %r" % p.stderr[-300:])
    out = os.path.join(TMP, "p3")
    swim("periodic", "models/example3.toml", "--out", out, "--quiet")
    T = json.load(open(os.path.join(out, "periodic.json")))["period"]
    mid = [r for r in rows if float(r["model.rho0"]) == 1.0]
    check(mid and abs(float(mid[0]["period"]) - T) < 1e-9 * T, "at rho0 = 1 the branch is the scene's orbit: %s vs %r"
          % (mid and mid[0]["period"], T))
    periods = [float(r["period"]) for r in rows]
    check(periods == sorted(periods), "a denser body swims slower strokes: %s" % periods)


LIB = "tests/scenes/example3_libration.toml"
MU = 0.4899   # sqrt of the volume of c_ref, which the scene's c0 has


def in_plane_period(E, name):
    """The libration of energy E from an independent start: at rest on the ellipse
    a_-1^2 + 2 b_-2^2 = MU^2 of the mirror plane, where W1 = MU (MU - a_-1), solved by swim periodic
    from there (am1 passes its maximum twice per period whatever the amplitude)."""
    a = MU - E / MU
    b = math.sqrt((MU * MU - a * a) / 2)
    out = os.path.join(TMP, name)
    p = swim("periodic", LIB, "--out", out, "--quiet", "--guess-event", "am1:max:2",
             "--set", "shape.c0.am1=%.17g" % a, "--set", "shape.c0.bm2=%.17g" % b)
    path = os.path.join(out, "periodic.json")
    d = json.load(open(path)) if os.path.exists(path) else None
    check(p.returncode == 0 and d and d["converged"] and abs(d["energy"] - E) <= 1e-9,
          "in-plane orbit at E = %g: %r" % (E, p.stderr[-300:]))
    return d["period"] if d else float("nan")


def test_libration_branch_stays_in_the_mirror_plane():
    """Example 3's librations are continued inside the plane b_-1 = a_-2 = 0 their first orbit lies
    in: the periods at E = 0.1 ... 0.4 do not depend on the number of points and agree with
    in-plane orbits started independently to 1e-9; branch.csv gives each phase point (in the
    plane); the branch points where orbits leaving the plane branch off are said."""
    runs = {}
    for n in (4, 7):
        p, rows, out = branch(LIB, "lib%d" % n, "--guess-event", "bm2:max", "--param", "energy=0.1:0.4",
                              "--max-points", str(n))
        check(p.returncode == 0 and len(rows) == n, "%d points: %d %r" % (n, p.returncode, p.stderr[-300:]))
        runs[n] = {round(float(r["energy_target"]), 9): r for r in rows}
        check(all(r[k] is not None and float(r[k]) == 0.0 for r in rows for k in ("bm1", "am2", "dbm1", "dam2"))
              and all(float(r["am1"]) != 0.0 for r in rows), "%d points: phase points in the mirror plane" % n)
        if n == 7:
            b = json.load(open(os.path.join(out, "branch.json")))
            check(b["invariant_subspace"]["held_zero"] == ["bm1", "am2", "dbm1", "dam2"],
                  "the invariant subspace named: %r" % b["invariant_subspace"])
            sp = [x for x in b["special_points"] if "leaving the invariant subspace" in x["kind"]]
            check(len(sp) == 2 and sp[0]["refined"] and 0.18 < sp[0]["between"][0] < 0.2,
                  "branch points of orbits leaving the plane said: %r" % [(x["kind"], x["between"]) for x in sp])
    for E in (0.1, 0.2, 0.3, 0.4):
        t4, t7 = (float(runs[n][E]["period"]) if E in runs[n] else float("nan") for n in (4, 7))
        t = in_plane_period(E, "lib-plane-%g" % E)
        check(abs(t4 - t) <= 1e-9 and abs(t7 - t) <= 1e-9,
              "E = %g: branch periods %.12g (4 points), %.12g (7) vs in-plane %.12g" % (E, t4, t7, t))


def test_bad_input():
    for scene, args, what in (("models/example7.toml", ["--param", "energy=0.1:0.2"], "energy is not conserved"),
                              ("models/example1.toml", ["--param", "energy=0.1"], "KEY=START:STOP"),
                              ("models/example1.toml", [], "KEY=START:STOP"),
                              ("models/example1.toml", ["--param", "nosuch.key=1:2"], "nosuch"),
                              ("models/example1.toml", ["--param", "energy=0.1:0.2", "--max-points", "1"], "max-points")):
        p = swim("continue", scene, "--out", os.path.join(TMP, "bad"), *args)
        check(p.returncode == 2 and what in p.stderr.strip().splitlines()[-1] if p.stderr.strip() else False,
              "%s %s: exit 2 naming it: %d %r" % (scene, args, p.returncode, p.stderr))


sys.exit(swimtest.main(globals(), "test_continue"))
