#!/usr/bin/env python3
"""The hard scenes at their own settings and at rtol 1e-10: do they complete, how close to the
boundary of D they go, how well the energy balance holds, what it costs.

Usage (from the repository root; `make bench-hard`):
    /usr/bin/python3 tests/bench/bench_hard.py [--out DIR] [--only NAME ...] [--own-only]
                                               [--tight-max-seconds S]

For every scene of models/hard/ (or the --only ones), `swim run` at the scene's own rtol/atol,
then at rtol 1e-10, atol 1e-12 (skipped when the first run took longer than
--tight-max-seconds, default 300, said in the table). Reported per run: status and t reached;
integration seconds and RHS evaluations (summary.json stats); min J over the run and its time
(summary jmin / jmin_t when the summary has it); the energy balance
max_t |E(t) - E(0) - work(t)| / max_t |E(t)| over the output rows (work = the work of the
forcing minus the dissipation, 0 in conservative scenes, so this is the drift there); the
integrator used (with the stiff fallback, when it switched).

Writes DIR/hard.csv and DIR/table.md (default build/bench/hard) and prints the table. Times are
wall-clock seconds of one run on whatever machine runs it: run it on a quiet machine."""

import argparse
import csv
import glob
import json
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")


def one(scene, out, extra):
    p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet", *extra], capture_output=True, text=True,
                       cwd=ROOT)
    try:
        with open(os.path.join(out, "summary.json")) as fh:
            s = json.load(fh)
    except (OSError, ValueError):
        return {"status": "no summary", "reason": p.stderr.strip()[-200:]}
    d = None
    path = os.path.join(out, "trajectory.csv")
    if os.path.exists(path) and os.path.getsize(path) > 0:
        d = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
    bal = float("nan")
    if d is not None and len(d) > 1:
        bal = np.max(np.abs(d["energy"] - d["energy"][0] - d["work"])) / np.max(np.abs(d["energy"]))
    st = s.get("stats", {})
    return {"status": s.get("status"), "reason": s.get("reason", ""), "t_reached": s.get("t_reached"),
            "t_end": s.get("t_end"), "seconds": st.get("integrate_seconds"), "rhs": st.get("rhs_evaluations"),
            "jmin": s.get("jmin"), "jmin_t": s.get("jmin_t"), "balance": bal, "rtol": s.get("rtol"),
            "integrator": s.get("integrator")}   # "abm+cvode-bdf" when the stiff fallback took over


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "hard"))
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--tight-max-seconds", type=float, default=300.0)
    ap.add_argument("--own-only", action="store_true", help="skip the rtol 1e-10 runs")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scenes = sorted(glob.glob(os.path.join(ROOT, "models", "hard", "*.toml")))
    if a.only:
        scenes = [s for s in scenes if os.path.splitext(os.path.basename(s))[0] in a.only]
    rows = []
    for sc in scenes:
        name = os.path.splitext(os.path.basename(sc))[0]
        for label, extra in (("own", []), ("1e-10", ["--rtol", "1e-10", "--atol", "1e-12"])):
            if label == "1e-10" and a.own_only:
                continue
            if label == "1e-10" and rows and rows[-1]["seconds"] and rows[-1]["seconds"] > a.tight_max_seconds:
                rows.append({"scene": name, "tol": label, "status": "skipped (own run > %g s)" % a.tight_max_seconds})
                continue
            r = one(sc, os.path.join(a.out, "%s-%s" % (name, label)), extra)
            r.update({"scene": name, "tol": label})
            rows.append(r)
            print("%-22s %-6s %-10s t %-8s %8.2f s %9s RHS  min J %-9.3g balance %.2e  %s" %
                  (name, label, r["status"], r.get("t_reached"), r.get("seconds") or float("nan"), r.get("rhs"),
                   r.get("jmin") or float("nan"), r.get("balance", float("nan")), r.get("integrator", "")),
                  flush=True)
    keys = ["scene", "tol", "status", "t_reached", "t_end", "seconds", "rhs", "jmin", "jmin_t", "balance", "rtol",
            "integrator", "reason"]
    with open(os.path.join(a.out, "hard.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    with open(os.path.join(a.out, "table.md"), "w") as fh:
        fh.write("| scene | rtol | status | t reached | integration s | RHS | min J (t) | balance / energy scale | integrator |\n")
        fh.write("|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            if "seconds" not in r:
                fh.write("| %s | %s | %s | | | | | | |\n" % (r["scene"], r["tol"], r["status"]))
                continue
            jt = " (%.6g)" % r["jmin_t"] if r.get("jmin_t") is not None else ""
            fh.write("| %s | %s | %s | %s | %.1f | %s | %.3g%s | %.1e | %s |\n" %
                     (r["scene"], "%g" % r["rtol"], r["status"], r["t_reached"], r["seconds"] or float("nan"),
                      r["rhs"], r["jmin"] if r["jmin"] is not None else float("nan"), jt, r["balance"],
                      r["integrator"]))
    print("wrote %s" % os.path.join(a.out, "table.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
