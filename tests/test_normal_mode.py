#!/usr/bin/env python3
"""Example 3's family of periodic orbits by energy as E -> 0: the linearized normal mode.

Scene: tests/scenes/example3_libration.toml, Example 3 displaced from its equilibrium c_ref along
b_-2 and at rest, on the volume of c_ref (so c_ref is an equilibrium there). The normal modes of
the elastic potential on the constraint manifold are computed here, independently of swim's
shooting and continuation: K(c_ref) from `swim inspect` (the reduced mass matrix, itself checked
against the closed forms of tests/reference by test_reference), R = diag(stiffness), the
tangent space T = null(G1, G2) at c_ref from the paper's rows (2.8) and (2.14), and
omega^2 the eigenvalues of K_T^-1 R_T. `swim continue --param energy=...` follows the libration
family down to E = 1e-6; its period is T(E) = T0 + O(E), and the extrapolation of two points to
E = 0 must be 2 pi / omega of the b_-2 mode to 1e-6 relative, with |T(E) - T0| shrinking in
proportion to E. Also: the librations do not swim (dy per period 0), are stable at small E;
Example 3's own orbit (round the ellipse) has the period of the continued branch and keeps dy.
Prints "test_normal_mode: P passed, F failed".
"""

import csv
import json
import math
import os
import subprocess
import sys

import numpy as np

from swimtest import ROOT, SWIM, TMP, check, main

SCENE = os.path.join(ROOT, "tests", "scenes", "example3_libration.toml")
N = 7
FREE = [2, 3, 4, 5]                  # am1, bm1, am2, bm2 in c = (a1, b1, a-1, b-1, ...)
STIFFNESS = {2: 1.0, 3: 1.0, 4: 2.0, 5: 2.0}
C_REF = [1.0, 0.0, 0.4899] + [0.0] * (2 * (N + 1) - 3)


def mode_number(i):
    return 1 if i < 2 else -(i // 2)


def constraint_rows(c):
    """G1 = grad sum_k k |c_k|^2 (2.8) and G2 (2.14): a_k -> b_k / (|k| + 1), b_k -> -a_k / (|k| + 1),
    on the free coordinates."""
    g1 = [2 * mode_number(i) * c[i] for i in FREE]
    g2 = [(c[i + 1] if i % 2 == 0 else -c[i - 1]) / (abs(mode_number(i)) + 1) for i in FREE]
    return np.array([g1, g2])


def normal_modes():
    p = subprocess.run([SWIM, "inspect", "--modes", str(N), "--shape", ",".join(repr(x) for x in C_REF)],
                       capture_output=True, text=True, cwd=ROOT)
    K = np.array(json.loads(p.stdout)["mass_reduced"]).reshape(2 * (N + 1), 2 * (N + 1))[np.ix_(FREE, FREE)]
    R = np.diag([STIFFNESS[i] for i in FREE])
    _, s, vt = np.linalg.svd(constraint_rows(C_REF))
    T = vt[np.sum(s > 1e-12):].T                      # orthonormal basis of null(G1, G2)
    w2, vec = np.linalg.eig(np.linalg.solve(T.T @ K @ T, T.T @ R @ T))
    return w2.real, T @ vec.real


def branch(out, spec, points, scene=SCENE, section="bm2:max"):
    p = subprocess.run([SWIM, "continue", scene, "--guess-event", section, "--param", "energy=" + spec,
                        "--max-points", str(points), "--out", out, "--quiet"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "swim continue energy=%s: %s" % (spec, p.stderr.strip()[-300:]))
    with open(os.path.join(out, "branch.csv")) as fh:
        return [{k: (v if k == "stable" else float(v)) for k, v in r.items()} for r in csv.DictReader(fh)]


def test_period_tends_to_the_normal_mode():
    w2, vec = normal_modes()
    check(len(w2) == 2 and np.all(w2 > 0), "two normal modes on the 2-dimensional tangent space (%s)" % w2)
    k = int(np.argmax(np.abs(vec[FREE.index(5)])))     # the b_-2 mode: the scene's displacement
    T0 = 2 * math.pi / math.sqrt(w2[k])
    rows = branch(os.path.join(TMP, "small"), "1e-6:1e-4", 3)
    if len(rows) < 3:
        return
    E = np.array([r["energy"] for r in rows])
    T = np.array([r["period"] for r in rows])
    slope = (T[1] - T[0]) / (E[1] - E[0])
    extrapolated = T[0] - slope * E[0]
    check(abs(extrapolated - T0) <= 1e-6 * T0, "T(E -> 0) = %.10f is 2 pi / omega = %.10f of the b_-2 mode "
          "(omega^2 = %.8f) to 1e-6" % (extrapolated, T0, w2[k]))
    err = np.abs(T - T0)
    check(err[0] < err[1] < err[2] and 0.5 < (err[2] / err[0]) / (E[2] / E[0]) < 2.0,
          "|T(E) - T0| shrinks in proportion to E (%s at E = %s)" % (err, E))
    check(all(abs(r["dy"]) < 1e-12 for r in rows), "librations do not swim: dy per period 0")
    check(all(r["stable"] == "yes" for r in rows), "small librations are linearly stable")


def test_rotations_round_the_ellipse():
    """Above E* = 2 (0.4899)^2 = max W1 on the ellipse the orbits go round it: Example 3's own
    family, whose dy per period does not depend on E."""
    rows = branch(os.path.join(TMP, "rot"), "0.75:2", 3, os.path.join(ROOT, "models", "example3.toml"), "am1:max")
    dys = [r["dy"] for r in rows]
    check(len(rows) == 3 and max(dys) - min(dys) < 1e-9 and abs(dys[0] - 0.4905016591) < 1e-9,
          "rotations: dy per period 0.4905016591 at every energy (%s)" % dys)
    lib = branch(os.path.join(TMP, "lib"), "0.3:0.45", 2)
    check(all(r["period"] > 2 * math.pi / 0.93 for r in lib) and all(abs(r["dy"]) < 1e-10 for r in lib),
          "librations below E* = 0.48 have longer periods and no net displacement (%s)"
          % [(r["energy"], r["period"]) for r in lib])


def test_special_point_refined():
    """The librations lose stability near E = 0.1895: a real pair leaves the unit circle at +1
    (a branch point of the symmetric orbits: the pair is the directions' across the mirror plane,
    and the special point says so). Between the points 0.15, 0.2, 0.25 of a coarse
    branch it is bracketed, then bisected to 2^-24 of the bracket."""
    out = os.path.join(TMP, "special")
    rows = branch(out, "0.15:0.25", 3)
    d = json.load(open(os.path.join(out, "branch.json")))
    sp = d["special_points"]
    check(len(sp) == 1 and "branch point of orbits leaving the invariant subspace" in sp[0]["kind"] and sp[0]["refined"],
          "one special point, refined: %s" % [(s["kind"], s["between"]) for s in sp])
    if len(sp) != 1:
        return
    lo, hi = sp[0]["between"]
    check(0.15 < lo < hi < 0.25 and hi - lo <= 0.05 / 2 ** 23, "bracket [%.12g, %.12g] narrowed by 2^-24" % (lo, hi))
    lam = [complex(*m) for m in sp[0]["at"]["multipliers"]]
    # one real multiplier just outside the circle; the one the orbit keeps at 1 (1 to ~1e-11, on
    # either side as the monodromy's rounding falls) has not left it
    real_out = [z for z in lam if z.imag == 0 and 1 + 1e-9 < abs(z) < 1 + 1e-3]
    check(len(real_out) == 1, "at the bracket's outer end a real multiplier has just left the circle at +1 (%s)" % lam)
    check([r["stable"] for r in rows] == ["yes", "no", "no"], "stable below it, not above (%s)"
          % [r["stable"] for r in rows])
    p = subprocess.run([SWIM, "plot", out], capture_output=True, text=True, cwd=ROOT)
    figs = [os.path.join(out, f) for f in ("bifurcation.png", "multipliers.png")]
    check(p.returncode == 0 and all(os.path.getsize(f) > 10000 for f in figs if os.path.exists(f))
          and all(os.path.exists(f) for f in figs), "swim plot of a branch: the bifurcation diagram and the "
          "multipliers (%s)" % p.stderr.strip()[-200:])
    p = subprocess.run([SWIM, "plot", out, "--mark", "1"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "branch" in p.stderr, "swim plot of a branch takes no options (exit 2, said)")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_normal_mode"))
