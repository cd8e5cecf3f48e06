#!/usr/bin/env python3
"""Work-precision diagrams from build/bench/accuracy/accuracy.csv (written by bench_accuracy.py).

work_precision_cpu.png: max error over the output grid vs CPU time (median integrate_seconds);
work_precision_rhs.png: the same error vs RHS evaluations. Log-log, one panel per scene, one line
per integrator (specialized kernel, solid), generic-kernel abm/rk8pd dashed with open markers, the
ode113-default abm run as a star, and the reference uncertainty (abm vs rk8pd at 1e-13) as a grey
dotted line. Failed runs are left out.
Usage: plot_accuracy.py ACCURACY_CSV OUTDIR
"""
import csv
import math
import os
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

COLORS = OrderedDict([
    ("abm", "tab:red"), ("abm-step", "salmon"), ("rk8pd", "tab:green"), ("msadams", "tab:blue"),
    ("cvode-adams", "tab:purple"), ("cvode-bdf", "tab:orange"), ("msbdf", "tab:brown")])
MARKERS = {"abm": "o", "abm-step": "x", "rk8pd": "^", "msadams": "s", "cvode-adams": "D", "cvode-bdf": "v", "msbdf": "P"}


def read(csv_path):
    scenes = OrderedDict()
    with open(csv_path) as fh:
        for r in csv.DictReader(fh):
            sc = scenes.setdefault(r["scene"], {"T": float(r["t_end"]), "ref": float(r["ref_err_grid"]),
                                                "curves": OrderedDict(), "ode113": None})
            if r["status"] != "completed":
                continue
            err = float(r["err_grid"])
            if not (err > 0 and math.isfinite(err)):
                continue
            p = (float(r["rtol"]), err, float(r["cpu_ms_median"]), int(r["rhs_evaluations"]))
            if r["series"] == "ode113":
                sc["ode113"] = p
            else:
                sc["curves"].setdefault((r["integrator"], r["kernel"]), []).append(p)
    return scenes


def draw_scene(ax, name, sc, xi, used):
    """One scene's panel: error against column xi (2 CPU ms, 3 RHS evaluations) of every curve,
    abm at ode113's defaults, the reference's uncertainty; the (method, kernel) drawn go to used."""
    for (m, k), pts in sc["curves"].items():
        pts = sorted(pts, key=lambda p: -p[0])
        generic = k == "generic"
        ax.loglog([p[xi] for p in pts], [p[1] for p in pts], color=COLORS.get(m, "k"),
                  marker=MARKERS.get(m, "x"), ms=4.5 if not generic else 6, lw=1.9 if m == "abm" else 1.3,
                  ls="--" if generic else "-", mfc="none" if generic else COLORS.get(m, "k"),
                  zorder=3 if m == "abm" else 2)
        used.add((m, k))
    if sc["ode113"]:
        p = sc["ode113"]
        ax.loglog([p[xi]], [p[1]], marker="*", ms=13, color="tab:red", mec="k", ls="none", zorder=4)
        used.add(("ode113", ""))
    if sc["ref"] > 0:
        ax.axhline(sc["ref"], color="0.4", ls=":", lw=1.2, zorder=1)
    ax.set_title("%s (T = %g)" % (name, sc["T"]))
    ax.grid(True, which="major", alpha=0.35)


def legend_handles(used):
    """The legend of the panels drawn, in the order of COLORS."""
    handles = []
    for m, col in COLORS.items():
        for k in ("specialized", "generic"):
            if (m, k) in used:
                g = k == "generic"
                handles.append(Line2D([], [], color=col, marker=MARKERS[m], ls="--" if g else "-",
                                      mfc="none" if g else col, label=m + (" (generic kernel)" if g else "")))
    if ("ode113", "") in used:
        handles.append(Line2D([], [], color="tab:red", marker="*", ms=13, mec="k", ls="none",
                              label="abm at ode113 defaults (rtol 1e-3, atol 1e-6)"))
    handles.append(Line2D([], [], color="0.4", ls=":", label="reference uncertainty (abm vs rk8pd at 1e-13)"))
    return handles


def plot(csv_path, outdir):
    scenes = read(csv_path)
    plt.rcParams.update({"font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10,
                         "xtick.labelsize": 9, "ytick.labelsize": 9, "legend.fontsize": 10})
    names = list(scenes)
    ncol = min(5, len(names)) if len(names) > 3 else len(names)
    nrow = int(math.ceil(len(names) / ncol))
    written = []
    for key, xlabel, fname in (("cpu", "CPU time [ms] (median integrate_seconds)", "work_precision_cpu.png"),
                               ("rhs", "RHS evaluations", "work_precision_rhs.png")):
        xi = 2 if key == "cpu" else 3
        fig, axes = plt.subplots(nrow, ncol, figsize=(3.9 * ncol, 3.6 * nrow + 2.0), squeeze=False)
        used = set()
        for i, name in enumerate(names):
            ax = axes[i // ncol][i % ncol]
            sc = scenes[name]
            draw_scene(ax, name, sc, xi, used)
            ax.set_ylim(top=max(ax.get_ylim()[1], 1.5))
            if i // ncol == nrow - 1 or i + ncol >= len(names):
                ax.set_xlabel(xlabel)
            if i % ncol == 0:
                ax.set_ylabel("max error over grid")
        for j in range(len(names), nrow * ncol):
            axes[j // ncol][j % ncol].axis("off")
        handles = legend_handles(used)
        width = 3.9 * ncol
        legcol = max(1, min(len(handles), int(width // 3.9)))
        legrows = int(math.ceil(len(handles) / legcol))
        bottom_in = 0.2 + 0.25 * legrows
        fig.set_size_inches(width, 3.6 * nrow + bottom_in + 0.8)
        fig.legend(handles=handles, loc="lower center", ncol=legcol, frameon=False)
        title = ("swim work-precision (%s)" % ("CPU time" if key == "cpu" else "RHS evaluations"),
                 "rtol 1e-3 .. 1e-13, atol = rtol*1e-2; specialized kernel unless marked generic")
        fig.suptitle(("; " if ncol >= 4 else "\n").join(title), fontsize=12)
        H = fig.get_size_inches()[1]
        fig.tight_layout(rect=(0, bottom_in / H, 1, 1))
        path = os.path.join(outdir, fname)
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    return written


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    for p in plot(sys.argv[1], sys.argv[2]):
        print("wrote", p)
