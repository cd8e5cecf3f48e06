#!/usr/bin/env python3
"""The companion page's work-precision figure, made from the current build.

Usage: work_precision.py OUTDIR [--scenes a,b,...] [--source auto|quick|CSV]

Source of the numbers (`--source`, default auto):
  * the full bench's latest table, build/bench/accuracy/accuracy.csv (`make bench-accuracy`,
    ~9 min), when it is newer than the swim binary measured (auto), or the CSV named;
  * otherwise (auto) or always (quick) a quick measurement: tests/bench/bench_accuracy.py --quick
    on the page's paper scenes (rtol 1e-4, 1e-7, 1e-10 per integrator, one repetition, errors
    against the abm reference at rtol 1e-13; ~30 s for the ten paper scenes on the 2-core
    machine), written to OUTDIR/accuracy.csv and OUTDIR/table.md.
The figure, OUTDIR/work_precision.png, is drawn for the page's width (1100 px, 3 panels a row,
10-11 pt text at 1:1), from the CSV by tests/bench/plot_accuracy.py's reader.
"""
import json
import math
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCH = os.path.join(ROOT, "tests", "bench")
FULL_CSV = os.path.join(ROOT, "build", "bench", "accuracy", "accuracy.csv")
PAPER_SCENES = ["example1", "example2a", "example2b", "example2c", "example3", "example4",
                "example5", "example6", "example7", "selfpropelled"]
WIDTH_PX = 1100


def quick_measure(outdir, scenes, swim, python):
    """bench_accuracy.py --quick on SCENES with SWIM (not only bin/swim: the bench's SWIM_SRC is
    set), into OUTDIR. Returns (csv path, seconds, log text)."""
    os.makedirs(outdir, exist_ok=True)
    prog = ("import sys; sys.path.insert(0, %r); import bench_accuracy as b; b.SWIM_SRC = %r; "
            "sys.exit(b.main(sys.argv[1:]))" % (BENCH, os.path.abspath(swim)))
    cmd = [python, "-c", prog, "--quick", "--scenes", ",".join(scenes), "--out", outdir]
    # the bench runs a private copy of the binary: tell it where the generator lives
    env = dict(os.environ, SWIM_SHARE=os.environ.get("SWIM_SHARE", ROOT))
    t = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    seconds = time.time() - t
    with open(os.path.join(outdir, "bench.log"), "w") as fh:
        fh.write("$ bench_accuracy.py --quick --scenes %s --out %s\n%s%s"
                 % (",".join(scenes), outdir, p.stderr, p.stdout))
    csv_path = os.path.join(outdir, "accuracy.csv")
    if not os.path.exists(csv_path) or os.path.getsize(csv_path) < 200:
        raise RuntimeError("quick work-precision measurement wrote no table (status %d): %s"
                           % (p.returncode, (p.stderr + p.stdout).strip()[-400:]))
    return csv_path, seconds


def choose_source(source, swim):
    """'full' (the bench's table, newer than the binary), 'quick', or a CSV path."""
    if source == "quick":
        return "quick"
    if source == "auto":
        if os.path.exists(FULL_CSV) and os.path.getmtime(FULL_CSV) > os.path.getmtime(swim):
            return FULL_CSV
        return "quick"
    return source


def plot(csv_path, png, subtitle):
    """Page-width work-precision: one panel per scene, 3 a row, max error over the grid against
    CPU ms; returns the number of scenes drawn."""
    sys.path.insert(0, BENCH)
    import plot_accuracy as pa
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = pa.read(csv_path)
    names = [n for n in scenes if scenes[n]["curves"]]
    if not names:
        raise RuntimeError("%s: no completed run to draw" % csv_path)
    ncol = 3 if len(names) > 2 else len(names)
    nrow = int(math.ceil(len(names) / ncol))
    plt.rcParams.update({"font.size": 11, "axes.titlesize": 12, "axes.labelsize": 11,
                         "xtick.labelsize": 10, "ytick.labelsize": 10, "legend.fontsize": 11})
    w_in = WIDTH_PX / 100.0
    panel_h = 2.9
    head_in, legend_in = 0.75, 0.9
    fig, axes = plt.subplots(nrow, ncol, figsize=(w_in, nrow * panel_h + head_in + legend_in),
                             squeeze=False)
    used = set()
    for i, name in enumerate(names):
        ax = axes[i // ncol][i % ncol]
        sc = scenes[name]
        pa.draw_scene(ax, name, sc, 2, used)
        if i % ncol == 0:
            ax.set_ylabel("max error")
        if i + ncol >= len(names):
            ax.set_xlabel("CPU ms (integrator)")
    for j in range(len(names), nrow * ncol):
        axes[j // ncol][j % ncol].axis("off")
    handles = pa.legend_handles(used)
    fig.legend(handles=handles, loc="lower center", ncol=4, frameon=False)
    fig.suptitle("Work-precision per paper scene: max error over the output grid against CPU "
                 "time\n" + subtitle, fontsize=12)
    H = fig.get_size_inches()[1]
    fig.tight_layout(rect=(0, legend_in / H, 1, 1 - 0.1 / H))
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return len(names)


def make(outdir, scenes, swim, python, source="auto"):
    """The figure and what the page says about it: dict(png, csv, source, seconds, scenes,
    when, table)."""
    os.makedirs(outdir, exist_ok=True)
    src = choose_source(source, swim)
    t0 = time.time()
    info = {"scenes": scenes}
    if src == "quick":
        csv_path, secs = quick_measure(outdir, scenes, swim, python)
        info.update(source="quick", measure_seconds=secs)
        sub = ("quick measurement for this page (bench_accuracy.py --quick: rtol 1e-4, 1e-7, "
               "1e-10, one repetition), %s" % time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
    else:
        csv_path = src
        info.update(source="table", measure_seconds=0.0)
        sub = ("make bench-accuracy's table %s (%s)" % (
            os.path.relpath(csv_path, ROOT),
            time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(csv_path)))))
    png = os.path.join(outdir, "work_precision.png")
    info["panels"] = plot(csv_path, png, sub)
    info.update(png=png, csv=csv_path, subtitle=sub, seconds=time.time() - t0)
    table = os.path.join(os.path.dirname(csv_path), "table.md")
    info["table"] = table if os.path.exists(table) else None
    return info


def main(argv):
    if not argv or argv[0].startswith("-"):
        print(__doc__.strip())
        return 2
    out = argv[0]
    scenes, source = PAPER_SCENES, "auto"
    i = 1
    while i < len(argv):
        if argv[i] == "--scenes":
            scenes = argv[i + 1].split(",")
        elif argv[i] == "--source":
            source = argv[i + 1]
        else:
            print(__doc__.strip())
            return 2
        i += 2
    swim = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
    info = make(out, scenes, swim, os.environ.get("PYTHON") or sys.executable, source)
    print(json.dumps({k: v for k, v in info.items()}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
