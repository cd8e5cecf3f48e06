#!/usr/bin/env python3
"""Drift over the long runs: relative energy error and volume residual vs time for
models/hard/long_example1.toml and long_example3.toml at their rtol 1e-10: as the scenes run
(projection, ABM step-size look-ahead p = 6), with STEP's step-size rule (--step-lookahead 0), and
without projection (--no-projection); and at rtol 1e-12.
Usage: plot_drift.py OUTPUT.png   (runs bin/swim; about 15 s)"""

import os
import subprocess
import sys
import tempfile

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(scene, out, *args):
    subprocess.run([os.path.join(ROOT, "bin", "swim"), "run", scene, "--out", out, "--quiet", *args],
                   check=True, capture_output=True, cwd=ROOT)
    return np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)


def main():
    out_png = sys.argv[1] if len(sys.argv) > 1 else "drift.png"
    tmp = tempfile.mkdtemp(prefix="swim-drift-")
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6), dpi=110)
    variants = [([], "rtol 1e-10 (scene)", "-"),
                (["--step-lookahead", "0"], "rtol 1e-10, STEP rule", "--"),
                (["--no-projection"], "rtol 1e-10, no projection", ":"),
                (["--rtol", "1e-12", "--atol", "1e-14"], "rtol 1e-12", "-.")]
    colors = {"long_example1": "tab:blue", "long_example3": "tab:red"}
    for name, color in colors.items():
        for i, (args, label, style) in enumerate(variants):
            d = run("models/hard/%s.toml" % name, os.path.join(tmp, "%s-%d" % (name, i)), *args)
            t = d["t"][1:]
            # running maxima: the worst error so far, which is what a user has to live with
            e = np.maximum.accumulate(np.abs(d["energy"][1:] - d["energy"][0]) / d["energy"][0])
            v = np.maximum.accumulate(np.abs(d["res_volume"][1:]))
            lab = "%s, %s" % (name.replace("long_", "Ex. ").replace("example", ""), label)
            axes[0].loglog(t, np.maximum(e, 1e-17), style, color=color, label=lab, lw=1.2)
            axes[1].loglog(t, np.maximum(v, 1e-17), style, color=color, label=lab, lw=1.2)
    tt = np.array([1.0, 1000.0])
    axes[0].loglog(tt, 1e-11 * tt, color="gray", lw=0.8, alpha=0.7)
    axes[0].text(2, 4e-11, "slope 1 (linear growth)", color="gray", fontsize=9)
    axes[0].axhline(1e-8, color="black", lw=0.8, ls=":")
    axes[0].text(1.2, 1.4e-8, "drift bound 1e-8 at T = 1000", fontsize=9)
    axes[0].set_title("max over [0, t] of |E - E(0)| / E(0)")
    axes[1].set_title("max over [0, t] of the volume residual |Σ k|c_k|² - µ0²| (2.5)")
    for ax in axes:
        ax.set_xlabel("time t")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlim(1, 1000)
    axes[1].legend(fontsize=8, loc="center right")
    fig.suptitle("Long runs (T = 1000) of Examples 1 and 3 with ABM: drift with and without projection and look-ahead")
    fig.tight_layout()
    fig.savefig(out_png)
    print(out_png)


if __name__ == "__main__":
    main()
