#!/usr/bin/env python3
"""BDF with the exact Jacobian against BDF with difference quotients, and what one exact
Jacobian costs.

Usage (from the repository root; `make bench` includes it):
    /usr/bin/python3 tests/bench/bench_jacobian.py [--runs K] [--out DIR] [--modes 7 15 20]

1. models/hard/stiff_n15.toml (N = 15, all 32 coordinates free, stiffness up to 1e4, damping,
   barrier: state dimension 68) with cvode-bdf and with msbdf, `[run] jacobian = "exact"` and
   `"differences"` (swim run --set run.jacobian=...), the two kinds run alternately K times
   (default 3): steps, RHS evaluations, Jacobian evaluations (deterministic: the same in every
   run) and the medians of the run's wall time, of its time in the RHS and of its time in the
   exact Jacobian (summary.json stats), side by side.
2. build/tests/bench/bench_jacobian_cost: ns per RHS and per exact Jacobian, all coordinates
   free with elastic, damping and barrier, N = 7, 15, 20 (medians of 7), and the Jacobian in
   RHS-evaluation units; a Jacobian by differences costs `state` RHS evaluations (CVODE) or
   state + 2 (msbdf).

Writes DIR/jacobian.csv, DIR/cost.csv and DIR/table.md (default build/bench/jacobian) and prints
the tables. Kernels come from $SWIM_CACHE (else build/cache); the first use of N = 20 generates
and compiles its kernels (about a minute)."""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
COST = os.path.join(ROOT, "build", "tests", "bench", "bench_jacobian_cost")
SCENE = os.path.join(ROOT, "models", "hard", "stiff_n15.toml")


def run(integrator, jacobian, out, env):
    cmd = [SWIM, "run", SCENE, "--integrator", integrator, "--set", "run.jacobian=" + jacobian,
           "--out", out, "--summary-only", "--quiet"]
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bench_jacobian: %s failed (%d): %s" % (" ".join(cmd), p.returncode, p.stderr.strip()))
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as fh:
        st = json.load(fh)["stats"]
    if st["jacobian"] != jacobian:
        sys.exit("bench_jacobian: asked for %s, the run used %s" % (jacobian, st["jacobian"]))
    return st


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "jacobian"))
    ap.add_argument("--modes", type=int, nargs="*", default=[7, 15, 20])
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for integrator in ("cvode-bdf", "msbdf"):
            runs = {"exact": [], "differences": []}
            for k in range(args.runs):
                for jac in ("exact", "differences"):
                    runs[jac].append(run(integrator, jac, os.path.join(tmp, "%s-%s-%d" % (integrator, jac, k)), env))
            for jac in ("exact", "differences"):
                r = runs[jac]
                rows.append(dict(integrator=integrator, jacobian=jac, steps=r[0]["steps"],
                                 rhs_evaluations=r[0]["rhs_evaluations"],
                                 jacobian_evaluations=r[0]["jacobian_evaluations"],
                                 wall_s=statistics.median(x["wall_seconds"] for x in r),
                                 rhs_s=statistics.median(x["rhs_seconds"] for x in r),
                                 jacobian_s=statistics.median(x["jacobian_seconds"] for x in r)))
    with open(os.path.join(args.out, "jacobian.csv"), "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    p = subprocess.run([COST] + [str(m) for m in args.modes], cwd=ROOT, env=env, capture_output=True,
                       text=True)
    if p.returncode != 0:
        sys.exit("bench_jacobian: bench_jacobian_cost failed: %s" % p.stderr.strip())
    with open(os.path.join(args.out, "cost.csv"), "w", encoding="utf-8") as fh:
        fh.write(p.stdout)
    cost = list(csv.DictReader(p.stdout.splitlines()))

    lines = ["stiff_n15 (state 68), t = 0..30, rtol 1e-6: medians of %d runs each, run alternately" % args.runs,
             "",
             "| integrator | Jacobian | steps | RHS evaluations | Jacobian evaluations | wall s | RHS s | exact Jacobian s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %s | %d | %d | %d | %.3f | %.3f | %.3f |" % (
            r["integrator"], r["jacobian"], r["steps"], r["rhs_evaluations"], r["jacobian_evaluations"],
            r["wall_s"], r["rhs_s"], r["jacobian_s"]))
    lines += ["", "One exact Jacobian in RHS evaluations (all free, elastic, damping, barrier; medians of 7):", "",
              "| N | state | ns per RHS | ns per Jacobian | Jacobian / RHS | by differences (CVODE) |",
              "|---|---|---|---|---|---|"]
    for c in cost:
        lines.append("| %s | %s | %s | %s | %s | %s |" % (c["N"], c["state"], c["ns_rhs"], c["ns_jacobian"],
                                                        c["jacobian_in_rhs_units"], c["state"]))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "table.md"), "w", encoding="utf-8") as fh:
        fh.write(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
