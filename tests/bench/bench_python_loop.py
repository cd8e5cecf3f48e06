#!/usr/bin/env python3
"""A family from Python: a loop of swim.run (libswim in this process) against `swim sweep --jobs 1`
(a forked child per member, each writing its summary.json, members.csv appended) on the same
members, one core each.

The family: Example 3 with model.rho0 = SPEC (BENCH_PY_SPEC, default "0.5:2:200": 200 members,
the values swim sweep computes from that SPEC, swim.spec_values), to t = BENCH_PY_T_END (default
1). Five ways, each BENCH_PY_REPEATS times (default 3), medians reported:
  python loop    for v in values: swim.run(scene, set={"model.rho0": v}, t_end=T)  (rows kept)
  Simulation     one swim.Simulation(scene, t_end=T); for v: sim.set("model.rho0", v); sim.run()
                 (rows kept), and the same with Simulation(..., rows=False)
  swim.sweep     swim.sweep(scene, vary={"model.rho0": SPEC}, t_end=T)  (summaries only)
  ... threads=2  the same on 2 threads
  swim sweep     bin/swim sweep scene --out FRESH_DIR --vary model.rho0=SPEC --t-end T --jobs 1 --quiet
The kernels are cached before timing (one warm-up run). Every member's final y of each way is
checked against members.csv's (the same doubles), so all ran the same family.
Then the threads, each family with threads=1 and threads=2 in turn (the same rows checked): short
members, BENCH_PY_SHORT (default "0.5:2:2000") to t = T_END, and longer ones, where the
integration is most of a member's time, BENCH_PY_LONG (default "0.5:2:20") to t =
BENCH_PY_LONG_T_END (default 300). Run on 2 cores: the threads only gain when the other core is
free, so the load average is printed beside the numbers.
Writes build/bench/python_loop.csv and prints the tables."""
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
os.environ.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
import swim  # noqa: E402

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
SCENE = os.path.join(ROOT, "models", "example3.toml")
SPEC = os.environ.get("BENCH_PY_SPEC", "0.5:2:200")
T_END = float(os.environ.get("BENCH_PY_T_END", "1"))
REPEATS = int(os.environ.get("BENCH_PY_REPEATS", "3"))
KEY = "model.rho0"
SHORT = os.environ.get("BENCH_PY_SHORT", "0.5:2:2000")
LONG = os.environ.get("BENCH_PY_LONG", "0.5:2:20")
LONG_T_END = float(os.environ.get("BENCH_PY_LONG_T_END", "300"))


def python_loop(values):
    return [swim.run(SCENE, set={KEY: v}, t_end=T_END) for v in values]


def python_sweep(values, spec=SPEC, t_end=T_END, threads=1):
    return swim.sweep(SCENE, vary={KEY: spec}, t_end=t_end, threads=threads)


def simulation_set(values, rows=True):
    ys = []
    with swim.Simulation(SCENE, t_end=T_END, rows=rows) as sim:
        for v in values:
            sim.set(KEY, v)
            ys.append(sim.run().final_state["y"])
    return ys


def cli_sweep(tmp, k):
    out = os.path.join(tmp, "sweep%d" % k)   # a fresh folder: an old one would be resumed, not run
    p = subprocess.run([SWIM, "sweep", SCENE, "--out", out, "--vary", "%s=%s" % (KEY, SPEC), "--t-end", repr(T_END),
                        "--jobs", "1", "--quiet"], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("swim sweep: " + p.stderr[-400:])
    with open(os.path.join(out, "members.csv")) as f:
        return list(csv.DictReader(f))


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def main():
    values = swim.spec_values(SPEC)
    swim.run(SCENE, t_end=T_END)   # warm-up: kernels into the cache, the library's pages in memory
    ways = ["python loop (swim.run)", "Simulation.set + run", "Simulation.set + run, rows=False",
            "swim.sweep (in process)", "swim.sweep threads=2", "swim sweep --jobs 1"]
    times = {w: [] for w in ways}
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="swim-bench-py-") as tmp:
        for k in range(REPEATS):
            t, loop = timed(python_loop, values)
            times[ways[0]].append(t)
            t, sim_ys = timed(simulation_set, values)
            times[ways[1]].append(t)
            t, sim_ys2 = timed(simulation_set, values, False)
            times[ways[2]].append(t)
            t, rows = timed(python_sweep, values)
            times[ways[3]].append(t)
            t, rows2 = timed(python_sweep, values, SPEC, T_END, 2)
            times[ways[4]].append(t)
            t, table = timed(cli_sweep, tmp, k)
            times[ways[5]].append(t)
    want = [repr(float(m["y"])) for m in table]
    if len(table) != len(values) or [repr(r.final_state["y"]) for r in loop] != want \
            or [repr(r["y"]) for r in rows] != want or [repr(r["y"]) for r in rows2] != want \
            or [repr(y) for y in sim_ys] != want or [repr(y) for y in sim_ys2] != want:
        print("FAIL: the loop, the Simulation, swim.sweep and swim sweep did not compute the same members")
        return 1
    cli = statistics.median(times["swim sweep --jobs 1"])
    print("Example 3, %d members (%s=%s), t_end = %g, median of %d (swim %s, %s), load average %.1f" % (
        len(values), KEY, SPEC, T_END, REPEATS, swim.__version__, os.path.basename(swim._L._name), load))
    print("%-26s %10s %12s %10s" % ("way", "seconds", "members/s", "vs sweep"))
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "python_loop.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["way", "members", "t_end", "median_seconds", "members_per_second", "ratio_to_swim_sweep"])
        for way, ts in times.items():
            med = statistics.median(ts)
            print("%-26s %10.3f %12.1f %9.2fx" % (way, med, len(values) / med, cli / med))
            w.writerow([way, len(values), T_END, "%.4f" % med, "%.1f" % (len(values) / med), "%.2f" % (cli / med)])
        # the threads, on short and on longer members
        for label, spec, t_end in (("short", SHORT, T_END), ("long", LONG, LONG_T_END)):
            fam = swim.spec_values(spec)
            thread_times = {1: [], 2: []}
            load = os.getloadavg()[0]
            for k in range(REPEATS):
                for threads in (1, 2):
                    t, out = timed(python_sweep, fam, spec, t_end, threads)
                    thread_times[threads].append(t)
                    if threads == 1:
                        ref = [repr(r["y"]) for r in out]
                    elif [repr(r["y"]) for r in out] != ref:
                        print("FAIL: threads=2 did not compute the members of threads=1")
                        return 1
            print("\nswim.sweep, %d %s members (%s=%s) to t = %g, median of %d, load average %.1f" % (
                len(fam), label, KEY, spec, t_end, REPEATS, load))
            print("%-26s %10s %12s %10s" % ("threads", "seconds", "members/s", "vs 1"))
            one = statistics.median(thread_times[1])
            for threads, ts in thread_times.items():
                med = statistics.median(ts)
                print("%-26s %10.3f %12.1f %9.2fx" % ("swim.sweep threads=%d" % threads, med, len(fam) / med,
                                                      one / med))
                w.writerow(["swim.sweep threads=%d" % threads, len(fam), t_end, "%.4f" % med, "%.1f" % (len(fam) / med),
                            ""])
    return 0


if __name__ == "__main__":
    sys.exit(main())
