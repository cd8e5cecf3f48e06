#!/usr/bin/env python3
"""Scene-specialized kernels, through `swim run`.

(The generated right-hand side itself is checked against the independent loop reference in
tests/test_rhs.c, for every kind of kernel.)
- `--generic` runs the generated kernel that carries every coordinate (locks by multipliers).
- An effect the scene lacks generates no code (checked in the emitted source); the forcing law
  reaches the kernel whole, however long.
- The kernel cache is keyed by the scene's structure: changing c0, dc0 or t_end reuses it;
  changing which coordinates are free regenerates it.
Prints "test_specialized: P passed, F failed".
"""

import glob
import os
import sys

import numpy as np

import swimtest
from swimtest import ROOT, TMP, check, main

# the suite's kernel cache (make test's build/cache); test_cache starts an empty one of its own
ENV = dict(os.environ)


def run(scene, name, *args, env=None):
    return swimtest.run(scene, name, *args, env=env or ENV)


SCENES = {"example1": 10, "example2a": 10, "example2b": 10, "example2c": 10, "example3": 10,
          "example4": 10, "example5": 10, "example6": 10, "example7": 5, "selfpropelled": 20}


def test_generic_kernel():
    for name in ("example1", "selfpropelled"):
        scene = "models/%s.toml" % name
        _, _, ss = run(scene, name + "-spec", "--t-end", "1")
        _, _, sg = run(scene, name + "-gen", "--t-end", "1", "--generic")
        check(ss["kernel"]["kind"] == "specialized" and sg["kernel"]["kind"] == "generic",
              "%s: kernel kinds %s / %s" % (name, ss["kernel"]["kind"], sg["kernel"]["kind"]))
        check(ss["status"] == "completed" and sg["status"] == "completed", "%s: both runs complete" % name)
        check(sg["kernel"]["state_dimension"] == 4 + 2 * 16,
              "%s: generic state carries %d entries, want 36" % (name, sg["kernel"]["state_dimension"]))
        n_free = len(ss["free"])
        check(ss["kernel"]["state_dimension"] == 4 + 2 * n_free,
              "%s: specialized state carries %d entries, want %d" % (name, ss["kernel"]["state_dimension"], 4 + 2 * n_free))
        diff = max(abs(a - b) for a, b in zip(ss["final_state"]["c"], sg["final_state"]["c"]))
        check(diff < 1e-6, "%s: final shapes of the two kernels differ by %.3g" % (name, diff))


def test_long_law():
    """A forcing law of more than 600 characters is simulated whole: the scene keeps it in an
    owned string of any length, and the generated kernel carries every term of it."""
    import re
    text = open(os.path.join(ROOT, "models", "selfpropelled.toml")).read()
    law = " + ".join("0.%018d*sin(%d*t)" % (123456789 * k, k) for k in range(1, 25))
    assert len(law) > 600
    text = re.sub(r'(?m)^law\s*=.*$', 'law = "%s"' % law, text)
    path = os.path.join(TMP, "longlaw.toml")
    with open(path, "w") as fh:
        fh.write(text)
    p, _, s = run(path, "longlaw", "--t-end", "0.2")
    check(p.returncode == 0 and s and s["status"] == "completed", "long law: run failed: %s" % p.stderr[-300:])
    if s:
        src = kernel_source(s)
        check("sin(24*t)" in src and law in src, "long law: the kernel does not carry the whole law")


def kernel_source(summary):
    with open(os.path.join(summary["kernel"]["cache"], "kernel.c")) as fh:
        return fh.read()


def test_effects_absent_generate_no_code():
    _, _, s3 = run("models/example3.toml", "fx3", "--t-end", "1")
    src = kernel_source(s3)
    check("p->damping" not in src, "example3 (no damping): the kernel has damping code")
    check("p->direction" not in src, "example3 (no forcing): the kernel has forcing code")
    check("SWIM_SCENE_BARRIER" not in src and "jacobian_circle" not in src, "example3 (no barrier): barrier code emitted")
    check("p->stiffness" in src, "example3 (elastic): W1 code missing")
    _, _, s1 = run("models/example1.toml", "fx1", "--t-end", "1")
    check("p->stiffness" not in kernel_source(s1), "example1 (no elasticity): W1 code emitted")
    _, _, s7 = run("models/selfpropelled.toml", "fx7", "--t-end", "1")
    src = kernel_source(s7)
    check("p->damping" in src and "p->direction" in src and "SWIM_SCENE_BARRIER" in src,
          "selfpropelled: damping, forcing and barrier code expected")
    check("atan(t)" in src, "selfpropelled: the forcing law is compiled into the kernel")


def scene_variant(name, change):
    text = open(os.path.join(ROOT, "models", "example1.toml")).read()
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(change(text))
    return path


def test_cache():
    env = dict(ENV, SWIM_CACHE=os.path.join(TMP, "fresh-cache"))   # start empty
    cache_runs = []
    base = scene_variant("c-base", lambda s: s)
    for label, path, args in [
        ("first run", base, []),
        ("same scene", base, []),
        ("other c0 and dc0", scene_variant("c-c0", lambda s: s.replace("c0  = [ 1, 0, 0.5,", "c0  = [ 1, 0, 0.45,")
                                           .replace("-0.35355339059327373", "-0.3")), []),
        ("other t_end and tolerance", base, ["--t-end", "2", "--rtol", "1e-9"]),
        ("more free coordinates", scene_variant("c-free", lambda s: s.replace('"bm2"]', '"bm2", "am3", "bm3"]')), []),
        ("elasticity added", scene_variant("c-el", lambda s: s.replace("[run]", "[elastic]\nstiffness = [0,0,1,1,1,1,0,0,0,0,0,0,0,0,0,0]\nreference = [1,0,0.5,0,0,0,0,0,0,0,0,0,0,0,0,0]\n\n[run]")), []),
    ]:
        _, _, s = run(path, "cache-" + label.replace(" ", "-"), *(args or ["--t-end", "1"]), env=env)
        cache_runs.append((label, s["kernel"]["from_cache"], s["kernel"]["cache"]))
    expect = [False, True, True, True, False, False]
    for (label, hit, _), want in zip(cache_runs, expect):
        check(hit == want, "cache: %s: from_cache = %s, want %s" % (label, hit, want))
    dirs = {c for _, _, c in cache_runs}
    check(len(dirs) == 3, "cache: %d kernels for 3 structures" % len(dirs))
    check(len(glob.glob(os.path.join(env["SWIM_CACHE"], "*", "kernel.so"))) == 3, "cache: 3 compiled kernels")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_specialized"))
