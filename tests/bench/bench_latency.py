#!/usr/bin/env python3
"""First use of a mode count N that is not linked in: generation + compilation of its kernels
on an empty cache, and the overhead of every later use (kernels from the cache).

For each N (BENCH_LATENCY_MODES, default "5 10 15 20 32"), in a fresh temporary cache:
  inspect first   `swim inspect --modes N` wall time (the kernel of N modes: generate + compile;
                  linked in for N <= 7), with the generator and compiler seconds it reports;
  run first       `swim run` of Example 3 with N modes (the added modes locked at 0), cache
                  holding the N kernel already: the scene kernel's generation + compilation;
  later use       median of 5 `swim inspect --modes N` wall times with everything cached (process
                  start and JSON output included), and the cache's own overhead: median of 5
                  fresh processes of build/tests/bench/bench_cache timing swim_codegen_kernel(N)
                  on the warm cache (hash of the generator folder and headers, manifest check
                  with the hash of kernel.so, dlopen).
Writes build/bench/latency.csv and prints a table."""

import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
MODES = [int(m) for m in os.environ.get("BENCH_LATENCY_MODES", "5 10 15 20 32").split()]
TIMES = re.compile(r"generated in ([0-9.]+) s, compiled in ([0-9.]+) s")


def timed(args, env):
    t0 = time.perf_counter()
    cpu0 = os.times()
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT, env=env)
    cpu1 = os.times()
    wall = time.perf_counter() - t0
    cpu = (cpu1.children_user - cpu0.children_user) + (cpu1.children_system - cpu0.children_system)
    if p.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(args[:4]), p.stderr[-300:]))
    gen = comp = 0.0
    for g, c in TIMES.findall(p.stderr):
        gen += float(g)
        comp += float(c)
    return wall, cpu, gen, comp


def scene(N, tmp):
    text = open(os.path.join(ROOT, "models", "example3.toml")).read()
    n = 2 * (N + 1)

    def vec(key, values):
        nonlocal text
        vals = (values + [0] * n)[:n]
        text = re.sub(r"(?m)^%s\s*=\s*\[.*\]" % key, "%s = [%s]" % (key, ", ".join(map(repr, vals))), text)

    text = re.sub(r"(?m)^modes = \d+", "modes = %d" % N, text)
    vec("c0 ", [1, 0, 0.4, 0, 0, 0.2])
    vec("dc0", [0, 0, 0.6, 0, 0, -0.6])
    vec("stiffness", [0, 0, 1, 1, 2, 2])
    vec("reference", [1, 0, 0.4899, 0])
    path = os.path.join(tmp, "ex3_n%d.toml" % N)
    with open(path, "w") as fh:
        fh.write(text)
    return path


def main():
    tmp = tempfile.mkdtemp(prefix="swim-latency-")
    env = dict(os.environ, SWIM_CACHE=os.path.join(tmp, "cache"))
    rows = []
    print("%4s | %10s %8s %8s %8s | %10s %8s %8s | %12s %12s" % (
        "N", "inspect 1st", "cpu", "gen", "cc", "run 1st", "gen", "cc", "later (ms)", "cache (ms)"))
    cache_prog = os.path.join(ROOT, "build", "tests", "bench", "bench_cache")
    for N in MODES:
        sh = ",".join(["1", "0", "0.2", "0.1"] + ["0.0005", "0"] * max(N - 1, 0)) if N >= 1 else "1,0"
        iw, icpu, ig, ic = timed([SWIM, "inspect", "--modes", str(N), "--shape", sh], env)
        sc = scene(N, tmp)
        rw, _, rg, rc = timed([SWIM, "run", sc, "--out", os.path.join(tmp, "out%d" % N), "--t-end", "0.1"], env)
        later = statistics.median(timed([SWIM, "inspect", "--modes", str(N), "--shape", sh], env)[0]
                                  for _ in range(5))
        overhead = statistics.median(
            float(subprocess.run([cache_prog, str(N)], capture_output=True, text=True, env=env,
                                 check=True).stdout.split(",")[1]) for _ in range(5))
        rows.append(dict(N=N, inspect_first_s=round(iw, 2), inspect_cpu_s=round(icpu, 2),
                         kernel_generate_s=round(ig, 2), kernel_compile_s=round(ic, 2),
                         run_first_s=round(rw, 2), scene_generate_s=round(rg, 2),
                         scene_compile_s=round(rc, 2), later_use_ms=round(1e3 * later, 1),
                         cache_overhead_ms=round(overhead, 2)))
        print("%4d | %10.2f %8.2f %8.2f %8.2f | %10.2f %8.2f %8.2f | %12.1f %12.2f" % (
            N, iw, icpu, ig, ic, rw, rg, rc, 1e3 * later, overhead), flush=True)
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "latency.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("(seconds of wall time on this machine; cpu = user + system of the generator and compiler; "
          "later = median of 5 cached `swim inspect` (whole process), cache = the lookup itself; "
          "build/bench/latency.csv)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
