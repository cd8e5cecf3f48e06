#!/usr/bin/env python3
"""What a run costs besides its right-hand side (issue targets: docs/performance.md, "Start-up
and the cost around the RHS"):

- start-up: process time (user + system, from wait4) of `swim --version` and of `swim run
  models/example3.toml --summary-only` with its kernel cached, to T = 0.05 (one row of work) and
  to its t_end (T = 30, about 5 ms of integration and diagnostics);
- a member close to its RHS: Example 3 to its t_end with --summary-only, the integration and the
  row diagnostics (summary.json stats.integrate_seconds + diagnostics_seconds) over the time
  spent in the right-hand side (stats.rhs_seconds), both measured inside the same run.

Medians of BENCH_RUNS runs (default 20 for start-up, 7 for the member). With SWIM_BENCH_REF=BIN
(an earlier build, e.g. tests/compare_reference.sh's build/compare-reference/src/bin/swim) each
measurement alternates between BIN and bin/swim, and the ratio is printed beside it: a busy
machine slows both alike. The load average is printed before and after. Writes
build/bench/overhead.csv."""

import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
REF = os.environ.get("SWIM_BENCH_REF", "")
RUNS = int(os.environ.get("BENCH_RUNS", "0"))
ENV = dict(os.environ, SWIM_SHARE=ROOT)
# The reference finds the generator and kernel headers of its own tree (next to its bin/): the
# kernel ABI may differ between the two, and a kernel built from the other's headers is refused.
ENV_REF = {k: v for k, v in os.environ.items() if k != "SWIM_SHARE"}


def env_for(exe):
    return ENV if exe == SWIM else ENV_REF


def load():
    with open("/proc/loadavg") as fh:
        return " ".join(fh.read().split()[:3])


def process_ms(argv):
    """Process time of one run of argv in ms (its children included: wait4's rusage)."""
    p = subprocess.Popen(argv, cwd=ROOT, env=env_for(argv[0]), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit("bench_overhead: %s exited %d" % (" ".join(argv), p.returncode))
    return 1e3 * (ru.ru_utime + ru.ru_stime)


def member(exe, out):
    subprocess.run([exe, "run", "models/example3.toml", "--summary-only", "--quiet", "--out", out],
                   check=True, cwd=ROOT, env=env_for(exe), capture_output=True)
    with open(os.path.join(out, "summary.json")) as fh:
        st = json.load(fh)["stats"]
    return (1e3 * st["integrate_seconds"], 1e3 * st["diagnostics_seconds"], 1e3 * st["rhs_seconds"])


def main():
    exes = [("ref", REF), ("new", SWIM)] if REF else [("new", SWIM)]
    rows = []
    print("load average before: %s" % load())
    with tempfile.TemporaryDirectory(prefix="swim-bench-") as tmp:
        out = os.path.join(tmp, "run")
        cases = [("swim --version", ["--version"]),
                 ("swim run example3 --summary-only (cached, T = 0.05)",
                  ["run", "models/example3.toml", "--summary-only", "--quiet", "--out", out, "--t-end", "0.05"]),
                 ("swim run example3 --summary-only (cached, T = 30)",
                  ["run", "models/example3.toml", "--summary-only", "--quiet", "--out", out])]
        for exe in (e for _, e in exes):   # the kernel in the cache before anything is timed
            process_ms([exe] + cases[1][1])
        for name, args in cases:
            got = {k: [] for k, _ in exes}
            for _ in range(RUNS or 20):
                for k, exe in exes:
                    got[k].append(process_ms([exe] + args))
            med = {k: statistics.median(v) for k, v in got.items()}
            rows.append({"measure": name + ": process ms", "ref": med.get("ref", ""), "new": med["new"]})
        got = {k: [] for k, _ in exes}
        for _ in range(RUNS or 7):
            for k, exe in exes:
                got[k].append(member(exe, out))
        for i, what in enumerate(("integrate ms", "diagnostics ms", "rhs ms")):
            med = {k: statistics.median(r[i] for r in v) for k, v in got.items()}
            rows.append({"measure": "example3 --summary-only: " + what, "ref": med.get("ref", ""), "new": med["new"]})
        ratio = {k: statistics.median((r[0] + r[1]) / r[2] for r in v) for k, v in got.items()}
        rows.append({"measure": "example3 --summary-only: (integrate + diagnostics) / rhs",
                     "ref": ratio.get("ref", ""), "new": ratio["new"]})
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "build", "bench", "overhead.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["measure", "ref", "new"])
        w.writeheader()
        w.writerows(rows)
    floor = statistics.median(process_ms(["/bin/true"]) for _ in range(RUNS or 20))
    print("start-up and the cost around the RHS (medians; targets: --version <= 5 ms, run <= 20 ms,"
          " ratio <= 1.5)")
    print("the floor of any process here (/bin/true): %.2f ms" % floor)
    if REF:
        print("%-62s %10s %10s %8s" % ("measure", "reference", "bin/swim", "new/ref"))
    for r in rows:
        if REF:
            print("%-62s %10.2f %10.2f %8.2f" % (r["measure"], r["ref"], r["new"], r["new"] / r["ref"]))
        else:
            print("%-62s %10.2f" % (r["measure"], r["new"]))
    print("load average after: %s" % load())


if __name__ == "__main__":
    main()
