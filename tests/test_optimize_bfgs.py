#!/usr/bin/env python3
"""swim optimize --method bfgs (gradients from the exact sensitivities), --starts and the
tolerance check.

1. Known optimum (Example 3 is conservative: E(T) = E(0), smallest at cref = c0): BFGS finds
   c0's 0.4 over elastic.reference.am1 in fewer runs than Nelder-Mead, and (0.4, 0.2) in 2-d.
2. Section 5.2 at A = 2 over w in [0.1, 0.6] has two local maxima of y (w ~ 0.31 and ~ 0.57):
   from the middle Nelder-Mead climbs to the lower one; --starts 3 finds the higher one, and
   BFGS from the middle reaches it too.
3. The tolerance check: at rtol 1e-3 the optimum's value moves at rtol 1e-5 by more than a value
   tolerance of 1e-7: optimize.json says it does not hold, converged is false, exit 1.
4. Bad input: --method bfgs for a quantity without a gradient, a key without a sensitivity or a
   prescribed stroke; an unknown method; --starts out of range: one line, exit 2, nothing written.
Prints "test_optimize_bfgs: P passed, F failed".
"""

import json
import os
import subprocess
import sys

from swimtest import ROOT, SWIM, TMP, check, check_refusals, main

EX3 = os.path.join("models", "example3.toml")
S52 = os.path.join("models", "control", "selfpropelled_params.toml")


def optimize(scene, name, *args):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "optimize", scene, "--out", out, "--quiet", *args],
                       capture_output=True, text=True, cwd=ROOT)
    path = os.path.join(out, "optimize.json")
    data = json.load(open(path)) if os.path.exists(path) else None
    return p, data


def test_known_optimum():
    runs = {}
    for method in ("bfgs", "nelder-mead"):
        p, d = optimize(EX3, "known_" + method, "--set", "run.t_end=1", "--vary", "elastic.reference.am1=0:1",
                        "--minimize", "energy", "--method", method, "--tol", "1e-6")
        check(p.returncode == 0 and d and d["converged"], "%s converges (%s)" % (method, p.stderr.strip()[-200:]))
        if not d:
            return
        check(abs(d["best"]["elastic.reference.am1"] - 0.4) < 1e-4, "%s: the optimum is c0's 0.4 (%r)"
              % (method, d["best"]["elastic.reference.am1"]))
        check(d["method"] == method and d["tight_check"]["holds"], "%s: optimize.json names the method; the value "
              "holds at rtol/100 (%s)" % (method, d["tight_check"]))
        runs[method] = d["evaluations"]
    check(runs["bfgs"] < runs["nelder-mead"], "BFGS takes fewer runs than Nelder-Mead (%s)" % runs)
    p, d = optimize(EX3, "known_2d", "--set", "run.t_end=1", "--vary", "elastic.reference.am1=0:1",
                    "--vary", "elastic.reference.bm2=-0.5:0.5", "--minimize", "energy", "--method", "bfgs",
                    "--tol", "1e-6")
    check(d is not None and abs(d["best"]["elastic.reference.am1"] - 0.4) < 1e-4
          and abs(d["best"]["elastic.reference.bm2"] - 0.2) < 1e-4 and d["gradient_evaluations"] > 0,
          "BFGS 2-d optimum at (0.4, 0.2) with gradients (%s)" % (d and d["best"]))


def test_two_local_maxima():
    common = ("--set", "parameters.A=2", "--vary", "parameters.w=0.1:0.6", "--maximize", "y")
    p, nm = optimize(S52, "nm1", *common)
    p3, ms = optimize(S52, "nm3", *common, "--starts", "3")
    pb, bf = optimize(S52, "bfgs1", *common, "--method", "bfgs")
    if not (nm and ms and bf):
        check(False, "the three searches ran (%s %s %s)" % (p.stderr[-200:], p3.stderr[-200:], pb.stderr[-200:]))
        return
    check(abs(nm["best"]["parameters.w"] - 0.567) < 0.01 and abs(nm["value"] - 0.9162) < 1e-3,
          "Nelder-Mead from the middle: the lower maximum, y = %.6g at w = %.6g" % (nm["value"], nm["best"]["parameters.w"]))
    check(len(ms["starts"]) == 3 and abs(ms["best"]["parameters.w"] - 0.3096) < 1e-3 and abs(ms["value"] - 1.08570) < 1e-4
          and ms["best_start"] != 1, "--starts 3: the higher maximum, y = %.6g at w = %.6g (start %d)"
          % (ms["value"], ms["best"]["parameters.w"], ms["best_start"]))
    ws = [s["start"]["parameters.w"] for s in ms["starts"]]
    check(abs(ws[0] - 0.35) < 1e-12 and len(set(ws)) == 3 and all(0.1 < w < 0.6 for w in ws),
          "the starts: the middle, then distinct points of the box (%s)" % ws)
    check(abs(bf["best"]["parameters.w"] - 0.3096) < 1e-3 and bf["converged"] and bf["evaluations"] < nm["evaluations"],
          "BFGS from the middle: y = %.6g at w = %.6g in %d runs (Nelder-Mead: %d)"
          % (bf["value"], bf["best"]["parameters.w"], bf["evaluations"], nm["evaluations"]))


def test_tolerance_check():
    p, d = optimize(EX3, "loose", "--set", "run.t_end=3", "--set", "run.rtol=1e-3", "--set", "run.atol=1e-5",
                    "--vary", "elastic.reference.am1=0:1", "--maximize", "y", "--tol", "1e-7", "--max-iter", "200")
    check(d is not None, "the loose search writes optimize.json (%s)" % p.stderr[-200:])
    if not d:
        return
    tc = d["tight_check"]
    check(tc["status"] == "completed" and abs(tc["change"]) > tc["value_tolerance"] and not tc["holds"],
          "at rtol 1e-5 the value moves by %.3g > %.3g: it does not hold" % (tc["change"], tc["value_tolerance"]))
    check(not d["converged"] and p.returncode == 1 and "does not hold" in p.stdout,
          "not called converged: exit 1, said (%d %r)" % (p.returncode, p.stdout[-300:]))


def test_bad_arguments():
    cases = [(S52, ["--vary", "parameters.A=0.5:4", "--maximize", "displacement_per_work", "--method", "bfgs"],
              "no gradient"),
             (EX3, ["--vary", "run.t_end=1:2", "--maximize", "y", "--method", "bfgs"], "swim optimize: --vary: run.t_end"),
             (os.path.join("models", "control", "stroke_phase.toml"),
              ["--vary", "parameters.phi=-0.5:1.2", "--minimize", "y", "--method", "bfgs"], "prescribed stroke"),
             (EX3, ["--vary", "elastic.reference.am1=0:1", "--minimize", "energy", "--method", "newton"], "--method"),
             (EX3, ["--vary", "elastic.reference.am1=0:1", "--minimize", "energy", "--starts", "0"], "--starts")]
    check_refusals("optimize", cases)

if __name__ == "__main__":
    sys.exit(main(globals(), "test_optimize_bfgs"))
