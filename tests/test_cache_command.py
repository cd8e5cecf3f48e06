#!/usr/bin/env python3
"""`swim cache path|list|clean`: the cache a run used is the one `path` names, `list` shows its
entries with their state (a damaged one as damaged), `clean --older-than` keeps what was used
recently and `clean` empties it; the cache key names the processor and the compiler's version,
which is asked of the compiler (a `cc --version` child) only when the compiler's stamp in the
cache's .identity no longer matches the program PATH finds; the hash of the generator's sources
is read again only when a file's stamp changes. Prints "test_cache_command: P passed, F failed"."""

import glob
import os
import shutil
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


def test_compiler_identity_kept():
    """cc --version runs once; again only when the compiler found on PATH is another file or
    was changed; and never for a cache it could not trust (there the identity is not kept)."""
    cache, bindir = os.path.join(TMP, "idcache"), os.path.join(TMP, "fakecc")
    os.makedirs(bindir)
    log, real = os.path.join(TMP, "cc.log"), shutil.which("cc")
    wrapper = os.path.join(bindir, "cc")

    def write_wrapper(extra):
        with open(wrapper, "w") as fh:   # logs --version calls, compiles with the real compiler
            fh.write('#!/bin/sh\n[ "$1" = --version ] && echo v >> %s\n%s\nexec %s "$@"\n' % (log, extra, real))
        os.chmod(wrapper, 0o755)

    def run():
        env = dict(ENV, SWIM_CACHE=cache, PATH=bindir + os.pathsep + os.environ["PATH"])
        p = subprocess.run([SWIM, "run", "models/example3.toml", "--out", os.path.join(TMP, "idrun"), "--t-end", "0.1",
                            "--summary-only", "--quiet"], capture_output=True, text=True, cwd=ROOT, env=env)
        check(p.returncode == 0, "run with the wrapper compiler: exit %d %s" % (p.returncode, p.stderr))
        return open(log).read().count("v") if os.path.exists(log) else 0

    write_wrapper("")
    check(run() == 1, "the first run asks the compiler its version once")
    kept = open(os.path.join(cache, ".identity")).read()
    check(kept.startswith("cc " + wrapper + " ") or ("\ncc " + wrapper + " ") in kept,
          "the version is kept with the stamp of the compiler PATH found: %r" % kept)
    check(run() == 1 and run() == 1, "later runs do not ask again")
    write_wrapper("# changed")   # another size and modification time
    check(run() == 2, "a changed compiler is asked again")
    check(run() == 2, "... once")
    entries = glob.glob(os.path.join(cache, "*", "manifest"))
    check(len(entries) == 1, "the same version makes the same key: one entry, found %d" % len(entries))
    os.chmod(cache, 0o777)   # a cache others can write: nothing read from it, nothing kept
    try:
        env = dict(ENV, SWIM_CACHE=cache, PATH=bindir + os.pathsep + os.environ["PATH"])
        before = open(log).read().count("v")
        subprocess.run([SWIM, "run", "models/example3.toml", "--out", os.path.join(TMP, "idrun2"), "--t-end", "0.1",
                        "--summary-only", "--quiet"], capture_output=True, text=True, cwd=ROOT, env=env)
        check(open(log).read().count("v") == before + 1, "an untrusted cache's .identity is not used")
    finally:
        os.chmod(cache, 0o700)


def test_sources_hash_kept():
    """The hash of generator/ and runtime/kernel/ is kept with their files' stamps: a file touched
    (a new stamp, the same bytes) reuses the kernel without building; a file whose bytes change
    gives a new key and a new entry."""
    share, cache = os.path.join(TMP, "share"), os.path.join(TMP, "srccache")
    for sub in ("generator", os.path.join("runtime", "kernel")):
        shutil.copytree(os.path.join(ROOT, sub), os.path.join(share, sub),
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    env = dict(ENV, SWIM_CACHE=cache, SWIM_SHARE=share)

    def run():
        p = subprocess.run([SWIM, "run", "models/example3.toml", "--out", os.path.join(TMP, "srcrun"), "--t-end", "0.1",
                            "--summary-only", "--quiet"], capture_output=True, text=True, cwd=ROOT, env=env)
        check(p.returncode == 0, "run with a copied share folder: exit %d %s" % (p.returncode, p.stderr))
        line = [l for l in open(os.path.join(cache, ".identity")).read().splitlines() if l.startswith("sources ")]
        return len(glob.glob(os.path.join(cache, "*", "manifest"))), line[0] if line else ""

    entries, first = run()
    check(entries == 1 and first.startswith("sources ") and share in first, "the sources' hash is kept: %r" % first)
    header = os.path.join(share, "runtime", "kernel", "coords.h")
    os.utime(header, None)
    entries, touched = run()
    check(entries == 1 and touched != first and touched.split("\t")[1] == first.split("\t")[1],
          "a touched file: new stamp, same hash, no new entry (%d entries; %r, %r)" % (entries, first, touched))
    with open(header, "a") as fh:
        fh.write("/* changed */\n")
    entries, changed = run()
    check(entries == 2 and changed.split("\t")[1] != first.split("\t")[1],
          "a changed file: a new hash and a new entry (%d entries)" % entries)


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
