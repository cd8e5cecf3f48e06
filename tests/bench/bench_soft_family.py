#!/usr/bin/env python3
"""Families of soft scenes like models/hard/soft_*: how often do they complete, how well do they
keep the energy, what do they cost -- over perturbed copies rather than the one scene file
(these runs are chaotic: two members a few percent apart meet different bounces, and a single
run says little about the next).

Usage (from the repository root; `make bench-soft`):
    /usr/bin/python3 tests/bench/bench_soft_family.py [--scene FILE ...] [--members M] [--seed S]
                                                      [--spread D] [--variant NAME=KEY=VALUE[,KEY=VALUE]]
                                                      [--out DIR]

Each scene (default models/hard/soft_n10_a05.toml and soft_n10_a1.toml) gives M members
(default 8): its initial shape velocities dc0[2:10] each moved by a uniform random amount in
[-D, D] (default 0.05, seed 3), then projected onto the constraints by the scene's own
project_initial. Every member runs at the scene's settings once per variant: "default" always,
plus each --variant (e.g. --variant noshift=run.origin_shift=false). Reported per scene and
variant: members completed, the energy balance (summary energy_drift_rel: max over the accepted
steps of |E - E0 - work| / |E0|) as median and maximum, members above 1e-7, integration seconds
(median, max). Writes DIR/family.csv and DIR/table.md (default build/bench/soft_family).
"""

import argparse
import csv
import json
import os
import random
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.environ.get("SWIM_BIN", os.path.join(ROOT, "bin", "swim"))


def members(scene, m, seed, spread, out):
    """Write m perturbed copies of scene into out; their paths."""
    src = open(os.path.join(ROOT, scene)).read()
    found = re.search(r"dc0\s*=\s*\[([^\]]*)\]", src)
    base = [float(x) for x in found.group(1).split(",")]
    rnd = random.Random(seed)
    paths = []
    for i in range(m):
        dc = list(base)
        for j in range(2, min(10, len(dc))):
            dc[j] += rnd.uniform(-spread, spread)
        text = src.replace(found.group(0), "dc0 = [ %s ]" % ", ".join("%.9g" % x for x in dc))
        path = os.path.join(out, "%s_m%d.toml" % (os.path.splitext(os.path.basename(scene))[0], i))
        with open(path, "w") as fh:
            fh.write(text)
        paths.append(path)
    return paths


def run(path, out, sets):
    args = [SWIM, "run", path, "--out", out, "--summary-only", "--quiet"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    try:
        with open(os.path.join(out, "summary.json")) as fh:
            return json.load(fh)
    except (OSError, ValueError):
        return None


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if len(v) % 2 else 0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2]) if v else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", action="append")
    ap.add_argument("--members", type=int, default=8)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--spread", type=float, default=0.05)
    ap.add_argument("--variant", action="append", default=[])
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "bench", "soft_family"))
    a = ap.parse_args()
    scenes = a.scene or ["models/hard/soft_n10_a05.toml", "models/hard/soft_n10_a1.toml"]
    variants = [("default", [])]
    for v in a.variant:
        name, _, sets = v.partition("=")
        variants.append((name, sets.split(",")))
    os.makedirs(a.out, exist_ok=True)
    rows, table = [], []
    for scene in scenes:
        paths = members(scene, a.members, a.seed, a.spread, a.out)
        for name, sets in variants:
            drift, secs, done = [], [], 0
            for i, p in enumerate(paths):
                s = run(p, os.path.join(a.out, "%s_%s_%d" % (os.path.basename(p)[:-5], name, i)), sets)
                ok = s is not None and s["status"] == "completed"
                done += ok
                d = s["energy_drift_rel"] if s and s.get("energy_drift_rel") is not None else float("nan")
                t = s["stats"]["integrate_seconds"] if s else float("nan")
                if ok:
                    drift.append(d)
                    secs.append(t)
                rows.append([scene, name, i, s["status"] if s else "no summary", d, s["jmin"] if s else "", t,
                             s["stats"]["steps"] if s else "", s["origin_shift"]["restarts"] if s else ""])
                print("%s %s member %d: %s, balance %.3g, %.1f s" % (scene, name, i, rows[-1][3], d, t), flush=True)
            table.append("| %s | %s | %d/%d | %.2g | %.2g | %d | %.1f | %.1f |" % (
                os.path.basename(scene)[:-5], name, done, len(paths), median(drift), max(drift or [float("nan")]),
                sum(x > 1e-7 for x in drift), median(secs), max(secs or [float("nan")])))
    with open(os.path.join(a.out, "family.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["scene", "variant", "member", "status", "balance", "jmin", "seconds", "steps", "origin_restarts"])
        w.writerows(rows)
    head = ["| scene | variant | completed | balance median | balance max | > 1e-7 | s median | s max |",
            "|---|---|---|---|---|---|---|---|"]
    text = "\n".join(head + table) + "\n"
    with open(os.path.join(a.out, "table.md"), "w") as fh:
        fh.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
