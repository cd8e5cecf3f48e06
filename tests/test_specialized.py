#!/usr/bin/env python3
"""Scene-specialized kernels (issue 5), through `swim run`.

- For every paper scene, the specialized run and the generic run (locks through the multipliers
  of (4.12)) agree to the integration tolerance on the whole trajectory.
- An effect the scene lacks generates no code (checked in the emitted source).
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

ENV = dict(os.environ, SWIM_CACHE=os.path.join(TMP, "cache"))


def run(scene, name, *args):
    return swimtest.run(scene, name, *args, env=ENV)


SCENES = {"example1": 10, "example2a": 10, "example2b": 10, "example2c": 10, "example3": 10,
          "example4": 10, "example5": 10, "example6": 10, "example7": 5, "selfpropelled": 20}


def test_agreement():
    for name, t_end in SCENES.items():
        scene = "models/%s.toml" % name
        ps, ds, ss = run(scene, name + "-spec", "--t-end", str(t_end), "--rtol", "1e-11", "--atol", "1e-13")
        pg, dg, sg = run(scene, name + "-gen", "--t-end", str(t_end), "--rtol", "1e-11", "--atol", "1e-13", "--generic")
        check(ss["kernel"]["kind"] == "specialized" and sg["kernel"]["kind"] == "generic",
              "%s: kernel kinds %s / %s" % (name, ss["kernel"]["kind"], sg["kernel"]["kind"]))
        check(ss["status"] == "completed" and sg["status"] == "completed", "%s: both runs complete" % name)
        cols = [c for c in ds.dtype.names if c != "t"][: 3 + 2 * 16]   # rigid motion, shape, velocity
        diff = max(np.max(np.abs(ds[c] - dg[c])) for c in cols)
        check(len(ds) == len(dg) and diff <= 1e-7,
              "%s: specialized vs generic differ by %.3g over the trajectory" % (name, diff))
        n_free = len(ss["free"])
        check(ss["kernel"]["state_dimension"] == 4 + 2 * n_free,
              "%s: specialized state carries %d entries, want %d" % (name, ss["kernel"]["state_dimension"], 4 + 2 * n_free))


def kernel_source(summary):
    with open(os.path.join(summary["kernel"]["cache"], "kernel.c")) as fh:
        return fh.read()


def test_effects_absent_generate_no_code():
    _, _, s3 = run("models/example3.toml", "fx3", "--t-end", "1")
    src = kernel_source(s3)
    check("p->damping" not in src, "example3 (no damping): the kernel has damping code")
    check("forcing_law" not in src, "example3 (no forcing): the kernel has a forcing law")
    check("p->barrier" not in src and "static int barrier_sums" not in src, "example3 (no barrier): barrier code emitted")
    check("p->stiffness" in src, "example3 (elastic): W1 code missing")
    _, _, s1 = run("models/example1.toml", "fx1", "--t-end", "1")
    check("p->stiffness" not in kernel_source(s1), "example1 (no elasticity): W1 code emitted")
    _, _, s7 = run("models/selfpropelled.toml", "fx7", "--t-end", "1")
    src = kernel_source(s7)
    check("p->damping" in src and "forcing_law" in src and "p->barrier" in src,
          "selfpropelled: damping, forcing and barrier code expected")
    check("atan(t)" in src, "selfpropelled: the forcing law is compiled into the kernel")


def scene_variant(name, change):
    text = open(os.path.join(ROOT, "models", "example1.toml")).read()
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(change(text))
    return path


def test_cache():
    ENV["SWIM_CACHE"] = os.path.join(TMP, "fresh-cache")   # start empty
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
        _, _, s = run(path, "cache-" + label.replace(" ", "-"), "--t-end", "1", *args)
        cache_runs.append((label, s["kernel"]["from_cache"], s["kernel"]["cache"]))
    expect = [False, True, True, True, False, False]
    for (label, hit, _), want in zip(cache_runs, expect):
        check(hit == want, "cache: %s: from_cache = %s, want %s" % (label, hit, want))
    dirs = {c for _, _, c in cache_runs}
    check(len(dirs) == 3, "cache: %d kernels for 3 structures" % len(dirs))
    check(len(glob.glob(os.path.join(ENV["SWIM_CACHE"], "*", "kernel.so"))) == 3, "cache: 3 compiled kernels")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_specialized"))
