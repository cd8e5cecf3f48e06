#!/usr/bin/env python3
"""swim run --sensitivity with the exact variational equations, against whole runs.

The sensitivities are integrated with the scene kernel's exact Jacobian and exact parameter
partials (kernel/swim_kernel.h, jacobian_params). For Example 3, Example 7 (damping, barrier,
all 16 coordinates free) and a forced scene (Example 3 with A sin(w t) along a_-1, b_-2), the full
final state's derivative (x, y, theta, the carried coordinates and velocities, as sensitivity.csv's
last row writes them) is compared with the Richardson extrapolation of three central differences
of whole `swim run`s (steps h, h/2, h/4: error O(h^6)) at rtol 1e-12, atol 1e-14:
    max |exact - Q| <= 1e-8 max |Q|,
where the extrapolation's error estimate |Q - Q'| (Q' from the two finer steps alone, so this
overestimates Q's error) must not exceed that bound, or the comparison would say nothing. Keys: a stiffness, the body density (through the
mass matrices), an initial shape coordinate and velocity (--sensitivity-initial), the barrier's
epsilon, a damping coefficient, a forcing law's two [parameters] and a forcing direction. Also:
every key is reported exact in summary.json, --sensitivity-method differences agrees to its own
~1e-7, and --sensitivity-initial adds one column per free coordinate and velocity.
Prints "test_sensitivity_exact: P passed, F failed".
"""

import csv
import json
import os
import subprocess
import sys

import numpy as np

from swimtest import ROOT, SWIM, TMP, check, main

TIGHT = ["--set", "run.rtol=1e-12", "--set", "run.atol=1e-14"]


def scene(name, base, t_end, extra=""):
    text = open(os.path.join(ROOT, "models", base)).read()
    lines = [l for l in text.splitlines() if not l.startswith("t_end") and not l.startswith("project_initial")]
    text = "\n".join(lines).replace("[run]", "[run]\nt_end = %r\nproject_initial = true" % t_end) + "\n" + extra
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


FORCING = ("\n[parameters]\nA = 0.3\nw = 1.3\n\n[forcing]\nlaw = \"A * sin(w * t)\"\n"
           "direction = [ 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 ]\n")

# scene -> (file, t_end, extra text, {sensitivity key: (--set key, value)})
CASES = {
    "example3": ("example3.toml", 3.0, "", {
        "elastic.stiffness.am1": ("elastic.stiffness.am1", 1.0),
        "model.rho0": ("model.rho0", 1.0),
        "c0.am1": ("shape.c0.am1", 0.4),
        "dc0.bm2": ("shape.dc0.bm2", -0.6)}),
    "example7": ("example7.toml", 1.5, "", {
        "model.rho0": ("model.rho0", 1.0),
        "barrier.epsilon": ("barrier.epsilon", 0.03),
        "damping.diagonal.bm2": ("damping.diagonal.bm2", 0.2)}),
    "forced3": ("example3.toml", 3.0, FORCING, {
        "parameters.A": ("parameters.A", 0.3),
        "parameters.w": ("parameters.w", 1.3),
        "forcing.direction.bm2": ("forcing.direction.bm2", 1.0),
        "model.rhof": ("model.rhof", 1.0)}),
}


def final_state(path, sets, tag):
    out = os.path.join(TMP, "run_" + tag)
    cmd = [SWIM, "run", path, "--out", out, "--quiet", "--summary-only"] + TIGHT
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    f = json.load(open(os.path.join(out, "summary.json")))["final_state"]
    return f


def state_vector(f, names):
    """x, y, theta and the carried coordinates' values and velocities, by trajectory column name."""
    coord = dict(zip(COORDS, f["c"]))
    vel = dict(zip(COORDS, f["dc"]))
    out = [f["x"], f["y"], f["theta"]]
    for n in names:
        out.append(vel[n[1:]] if n.startswith("d") and n[1:] in vel and n not in coord else coord[n])
    return np.array(out)


COORDS = ["a1", "b1"] + [p % m for m in range(1, 8) for p in ("am%d", "bm%d")]


def sensitivity_run(path, keys, method, tag, initial=False):
    out = os.path.join(TMP, "sens_" + tag)
    cmd = [SWIM, "run", path, "--out", out, "--quiet", "--sensitivity", ",".join(keys),
           "--sensitivity-method", method] + TIGHT
    if initial:
        cmd.append("--sensitivity-initial")
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    with open(os.path.join(out, "sensitivity.csv")) as fh:
        rows = list(csv.reader(fh))
    summary = json.load(open(os.path.join(out, "summary.json")))
    return rows[0], [float(v) for v in rows[-1]], summary


def columns(header, last, key):
    """The exact derivative of the state vector from sensitivity.csv's last row, and the carried
    coordinates' names (trajectory.csv's columns: am1, ..., dam1, ...)."""
    want = ["dx/d" + key, "dy/d" + key, "dtheta/d" + key]
    names = []
    suffix = "/d" + key
    for h in header:
        if h.endswith(suffix) and h[:-len(suffix)] not in ("dx", "dy", "dtheta", "denergy", "dwork"):
            names.append(h[1:-len(suffix)])
            want.append(h)
    return np.array([last[header.index(w)] for w in want]), names


def richardson(path, set_key, value, names, tag):
    h = 1e-2 * max(abs(value), 1e-2)
    D = []
    for lev in range(3):
        hh = h / 2 ** lev
        fp = state_vector(final_state(path, ["%s=%r" % (set_key, value + hh)], tag + "p"), names)
        fm = state_vector(final_state(path, ["%s=%r" % (set_key, value - hh)], tag + "m"), names)
        D.append((fp - fm) / (2 * hh))
    ra, rb = (4 * D[1] - D[0]) / 3, (4 * D[2] - D[1]) / 3
    return (16 * rb - ra) / 15, rb


def test_exact_against_whole_runs():
    for name, (base, t_end, extra, keys) in CASES.items():
        path = scene(name, base, t_end, extra)
        header, last, summary = sensitivity_run(path, list(keys), "exact", name)
        sm = summary["sensitivity"]
        check(sm["status"] == "written" and sm["method"] == "exact" and sm["jacobians"] > 0,
              "%s: every key exact, %d Jacobians (%s)" % (name, sm["jacobians"], sm))
        _, dlast, dsummary = sensitivity_run(path, list(keys), "differences", name + "_d")
        check(dsummary["sensitivity"]["method"] == "differences" and dsummary["sensitivity"]["jacobians"] == 0,
              "%s: --sensitivity-method differences takes no Jacobian" % name)
        for key, (set_key, value) in keys.items():
            exact, names = columns(header, last, key)
            diff, _ = columns(header, dlast, key)
            Q, Q1 = richardson(path, set_key, value, names, name + key)
            scale = np.max(np.abs(Q))
            err = np.max(np.abs(exact - Q)) / scale
            qerr = np.max(np.abs(Q1 - Q)) / scale
            check(scale > 1e-3, "%s %s: the derivative is not trivially zero (%.3g)" % (name, key, scale))
            check(qerr <= 1e-8, "%s %s: the whole-run extrapolation is good to %.2g (its coarser level's error: "
                  "the bound 1e-8 needs it no larger)"
                  % (name, key, qerr))
            check(err <= 1e-8, "%s %s: exact sensitivities of the %d state components agree with whole runs "
                  "to %.2g relative (bound 1e-8)" % (name, key, len(exact), err))
            derr = np.max(np.abs(diff - exact)) / scale
            check(derr <= 1e-6, "%s %s: the difference method agrees with the exact one to %.2g" % (name, key, derr))
            print("  %-9s %-22s exact vs whole runs %.1e (extrapolation %.1e); differences vs exact %.1e"
                  % (name, key, err, qerr, derr))


def test_initial_columns():
    path = scene("initial3", "example3.toml", 1.0)
    header, last, summary = sensitivity_run(path, ["model.rho0"], "exact", "initial", initial=True)
    keys = sorted({h.split("/d", 1)[1] for h in header[1:]})
    want = sorted(["model.rho0"] + ["%s.%s" % (t, c) for t in ("c0", "dc0") for c in ("am1", "bm1", "am2", "bm2")])
    check(keys == want, "--sensitivity-initial adds c0.NAME and dc0.NAME of every free coordinate (%s)" % keys)
    per_key = 5 + 2 * 4
    check(len(header) == 1 + per_key * len(want), "5 + 2 x 4 columns per key (%d)" % len(header))
    first = dict(zip(header, [float(v) for v in open(os.path.join(TMP, "sens_initial", "sensitivity.csv"))
                                   .read().splitlines()[1].split(",")]))
    check(first["dam2/dc0.am2"] == 1.0 and first["dam1/dc0.am2"] == 0.0,
          "the initial column of c0.am2 is the unit vector (%r)" % first["dam2/dc0.am2"])


def test_after_origin_shifts():
    """A run that approaches the barrier shifts the integrator's origin and clock (driver/run.c);
    the sensitivity pass after it starts from t = 0 in absolute state and time. Section 5.2 at
    A = 2.25, w = 0.55 (two shifts by T = 30): x stays 0 by symmetry, so dx/dA must too, and dy/dA
    agrees with central differences of whole runs. (Before the fix the pass integrated from the
    last origin at the shifted time: dx/dA = -2642, dy/dA = 11468.)"""
    scene = os.path.join(ROOT, "models", "control", "selfpropelled_params.toml")
    sets = ["--set", "parameters.A=2.25", "--set", "parameters.w=0.55"]
    out = os.path.join(TMP, "shifted")
    p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet", "--summary-only", "--sensitivity", "parameters.A"]
                       + sets, capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "the run with sensitivities completes (%s)" % p.stderr.strip()[-200:])
    if p.returncode != 0:
        return
    summary = json.load(open(os.path.join(out, "summary.json")))
    check(summary["origin_shift"]["restarts"] >= 1, "the run shifted its origin (%s)" % summary["origin_shift"])
    with open(os.path.join(out, "sensitivity.csv")) as fh:
        last = list(csv.DictReader(fh))[-1]
    ys = []
    for a in (2.2499, 2.2501):
        o = os.path.join(TMP, "shifted_%r" % a)
        subprocess.run([SWIM, "run", scene, "--out", o, "--quiet", "--summary-only", "--set", "parameters.A=%r" % a,
                        "--set", "parameters.w=0.55"], capture_output=True, text=True, cwd=ROOT)
        ys.append(json.load(open(os.path.join(o, "summary.json")))["final_state"]["y"])
    fd = (ys[1] - ys[0]) / 2e-4
    dxa, dya = float(last["dx/dparameters.A"]), float(last["dy/dparameters.A"])
    check(abs(dxa) < 1e-6, "dx/dA = %.3g: zero, as x is" % dxa)
    check(abs(dya - fd) <= 1e-2 * abs(fd), "dy/dA = %.6g against whole runs' %.6g" % (dya, fd))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_sensitivity_exact"))
