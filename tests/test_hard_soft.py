#!/usr/bin/env python3
"""All-free scenes at N = 10, 15, 20 with soft high modes that bounce off the barrier.

models/hard/soft_n{10,15,20}_a{05,1}.toml: every shape coordinate free, R_k = 1/|k|, no damping
(alpha = 1/2) or light damping (alpha = 1). Each is run at its own rtol 1e-8 over the first
T_TEST time units (the whole t_end = 20 is `make bench-hard`, which also times them) and must:
- complete, with min J > 0 on every row and the summary's min J > 0;
- bounce: at least three local minima of min J below 0.1 on the rows;
- keep the energy balance E - E0 - work (5.3) within 1e-7 of the energy scale max |E|;
and abm's balance test (energy_control) must do what it is for on soft_n10_a05.
Prints "test_hard_soft: P passed, F failed".
"""

import numpy as np

from swimtest import check, main, run

T_TEST = "4"


def test_soft_scenes():
    for n in (10, 15, 20):
        for a in ("05", "1"):
            name = "soft_n%d_a%s" % (n, a)
            p, d, s = run("models/hard/%s.toml" % name, name, "--t-end", T_TEST)
            ok = d is not None and s is not None
            check(ok, "%s: rows and summary written" % name)
            if not ok:
                continue
            check(s["status"] == "completed", "%s: %s" % (name, s.get("reason")))
            check(np.min(d["jmin"]) > 0 and s["jmin"] > 0, "%s: min J %.3g" % (name, np.min(d["jmin"])))
            j = d["jmin"]
            dips = np.sum((j[1:-1] < j[:-2]) & (j[1:-1] <= j[2:]) & (j[1:-1] < 0.1))
            check(dips >= 3, "%s: %d dips of min J below 0.1 (want >= 3 bounces)" % (name, dips))
            scale = np.max(np.abs(d["energy"]))
            bal = np.max(np.abs(d["energy"] - d["energy"][0] - d["work"])) / scale
            check(bal <= 1e-7, "%s: energy balance off by %.3g of the energy scale" % (name, bal))
            print("  %s to t = %s: min J %.3g, %d dips below 0.1, balance %.2e, %d RHS" %
                  (name, T_TEST, np.min(j), dips, bal, s["stats"]["rhs_evaluations"]))


def test_energy_control():
    """abm's balance test (swim_ode_options.invariant, [run] energy_control): on an alpha = 1/2 soft
    scene without damping, where Adams' per-step dissipation adds up over the steps near the wall,
    it must keep the balance well inside the bound and be reported; off, the run is the old one."""
    name = "soft_n10_a05"
    p1, d1, s1 = run("models/hard/%s.toml" % name, name + "_ec", "--t-end", "8")
    p0, d0, s0 = run("models/hard/%s.toml" % name, name + "_noec", "--t-end", "8", "--set", "run.energy_control=false")
    ok = s1 is not None and s0 is not None
    check(ok, "energy control: both summaries written")
    if not ok:
        return
    ec1, ec0 = s1.get("energy_control", {}), s0.get("energy_control", {})
    check(ec1.get("enabled") is True and ec1.get("tolerance", 0) > 0 and ec1.get("rejected_steps", -1) >= 0,
          "energy control reported when on: %s" % ec1)
    check(ec0.get("enabled") is False and ec0.get("rejected_steps") == 0, "energy control reported off: %s" % ec0)
    b1, b0 = s1["energy_drift_rel"], s0["energy_drift_rel"]
    check(s1["status"] == "completed" and s0["status"] == "completed", "energy control: both complete")
    check(b1 <= 1e-8, "energy control: balance %.3g (want <= 1e-8, a tenth of the bound)" % b1)
    check(b1 <= 0.3 * b0, "energy control: balance %.3g against %.3g without it (want <= 0.3x)" % (b1, b0))
    print("  %s to t = 8: balance %.2e with energy control (%d steps, %d rejected by it), %.2e without (%d steps)" %
          (name, b1, s1["stats"]["steps"], ec1["rejected_steps"], b0, s0["stats"]["steps"]))


if __name__ == "__main__":
    main(globals(), "test_hard_soft")
