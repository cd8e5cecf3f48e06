#!/usr/bin/env python3
"""The cost of an energy law ([elastic] energy, docs/materials.md): ns per right-hand side of
Example 3 (models/example3.toml, T = 30, rtol 1e-10) with the quadratic W1 alone, with W1 and a
closed-form law (Saint Venant-Kirchhoff, a polynomial in I1 and J) and with W1 and a quadrature
law (compressible neo-Hookean, with ln J); and the first use of each scene kernel (generation +
compilation, in a fresh cache).

For each variant: one run on an empty cache (its summary's generate_seconds and
compile_seconds), then BENCH_MATERIALS_REPEATS (default 5) runs from the cache, whose median
summary stats.ns_per_rhs is reported (the machine is shared: medians, and the ratios to W1).
Writes build/bench/materials.csv and prints a table."""

import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
REPEATS = int(os.environ.get("BENCH_MATERIALS_REPEATS", "5"))
LAWS = [("W1 only", None),
        ("W1 + closed form (SVK)", "lam/8*(I1 - 2)^2 + mu/4*(I1^2 - 2*I1 + 2 - 2*J^2)"),
        ("W1 + quadrature (CNH)", "mu/2*(I1 - 2) - mu*log(J) + lam/2*log(J)^2")]


def scene(tmp, i, law):
    text = open(os.path.join(ROOT, "models", "example3.toml")).read()
    if law:
        text = text.replace("[elastic]\n", '[elastic]\nenergy = "%s"\n' % law)
        text += "\n[parameters]\nmu = 0.3\nlam = 0.5\n"
    path = os.path.join(tmp, "law%d.toml" % i)
    with open(path, "w") as fh:
        fh.write(text)
    return path


def summary(path, out, env):
    p = subprocess.run([SWIM, "run", path, "--out", out, "--quiet"], capture_output=True, text=True,
                       cwd=ROOT, env=env)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-300:])
    with open(os.path.join(out, "summary.json")) as fh:
        return json.load(fh)


def main():
    rows = []
    with tempfile.TemporaryDirectory(prefix="swim-bench-materials-") as tmp:
        env = dict(os.environ, SWIM_CACHE=os.path.join(tmp, "cache"))
        for i, (name, law) in enumerate(LAWS):
            path = scene(tmp, i, law)
            first = summary(path, os.path.join(tmp, "first%d" % i), env)
            ns = [summary(path, os.path.join(tmp, "r%d_%d" % (i, k)), env)["stats"]["ns_per_rhs"]
                  for k in range(REPEATS)]
            rows.append({"variant": name, "law": law or "", "ns_per_rhs": statistics.median(ns),
                         "generate_seconds": first["kernel"]["generate_seconds"],
                         "compile_seconds": first["kernel"]["compile_seconds"]})
    base = rows[0]["ns_per_rhs"]
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "materials.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("%-26s %12s %8s %10s %10s" % ("Example 3", "ns/RHS", "x W1", "generate", "compile"))
    for r in rows:
        print("%-26s %12.0f %8.2f %9.2fs %9.2fs" % (r["variant"], r["ns_per_rhs"], r["ns_per_rhs"] / base,
                                                   r["generate_seconds"], r["compile_seconds"]))
    print("(medians of %d runs each; a shared machine: compare the ratios)" % REPEATS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
