#!/usr/bin/env python3
"""swim optimize evaluates every candidate through the run driver, as swim run runs a scene: the
value it reports for its best candidate is what `swim run DIR/best.toml` gives, to the last bit,
on a scene with a barrier (restarts near the wall, energy control in the error test), on a forced
scene's forcing work, and on a prescribed stroke."""
import json
import os
import subprocess
import sys

import swimtest
from swimtest import ROOT, SWIM, TMP, check, run

BARRIER = os.path.join("models", "control", "selfpropelled_params.toml")
STROKE = os.path.join("models", "control", "stroke_phase.toml")


def optimize(name, scene, *args):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "optimize", scene, "--out", out, "--quiet", *args], capture_output=True, text=True,
                       cwd=ROOT)
    path = os.path.join(out, "optimize.json")   # exit 1 when not converged in --max-iter: still written
    data = json.load(open(path)) if p.returncode in (0, 1) and os.path.exists(path) else None
    return p, out, data


def final(summary, quantity):
    s = summary["final_state"]
    return {"x": s["x"], "y": s["y"], "theta": s["theta"], "forcing_work": summary.get("forcing_work")}[quantity]


def check_reproduced(name, scene, quantity, *args):
    p, out, d = optimize(name, scene, *args)
    check(d is not None, "%s: optimize runs: %s" % (name, p.stderr.strip()[-300:]))
    if not d:
        return
    q, _, summary = run(os.path.join(out, "best.toml"), name + "_best")
    check(q.returncode == 0 and summary is not None, "%s: swim run best.toml completes: %s" % (name, q.stderr.strip()))
    if summary:
        got = final(summary, quantity)
        check(got == d["value"], "%s: swim run best.toml gives the reported %s to the last bit (%r vs %r)"
              % (name, quantity, got, d["value"]))


def test_barrier_scene():
    # selfpropelled_params has a barrier: its runs use the tolerance cut, the shifted origin and
    # the energy balance in abm's error test; the evaluations must too
    check_reproduced("barrier_y", BARRIER, "y", "--set", "run.t_end=2", "--vary", "parameters.A=1:3",
                     "--maximize", "y", "--max-iter", "2")


def test_forcing_work():
    check_reproduced("barrier_fw", BARRIER, "forcing_work", "--set", "run.t_end=2", "--vary", "parameters.w=0.2:0.5",
                     "--minimize", "forcing_work", "--max-iter", "2")


def test_stroke():
    check_reproduced("stroke_y", STROKE, "y", "--vary", "parameters.phi=-1.2:1.2", "--minimize", "y", "--max-iter", "2")


if __name__ == "__main__":
    os.chdir(ROOT)
    sys.exit(swimtest.main(globals(), "test_optimize_reproduces"))
