#!/usr/bin/env python3
"""swim run --sensitivity: forward sensitivities against central differences of whole runs.

Scene: Example 3 forced by A sin(w t) along a_-1 and b_-2 ([parameters] A, w), with
project_initial = true so that a perturbed c0 or dc0 is projected onto the constraints as the
sensitivities' initial columns are. For a parameter, a stiffness, the fluid density, c0.am1,
dc0.bm2 and a locked coordinate's value c0.a1 (a parameter the energy's difference quotient moves in
place: the full state must take it up), d x, d y, d theta, d E and d work at every 10th row are compared with the Richardson
extrapolation of two central differences of whole runs (--set KEY=value +- h, +- h/2). Also:
dE/dp at t = 0 is the exact derivative of the initial energy (0.5 (c0 - cref)^2 for a stiffness);
the run's own trajectory is unchanged by --sensitivity; bad keys are one line and exit 2 before
anything is written. Prints "test_sensitivity: P passed, F failed".
"""

import csv
import os
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main

WHAT = ("x", "y", "theta", "energy", "work")
KEYS = {"parameters.w": 1.3, "parameters.A": 0.3, "elastic.stiffness.am1": 1.0, "model.rhof": 1.0,
        "c0.am1": 0.4, "dc0.bm2": -0.6, "c0.a1": 1.0}
SET_KEY = {"c0.am1": "shape.c0.am1", "dc0.bm2": "shape.dc0.bm2", "c0.a1": "shape.c0.a1"}
T_END = 6.0


def scene():
    text = open(os.path.join(ROOT, "models", "example3.toml")).read()
    text = text.replace("t_end = 30.0", "t_end = %r" % T_END).replace("atol = 1e-12", "atol = 1e-12\nproject_initial = true")
    text += ("\n[parameters]\nA = 0.3\nw = 1.3\n\n[forcing]\nlaw = \"A * sin(w * t)\"\n"
             "direction = [ 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 ]\n")
    path = os.path.join(TMP, "forced3.toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def rows(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


def final(path, key, value, tag):
    out = os.path.join(TMP, "fd_" + tag)
    p = subprocess.run([SWIM, "run", path, "--out", out, "--quiet", "--set", "%s=%r" % (key, value)],
                       capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    r = rows(os.path.join(out, "trajectory.csv"))
    return np.array([[float(x[c]) for c in WHAT] for x in r[::10]])


def test_against_central_differences():
    path = scene()
    out = os.path.join(TMP, "sens")
    p = subprocess.run([SWIM, "run", path, "--out", out, "--quiet", "--sensitivity", ",".join(KEYS)],
                       capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "run with --sensitivity: %s" % p.stderr)
    if p.returncode != 0:
        return
    sens = rows(os.path.join(out, "sensitivity.csv"))
    traj = rows(os.path.join(out, "trajectory.csv"))
    check(len(sens) == len(traj) and all(float(a["t"]) == float(b["t"]) for a, b in zip(sens, traj)),
          "sensitivity.csv has the rows of trajectory.csv")
    p0, r0, _ = swimtest.run(path, "plain")
    check(r0 is not None and open(os.path.join(TMP, "plain", "trajectory.csv")).read()
          == open(os.path.join(out, "trajectory.csv")).read(), "--sensitivity leaves trajectory.csv unchanged")
    for key, base in KEYS.items():
        h = 2e-4 * max(abs(base), 1e-2)
        sk = SET_KEY.get(key, key)
        d1 = (final(path, sk, base + h, "p") - final(path, sk, base - h, "m")) / (2 * h)
        d2 = (final(path, sk, base + h / 2, "p") - final(path, sk, base - h / 2, "m")) / h
        fd = d2 + (d2 - d1) / 3
        sv = np.array([[float(r["d%s/d%s" % (w, key)]) for w in WHAT] for r in sens[::10]])
        err = np.abs(fd - sv)
        tol = 5e-6 + 1e-5 * np.abs(fd)
        worst = np.unravel_index(np.argmax(err / tol), err.shape)
        check(np.all(err <= tol), "%s: sensitivities agree with central differences of runs (worst %s at "
              "row %d: %.3g vs %.3g)" % (key, WHAT[worst[1]], 10 * worst[0], sv[worst], fd[worst]))
        check(np.max(np.abs(sv)) > 1e-3, "%s: the derivative is not trivially zero" % key)
    e0 = float(sens[0]["denergy/delastic.stiffness.am1"])
    check(abs(e0 - 0.5 * (0.4 - 0.4899) ** 2) < 1e-9, "dE/dR at t = 0 is 0.5 (c0 - cref)^2 (%r)" % e0)
    w = [float(r["dwork/dparameters.A"]) for r in sens]
    check(w[0] == 0.0 and abs(w[-1]) > 1e-3, "d work/dA starts at 0 and grows")


def test_state_steps():
    """--sensitivity-steps state: no error test on the sensitivities, the state's steps only."""
    path = scene()
    keys = "parameters.w,c0.am1"
    res = {}
    for mode in ("all", "state"):
        out = os.path.join(TMP, "steps_" + mode)
        p = subprocess.run([SWIM, "run", path, "--out", out, "--sensitivity", keys, "--sensitivity-steps", mode],
                           capture_output=True, text=True, cwd=ROOT)
        check(p.returncode == 0, "--sensitivity-steps %s runs: %s" % (mode, p.stderr))
        line = [l for l in p.stdout.splitlines() if "sensitivities of" in l]
        evals = int(line[0].split(",")[-1].split()[0]) if line else -1
        r = rows(os.path.join(out, "sensitivity.csv"))[-1] if p.returncode == 0 else {}
        res[mode] = (evals, r)
    (ea, ra), (es, rs) = res["all"], res["state"]
    check(0 < es < ea, "state steps need fewer evaluations (%d vs %d)" % (es, ea))
    if ra and rs:
        err = max(abs(float(ra[k]) - float(rs[k])) / (1e-3 + abs(float(ra[k]))) for k in ra if k != "t")
        check(err < 1e-4, "state steps agree with the controlled sensitivities (%.2g)" % err)
    p = subprocess.run([SWIM, "run", path, "--out", os.path.join(TMP, "steps_bad"), "--sensitivity", keys,
                        "--sensitivity-steps", "some"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2 and "--sensitivity-steps" in p.stderr, "a bad --sensitivity-steps is exit 2")


def test_bad_keys():
    path = scene()
    for key, want in (("run.t_end", "not a value the equations read"), ("parameters.Z", "no 'Z'"),
                      ("damping.diagonal.am1", "damping is 0"), ("dc0.a1", "locked"),
                      ("c0.zz", "unknown coordinate"), ("parameters.A,parameters.A", "given twice")):
        out = os.path.join(TMP, "bad_" + key.replace(".", "_").replace(",", "_"))
        p = subprocess.run([SWIM, "run", path, "--out", out, "--quiet", "--sensitivity", key],
                           capture_output=True, text=True, cwd=ROOT)
        lines = [l for l in p.stderr.splitlines() if l.strip() and not l.startswith("swim: ")]
        check(p.returncode == 2 and len(lines) == 1 and "--sensitivity" in lines[0] and want in lines[0],
              "--sensitivity %s: exit 2 with one line saying '%s' (%d: %r)" % (key, want, p.returncode, p.stderr))
        check(not os.path.exists(out), "--sensitivity %s: nothing written" % key)


if __name__ == "__main__":
    sys.exit(main(globals(), "test_sensitivity"))
