#!/usr/bin/env python3
"""Cost of the checks `swim run` makes at every accepted step (min J located between steps,
crossing of J = 0, energy balance, residuals; runtime/cli/run_watch.c), against the cost of the
right-hand side, both measured inside the same run (summary.json: step_checks.seconds,
stats.rhs_seconds), so a busy machine slows both alike. Medians of BENCH_RUNS = 7 runs per scene.
Writes build/bench/step_checks.csv and prints a table."""

import csv
import json
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = ["example3", "example5", "example7", "selfpropelled"]
RUNS = int(os.environ.get("BENCH_RUNS", "7"))


def one(scene, out):
    subprocess.run([os.path.join(ROOT, "bin", "swim"), "run", "models/%s.toml" % scene, "--out", out, "--quiet"],
                   check=True, capture_output=True, cwd=ROOT)
    with open(os.path.join(out, "summary.json")) as fh:
        return json.load(fh)


def main():
    rows = []
    with tempfile.TemporaryDirectory(prefix="swim-bench-") as tmp:
        for scene in SCENES:
            ratio, per_step, per_rhs = [], [], []
            for r in range(RUNS):
                s = one(scene, os.path.join(tmp, scene))
                st, sc = s["stats"], s["step_checks"]
                ratio.append(100.0 * sc["seconds"] / st["rhs_seconds"])
                per_step.append(1e6 * sc["seconds"] / max(1, sc["steps"]))
                per_rhs.append(1e6 * st["rhs_seconds"] / max(1, st["rhs_evaluations"]))
            rows.append({"scene": scene, "steps": sc["steps"], "rhs_evaluations": st["rhs_evaluations"],
                         "us_per_step_checks": statistics.median(per_step), "us_per_rhs": statistics.median(per_rhs),
                         "checks_percent_of_rhs": statistics.median(ratio)})
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "step_checks.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("checks at every accepted step vs the right-hand side (medians of %d runs)" % RUNS)
    print("%-14s %7s %8s %14s %10s %14s" % ("scene", "steps", "RHS", "us/step check", "us/RHS", "% of RHS time"))
    for r in rows:
        print("%-14s %7d %8d %14.2f %10.2f %13.1f%%" % (r["scene"], r["steps"], r["rhs_evaluations"],
                                                        r["us_per_step_checks"], r["us_per_rhs"],
                                                        r["checks_percent_of_rhs"]))


if __name__ == "__main__":
    main()
