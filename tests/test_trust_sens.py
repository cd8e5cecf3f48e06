#!/usr/bin/env python3
"""Can a user believe what `swim run --sensitivity` says? sensitivity.csv ends where the
trajectory ends (a stopping event included); an interrupt during the sensitivity pass makes the
run "interrupted", exit 1, never "completed"; summary.json records the sensitivity outcome; an
option given twice either accumulates (--sensitivity) or is refused with one line, exit 2.
Prints "test_trust_sens: P passed, F failed".
"""

import os
import signal
import subprocess
import sys
import time

import numpy as np

from swimtest import ROOT, SWIM, TMP, check, main, run

SCENE = os.path.join(ROOT, "models", "example3.toml")


def read_csv(path):
    return np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))


def test_event_stop_ends_sensitivities():
    # a :stop event ends the trajectory early; the sensitivities must stop there too
    p, rows, summary = run(SCENE, "event", "--t-end", "3", "--event", "am1:max:stop",
                           "--sensitivity", "model.rhof")
    check(p.returncode == 0, "event stop with --sensitivity: exit %d: %s" % (p.returncode, p.stderr))
    sens = read_csv(os.path.join(TMP, "event", "sensitivity.csv"))
    check(rows is not None and rows["t"][-1] < 3, "the event stopped the trajectory before t_end")
    check(rows is not None and abs(sens["t"][-1] - rows["t"][-1]) < 1e-12,
          "sensitivity.csv ends at %r, the trajectory at %r" % (sens["t"][-1], rows["t"][-1] if rows is not None else None))
    check(rows is not None and len(sens) == len(rows), "one sensitivity row per trajectory row")
    s = (summary or {}).get("sensitivity", {})
    check(s.get("status") == "written" and abs(s.get("t_end", -1) - rows["t"][-1]) < 1e-12,
          "summary.json records the sensitivities and where they end: %r" % s)
    check(s.get("rows") == len(sens) and s.get("t_reached") == sens["t"][-1],
          "summary.json counts the sensitivity rows (%d, last t %r): %r" % (len(sens), sens["t"][-1], s))


def test_sigint_during_sensitivities_is_interrupted():
    out = os.path.join(TMP, "sigint")
    proc = subprocess.Popen([SWIM, "run", SCENE, "--out", out, "--quiet", "--t-end", "3000",
                             "--sensitivity", "model.rhof,model.rho0,elastic.stiffness.am1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    sens = os.path.join(out, "sensitivity.csv")
    deadline = time.time() + 60
    while proc.poll() is None and not os.path.exists(sens) and time.time() < deadline:
        time.sleep(0.005)
    sent = proc.poll() is None
    if sent:
        proc.send_signal(signal.SIGINT)
    so, se = proc.communicate()
    check(sent, "the sensitivity pass was still running when SIGINT came")
    if not sent:
        return
    check(proc.returncode == 1, "SIGINT during the sensitivities: exit %d, expected 1" % proc.returncode)
    check("completed" not in so, "an interrupted run does not say completed: %r" % so)
    import json
    with open(os.path.join(out, "summary.json")) as fh:
        summary = json.load(fh)
    check(summary["status"] == "failed" and "interrupted" in summary["reason"],
          "summary.json says interrupted: %r" % summary["reason"])
    check(summary.get("sensitivity", {}).get("status") == "interrupted",
          "summary.json's sensitivity entry says interrupted: %r" % summary.get("sensitivity"))
    with open(sens) as fh:
        partial = max(0, sum(1 for _ in fh) - 1)
    entry = summary.get("sensitivity", {})
    check(entry.get("rows") == partial and (partial == 0 or entry.get("t_reached") < entry.get("t_end")),
          "the interrupted entry counts the %d rows the partial file holds: %r" % (partial, entry))


def test_repeated_sensitivity_accumulates():
    p, rows, summary = run(SCENE, "repeat", "--t-end", "0.5", "--sensitivity", "model.rhof",
                           "--sensitivity", "model.rho0")
    check(p.returncode == 0, "two --sensitivity: exit %d: %s" % (p.returncode, p.stderr))
    with open(os.path.join(TMP, "repeat", "sensitivity.csv")) as fh:
        head = fh.readline()
    check("dy/dmodel.rhof" in head and "dy/dmodel.rho0" in head,
          "both --sensitivity lists are in sensitivity.csv: %r" % head)


def test_repeated_single_option_refused():
    for opt, a, b in (("--rtol", "1e-6", "1e-7"), ("--t-end", "1", "2"), ("--out", TMP + "/o1", TMP + "/o2")):
        args = [SWIM, "run", SCENE, "--quiet", opt, a, opt, b]
        if opt != "--out":
            args += ["--out", os.path.join(TMP, "twice")]
        p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2 and len(lines) == 1 and opt in lines[0] and "twice" in lines[0],
              "%s given twice: exit %d, stderr %r" % (opt, p.returncode, p.stderr))
    p = subprocess.run([SWIM, "inspect", SCENE, "--rho0", "1", "--rho0", "2"], capture_output=True, text=True, cwd=ROOT)
    check(p.returncode == 2, "an option of another command given twice is refused too: %r" % p.stderr)


def test_repeated_event_still_allowed():
    p, rows, summary = run(SCENE, "events2", "--t-end", "1", "--event", "am1:max", "--event", "am1:min")
    check(p.returncode == 0, "--event stays repeatable: exit %d: %s" % (p.returncode, p.stderr))


sys.exit(main(globals(), "test_trust_sens"))
