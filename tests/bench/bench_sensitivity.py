#!/usr/bin/env python3
"""Forward sensitivities: the exact variational equations against the difference method.

Usage (from the repository root; `make bench` includes it):
    /usr/bin/python3 tests/bench/bench_sensitivity.py [--runs K] [--out DIR]

For each case, `swim run --sensitivity KEYS` with `--sensitivity-method exact` (the kernel's exact
Jacobian and parameter partials, one Jacobian per evaluation of the augmented system) and
`--sensitivity-method differences` (two right-hand sides per key and evaluation, the augmented
system at rtol >= 1e-10) are run alternately K times (default 3): the sensitivity pass's wall time
(median, summary.json's sensitivity.seconds), its Jacobians and right-hand sides (deterministic),
the ratio of the medians, and how far the two final rows are apart (relative to the largest
entry). Cases: Example 3 (T = 30) with 3 keys, Example 7 (T = 10) with 3 keys, a forced Example 3
with its 2 law parameters, and Example 3 with --sensitivity-initial (8 initial-value columns,
the monodromy's shape). Writes DIR/sensitivity.csv and DIR/table.md (default
build/bench/sensitivity) and prints the table."""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")

FORCING = ("\n[parameters]\nA = 0.3\nw = 1.3\n\n[forcing]\nlaw = \"A * sin(w * t)\"\n"
           "direction = [ 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 ]\n")


def forced_scene(out):
    path = os.path.join(out, "forced3.toml")
    with open(os.path.join(ROOT, "models", "example3.toml")) as fh, open(path, "w") as o:
        o.write(fh.read() + FORCING)
    return path


def cases(out):
    ex3, ex7 = os.path.join(ROOT, "models", "example3.toml"), os.path.join(ROOT, "models", "example7.toml")
    return [
        ("Example 3, T = 30", ex3, ["--sensitivity", "elastic.stiffness.am1,model.rho0,c0.am1"]),
        ("Example 7, T = 10", ex7, ["--sensitivity", "model.rho0,barrier.epsilon,damping.diagonal.bm2"]),
        ("forced Example 3, T = 30", forced_scene(out), ["--sensitivity", "parameters.A,parameters.w"]),
        ("Example 3, 8 initial values", ex3, ["--sensitivity-initial"]),
    ]


def run(scene, args, method, out, env):
    cmd = [SWIM, "run", scene, "--out", out, "--quiet", "--summary-only", "--sensitivity-method", method] + args
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bench_sensitivity: %s failed (%d): %s" % (" ".join(cmd), p.returncode, p.stderr.strip()))
    with open(os.path.join(out, "summary.json")) as fh:
        sm = json.load(fh)["sensitivity"]
    with open(os.path.join(out, "sensitivity.csv")) as fh:
        last = [float(v) for v in list(csv.reader(fh))[-1][1:]]
    return sm, last


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "sensitivity"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    rows = []
    for name, scene, extra in cases(args.out):
        t = {"exact": [], "differences": []}
        info, last = {}, {}
        for _ in range(args.runs):   # alternately, so that the machine's load is shared
            for method in ("exact", "differences"):
                sm, row = run(scene, extra, method, os.path.join(args.out, "run_" + method), env)
                t[method].append(sm["seconds"])
                info[method], last[method] = sm, row
        scale = max(abs(v) for v in last["exact"]) or 1.0
        apart = max(abs(a - b) for a, b in zip(last["exact"], last["differences"])) / scale
        me, md = statistics.median(t["exact"]), statistics.median(t["differences"])
        rows.append({"case": name, "exact_s": me, "exact_jacobians": info["exact"]["jacobians"],
                     "exact_rhs": info["exact"]["rhs_evaluations"], "differences_s": md,
                     "differences_rhs": info["differences"]["rhs_evaluations"], "ratio": md / me,
                     "apart": apart})
    with open(os.path.join(args.out, "sensitivity.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = ["| case | exact: s (median of %d) | Jacobians (= augmented RHS) | differences: s | RHS | "
             "differences / exact | final rows apart |" % args.runs, "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %.3f | %d | %.3f | %d | %.1f× | %.1e |" % (
            r["case"], r["exact_s"], r["exact_jacobians"], r["differences_s"], r["differences_rhs"],
            r["ratio"], r["apart"]))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "table.md"), "w") as fh:
        fh.write(text)
    print(text, end="")


if __name__ == "__main__":
    main()
