#!/usr/bin/env python3
"""convergence.png of a `swim optimize` folder: the best value of the quantity and the varied keys
against the iteration, from DIR/optimize.csv (one row per iteration, written by the optimizer)."""

import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(folder):
    with open(os.path.join(folder, "optimize.csv")) as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        print("plot_optimize.py: %s/optimize.csv has no rows" % folder, file=sys.stderr)
        return 1
    cols = list(rows[0].keys())
    # iteration, evaluations, the keys, the quantity, size and (since multi-start) start
    tail = 3 if cols[-1] == "start" else 2
    keys, quantity = cols[2:-tail], cols[-tail]
    it = list(range(len(rows)))   # every logged iteration of every start, in order
    fig, axes = plt.subplots(1 + len(keys), 1, figsize=(7, 2.2 * (1 + len(keys))), sharex=True)
    axes[0].plot(it, [float(r[quantity]) for r in rows], "o-", ms=3)
    axes[0].set_ylabel("best " + quantity + " of the start")
    starts = len({r.get("start", "1") for r in rows})
    axes[0].set_title("swim optimize: convergence (%d iterations over %d start%s, %s runs)"
                      % (len(rows) - starts, starts, "" if starts == 1 else "s", rows[-1]["evaluations"]))
    for ax, k in zip(axes[1:], keys):
        ax.plot(it, [float(r[k]) for r in rows], "o-", ms=3, color="C1")
        ax.set_ylabel(k)
    axes[-1].set_xlabel("iteration (all starts in turn)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "convergence.png"), dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
