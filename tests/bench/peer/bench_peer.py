#!/usr/bin/env python3
"""swim against a careful NumPy/SciPy implementation of the same model (tests/bench/peer/
peer_model.py, written from the paper and the errata), at matched error.

Usage (from the repository root; part of `make bench`):
    /usr/bin/python3 tests/bench/peer/bench_peer.py [--scenes example3,example7] [--t-end T]
                                                    [--repeat N] [--quick] [--out DIR]

Per scene, on T = 10 (Example 7's own t_end; Example 3's first third):
1. Reference: the peer with DOP853 at rtol 1e-13 / atol 1e-15. swim's abm at the same tolerances
   is compared with it at t = T ("reference agreement" in the table); the peer's initial state
   must equal swim's first row (the initial velocity of Example 7 is projected by both, ERRATA D5).
2. Sweep: swim (`swim run --summary-only`, its default integrator and checks, atol = rtol/100)
   and the peer with solve_ivp's DOP853, LSODA and Radau, each at a few tolerances. Error = max
   abs difference at t = T of the state (x, y, theta, c, c') against the reference. CPU time =
   median of --repeat runs: swim's stats.integrate_seconds (time inside its integrator: RHS, step
   control and the checks at every step; process start and the kernel's loading excluded), the
   peer's process time around solve_ivp (the same scope: no output grid).
3. Ratio at matched error: each curve's CPU time at errors 1e-6, 1e-8 and 1e-10, interpolated
   log-log on its monotone envelope (bench_accuracy.cost_to_reach); the ratio peer/swim says how
   many times faster swim is. Also the cost of one RHS on each side: swim's stats.ns_per_rhs
   (median over its runs), the peer's right-hand side at the initial state (process time, median
   of 7 x 1000 calls). peer.csv's ns_per_rhs is, for the peer, its CPU time per RHS evaluation
   (the integrator's own work included).
Writes DIR/peer.csv and DIR/table.md (default build/bench/peer/) and prints the table; the load
average before and after is in the table. Timings on a shared machine are noisy: medians.
Radau and LSODA estimate the Jacobian by finite differences (2 + 2*16 + 3 columns), as a SciPy
user would without an analytic Jacobian."""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import timeit

import numpy as np
from scipy.integrate import solve_ivp

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))
import peer_model  # noqa: E402
from bench_accuracy import cost_to_reach  # noqa: E402

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
TOLS = {"swim": [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
        "DOP853": [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12],
        "LSODA": [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11],
        "Radau": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9]}
QUICK = {"swim": [1e-6, 1e-9], "DOP853": [1e-6, 1e-9], "LSODA": [1e-6], "Radau": [1e-5]}
TARGETS = [1e-6, 1e-8, 1e-10]
PEER_METHODS = ["DOP853", "LSODA", "Radau"]


def loadavg():
    with open("/proc/loadavg") as fh:
        return float(fh.read().split()[0])


def swim_final(scene_path, T, rtol, out):
    """(final state y, integrate_seconds, ns_per_rhs, rhs evaluations) of one `swim run`."""
    args = [SWIM, "run", scene_path, "--out", out, "--quiet", "--summary-only", "--t-end", repr(T),
            "--rtol", repr(rtol), "--atol", repr(rtol * 1e-2)]
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    path = os.path.join(out, "summary.json")
    if p.returncode != 0 or not os.path.exists(path):
        raise RuntimeError("swim run failed (%d): %s" % (p.returncode, p.stderr.strip()[-300:]))
    with open(path) as fh:
        s = json.load(fh)
    if s["status"] != "completed":
        raise RuntimeError("swim run: status %s (%s)" % (s["status"], s.get("reason")))
    f = s["final_state"]
    y = np.concatenate([[f["x"], f["y"], f["theta"]], f["c"], f["dc"]])
    st = s["stats"]
    return y, st["integrate_seconds"], st["ns_per_rhs"], st["rhs_evaluations"]


def peer_final(sc, y0, T, method, rtol):
    """(final state, process seconds of solve_ivp, RHS evaluations)."""
    t0 = time.process_time()
    sol = solve_ivp(sc.rhs, (0.0, T), y0, method=method, rtol=rtol, atol=rtol * 1e-2)
    dt = time.process_time() - t0
    if sol.status != 0:
        raise RuntimeError("solve_ivp %s rtol %g: %s" % (method, rtol, sol.message))
    return sol.y[:, -1], dt, sol.nfev


def measure_scene(name, T, repeat, tols, tmp, log):
    path = os.path.join(ROOT, "models", name + ".toml")
    sc, y0, _ = peer_model.load_scene(path)
    ref, ref_cpu, ref_nfev = peer_final(sc, y0, T, "DOP853", 1e-13)
    # the peer starts where swim starts (ERRATA D5's projection of c'0 on both sides)
    out0 = os.path.join(tmp, name + "-row0")
    subprocess.run([SWIM, "run", path, "--out", out0, "--quiet", "--t-end", repr(min(T, 0.1)),
                    "--output-step", repr(min(T, 0.1))], capture_output=True, cwd=ROOT, check=True)
    row0 = np.genfromtxt(os.path.join(out0, "trajectory.csv"), delimiter=",", skip_header=1)[0]
    start_diff = float(np.abs(row0[1:1 + len(y0)] - y0).max())
    swim_ref, _, _, _ = swim_final(path, T, 1e-13, os.path.join(tmp, name + "-ref"))
    agree = float(np.abs(swim_ref - ref).max())
    log("%s: T = %g, reference DOP853 1e-13 (%d RHS, %.1f s), swim abm 1e-13 differs by %.2e, "
        "initial states differ by %.1e" % (name, T, ref_nfev, ref_cpu, agree, start_diff))
    calls = timeit.Timer(lambda: sc.rhs(0.0, y0), timer=time.process_time).repeat(7, 1000)
    rhs_ns = 1e9 * statistics.median(calls) / 1000
    rows = []
    runs = [("swim", r) for r in tols["swim"]] + [(m, r) for m in PEER_METHODS for r in tols[m]]
    cpu = {k: [] for k in runs}
    first = {}
    for rep in range(repeat):          # interleaved, so a burst of load does not hit one method
        for key in runs:
            method, rtol = key
            if method == "swim":
                y, sec, ns, nfev = swim_final(path, T, rtol, os.path.join(tmp, name + "-run"))
            else:
                y, sec, nfev = peer_final(sc, y0, T, method, rtol)
                ns = 1e9 * sec / nfev
            cpu[key].append(sec)
            if rep == 0:
                first[key] = (float(np.abs(y - ref).max()), nfev, ns)
    for key in runs:
        err, nfev, ns = first[key]
        rows.append({"scene": name, "method": key[0], "rtol": key[1], "error": err,
                     "cpu_s": statistics.median(cpu[key]), "rhs_evals": nfev,
                     "ns_per_rhs": statistics.median([1e9 * c / nfev for c in cpu[key]])
                     if key[0] != "swim" else ns})
    return rows, {"agree": agree, "start_diff": start_diff, "ref_nfev": ref_nfev, "rhs_ns": rhs_ns}


def table(all_rows, info, T, repeat, loads):
    out = ["| scene | method | CPU at error 1e-6 | 1e-8 | 1e-10 | one RHS | swim faster ×"
           " (1e-6 / 1e-8 / 1e-10) |", "|---|---|---|---|---|---|---|"]
    for name in info:
        rows = [r for r in all_rows if r["scene"] == name]
        cost = {}
        per_rhs = {}
        for m in ["swim"] + PEER_METHODS:
            pts = [(r["cpu_s"], r["error"]) for r in rows if r["method"] == m]
            cost[m] = [cost_to_reach(pts, e) for e in TARGETS]
            per_rhs[m] = (statistics.median(r["ns_per_rhs"] for r in rows if r["method"] == m)
                          if m == "swim" else info[name]["rhs_ns"])

        def fmt(c):
            if c is None:
                return "not reached"
            t = "%.3g s" % c[0] if c[0] >= 1 else "%.3g ms" % (1e3 * c[0])
            return ("≤ " if c[1] == "bound" else "") + t

        for m in ["swim"] + PEER_METHODS:
            ratios = []
            for cs, cp in zip(cost["swim"], cost[m]):
                if m == "swim":
                    break
                # a "bound" cost (the loosest run is already below the error) is an upper bound
                if cs is None or cp is None or cs[1] == cp[1] == "bound":
                    ratios.append("—")
                else:
                    ratios.append({"bound": "≥ ", "interp": ""}[cs[1]] if cp[1] == "interp" else "≤ ")
                    ratios[-1] += "%.0f" % (cp[0] / cs[0])
            out.append("| %s | %s | %s | %s | %s | %.3g µs | %s |" % (
                name, m if m == "swim" else "SciPy " + m, *[fmt(c) for c in cost[m]],
                per_rhs[m] / 1e3, " / ".join(ratios) if ratios else ""))
    notes = ["", "T = %g; error = max abs difference of (x, y, θ, c, c') at t = T from the peer's DOP853 at "
             "rtol 1e-13 (swim's abm at rtol 1e-13 differs from it by %s); CPU = median of %d runs (swim: "
             "`stats.integrate_seconds`; peer: process time of `solve_ivp`), interpolated log-log at the "
             "error (≤: the loosest run is already below it, an upper bound); atol = rtol/100; \"—\": no ratio. One RHS: "
             "swim's `stats.ns_per_rhs` (median over its runs), the peer's at the initial state (median of 7 × 1000 "
             "calls). Load average %.1f → %.1f "
             "on %d cores. Made by `make bench` (tests/bench/peer/bench_peer.py)."
             % (T, ", ".join("%.1e (%s)" % (v["agree"], k) for k, v in info.items()), repeat,
                loads[0], loads[1], os.cpu_count())]
    return "\n".join(out + notes + decomposition(all_rows, info)) + "\n"


def decomposition(all_rows, info):
    """Where the ratio against DOP853 comes from, at each target error: the RHS evaluations each
    side needs (interpolated like the CPU time), the CPU time per evaluation (swim's RHS alone
    beside it: the rest is its step control and checks), their product, and the CPU time per
    evaluation swim would need, with the evaluations it needs, for 100x and 300x."""
    out = ["", "| scene | error | RHS evaluations: DOP853 / swim | CPU per evaluation: DOP853 / swim "
           "(its RHS alone) | swim faster × | swim's CPU per evaluation for 100× / 300× |",
           "|---|---|---|---|---|---|"]
    for name in info:
        rows = [r for r in all_rows if r["scene"] == name]
        rhs_alone = statistics.median(r["ns_per_rhs"] for r in rows if r["method"] == "swim")
        for e in TARGETS:
            got = {}
            for m in ("swim", "DOP853"):
                mr = [r for r in rows if r["method"] == m]
                got[m] = (cost_to_reach([(r["cpu_s"], r["error"]) for r in mr], e),
                          cost_to_reach([(r["rhs_evals"], r["error"]) for r in mr], e))
            if any(c is None or n is None or c[1] != "interp" or n[1] != "interp" for c, n in got.values()):
                out.append("| %s | %.0e | — | — | — | — |" % (name, e))   # not reached, or only bounded
                continue
            (cs, ns), (cp, np_) = ((c[0], n[0]) for c, n in (got["swim"], got["DOP853"]))
            per_s, per_p = 1e9 * cs / ns, 1e9 * cp / np_
            out.append("| %s | %.0e | %.0f / %.0f (%.2f×) | %.0f µs / %.2f µs (%.2f µs) (%.0f×) | %.0f | %.2f µs / %.2f µs |"
                       % (name, e, np_, ns, np_ / ns, per_p / 1e3, per_s / 1e3, rhs_alone / 1e3, per_p / per_s,
                          cp / cs, 1e6 * cp / (100 * ns), 1e6 * cp / (300 * ns)))
    out.append("")
    out.append("The ratio is the product of the two quotients in brackets. Evaluations and CPU time are "
               "interpolated log-log at the error on each side's runs (as the table above); CPU per "
               "evaluation = CPU time / evaluations there. The last column is what swim's CPU time per "
               "evaluation -- its RHS and everything around it -- would have to be, with the evaluations it "
               "needs, for swim to be 100× or 300× faster than DOP853.")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="example3,example7")
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "peer"))
    a = ap.parse_args(argv)
    tols = QUICK if a.quick else TOLS
    repeat = 1 if a.quick else a.repeat
    os.makedirs(a.out, exist_ok=True)
    loads = [loadavg()]
    all_rows, info = [], {}
    with tempfile.TemporaryDirectory(prefix="bench-peer-") as tmp:
        for name in a.scenes.split(","):
            rows, inf = measure_scene(name, a.t_end, repeat, tols, tmp, lambda m: print(m, flush=True))
            all_rows += rows
            info[name] = inf
    loads.append(loadavg())
    with open(os.path.join(a.out, "peer.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(all_rows[0]))
        w.writeheader()
        w.writerows(all_rows)
    text = table(all_rows, info, a.t_end, repeat, loads)
    with open(os.path.join(a.out, "table.md"), "w", encoding="utf-8") as fh:
        fh.write(text)
    for r in all_rows:
        print("%-9s %-7s rtol %.0e  error %.2e  cpu %.4g s  %d RHS" % (
            r["scene"], r["method"], r["rtol"], r["error"], r["cpu_s"], r["rhs_evals"]))
    print(text)
    print("wrote", os.path.join(a.out, "peer.csv"), "and table.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
