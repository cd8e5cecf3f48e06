#!/usr/bin/env python3
"""`swim cache list|clean` never follow a symbolic link named like an entry: the folder it points
to (outside the cache) keeps everything it holds, the link is reported as what it is (never as
"in use by a build"), and a real entry beside it is still cleaned.
Prints "test_trust_cache_links: P passed, F failed"."""

import os
import shutil
import subprocess
import sys

from swimtest import ROOT, SWIM, TMP, check, main

BASE = os.path.join(TMP, "cache-links")


def swim(env, *args):
    return subprocess.run([SWIM, *args], capture_output=True, text=True, cwd=ROOT, env=env)


def setup():
    shutil.rmtree(BASE, ignore_errors=True)
    cache, victim = os.path.join(BASE, "cache"), os.path.join(BASE, "victim")
    os.makedirs(cache, mode=0o700)
    os.makedirs(victim, mode=0o700)
    for name in ("precious.txt", "lock", "manifest"):    # an entry's names too: nothing is special
        with open(os.path.join(victim, name), "w") as fh:
            fh.write("keep me\n")
    os.makedirs(os.path.join(victim, "sub"))
    with open(os.path.join(victim, "sub", "deep.txt"), "w") as fh:
        fh.write("keep me too\n")
    os.symlink(victim, os.path.join(cache, "0123456789abcdef"))
    # a file named like an entry, and a real (partial) entry that clean may remove
    with open(os.path.join(cache, "fedcba9876543210"), "w") as fh:
        fh.write("not a folder\n")
    real = os.path.join(cache, "00000000000000aa")
    os.makedirs(real, mode=0o700)
    with open(os.path.join(real, "build.log"), "w") as fh:
        fh.write("half a build\n")
    return cache, victim, real


def victim_files(victim):
    return sorted(os.path.relpath(os.path.join(d, f), victim) for d, _, fs in os.walk(victim) for f in fs)


def test_clean_never_follows_a_link():
    cache, victim, real = setup()
    before = victim_files(victim)
    env = dict(os.environ, SWIM_CACHE=cache)
    p = swim(env, "cache", "list")
    check(p.returncode == 0 and "symbolic link" in p.stdout, "cache list names the link: %d %r" % (p.returncode, p.stdout))
    p = swim(env, "cache", "clean")
    check(p.returncode == 0, "cache clean: exit %d %s" % (p.returncode, p.stderr))
    check(victim_files(victim) == before, "cache clean removed files outside the cache: %s -> %s"
          % (before, victim_files(victim)))
    check(os.path.islink(os.path.join(cache, "0123456789abcdef")), "the link itself is left alone")
    check(os.path.isfile(os.path.join(cache, "fedcba9876543210")), "a file named like an entry is left alone")
    check(not os.path.exists(real), "the real entry beside them is removed")
    check("in use by a build" not in p.stdout and "2 not entry folders" in p.stdout,
          "clean reports the link and the file as not entries: %r" % p.stdout)
    p = swim(env, "cache", "clean", "--older-than", "0")
    check(p.returncode == 0 and victim_files(victim) == before, "clean --older-than 0 leaves the link's folder alone")


def test_entry_folder_a_link_is_not_used():
    """A kernel lookup does not take an entry that is a link for a folder of the cache."""
    cache, victim, real = setup()
    env = dict(os.environ, SWIM_CACHE=cache)
    # inspect with linked-in kernels needs no entry; listing checks the entry as a load would
    p = swim(env, "cache", "list")
    line = [l for l in p.stdout.splitlines() if l.startswith("0123456789abcdef")]
    check(len(line) == 1 and "damaged" in line[0] and "0.0 k" in line[0],
          "the link is listed as not an entry, its target not measured: %r" % line)


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_cache_links"))
