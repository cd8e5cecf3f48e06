#!/usr/bin/env python3
"""End-to-end tests of `swim run` on the paper's scenes, through the command line.

Physics checks re-derive nothing: they test the invariants the paper states (energy (4.14),
(4.16), (5.3); constraints (2.8), (2.14); zero total impulse (3.19); the particular solution
(4.17); the symmetry of ERRATA D7) and the event times of Fig. 4.8 (ERRATA E2).
Prints "test_scenes: P passed, F failed".
"""

import json
import os
import re
import signal
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main


def run(scene, *args, name=None):
    return swimtest.run(scene, name or os.path.basename(scene).replace(".toml", ""), *args)


def scene_path(name):
    return os.path.join("models", name + ".toml")


def test_conservative():
    for name in ["example1", "example2a", "example2b", "example2c", "example3", "example4", "example6"]:
        p, d, s = run(scene_path(name), "--t-end", "10")
        check(p.returncode == 0 and s["status"] == "completed", "%s: run completed (%s)" % (name, p.stderr.strip()))
        e = d["energy"]
        drift = np.max(np.abs(e - e[0])) / abs(e[0])
        # rtol 1e-10 in these scenes; the global error of a 10-time-unit run is a few hundred rtol.
        check(drift <= 1e-7, "%s: relative energy drift %.3g > 1e-7" % (name, drift))
        imp = [d["impulse_body_" + a] + d["impulse_fluid_rigid_" + a] + d["impulse_fluid_shape_" + a]
               for a in ("x", "y", "ang")]
        check(max(np.max(np.abs(i)) for i in imp) <= 1e-12, "%s: total impulse not zero (3.19)" % name)
        check(np.max(np.abs(d["res_volume"])) <= 1e-7, "%s: volume drift %.3g" % (name, np.max(np.abs(d["res_volume"]))))
        check(np.max(np.abs(d["res_angular"])) <= 1e-9, "%s: angular constraint residual" % name)
        check(np.max(d["res_locks"]) <= 1e-12, "%s: locks moved by %.3g" % (name, np.max(d["res_locks"])))


def test_energy_tolerance():
    """The energy error shrinks with the tolerance (it is integration error, not a model error)."""
    drifts = []
    for rtol in ("1e-7", "1e-10"):
        p, d, s = run(scene_path("example3"), "--t-end", "10", "--rtol", rtol, "--atol=1e-14", name="ex3_" + rtol)
        drifts.append(s["energy_drift_rel"])
    check(drifts[1] < drifts[0] / 30, "example3: energy drift %.3g at rtol 1e-10 not << %.3g at 1e-7" % (drifts[1], drifts[0]))


def test_example1_form():
    p, d, s = run(scene_path("example1"))
    check(np.max(np.abs(d["bm1"])) <= 1e-14 and np.max(np.abs(d["am2"])) <= 1e-14, "example1: b-1, a-2 left 0 (4.17)")
    g2 = d["am1"] ** 2 + 2 * d["bm2"] ** 2
    check(np.max(np.abs(g2 - 0.25)) <= 1e-8, "example1: |a-1|^2 + 2|b-2|^2 not constant: %.3g" % np.max(np.abs(g2 - 0.25)))
    check(np.max(np.abs(d["x"])) <= 1e-14 and np.max(np.abs(d["theta"])) <= 1e-14, "example1: moved off the y-axis")
    check(d["y"][-1] > 1.0, "example1: betadot0 < 0 moves toward +y (ERRATA C4): y(T) = %.3g" % d["y"][-1])


def test_example3_events():
    p, d, s = run(scene_path("example3"), "--t-end", "10")
    check(np.max(np.abs(d["x"])) <= 1e-14, "example3: x not identically 0")
    t = d["t"]

    def event(col, lo, hi, sign):
        m = (t > lo) & (t < hi)
        i = np.argmax(sign * d[col][m])
        tt, ff = t[m][i - 1:i + 2], sign * d[col][m][i - 1:i + 2]
        a, b, _ = np.polyfit(tt - tt[1], ff, 2)   # parabola through the three rows around the extremum
        return tt[1] - b / (2 * a)

    ev = [event("kinetic_rigid", 2.5, 3.6, 1), event("potential", 3.5, 4.5, -1),
          event("kinetic_rigid", 5.8, 6.5, -1), event("potential", 9.0, 9.9, 1)]
    for got, want in zip(ev, [3.17, 3.95, 6.07, 9.50]):
        check(abs(got - want) <= 0.01, "example3: Fig. 4.8 event at %.3f, paper %.2f" % (got, want))
    check(d["y"][-1] > 0.5, "example3: no net displacement along y")


def test_damped_forced():
    p, d, s = run(scene_path("example7"), "--t-end", "5")
    check(p.returncode == 0, "example7 ran: " + p.stderr.strip())
    check("projected" in p.stderr, "example7: the projection of dc0 is reported")
    de = np.diff(d["energy"])
    check(np.max(de) <= 1e-8 * d["energy"][0], "example7: damped energy increased by %.3g (4.16)" % np.max(de))
    check(np.min(d["jmin"]) > 0, "example7: min J > 0 with the barrier")
    bal = d["energy"] - d["energy"][0] - d["work"]
    check(np.max(np.abs(bal)) <= 1e-6, "example7: energy balance %.3g" % np.max(np.abs(bal)))
    p, d, s = run(scene_path("selfpropelled"), "--t-end", "20")
    bal = d["energy"] - d["energy"][0] - d["work"]
    check(np.max(np.abs(bal)) <= 1e-6, "selfpropelled: energy balance (5.3) %.3g" % np.max(np.abs(bal)))
    check(d["work"][-1] > 0.01, "selfpropelled: forcing did no work")
    check(d["y"][-1] > 0.1 and np.max(np.abs(d["x"])) <= 1e-9, "selfpropelled: no swimming along y")


def test_output_grid_and_options():
    p, d, s = run(scene_path("example3"), "--t-end=1.03", "--rtol=1e-9", "--integrator", "rk8pd", name="grid")
    t = d["t"]
    check(len(t) == 22, "grid: %d rows for t_end 1.03, step 0.05 (want 22)" % len(t))
    check(np.all(t[:-1] == np.arange(21) * 0.05), "grid: rows not at k*dt")
    check(t[-1] == 1.03, "grid: last row not at t_end")
    check(s["integrator"] == "rk8pd" and s["rtol"] == 1e-9, "grid: options not applied")
    for key in ("steps", "rhs_evaluations", "rejected_steps", "rhs_seconds", "wall_seconds"):
        check(key in s["stats"], "summary stats lack " + key)


def test_interrupt():
    out = os.path.join(TMP, "interrupted")
    proc = subprocess.Popen([SWIM, "run", scene_path("example4"), "--out", out, "--t-end", "100000",
                             "--quiet"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    swimtest.wait_rows(proc, out)   # integrating: its SIGINT handler is in place
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=30)
    with open(os.path.join(out, "summary.json")) as fh:
        s = json.load(fh)
    d = np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)
    check(proc.returncode == 1, "SIGINT: exit status %d, want 1" % proc.returncode)
    check(s["status"] == "failed" and "interrupted" in s["reason"], "SIGINT: summary says " + s["reason"])
    check(len(d) == s["rows"] and len(d) > 10, "SIGINT: rows kept (%d)" % len(d))


def test_inspect():
    """swim inspect: JSON keys and sizes, both option forms, lists starting with a minus sign."""
    shape = "-1,0,0.2,0.1,0,-0.05"
    for args in (["--modes", "2", "--shape", shape, "--velocity", "0,0,0.3,-0.1,0.2,0"],
                 ["--modes=2", "--shape=" + shape, "--velocity=0,0,0.3,-0.1,0.2,0"]):
        p = subprocess.run([SWIM, "inspect", *args, "--full", "--rho0", "2"], capture_output=True, text=True)
        check(p.returncode == 0, "inspect %s: exit %d %s" % (args, p.returncode, p.stderr))
        j = json.loads(p.stdout)
        n = 6
        check(np.shape(j["mass_rigid"]) == (3, 3) and np.shape(j["mass_coupling"]) == (3, n)
              and np.shape(j["mass_shape"]) == (n, n) and np.shape(j["mass_reduced"]) == (n, n),
              "inspect: matrix sizes")
        check(len(j["christoffel_vv"]) == n and np.shape(j["christoffel"]) == (n, n, n), "inspect: Christoffel sizes")
        G, v = np.array(j["christoffel"]), np.array([0, 0, 0.3, -0.1, 0.2, 0])
        check(np.allclose(np.einsum("ijl,j,l->i", G, v, v), j["christoffel_vv"], rtol=1e-12, atol=1e-14),
              "inspect: contracted Christoffel = tensor contracted with v, v")
        check(j["rho0"] == 2 and j["rhof"] == 1, "inspect: densities")
    for args, expect in [(["--modes", "2", "--shape", "1,0,0.2"], "needs 6 coordinates"),
                         (["--modes", "1", "--shape", "1,0,1.2,0"], "outside the admissible set D"),
                         (["--modes", "2", "--shape", "1,0,0,0,0.6,0"], "outside the admissible set D"),
                         (["--modes", "33", "--shape", "1,0"], "out of range"),
                         (["--modes", "2"], "required"),
                         (["--modes", "1", "--shape", "1,0,0,0", "--rhof", "-1"], "density must be > 0"),
                         (["--modes", "1", "--shape", "1,0,x,0"], "not a finite number"),
                         (["--modes", "1", "--shape", "1,0,0,0", "--bogus"], "unknown option")]:
        p = subprocess.run([SWIM, "inspect", *args], capture_output=True, text=True)
        check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and expect in p.stderr,
              "inspect %s: want exit 2 and %r, got %d %r" % (args, expect, p.returncode, p.stderr))


BASE = open(os.path.join(ROOT, "models", "example3.toml")).read()

# (what, how to change example3.toml, expected message part)
BAD = [
    ("unknown top-level key", lambda s: s + "\nspeed = 3\n", "speed: unknown key"),
    ("unknown key in table", lambda s: s.replace("rho0 = 1.0", "rho0 = 1.0\nrho1 = 2"), "model.rho1: unknown key"),
    ("modes not an integer", lambda s: s.replace("modes = 7", "modes = 7.5"), "model.modes: expected an integer"),
    ("modes out of range", lambda s: s.replace("modes = 7", "modes = 99"), "out of range"),
    ("negative density", lambda s: s.replace("rho0 = 1.0", "rho0 = -1"), "model.rho0: density must be > 0"),
    ("rhof word", lambda s: s.replace("rhof = 1.0", 'rhof = "heavy"'), "model.rhof: expected a number or \"neutral\""),
    ("missing rhof", lambda s: s.replace("rhof = 1.0\n", ""), "model.rhof: missing"),
    ("c0 too short", lambda s: s.replace("c0  = [ 1, 0, 0.4, 0,", "c0  = [ 1, 0, 0.4,"), "shape.c0: expected 16 numbers"),
    ("c0 string item", lambda s: s.replace("c0  = [ 1,", 'c0  = [ "1",'), "shape.c0: item 1 is a string"),
    ("c0 nan", lambda s: s.replace("c0  = [ 1,", "c0  = [ nan,"), "not a finite number"),
    ("c0 outside D", lambda s: s.replace("c0  = [ 1, 0, 0.4,", "c0  = [ 0, 0, 0.4,"), "outside the admissible set D"),
    ("dc0 violates G1", lambda s: s.replace("dc0 = [ 0, 0, 0.6,", "dc0 = [ 0, 0, 0.7,"), "violates the volume constraint G1"),
    ("dc0 moves a lock", lambda s: s.replace("dc0 = [ 0, 0, 0.6, 0,  0, -0.6, 0,", "dc0 = [ 0, 0, 0.6, 0,  0, -0.6, 0.1,"), "the lock of am3"),
    ("unknown free name", lambda s: s.replace('"am1", "bm1"', '"am1", "zz9"'), "unknown coordinate \"zz9\""),
    ("free twice", lambda s: s.replace('"am1", "bm1"', '"am1", "am1"'), "listed twice"),
    ("free wrong type", lambda s: s.replace('free = ["am1", "bm1", "am2", "bm2"]', "free = 4"), "shape.free: expected \"all\" or an array"),
    ("negative stiffness", lambda s: s.replace("stiffness = [ 0, 0, 1,", "stiffness = [ 0, 0, -1,"), "R must be >= 0"),
    ("t_end zero", lambda s: s.replace("t_end = 30.0", "t_end = 0"), "run.t_end: must be > 0"),
    ("negative rtol", lambda s: s.replace("rtol = 1e-10", "rtol = -1e-10"), "run.rtol: must be > 0"),
    ("unknown integrator", lambda s: s.replace("atol = 1e-12", 'atol = 1e-12\nintegrator = "euler"'), "unknown integrator \"euler\""),
    ("missing table", lambda s: s.replace("[run]", "[running]"), "running: unknown key"),
    ("truncated file", lambda s: s[: s.index("dc0")] + "dc0 = [ 0, 0,", "unterminated array"),
    ("duplicate key", lambda s: s.replace("rho0 = 1.0", "rho0 = 1.0\nrho0 = 2.0"), "duplicate key"),
    ("bad forcing law", lambda s: s + '\n[forcing]\nlaw = "sin(t"\ndirection = [0,0,1,0,0,1,0,0,0,0,0,0,0,0,0,0]\n', "forcing.law"),
    ("negative damping", lambda s: s + "\n[damping]\ndiagonal = [0,0,-1,0,0,0,0,0,0,0,0,0,0,0,0,0]\n", "D must be >= 0"),
    ("huge N", lambda s: s.replace("modes = 7", "modes = 100000000000"), "out of range 0..32"),
    ("N above the largest", lambda s: s.replace("modes = 7", "modes = 33"), "33 is out of range 0..32"),
    ("negative fluid density", lambda s: s.replace("rhof = 1.0", "rhof = -2"), "model.rhof: density must be > 0"),
    ("stiffness too short", lambda s: s.replace("stiffness = [ 0, 0, 1,", "stiffness = [ 0, 1,"), "elastic.stiffness: expected 16 numbers"),
    ("dc0 inf", lambda s: s.replace("dc0 = [ 0,", "dc0 = [ inf,"), "shape.dc0: item 1 (inf) is not a finite number"),
    ("t_end not a number", lambda s: s.replace("t_end = 30.0", 't_end = "long"'), "run.t_end: expected a number, got a string"),
    ("output step nan", lambda s: s.replace("output_step = 0.05", "output_step = nan"), "run.output_step: value nan is not a finite number"),
    ("too many rows", lambda s: s.replace("output_step = 0.05", "output_step = 1e-9"), "gives more than 10^7 rows"),
    ("no free coordinate", lambda s: s.replace('free = ["am1", "bm1", "am2", "bm2"]', "free = []"), "no free coordinate"),
    ("table is a value", lambda s: "elastic = 3\n" + s[:s.index("[elastic]")] + s[s.index("[run]"):], "elastic: expected a table"),
    ("forcing without direction", lambda s: s + '\n[forcing]\nlaw = "sin(t)"\n', "forcing.direction: missing"),
    ("barrier alpha zero", lambda s: s + "\n[barrier]\nepsilon = 0.03\nalpha = 0\n", "barrier.alpha: must be > 0"),
    ("bad stiff fallback", lambda s: s.replace("atol = 1e-12", 'atol = 1e-12\nstiff_fallback = "bdf9"'), "unknown integrator \"bdf9\""),
    ("projection not bool", lambda s: s.replace("atol = 1e-12", "atol = 1e-12\nprojection = 1"), "run.projection: expected true or false"),
    ("step_lookahead out of range", lambda s: s.replace("atol = 1e-12", "atol = 1e-12\nstep_lookahead = 13"), "run.step_lookahead: expected an integer 0..12"),
    ("step_lookahead not integer", lambda s: s.replace("atol = 1e-12", "atol = 1e-12\nstep_lookahead = 2.5"), "run.step_lookahead: expected an integer 0..12"),
    ("impact_depth negative", lambda s: s.replace("atol = 1e-12", "atol = 1e-12\nimpact_depth = -1e-16"), "run.impact_depth: value -1e-16 must be in [0, 1)"),
    ("impact_depth not a number", lambda s: s.replace("atol = 1e-12", "atol = 1e-12\nimpact_depth = \"deep\""), "run.impact_depth: expected a number"),
    ("empty file", lambda s: "", "[model]: missing table"),
    ("binary garbage", lambda s: "\x01\x02\xff\xfe" * 10, "invalid UTF-8"),
]


def test_bad_scenes():
    folder = os.path.join(TMP, "bad")
    os.makedirs(folder, exist_ok=True)
    for i, (what, change, expect) in enumerate(BAD):
        path = os.path.join(folder, "bad%02d.toml" % i)
        with open(path, "w", encoding="latin-1") as fh:
            fh.write(change(BASE))
        p = subprocess.run([SWIM, "run", path, "--out", os.path.join(TMP, "badout")], capture_output=True, text=True)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2, "%s: exit status %d, want 2" % (what, p.returncode))
        check(len(lines) == 1 and path in lines[0] and re.search(r":\d+:", lines[0]) is not None,
              "%s: want one line naming the file and line, got %r" % (what, p.stderr))
        check(expect in p.stderr, "%s: message %r lacks %r" % (what, p.stderr.strip(), expect))
    p = subprocess.run([SWIM, "run", "models/example3.toml", "--rtol", "abc"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "--rtol" in p.stderr, "bad --rtol value")
    p = subprocess.run([SWIM, "run", "models/example3.toml", "--step-lookahead", "-1"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "--step-lookahead" in p.stderr and len(p.stderr.strip().splitlines()) == 1,
          "bad --step-lookahead value: " + p.stderr)
    p = subprocess.run([SWIM, "run", "models/example3.toml", "--out", "/proc/forbidden"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "--out" in p.stderr, "unwritable output folder: " + p.stderr)
    p = subprocess.run([SWIM, "run", "models/none.toml"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "cannot open" in p.stderr, "missing scene file")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_scenes"))
