#!/usr/bin/env python3
"""A family of Example 3 from Python: how fast does the passive swimmer go as its body gets heavier?

Example 3 (section 4.3 of the paper) swims along y driven only by its elasticity. Here its body
density rho0 is varied from 0.25 to 4 (the fluid's stays 1), each member run to t = 30 with the
event am1:max, which marks one stroke of the shape (docs/integrators-and-events.md): the
summary's "periodic" entry then gives the period of the stroke and the mean displacement per
stroke. Left: y(t) of a few members; right: displacement per stroke, and per unit time, against
rho0. Run from the top of the source tree after `make lib`:

    /usr/bin/python3 docs/examples/family_from_python.py      # writes docs/figures/python-family.png

(about 1 s of runs; the package is taken from python/ here, from PYTHONPATH once installed).
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
import swim  # noqa: E402

SCENE = os.path.join(ROOT, "models", "example3.toml")
OUT = os.path.join(ROOT, "docs", "figures", "python-family.png")

# %% The family: 25 densities, log-spaced as `swim sweep --vary model.rho0=log:0.25:4:25` would
# space them. results=True keeps each member's rows for the left panel.
members = swim.sweep(SCENE, vary={"model.rho0": "log:0.25:4:25"}, events=["am1:max"], results=True)
failed = [m for m in members if not m["completed"]]
for m in failed:   # a failed member is a row with its reason, not an exception
    print("member %d (rho0 = %g) failed: %s" % (m["id"], m["model.rho0"], m["reason"]))

# %% Per stroke: the period and the mean displacement between successive maxima of a_-1.
rho0, period, dy = [], [], []
for m in members:
    if not m["completed"]:
        continue
    stroke = m["result"].summary["periodic"][0]
    rho0.append(m["model.rho0"])
    period.append(stroke["period"])
    dy.append(stroke["displacement_per_period"]["y"])
rho0, period, dy = map(np.array, (rho0, period, dy))
speed = dy / period
print("rho0    period    dy/stroke   dy/dt")
for row in zip(rho0, period, dy, speed):
    print("%-7.4g %-9.6g %-11.6g %.6g" % row)

# %% The figure.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
for m in members[::6]:
    r = m["result"]
    ax1.plot(r["t"], r["y"], label=r"$\rho_0$ = %.3g" % m["model.rho0"])
ax1.set_xlabel("t")
ax1.set_ylabel("y (body position)")
ax1.set_title("Example 3, y(t) of 5 members")
ax1.legend(fontsize=8)
ax2.semilogx(rho0, dy, "o-", label="displacement per stroke")
ax2.semilogx(rho0, speed, "s-", label="displacement per unit time")
ax2.set_xlabel(r"body density $\rho_0$ (fluid: $\rho_f$ = 1)")
ax2.set_ylabel(r"$\Delta y$")
ax2.set_title("per stroke (events am1:max), t = 0..30")
ax2.legend(fontsize=8)
ax2.grid(True, which="both", alpha=0.3)
fig.suptitle("swim %s from Python: %d members, %d failed" % (swim.__version__, len(members), len(failed)))
fig.tight_layout()
fig.savefig(OUT, dpi=110)
print("wrote", os.path.relpath(OUT, ROOT))
