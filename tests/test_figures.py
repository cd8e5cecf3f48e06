#!/usr/bin/env python3
"""Which figures `swim plot` draws for which scene, on real short runs: phase3d for few free
coordinates, modes for many free modes, path only when the body travels, instants only with
marks; marks come from DIR/events.csv (a synthetic file here, in the t,column,kind,value format
of `swim run --event`) and change energy.png; the body pictures are computed by `swim flow` when
snapshots.json is missing."""
import os
import subprocess
import sys

import matplotlib.image as mpimg
import numpy as np

import swimtest
from swimtest import check

PLOT = os.path.join(swimtest.ROOT, "runtime", "plot", "plot_run.py")


def plot(d, *args, cmd=None):
    env = dict(os.environ, SWIM_BIN=swimtest.SWIM)
    argv = cmd or [os.environ.get("PYTHON", "/usr/bin/python3"), PLOT, d, *args]
    return subprocess.run(argv, capture_output=True, text=True, env=env, cwd=swimtest.ROOT)


def written(p):
    return sorted(os.path.basename(x)[:-4] for x in p.stdout.split())


def test_few_free_coordinates():
    swimtest.run("models/example3.toml", "fig3", "--t-end", "3")
    d = os.path.join(swimtest.TMP, "fig3")
    p = plot(d, cmd=[swimtest.SWIM, "plot", d])
    got = written(p)
    check(p.returncode == 0, "swim plot failed: %s" % p.stderr[-300:])
    check(got == ["energy", "impulse", "phase", "phase3d", "snapshots", "trajectory"],
          "example3, 3 s: figures %s" % got)
    check(os.path.exists(os.path.join(d, "snapshots.json")), "swim plot did not keep snapshots.json")
    check("modes.png skipped" in p.stderr and "path.png skipped" in p.stderr
          and "instants.png skipped" in p.stderr, "skips not explained: %s" % p.stderr[-400:])


def test_many_free_modes():
    swimtest.run("models/example7.toml", "fig7", "--t-end", "1")
    d = os.path.join(swimtest.TMP, "fig7")
    got = written(plot(d, "--only", "modes,phase3d,phase"))
    check(got == ["modes", "phase"], "example7: figures %s" % got)


def test_path_when_travelling():
    swimtest.run("models/example4.toml", "fig4")
    d = os.path.join(swimtest.TMP, "fig4")
    p = plot(d, "--only", "path")
    check(written(p) == ["path"], "example4 (travels ~6 body radii): no path.png: %s" % p.stderr)


def test_marks_from_events():
    swimtest.run("models/example3.toml", "figev", "--t-end", "3")
    d = os.path.join(swimtest.TMP, "figev")
    plot(d, "--only", "energy")
    plain = mpimg.imread(os.path.join(d, "energy.png"))
    with open(os.path.join(d, "events.csv"), "w") as fh:
        fh.write("t,column,kind,value\n1.05,kinetic_rigid,max,0.1\n1.85,kinetic_rigid,min,0.01\n"
                 "1.85,impulse_body_y,zero,0\n")
    p = plot(d, "--only", "energy,instants")
    check(written(p) == ["energy", "instants"], "with events.csv: %s (%s)" % (written(p), p.stderr))
    marked = mpimg.imread(os.path.join(d, "energy.png"))
    check(plain.shape == marked.shape and np.abs(plain - marked).max() > 0.1,
          "energy.png unchanged by the events")
    # explicit --mark wins over events.csv; a bad events.csv header is ignored with a message
    with open(os.path.join(d, "events.csv"), "w") as fh:
        fh.write("time,what\n1,2\n")
    p = plot(d, "--only", "instants")
    check(p.returncode == 1 and "lacks t,column,kind" in p.stderr, "bad events.csv: %s" % p.stderr)
    p = plot(d, "--only", "instants", "--mark", "0.5,2.5")
    check(p.returncode == 0 and written(p) == ["instants"], "--mark: %s" % p.stderr)
    p = plot(d, "--mark", "1,x")
    check(p.returncode == 2, "--mark 1,x: status %d" % p.returncode)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_figures"))
