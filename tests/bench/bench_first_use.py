#!/usr/bin/env python3
"""First use of a new structure at large N, against the straight-line generator it replaced.

For each N (BENCH_FIRST_USE_MODES, default "10 20 32"): `swim run` of a scene with every one of
its 2(N+1) coordinates free (models/hard/soft_n20_a05.toml with its vectors padded or cut to
2(N+1), t_end 0.001) on an empty kernel cache, which generates and compiles two kernels (the
kernel of N modes and the scene kernel). Printed per N and per generator:
  first use   wall seconds of that `swim run` (median of BENCH_FIRST_USE_REPS, default 3, for
              this tree; of BENCH_FIRST_USE_BASE_REPS, default 1, for the base: minutes each);
  gen, cc     the seconds `swim` reports for generating and compiling both kernels (medians);
  gen MB, cc MB   peak resident memory of the generator and of the compiler (the larger of the
              two kernels; each rerun alone from the cache entry's input under wait4);
  .so kB      size of both compiled kernels;
  profile     the generator of the kernel of N modes alone, in-process: seconds of import,
              of SymPy's cse, of printing, and of the rest (deriving, building expressions);
  ns/RHS      the scene's right-hand side, specialized and --generic kernels
              (build/tests/bench/bench_rhs at the initial state, median of 5 runs of its
              median of 7, BENCH_FIRST_USE_RHS_RUNS; the runs alternate between the two
              generators' kernels so both see the same load), and the same for Example 7
              (N = 7: code identical in both, a check of the noise).
The base is the generator of BENCH_FIRST_USE_BASE (default 96c5de6, the last straight-line
generator), taken by `git archive`, with this tree's runtime/kernel/ (whose entry points bin/swim
loads), used through SWIM_SHARE; the cache key hashes generator/, so the two never share a kernel. Writes build/bench/first_use.csv
and prints a table with the load average before and after.
"""

import csv
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
BENCH_RHS = os.path.join(ROOT, "build", "tests", "bench", "bench_rhs")
OUT = os.path.join(ROOT, "build", "bench", "first_use")
MODES = [int(m) for m in os.environ.get("BENCH_FIRST_USE_MODES", "10 20 32").split()]
REPS = int(os.environ.get("BENCH_FIRST_USE_REPS", "3"))
BASE_REPS = int(os.environ.get("BENCH_FIRST_USE_BASE_REPS", "1"))
BASE = os.environ.get("BENCH_FIRST_USE_BASE", "96c5de6")
RHS_RUNS = int(os.environ.get("BENCH_FIRST_USE_RHS_RUNS", "5"))
PYTHON = os.environ.get("SWIM_PYTHON", "/usr/bin/python3")
CC = os.environ.get("SWIM_CC", "cc")
# the compiler's flags for each kind of kernel (runtime/codegen/codegen.c: SWIM_KERNEL_CFLAGS,
# SWIM_KERNEL_CFLAGS_N and the fixed ones)
CFLAGS = {"modes": ["-O3", "-march=native", "-O1"], "scene": ["-O3", "-march=native"]}
TIMES = re.compile(r"generated in ([0-9.]+) s, compiled in ([0-9.]+) s")


def scene(N):
    """models/hard/soft_n20_a05.toml at N modes, every coordinate free."""
    text = open(os.path.join(ROOT, "models", "hard", "soft_n20_a05.toml")).read()
    n = 2 * (N + 1)

    def fit(m):
        vals = [v.strip() for v in m.group(2).split(",")]
        if m.group(1).startswith("stiffness"):   # R_k = 1/|k| as in the scene
            vals += ["%.6g" % (1.0 / (k // 2)) for k in range(len(vals), n)]
        vals = (vals + ["0"] * n)[:n]
        return "%s[ %s ]" % (m.group(1), ", ".join(vals))

    text = re.sub(r"(?m)^((?:c0|dc0|stiffness|reference)\s*=\s*)\[(.*)\]", fit, text)
    text = re.sub(r"(?m)^modes = \d+", "modes = %d" % N, text)
    path = os.path.join(OUT, "soft_n%d.toml" % N)
    with open(path, "w") as fh:
        fh.write(text)
    return path


def fresh_cache(name):
    path = os.path.join(OUT, "cache-" + name)
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path, mode=0o700)
    return path


def measured(args, **kw):
    """(seconds, peak RSS in MB) of one child process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kw)
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise RuntimeError("%s failed" % " ".join(args[:3]))
    return time.perf_counter() - t0, ru.ru_maxrss / 1024.0


def memory(cache, share, N):
    """Peak RSS of the generator and of the compiler (MB) and kernel sizes (kB) of a cache."""
    gen_mb = cc_mb = so_kb = 0.0
    tmp = os.path.join(OUT, "rerun")
    os.makedirs(tmp, exist_ok=True)
    for entry in sorted(os.listdir(cache)):
        d = os.path.join(cache, entry)
        if not os.path.exists(os.path.join(d, "kernel.so")):
            continue
        so_kb += os.path.getsize(os.path.join(d, "kernel.so")) / 1024.0
        structure = os.path.join(d, "structure.json")   # only scene kernels have one
        kind = "scene" if os.path.exists(structure) else "modes"
        gen = [PYTHON, os.path.join(share, "generator", "generate.py")]
        if kind == "scene":
            gen += ["--scene", structure, "--out", os.path.join(tmp, "k.c"), "--quiet"]
        else:
            gen += ["--modes", str(N), "--out", tmp, "--quiet"]
        gen_mb = max(gen_mb, measured(gen)[1])
        cc = [CC] + CFLAGS[kind] + ["-std=c11", "-shared", "-fPIC", "-I", os.path.join(share, "runtime"),
                                    "-o", os.path.join(tmp, "k.so"), os.path.join(d, "kernel.c"), "-lm"]
        cc_mb = max(cc_mb, measured(cc)[1])
    return gen_mb, cc_mb, so_kb


PROFILE = r"""
import sys, time
sys.path.insert(0, sys.argv[1])
t0 = time.perf_counter()
import sympy as sp
from swimgen import emit
t1 = time.perf_counter()
spent = {"cse": 0.0, "print": 0.0}
def emit_assignments(assignments, printer, indent="    ", tmp="t"):
    if not assignments:
        return []
    a = time.perf_counter()
    temps, reduced = sp.cse([e for _, e in assignments], symbols=sp.numbered_symbols(tmp),
                            optimizations=None)
    b = time.perf_counter()
    lines = ["%sconst double %s = %s;" % (indent, s.name, printer.doprint(e)) for s, e in temps]
    lines += ["%s%s = %s;" % (indent, lhs, printer.doprint(e)) for (lhs, _), e in zip(assignments, reduced)]
    spent["cse"] += b - a
    spent["print"] += time.perf_counter() - b
    return lines
emit.emit_assignments = emit_assignments
emit.kernel_source(int(sys.argv[2]), "profile")
t2 = time.perf_counter()
print(t1 - t0, spent["cse"], spent["print"], t2 - t1 - spent["cse"] - spent["print"])
"""


def profile(share, N):
    """Where the generator of the kernel of N modes spends its time: (import, SymPy's cse,
    printing, the rest: deriving and building the expressions), seconds, one run in-process
    (emit_assignments, cprint.py's one cse-and-print, timed around its two halves)."""
    p = subprocess.run([PYTHON, "-c", PROFILE, os.path.join(share, "generator"), str(N)],
                       capture_output=True, text=True, check=True)
    return [float(v) for v in p.stdout.split()]


def rhs(path, env):
    """One run of bench_rhs: (ns specialized, ns generic), each its median of 7."""
    p = subprocess.run([BENCH_RHS, path], capture_output=True, text=True, env=env, check=True)
    row = p.stdout.strip().splitlines()[-1].split(",")
    return float(row[6]), float(row[5])


def rhs_side_by_side(path, envs, runs=RHS_RUNS):
    """The RHS of the scene at path under each environment (one per generator), bench_rhs runs
    alternating between them so that both see the same load: per environment, the medians of
    `runs` runs of (ns specialized, ns generic)."""
    got = [([], []) for _ in envs]
    for _ in range(runs):
        for (spec, gen), env in zip(got, envs):
            s, g = rhs(path, env)
            spec.append(s)
            gen.append(g)
    return [(statistics.median(spec), statistics.median(gen)) for spec, gen in got]


def first_use(N, name, share, reps):
    """First use at N modes with the generator in `share`: the row (its ns per RHS measured
    later, side by side) and the environment whose cache holds its kernels."""
    path = scene(N)
    walls, gens, ccs = [], [], []
    env = dict(os.environ)
    if share != ROOT:
        env["SWIM_SHARE"] = share
    for _ in range(max(reps, 1)):
        env["SWIM_CACHE"] = cache = fresh_cache(name)
        t0 = time.perf_counter()
        p = subprocess.run([SWIM, "run", path, "--out", os.path.join(OUT, "run-" + name),
                            "--set", "run.t_end=0.001"], capture_output=True, text=True,
                           env=env, cwd=ROOT)
        walls.append(time.perf_counter() - t0)
        if p.returncode != 0:
            raise RuntimeError("swim run %s (%s): %s" % (path, name, p.stderr[-400:]))
        found = TIMES.findall(p.stderr)
        gens.append(sum(float(g) for g, _ in found))
        ccs.append(sum(float(c) for _, c in found))
    gen_mb, cc_mb, so_kb = memory(cache, share, N)
    imp, cse, printing, derive = profile(share, N)
    return dict(N=N, version=name, reps=max(reps, 1), first_use_s=statistics.median(walls),
                gen_import_s=imp, gen_cse_s=cse, gen_print_s=printing, gen_derive_s=derive,
                gen_s=statistics.median(gens), cc_s=statistics.median(ccs), gen_mb=gen_mb,
                cc_mb=cc_mb, so_kb=so_kb), path, env


def main():
    os.makedirs(OUT, exist_ok=True)
    base = os.path.join(OUT, "base")
    if not os.path.exists(os.path.join(base, BASE)):
        shutil.rmtree(base, ignore_errors=True)
        os.makedirs(base)
        archive = subprocess.run(["git", "-C", ROOT, "archive", BASE, "generator"],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", base], input=archive, check=True)
        open(os.path.join(base, BASE), "w").close()
    # this tree's runtime/kernel/ beside the base's generator: the kernels bin/swim loads have its
    # entry points (kernel ABI), and the two differ in what the generators print alone
    shutil.rmtree(os.path.join(base, "runtime"), ignore_errors=True)
    shutil.copytree(os.path.join(ROOT, "runtime", "kernel"), os.path.join(base, "runtime", "kernel"))
    load0 = os.getloadavg()[0]
    rows = []
    for N in MODES:
        pair, envs = [], []
        for name, share, reps in (("this tree", ROOT, REPS), ("base " + BASE, base, BASE_REPS)):
            row, path, env = first_use(N, name.split()[0], share, reps)
            row["version"] = name
            pair.append(row)
            envs.append(env)
        for row, (ns_spec, ns_gen) in zip(pair, rhs_side_by_side(path, envs)):
            row.update(ns_rhs=ns_spec, ns_rhs_generic=ns_gen)
        rows += pair
    ex7 = os.path.join(ROOT, "models", "example7.toml")
    ex7_envs = [dict(os.environ, SWIM_CACHE=fresh_cache("example7")),
                dict(os.environ, SWIM_SHARE=base, SWIM_CACHE=fresh_cache("example7-base"))]
    ex7_new, ex7_base = rhs_side_by_side(ex7, ex7_envs)
    load1 = os.getloadavg()[0]
    keys = list(rows[0].keys())
    with open(os.path.join(ROOT, "build", "bench", "first_use.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print("First use of a new structure (every coordinate free), empty cache; load average %.1f -> %.1f"
          " on %d cores" % (load0, load1, os.cpu_count()))
    print("%3s  %-14s %4s %9s %6s %6s %7s %6s %7s %10s %12s" % (
        "N", "generator", "reps", "first s", "gen s", "cc s", "gen MB", "cc MB", ".so kB",
        "ns/RHS", "ns/RHS gen."))
    for r in rows:
        print("%3d  %-14s %4d %9.2f %6.2f %6.2f %7.0f %6.0f %7.0f %10.0f %12.0f" % (
            r["N"], r["version"], r["reps"], r["first_use_s"], r["gen_s"], r["cc_s"], r["gen_mb"],
            r["cc_mb"], r["so_kb"], r["ns_rhs"], r["ns_rhs_generic"]))
    print("Generator of the kernel of N modes alone, one run in-process (s): import, SymPy's cse, "
          "printing, deriving and the rest")
    for r in rows:
        print("%3d  %-14s %6.2f %6.2f %6.2f %6.2f" % (r["N"], r["version"], r["gen_import_s"],
                                                    r["gen_cse_s"], r["gen_print_s"], r["gen_derive_s"]))
    print("Example 7 (N = 7, the same code in both): ns/RHS %.0f (generic %.0f) this tree, "
          "%.0f (%.0f) base" % (ex7_new + ex7_base))
    print("(first s: median wall of `swim run`, both kernels generated and compiled; gen s, cc s: "
          "what swim reports, medians; MB: peak RSS; ns/RHS: median of %d bench_rhs runs alternating "
          "between the generators; written to build/bench/first_use.csv)" % RHS_RUNS)
    return 0


if __name__ == "__main__":
    sys.exit(main())
