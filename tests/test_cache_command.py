#!/usr/bin/env python3
"""`swim cache path|list|clean`: the cache a run used is the one `path` names, `list` shows its
entries with their state (a damaged one as damaged), `clean --older-than` keeps what was used
recently and `clean` empties it; the cache key names the processor and the compiler's version.
Prints "test_cache_command: P passed, F failed"."""

import glob
import os
import subprocess
import sys
import time

from swimtest import ROOT, SWIM, TMP, check, main

CACHE = os.path.join(TMP, "cache")
ENV = dict(os.environ, SWIM_CACHE=CACHE)


def swim(*args):
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, env=ENV)


def test_path_list_clean():
    p = swim("run", "models/example3.toml", "--out", os.path.join(TMP, "run"), "--t-end", "0.5", "--quiet")
    check(p.returncode == 0, "run: exit %d %s" % (p.returncode, p.stderr))
    p = swim("cache", "path")
    check(p.returncode == 0 and p.stdout.strip() == CACHE, "cache path: %r" % p.stdout)
    entries = glob.glob(os.path.join(CACHE, "*", "manifest"))
    check(len(entries) == 1, "one entry after one run, found %d" % len(entries))
    p = swim("cache", "list")
    check(p.returncode == 0 and "sound" in p.stdout and "1 entries" in p.stdout, "cache list: " + p.stdout)
    key = open(entries[0]).read()
    check(" cpu=" in key and " ccversion=" in key and "ccversion=unknown" not in key,
          "the cache key should name the processor and the compiler version: " + key)
    # damage kernel.so: list says so
    so = os.path.join(os.path.dirname(entries[0]), "kernel.so")
    with open(so, "r+b") as fh:
        fh.seek(100)
        fh.write(b"\xff\xfe")
    p = swim("cache", "list")
    check("damaged" in p.stdout, "cache list should show the damaged entry: " + p.stdout)
    p = swim("cache", "clean", "--older-than", "1d")
    check(p.returncode == 0 and "removed 0 entries" in p.stdout, "clean --older-than 1d removed a fresh entry: " + p.stdout)
    old = time.time() - 3 * 86400
    os.utime(entries[0], (old, old))
    p = swim("cache", "clean", "--older-than", "2d")
    check(p.returncode == 0 and "removed 1 entries" in p.stdout and not glob.glob(os.path.join(CACHE, "*")),
          "clean --older-than 2d should remove a 3-day-old entry: " + p.stdout)


def test_bad_input():
    for args, want in ((["cache"], "expected one of"), (["cache", "purge"], "purge"),
                       (["cache", "clean", "--older-than", "soon"], "soon"),
                       (["cache", "list", "--older-than", "1"], "clean only")):
        p = swim(*args)
        check(p.returncode == 2 and want in p.stderr and len(p.stderr.strip().splitlines()) == 1,
              "swim %s: exit %d %r" % (" ".join(args), p.returncode, p.stderr))


def test_full_stdout():
    with open("/dev/full", "w") as full:
        p = subprocess.run([SWIM, "cache", "list"], stdout=full, stderr=subprocess.PIPE, text=True, env=ENV)
    check(p.returncode == 1 and "stdout" in p.stderr, "cache list > /dev/full: exit %d %s" % (p.returncode, p.stderr))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_cache_command"))
