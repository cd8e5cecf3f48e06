"""swim continue: branches of periodic orbits. Example 1 has no potential energy, so its equations
are invariant under a rescaling of time (c(t; s v) = c(s t; v)): along its family by energy the
period times sqrt(E) and the displacement per period are constants, to 1e-9 (test); the symmetry
of its parametrization is found (a multiplier at 1 whose generator M fixes) and held by a phase
condition, so the branch does not turn the swimmer. A branch in a run-time key passes through the
scene's own orbit (the point at the scene's value equals swim periodic's). Bad input: one line,
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
