#!/usr/bin/env python3
"""The text of every figure of `swim plot DIR` is legible: on short real runs of three scenes
(Example 1, Example 3 with events so instants.png has marks, Example 6 with three free modes, the
prescribed stroke), every figure
kind plot_run.py draws is built through plot_run.build_figure (the function `swim plot` saves) and
drawn with matplotlib's renderer; then, per figure:
  * no two drawn texts overlap (titles, axis and tick labels, legend texts, annotations, colour
    bar labels; empty strings ignored), and every text lies inside the figure;
  * every axis that shows tick labels has a non-empty label that gives a unit (or says it is
    dimensionless), colour bars included;
  * every colour-mapped artist (pcolormesh, coloured line collection, scalar mappable) has a
    colour bar;
  * no raw coordinate name (am3, dbm2, c_-3) outside math text.
energy.png of Example 1 (no elasticity) must not list a potential term. The same checks on the
figures of a sweep (plot_family.py), with and without kept trajectories."""
import os
import re
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.text import Text  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.collections import Collection  # noqa: E402

import swimtest  # noqa: E402
from swimtest import check  # noqa: E402

sys.path.insert(0, os.path.join(swimtest.ROOT, "runtime", "plot"))
os.environ.setdefault("SWIM_BIN", swimtest.SWIM)
import plot_run  # noqa: E402

UNIT_WORDS = ("dimensionless", "radii", "(%)", "count", "(rad)", "rad per unit time")
RAW_NAME = re.compile(r"(?<![A-Za-z0-9_])(d?[ab](?:1|m[0-9]+)|c_-?[0-9]+)(?![A-Za-z0-9_])")
SLACK = 1.0   # pixels two boxes may share (antialiasing, rounding of the extents)


def drawn_texts(fig):
    """Draws fig and returns [(Text, bbox, corners)] of every Text drawn with a non-empty string:
    its window extent (axis-aligned) and the 4 corners of the rotated rectangle the text fills
    (same centre, the unrotated width and height, turned by its rotation), taken at the moment it
    was drawn (3-d tick and axis labels move and turn during the draw)."""
    seen = []
    orig = Text.draw

    def spy(self, renderer):
        orig(self, renderer)
        if self.get_visible() and self.get_text().strip():
            box = self.get_window_extent(renderer).frozen()
            rot = self.get_rotation()
            if rot % 180:
                self.set_rotation(0)
                flat = self.get_window_extent(renderer)
                self.set_rotation(rot)
                w, h = flat.width, flat.height
            else:
                w, h = box.width, box.height
            c, s = np.cos(np.radians(rot)), np.sin(np.radians(rot))
            half = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2.0
            corners = np.array([box.x0 + box.x1, box.y0 + box.y1]) / 2.0 + half @ np.array([[c, s], [-s, c]])
            seen.append((self, box, corners))

    Text.draw = spy
    try:
        fig.canvas.draw()
    finally:
        Text.draw = orig
    return seen


def overlaps(a, b):
    """Whether two convex quadrilaterals (4x2 corners) share more than SLACK pixels in every
    direction (separating axis test on the edge normals of both)."""
    for poly in (a, b):
        for i in range(4):
            e = poly[(i + 1) % 4] - poly[i]
            n = np.array([-e[1], e[0]])
            norm = np.hypot(*n)
            if norm == 0:
                continue
            n = n / norm
            pa, pb = a @ n, b @ n
            if min(pa.max(), pb.max()) - max(pa.min(), pb.min()) <= SLACK:
                return False
    return True


def describe(t):
    return repr(t.get_text()[:50])


def axes_of(fig):
    return [ax for ax in fig.axes if ax.get_visible()]


def colorbar_axes(fig):
    return [ax for ax in fig.axes if getattr(ax, "_colorbar", None) is not None]


def problems(fig):
    """What is wrong with the text of fig: {"overlap", "labels", "colorbar", "raw"} -> messages;
    also the drawn texts."""
    texts = drawn_texts(fig)
    fb = fig.bbox
    out = {"overlap": [], "labels": [], "colorbar": [], "raw": []}
    # 1. no overlap, inside the figure
    for i in range(len(texts)):
        ti, bi, ci = texts[i]
        if bi.x0 < fb.x0 - SLACK or bi.x1 > fb.x1 + SLACK or bi.y0 < fb.y0 - SLACK or bi.y1 > fb.y1 + SLACK:
            out["overlap"].append("%s outside the figure" % describe(ti))
        for j in range(i + 1, len(texts)):
            tj, bj, cj = texts[j]
            if overlaps(ci, cj):
                out["overlap"].append("%s overlaps %s" % (describe(ti), describe(tj)))
    drawn = {id(t) for t, _, _ in texts}
    # 2. every axis with tick labels has a label with a unit
    for ax in axes_of(fig):
        axis_list = [("x", ax.xaxis), ("y", ax.yaxis)] + ([("z", ax.zaxis)] if hasattr(ax, "zaxis") else [])
        for which, axis in axis_list:
            if not axis.get_visible():
                continue
            if not any(id(tk.label1) in drawn or id(tk.label2) in drawn for tk in axis.get_major_ticks()):
                continue
            label = axis.get_label().get_text().strip()
            if not label:
                out["labels"].append("%s-axis of %r has no label" % (which, ax.get_title()[:30]))
            elif not any(w in label for w in UNIT_WORDS):
                out["labels"].append("%s-axis label %r has no unit" % (which, label[:60]))
    # 3. every colour-mapped artist has a colour bar (and the bar a label with a unit)
    bars = colorbar_axes(fig)
    mapped = 0
    for ax in axes_of(fig):
        if ax in bars:
            continue
        for art in ax.get_children():
            if isinstance(art, ScalarMappable) and isinstance(art, Collection) and art.get_visible() \
                    and art.get_array() is not None and len(art.get_array()) > 0:
                mapped += 1
    if mapped and not bars:
        out["colorbar"].append("%d colour-mapped artist(s) but no colour bar" % mapped)
    for cax in bars:
        cb = cax._colorbar
        lab = cb.ax.get_ylabel() if cb.orientation == "vertical" else cb.ax.get_xlabel()
        if not (lab.strip() and any(w in lab for w in UNIT_WORDS)):
            out["colorbar"].append("colour bar label %r" % lab)
    # 4. raw coordinate names outside math text
    for t, _, _ in texts:
        if RAW_NAME.search(re.sub(r"\$[^$]*\$", "", t.get_text())):
            out["raw"].append(describe(t))
    return out, texts


# ---- axes and legends: no round-off drawn as structure, no legend entry without data, no legend
# over the data

OFFSET_REL = 1e-6   # an axis spanning less than this fraction of its values draws round-off


def legend_sources(fig):
    """{id(Legend): [the handles it was made from]} (the legend draws copies of its own)."""
    return getattr(fig, "_legend_sources", {})


def record_legend_sources():
    """From now on every Legend remembers the handles it was given (on its figure)."""
    from matplotlib.legend import Legend
    if getattr(Legend, "_spied", False):
        return
    orig = Legend.__init__

    def init(self, parent, handles, labels, *a, **kw):
        orig(self, parent, handles, labels, *a, **kw)
        fig = parent if not hasattr(parent, "figure") or parent.figure is None else parent.figure
        if not hasattr(fig, "_legend_sources"):
            fig._legend_sources = {}
        fig._legend_sources[id(self)] = (self, list(handles), list(labels))
    Legend.__init__ = init
    Legend._spied = True


def has_data(art):
    from matplotlib.lines import Line2D
    if isinstance(art, Line2D):
        xy = np.asarray(art.get_xydata(), float).reshape(-1, 2)
        return bool(np.isfinite(xy).all(axis=1).any())
    if isinstance(art, Collection):
        offs = np.asarray(art.get_offsets()).reshape(-1, 2) if art.get_offsets() is not None else np.zeros((0, 2))
        return len(art.get_paths()) > 0 and (len(offs) > 0 or any(len(p.vertices) for p in art.get_paths()))
    return True     # patches, images, containers: drawn as given


def style(art):
    from matplotlib.colors import to_rgba
    from matplotlib.lines import Line2D
    if isinstance(art, Line2D):
        return ("line", to_rgba(art.get_color()), art.get_linestyle(), str(art.get_marker()))
    if isinstance(art, Collection):
        fc = art.get_facecolor()
        return ("coll", tuple(np.round(fc[0], 3)) if len(fc) else None)
    return ("other", id(art))


def legend_problems(fig):
    """Offsets below OFFSET_REL of an axis's values; legend entries whose artist (or, for a proxy
    without data, every artist of the same style) has no data; legends over data points."""
    out = {"offset": [], "legend": [], "cover": []}
    fig.canvas.draw()
    for ax in axes_of(fig):
        if ax.name != "rectilinear" or getattr(ax, "_colorbar", None) is not None:
            continue
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if axis.get_scale() != "linear" or not axis.get_visible():
                continue
            lo, hi = axis.get_view_interval()
            mag = max(abs(lo), abs(hi))
            if mag > 0 and abs(hi - lo) < OFFSET_REL * mag:
                out["offset"].append("%s-axis of %r spans %.3g around %.10g (offset text %r)" % (
                    which, ax.get_title()[:30], hi - lo, 0.5 * (lo + hi),
                    axis.get_major_formatter().get_offset()))
    from matplotlib.lines import Line2D
    styles_with_data = {style(a) for ax in axes_of(fig) for a in ax.get_children()
                        if isinstance(a, (Line2D, Collection)) and a.get_visible() and has_data(a)}
    rend = fig.canvas.get_renderer()
    for leg, handles, labels in legend_sources(fig).values():
        if leg.figure is not fig or not leg.get_visible():
            continue
        for h, lab in zip(handles, labels):
            if has_data(h) and (getattr(h, "axes", None) is not None
                                or getattr(h, "figure", None) is not None or not hasattr(h, "axes")):
                continue
            if not has_data(h) and style(h) in styles_with_data:
                continue
            out["legend"].append("legend entry %r has no artist with data" % lab)
        box = leg.get_window_extent(rend)
        for ax in axes_of(fig):
            for a in ax.get_lines():
                if a.get_transform() != ax.transData or not a.get_visible():
                    continue
                xy = np.asarray(a.get_xydata(), float).reshape(-1, 2)
                xy = xy[np.isfinite(xy).all(axis=1)]
                if not len(xy):
                    continue
                pix = ax.transData.transform(xy)
                # points drawn (inside the axes) and inside the legend's box
                hit = [p for p in pix if ax.bbox.x0 <= p[0] <= ax.bbox.x1 and ax.bbox.y0 <= p[1] <= ax.bbox.y1
                       and box.x0 + SLACK < p[0] < box.x1 - SLACK and box.y0 + SLACK < p[1] < box.y1 - SLACK]
                if hit:
                    out["cover"].append("legend covers %d point(s) of %r" % (len(hit), a.get_label()[:40]))
                    break
    return out


def check_figure(tag, fig):
    found, texts = problems(fig)
    for kind, what in (("overlap", "text overlaps"), ("labels", "axis labels"),
                       ("colorbar", "colour bars"), ("raw", "raw coordinate names")):
        check(not found[kind], "%s: %s: %s" % (tag, what, "; ".join(found[kind][:6])))
    found = legend_problems(fig)
    for kind, what in (("offset", "axis offset below 1e-6 of its values"),
                       ("legend", "legend entries without data"), ("cover", "legend over data")):
        check(not found[kind], "%s: %s: %s" % (tag, what, "; ".join(found[kind][:6])))
    return texts


def test_legend_checker_catches():
    """A constant drawn on a 1e-13 offset axis, a legend entry for nothing drawn, a legend over
    the points: each reported; the same figure made right passes."""
    from matplotlib.lines import Line2D
    for bad in (True, False):
        fig, ax = plt.subplots(figsize=(4, 3))
        x = np.linspace(0, 1, 40)
        y = 0.5093094348 + (1e-13 if bad else 0.2) * x   # through the centre, under the legend
        ax.plot(x, y, "o-", color="C0", label="|dr|")
        handles = [Line2D([], [], color="C0", marker="o", label="|dr|")]
        if bad:
            handles.append(Line2D([], [], color="C3", ls="--", label="unstable"))
        ax.legend(handles=handles, loc="center" if bad else "upper left",
                  bbox_to_anchor=None if bad else (1.02, 1.0))
        found = legend_problems(fig)
        plt.close(fig)
        for kind in ("offset", "legend", "cover"):
            check(bool(found[kind]) == bad, "the legend checker, kind %s, %s figure: %s"
                  % (kind, "faulty" if bad else "right", found[kind]))


def test_checker_catches():
    """The checks see what they are meant to see: a figure with every fault is faulted on each."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.set_title("a title on top of a note")
    ax.text(0.5, 1.02, "a note under the title", transform=ax.transAxes, ha="center")
    ax.pcolormesh(np.arange(4).reshape(2, 2))
    ax.set_xlabel("am3 without a unit")
    found, _ = problems(fig)
    plt.close(fig)
    for kind in ("overlap", "labels", "colorbar", "raw"):
        check(found[kind], "the checker misses a fault of kind %s" % kind)
    # a label turned by 45 degrees (a 3-d axis label) and a tick label inside its axis-aligned box
    # but off the diagonal do not overlap; moved onto the diagonal they do
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    diag = np.array([[-14, -1], [14, -1], [14, 1], [-14, 1]], float) @ np.array([[c, s], [-s, c]]) + [10, 10]
    tick = np.array([[15, 1], [19, 1], [19, 4], [15, 4]], float)
    check(not overlaps(diag, tick) and overlaps(diag, tick + [-7, 7]), "the separating-axis test")


def figures_of(d, expect):
    """Builds every figure kind of run directory d; checks that exactly `expect` are drawn."""
    run = plot_run.open_run(d)
    got = []
    for name in plot_run.FIGURES:
        try:
            fig = plot_run.build_figure(run, name)
        except plot_run.Skip:
            continue
        got.append(name)
        try:
            yield name, fig
        finally:
            plt.close(fig)
    check(sorted(got) == sorted(expect), "%s: figures %s, expected %s" % (d, sorted(got), sorted(expect)))


def run_scene(scene, name, *args):
    p, _, _ = swimtest.run(scene, name, *args)
    check(p.returncode == 0, "%s: swim run failed: %s" % (scene, p.stderr[-300:]))
    return os.path.join(swimtest.TMP, name)


def test_example1():
    d = run_scene("models/example1.toml", "e1")   # 30 time units (1 s): it travels far enough for path.png
    for name, fig in figures_of(d, ["trajectory", "energy", "impulse", "phase", "snapshots",
                                    "phase3d", "path"]):
        texts = check_figure("example1 " + name, fig)
        if name == "energy":
            legend = [t.get_text() for t, _, _ in texts if t.axes is None and "potential" in t.get_text()]
            check(all("not drawn" in s for s in legend),
                  "example1 energy.png lists a potential term: %s" % legend)
        if name == "path":
            # the outlines are coloured by time (plain lines, invisible to the mapped-artist check)
            labels = [ax._colorbar.ax.get_ylabel() for ax in colorbar_axes(fig)]
            check(any("time" in lab for lab in labels) and any("density" in lab for lab in labels),
                  "example1 path.png: colour bars %s, want time and density" % labels)
        if name == "phase":
            # 30 time units are several turns of the orbit: the passes are told apart
            bars = colorbar_axes(fig)
            check(bars and "pass" in bars[0]._colorbar.ax.get_ylabel(), "phase.png not coloured by pass")


def test_example3_events():
    d = run_scene("models/example3.toml", "e3", "--t-end", "3", "--event", "kinetic_rigid:max",
                  "--event", "impulse_body_y:zero")
    check(os.path.exists(os.path.join(d, "events.csv")), "example3: no events.csv")
    for name, fig in figures_of(d, ["trajectory", "energy", "impulse", "phase", "snapshots",
                                    "instants", "phase3d"]):
        texts = check_figure("example3 " + name, fig)
        if name in ("energy", "impulse"):
            marks = [t.get_text() for t, _, _ in texts if t.get_text().startswith("event: ")]
            check(any("kinetic_rigid max" in m for m in marks) and any("impulse_body_y zero" in m for m in marks),
                  "example3 %s.png: event marks not in the legend (%s)" % (name, marks))
        if name == "instants":
            titles = [ax.get_title() for ax in fig.axes if ax.get_visible()]
            check(sum("kinetic_rigid max" in s or "impulse_body_y zero" in s for s in titles) >= 2,
                  "example3 instants.png: panels do not name their events: %s" % titles[:4])


def test_example6_three_free_modes():
    """Three free complex modes: modes.png, and phase3d.png with three 3-d panels."""
    d = run_scene("models/example6.toml", "e6", "--t-end", "4")
    for name, fig in figures_of(d, ["trajectory", "energy", "impulse", "phase", "snapshots",
                                    "phase3d", "modes"]):
        check_figure("example6 " + name, fig)


def test_stroke():
    d = run_scene("models/stroke_loop.toml", "stroke")
    for name, fig in figures_of(d, ["trajectory", "energy", "impulse", "phase", "snapshots",
                                    "phase3d", "modes", "stroke"]):
        check_figure("stroke_loop " + name, fig)


def test_family():
    """The figures of a sweep (plot_family.py, what `swim plot SWEEPDIR` saves): family.png with
    kept trajectories (members on the reduction (4.17): the phase portrait too) and without."""
    import subprocess
    import plot_family
    for name, keep in (("fam", ["--keep", "trajectories"]), ("fam_summaries", [])):
        out = os.path.join(swimtest.TMP, name)
        p = subprocess.run([swimtest.SWIM, "sweep", "models/example1.toml", "--out", out, "--quiet",
                            "--jobs", "2", "--t-end", "8", "--vary", "shape.dc0.bm2=-0.7:0.7:4", *keep],
                           capture_output=True, text=True, cwd=swimtest.ROOT)
        check(p.returncode == 0, "swim sweep %s: %s" % (name, p.stderr[-300:]))
        sweep, members = plot_family.load_sweep(out)
        figs = []
        plot_family.plot_family(out, sweep, members, None, collect=figs)
        if keep:
            plot_family.plot_phase(out, sweep, members, swimtest.SWIM, None, collect=figs)
        got = sorted(n for n, _ in figs)
        check(got == (["family", "phase"] if keep else ["family"]), "%s: figures %s" % (name, got))
        for fname, fig in figs:
            check_figure("%s %s" % (name, fname), fig)
            plt.close(fig)


def test_branch():
    """The figures of a `swim continue` folder (plot_branch.py) on a branch like Example 1's: the
    displacement per period constant to round-off (0.5093094348 +- 1e-13), every point stable, no
    special point -- no offset axis, legend entries only for what is drawn, the same units."""
    import csv
    import json
    import plot_branch
    d = os.path.join(swimtest.TMP, "branch")
    os.makedirs(d, exist_ok=True)
    rng = np.random.default_rng(1)
    with open(os.path.join(d, "branch.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["shape.dc0.bm2", "period", "dx", "dy", "stable"])
        for i in range(12):
            w.writerow(["%.6f" % (0.1 + 0.05 * i), "%.12f" % (7.9 + 0.01 * i), "0",
                        repr(0.5093094348 + 1e-13 * rng.standard_normal()), "yes"])
    meta = {"parameter": "shape.dc0.bm2", "scene": "models/example1.toml", "special_points": [],
            "points": [{"parameter": 0.1 + 0.05 * i, "multipliers": [[0.9, 0.3], [0.9, -0.3]]}
                       for i in range(12)]}
    with open(os.path.join(d, "branch.json"), "w") as fh:
        json.dump(meta, fh)
    rows, meta = plot_branch.read(d)
    for name, build in (("bifurcation", plot_branch.build_bifurcation),
                        ("multipliers", plot_branch.build_multipliers)):
        fig = build(rows, meta)
        check_figure("branch " + name, fig)
        plt.close(fig)


def test_arrows_at_a_vertex():
    """Arrow feet bunched at a sharp vertex with speeds growing towards it (a star): after
    plot_run.tame_arrows no two drawn feet are closer than half the median foot spacing, none is
    drawn on the boundary, none is longer than the 98th percentile speed; far arrows stay."""
    ring = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    X = list(2.0 * np.cos(ring))
    Y = list(2.0 * np.sin(ring))
    for k in range(12):                       # the star: feet crowding to the vertex (1, 0)
        a = 2 * np.pi * k / 12
        X.append(1.0 + 0.02 * np.cos(a))
        Y.append(0.02 * np.sin(a))
    X, Y = np.array(X), np.array(Y)
    r = np.hypot(X - 1.0, Y)
    U, V = (X - 1.0) / r ** 2, Y / r ** 2    # speed ~ 1/r at the vertex
    th = np.linspace(0, 2 * np.pi, 400)
    snap = {"t": 0.0, "arrows": [X, Y, U, V], "boundary": (np.cos(th), 0.5 * np.sin(th))}
    speeds = np.hypot(U, V)
    vref = np.percentile(speeds, 98)
    plot_run.tame_arrows([snap])
    X2, Y2, U2, V2 = snap["arrows"]
    shown = np.isfinite(U2)
    P = np.column_stack([X2[shown], Y2[shown]])
    D = np.hypot(P[:, None, 0] - P[None, :, 0], P[:, None, 1] - P[None, :, 1])
    np.fill_diagonal(D, np.inf)
    check(X2.size == X.size, "the arrow count changed (the animation moves a fixed set)")
    check(shown[:24].all(), "arrows away from the body were dropped: %d of 24" % shown[:24].sum())
    check(shown[24:].sum() <= 1, "%d arrows of the star still drawn" % shown[24:].sum())
    check(np.nanmax(np.hypot(U2, V2)) <= vref * (1 + 1e-12), "an arrow longer than the key speed")


def test_cli_same_files():
    """`swim plot` still writes the figures under their names (the CLI uses build_figure)."""
    d = run_scene("models/example1.toml", "cli", "--t-end", "2")
    p = swimtest.swim("plot", d, "--only", "energy,phase")
    names = sorted(os.path.basename(x) for x in p.stdout.split())
    check(p.returncode == 0 and names == ["energy.png", "phase.png"], "swim plot: %s %s" % (names, p.stderr[-300:]))


record_legend_sources()

if __name__ == "__main__":
    sys.exit(swimtest.main(globals(), "test_figure_text"))
