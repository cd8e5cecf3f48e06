#!/usr/bin/env python3
"""No silent length limits: paths of 600 and 1500 characters (nested folders, each name under
255) are used in full by swim run, swim sweep (scene and --out) and swim flow; a path over the
system's limit (4096) is refused with one line, exit 2, before any work.
Prints "test_trust_paths: P passed, F failed"."""

import os
import shutil
import sys

from swimtest import ROOT, TMP, check, main, one_line, swim

EX1 = os.path.join(ROOT, "models", "example1.toml")


def long_dir(total):
    """A folder path of about `total` characters under TMP, made."""
    parts, length = [], len(TMP)
    while length < total:
        name = "d" * min(200, max(1, total - length - 1))
        parts.append(name)
        length += len(name) + 1
    path = os.path.join(TMP, *parts)
    os.makedirs(path, exist_ok=True)
    return path


def test_long_paths_used_in_full():
    for total in (600, 1500):
        base = long_dir(total)
        scene = os.path.join(base, "scene.toml")
        shutil.copy(EX1, scene)
        run = os.path.join(base, "run")
        p = swim("run", scene, "--out", run, "--t-end", "0.5", "--quiet")
        check(p.returncode == 0 and os.path.exists(os.path.join(run, "summary.json")),
              "run with %d-character paths: exit %d %s" % (total, p.returncode, p.stderr[-200:]))
        p = swim("flow", run, "--frames", "2", "--out", os.path.join(base, "snap.json"))
        check(p.returncode == 0 and os.path.exists(os.path.join(base, "snap.json")),
              "flow with %d-character paths: exit %d %s" % (total, p.returncode, p.stderr[-200:]))
        fam = os.path.join(base, "fam")
        p = swim("sweep", scene, "--out", fam, "--quiet", "--t-end", "0.5", "--vary", "shape.dc0.bm2=-0.1,0.1")
        check(p.returncode == 0 and os.path.exists(os.path.join(fam, "members.csv")),
              "sweep with a %d-character scene path and --out: exit %d %s" % (total, p.returncode, p.stderr[-200:]))


def test_too_long_refused():
    too_long = "/tmp/" + "/".join(["x" * 200] * 25)   # 5000+ characters, more than PATH_MAX
    for args in (["sweep", EX1, "--out", too_long, "--vary", "shape.dc0.bm2=-0.1,0.1"],
                 ["sweep", too_long + ".toml", "--out", os.path.join(TMP, "tl"), "--vary", "shape.dc0.bm2=-0.1,0.1"],
                 ["flow", too_long]):
        p = swim(*args)
        check(p.returncode == 2 and one_line(p), "%s with a 5000-character path: exit %d %r"
              % (args[0], p.returncode, p.stderr[-200:]))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_trust_paths"))
