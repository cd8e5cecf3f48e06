#!/usr/bin/env python3
"""The measurements the documentation quotes (make bench-docs, ~7 min): written to
build/bench/docs/NAME.json, each with the command that made it, the date and the machine's load
average before and after, for `make docs-numbers` (tools/docs_numbers.py) to write into the
generated blocks of README.md and docs/.

  member_cost  Example 3 (T = 30, 601 rows): summary.json stats (integrate, diagnostics, output,
               wall seconds), medians of 5 runs, full and --summary-only.
  event_cost   Example 3 (T = 30): stats.integrate_seconds without events, with am1:max and with
               the four energy events of Fig. 4.8, medians of 3 runs.
  lyapunov     swim run --lyapunov --t-end 20 of models/hard/soft_n10_a1.toml and
               soft_n10_a05.toml at rtol 1e-8 and 1e-10 (exponent, verdict, horizon, pass time),
               soft_n10_a1 over T = 10 and T = 3 (verdicts), and Example 3 over its own T.
  rhs_cost     ns per right-hand side at the initial state of every paper scene, specialized
               and generic kernel (build/tests/bench/bench_rhs, its medians of 7), the median
               of 3 runs of it.
  rhs_parts    the parts of a full-coordinate RHS (Example 7, §5.2): whole, barrier quadrature,
               kernel K + P + Γ, Γ's contraction, the rest (build/tests/bench/bench_rhs_parts, its
               medians of 7), the median of 3 runs of it.
  kernel_flags the scene kernel of Example 7 rebuilt with -ffp-contract=fast and with reassociation,
               against the kernels' own flags (build/tests/bench/bench_kernel_flags, interleaved
               rounds; its minima and medians), once.
  peer         swim against the NumPy/SciPy implementation of the same model (DOP853, LSODA,
               Radau) at matched error on Examples 3 and 7 (tests/bench/peer/bench_peer.py, its
               medians of 3): its table.
  member_floor Example 3's --summary-only run (T = 30) per accepted step, medians of 15 runs: its
               right-hand side, its checks at every step, its row diagnostics and the rest of its
               integration, beside the cost of ABM's own step on a problem of the same dimension
               with a trivial right-hand side (build/tests/bench/bench_step_floor, its medians of
               5, with GSL msadams and CVODE-Adams): the floor under item 4's ratio.
  first_use    first use of a new structure at N = 10, 20, 32 against the straight-line
               generator it replaced (tests/bench/bench_first_use.py: medians of 3, the base once).

Usage: bench_docs.py [NAME ...] (default: all). Timings on a shared machine are noisy: the load
is recorded beside them."""
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.environ.get("SWIM_BIN", os.path.join(ROOT, "bin", "swim"))
OUT = os.path.join(ROOT, "build", "bench", "docs")


def load():
    with open("/proc/loadavg") as fh:
        return float(fh.read().split()[0])


def run(scene, *args):
    """summary.json of `swim run SCENE --quiet ARGS` in a fresh folder."""
    d = tempfile.mkdtemp(prefix="bench-docs-")
    try:
        p = subprocess.run([SWIM, "run", scene, "--out", os.path.join(d, "o"), "--quiet", *args],
                           capture_output=True, text=True, cwd=ROOT)
        if p.returncode != 0:
            raise RuntimeError("swim run %s %s failed: %s" % (scene, " ".join(args), p.stderr[-300:]))
        with open(os.path.join(d, "o", "summary.json")) as fh:
            return json.load(fh)
    finally:
        shutil.rmtree(d, ignore_errors=True)


def median_stats(scene, n, *args):
    stats = [run(scene, *args)["stats"] for _ in range(n)]
    keys = ("integrate_seconds", "diagnostics_seconds", "output_seconds", "wall_seconds")
    return {k: statistics.median(s[k] for s in stats) for k in keys if k in stats[0]}


def member_cost():
    ex3 = "models/example3.toml"
    return {"runs": 5, "scene": ex3,
            "full": median_stats(ex3, 5),
            "summary_only": median_stats(ex3, 5, "--summary-only")}


FIG48_EVENTS = ["kinetic_rigid:max", "potential:min", "kinetic_rigid:min", "potential:max"]


def event_cost():
    ex3 = "models/example3.toml"
    ev = [a for e in FIG48_EVENTS for a in ("--event", e)]
    return {"runs": 3, "scene": ex3,
            "none": median_stats(ex3, 3, "--summary-only")["integrate_seconds"],
            "am1_max": median_stats(ex3, 3, "--summary-only", "--event", "am1:max")["integrate_seconds"],
            "four_energy_events": median_stats(ex3, 3, "--summary-only", *ev)["integrate_seconds"],
            "events": FIG48_EVENTS}


def lyapunov():
    out = {}
    for name in ("soft_n10_a1", "soft_n10_a05"):
        for rtol in ("1e-8", "1e-10"):
            ly = run("models/hard/%s.toml" % name, "--rtol", rtol, "--t-end", "20", "--lyapunov",
                     "--summary-only")["lyapunov"]
            out["%s@%s" % (name, rtol)] = {k: ly.get(k) for k in (
                "exponent", "exponent_second_half", "verdict", "horizon", "horizon_from_exponent",
                "seconds", "rate_first_half", "rate_second_half")}
    for t_end in ("10", "3"):     # the verdicts of a long enough and of a too short run
        ly = run("models/hard/soft_n10_a1.toml", "--t-end", t_end, "--lyapunov", "--summary-only")["lyapunov"]
        out["soft_n10_a1@T" + t_end] = {k: ly.get(k) for k in (
            "exponent", "verdict", "rate_first_half", "rate_second_half", "t_end_needed")}
    ly = run("models/example3.toml", "--lyapunov", "--summary-only")["lyapunov"]
    out["example3"] = {k: ly.get(k) for k in ("exponent", "verdict", "growth_power",
                                              "rate_second_half", "horizon_from_power", "seconds")}
    return out


RHS_SCENES = ["models/example%s.toml" % e for e in ("1", "2a", "2b", "2c", "3", "4", "5", "6", "7")] + [
    "models/selfpropelled.toml"]


def csv_runs(prog, args, n=3):
    """n runs of a bench program that prints CSV: for each run, its rows as dicts."""
    env = dict(os.environ)
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    runs = []
    for _ in range(n):
        p = subprocess.run([prog, *args], capture_output=True, text=True, cwd=ROOT, env=env)
        if p.returncode != 0:
            raise RuntimeError("%s failed: %s" % (prog, p.stderr[-300:]))
        lines = p.stdout.strip().splitlines()
        head = lines[0].split(",")
        runs.append([dict(zip(head, line.split(","))) for line in lines[1:]])
    return runs


def rhs_cost():
    prog = os.environ.get("BENCH_RHS", os.path.join(ROOT, "build", "tests", "bench", "bench_rhs"))
    runs = csv_runs(prog, RHS_SCENES)
    out = []
    for i, scene in enumerate(RHS_SCENES):
        rows = [r[i] for r in runs]
        out.append({"scene": os.path.basename(scene)[:-5], "n_free": int(rows[0]["n_free"]),
                    "state_generic": int(rows[0]["state_generic"]),
                    "state_specialized": int(rows[0]["state_specialized"]),
                    "ns_generic": statistics.median(float(r["ns_generic"]) for r in rows),
                    "ns_specialized": statistics.median(float(r["ns_specialized"]) for r in rows)})
    return {"runs": 3, "scenes": out}


def rhs_parts():
    runs = csv_runs(os.path.join(ROOT, "build", "tests", "bench", "bench_rhs_parts"), [])
    out = []
    for i in range(len(runs[0])):
        rows = [r[i] for r in runs]
        rec = {"scene": os.path.basename(rows[0]["scene"])[:-5], "barrier_nodes": rows[0]["barrier_nodes"]}
        for c in ("ns_rhs", "ns_barrier", "ns_kernel", "ns_christoffel", "ns_rest"):
            rec[c] = statistics.median(float(r[c]) for r in rows)
        out.append(rec)
    return {"runs": 3, "scenes": out}


def kernel_flags():
    runs = csv_runs(os.path.join(ROOT, "build", "tests", "bench", "bench_kernel_flags"), [], n=1)
    return {"rows": [{"flags": r["flags"], "ns_min": float(r["ns_min"]), "ns_median": float(r["ns_median"]),
                      "ratio_min": float(r["ratio_min"]), "same_bits": int(r["same_bits"])} for r in runs[0]],
            "scene": os.path.basename(runs[0][0]["scene"])[:-5]}


def script_rows(script, args, csv_path, stdout=None):
    """Runs a bench script of tests/bench/ and returns the rows of the CSV it writes (and its
    standard output into the list stdout when given)."""
    import csv
    env = dict(os.environ, SWIM_BIN=SWIM)
    env.setdefault("SWIM_CACHE", os.path.join(ROOT, "build", "cache"))
    p = subprocess.run([sys.executable, os.path.join(ROOT, "tests", "bench", script), *args],
                       capture_output=True, text=True, cwd=ROOT, env=env)
    if p.returncode != 0:
        raise RuntimeError("%s failed: %s" % (script, (p.stdout + p.stderr)[-300:]))
    if stdout is not None:
        stdout.append(p.stdout)
    with open(csv_path) as fh:
        return list(csv.DictReader(fh))


def sensitivity():
    out = os.path.join(OUT, "sensitivity")
    rows = script_rows("bench_sensitivity.py", ["--out", out], os.path.join(out, "sensitivity.csv"))
    return {"runs": 3, "rows": [{k: (v if k == "case" else float(v)) for k, v in r.items()} for r in rows]}


def sweep():
    import re
    text = []
    rows = script_rows("bench_sweep.py", [], os.path.join(ROOT, "build", "bench", "sweep.csv"), text)
    m = re.search(r"member: median ([0-9.]+) ms inside swim run.*?; ([0-9.]+) ms per member end to end", text[0])
    out = {"runs": int(os.environ.get("SWEEP_BENCH_REPS", "3")), "rows": [], "rank0": None,
           "member_ms": float(m.group(1)) if m else None, "member_end_to_end_ms": float(m.group(2)) if m else None}
    for r in rows:
        if r["configuration"] == "rank0_us_per_member":
            out["rank0"] = {"us_per_member": float(r["seconds"]), "members_per_s": float(r["members_per_s"]),
                            "ranks_fed": float(r["efficiency_or_ranks_fed"])}
        else:
            out["rows"].append({"configuration": r["configuration"], "workers": int(r["workers"]),
                                "seconds": float(r["seconds"]), "members_per_s": float(r["members_per_s"]),
                                "speedup": float(r["speedup"]), "efficiency": float(r["efficiency_or_ranks_fed"]),
                                "cpu_ms_per_member": 1e3 * float(r["cpu_seconds_per_member"])})
    return out


def jacobian():
    out = os.path.join(OUT, "jacobian")
    script_rows("bench_jacobian.py", ["--out", out], os.path.join(out, "jacobian.csv"))
    with open(os.path.join(out, "table.md"), encoding="utf-8") as fh:
        return {"runs": 3, "table": fh.read()}


def python_loop():
    rows = script_rows("bench_python_loop.py", [], os.path.join(ROOT, "build", "bench", "python_loop.csv"))

    def row(r):
        return {"way": r["way"], "members": int(r["members"]), "t_end": float(r["t_end"]),
                "seconds": float(r["median_seconds"]), "members_per_second": float(r["members_per_second"])}
    # the family's ways against swim sweep, then the threads' rows (no ratio to swim sweep), 1 then 2 per family
    return {"runs": 3, "rows": [dict(row(r), ratio_to_swim_sweep=float(r["ratio_to_swim_sweep"]))
                                for r in rows if r["ratio_to_swim_sweep"]],
            "threads": [row(r) for r in rows if not r["ratio_to_swim_sweep"]]}


def member_floor():
    floor = csv_runs(os.path.join(ROOT, "build", "tests", "bench", "bench_step_floor"), [], n=1)[0]
    methods = [{"method": r["method"], "rows": int(r["rows"]), "steps": int(r["steps"]),
                "rhs_evals": int(r["rhs_evals"]), "ns_per_step_net": float(r["ns_per_step_net"])} for r in floor]
    ex3 = "models/example3.toml"
    per = {k: [] for k in ("rhs", "checks", "diagnostics", "integrate")}
    for _ in range(15):
        s = run(ex3, "--summary-only")
        st, steps = s["stats"], s["stats"]["steps"]
        per["rhs"].append(1e9 * st["rhs_seconds"] / steps)
        per["checks"].append(1e9 * s["step_checks"]["seconds"] / steps)
        per["diagnostics"].append(1e9 * st["diagnostics_seconds"] / steps)
        per["integrate"].append(1e9 * st["integrate_seconds"] / steps)
    return {"scene": ex3, "runs": 15, "steps": steps, "rows": s["rows"], "rhs_evaluations": st["rhs_evaluations"],
            "ns_per_step": {k: statistics.median(v) for k, v in per.items()}, "methods": methods}


def peer():
    out = os.path.join(OUT, "peer")
    script_rows(os.path.join("peer", "bench_peer.py"), ["--out", out], os.path.join(out, "peer.csv"))
    with open(os.path.join(out, "table.md"), encoding="utf-8") as fh:
        return {"runs": 3, "table": fh.read()}


def first_use():
    rows = script_rows("bench_first_use.py", [], os.path.join(ROOT, "build", "bench", "first_use.csv"))
    return {"rows": [{k: (v if k == "version" else float(v)) for k, v in r.items()} for r in rows]}


MEASURE = {"member_cost": member_cost, "event_cost": event_cost, "lyapunov": lyapunov, "rhs_cost": rhs_cost,
           "rhs_parts": rhs_parts, "kernel_flags": kernel_flags, "sensitivity": sensitivity, "python_loop": python_loop, "sweep": sweep,
           "jacobian": jacobian, "peer": peer, "first_use": first_use, "member_floor": member_floor}


def main(argv):
    names = argv or list(MEASURE)
    bad = [n for n in names if n not in MEASURE]
    if bad:
        print("bench_docs.py: unknown measurement %s (known: %s)" % (", ".join(bad), ", ".join(MEASURE)),
              file=sys.stderr)
        return 2
    os.makedirs(OUT, exist_ok=True)
    failed = []
    for n in names:
        before, t0 = load(), time.time()
        try:
            values = MEASURE[n]()
        except (RuntimeError, OSError, ValueError, KeyError) as e:
            # the others are still measured; the old record of this one (if any) stays
            print("bench_docs: %s not measured: %s" % (n, e), file=sys.stderr)
            failed.append(n)
            continue
        rec = {"name": n, "command": "make bench-docs", "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
               "load_before": before, "load_after": load(), "cores": os.cpu_count(),
               "seconds": round(time.time() - t0, 1), "values": values}
        with open(os.path.join(OUT, n + ".json"), "w") as fh:
            json.dump(rec, fh, indent=1)
        print("bench_docs: %s in %.0f s (load %.1f -> %.1f): %s" % (
            n, rec["seconds"], before, rec["load_after"], os.path.join(OUT, n + ".json")))
    if failed:
        print("bench_docs: not measured: %s" % ", ".join(failed), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
