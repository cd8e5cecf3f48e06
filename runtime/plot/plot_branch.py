#!/usr/bin/env python3
"""The figures of a `swim continue` folder (swim plot DIR when DIR holds branch.json).

bifurcation.png: the displacement per period |(dx, dy)| and the period against the parameter,
stable points joined by solid lines and unstable ones by dashed lines, the special points
(refined brackets) marked and named. multipliers.png: every point's multipliers on the
complement of the exact 1s, in the complex plane with the unit circle, coloured by the parameter,
and max |lambda| - 1 against the parameter (where stability is decided: 1e-6, the branch's
tolerance). Reads DIR/branch.csv and DIR/branch.json, writes the figures into DIR."""

import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_run import DIMLESS, LENGTH, steady_axis, with_unit  # noqa: E402  (one set of unit labels)
from plot_family import key_label  # noqa: E402  (scene keys named as in a sweep's figures)

OUTSIDE_TOL = 1e-6   # runtime/control/continuation.h, SWIM_CONT_OUTSIDE_TOL


def read(folder):
    with open(os.path.join(folder, "branch.csv")) as fh:
        rows = list(csv.DictReader(fh))
    with open(os.path.join(folder, "branch.json")) as fh:
        meta = json.load(fh)
    return rows, meta


def parameter_label(meta, column):
    key = meta["parameter"]
    return with_unit("energy $E$ (target)" if key == "energy" else key_label(column), DIMLESS)


def runs_of_stability(x, y, stable):
    """Consecutive points with the same stability, each run extended to the next point so that
    the curve stays connected."""
    out, start = [], 0
    for i in range(1, len(x) + 1):
        if i == len(x) or stable[i] != stable[start]:
            end = min(i + 1, len(x))
            out.append((x[start:end], y[start:end], stable[start]))
            start = i
    return out


def fig_bifurcation(folder, rows, meta):
    fig = build_bifurcation(rows, meta)
    fig.savefig(os.path.join(folder, "bifurcation.png"), dpi=110)
    plt.close(fig)


def build_bifurcation(rows, meta):
    col = list(rows[0].keys())[0]
    x = [float(r[col]) for r in rows]
    disp = [math.hypot(float(r["dx"]), float(r["dy"])) for r in rows]
    period = [float(r["period"]) for r in rows]
    stable = [r["stable"] == "yes" for r in rows]
    fig, axes = plt.subplots(2, 1, figsize=(7.5, 6.4), sharex=True)
    for ax, y, label in ((axes[0], disp, with_unit(r"displacement per period $|\Delta r|$", LENGTH, newline=True)),
                         (axes[1], period, with_unit("period $T$", DIMLESS, newline=True))):
        for xs, ys, st in runs_of_stability(x, y, stable):
            ax.plot(xs, ys, "-" if st else "--", color="C0" if st else "C3", lw=1.6)
        ax.plot(x, y, "o", ms=3, color="k")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if not (ax is axes[0] and max(disp) < 1e-8):
            steady_axis(ax, y)
        for i, s in enumerate(meta["special_points"]):
            at = 0.5 * (s["between"][0] + s["between"][1])
            ax.axvline(at, color="C2", lw=0.9, ls=":")
            if ax is axes[0]:
                ax.annotate("%d" % (i + 1), (at, 1.0), xycoords=("data", "axes fraction"), ha="center",
                            va="bottom", fontsize=8, color="C2")
    axes[1].set_xlabel(parameter_label(meta, col))
    if max(disp) < 1e-8:   # librations: rounding, not a displacement, would fill the axis
        axes[0].set_ylim(-0.01, 0.1)
        axes[0].text(0.5, 0.5, "no net displacement (|Δr| < 1e-8 at every point)", transform=axes[0].transAxes,
                     ha="center", va="center", fontsize=9, color="0.3")
    x0 = meta.get("start_orbit_parameter")
    if x0 is not None:
        for ax in axes:
            ax.axvline(x0, color="0.5", lw=0.8)
    # an entry only for what is drawn
    handles = ([Line2D([], [], color="C0", lw=1.6, label="stable")] if any(stable) else []) + \
        ([Line2D([], [], color="C3", lw=1.6, ls="--", label="unstable")] if not all(stable) else []) + \
        ([Line2D([], [], color="0.5", lw=0.8, label="the scene's own orbit")] if x0 is not None else []) + \
        ([Line2D([], [], color="C2", lw=0.9, ls=":", label="special points (numbered)")]
         if meta["special_points"] else [])
    notes = ["%d: %s at %.8g%s" % (i + 1, s["kind"], 0.5 * (s["between"][0] + s["between"][1]),
                                   "" if s.get("refined") else " (not refined)")
             for i, s in enumerate(meta["special_points"])]
    lines_below = (len(notes) + 1) // 2
    bottom = 0.08 + 0.035 * lines_below
    fig.suptitle("swim continue: %s, %d points in %s" % (os.path.basename(meta["scene"]), len(rows),
                                                         key_label(meta["parameter"])),
                 fontsize=10)
    fig.tight_layout(rect=(0, bottom, 1, 0.97))
    if handles:
        fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8, frameon=False,
                   bbox_to_anchor=(0.5, bottom - 0.07))
    for k, note in enumerate(notes):   # two columns of notes under the legend
        fig.text(0.08 + 0.46 * (k % 2), bottom - 0.085 - 0.035 * (k // 2), note, fontsize=8, color="C2", va="top")
    return fig


def fig_multipliers(folder, rows, meta):
    fig = build_multipliers(rows, meta)
    fig.savefig(os.path.join(folder, "multipliers.png"), dpi=110)
    plt.close(fig)


def build_multipliers(rows, meta):
    col = list(rows[0].keys())[0]
    pts = meta["points"]
    pmin, pmax = min(p["parameter"] for p in pts), max(p["parameter"] for p in pts)
    cmap = plt.get_cmap("viridis")
    norm = plt.Normalize(pmin, pmax if pmax > pmin else pmin + 1)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 4.6))
    th = [2 * math.pi * k / 400 for k in range(401)]
    ax0.plot([math.cos(t) for t in th], [math.sin(t) for t in th], color="0.6", lw=0.8)
    for p in pts:
        ax0.plot([m[0] for m in p["multipliers"]], [m[1] for m in p["multipliers"]], "o", ms=3,
                 color=cmap(norm(p["parameter"])))
    far = [math.hypot(*m) for p in pts for m in p["multipliers"] if max(abs(m[0]), abs(m[1])) > 1.6]
    ax0.set_xlim(-1.6, 1.6)   # the unit circle; multipliers far outside it are counted, not drawn
    ax0.set_ylim(-1.6, 1.6)
    if far:
        ax0.text(0.02, 0.02, "%d beyond the frame (|λ| up to %.3g)" % (len(far), max(far)),
                 transform=ax0.transAxes, fontsize=8, color="0.3")
    ax0.set_aspect("equal")
    ax0.set_xlabel(with_unit(r"Re $\lambda$", DIMLESS))
    ax0.set_ylabel(with_unit(r"Im $\lambda$", DIMLESS))
    ax0.set_title("multipliers (the exact 1s taken out) and the unit circle", fontsize=9)
    ax0.grid(alpha=0.3)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax0, label=parameter_label(meta, col))
    dev = [max([math.hypot(*m) for m in p["multipliers"]] or [1.0]) - 1.0 for p in pts]
    ax1.plot([p["parameter"] for p in pts], dev, "o-", ms=3)
    ax1.set_yscale("symlog", linthresh=1e-12)
    ax1.axhline(OUTSIDE_TOL, color="C3", lw=0.8, ls="--", label="outside the circle above 1e-6")
    ax1.set_xlabel(parameter_label(meta, col))
    ax1.set_ylabel(with_unit(r"max $|\lambda| - 1$", DIMLESS))
    ax1.grid(alpha=0.3)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    # under the panels: inside the axes it would cover the points
    fig.legend(handles=[Line2D([], [], color="C3", lw=0.8, ls="--", label="outside the circle above 1e-6")],
               loc="lower center", fontsize=8, frameon=False)
    return fig


def main(argv):
    if len(argv) != 2:
        print("plot_branch.py: expected one folder of swim continue", file=sys.stderr)
        return 2
    folder = argv[1]
    try:
        rows, meta = read(folder)
    except (OSError, ValueError) as e:
        print("plot_branch.py: %s: %s" % (folder, e), file=sys.stderr)
        return 1
    if not rows:
        print("plot_branch.py: %s/branch.csv has no points" % folder, file=sys.stderr)
        return 1
    fig_bifurcation(folder, rows, meta)
    fig_multipliers(folder, rows, meta)
    print("%s: bifurcation.png, multipliers.png" % folder)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
