#!/usr/bin/env python3
"""Scene-specialized vs generic kernels on every paper scene, and against the code before the
model was written once.

Per scene: size of the specialized system, emitted C lines, ns per RHS evaluation (from
build/tests/bench/bench_rhs, medians of 7) and the whole `swim run` wall time (median of
BENCH_RUNS = 5 runs of each kind, run alternately). The same bench_rhs of the revision
BENCH_BASE_REV (default fc2b691: hand-written generic RHS with LAPACK, specialized RHS from C
text in the generator) is built once into build/bench/base/ from `git archive` and run side by
side (BENCH_BASE_REV= skips it). Writes build/bench/scenes.csv and prints two tables."""

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


BASE_REV = os.environ.get("BENCH_BASE_REV", "fc2b691")


def base_bench_rhs():
    """build/bench/base/build/tests/bench/bench_rhs of BASE_REV, built on first use; or None."""
    if not BASE_REV:
        return None
    base = os.path.join(ROOT, "build", "bench", "base")
    prog = os.path.join(base, "build", "tests", "bench", "bench_rhs")
    if not os.path.exists(prog):
        os.makedirs(base, exist_ok=True)
        try:
            arch = subprocess.run(["git", "-C", ROOT, "archive", BASE_REV], check=True, capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", base], input=arch, check=True)
            print("building %s (the code before) in %s ..." % (BASE_REV, base), flush=True)
            subprocess.run(["nice", "make", "-s", "-C", base, "bin/swim", "build/tests/bench/bench_rhs"],
                           check=True, capture_output=True)
        except (subprocess.CalledProcessError, OSError) as exc:
            print("(no comparison with %s: %s)" % (BASE_REV, exc))
            return None
    return base, prog


def bench_rhs(prog, paths, cwd, env=None):
    out = subprocess.run([prog] + paths, check=True, capture_output=True, text=True, cwd=cwd, env=env).stdout
    return {r["scene"]: r for r in csv.DictReader(io.StringIO(out))}


def main():
    paths = ["models/%s.toml" % s for s in SCENES]
    rows = bench_rhs(os.path.join(ROOT, "build", "tests", "bench", "bench_rhs"), paths, ROOT)
    base = base_bench_rhs()
    if base:
        env = dict(os.environ, SWIM_CACHE=os.path.join(ROOT, "build", "bench", "base-cache"))
        old = bench_rhs(base[1], paths, base[0], env)
        print("ns per RHS evaluation, %s (before) vs now (medians of 7, initial state):" % BASE_REV)
        print("%-14s %6s %12s %12s %12s %12s %9s" % ("scene", "n_free", "generic then", "generic now",
                                                   "spec then", "spec now", "spec t/n"))
        for name, path in zip(SCENES, paths):
            o, r = old[path], rows[path]
            print("%-14s %6s %12.0f %12.0f %12.0f %12.0f %8.2fx" % (
                name, r["n_free"], float(o["ns_generic"]), float(r["ns_generic"]),
                float(o["ns_specialized"]), float(r["ns_specialized"]),
                float(o["ns_specialized"]) / float(r["ns_specialized"])))
            rows[path]["ns_generic_before"] = o["ns_generic"]
            rows[path]["ns_specialized_before"] = o["ns_specialized"]
        print()
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
                        run_ratio=round(wg / ws, 2),
                        ns_rhs_generic_before=r.get("ns_generic_before", ""),
                        ns_rhs_specialized_before=r.get("ns_specialized_before", "")))
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
