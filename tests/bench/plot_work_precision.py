#!/usr/bin/env python3
"""Work-precision diagram for the ODE benchmark.

Reads the CSV written by bench_ode (problem,method,tol,error,rhs_evals,steps,
rejected,cpu_s) and draws, for every problem, RHS evaluations (top row) and
CPU time (bottom row) against the achieved error, one curve per method.
Usage: plot_work_precision.py CSV PNG
"""
import csv
import sys
from collections import OrderedDict, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "abm": dict(color="tab:red", marker="o", lw=2.2),
    "msadams": dict(color="tab:blue", marker="s", lw=1.2),
    "rk8pd": dict(color="tab:green", marker="^", lw=1.2),
    "cvode-adams": dict(color="tab:purple", marker="D", lw=1.2),
    "abm-step": dict(color="salmon", marker="x", lw=1.2, ls="--"),
}


def main(csv_path, png_path):
    data = OrderedDict()
    with open(csv_path) as fh:
        for row in csv.DictReader(fh):
            err = float(row["error"])
            cpu = float(row["cpu_s"])
            if not (err > 0 and cpu == cpu):
                continue
            prob = data.setdefault(row["problem"], defaultdict(list))
            prob[row["method"]].append((err, int(row["rhs_evals"]), cpu, float(row["tol"])))
    probs = list(data)
    fig, axes = plt.subplots(2, len(probs), figsize=(4.2 * len(probs), 7.5), squeeze=False)
    for j, name in enumerate(probs):
        for method, pts in data[name].items():
            pts.sort(key=lambda p: -p[3])
            errs = [p[0] for p in pts]
            st = STYLE.get(method, dict(marker="x", lw=1))
            axes[0][j].loglog(errs, [p[1] for p in pts], label=method, ms=4, **st)
            axes[1][j].loglog(errs, [p[2] * 1e3 for p in pts], label=method, ms=4, **st)
        axes[0][j].set_title(name)
        axes[1][j].set_xlabel("achieved error (max norm at t_end)")
        for ax in (axes[0][j], axes[1][j]):
            ax.invert_xaxis()
            ax.grid(True, which="major", alpha=0.3)
            ax.axvspan(1e-12, 1e-6, color="0.9", zorder=0)
    axes[0][0].set_ylabel("RHS evaluations")
    axes[1][0].set_ylabel("CPU time per solve [ms] (median)")
    axes[0][0].legend(fontsize=8)
    fig.suptitle("swim ODE work-precision: tolerances 1e-4 .. 1e-14 (shaded: target error range)")
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    print("wrote", png_path)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
