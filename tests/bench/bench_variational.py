#!/usr/bin/env python3
"""The cost of the variational equations in a run: sensitivities and the Lyapunov tangent vector.

Usage (from the repository root; `make bench` and `make bench-variational` include it):
    /usr/bin/python3 tests/bench/bench_variational.py [--before PATH] [--runs K] [--out DIR]

Examples 3 (T = 30) and 7 (T = 10), each with 0, 1 and 4 sensitivity keys, without and with
--lyapunov: the wall time of the whole `swim run` (median of K runs, default 5, the binaries
alternating run by run so that the machine's load falls on both alike) and the run's right-hand
side evaluations (summary.json: the run's, plus the sensitivity entry's when that was a second
integration, plus the Lyapunov entry's). With --before (default build/bench/swim-before, when it
exists: a copy of bin/swim from before the change, not committed) the two binaries side by side:
"before" integrated the trajectory, then the sensitivities (in their error test), then the
Lyapunov vector, each from t = 0; "after" integrates once. Writes DIR/variational.csv and
DIR/table.md (default build/bench/variational) and prints the table. Timings on a shared machine
are noisy: the medians are what to read."""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
KEYS = {1: "model.rho0", 4: "model.rho0,model.rhof,elastic.stiffness.am1,elastic.stiffness.bm1"}
SCENES = (("Example 3, T = 30", "models/example3.toml"), ("Example 7, T = 10", "models/example7.toml"))


def one(exe, scene, nkeys, lyap, out):
    args = [exe, "run", scene, "--out", out, "--quiet"]
    if nkeys:
        args += ["--sensitivity", KEYS[nkeys]]
    if lyap:
        args += ["--lyapunov"]
    t0 = time.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(args), p.stderr.strip()[-300:]))
    s = json.load(open(os.path.join(out, "summary.json")))
    evals = s["stats"]["rhs_evaluations"]
    sens = s.get("sensitivity") or {}
    lya = s.get("lyapunov") or {}
    # before: the sensitivities and the Lyapunov vector were integrations of their own; after, the
    # entries count the run's own evaluations (which carried them)
    if sens and sens.get("jacobians", 0) != evals:
        evals += sens.get("rhs_evaluations", 0)
    if lya and lya.get("rhs_evaluations", 0) != s["stats"]["rhs_evaluations"]:
        evals += lya.get("rhs_evaluations", 0)
    return wall, evals


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", default=os.path.join(ROOT, "build", "bench", "swim-before"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "variational"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    exes = [("after", SWIM)]
    if os.path.exists(a.before):
        exes.insert(0, ("before", a.before))
    rows = []
    for title, scene in SCENES:
        for nkeys in (0, 1, 4):
            for lyap in (0, 1):
                times = {name: [] for name, _ in exes}
                evals = {}
                for k in range(a.runs):
                    for name, exe in exes:
                        w, e = one(exe, scene, nkeys, lyap, os.path.join(a.out, "run_" + name))
                        times[name].append(w)
                        evals[name] = e
                row = {"scene": title, "keys": nkeys, "lyapunov": lyap}
                for name, _ in exes:
                    row[name + "_s"] = statistics.median(times[name])
                    row[name + "_rhs"] = evals[name]
                rows.append(row)
                print(row, flush=True)
    names = [n for n, _ in exes]
    with open(os.path.join(a.out, "variational.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    head = "| scene | keys | --lyapunov | " + " | ".join("%s: s (median of %d) | %s: RHS evaluations" % (n, a.runs, n)
                                                         for n in names)
    if len(names) == 2:
        head += " | before / after |"
    else:
        head += " |"
    lines = [head, "|" + "---|" * (3 + 2 * len(names) + (len(names) == 2))]
    for r in rows:
        cells = [r["scene"], str(r["keys"]), "yes" if r["lyapunov"] else "no"]
        for n in names:
            cells += ["%.3f" % r[n + "_s"], "%d" % r[n + "_rhs"]]
        if len(names) == 2:
            cells.append("%.2f×" % (r["before_s"] / r["after_s"]))
        lines.append("| " + " | ".join(cells) + " |")
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    lines.append("")
    lines.append("*tests/bench/bench_variational.py, %s UTC, load average %.1f on %d cores.*"
                 % (time.strftime("%Y-%m-%d %H:%M", time.gmtime()), load, os.cpu_count() or 0))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as fh:
        fh.write(text)
    print(text)


if __name__ == "__main__":
    sys.exit(main())
