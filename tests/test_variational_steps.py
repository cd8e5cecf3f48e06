#!/usr/bin/env python3
"""The variational equations ride on the run's own integration (driver/run.h, swim_run_variational).

For Example 3, Example 7 and the Section 5.2 scene with parameters (models/control/
selfpropelled_params.toml at A = 2.25, w = 0.55, whose run shifts its origin near the barrier):
trajectory.csv is byte-identical with and without --sensitivity and --lyapunov (the default
--sensitivity-steps state keeps them out of the error control); the run integrates once: the
state's counters are those of the run without them, and the sensitivities took one Jacobian per
evaluation of that one integration. --sensitivity-steps all puts them in the error test (the
steps change). An integrator that cannot keep them out is refused, one line, exit 2.
Prints "test_variational_steps: P passed, F failed".
"""

import json
import os
import subprocess
import sys

from swimtest import ROOT, SWIM, TMP, check, main

SCENES = {
    "example3": ("models/example3.toml", ["--t-end", "4"], "model.rhof,elastic.stiffness.am1"),
    "example7": ("models/example7.toml", ["--t-end", "3"], "model.rhof"),
    "shifted": ("models/control/selfpropelled_params.toml",
                ["--t-end", "30", "--set", "parameters.A=2.25", "--set", "parameters.w=0.55"], "parameters.A"),
}


def run(scene, name, *args):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet"] + list(args), capture_output=True, text=True,
                       cwd=ROOT)
    path = os.path.join(out, "summary.json")
    return p, out, (json.load(open(path)) if os.path.exists(path) else None)


def trajectory(out):
    with open(os.path.join(out, "trajectory.csv"), "rb") as fh:
        return fh.read()


def test_bit_identical_and_once():
    for tag, (scene, args, keys) in SCENES.items():
        p0, out0, s0 = run(scene, tag + "_plain", *args)
        check(p0.returncode == 0, "%s: the plain run completes (%s)" % (tag, p0.stderr.strip()[-200:]))
        if p0.returncode != 0:
            continue
        if tag == "shifted":
            check(s0["origin_shift"]["restarts"] >= 1, "%s: the run shifts its origin (%s)" % (tag, s0["origin_shift"]))
        base = trajectory(out0)
        for what, extra in (("sens", ["--sensitivity", keys]), ("lyap", ["--lyapunov"]),
                            ("both", ["--sensitivity", keys, "--lyapunov"])):
            p, out, s = run(scene, "%s_%s" % (tag, what), *(args + extra))
            check(p.returncode == 0, "%s %s: completes (%s)" % (tag, what, p.stderr.strip()[-200:]))
            if p.returncode != 0:
                continue
            check(trajectory(out) == base, "%s %s: trajectory.csv byte-identical to the run without" % (tag, what))
            st, st0 = s["stats"], s0["stats"]
            check(st["steps"] == st0["steps"] and st["rhs_evaluations"] == st0["rhs_evaluations"],
                  "%s %s: the state's steps and evaluations (%d, %d) as without (%d, %d)"
                  % (tag, what, st["steps"], st["rhs_evaluations"], st0["steps"], st0["rhs_evaluations"]))
            if "sens" in what or what == "both":
                se = s["sensitivity"]
                check(se["status"] == "written" and se["jacobians"] == st["rhs_evaluations"],
                      "%s %s: one integration: %d Jacobians for the run's %d evaluations (%s)"
                      % (tag, what, se["jacobians"], st["rhs_evaluations"], se["status"]))
                with open(os.path.join(out, "sensitivity.csv")) as fh:
                    nrows = sum(1 for _ in fh) - 1
                check(nrows == s["rows"], "%s %s: a sensitivity row per trajectory row (%d, %d)" % (tag, what, nrows, s["rows"]))
            if "lyap" in what or what == "both":
                check(s["lyapunov"]["status"] == "written" and s["lyapunov"]["t_end"] == s["t_reached"],
                      "%s %s: lyapunov.csv up to the run's end (%s)" % (tag, what, s["lyapunov"].get("t_end")))


def test_steps_all_changes_steps():
    scene, args, keys = SCENES["example3"]
    _, _, s0 = run(scene, "example3_plain", *args)
    p, out, s = run(scene, "example3_all", *(args + ["--sensitivity", keys, "--sensitivity-steps", "all"]))
    check(p.returncode == 0 and s is not None, "--sensitivity-steps all completes (%s)" % p.stderr.strip()[-200:])
    if s and s0:
        check(s["stats"]["steps"] > s0["stats"]["steps"],
              "--sensitivity-steps all: the sensitivities in the error test take more steps (%d vs %d)"
              % (s["stats"]["steps"], s0["stats"]["steps"]))


def test_integrator_that_cannot():
    scene, args, keys = SCENES["example3"]
    for extra, word in ((["--sensitivity", keys], "--sensitivity"), (["--lyapunov"], "--lyapunov")):
        out = os.path.join(TMP, "refused")
        p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet", "--integrator", "rk8pd"] + args + extra,
                           capture_output=True, text=True, cwd=ROOT)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(lines) == 1 and word in lines[0] and "rk8pd" in lines[0] and "abm" in lines[0],
              "%s on rk8pd: one line, exit 2: %r" % (word, p.stderr))
        check(not os.path.exists(out), "%s on rk8pd: nothing written" % word)
    p, out, s = run(scene, "rk8pd_all", "--integrator", "rk8pd", "--sensitivity", keys, "--sensitivity-steps", "all", *args)
    check(p.returncode == 0 and s and s["sensitivity"]["status"] == "written",
          "rk8pd with --sensitivity-steps all: the sensitivities in its error test (%s)" % p.stderr.strip()[-200:])


if __name__ == "__main__":
    sys.exit(main(globals(), "test_variational_steps"))
