#!/usr/bin/env python3
"""swim periodic, swim continue and swim floquet keep what they computed on every stopping signal.

Each signal (SIGINT, SIGTERM, SIGHUP) is sent once the work has begun -- after the first Newton
iterate's line (periodic on Example 7, whose damped Newton takes a minute and never converges)
or the first branch point's line (continue along Example 3's librations, 1000 points) or the
period's line (floquet on soft_n20_a05, whose variational equations take seconds) -- never
after a fixed sleep. Then: exit 1 (as a stopped `swim run`), the signal named on stderr and in
the report; periodic.json with status "stopped", the signal, the last iterate's residual and
period, converged false; branch.csv with the points found so far and branch.json with status
"stopped" and the signal; floquet.json with status "stopped", the signal and the period, no
multipliers.
Prints "test_orbit_signals: P passed, F failed".
"""

import csv
import json
import os
import signal
import sys

from swimtest import TMP, check, main, signal_at_marker

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def stopped(command, name, args, marker, sig, report):
    """swim COMMAND ARGS --out TMP/COMMAND_NAME, sig at marker: checks that the work began and that
    it ended with exit 1 naming the signal on stderr (and on stdout when it prints a report);
    the JSON report (None when missing)."""
    out = os.path.join(TMP, "%s_%s" % (command, name))
    proc, so, se, seen = signal_at_marker([command, *args, "--out", out], marker, sig)
    check(seen, "%s %s: the work began (%r)" % (command, name, se[-300:]))
    check(proc.returncode == 1 and ("stopped by " + name) in se and (report is None or ("STOPPED by " + name) in so),
          "%s %s: exit 1, the signal named (%d, %r, %r)" % (command, name, proc.returncode, so[-200:], se[-300:]))
    path = os.path.join(out, report or "branch.json")
    return (json.load(open(path)) if os.path.exists(path) else None), out


def test_periodic_stopped():
    for sig in SIGNALS:
        name = signal.Signals(sig).name
        d, _ = stopped("periodic", name, ["models/example7.toml"], "Newton iterate 0", sig, "periodic.json")
        check(d is not None and d["status"] == "stopped" and d["signal"] == name and d["converged"] is False,
              "%s: periodic.json says stopped by it, not converged (%r)" % (name, d and d["status"]))
        if d:
            last = d["newton"][-1]
            check(len(d["newton"]) >= 1 and last["residual"] == d["residual"] and d["residual"] > 0
                  and last["period"] == d["period"] and d["period"] > 0,
                  "%s: the last iterate and its residual kept (%r)" % (name, last))


def test_continue_stopped():
    for sig in SIGNALS:
        name = signal.Signals(sig).name
        b, out = stopped("continue", name, ["tests/scenes/example3_libration.toml", "--guess-event", "bm2:max", "--param",
                                            "energy=1e-6:0.47", "--max-points", "1000"], "point at", sig, None)
        path = os.path.join(out, "branch.csv")
        rows = list(csv.DictReader(open(path))) if os.path.exists(path) else []
        check(b is not None and b["status"] == "stopped" and b["signal"] == name and len(b["points"]) == len(rows)
              and 1 <= len(rows) < 1000, "%s: the %d points so far kept, branch.json says stopped (%r)"
              % (name, len(rows), b and (b["status"], b["ended_early"])))
        check(all(float(r["residual"]) <= 1e-11 for r in rows), "%s: every kept point converged" % name)


def test_floquet_stopped():
    """soft_n20_a05's variational equations (84 x 85) take seconds after the period is found."""
    for sig in SIGNALS:
        name = signal.Signals(sig).name
        d, _ = stopped("floquet", name, ["models/hard/soft_n20_a05.toml"], "period T =", sig, "floquet.json")
        check(d is not None and d["status"] == "stopped" and d["signal"] == name and d["periodic"] is False
              and d["period"] > 0 and "multipliers" not in json.dumps(d),
              "%s: floquet.json says stopped, keeps the period, claims no multipliers (%r)" % (name, d))


if __name__ == "__main__":
    sys.exit(main(globals(), "test_orbit_signals"))
