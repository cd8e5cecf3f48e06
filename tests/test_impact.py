#!/usr/bin/env python3
"""Bounces off the barrier too deep to follow, taken as impacts (model/bounce.h, run.impact_depth).

1. The impulsive limit against the bounce itself: tests/scenes/impact_soft_n10.toml bounces once to
   min J ~ 7e-16 (one contact angle), which the shifted coordinates follow exactly. Run at rtol 1e-9
   and 1e-10, followed (impact_depth = 0) and as an impact (impact_depth = 1e-12 asks for it), the
   two must agree row for row before the bounce (the check changes nothing), the predicted turning
   depth must match the followed minimum, and after the bounce they may differ only by what the
   impact neglects -- O(min J at the impact) = O(IMPACT_AT rtol), converging like rtol.
2. Forcing 20x that of section 5.2 against the alpha = 1/2 barrier (models/hard/large_forcing.toml),
   whose bounces would turn at min J ~ 1e-25 ... 1e-110: with impacts it completes, inside D, with
   the energy balance (5.3) kept and the impacts reported.
Prints "test_impact: P passed, F failed".
"""

import os

import numpy as np

from swimtest import check, main, run

SCENE = "tests/scenes/impact_soft_n10.toml"
IMPACT_AT = 0.01   # runtime/cli/run.c: an impact is taken at min J < IMPACT_AT rtol |c_1|^2


def state(d):
    """The state columns of the rows: position, shape and shape velocity."""
    names = [n for n in d.dtype.names if n in ("x", "y", "theta") or n[:1] in ("a", "b") or n[:2] in ("da", "db")]
    return np.column_stack([d[n] for n in names])


def test_impulsive_limit():
    after = {}
    for rtol in ("1e-9", "1e-10"):
        tag = rtol.replace("-", "m")
        pf, df, sf = run(SCENE, "follow_" + tag, "--rtol", rtol, "--atol", "1e-14", "--set", "run.impact_depth=0")
        pi, di, si = run(SCENE, "impact_" + tag, "--rtol", rtol, "--atol", "1e-14", "--set", "run.impact_depth=1e-12")
        ok = sf is not None and si is not None and df is not None and di is not None and len(df) == len(di)
        check(ok, "rtol %s: both runs wrote their rows and summaries" % rtol)
        if not ok:
            continue
        check(sf["status"] == "completed" and si["status"] == "completed", "rtol %s: both complete (%s; %s)"
              % (rtol, sf["reason"], si["reason"]))
        imp, none = si["impacts"], sf["impacts"]
        check(none["enabled"] is False and none["count"] == 0, "impact_depth = 0: no impact (%s)" % none)
        check(imp["enabled"] is True and imp["count"] == 1, "rtol %s: one impact (%s)" % (rtol, imp))
        if imp["count"] != 1:
            continue
        depth = sf["jmin"]   # the followed bounce's own minimum
        check(0 < depth < 1e-14, "rtol %s: the followed bounce goes to %.3g" % (rtol, depth))
        check(abs(imp["first_t"] - sf["jmin_t"]) < 1e-6, "rtol %s: impact at t = %.12g, the followed bounce turns at %.12g"
              % (rtol, imp["first_t"], sf["jmin_t"]))
        check(depth / 3 < imp["turning_min"] < 3 * depth, "rtol %s: predicted turning depth %.3g, followed %.3g"
              % (rtol, imp["turning_min"], depth))
        check(imp["jmin_max"] <= IMPACT_AT * float(rtol), "rtol %s: taken at min J = %.3g" % (rtol, imp["jmin_max"]))
        t = df["t"]
        diff = np.max(np.abs(state(df) - state(di)), axis=1)
        before, later = t < imp["first_t"], t > imp["first_t"]
        check(np.all(diff[before] == 0), "rtol %s: the runs differ before the impact (%.3g)" % (rtol, np.max(diff[before])))
        err = np.max(diff[later])
        check(0 < err <= 20 * IMPACT_AT * float(rtol), "rtol %s: after the impact the states differ by %.3g (want <= %.1g)"
              % (rtol, err, 20 * IMPACT_AT * float(rtol)))
        check(si["energy_drift_rel"] <= 2 * sf["energy_drift_rel"] + 1e-11, "rtol %s: energy balance %.3g with the impact, %.3g followed"
              % (rtol, si["energy_drift_rel"], sf["energy_drift_rel"]))
        after[rtol] = err
        print("  rtol %s: impact at t = %.10f, min J %.2e (predicted turning %.2e, followed %.2e); after it the "
              "states differ by %.2e" % (rtol, imp["first_t"], imp["jmin_max"], imp["turning_min"], depth, err))
    if len(after) == 2:
        ratio = after["1e-9"] / after["1e-10"]
        check(ratio > 4, "the impact's error converges with its depth: %.3g at rtol 1e-9, %.3g at 1e-10" %
              (after["1e-9"], after["1e-10"]))


def test_no_sensitivities_across_impacts():
    # the variational equations would need the impact's jump: swim says so instead of writing
    # sensitivities of a run it did not integrate
    p, d, s = run(SCENE, "impact_sens", "--rtol", "1e-9", "--atol", "1e-14", "--set", "run.impact_depth=1e-12",
                  "--sensitivity", "barrier.epsilon")
    said = p.stdout + p.stderr
    check(p.returncode == 1 and "across which sensitivities are not computed" in said,
          "--sensitivity with an impact: exit %d, %s" % (p.returncode, said.strip()[-200:]))
    # the command failed (what was asked is not there) but the trajectory it did integrate is kept
    check(s is not None and s["status"] == "failed" and s["t_reached"] == s["t_end"] and s["impacts"]["count"] == 1
          and s["sensitivity"]["status"] == "failed", "the run itself is kept, the summary says the sensitivities failed")
    check(d is not None and len(d) > 10, "the trajectory is kept")
    check(not os.path.exists(os.path.join(p.args[p.args.index("--out") + 1], "sensitivity.csv")), "no sensitivity.csv")


def test_large_forcing():
    p, d, s = run("models/hard/large_forcing.toml", "large_forcing", "--t-end", "3")
    ok = d is not None and s is not None
    check(ok, "large_forcing: rows and summary written")
    if not ok:
        return
    check(p.returncode == 0 and s["status"] == "completed", "large_forcing completes t = 3: %s" % s["reason"])
    check(np.min(d["jmin"]) > 0 and s["jmin"] > 0, "large_forcing: min J %.3g" % s["jmin"])
    imp = s["impacts"]
    check(imp["count"] >= 1 and imp["turning_min"] < 1e-16, "large_forcing: impacts reported (%s)" % imp)
    check("taken as an impact" in p.stderr, "the first impact is said on stderr even with --quiet: %s" % p.stderr.strip())
    scale = np.max(np.abs(d["energy"]))
    bal = np.max(np.abs(d["energy"] - d["energy"][0] - d["work"])) / scale
    check(bal <= 1e-7, "large_forcing: energy balance off by %.3g of the energy scale" % bal)
    print("  large_forcing to t = 3: %d impacts (turning points predicted down to %.1e), min J %.2e, balance %.2e"
          % (imp["count"], imp["turning_min"], s["jmin"], bal))


if __name__ == "__main__":
    main(globals(), "test_impact")
