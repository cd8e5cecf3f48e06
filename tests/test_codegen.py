#!/usr/bin/env python3
"""Run-time kernel generation and its cache (runtime/codegen), through bin/swim.

- Any N: a scene copied from example3 with modes raised to 10 and 20 runs without a rebuild
  (kernels generated on first use, reused afterwards); `swim inspect --modes 20` works.
  N = 32 too when SWIM_TEST_N32=1 (slow on a fresh cache: see docs/kernels-and-cache.md).
- A damaged entry is detected before it is loaded and rebuilt, with one line on stderr:
  truncated kernel.so, empty kernel.c, a manifest for another key.
- Four processes starting on an empty cache at once: one builds, the others wait and load it;
  every run is correct and the cache holds one entry, with no temporary files left.
- A cache that cannot be written: the run still completes, using a private temporary folder (removed),
  and says so in one line.
Prints "test_codegen: P passed, F failed".
"""

import glob
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main


def scene_with_modes(N, name):
    """example3 with N modes: same shape, the new coordinates locked at 0."""
    text = open(os.path.join(ROOT, "models", "example3.toml")).read()
    n = 2 * (N + 1)

    def vec(line_key, values):
        nonlocal text
        vals = values + [0] * (n - len(values))
        text = re.sub(r"(?m)^%s\s*=\s*\[.*\]" % line_key,
                      "%s = [%s]" % (line_key, ", ".join(repr(v) for v in vals)), text)

    text = re.sub(r"(?m)^modes = \d+", "modes = %d" % N, text)
    vec("c0 ", [1, 0, 0.4, 0, 0, 0.2])
    vec("dc0", [0, 0, 0.6, 0, 0, -0.6])
    vec("stiffness", [0, 0, 1, 1, 2, 2])
    vec("reference", [1, 0, 0.4899, 0])
    path = os.path.join(TMP, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def swim_run(scene, out, env, *args):
    p = subprocess.run([SWIM, "run", scene, "--out", os.path.join(TMP, out), "--quiet", "--t-end", "1", *args],
                       capture_output=True, text=True, cwd=ROOT, env=env)
    summary = None
    path = os.path.join(TMP, out, "summary.json")
    if os.path.exists(path):
        with open(path) as fh:
            summary = json.load(fh)
    return p, summary


def final_y(out):
    rows = np.genfromtxt(os.path.join(TMP, out, "trajectory.csv"), delimiter=",", names=True)
    return rows["y"][-1]


def env_with(cache):
    return dict(os.environ, SWIM_CACHE=cache)


def test_any_modes():
    modes = [10, 20] + ([32] if os.environ.get("SWIM_TEST_N32") == "1" else [])
    env = dict(os.environ)   # the suite's cache (build/cache under make test)
    y7 = None
    p, s = swim_run(os.path.join(ROOT, "models", "example3.toml"), "n7", env)
    if s:
        y7 = s["final_state"]["y"]
    for N in modes:
        scene = scene_with_modes(N, "example3_n%d" % N)
        p, s = swim_run(scene, "n%d" % N, env)
        check(p.returncode == 0 and s and s["status"] == "completed",
              "N = %d: scene did not run: %s" % (N, p.stderr[-400:]))
        if not s:
            continue
        check(len(s["final_state"]["c"]) == 2 * (N + 1), "N = %d: %d coordinates" % (N, len(s["final_state"]["c"])))
        # the added modes stay at 0, so the motion is Example 3's (N = 7)
        check(y7 is not None and abs(s["final_state"]["y"] - y7) < 1e-9,
              "N = %d: y(1) = %r, Example 3 (N = 7) gives %r" % (N, s["final_state"]["y"], y7))
        p, s = swim_run(scene, "n%d-again" % N, env)
        check(s and s["kernel"]["from_cache"], "N = %d: second run did not reuse the kernel" % N)
    shape = ",".join(["1", "0", "0.2", "0.1"] + ["0.0005", "0"] * 19)
    p = subprocess.run([SWIM, "inspect", "--modes", "20", "--shape", shape], capture_output=True, text=True, env=env)
    check(p.returncode == 0, "inspect --modes 20 failed: %s" % p.stderr[-300:])
    if p.returncode == 0:
        K = np.array(json.loads(p.stdout)["mass_reduced"])
        check(K.shape == (42, 42) and np.allclose(K, K.T, rtol=0, atol=0), "inspect --modes 20: K not 42x42 symmetric")


def fresh(name):
    cache = os.path.join(TMP, name)
    shutil.rmtree(cache, ignore_errors=True)
    return cache


def entry(cache):
    dirs = [d for d in glob.glob(os.path.join(cache, "*")) if os.path.exists(os.path.join(d, "manifest"))]
    return dirs[0] if len(dirs) == 1 else None


def notice_lines(stderr):
    return [l for l in stderr.splitlines() if "damaged" in l]


def test_damaged_entries():
    scene = os.path.join(ROOT, "models", "example1.toml")
    cache = fresh("cache-damage")
    env = env_with(cache)
    p, s = swim_run(scene, "dmg0", env)
    ref = final_y("dmg0") if s else None
    d = entry(cache)
    check(d is not None, "one cache entry after the first run")
    if not d:
        return
    cases = [
        ("truncated kernel.so", "kernel.so", lambda path: open(path, "r+b").truncate(os.path.getsize(path) // 3)),
        ("empty kernel.so", "kernel.so", lambda path: open(path, "w").close()),
        ("empty kernel.c", "kernel.c", lambda path: open(path, "w").close()),
        ("manifest for another key", "manifest", None),
    ]
    for i, (label, fname, damage) in enumerate(cases):
        path = os.path.join(d, fname)
        if fname == "manifest":
            text = open(path).read()
            with open(path, "w") as fh:
                fh.write(re.sub(r"(?m)^key ", "key other ", text))
        else:
            damage(path)
        p, s = swim_run(scene, "dmg%d" % (i + 1), env)
        ok = p.returncode == 0 and s and s["status"] == "completed"
        check(ok, "%s: the run failed (exit %d): %s" % (label, p.returncode, p.stderr[-300:]))
        check(len(notice_lines(p.stderr)) == 1, "%s: want one line saying the entry is damaged, got %r" % (label, p.stderr))
        check(s is not None and not s["kernel"]["from_cache"], "%s: the entry was not rebuilt" % label)
        check(ok and final_y("dmg%d" % (i + 1)) == ref, "%s: the rebuilt kernel gives another trajectory" % label)
        p, s = swim_run(scene, "dmg%d-after" % (i + 1), env)
        check(s is not None and s["kernel"]["from_cache"] and not notice_lines(p.stderr),
              "%s: the rebuilt entry is not reused quietly" % label)


def test_concurrent_first_use():
    scene = os.path.join(ROOT, "models", "example5.toml")
    cache = fresh("cache-concurrent")
    env = env_with(cache)
    procs = [subprocess.Popen([SWIM, "run", scene, "--out", os.path.join(TMP, "conc%d" % i), "--quiet", "--t-end", "1"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env)
             for i in range(4)]
    results = [p.communicate() + (p.returncode,) for p in procs]
    check(all(rc == 0 for _, _, rc in results), "concurrent runs: exit codes %r" % [r[2] for r in results])
    summaries = []
    for i in range(4):
        path = os.path.join(TMP, "conc%d" % i, "summary.json")
        if os.path.exists(path):
            summaries.append(json.load(open(path)))
    check(len(summaries) == 4 and all(s["status"] == "completed" for s in summaries), "concurrent runs: not all completed")
    check(sum(not s["kernel"]["from_cache"] for s in summaries) == 1,
          "concurrent runs: %d of 4 built the kernel, want 1" % sum(not s["kernel"]["from_cache"] for s in summaries))
    ys = {final_y("conc%d" % i) for i in range(len(summaries))}
    check(len(ys) == 1, "concurrent runs: different trajectories %r" % ys)
    dirs = glob.glob(os.path.join(cache, "*"))
    check(len(dirs) == 1, "concurrent runs: %d cache entries, want 1" % len(dirs))
    leftovers = [f for d in dirs for f in os.listdir(d) if "tmp" in f]
    check(not leftovers, "concurrent runs: temporary files left: %r" % leftovers)
    check(not any("damaged" in e for _, e, _ in results), "concurrent runs: an entry was seen as damaged")


def test_read_only_cache():
    scene = os.path.join(ROOT, "models", "example2a.toml")
    if os.geteuid() != 0:
        cache = fresh("cache-ro")
        os.makedirs(cache)
        os.chmod(cache, 0o555)
    else:   # root writes through permissions: a cache under /proc cannot be created at all
        cache = "/proc/self/swim-cache"
    p, s = swim_run(scene, "ro", env_with(cache))
    check(p.returncode == 0 and s and s["status"] == "completed", "read-only cache: run failed: %s" % p.stderr[-300:])
    lines = [l for l in p.stderr.splitlines() if "cannot be written" in l]
    check(len(lines) == 1, "read-only cache: want one line saying so, got %r" % p.stderr)
    # built in a private folder that is gone with the run: the summary names no cache entry
    check(s is not None and s["kernel"]["cache"] == "" and not s["kernel"]["from_cache"],
          "read-only cache: the summary names a cache entry: %r" % (s and s["kernel"]))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_codegen"))
