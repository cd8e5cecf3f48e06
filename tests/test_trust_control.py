#!/usr/bin/env python3
"""Can a user believe what swim floquet, swim inspect and swim run --sensitivity report? End-to-end
checks of the control commands under the ways a run goes wrong or is asked wrongly: a prescribed
stroke given to floquet, a run that is not periodic, a stopping event or a signal during a run with
sensitivities, a report to a full stdout, repeated options, bad --set overrides and option values.
Bad input is exit status 2 and one line naming the option, key or value; an output that could not
be written (stdout included) is exit status 1 and named.
Prints "test_trust_control: P passed, F failed".
"""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main, one_line, scene, swim

EXAMPLE3 = os.path.join(ROOT, "models", "example3.toml")
STROKE = os.path.join(ROOT, "models", "stroke_loop.toml")
BASE = open(EXAMPLE3).read()
DAMPING = '\n[damping]\ndiagonal = [0,0,0.3,0.3,0.3,0.3,0,0,0,0,0,0,0,0,0,0]\n'





def refused(p, what, *words):
    """Exit 2 and exactly one line on stderr that contains every word."""
    line = p.stderr.strip()
    check(p.returncode == 2, "%s: exit 2 (got %d, %r)" % (what, p.returncode, line))
    check(one_line(p), "%s: one line on stderr (%r)" % (what, line))
    for w in words:
        check(w in line, "%s: the line names %r (%r)" % (what, w, line))


# ---- reports to a full stdout -------------------------------------------------------------------

def full_stdout(*args):
    with open("/dev/full", "w") as full:
        return subprocess.run([SWIM, *args], stdout=full, stderr=subprocess.PIPE, text=True, cwd=ROOT)


def test_reports_to_full_stdout():
    cases = {
        "inspect": ["inspect", "--modes", "1", "--shape", "1,0,0.2,0"],
        "floquet": ["floquet", EXAMPLE3, "--out", os.path.join(TMP, "full-floquet"), "--quiet"],
        # (no --quiet: it prints nothing, so it has nothing to lose)
        "run": ["run", EXAMPLE3, "--out", os.path.join(TMP, "full-run"), "--t-end", "0.2"],
        "stroke run": ["run", STROKE, "--out", os.path.join(TMP, "full-stroke"), "--set", "run.t_end=0.2"],
        "help": ["--help"],
        "command help": ["floquet", "--help"],
    }
    for what, args in cases.items():
        p = full_stdout(*args)
        check(p.returncode == 1, "%s > /dev/full: exit 1 (got %d)" % (what, p.returncode))
        # a run without --quiet may first say where its kernel came from (the cache, or generated
        # now on a cold cache): a notice, not the error
        errors = [ln for ln in p.stderr.splitlines()
                  if not (ln.startswith("swim: ") and "kernel" in ln and ("cache" in ln or "generat" in ln))]
        check(len(errors) == 1 and "stdout" in errors[0], "%s > /dev/full: one line naming stdout (%r)" % (what, p.stderr))


# ---- --set overrides and bad option values ------------------------------------------------------

def test_set_errors_name_the_override():
    out = os.path.join(TMP, "set-errors")
    for ov, key in [("run.foo=1", "run.foo"), ("run.t_end=-1", "run.t_end"), ("model.rho0=-2", "model.rho0"),
                    ("elastic.stiffness[2]=-1", "elastic.stiffness")]:
        for cmd in (["run", EXAMPLE3, "--out", out], ["floquet", EXAMPLE3, "--out", out]):
            p = swim(*cmd, "--set", ov, "--quiet")
            refused(p, "%s --set %s" % (cmd[0], ov), "--set " + ov, key)
            check(":0:" not in p.stderr, "%s --set %s: no line 0 of the file (%r)" % (cmd[0], ov, p.stderr))


def test_bad_option_values_one_line():
    out = os.path.join(TMP, "bad-values")
    for v in ["nan", "inf", "-1", "0", "x"]:
        refused(swim("floquet", EXAMPLE3, "--out", out, "--t-max", v), "floquet --t-max %s" % v, "--t-max", v)
    refused(swim("optimize", EXAMPLE3, "--vary", "model.rho0=0.5:2", "--maximize", "x", "--tol", "nan"),
            "optimize --tol nan", "--tol")


# ---- swim floquet: prescribed strokes and orbits that do not close -----------------------------

def test_floquet_refuses_a_prescribed_stroke():
    for sc in [STROKE, os.path.join(ROOT, "models", "stroke_completed.toml"),
               os.path.join(ROOT, "models", "control", "stroke_phase.toml")]:
        out = os.path.join(TMP, "floquet-stroke-" + os.path.basename(sc))
        p = swim("floquet", sc, "--out", out, "--quiet")
        refused(p, "floquet on %s" % os.path.basename(sc), "[stroke]", sc)
        check(not os.path.exists(out), "floquet on a stroke: nothing written (%s)" % out)


def test_floquet_orbit_that_does_not_close():
    for name, extra in [("damped", DAMPING),
                        ("forced", '\n[forcing]\nlaw = "0.5*sin(1.3*t)"\n'
                                   'direction = [0,0,1,0,0,1,0,0,0,0,0,0,0,0,0,0]\n')]:
        out = os.path.join(TMP, "floquet-" + name)
        p = swim("floquet", scene(name, BASE + extra), "--out", out, "--quiet")
        check(p.returncode == 1, "floquet %s: exit 1 (got %d)" % (name, p.returncode))
        check(one_line(p) and "no periodic orbit" in p.stderr, "floquet %s: one line: no periodic orbit (%r)"
              % (name, p.stderr))
        check("UNSTABLE" not in p.stdout and "stable" not in p.stdout.lower().replace("unstable", ""),
              "floquet %s: no stability verdict (%r)" % (name, p.stdout[-200:]))
        path = os.path.join(out, "floquet.json")
        d = json.load(open(path)) if os.path.exists(path) else {}
        check(d.get("periodic") is False and d.get("stable", 0) is None,
              "floquet %s: floquet.json kept, periodic false, stable null (%s)" % (name, d.get("periodic")))
    p = swim("floquet", EXAMPLE3, "--out", os.path.join(TMP, "floquet-ex3"), "--quiet")
    d = json.load(open(os.path.join(TMP, "floquet-ex3", "floquet.json"))) if p.returncode == 0 else {}
    check(p.returncode == 0 and d.get("periodic") is True and d.get("stable") is True,
          "floquet example3: a closed orbit is periodic and stable (exit %d)" % p.returncode)


def test_sensitivity_on_a_stroke_refused():
    out = os.path.join(TMP, "stroke-sens")
    for opt in [["--sensitivity", "parameters.A"], ["--sensitivity-steps", "state"]]:
        p = swim("run", STROKE, "--out", out, "--quiet", *opt)
        refused(p, "stroke run %s" % opt[0], opt[0], "prescribed stroke")
        check("unknown option" not in p.stderr, "stroke run %s: not 'unknown option' (%r)" % (opt[0], p.stderr))
    h = swim("run", "--help")
    check("--sensitivity" in h.stdout and "without --sensitivity" in h.stdout,
          "swim run --help says --sensitivity is not for prescribed strokes")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_control"))
