#!/usr/bin/env python3
"""Sweep throughput (make bench-sweep): members per second for a 200-member Example 1 family
(beta'(0) from -2 to 2, T = 30) with swim sweep --jobs 1, --jobs 2, and bin/swim-mpi with 2 and 4
ranks (rank 0 deals, the others run members), the parallel efficiency, and rank 0's own cost per
member on trivial members (T = 0.01) -- from which the number of worker ranks one rank 0 can keep
busy is estimated. Medians of REPS runs (default 3; SWEEP_BENCH_REPS). Writes
build/bench/sweep.csv. bin/swim-mpi rows are skipped when it is not built (make mpi)."""
import csv
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
MPI = os.path.join(ROOT, "bin", "swim-mpi")
REPS = int(os.environ.get("SWEEP_BENCH_REPS", "3"))
MEMBERS = int(os.environ.get("SWEEP_BENCH_MEMBERS", "200"))
CORES = os.cpu_count() or 1
ENV = dict(os.environ, OMPI_MCA_btl="self,vader", OMPI_MCA_plm_rsh_agent="")
FAMILY = ["models/example1.toml", "--quiet", "--vary", "shape.dc0.bm2=-0.70710678118654746:0.70710678118654746:%d" % MEMBERS]


def one(kind, n, extra=()):
    """Seconds of one whole sweep (process start to end) and the last stdout."""
    out = tempfile.mkdtemp(prefix="swim-bench-sweep-")
    shutil.rmtree(out)
    if kind == "jobs":
        cmd = [SWIM, "sweep", *FAMILY, "--out", out, "--jobs", str(n), *extra]
    else:
        cmd = ["mpirun", "--oversubscribe", "--allow-run-as-root", "-np", str(n), MPI, "sweep", *FAMILY,
               "--out", out, *extra]
    t = time.monotonic()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True)
    dt = time.monotonic() - t
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    one.cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)   # every descendant, reaped
    with open(os.path.join(out, "members.csv")) as fh:
        rows = list(csv.DictReader(fh))
    shutil.rmtree(out, ignore_errors=True)
    if p.returncode != 0 or len(rows) != MEMBERS:
        sys.exit("bench_sweep: %s failed (%d, %d rows): %s" % (" ".join(cmd), p.returncode, len(rows), p.stderr[-400:]))
    return dt, p.stdout, rows


def main():
    print("load average before: %.2f %.2f %.2f (on %d cores)" % (*os.getloadavg(), CORES))
    # warm the kernel cache so no configuration pays the generation
    subprocess.run([SWIM, "run", "models/example1.toml", "--out", tempfile.mkdtemp(), "--quiet", "--summary-only"],
                   cwd=ROOT, check=True, capture_output=True)
    configs = [("jobs", 1, "--jobs 1", 1), ("jobs", 2, "--jobs 2", 2)]
    if os.path.exists(MPI) and shutil.which("mpirun"):
        configs += [("mpi", 2, "MPI 2 ranks", 1), ("mpi", 4, "MPI 4 ranks", 3)]
    else:
        print("bench_sweep: %s not built (make mpi): MPI rows skipped" % MPI)
    results = []
    member_wall = []
    for kind, n, name, workers in configs:
        times, cpus = [], []
        for _ in range(REPS):
            dt, _, rows = one(kind, n)
            times.append(dt)
            cpus.append(one.cpu)
            if kind == "jobs" and n == 1:
                member_wall += [float(r["wall_seconds"]) for r in rows]
        med = statistics.median(times)
        results.append((name, workers, med, MEMBERS / med, statistics.median(cpus) / MEMBERS))
    base = results[0][3]
    print("\n%d-member Example 1 family (T = 30, summaries only), %d cores, median of %d:" % (MEMBERS, CORES, REPS))
    print("| configuration | members running at once | seconds | members/s | speed-up | efficiency per core used "
          "| CPU ms per member (all processes) |")
    print("|---|---|---|---|---|---|---|")
    rows_out = []
    for name, workers, med, rate, cpu in results:
        used = min(workers, CORES)
        eff = rate / (base * used)
        print("| %s | %d | %.2f | %.1f | %.2f | %.0f %% | %.1f |" % (name, workers, med, rate, rate / base, 100 * eff,
                                                                     1e3 * cpu))
        rows_out.append([name, workers, "%.3f" % med, "%.2f" % rate, "%.3f" % (rate / base), "%.3f" % eff,
                         "%.4f" % cpu])
    mean_member = statistics.median(member_wall)
    print("member: median %.1f ms inside swim run (wall_seconds of summary.json); %.1f ms per member end to end "
          "with --jobs 1" % (1e3 * mean_member, 1e3 / base))
    # rank 0 on trivial members
    if os.path.exists(MPI) and shutil.which("mpirun"):
        busy = []
        for _ in range(REPS):
            _, out, _ = one("mpi", 4, ("--t-end", "0.01"))
            m = re.search(r"rank 0: (\d+) results handled, ([0-9.]+) s busy \(([0-9.]+) us per member\)", out)
            busy.append(float(m.group(3)))
        us = statistics.median(busy)
        per_member = results[0][4]   # CPU seconds of one T = 30 member (--jobs 1): a worker's busy time
        feeds = per_member / (us * 1e-6)
        print("rank 0 on trivial members (T = 0.01, 4 ranks): %.1f us busy per member (median of %d) -> "
              "%.0f members/s of dealing; a T = 30 member costs a worker %.1f ms of CPU, so one rank 0 can feed "
              "~%.0f worker ranks busy with such members" % (us, REPS, 1e6 / us, 1e3 * per_member, feeds))
        rows_out.append(["rank0_us_per_member", "", "%.2f" % us, "%.0f" % (1e6 / us), "", "%.0f" % feeds])
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "sweep.csv"), "w") as fh:
        w = csv.writer(fh)
        w.writerow(["configuration", "workers", "seconds", "members_per_s", "speedup", "efficiency_or_ranks_fed",
                    "cpu_seconds_per_member"])
        w.writerows(rows_out)


if __name__ == "__main__":
    main()
