#!/usr/bin/env python3
"""swim optimize on problems with a known optimum, its bounds, best.toml and bad input.

Known optimum: Example 3 is conservative, so its energy at t_end is its initial energy,
1/2 dc0^T K(c0) dc0 + 1/2 sum R_i (c0_i - cref_i)^2, smallest when the reference shape is c0:
minimizing `energy` over elastic.reference.am1 (and .bm2) must find c0's 0.4 (and 0.2). With
the range [0.45, 0.9] the optimum is on the bound 0.45, and no evaluated value leaves the range.
best.toml run by swim run gives the reported value; convergence.png is drawn. Bad arguments are
one line and exit 2 before any run. Prints "test_optimize: P passed, F failed".
"""

import csv
import json
import os
import subprocess
import sys

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main

EX3 = os.path.join("models", "example3.toml")


def optimize(name, *args):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "optimize", EX3, "--out", out, "--quiet", "--set", "run.t_end=1", *args],
                       capture_output=True, text=True, cwd=ROOT)
    data = None
    if p.returncode == 0:
        with open(os.path.join(out, "optimize.json")) as fh:
            data = json.load(fh)
    return p, out, data


def log_rows(out):
    with open(os.path.join(out, "optimize.csv")) as fh:
        return list(csv.DictReader(fh))


def test_known_optimum_1d_and_reproduction():
    p, out, d = optimize("one", "--vary", "elastic.reference.am1=0:1", "--minimize", "energy")
    check(p.returncode == 0, "optimize runs: %s" % p.stderr)
    if not d:
        return
    best = d["best"]["elastic.reference.am1"]
    check(abs(best - 0.4) < 2e-3, "the reference a_-1 that minimizes the energy is c0's 0.4 (%r)" % best)
    check(d["converged"], "converged")
    rows = log_rows(out)
    q = [float(r["energy"]) for r in rows]
    check(len(rows) == d["iterations"] + 1 and all(b <= a for a, b in zip(q, q[1:])),
          "one log row per iteration, the best value never gets worse")
    check(os.path.getsize(os.path.join(out, "convergence.png")) > 1000, "convergence.png drawn")
    p2, r2, _ = swimtest.run(os.path.join(out, "best.toml"), "best_run")
    check(p2.returncode == 0 and r2 is not None, "best.toml runs: %s" % p2.stderr)
    if r2 is not None:
        check(abs(r2["energy"][-1] - d["value"]) <= 1e-12 * abs(d["value"]),
              "swim run best.toml gives the reported value (%r vs %r)" % (r2["energy"][-1], d["value"]))
    # the analytic optimum: the energy with cref = c0 is the kinetic energy alone
    p3, r3, _ = swimtest.run(EX3, "cref_c0", "--set", "run.t_end=1", "--set", "elastic.reference.am1=0.4")
    if r3 is not None:
        e_opt = r3["energy"][0]
        check(0 <= d["value"] - e_opt < 1e-5, "the minimum is the energy at cref = c0 (%r vs %r)" % (d["value"], e_opt))


def test_prescribed_stroke():
    # a loop am1 = A cos t, bm2 = B sin(t + phi) encloses pi A B cos(phi): the displacement per
    # stroke (a geometric phase, proportional to the area for small loops) is largest at phi = 0
    scene = os.path.join("models", "control", "stroke_phase.toml")
    out = os.path.join(TMP, "stroke_phase")
    p = subprocess.run([SWIM, "optimize", scene, "--out", out, "--quiet", "--vary", "parameters.phi=-0.5:1.2",
                        "--minimize", "y"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "optimize on a prescribed stroke runs: %s" % p.stderr)
    if p.returncode != 0:
        return
    with open(os.path.join(out, "optimize.json")) as fh:
        d = json.load(fh)
    phi = d["best"]["parameters.phi"]
    check(abs(phi) < 2e-3, "the best phase lag is 0 (%r)" % phi)
    p2, r2, s2 = swimtest.run(os.path.join(out, "best.toml"), "stroke_best_run")
    check(p2.returncode == 0 and r2 is not None, "best.toml of a stroke runs: %s" % p2.stderr)
    if r2 is not None:
        check(abs(r2["y"][-1] - d["value"]) <= 1e-9 * abs(d["value"]),
              "swim run best.toml gives the reported y (%r vs %r)" % (r2["y"][-1], d["value"]))
    p3, r3, _ = swimtest.run(scene, "stroke_phase_0.6")
    if r3 is not None:
        check(d["value"] < r3["y"][-1] - 1e-3, "phi = 0 swims farther than the scene's phi = 0.6")
    # displacement per unit of positive work is defined for strokes (no [forcing] needed)
    q = subprocess.run([SWIM, "optimize", scene, "--out", os.path.join(TMP, "stroke_dpw"), "--quiet",
                        "--vary", "parameters.phi=-0.5:1.2", "--maximize", "displacement_per_work",
                        "--max-iter", "3"], capture_output=True, text=True, cwd=ROOT)
    check(q.returncode in (0, 1) and "needs a [forcing]" not in q.stderr,
          "displacement_per_work accepted on a stroke: %s" % q.stderr)


def test_known_optimum_2d():
    p, out, d = optimize("two", "--vary", "elastic.reference.am1=0:1", "--vary", "elastic.reference.bm2=-0.5:0.5",
                         "--minimize", "energy", "--tol", "1e-4")
    check(p.returncode == 0, "2-d optimize runs: %s" % p.stderr)
    if d:
        a, b = d["best"]["elastic.reference.am1"], d["best"]["elastic.reference.bm2"]
        check(abs(a - 0.4) < 2e-3 and abs(b - 0.2) < 2e-3, "2-d optimum at c0's (0.4, 0.2): (%r, %r)" % (a, b))


def test_bounds():
    p, out, d = optimize("bound", "--vary", "elastic.reference.am1=0.45:0.9", "--minimize", "energy")
    check(p.returncode == 0, "bounded optimize runs: %s" % p.stderr)
    if not d:
        return
    best = d["best"]["elastic.reference.am1"]
    check(0.45 <= best < 0.451, "the optimum is on the lower bound 0.45 (%r)" % best)
    vals = [float(r["elastic.reference.am1"]) for r in log_rows(out)]
    check(all(0.45 <= v <= 0.9 for v in vals), "every logged value within [0.45, 0.9]")
    p, out, d = optimize("maxy", "--vary", "elastic.reference.am1=0.45:0.9", "--maximize", "energy")
    check(d is not None and d["best"]["elastic.reference.am1"] > 0.899,
          "maximizing puts it on the upper bound (%r)" % (d and d["best"]))


def test_not_converged_and_interrupted():
    p, out, _ = optimize("short", "--vary", "elastic.reference.am1=0:1", "--minimize", "energy", "--max-iter", "2")
    check(p.returncode == 1 and "NOT converged" in p.stdout, "--max-iter 2: exit 1, says NOT converged (%d %r)"
          % (p.returncode, p.stdout))
    check(os.path.exists(os.path.join(out, "best.toml")), "--max-iter 2: the best so far is still written")
    out = os.path.join(TMP, "sigint")
    proc = subprocess.Popen([SWIM, "optimize", "models/control/selfpropelled_params.toml", "--out", out, "--quiet",
                             "--vary", "parameters.A=0.5:4", "--vary", "parameters.w=0.1:1",
                             "--maximize", "displacement_per_work", "--max-iter", "100000", "--tol", "1e-12",
                             "--set", "run.t_end=10"],   # short runs that go on: the log fills within a second
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    import time
    log = os.path.join(out, "optimize.csv")
    deadline = time.time() + 60
    while time.time() < deadline and not (os.path.exists(log) and len(open(log).read().splitlines()) >= 3):
        time.sleep(0.1)
    proc.send_signal(2)
    so, se = proc.communicate(timeout=60)
    check(proc.returncode == 1 and "INTERRUPTED" in so, "SIGINT: exit 1, says INTERRUPTED (%d %r %r)" % (proc.returncode, so, se))
    try:
        with open(os.path.join(out, "optimize.json")) as fh:
            d = json.load(fh)
        check(d["interrupted"] and not d["converged"], "optimize.json says interrupted")
        check(os.path.exists(os.path.join(out, "best.toml")), "SIGINT: best.toml of the best so far written")
    except (OSError, ValueError) as exc:
        check(False, "SIGINT: optimize.json readable (%r)" % exc)


def test_scene_read_once():
    """The search parses the scene's text read once, however many runs it makes: strace counts
    the opens of the scene file (a copy, so no other program's open is counted)."""
    probe = subprocess.run(["strace", "-f", "-o", os.devnull, "true"], capture_output=True, text=True)
    if probe.returncode != 0:   # no ptrace in this container: nothing to count with
        print("skipped: strace cannot trace here: %s" % probe.stderr.strip())
        return
    scene = os.path.join(TMP, "read_once.toml")
    with open(os.path.join(ROOT, EX3)) as src, open(scene, "w") as dst:
        dst.write(src.read())
    trace, out = os.path.join(TMP, "read_once.strace"), os.path.join(TMP, "read_once")
    p = subprocess.run(["strace", "-f", "-e", "trace=open,openat", "-o", trace, SWIM, "optimize", scene, "--out", out,
                        "--quiet", "--set", "run.t_end=0.5", "--vary", "model.rho0=0.5:2", "--maximize", "x",
                        "--max-iter", "4"], capture_output=True, text=True, cwd=ROOT)
    with open(trace) as fh:
        opens = sum(1 for line in fh if scene in line)
    with open(os.path.join(out, "optimize.json")) as fh:
        runs = json.load(fh)["evaluations"]
    check(p.returncode in (0, 1) and runs >= 5, "the search ran (exit %d, %d runs): %s" % (p.returncode, runs, p.stderr))
    check(opens == 1, "the scene file opened once for %d runs, best.toml included (%d opens)" % (runs, opens))


def test_bad_arguments():
    cases = [(["--vary", "elastic.reference.am1=0:1"], "exactly one of"),
             (["--vary", "elastic.reference.am1=1:0", "--minimize", "energy"], "LO < HI"),
             (["--vary", "elastic.reference.am1", "--minimize", "energy"], "KEY=LO:HI"),
             (["--vary", "elastic.reference.am1=0:1", "--minimize", "speed"], "unknown quantity"),
             (["--vary", "parameters.A=0:1", "--minimize", "energy"], "[parameters]"),
             (["--vary", "elastic.reference.am1=0:1", "--maximize", "displacement_per_work"], "forcing"),
             (["--minimize", "energy"], "--vary")]
    for i, (args, want) in enumerate(cases):
        out = os.path.join(TMP, "bad%d" % i)
        p = subprocess.run([SWIM, "optimize", EX3, "--out", out, "--quiet", *args], capture_output=True, text=True, cwd=ROOT)
        lines = [l for l in p.stderr.splitlines() if l.strip()]
        check(p.returncode == 2 and len(lines) == 1 and want in lines[0], "%s: exit 2, one line with '%s' (%d %r)"
              % (" ".join(args), want, p.returncode, p.stderr))
        check(not os.path.exists(out), "%s: nothing written" % " ".join(args))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_optimize"))
