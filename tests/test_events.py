#!/usr/bin/env python3
"""Events of `swim run` (--event COLUMN:KIND[:stop] and the scene's [events] list), end to end.

Fig. 4.8's four instants from events, default tolerance against rtol 1e-12; terminal events;
bad event specifications (exit 2, one line, before any work); events do not change the run;
periods and displacements per period from independent event sequences agree.
Prints "test_events: P passed, F failed".
"""

import csv
import os
import subprocess
import sys

import numpy as np

import swimtest
from swimtest import ROOT, SWIM, TMP, check, main

EX3 = os.path.join("models", "example3.toml")
FIG48 = ["kinetic_rigid:max", "potential:min", "kinetic_rigid:min", "potential:max"]


def events(name):
    with open(os.path.join(TMP, name, "events.csv")) as fh:
        return list(csv.DictReader(fh))


def event_args(specs):
    return [a for s in specs for a in ("--event", s)]


def first(evs, column, kind, lo, hi):
    ts = [float(e["t"]) for e in evs if e["column"] == column and e["kind"] == kind and lo < float(e["t"]) < hi]
    return ts[0] if ts else float("nan")


def fig48(evs):
    return [first(evs, "kinetic_rigid", "max", 2.5, 3.6), first(evs, "potential", "min", 3.5, 4.5),
            first(evs, "kinetic_rigid", "min", 5.8, 6.5), first(evs, "potential", "max", 9.0, 9.9)]


def test_fig48_instants():
    p, d, s = swimtest.run(EX3, "ev_default", "--t-end", "10", *event_args(FIG48))
    check(p.returncode == 0 and s["status"] == "completed", "example3 with events: completed (%s)" % p.stderr.strip())
    q, _, _ = swimtest.run(EX3, "ev_tight", "--t-end", "10", "--rtol", "1e-12", "--atol", "1e-14", *event_args(FIG48))
    check(q.returncode == 0, "example3 at rtol 1e-12 with events: completed (%s)" % q.stderr.strip())
    got, ref = fig48(events("ev_default")), fig48(events("ev_tight"))
    for g, r, paper in zip(got, ref, [3.17, 3.95, 6.07, 9.50]):
        check(abs(g - r) <= 1e-8, "Fig. 4.8 instant %.10f at the scene's tolerance, %.10f at rtol 1e-12" % (g, r))
        check(abs(g - paper) <= 0.01, "Fig. 4.8 instant %.4f against the paper's %.2f" % (g, paper))
    # every event of the same sequences agrees with the tight run
    a, b = events("ev_default"), events("ev_tight")
    check(len(a) == len(b) and len(a) > 20, "same events at both tolerances (%d, %d)" % (len(a), len(b)))
    if len(a) == len(b):
        worst = max(abs(float(x["t"]) - float(y["t"])) for x, y in zip(a, b))
        check(worst <= 1e-8, "worst event time difference to rtol 1e-12: %.3g" % worst)
    listed = s["events"]
    check(len(listed) == len(a) and all(abs(e["t"] - float(r["t"])) == 0 for e, r in zip(listed, a)),
          "summary.json lists the events of events.csv")
    # an extreme is where the column's row values peak: the located maximum is above its neighbours
    t = d["t"]
    k = int(np.argmin(np.abs(t - got[0])))
    val = float([e for e in a if abs(float(e["t"]) - got[0]) < 1e-12][0]["value"])
    check(val >= np.max(d["kinetic_rigid"][k - 1:k + 2]) - 1e-12, "located maximum %.12g >= the rows around it" % val)


def test_events_do_not_change_the_run():
    for integ in ("abm", "cvode-bdf"):
        swimtest.run(EX3, "ev_none_" + integ, "--t-end", "5", "--integrator", integ)
        swimtest.run(EX3, "ev_some_" + integ, "--t-end", "5", "--integrator", integ,
                     *event_args(FIG48 + ["am1:zero", "y:max"]))
        with open(os.path.join(TMP, "ev_none_" + integ, "trajectory.csv"), "rb") as f1, \
                open(os.path.join(TMP, "ev_some_" + integ, "trajectory.csv"), "rb") as f2:
            check(f1.read() == f2.read(), "%s: trajectory.csv identical with and without events" % integ)


def test_period_and_displacement():
    p, d, s = swimtest.run(EX3, "ev_period", "--t-end", "30", *event_args(["am1:max", "am1:min", "am1:zero", "bm2:max"]))
    per = {(e["column"], e["kind"]): e for e in s["periodic"]}
    check(len(per) == 4, "four periodic sequences (%s)" % list(per))
    if len(per) == 4:
        periods = [e["period"] for e in per.values()]
        dys = [e["displacement_per_period"]["y"] for e in per.values()]
        check(max(periods) - min(periods) <= 1e-8, "the same period from four sequences: %s" % periods)
        check(max(dys) - min(dys) <= 1e-7, "the same displacement per period from four sequences: %s" % dys)
        e = per[("am1", "max")]
        check(e["period_max"] - e["period_min"] <= 1e-8, "the stroke is periodic: periods %.12g .. %.12g" % (e["period_min"], e["period_max"]))
        check(abs(e["displacement_per_period"]["x"]) <= 1e-14, "no displacement along x (ERRATA D7)")
        check(e["displacement_per_period"]["y"] > 0.1, "swims along y: %.4g per period" % e["displacement_per_period"]["y"])
        # displacement from the rows: y(t + T) - y(t) at an output row, interpolated linearly is too coarse;
        # use the rows at k*dt and the period to second order
        T = e["period"]
        t = d["t"]
        i0 = int(np.searchsorted(t, 5.0))
        yT = np.interp(t[i0] + T, t, d["y"])
        check(abs((yT - d["y"][i0]) - e["displacement_per_period"]["y"]) <= 1e-3,
              "displacement per period %.6g against the trajectory rows %.6g" % (e["displacement_per_period"]["y"], yT - d["y"][i0]))


def test_terminal_event():
    p, d, s = swimtest.run(EX3, "ev_stop", *event_args(["am1:max:stop", "potential:min"]))
    check(p.returncode == 0 and s["status"] == "completed", "run stopped by an event completes (%d, %s)" % (p.returncode, p.stderr.strip()))
    evs = events("ev_stop")
    stops = [e for e in evs if e["column"] == "am1"]
    check(len(stops) == 1, "one am1:max event (%d)" % len(stops))
    if stops:
        te = float(stops[0]["t"])
        check("stopped by event am1:max" in s["reason"] and s["event_stop"] == "am1:max", "reason: %s" % s["reason"])
        check(s["t_reached"] == te and d["t"][-1] == te, "last row and t_reached at the event time %.12g (%.12g, %.12g)"
              % (te, d["t"][-1], s["t_reached"]))
        check(all(float(e["t"]) <= te for e in evs), "no event after the terminal one")
        check(d["t"][-2] < te and abs(float(stops[0]["value"]) - d["am1"][-1]) <= 1e-15,
              "the last row is the state at the event")
        check(abs(d["dam1"][-1]) <= 1e-9, "am1 is extreme there: dam1 = %.3g" % d["dam1"][-1])


def test_cvode_events():
    p, d, s = swimtest.run(EX3, "ev_cvode", "--t-end", "10", "--integrator", "cvode-bdf", "--rtol", "1e-11", *event_args(FIG48))
    check(p.returncode == 0, "cvode-bdf with events ran (%s)" % p.stderr.strip())
    got = fig48(events("ev_cvode"))
    if not os.path.exists(os.path.join(TMP, "ev_tight", "events.csv")):
        swimtest.run(EX3, "ev_tight", "--t-end", "10", "--rtol", "1e-12", "--atol", "1e-14", *event_args(FIG48))
    ref = fig48(events("ev_tight"))
    for g, r in zip(got, ref):
        check(abs(g - r) <= 1e-7, "cvode-bdf Fig. 4.8 instant %.10f against abm at rtol 1e-12 %.10f" % (g, r))


def bad(args, name, want, scene=EX3):
    out = os.path.join(TMP, name)
    p = subprocess.run([SWIM, "run", scene, "--out", out, "--quiet", *args], capture_output=True, text=True, cwd=ROOT)
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 2 and len(lines) == 1 and want in p.stderr,
          "%s: exit 2 and one line with %r, got %d %r" % (name, want, p.returncode, p.stderr))
    check(not os.path.exists(os.path.join(out, "trajectory.csv")), "%s: no work done" % name)


def test_bad_events():
    bad(["--event", "nosuch:max"], "ev_bad_col", "unknown column 'nosuch'")
    bad(["--event", "t:zero"], "ev_bad_t", "unknown column 't'")
    bad(["--event", "energy:peak"], "ev_bad_kind", "unknown kind 'peak'")
    bad(["--event", "energy"], "ev_bad_form", "COLUMN:KIND")
    bad(["--event", "energy:max:halt"], "ev_bad_stop", ":stop")
    bad(["--event", "energy:max", "--integrator", "rk8pd"], "ev_bad_integrator", "cannot locate events")
    with open(os.path.join(ROOT, EX3)) as fh:
        text = fh.read()
    path = os.path.join(TMP, "ev_scene_bad.toml")
    with open(path, "w") as fh:
        fh.write(text + '\n[events]\nlist = ["energy:max", "bogus:min"]\n')
    line = text.count("\n") + 3
    bad([], "ev_bad_scene", "%s:%d: events.list: unknown column 'bogus'" % (path, line), scene=path)


def test_scene_events_table():
    with open(os.path.join(ROOT, EX3)) as fh:
        text = fh.read()
    path = os.path.join(TMP, "ev_scene.toml")
    with open(path, "w") as fh:
        fh.write(text + '\n[events]\nlist = ["am1:max", "potential:min"]\n')
    p, d, s = swimtest.run(path, "ev_scene", "--t-end", "10", "--event", "kinetic_rigid:max")
    check(p.returncode == 0, "scene with [events] ran (%s)" % p.stderr.strip())
    evs = events("ev_scene")
    kinds = {(e["column"], e["kind"]) for e in evs}
    check(kinds == {("am1", "max"), ("potential", "min"), ("kinetic_rigid", "max")},
          "events of the scene table and of --event together: %s" % sorted(kinds))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_events"))
