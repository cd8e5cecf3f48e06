#!/usr/bin/env python3
"""swim flow and the run directory it reads: `swim run` copies the scene into DIR/scene.toml and
writes no snapshots.json unless asked (--snapshots, which removes nothing else); `swim flow DIR`
returns one picture per requested time with the documented shape, identical to --snapshots at
the same times, Hermite-interpolated between rows; bad input exits 2 with one line."""
import json
import os
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import check

SCENE = "models/example3.toml"


def flow(d, *args):
    return subprocess.run([swimtest.SWIM, "flow", d, *args], capture_output=True, text=True,
                          cwd=swimtest.ROOT)


def test_run_directory():
    p, rows, _ = swimtest.run(SCENE, "lazy", "--t-end", "2")
    d = os.path.join(swimtest.TMP, "lazy")
    check(p.returncode == 0, "swim run failed: %s" % p.stderr)
    check(not os.path.exists(os.path.join(d, "snapshots.json")), "swim run wrote snapshots.json unasked")
    with open(os.path.join(swimtest.ROOT, SCENE)) as a, open(os.path.join(d, "scene.original.toml")) as b:
        check(a.read() == b.read(), "DIR/scene.original.toml is not a copy of the scene")
    with open(os.path.join(d, "scene.toml")) as b:
        resolved = b.read()
    check(resolved.startswith("# resolved by swim: --set run.t_end=2 applied to") and "t_end = 2" in resolved,
          "DIR/scene.toml is the scene as run (--t-end 2 written in)")
    # a stale snapshots.json from an earlier run is removed, not left to contradict the new rows
    with open(os.path.join(d, "snapshots.json"), "w") as fh:
        fh.write("[]")
    swimtest.run(SCENE, "lazy", "--t-end", "1")
    check(not os.path.exists(os.path.join(d, "snapshots.json")), "stale snapshots.json kept")


def shape_ok(s):
    try:
        return (len(s["boundary"]["X"]) == 256 and len(s["boundary"]["Y"]) == 256
                and np.array(s["density"]["rho"], float).shape == (12, 96)
                and np.array(s["density"]["X"], float).shape == (12, 96)
                and len(s["arrows"]["U"]) == 96 and len(s["arrows"]["X"]) == 96)
    except (KeyError, TypeError, ValueError):
        return False


def test_flow_output():
    p, rows, _ = swimtest.run(SCENE, "snap", "--t-end", "3", "--snapshots")
    d = os.path.join(swimtest.TMP, "snap")
    with open(os.path.join(d, "snapshots.json")) as fh:
        ref = json.load(fh)
    check(len(ref) >= 10, "--snapshots wrote %d snapshots" % len(ref))
    times = [s["t"] for s in ref]
    out = os.path.join(swimtest.TMP, "flow_at_rows.json")
    q = flow(d, "--times", ",".join(repr(t) for t in reversed(times)), "--out", out)
    check(q.returncode == 0, "swim flow --times failed: %s" % q.stderr)
    with open(out) as fh:
        got = json.load(fh)
    check([s["t"] for s in got] == sorted(times), "swim flow times not sorted/complete")
    check(all(shape_ok(s) for s in got), "swim flow: a snapshot has the wrong shape")
    diff = 0.0
    for a, b in zip(ref, got):
        for k in ("boundary", "density", "arrows"):
            for kk in a[k]:
                x, y = np.array(a[k][kk], float), np.array(b[k][kk], float)
                diff = max(diff, float(np.nanmax(np.abs(x - y))))
    check(diff < 1e-12, "swim flow at row times differs from --snapshots by %g" % diff)
    # --frames K: K evenly spaced pictures over [t0, t_end] into DIR/snapshots.json by default
    os.remove(os.path.join(d, "snapshots.json"))
    q = flow(d, "--frames", "7")
    check(q.returncode == 0, "swim flow --frames failed: %s" % q.stderr)
    with open(os.path.join(d, "snapshots.json")) as fh:
        fr = json.load(fh)
    check(len(fr) == 7 and abs(fr[0]["t"]) < 1e-12 and abs(fr[-1]["t"] - 3.0) < 1e-12
          and abs(fr[1]["t"] - 0.5) < 1e-12, "--frames 7 times: %s" % [s["t"] for s in fr])
    # between rows: the outline moves continuously (Hermite in c), close to both neighbours
    q = flow(d, "--times", "1.025,1.0,1.05", "--out", "-")
    mid = json.loads(q.stdout)
    bx = [np.array(s["boundary"]["X"]) for s in mid]
    gap = float(np.abs(bx[0] - bx[1]).max()) + float(np.abs(bx[1] - bx[2]).max())
    dev = float(np.abs(bx[1] - 0.5 * (bx[0] + bx[2])).max())
    check(0 < dev < 0.05 * gap, "mid-row outline not between its neighbours (%g vs %g)" % (dev, gap))


def test_flow_errors():
    swimtest.run(SCENE, "errs", "--t-end", "3")
    d = os.path.join(swimtest.TMP, "errs")
    cases = [(["--times", "1,abc"], "item 2"), (["--times", "99"], "outside the run"),
             (["--frames", "0"], "out of range"), (["--times", "1", "--frames", "3"], "not both"),
             (["--bogus"], "unknown option")]
    for args, msg in cases:
        q = flow(d, *args)
        check(q.returncode == 2 and msg in q.stderr and q.stderr.count("\n") == 1,
              "swim flow %s: status %d, stderr %r" % (args, q.returncode, q.stderr))
    q = flow(os.path.join(swimtest.TMP, "nowhere"))
    check(q.returncode == 2 and "scene.toml" in q.stderr, "missing run dir: %r" % q.stderr)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_flow"))
