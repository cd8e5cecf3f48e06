#!/usr/bin/env python3
"""[parameters] in forcing laws, end to end.

A law written with named parameters gives the run of the same law written with numbers; a value
changed by --set parameters.NAME or by swim sweep --vary parameters.NAME reuses the kernel (the
structure key holds the names, not the values) and gives the run of a file with that value; the
interpreter that checks the law (finite at t = 0) reads the values too; unknown names in a law,
names the grammar takes, and non-numbers are one line naming file, key and name, exit 2.
Prints "test_parameters: P passed, F failed".
"""

import csv
import os
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main

EX3 = open(os.path.join(ROOT, "models", "example3.toml")).read()
LITERAL = 'law = "0.5 * sin(2 * t) * exp(-t / 4)"'
NAMED = 'law = "A * sin(w * t) * exp(-t / tau)"'


def scene(name, law, params=None, t_end=4.0):
    """Example 3 forced along a_-1 and b_-2 by `law`, with an optional [parameters] table."""
    text = EX3.replace("t_end = 30.0", "t_end = %r" % t_end)
    if params is not None:
        text += "\n[parameters]\n" + "".join("%s = %r\n" % kv for kv in params.items())
    text += ("\n[forcing]\n%s\ndirection = [ 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 ]\n"
             % law)
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def cache_entries():
    d = os.environ.get("SWIM_CACHE")
    return len(os.listdir(d)) if d and os.path.isdir(d) else -1


def columns(rows):
    return np.array([rows[k] for k in ("x", "y", "theta", "am1", "bm2", "energy", "work")])


def test_named_law_equals_literal_law():
    lit = scene("literal", LITERAL)
    par = scene("named", NAMED, {"A": 0.5, "w": 2.0, "tau": 4.0})
    p0, r0, s0 = swimtest.run(lit, "literal")
    p1, r1, s1 = swimtest.run(par, "named")
    check(p0.returncode == 0 and p1.returncode == 0, "both runs complete: %s %s" % (p0.stderr, p1.stderr))
    if r0 is None or r1 is None:
        return
    a, b = columns(r0), columns(r1)
    err = np.max(np.abs(a - b))
    check(err < 1e-9, "a law with parameters gives the run of the same law with numbers (max diff %.2g)" % err)
    check(abs(r1["work"][-1]) > 1e-3, "the forcing does work (%.3g)" % r1["work"][-1])


def test_set_parameter_reuses_kernel_and_matches_file():
    par = scene("named2", NAMED, {"A": 0.5, "w": 2.0, "tau": 4.0})
    p, _, s = swimtest.run(par, "warm")
    before = cache_entries()
    p1, r1, s1 = swimtest.run(par, "set", "--set", "parameters.A=0.8", "--set", "parameters.w=1.5")
    check(p1.returncode == 0, "--set parameters.A runs: %s" % p1.stderr)
    check(cache_entries() == before, "changing parameter values generates no new kernel (%d -> %d)"
          % (before, cache_entries()))
    check(s1 is not None and s1["kernel"].get("from_cache") is True, "the kernel comes from the cache")
    filed = scene("named3", NAMED, {"A": 0.8, "w": 1.5, "tau": 4.0})
    p2, r2, _ = swimtest.run(filed, "filed")
    if r1 is None or r2 is None:
        check(False, "rows of both runs")
        return
    check(np.array_equal(columns(r1), columns(r2)), "--set parameters.A=0.8 is bit for bit the file with A = 0.8")
    check(abs(r1["y"][-1] - s["final_state"]["y"]) > 1e-6, "the value changed the run")


def test_interpreter_reads_values():
    good = scene("logok", 'law = "log(t + T0)"', {"T0": 1.0}, t_end=1.0)
    p, _, _ = swimtest.run(good, "logok")
    check(p.returncode == 0, "log(t + T0) with T0 = 1 is finite at t = 0: %s" % p.stderr)
    p, _, _ = swimtest.run(good, "logbad", "--set", "parameters.T0=-1")
    check(p.returncode == 2 and "forcing.law" in p.stderr,
          "log(t + T0) with --set parameters.T0=-1 is refused at t = 0 (exit %d): %s" % (p.returncode, p.stderr))


def bad(name, law, params, *want):
    path = scene(name, law, params)
    p, _, _ = swimtest.run(path, name)
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    check(p.returncode == 2, "%s: exit status 2 (got %d)" % (name, p.returncode))
    check(len(lines) == 1 and all(w in lines[0] for w in (path,) + want),
          "%s: one line naming %s: %r" % (name, want, p.stderr))
    check(not os.path.exists(os.path.join(TMP, name, "summary.json")), "%s: nothing written" % name)


def test_bad_parameters():
    bad("unknown", 'law = "A * sin(W * t)"', {"A": 1.0}, "forcing.law", "'W'")
    bad("reserved", 'law = "sin(t)"', {"exp": 1.0}, "parameters.exp", "taken")
    bad("noparams", 'law = "A * sin(t)"', None, "forcing.law", "'A'")
    path = scene("string", NAMED, {"A": 0.5, "w": 2.0, "tau": 4.0}).replace(".toml", "")
    text = open(path + ".toml").read().replace("w = 2.0", 'w = "fast"')
    with open(path + "s.toml", "w") as fh:
        fh.write(text)
    p, _, _ = swimtest.run(path + "s.toml", "strings")
    check(p.returncode == 2 and "parameters.w" in p.stderr and "number" in p.stderr,
          "a string parameter is refused naming parameters.w: %s" % p.stderr)
    p, _, _ = swimtest.run(scene("noparams2", LITERAL), "noptable", "--set", "parameters.A=1")
    check(p.returncode == 2 and "[parameters]" in p.stderr,
          "--set parameters.A on a scene without [parameters] is refused: %s" % p.stderr)


def test_sweep_varies_parameter():
    par = scene("sweep", NAMED, {"A": 0.5, "w": 2.0, "tau": 4.0}, t_end=2.0)
    out = os.path.join(TMP, "sweepdir")
    p = subprocess.run([SWIM, "sweep", par, "--out", out, "--quiet", "--jobs", "1",
                        "--vary", "parameters.A=0.2,0.9"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 0, "swim sweep --vary parameters.A runs: %s" % p.stderr)
    if p.returncode != 0:
        return
    with open(os.path.join(out, "members.csv")) as fh:
        rows = list(csv.DictReader(fh))
    check(len(rows) == 2, "two members")
    for r in rows:
        a = 0.2 if int(r["id"]) == 0 else 0.9
        _, _, s = swimtest.run(par, "single%d" % int(r["id"]), "--set", "parameters.A=%r" % a)
        check(s is not None and float(r["y"]) == s["final_state"]["y"],
              "member A = %g is the single run with --set (%s vs %s)" % (a, r.get("y"), s and s["final_state"]["y"]))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_parameters"))
