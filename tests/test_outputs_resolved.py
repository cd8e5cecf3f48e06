#!/usr/bin/env python3
"""An output folder is the run it holds: DIR/scene.toml is the scene as run (the --set overrides
written in, the file as given kept as scene.original.toml), summary.json says how it was made
(swim's version, the command line, the overrides, the kernel's key), and everything that reads DIR
-- swim flow, a rerun of DIR/scene.toml, a sweep member's folder -- sees the scene that was run."""
import json
import os
import sys

import numpy as np

import swimtest
from swimtest import check, run, swim, TMP

EX3 = "models/example3.toml"
SHORT = ["--set", "run.t_end=0.5"]


def flow_density(out):
    p = swim("flow", out, "--times", "0", "--out", "-")
    check(p.returncode == 0, "swim flow %s: %s" % (out, p.stderr.strip()))
    return np.array(json.loads(p.stdout)[0]["density"]["rho"], dtype=float)


def numbers(summary):
    """The summary's results, without what differs from one run of the same scene to the next."""
    skip = ("seconds", "max_rss_kb", "ns_per_rhs", "from_cache")
    out = {}

    def walk(x, path):
        if isinstance(x, dict):
            for k, v in x.items():
                walk(v, path + "." + k)
        elif isinstance(x, list):
            for i, v in enumerate(x):
                walk(v, "%s[%d]" % (path, i))
        elif not any(s in path for s in skip) and not path.startswith((".out", ".provenance", ".scene")):
            out[path] = x
    walk(summary, "")
    return out


def test_density_follows_the_override():
    """swim flow on a --set model.rho0=2 run shows twice the density of the rho0 = 1 run at t = 0."""
    p1, _, _ = run(EX3, "rho1", *SHORT)
    p2, _, s2 = run(EX3, "rho2", *SHORT, "--set", "model.rho0=2")
    check(p1.returncode == 0 and p2.returncode == 0, "both runs complete")
    r1, r2 = flow_density(os.path.join(TMP, "rho1")), flow_density(os.path.join(TMP, "rho2"))
    ok = r1.shape == r2.shape and np.all(np.isfinite(r1)) and np.allclose(r2, 2 * r1, rtol=1e-12, atol=0)
    check(ok, "density at t = 0 of the rho0 = 2 run is twice that of the rho0 = 1 run")
    check(s2 and s2["rho0"] == 2.0, "summary.json rho0 = 2")


def test_folder_holds_the_scene_as_run():
    out = os.path.join(TMP, "rho2")
    with open(os.path.join(out, "scene.original.toml"), "rb") as fh, open(EX3, "rb") as orig:
        check(fh.read() == orig.read(), "scene.original.toml is the scene file as given, byte for byte")
    text = open(os.path.join(out, "scene.toml")).read()
    check(text.startswith("# resolved by swim:") and "model.rho0=2" in text.splitlines()[0],
          "scene.toml says which overrides it holds")
    check("rho0 = 2" in text, "scene.toml holds rho0 = 2")
    prov = json.load(open(os.path.join(out, "summary.json"))).get("provenance", {})
    check(prov.get("swim_version"), "summary.json: swim's version")
    check(prov.get("overrides") == ["run.t_end=0.5", "model.rho0=2"], "summary.json: the overrides, in order")
    check("--set model.rho0=2" in (prov.get("command") or ""), "summary.json: the command line")
    check(isinstance(prov.get("kernel_key"), str) and prov["kernel_key"], "summary.json: the kernel's key")


def test_rerun_of_the_folder_is_the_same_run():
    """`swim run DIR/scene.toml` (no options) reproduces the run to the last digit."""
    src = os.path.join(TMP, "rho2")
    p, _, again = run(os.path.join(src, "scene.toml"), "rho2_again")
    check(p.returncode == 0, "rerun completes: %s" % p.stderr.strip())
    first = json.load(open(os.path.join(src, "summary.json")))
    check(again is not None and numbers(again) == numbers(first), "rerun: the same summary numbers")
    a = open(os.path.join(src, "trajectory.csv")).read()
    b = open(os.path.join(TMP, "rho2_again", "trajectory.csv")).read()
    check(a == b, "rerun: trajectory.csv byte for byte")


def test_plain_run_leaves_no_stale_original():
    """A run without overrides into a folder that had one keeps no scene.original.toml of another run."""
    out = os.path.join(TMP, "reuse")
    run(EX3, "reuse", *SHORT)
    check(os.path.exists(os.path.join(out, "scene.original.toml")), "with overrides: scene.original.toml")
    text = open("models/example1.toml").read().replace("t_end = 30.0", "t_end = 0.2")
    short = swimtest.scene("example1_short", text)
    p = swim("run", short, "--out", out, "--quiet")
    check(p.returncode == 0, "plain run completes")
    check(not os.path.exists(os.path.join(out, "scene.original.toml")), "without overrides: none left")
    check(open(os.path.join(out, "scene.toml")).read() == text, "without overrides: scene.toml is the file")


def test_run_options_are_recorded():
    """--t-end, --rtol, --integrator, --no-projection are in DIR/scene.toml too: a rerun is the run."""
    p, _, first = run(EX3, "options", "--t-end", "0.4", "--rtol", "1e-9", "--integrator", "cvode-bdf", "--no-projection")
    check(p.returncode == 0, "run with options completes: %s" % p.stderr.strip())
    src = os.path.join(TMP, "options")
    q, _, again = run(os.path.join(src, "scene.toml"), "options_again")
    check(q.returncode == 0 and again is not None and numbers(again) == numbers(first),
          "rerun of DIR/scene.toml: the same summary (t_end, rtol, integrator, projection recorded)")
    check(again and again["integrator"] == "cvode-bdf" and again["t_end"] == 0.4 and not again["projection"]["enabled"],
          "rerun: cvode-bdf to 0.4 without projection")


def test_sweep_member_folder_reruns():
    """A sweep member's folder holds its own scene: plain `swim run DIR/scene.toml` gives its summary."""
    d = os.path.join(TMP, "sweep")
    p = swim("sweep", EX3, "--vary", "model.rho0=1,3", "--set", "run.t_end=0.5", "--out", d, "--quiet")
    check(p.returncode == 0, "sweep completes: %s" % p.stderr.strip())
    for m in ("00000", "00001"):
        mdir = os.path.join(d, "members", m)
        text = open(os.path.join(mdir, "scene.toml")).read()
        check("rho0 = %s" % ("1" if m == "00000" else "3") in text, "member %s: scene.toml holds its rho0" % m)
        q, _, again = run(os.path.join(mdir, "scene.toml"), "member" + m)
        first = json.load(open(os.path.join(mdir, "summary.json")))
        check(q.returncode == 0 and again is not None and numbers(again) == numbers(first),
              "member %s reruns to the same summary" % m)


if __name__ == "__main__":
    os.chdir(swimtest.ROOT)
    sys.exit(swimtest.main(globals(), "test_outputs_resolved"))
