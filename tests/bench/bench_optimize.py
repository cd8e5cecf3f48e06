#!/usr/bin/env python3
"""Nelder-Mead against BFGS (exact gradients) on the Section 5.2 problems, with multi-start and
the tolerance check.

Usage (from the repository root; `make bench-optimize`, ~30 min on 2 cores: problem 3's Nelder-Mead alone ~26 min):
    /usr/bin/python3 tests/bench/bench_optimize.py [--out DIR] [--quick]

Problems (models/control/selfpropelled_params.toml, T = 30, rtol 1e-8):
  1. maximize y over w in [0.2, 0.45] at A = 2 (one local maximum in the range);
  2. maximize y over A in [1, 3], w in [0.2, 0.45] (the optimum docs/control.md quoted);
  3. maximize displacement over the whole box A in [0.5, 4], w in [0.1, 1], 4 starts, at most 30
     iterations per start: the region of large displacement near w ~ 0.7-0.85, where the runs
     graze the boundary of D (min J 1e-13 and below) and the value does not hold at rtol/100.
For each, both methods: the best value and point, iterations of the best start, runs, gradient
runs, wall time (optimize.json), and the tight check (value at rtol/100, change, holds).
Each search runs once (they are deterministic; the times are single measurements, on a quiet
machine within ~10 %). Writes DIR/optimize.csv and DIR/table.md (default build/bench/optimize).
--quick: problems 1 and 2 only."""

import argparse
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
SCENE = os.path.join("models", "control", "selfpropelled_params.toml")

PROBLEMS = [
    ("1: y over w (A = 2)", ["--set", "parameters.A=2", "--vary", "parameters.w=0.2:0.45", "--maximize", "y"]),
    ("2: y over A, w", ["--vary", "parameters.A=1:3", "--vary", "parameters.w=0.2:0.45", "--maximize", "y"]),
    ("3: displacement, whole box, 4 starts", ["--vary", "parameters.A=0.5:4", "--vary", "parameters.w=0.1:1",
                                              "--maximize", "displacement", "--starts", "4", "--max-iter", "30"]),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "optimize"))
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    rows = []
    for name, extra in PROBLEMS[:2] if args.quick else PROBLEMS:
        for method in ("nelder-mead", "bfgs"):
            out = os.path.join(args.out, "run_%s_%s" % (name.split(":")[0], method))
            p = subprocess.run([SWIM, "optimize", SCENE, "--out", out, "--quiet", "--method", method] + extra,
                               cwd=ROOT, env=env, capture_output=True, text=True)
            path = os.path.join(out, "optimize.json")
            if not os.path.exists(path):
                sys.exit("bench_optimize: %s %s failed (%d): %s" % (name, method, p.returncode, p.stderr.strip()))
            d = json.load(open(path))
            tc = d["tight_check"]
            rows.append({"problem": name, "method": method, "value": d["value"],
                         "point": " ".join("%s=%.5g" % (k.split(".")[-1], v) for k, v in d["best"].items()),
                         "iterations": d["iterations"], "runs": d["evaluations"], "gradient_runs": d["gradient_evaluations"],
                         "seconds": d["seconds"], "tight_value": tc["value"], "tight_change": tc["change"],
                         "holds": tc["holds"], "converged": d["converged"], "best_start": d["best_start"]})
            print("%-40s %-12s %s" % (name, method, rows[-1]), flush=True)
    with open(os.path.join(args.out, "optimize.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = ["| problem | method | best value | at | iterations (best start) | runs (with gradient) | time | "
             "at rtol/100 | converged |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        tight = "%.10g (%+.2g, %s)" % (r["tight_value"], r["tight_change"], "holds" if r["holds"] else "does not hold") \
            if r["tight_value"] is not None else "run failed"
        lines.append("| %s | %s | %.10g | %s | %d | %d (%d) | %.1f s | %s | %s |" % (
            r["problem"], r["method"], r["value"], r["point"], r["iterations"], r["runs"], r["gradient_runs"],
            r["seconds"], tight, "yes" if r["converged"] else "no"))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(text)
    print(text, end="")


if __name__ == "__main__":
    main()
