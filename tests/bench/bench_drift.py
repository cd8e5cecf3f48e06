#!/usr/bin/env python3
"""Energy drift over the long conservative runs and what the ABM step-size look-ahead
does to it.

Usage (from the repository root; `make bench-drift` runs it, `make bench` includes it):
    /usr/bin/python3 tests/bench/bench_drift.py [--out DIR]

Scenes: models/hard/long_example1.toml and long_example3.toml (Examples 1 and 3, T = 1000, no
damping, no forcing: the energy is a first integral). The relative energy drift is the summary's
energy_drift_rel, max over the output rows of |E(t) - E(0)| / max |E|. Every number here is
deterministic (a function of the build and the arguments), so nothing is repeated; cost is given
as RHS evaluations, which is what the look-ahead changes (the CPU per evaluation is the same).

1. Tolerance sweep: abm with the look-ahead (default, p = 6) and with STEP's rule (p = 0) at
   rtol 0.8, 0.9, 1, 1.1, 1.25 x 1e-10 (the issue's tolerance and its neighbours: the drift of a
   variable-step code depends on the step sequence, so one tolerance alone can mislead), and at
   1e-11, 1e-12; atol = rtol / 100.
2. Look-ahead p = 0, 2, 4, 6, 8 over the five tolerances around 1e-10: worst drift and mean RHS
   evaluations relative to p = 0.
3. The other integrators at rtol 1e-10 (they have no projection hook, so the constraints drift
   too; their energy drift is listed for scale).
4. Where the drift is made: abm at rtol 1e-10 with --trace-steps (one row per step attempt with
   the energy of each accepted state), p = 0 and p = 6. Each accepted step's energy change is
   put in one class: the step whose estimate grew by more than 1.3 per step (rho of the
   look-ahead, reported for p = 0 as well), the two steps before an error-test failure, the
   rest. The sum of each class is its share of the drift.

Writes DIR/drift.csv (default build/bench/drift) and DIR/table.md and prints the tables. Takes
about 25 s (some 90 runs of 0.1 - 0.6 s)."""

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
SCENES = [("Ex. 1", "models/hard/long_example1.toml"), ("Ex. 3", "models/hard/long_example3.toml")]
NEAR = [0.8e-10, 0.9e-10, 1e-10, 1.1e-10, 1.25e-10]
TIGHT = [1e-11, 1e-12]
LOOKAHEADS = [0, 2, 4, 6, 8]
PEERS = ["rk8pd", "msadams", "cvode-adams"]
BOUND = 1e-8


def swim_args(scene, out, rtol, integrator="abm", lookahead=None):
    args = [SWIM, "run", scene, "--out", out, "--quiet", "--rtol", repr(rtol), "--atol", repr(rtol / 100),
            "--integrator", integrator]
    if lookahead is not None:
        args += ["--step-lookahead", str(lookahead)]
    return args


def run(scene, tmp, rtol, integrator="abm", lookahead=None):
    out = os.path.join(tmp, "run")
    args = swim_args(scene, out, rtol, integrator, lookahead)
    p = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    with open(os.path.join(out, "summary.json")) as fh:
        s = json.load(fh)
    if p.returncode != 0 or s["status"] != "completed":
        sys.exit("bench_drift: %s failed: %s" % (" ".join(args), s["reason"]))
    st = s["stats"]
    return dict(drift=s["energy_drift_rel"], steps=st["steps"], rhs=st["rhs_evaluations"],
                rejected=st["rejected_steps"], residual=max(s["max_residuals"].values()))


def drift_classes(scene, tmp, p):
    """Classify the energy changes of the accepted steps of one traced run (part 4)."""
    trace = os.path.join(tmp, "steps.csv")
    subprocess.run(swim_args(scene, os.path.join(tmp, "traced"), 1e-10, lookahead=p) + ["--trace-steps", trace],
                   cwd=ROOT, check=True, capture_output=True)
    with open(trace) as fh:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(fh)]
    acc = [i for i, r in enumerate(rows) if r["accepted"] == 1]
    prerej, last_two = set(), []
    for i, r in enumerate(rows):
        if r["accepted"] == 1:
            last_two = (last_two + [i])[-2:]
        else:
            prerej.update(last_two)
    e0 = rows[acc[0]]["energy"] - rows[acc[0]]["work"]
    out = dict(steps=len(acc), rejected=len(rows) - len(acc), n_grow=0, grow=0.0, n_prerej=0, prerej=0.0,
               other=0.0, total=0.0)
    for a, b in zip(acc, acc[1:]):
        de = ((rows[b]["energy"] - rows[b]["work"]) - (rows[a]["energy"] - rows[a]["work"])) / e0
        out["total"] += de
        if rows[b]["growth"] > 1.3:
            out["n_grow"] += 1
            out["grow"] += de
        elif b in prerej:
            out["n_prerej"] += 1
            out["prerej"] += de
        else:
            out["other"] += de
    return out


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "drift"))
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="swim-drift-")
    rows, done = [], {}

    def measure(name, scene, rtol, p=None, integrator="abm"):
        """One run (each configuration once), recorded for drift.csv."""
        key = (name, integrator, p, rtol)
        if key not in done:
            done[key] = run(scene, tmp, rtol, integrator, p)
            rows.append(dict(done[key], scene=name, integrator=integrator, lookahead="" if p is None else p,
                             rtol=rtol))
        return done[key]

    L = ["# Energy drift over T = 1000 (`make bench-drift`)", ""]
    # 1. tolerance sweep, look-ahead on and off side by side
    L += ["## abm: relative energy drift (RHS evaluations) with the look-ahead (p = 6) and with "
          "STEP's rule (p = 0)", "",
          "| scene | rtol | p = 6: drift | RHS | rejected | p = 0: drift | RHS | rejected |",
          "|---|---|---|---|---|---|---|---|"]
    for name, scene in SCENES:
        for rtol in NEAR + TIGHT:
            r6, r0 = measure(name, scene, rtol, 6), measure(name, scene, rtol, 0)
            L.append("| %s | %.3g | %.2g%s | %d | %d | %.2g%s | %d | %d |" % (
                name, rtol, r6["drift"], "" if r6["drift"] <= BOUND else " (> 1e-8)", r6["rhs"], r6["rejected"],
                r0["drift"], "" if r0["drift"] <= BOUND else " (> 1e-8)", r0["rhs"], r0["rejected"]))
    # 2. the look-ahead p over the tolerances around 1e-10
    L += ["", "## Look-ahead p: worst drift over rtol %s x 1e-10, RHS evaluations relative to p = 0" %
          ", ".join("%g" % (r * 1e10) for r in NEAR), "",
          "| p | " + " | ".join("%s: worst drift | RHS / RHS(p=0)" % n for n, _ in SCENES) + " |",
          "|---|" + "---|---|" * len(SCENES)]
    for p in LOOKAHEADS:
        cells = []
        for name, scene in SCENES:
            rs = [measure(name, scene, rtol, p) for rtol in NEAR]
            base = sum(measure(name, scene, rtol, 0)["rhs"] for rtol in NEAR)
            cells.append("%.2g | %.3f" % (max(r["drift"] for r in rs), sum(r["rhs"] for r in rs) / base))
        L.append("| %d | %s |" % (p, " | ".join(cells)))
    # 3. the other integrators
    L += ["", "## Other integrators at rtol 1e-10 (no projection: the constraints drift as well)", "",
          "| scene | integrator | energy drift | max constraint residual | RHS |", "|---|---|---|---|---|"]
    for name, scene in SCENES:
        for m in ["abm"] + PEERS:
            r = measure(name, scene, 1e-10, 6) if m == "abm" else measure(name, scene, 1e-10, integrator=m)
            L.append("| %s | %s | %.2g | %.2g | %d |" % (name, m, r["drift"], r["residual"], r["rhs"]))
    # 4. where the drift is made
    L += ["", "## Where the drift is made (rtol 1e-10): sum of the energy changes of the accepted steps "
          "per class, relative to E(0)", "",
          "| scene | p | steps | rejected | growing estimate (rho > 1.3): steps, sum | two steps before "
          "a rejection: steps, sum | other steps: sum | total |", "|---|---|---|---|---|---|---|---|"]
    for name, scene in SCENES:
        for p in (0, 6):
            c = drift_classes(scene, tmp, p)
            L.append("| %s | %d | %d | %d | %d, %+.2g | %d, %+.2g | %+.2g | %+.2g |" % (
                name, p, c["steps"], c["rejected"], c["n_grow"], c["grow"], c["n_prerej"], c["prerej"],
                c["other"], c["total"]))
    text = "\n".join(L) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as fh:
        fh.write(text)
    with open(os.path.join(a.out, "drift.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    shutil.rmtree(tmp, ignore_errors=True)
    print(text)
    print("wrote %s/drift.csv and table.md" % a.out)


if __name__ == "__main__":
    main(sys.argv[1:])
