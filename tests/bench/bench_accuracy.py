#!/usr/bin/env python3
"""What accuracy costs in time: work-precision for every paper scene.

Usage (from the repository root; `make bench-accuracy` runs the default):
    /usr/bin/python3 tests/bench/bench_accuracy.py [--scenes a,b] [--quick] [--repeat N]
                                                   [--t-end T] [--out DIR]

Per scene, on the bench horizon T = min(scene t_end, 10) (or --t-end) with an output grid of
T/100 (101 rows, so writing output costs little):

1. Reference: abm and rk8pd at rtol 1e-13 / atol 1e-15 on the same grid. The abm run is the
   reference; the largest difference between the two over the state columns (x, y, theta, the
   shape coordinates and their velocities) is its estimated error ("reference uncertainty").
   Above 1e-9 the table says "reference NOT converged". The CSVs are kept in
   build/bench/accuracy/ref/<scene>/ and reused unless the scene file or bin/swim is newer or T
   changed.
2. Sweep: abm, abm-step (abm with STEP's step-size rule, --step-lookahead 0, to show what the
   look-ahead buys), rk8pd, msadams, cvode-adams (plus cvode-bdf and msbdf on the damped/forced
   scenes example7 and selfpropelled) at rtol 1e-3 .. 1e-13, atol = rtol * 1e-2, specialized
   kernel; abm and rk8pd with --generic at rtol 1e-4, 1e-7, 1e-10; and abm at ode113's default
   tolerances (rtol 1e-3, atol 1e-6), the paper's own setting, with STEP's step-size rule
   (abm-step) as ode113 has it.
   GSL's steppers (rk8pd, msadams, msbdf) end every call exactly at the output time (no dense
   output), so with 101 rows rk8pd takes at least ~100 steps (~1300 RHS evaluations): its
   loose-tolerance points sit on that floor, far below the asked tolerance.
   The abm run at rtol 1e-13 *is* the reference, so its error is measured against the rk8pd
   reference run instead (column error_vs = "rk8pd-ref").
3. Per run: error at t = T and max over the grid (max abs difference of the state columns vs the
   reference), summary energy_drift_rel, RHS evaluations, steps, rejections (deterministic; from
   the first repetition, and checked equal across repetitions), the order histogram, and CPU time
   = median over --repeat runs of stats.integrate_seconds (time inside the integrator). The
   repetitions of one scene are interleaved (rep 1 of every configuration, then rep 2, ...) so a
   burst of load from other work does not land on one integrator only. A run that fails (status
   failed, error > 1 or NaN) is recorded with its reason, is not repeated and is left out of the
   curves.
4. Writes build/bench/accuracy/accuracy.csv, work_precision_cpu.png, work_precision_rhs.png and
   table.md (cost to reach max-grid errors 1e-6, 1e-9, 1e-12, interpolated log-log on the
   monotone envelope of each curve), and prints the table.

Runtime: every run is cheap (a few ms to ~0.5 s inside the integrator; process start and loading
the cached specialized kernel add ~50 ms), so the default (10 scenes, 554 configurations x 5
repetitions, about 2,800 runs of swim, one at a time) took 7.0 minutes (fresh references) and
7.7 minutes (references reused, other work running) on the 2-core bench machine, so no repeat
reduction was needed. CPU medians of ~1 ms runs still move by 10-30% between full runs when other
work shares the machine: read CPU differences below ~20% as ties. The generic-kernel runs
are kept to three tolerances per integrator. --quick (smoke test) runs example1 and example7 (or
--scenes) at rtol 1e-4, 1e-7, 1e-10, generic at 1e-7 only, repeat 1, and writes to
build/bench/accuracy/quick/ so it does not overwrite the full results.
"""

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import plot_accuracy  # noqa: E402

SWIM_SRC = os.path.join(ROOT, "bin", "swim")
SWIM = SWIM_SRC          # replaced in main() by a private copy, so a rebuild mid-run cannot break it
SWIM_STAMP = None        # bin/swim's mtime when the copy was made
SCENES = ["example1", "example2a", "example2b", "example2c", "example3", "example4", "example5",
          "example6", "example7", "selfpropelled"]
STIFFISH = {"example7", "selfpropelled"}          # damped/forced, barrier: add the BDF codes
NONSTIFF_METHODS = ["abm", "abm-step", "rk8pd", "msadams", "cvode-adams"]
# Variants of an integrator, run side by side with it: "abm-step" is abm with STEP's step-size
# rule (--step-lookahead 0), i.e. without the look-ahead that abm uses by default.
VARIANTS = {"abm-step": ("abm", ["--step-lookahead", "0"])}
STIFF_METHODS = ["cvode-bdf", "msbdf"]
GENERIC_METHODS = ["abm", "rk8pd"]
TOL_EXPS = list(range(3, 14))                      # rtol 1e-3 .. 1e-13
GENERIC_EXPS = [4, 7, 10]
QUICK_EXPS = [4, 7, 10]
QUICK_GENERIC_EXPS = [7]
QUICK_SCENES = ["example1", "example7"]
REF_EXP = 13                                       # reference: rtol 1e-13, atol 1e-15
REF_CONVERGED = 1e-9
TARGETS = [1e-6, 1e-9, 1e-12]
HORIZON = 10.0
ROWS = 100


def tol_str(e):
    return "1e-%d" % e


def texp(t):
    return "1e%d" % round(np.log10(t))


class Config:
    def __init__(self, scene, integrator, kernel, rexp, aexp, series):
        self.scene, self.integrator, self.kernel = scene, integrator, kernel
        self.rexp, self.aexp, self.series = rexp, aexp, series
        self.result = None
        self.cpu = []
        self.wall = []
        self.outside = []          # integrate_seconds - rhs_seconds: the integrator's own work
        self.nondeterministic = False

    @property
    def rtol(self):
        return 10.0 ** -self.rexp

    @property
    def atol(self):
        return 10.0 ** -self.aexp

    def label(self):
        return "%s %s %s rtol %s atol %s" % (self.scene, self.integrator, self.kernel,
                                            tol_str(self.rexp), tol_str(self.aexp))


# ---------------------------------------------------------------------------------------------
# running swim

def run_swim(scene_path, out, T, dt, integrator, rexp, aexp, generic):
    """One `swim run`; returns the summary dict (None if swim wrote none) and a note."""
    summ = os.path.join(out, "summary.json")
    if os.path.exists(summ):
        os.remove(summ)
    method, extra = VARIANTS.get(integrator, (integrator, []))
    args = [SWIM, "run", scene_path, "--out", out, "--t-end", repr(T), "--output-step", repr(dt),
            "--rtol", tol_str(rexp), "--atol", tol_str(aexp), "--integrator", method, "--quiet",
            "--set", "run.energy_control=false"] + extra   # the integrators themselves (bench-soft measures it)
    if generic:
        args.append("--generic")
    p = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    if not os.path.exists(summ):
        tail = (p.stderr or p.stdout).strip().splitlines()[-1:] or [""]
        return None, "swim exited with %d and wrote no summary: %s" % (p.returncode, tail[0])
    with open(summ) as fh:
        return json.load(fh), ""


def load_traj(path):
    """(column names, data array) of a trajectory.csv; data may have 0 rows."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError:
        data = np.zeros((0, len(header)))
    if data.size == 0:
        data = np.zeros((0, len(header)))
    return header, data


def state_columns(header):
    """Indices of x, y, theta, the shape coordinates and their velocities."""
    return list(range(1, header.index("kinetic_fluid")))


def compare(run, ref):
    """(max-grid error, final-time error, note) of trajectory `run` against `ref`."""
    hr, dr = run
    hf, df = ref
    if hr != hf:
        return float("nan"), float("nan"), "columns differ from the reference"
    if dr.shape[0] != df.shape[0]:
        return float("nan"), float("nan"), "%d rows, reference has %d" % (dr.shape[0], df.shape[0])
    if np.max(np.abs(dr[:, 0] - df[:, 0])) > 1e-9 * max(1.0, abs(df[-1, 0])):
        return float("nan"), float("nan"), "output times differ from the reference"
    cols = state_columns(hf)
    d = np.abs(dr[:, cols] - df[:, cols])
    if not np.all(np.isfinite(d)):
        return float("nan"), float("nan"), "NaN in the trajectory"
    return float(d.max()), float(d[-1].max()), ""


# ---------------------------------------------------------------------------------------------
# reference

class RefFailed(Exception):
    pass


def reference(scene, scene_path, T, dt, ref_root, log):
    """Reference trajectories (abm and rk8pd at 1e-13/1e-15), computed or reused."""
    d = os.path.join(ref_root, scene)
    meta_path = os.path.join(d, "meta.json")
    want = {"t_end": T, "output_step": dt, "rtol": tol_str(REF_EXP), "atol": tol_str(REF_EXP + 2)}
    fresh = False
    if os.path.exists(meta_path):
        with open(meta_path) as fh:
            meta = json.load(fh)
        stamp = os.path.getmtime(meta_path)
        fresh = (all(meta.get(k) == v for k, v in want.items())
                 and stamp >= os.path.getmtime(scene_path) and stamp >= SWIM_STAMP
                 and all(os.path.exists(os.path.join(d, m, "trajectory.csv")) for m in ("abm", "rk8pd")))
    if not fresh:
        log("  reference: abm and rk8pd at rtol %s atol %s ..." % (want["rtol"], want["atol"]))
        shutil.rmtree(d, ignore_errors=True)
        summaries = {}
        for m in ("abm", "rk8pd"):
            s, note = run_swim(scene_path, os.path.join(d, m), T, dt, m, REF_EXP, REF_EXP + 2, False)
            if s is None or s["status"] != "completed":
                shutil.rmtree(d, ignore_errors=True)
                raise RefFailed("reference run %s at rtol %s failed: %s" % (
                    m, want["rtol"], note or s["reason"]))
            summaries[m] = {k: s[k] for k in ("status", "reason", "integrator", "energy_drift_rel")}
            summaries[m]["stats"] = s["stats"]
        meta = dict(want, summaries=summaries)
        with open(meta_path, "w") as fh:
            json.dump(meta, fh, indent=1)
    else:
        log("  reference: reused %s" % os.path.relpath(d, ROOT))
    ref = load_traj(os.path.join(d, "abm", "trajectory.csv"))
    alt = load_traj(os.path.join(d, "rk8pd", "trajectory.csv"))
    eg, ef, note = compare(alt, ref)
    if note:
        raise RefFailed("the two reference runs do not compare: %s" % note)
    return ref, alt, eg, ef, meta


# ---------------------------------------------------------------------------------------------
# sweep

def configs_for(scene, quick):
    exps = QUICK_EXPS if quick else TOL_EXPS
    gexps = QUICK_GENERIC_EXPS if quick else GENERIC_EXPS
    methods = NONSTIFF_METHODS + (STIFF_METHODS if scene in STIFFISH else [])
    out = [Config(scene, m, "specialized", e, e + 2, "sweep") for m in methods for e in exps]
    out += [Config(scene, m, "generic", e, e + 2, "sweep") for m in GENERIC_METHODS for e in gexps]
    # MATLAB ode113's defaults, with abm's STEP rule (ode113 has no look-ahead)
    out.append(Config(scene, "abm-step", "specialized", 3, 6, "ode113"))
    return out


def first_run(c, scene_path, out, T, dt, ref, alt):
    s, note = run_swim(scene_path, out, T, dt, c.integrator, c.rexp, c.aexp, c.kernel == "generic")
    r = dict(status="failed", reason=note, err_grid=float("nan"), err_final=float("nan"),
             energy_drift_rel=float("nan"), rhs_evaluations="", steps="", rejected_steps="",
             order_histogram="", stiffness_suspected="", error_vs="abm-ref", kernel_used="",
             integrator_used="")
    c.result = r
    if s is None:
        return False
    st = s["stats"]
    r.update(reason=s["reason"], energy_drift_rel=s["energy_drift_rel"],
             rhs_evaluations=st["rhs_evaluations"], steps=st["steps"],
             rejected_steps=st["rejected_steps"], stiffness_suspected=st.get("stiffness_suspected", ""),
             kernel_used=s["kernel"]["kind"], integrator_used=s["integrator"])
    if c.integrator in ("abm", "abm-step", "msadams", "cvode-adams", "cvode-bdf", "msbdf"):
        r["order_histogram"] = " ".join(str(v) for v in st.get("order_histogram", []))
    if s["kernel"]["kind"] != c.kernel:
        r["reason"] = "asked for the %s kernel, got %s" % (c.kernel, s["kernel"]["kind"])
        return False
    traj = load_traj(os.path.join(out, "trajectory.csv"))
    against = ref
    if c.integrator == "abm" and c.kernel == "specialized" and c.rexp == REF_EXP and c.aexp == REF_EXP + 2:
        against, r["error_vs"] = alt, "rk8pd-ref"      # this run is the reference itself
    eg, ef, cnote = compare(traj, against)
    r["err_grid"], r["err_final"] = eg, ef
    if s["status"] != "completed":
        return False
    if cnote:
        r["reason"] = cnote
        return False
    if not (eg <= 1.0):
        r["reason"] = "error %.3g > 1 (reached t_end but wrong)" % eg
        return False
    r["status"] = "completed"
    c.cpu.append(st["integrate_seconds"])
    c.wall.append(st["wall_seconds"])
    c.outside.append(st["integrate_seconds"] - st["rhs_seconds"])
    return True


def repeat_run(c, scene_path, out, T, dt):
    s, note = run_swim(scene_path, out, T, dt, c.integrator, c.rexp, c.aexp, c.kernel == "generic")
    if s is None or s["status"] != "completed":
        c.nondeterministic = True      # failed now, completed before: note it, keep the timings
        return
    if s["stats"]["rhs_evaluations"] != c.result["rhs_evaluations"]:
        c.nondeterministic = True
    c.cpu.append(s["stats"]["integrate_seconds"])
    c.wall.append(s["stats"]["wall_seconds"])
    c.outside.append(s["stats"]["integrate_seconds"] - s["stats"]["rhs_seconds"])


# ---------------------------------------------------------------------------------------------
# cost to reach a target error

def cost_to_reach(points, target):
    """points: (cost, err) of the completed runs of one curve. Returns (cost, kind) with kind
    "interp" (log-log interpolation on the monotone envelope between the last point above the
    target and the cheapest point reaching it), "bound" (the cheapest run is already below the
    target: its cost is an upper bound) or None if no run reaches the target."""
    pts = sorted((c, e) for c, e in points if c > 0 and e == e)
    env, best = [], float("inf")
    for c, e in pts:                       # monotone envelope: running minimum of the error
        best = min(best, e)
        env.append((c, best))
    for j, (c, e) in enumerate(env):
        if e <= target:
            if j == 0:
                return c, "bound"
            c0, e0 = env[j - 1]
            if e <= 0:
                return c, "interp"
            f = (np.log(target) - np.log(e0)) / (np.log(e) - np.log(e0))
            return float(np.exp(np.log(c0) + f * (np.log(c) - np.log(c0)))), "interp"
    return None


UNRESOLVED = 10.0      # a target below UNRESOLVED * reference uncertainty is marked "†"


def fmt_cost(res, scale, digits, dagger=False):
    if res is None:
        return "–"
    v, kind = res
    s = ("%.*g" % (digits, v * scale)) if scale != 1 else "%d" % round(v)
    return ("≤" if kind == "bound" else "") + s + ("†" if dagger else "")


# ---------------------------------------------------------------------------------------------
# outputs

CSV_FIELDS = ["scene", "t_end", "integrator", "kernel", "series", "rtol", "atol", "status", "reason",
              "err_grid", "err_final", "error_vs", "ref_err_grid", "energy_drift_rel",
              "rhs_evaluations", "steps", "rejected_steps", "cpu_ms_median", "cpu_ms_min",
              "cpu_ms_max", "outside_rhs_us_per_step", "repeats", "wall_s_median", "deterministic", "order_histogram",
              "stiffness_suspected", "integrator_used"]


def csv_rows(scenes_data):
    rows = []
    for sd in scenes_data:
        for c in sd["configs"]:
            r = c.result
            ok = r["status"] == "completed"
            rows.append(dict(
                scene=c.scene, t_end=sd["T"], integrator=c.integrator, kernel=c.kernel,
                series=c.series, rtol=tol_str(c.rexp), atol=tol_str(c.aexp), status=r["status"],
                reason=r["reason"], err_grid="%.4g" % r["err_grid"], err_final="%.4g" % r["err_final"],
                error_vs=r["error_vs"], ref_err_grid="%.4g" % sd["ref_err_grid"],
                energy_drift_rel="%.4g" % r["energy_drift_rel"] if r["energy_drift_rel"] != "" else "",
                rhs_evaluations=r["rhs_evaluations"], steps=r["steps"],
                rejected_steps=r["rejected_steps"],
                cpu_ms_median="%.4f" % (1e3 * statistics.median(c.cpu)) if ok else "",
                cpu_ms_min="%.4f" % (1e3 * min(c.cpu)) if ok else "",
                cpu_ms_max="%.4f" % (1e3 * max(c.cpu)) if ok else "",
                outside_rhs_us_per_step="%.3f" % (1e6 * statistics.median(c.outside) / max(1, r["steps"]))
                if ok else "",
                repeats=len(c.cpu), wall_s_median="%.4f" % statistics.median(c.wall) if ok else "",
                deterministic="" if not ok else ("no" if c.nondeterministic else "yes"),
                order_histogram=r["order_histogram"], stiffness_suspected=r["stiffness_suspected"],
                integrator_used=r["integrator_used"]))
    return rows


def short_reason(reason, n=70):
    reason = reason.split(":")[0] if reason.startswith("stiffness detected") else reason
    return reason if len(reason) <= n else reason[:n - 1] + "…"


def mean_order(hist):
    h = [int(v) for v in hist.split()] if hist else []
    n = sum(h)
    return sum(i * v for i, v in enumerate(h)) / n if n else float("nan")


def curve_label(integrator, kernel):
    return integrator if kernel == "specialized" else integrator + " (generic)"


def build_table(scenes_data, repeat, elapsed=None, exps=TOL_EXPS):
    L = []
    L.append("# Work-precision: what accuracy costs, per paper scene")
    L.append("")
    L.append("Generated by `tests/bench/bench_accuracy.py` (repeat %d%s). Horizon T = min(t_end, 10), "
             "output every T/100. Error = max abs difference of the state columns (x, y, theta, "
             "shape coordinates and velocities) over the output grid, vs the abm reference at rtol "
             "1e-13/atol 1e-15. Sweep rtol %s, atol = rtol*1e-2. CPU = median of "
             "stats.integrate_seconds (ms). Costs to reach 1e-6 / 1e-9 / 1e-12 are interpolated "
             "log-log on the monotone envelope of each curve; \"≤x\": the loosest run "
             "already beats the target (x is an upper bound); \"–\": never reached in the "
             "tolerance range; \"†\": the target is below 10x the scene's reference uncertainty, "
             "so that cost is only indicative. GSL steppers (rk8pd, msadams, msbdf) stop at every "
             "output time, so rk8pd never takes fewer than ~100 steps (~1300 RHS) here. "
             "\"outside the RHS\" = integrate_seconds - rhs_seconds (step logic, interpolation and, "
             "for abm, the projection). cvode-* use Debian's unoptimized SUNDIALS build: compare them on RHS "
             "evaluations." % (repeat, "" if elapsed is None else ", %.0f s" % elapsed,
                                ", ".join(tol_str(e) for e in exps)))
    L.append("")
    # winners overview
    L.append("## Cheapest specialized integrator per target (CPU ms / RHS evaluations)")
    L.append("")
    hdr = "| scene | ref. uncertainty |" + "".join(" %s: CPU | %s: RHS |" % (texp(t), texp(t)) for t in TARGETS)
    L.append(hdr)
    L.append("|" + "---|" * (2 + 2 * len(TARGETS)))
    for sd in scenes_data:
        cells = ["%s" % sd["scene"], "%.1e%s" % (sd["ref_err_grid"], "" if sd["ref_err_grid"] <= REF_CONVERGED
                                                 else " NOT converged")]
        for t in TARGETS:
            for key, scale in (("cpu", 1e3), ("rhs", 1)):
                best = None
                for (m, k), cur in sd["curves"].items():
                    if k != "specialized" or m in VARIANTS:
                        continue
                    res = cur["reach"][key][t]
                    if res is not None and (best is None or res[0] < best[1][0]):
                        best = (m, res)
                cells.append("–" if best is None else "%s %s" % (
                    best[0], fmt_cost(best[1], scale, 3, t < UNRESOLVED * sd["ref_err_grid"])))
        L.append("| " + " | ".join(cells) + " |")
    L.append("")
    # each variant against the integrator it varies, at equal error
    for var, (base, extra) in VARIANTS.items():
        L.append("## %s / %s at equal error (specialized kernels)" % (base, var))
        L.append("")
        L.append("Ratios of the interpolated costs to reach each target (< 1: %s is cheaper); %s is %s "
                 "with `%s`." % (base, var, base, " ".join(extra)))
        L.append("")
        L.append("| scene |" + "".join(" %s: RHS | %s: CPU |" % (texp(t), texp(t)) for t in TARGETS))
        L.append("|---|" + "---|---|" * len(TARGETS))
        logs = {"rhs": [], "cpu": []}
        for sd in scenes_data:
            a, b = sd["curves"].get((base, "specialized")), sd["curves"].get((var, "specialized"))
            if not a or not b:
                continue
            cells = [sd["scene"]]
            for t in TARGETS:
                for key in ("rhs", "cpu"):
                    ra, rb = a["reach"][key][t], b["reach"][key][t]
                    if (ra is None or rb is None or "bound" in (ra[1], rb[1])
                            or t < UNRESOLVED * sd["ref_err_grid"]):
                        cells.append("–")
                    else:
                        logs[key].append(np.log(ra[0] / rb[0]))
                        cells.append("%.2f" % (ra[0] / rb[0]))
            L.append("| " + " | ".join(cells) + " |")
        L.append("")
        L.append("Geometric mean over the resolved targets: RHS %.3f, CPU %.3f (%d targets)." % (
            np.exp(np.mean(logs["rhs"])) if logs["rhs"] else float("nan"),
            np.exp(np.mean(logs["cpu"])) if logs["cpu"] else float("nan"), len(logs["rhs"])))
        L.append("")
    for sd in scenes_data:
        conv = sd["ref_err_grid"] <= REF_CONVERGED
        L.append("## %s (T = %g)" % (sd["scene"], sd["T"]))
        L.append("")
        L.append("Reference: abm vs rk8pd at rtol 1e-13/atol 1e-15 differ by %.2e over the grid (%.2e at "
                 "t = T): %s" % (sd["ref_err_grid"], sd["ref_err_final"],
                                  "converged." if conv else
                                  "**reference NOT converged (> 1e-9)**: errors below this are not "
                                  "meaningful."))
        if any(t < UNRESOLVED * sd["ref_err_grid"] for t in TARGETS):
            L.append("† target below 10x the reference uncertainty: indicative only (and biased towards "
                     "abm, whose errors are measured against an abm reference).")
        L.append("")
        L.append("| integrator | " + " | ".join("CPU ms @%s | RHS @%s" % (texp(t), texp(t)) for t in TARGETS)
                 + " | best error (rtol) | failures |")
        L.append("|---|" + "---|---|" * len(TARGETS) + "---|---|")
        for (m, k), cur in sd["curves"].items():
            cells = [curve_label(m, k)]
            for t in TARGETS:
                dag = t < UNRESOLVED * sd["ref_err_grid"]
                cells.append(fmt_cost(cur["reach"]["cpu"][t], 1e3, 3, dag))
                cells.append(fmt_cost(cur["reach"]["rhs"][t], 1, 0, dag))
            ok = [c for c in cur["configs"] if c.result["status"] == "completed"]
            if ok:
                b = min(ok, key=lambda c: c.result["err_grid"])
                cells.append("%.1e (%s)" % (b.result["err_grid"], tol_str(b.rexp)))
            else:
                cells.append("–")
            fails = ["rtol %s: %s" % (tol_str(c.rexp), short_reason(c.result["reason"]))
                     for c in cur["configs"] if c.result["status"] != "completed"]
            nd = [tol_str(c.rexp) for c in cur["configs"] if c.nondeterministic]
            if nd:
                fails.append("RHS count differed between repetitions at " + ", ".join(nd))
            cells.append("; ".join(fails) if fails else "")
            L.append("| " + " | ".join(cells) + " |")
        L.append("")
        o = sd["ode113"].result
        if o["status"] == "completed":
            L.append("ode113 defaults (abm-step, rtol 1e-3, atol 1e-6, the paper's MATLAB setting): "
                     "%.3g ms CPU, %s RHS evaluations, %s steps (%s rejected), error %.2e over the grid, "
                     "%.2e at t = T, energy drift %.2e (relative)." % (
                         1e3 * statistics.median(sd["ode113"].cpu), o["rhs_evaluations"], o["steps"],
                         o["rejected_steps"], o["err_grid"], o["err_final"], o["energy_drift_rel"]))
        else:
            L.append("ode113 defaults (abm-step, rtol 1e-3, atol 1e-6): FAILED: %s" % o["reason"])
        # abm's behaviour at three tolerances: what explains its position
        parts = []
        rk = {c.rexp: c for c in sd["curves"].get(("rk8pd", "specialized"), {}).get("configs", [])}
        for c in sd["curves"].get(("abm", "specialized"), {}).get("configs", []):
            if c.rexp in (6, 9, 12) and c.result["status"] == "completed":
                txt = "rtol %s: %s steps, %s rejected, mean order %.1f, %.1f µs/step outside the RHS" % (
                    tol_str(c.rexp), c.result["steps"], c.result["rejected_steps"],
                    mean_order(c.result["order_histogram"]),
                    1e6 * statistics.median(c.outside) / max(1, c.result["steps"]))
                r = rk.get(c.rexp)
                if r is not None and r.result["status"] == "completed":
                    txt += " (rk8pd: %s steps, %.1f µs/step)" % (
                        r.result["steps"], 1e6 * statistics.median(r.outside) / max(1, r.result["steps"]))
                parts.append(txt)
        if parts:
            L.append("")
            L.append("abm (specialized): " + "; ".join(parts) + ".")
        L.append("")
    return "\n".join(L) + "\n"


def curves(configs, ref_err):
    """Group the sweep configurations of one scene into curves with their reach costs."""
    out = {}
    for c in configs:
        if c.series != "sweep":
            continue
        out.setdefault((c.integrator, c.kernel), {"configs": []})["configs"].append(c)
    for cur in out.values():
        ok = [c for c in cur["configs"] if c.result["status"] == "completed"]
        cur["reach"] = {
            "cpu": {t: cost_to_reach([(statistics.median(c.cpu), c.result["err_grid"]) for c in ok], t)
                    for t in TARGETS},
            "rhs": {t: cost_to_reach([(c.result["rhs_evaluations"], c.result["err_grid"]) for c in ok], t)
                    for t in TARGETS}}
    return out


# ---------------------------------------------------------------------------------------------

def scene_horizon(path, override):
    with open(path, "rb") as fh:
        t_end = tomllib.load(fh).get("run", {}).get("t_end", HORIZON)
    return override if override else min(float(t_end), HORIZON)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", help="comma-separated scene names (default: all paper scenes)")
    ap.add_argument("--quick", action="store_true", help="smoke run: 2 scenes, 3 tolerances, repeat 1")
    ap.add_argument("--repeat", type=int, default=None, help="timing repetitions (default 5; 1 with --quick)")
    ap.add_argument("--t-end", type=float, default=None, help="bench horizon (default min(t_end, 10))")
    ap.add_argument("--out", default=None, help="output directory (default build/bench/accuracy, "
                    "build/bench/accuracy/quick with --quick)")
    a = ap.parse_args(argv)
    repeat = a.repeat if a.repeat is not None else (1 if a.quick else 5)
    if repeat < 1:
        ap.error("--repeat must be >= 1")
    scenes = a.scenes.split(",") if a.scenes else (QUICK_SCENES if a.quick else SCENES)
    for s in scenes:
        if not os.path.exists(os.path.join(ROOT, "models", s + ".toml")):
            ap.error("no scene models/%s.toml" % s)
    if not os.access(SWIM_SRC, os.X_OK):
        raise SystemExit("bench_accuracy: %s missing; run `make` first" % SWIM_SRC)
    base = os.path.join(ROOT, "build", "bench", "accuracy")
    outdir = a.out or (os.path.join(base, "quick") if a.quick else base)
    os.makedirs(outdir, exist_ok=True)
    ref_root = os.path.join(base, "ref")
    tmp = tempfile.mkdtemp(prefix="swim-accuracy-")
    # Bench one binary throughout: a private copy. It finds the generator and the kernel headers
    # from its own location, which is no longer the tree's, so they are named (SWIM_SHARE); the
    # kernel cache is SWIM_CACHE's as for bin/swim. References are checked against bin/swim's
    # time stamp as it was when the copy was made.
    os.environ.setdefault("SWIM_SHARE", ROOT)
    global SWIM, SWIM_STAMP
    SWIM = os.path.join(tmp, "swim")
    for attempt in range(10):              # bin/swim may be mid-rebuild: wait for a working copy
        SWIM_STAMP = os.path.getmtime(SWIM_SRC)
        shutil.copy2(SWIM_SRC, SWIM)
        if subprocess.run([SWIM, "--help"], capture_output=True).returncode == 0:
            break
        time.sleep(3)
    else:
        raise SystemExit("bench_accuracy: %s does not run (`make` first?)" % SWIM_SRC)
    t0 = time.monotonic()

    def log(msg):
        print("[%6.1fs] %s" % (time.monotonic() - t0, msg), file=sys.stderr, flush=True)

    scenes_data, skipped = [], []
    try:
        for scene in scenes:
            path = os.path.join("models", scene + ".toml")
            T = scene_horizon(os.path.join(ROOT, path), a.t_end)
            dt = T / ROWS
            log("%s: T = %g, output step %g" % (scene, T, dt))
            try:
                ref, alt, eg, ef, _ = reference(scene, os.path.join(ROOT, path), T, dt, ref_root, log)
            except RefFailed as e:
                log("  %s: SKIPPED: %s" % (scene, e))
                skipped.append((scene, str(e)))
                continue
            cfgs = configs_for(scene, a.quick)
            out = os.path.join(tmp, "run")
            for rep in range(repeat):
                for c in cfgs:
                    if rep == 0:
                        first_run(c, path, out, T, dt, ref, alt)
                    elif c.result["status"] == "completed":
                        repeat_run(c, path, out, T, dt)
                log("  %s: repetition %d/%d of %d configurations done" % (scene, rep + 1, repeat, len(cfgs)))
            nfail = sum(c.result["status"] != "completed" for c in cfgs)
            if nfail:
                log("  %d configuration(s) failed" % nfail)
            scenes_data.append(dict(scene=scene, T=T, ref_err_grid=eg, ref_err_final=ef, configs=cfgs,
                                    curves=curves(cfgs, eg),
                                    ode113=[c for c in cfgs if c.series == "ode113"][0]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    rows = csv_rows(scenes_data)
    csv_path = os.path.join(outdir, "accuracy.csv")
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS)
        w.writeheader()
        w.writerows(rows)
    elapsed = time.monotonic() - t0
    table = build_table(scenes_data, repeat, elapsed, QUICK_EXPS if a.quick else TOL_EXPS)
    if skipped:
        table += "\n## Scenes skipped (no reference)\n\n" + "".join(
            "- %s: %s\n" % (sc, why) for sc, why in skipped)
    if os.path.getmtime(SWIM_SRC) != SWIM_STAMP:
        table += ("\nNote: bin/swim was rebuilt during this run; the numbers are for the binary as it "
                  "was at the start.\n")
    with open(os.path.join(outdir, "table.md"), "w") as fh:
        fh.write(table)
    pngs = plot_accuracy.plot(csv_path, outdir) if rows else []
    print(table)
    print("wrote %s, %s/table.md, %s (%.0f s)" % (os.path.relpath(csv_path, ROOT), os.path.relpath(outdir, ROOT),
                                                 ", ".join(os.path.relpath(p, ROOT) for p in pngs), elapsed))
    return 1 if skipped else 0


if __name__ == "__main__":
    sys.exit(main())
