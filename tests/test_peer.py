#!/usr/bin/env python3
"""The NumPy/SciPy peer of `make bench` (tests/bench/peer/peer_model.py, written from the paper and
the errata, not from swim's code) still models what swim simulates, so the speed comparison of
tests/bench/peer/bench_peer.py cannot silently compare two different problems:

1. Initial state: the peer's (x, y, theta, c, c'), with Example 7's c'0 projected onto the
   constraints (ERRATA D5), equals swim's first row, and so do its energies (kinetic_fluid,
   kinetic_shape, kinetic_rigid, potential) for Examples 3 and 7.
2. A short run: swim (abm) and the peer (DOP853), both at rtol 1e-12, over t in [0, 0.5]: the
   states at every output row agree to 1e-9 (they agree to ~1e-12 at t = 10).
3. The peer's right-hand side at Example 7's start is the Euler-Lagrange equation: its c'' is what
   a fourth-order centred difference of swim's c' (5 rows 1e-3 apart around t = 0.5) gives, to 1e-7
   (the difference's own truncation error is ~3e-9 there; a model term off by 1e-6 would show).
4. The peer's barrier quadrature (trapezoidal, 256 nodes) is converged at Example 7's start
   (min J = 0.0396): its gradient agrees with 1024 nodes to 1e-12."""
import os
import sys

import numpy as np

import swimtest
from swimtest import check

sys.path.insert(0, os.path.join(swimtest.ROOT, "tests", "bench", "peer"))
import peer_model  # noqa: E402

SCENES = ["example3", "example7"]


def scene(name, nodes=256):
    return peer_model.load_scene(os.path.join(swimtest.ROOT, "models", name + ".toml"), nodes=nodes)


def state_of(rows, nx):
    names = ["x", "y", "theta"] + peer_model.coord_names((nx - 2) // 2)
    names += ["d" + n for n in peer_model.coord_names((nx - 2) // 2)]
    return np.array([[r[n] for n in names] for r in rows])


def test_1_initial_state_and_energies():
    for name in SCENES:
        sc, y0, _ = scene(name)
        p, rows, _ = swimtest.run("models/%s.toml" % name, name + "-start", "--t-end", "0.1",
                                  "--output-step", "0.1")
        check(rows is not None, "%s: swim wrote no trajectory: %s" % (name, p.stderr[-300:]))
        if rows is None:
            continue
        d = np.abs(state_of(rows, sc.nx)[0] - y0).max()
        check(d <= 1e-15, "%s: initial state differs from swim's first row by %.2e" % (name, d))
        nx = sc.nx
        fluid, shape, rigid, pot = sc.energies(y0[3:3 + nx], y0[3 + nx:])
        r = rows[0]
        for what, mine, swims in (("kinetic_fluid", fluid, r["kinetic_fluid"]),
                                  ("kinetic_shape", shape, r["kinetic_shape"]),
                                  ("kinetic_rigid", rigid, r["kinetic_rigid"]), ("potential", pot, r["potential"])):
            check(abs(mine - swims) <= 1e-12 * max(1.0, abs(swims)),
                  "%s: %s at t = 0: peer %.15g, swim %.15g" % (name, what, mine, swims))


def test_2_short_run():
    from scipy.integrate import solve_ivp
    for name in SCENES:
        sc, y0, _ = scene(name)
        p, rows, _ = swimtest.run("models/%s.toml" % name, name + "-short", "--t-end", "0.5",
                                  "--output-step", "0.1", "--rtol", "1e-12", "--atol", "1e-14")
        check(rows is not None, "%s: swim wrote no trajectory: %s" % (name, p.stderr[-300:]))
        if rows is None:
            continue
        t = np.atleast_1d(rows["t"])
        sol = solve_ivp(sc.rhs, (0.0, t[-1]), y0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t)
        check(sol.status == 0, "%s: solve_ivp: %s" % (name, sol.message))
        d = np.abs(sol.y.T - state_of(rows, sc.nx)).max()
        check(d <= 1e-9, "%s: peer and swim differ by %.2e over t in [0, 0.5]" % (name, d))


def test_3_acceleration():
    sc, _, _ = scene("example7")
    nx = sc.nx
    p, rows, _ = swimtest.run("models/example7.toml", "ex7-fd", "--t-end", "0.505", "--output-step", "0.001",
                              "--rtol", "1e-12", "--atol", "1e-14")
    check(rows is not None, "example7: swim wrote no trajectory: %s" % p.stderr[-300:])
    if rows is None:
        return
    S = state_of(rows, nx)
    i = int(np.argmin(np.abs(rows["t"] - 0.5)))
    h = rows["t"][i + 1] - rows["t"][i]
    v = S[:, 3 + nx:]
    fd = (-v[i + 2] + 8 * v[i + 1] - 8 * v[i - 1] + v[i - 2]) / (12 * h)
    xdd, _ = sc.accel(0.5, S[i, 3:3 + nx], S[i, 3 + nx:])
    d = np.abs(xdd - fd).max()
    check(d <= 1e-7 * max(1.0, np.abs(fd).max()), "example7: peer c'' differs from swim's by %.2e" % d)
    check(np.abs(xdd).max() > 1e-2, "example7: c'' is not trivially 0")


def test_4_barrier_quadrature():
    sc256, y0, _ = scene("example7", 256)
    sc1024, _, _ = scene("example7", 1024)
    x = y0[3:3 + sc256.nx]
    d = np.abs(sc256.gradW(x) - sc1024.gradW(x)).max()
    check(d <= 1e-12, "example7: barrier gradient with 256 and 1024 nodes differs by %.2e" % d)


if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_peer"))
