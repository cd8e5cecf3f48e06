#!/usr/bin/env python3
"""Scene-specialized vs generic kernels on every paper scene (issue 5 benchmark).

Per scene: size of the specialized system, emitted C lines, ns per RHS evaluation (from
build/tests/bench/bench_rhs, medians of 7) and the whole `swim run` wall time (median of 5 runs of
each kind, run alternately). Writes build/bench/scenes.csv and prints a table."""

import csv
import io
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = ["example1", "example2a", "example2b", "example2c", "example3", "example4", "example5",
          "example6", "example7", "selfpropelled"]
RUNS = int(os.environ.get("BENCH_RUNS", "5"))


def wall(scene, generic, out):
    args = [os.path.join(ROOT, "bin", "swim"), "run", scene, "--out", out, "--quiet"]
    if generic:
        args.append("--generic")
    subprocess.run(args, check=True, capture_output=True, cwd=ROOT)
    with open(os.path.join(out, "summary.json")) as fh:
        s = json.load(fh)
    return s["stats"]["wall_seconds"], s["stats"]["rhs_evaluations"]


def main():
    paths = ["models/%s.toml" % s for s in SCENES]
    rhs = subprocess.run([os.path.join(ROOT, "build", "tests", "bench", "bench_rhs")] + paths,
                         check=True, capture_output=True, text=True, cwd=ROOT).stdout
    rows = {r["scene"]: r for r in csv.DictReader(io.StringIO(rhs))}
    tmp = tempfile.mkdtemp(prefix="swim-bench-")
    out = []
    hdr = "%-14s %6s %7s %7s %9s %9s %7s %9s %9s %7s" % (
        "scene", "n_free", "state", "C lines", "ns gen", "ns spec", "ratio", "run gen", "run spec", "ratio")
    print(hdr)
    for name, path in zip(SCENES, paths):
        g, s = [], []
        for _ in range(RUNS):
            g.append(wall(path, True, os.path.join(tmp, "g"))[0])
            s.append(wall(path, False, os.path.join(tmp, "s"))[0])
        r = rows[path]
        ng, ns = float(r["ns_generic"]), float(r["ns_specialized"])
        wg, ws = statistics.median(g), statistics.median(s)
        out.append(dict(scene=name, n_free=r["n_free"], state_generic=r["state_generic"],
                        state_specialized=r["state_specialized"], c_lines=r["c_lines"],
                        ns_rhs_generic=ng, ns_rhs_specialized=ns, rhs_ratio=round(ng / ns, 1),
                        run_s_generic=round(wg, 4), run_s_specialized=round(ws, 4),
                        run_ratio=round(wg / ws, 2)))
        print("%-14s %6s %3s->%-3s %7s %9.0f %9.0f %6.1fx %8.3fs %8.3fs %6.2fx" % (
            name, r["n_free"], r["state_generic"], r["state_specialized"], r["c_lines"], ng, ns,
            ng / ns, wg, ws, wg / ws))
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "scenes.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(out[0]))
        w.writeheader()
        w.writerows(out)
    print("(ns: medians of 7 repetitions at the initial state; run: median wall time of %d runs "
          "of swim run each, output included; build/bench/scenes.csv)" % RUNS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
