#!/usr/bin/env python3
"""Trust checks of the tools around `swim run`: paths of any length where the user names them
(`swim run --out`, the scene path, `swim sweep --out`, `swim flow`) land exactly where asked,
and scene keys whose value names an integrator are held to what the value must be able to do.
Bad input is exit status 2 and one line naming file, key and value; an output that could not be
written is exit status 1.
Prints "test_trust_tools: P passed, F failed".
"""

import json
import os
import subprocess
import sys

from swimtest import ROOT, SWIM, TMP, check, main, one_line, scene, swim

BASE = open(os.path.join(ROOT, "models", "example3.toml")).read()





def with_run_key(line):
    return BASE.replace("atol = 1e-12", "atol = 1e-12\n" + line)


def test_stiff_fallback_must_be_implicit():
    """Only an implicit integrator can take over where ABM's stiffness diagnostic fires: every
    other registry name (ABM itself, the explicit and PECE ones) is refused up front."""
    for value in ("abm", "cvode-adams", "rk8pd", "rkf45", "msadams"):
        path = scene("fallback_" + value, with_run_key('stiff_fallback = "%s"' % value))
        p = swim("run", path, "--out", os.path.join(TMP, "fallback_" + value), "--t-end", "0.5", "--quiet")
        err = p.stderr.strip()
        check(p.returncode == 2 and one_line(p) and path in err and "run.stiff_fallback" in err
              and '"%s"' % value in err and ":%d:" % (BASE.count("\n", 0, BASE.index("atol = 1e-12")) + 2) in err,
              "stiff_fallback = %s: exit %d, %r" % (value, p.returncode, err))
        check(not os.path.exists(os.path.join(TMP, "fallback_" + value)), "stiff_fallback = %s: no output folder" % value)
    path = scene("fallback_number", with_run_key("stiff_fallback = 3"))
    p = swim("run", path, "--out", os.path.join(TMP, "fallback_number"), "--quiet")
    check(p.returncode == 2 and one_line(p) and "run.stiff_fallback" in p.stderr, "stiff_fallback = 3: %r" % p.stderr)


def test_stiff_fallback_implicit_accepted():
    for value in ("msbdf", "cvode-bdf", "none"):
        path = scene("fallback_ok_" + value, with_run_key('stiff_fallback = "%s"' % value))
        out = os.path.join(TMP, "fallback_ok_" + value)
        p = swim("run", path, "--out", out, "--t-end", "0.5", "--quiet")
        check(p.returncode == 0 and os.path.exists(os.path.join(out, "summary.json")),
              "stiff_fallback = %s: exit %d, %r" % (value, p.returncode, p.stderr))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_tools"))
