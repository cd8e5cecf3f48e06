#!/usr/bin/env python3
"""Figures of one `swim run` output directory.

Usage: plot_run.py DIR [--only NAME ...] [--mark t1,t2,...] [--events all|COLUMN:KIND,...]

Reads DIR/trajectory.csv, DIR/summary.json, DIR/events.csv (if present) and
the body pictures: DIR/snapshots.json if present, otherwise computed by
`swim flow DIR` (from DIR/scene.toml and the trajectory; the binary is $SWIM_BIN
or bin/swim of this tree). Writes into DIR, printing each path written:

  trajectory.png  centre-of-mass path y vs x, and y(t)          (paper Figs 4.2, 4.9, 4.17)
  energy.png      energy distribution, absolute and in percent   (Figs 4.4, 4.11, 4.16, 4.20)
  impulse.png     linear impulses of body and fluid and their sum (Fig 4.12)
  phase.png       phase portraits of the most active free coordinates, coloured by the pass
                  around the orbit (first pass widest, so a retraced orbit shows every pass)
  snapshots.png   body density, outline, path and fluid velocity  (Figs 4.3, 4.15, 4.18, 4.22)
  instants.png    the body at the marked instants                  (Fig 4.8)
  phase3d.png     (coordinate, velocity, t) curves                 (Figs 4.10, 4.14, 4.19)
  modes.png       mode amplitudes (k+1)^2 |c_-k|^2 over time        (Figs 4.24, 4.25)
  path.png        the path of the centre of mass with the body along it (Figs 4.13, 5.1)
  stroke.png      a prescribed stroke ([stroke] scenes): the power the body spends and, per
                  stroke, its displacement and positive work

Only the figures that say something about the run are drawn: instants.png when
there are marks, phase3d.png for scenes with at most 8 free coordinates,
modes.png for scenes with at least 3 free complex modes, path.png when the
centre of mass travels at least 0.6 body diameters, stroke.png for prescribed strokes.

Marks (dashed lines on energy.png and impulse.png, the panels of instants.png)
are the times given with --mark and the events of DIR/events.csv (columns
t,column,kind,value) that --events selects: `all`, or COLUMN:KIND pairs such as
kinetic_rigid:max (KIND as events.csv has it; `COLUMN:*` for every kind).
With neither option the first 12 distinct event times are marked, and stderr
says how many were left out. instants.png shows at most 16 instants (the first
ones; stderr says when it leaves some out).

Every axis gives its unit: the paper's scaling is dimensionless, lengths in radii of the
reference disc (models/README.md). Colour scales have colour bars; energy.png draws only the
terms the scene has (and says which it leaves out); marks are told apart by line style and named
in the legend (COLUMN KIND of the event, and the first times).

From Python: build_figure(DIR or open_run(DIR, marks, events), NAME) returns figure NAME as a
matplotlib Figure without saving it (what `swim plot` saves; tests/test_figure_text.py checks its
text); it raises Skip when the figure says nothing about the run.

NAME is one of the figure names above (with or without ".png"). A figure whose
input is missing or unusable is skipped with a message on stderr. The CSV may
be truncated (failed run) and may contain "nan". Exit status 0 if at least one
figure was written, 1 otherwise.
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402

FIGURES = ("trajectory", "energy", "impulse", "phase", "snapshots", "instants", "phase3d",
           "modes", "path", "stroke")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MAX_MARKS = 12
MAX_INSTANTS = 16
FIGSIZE = (12.0, 5.0)
DPI = 110

plt.rcParams.update({
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.labelsize": 10,
    "legend.fontsize": 9,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "figure.titlesize": 12,
})


class Skip(Exception):
    """The figure cannot be drawn from the data at hand (message says why)."""


def warn(msg):
    print("plot_run: " + msg, file=sys.stderr)


# ---------------------------------------------------------------- input

def read_trajectory(path):
    """Columns of the CSV as a dict name -> float array, in header order.

    Rows whose field count differs from the header (a truncated last line) are
    dropped; fields that do not parse become NaN."""
    with open(path, "r", errors="replace") as fh:
        lines = fh.read().splitlines()
    if not lines:
        raise Skip("%s is empty" % path)
    names = [h.strip() for h in lines[0].split(",")]
    rows = []
    dropped = 0
    for line in lines[1:]:
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != len(names):
            dropped += 1
            continue
        row = []
        for f in fields:
            try:
                row.append(float(f))
            except ValueError:
                row.append(math.nan)
        rows.append(row)
    if dropped:
        warn("%s: dropped %d incomplete row(s)" % (path, dropped))
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    cols = {}
    for i, name in enumerate(names):
        if name and name not in cols:
            cols[name] = data[:, i]
    return cols


def read_json(path):
    with open(path, "r", errors="replace") as fh:
        return json.load(fh)


def need(cols, *names):
    """The named columns, or Skip naming the missing ones."""
    if cols is None:
        raise Skip("no trajectory.csv data")
    missing = [n for n in names if n not in cols]
    if missing:
        raise Skip("missing column(s) " + ", ".join(missing))
    if len(cols[names[0]]) == 0:
        raise Skip("trajectory.csv has no data rows")
    return [cols[n] for n in names]


def finite_any(a):
    return a is not None and np.isfinite(a).any()


def density_values(snaps):
    """The finite densities rho0/J of all pictures, one array."""
    rhos = np.concatenate([s["density"][2].ravel() for s in snaps if s["density"] is not None]
                          or [np.zeros(0)])
    return rhos[np.isfinite(rhos)]


def density_norm(snaps):
    """One colour scale for the density rho0/J over several pictures, robust against the few huge
    values near J -> 0 (0.5 and 99.5 percentiles)."""
    rhos = density_values(snaps)
    if not rhos.size:
        return Normalize(0.0, 1.0)
    vmin, vmax = np.percentile(rhos, [0.5, 99.5])
    if vmax <= vmin:
        vmin, vmax = vmin - 0.5 * abs(vmin or 1), vmax + 0.5 * abs(vmax or 1)
    return Normalize(vmin, vmax)


def span(a):
    a = np.asarray(a, dtype=float)
    a = a[np.isfinite(a)]
    return float(a.max() - a.min()) if a.size else 0.0


def absmax(*arrays):
    m = 0.0
    for a in arrays:
        a = np.asarray(a, dtype=float)
        a = a[np.isfinite(a)]
        if a.size:
            m = max(m, float(np.abs(a).max()))
    return m


def coord_label(name, dot=False):
    """'am2' -> $a_{-2}$, 'db1' -> $\\dot b_{1}$ (mathtext)."""
    if name.startswith("d") and len(name) > 1 and name[1] in "ab":
        name, dot = name[1:], True
    letter, idx = name[0], name[1:]
    if idx.startswith("m"):
        idx = "-" + idx[1:]
    sym = r"\dot %s" % letter if dot else letter
    return r"$%s_{%s}$" % (sym, idx)


# Every axis says its unit. The paper's quantities are dimensionless (the reference body is the unit
# disc, rho0 and rho_f set the density scale: models/README.md, "Conventions").
DIMLESS = "dimensionless, paper's scaling"
LENGTH = "reference-disc radii"
T_LABEL = "time $t$ (%s)" % DIMLESS


def with_unit(text, unit=DIMLESS, newline=False):
    """'energy' -> "energy (dimensionless, paper's scaling)"; newline puts the unit on a line of its own."""
    return "%s%s(%s)" % (text, "\n" if newline else " ", unit)


# An axis whose values vary by less than this fraction of their size would show round-off as
# structure (on an offset axis such as "1e-13 + 5.093e-1").
STEADY_REL = 1e-6


def steady_axis(ax, values, axis="y"):
    """When VALUES vary by less than STEADY_REL of their size, the axis is centred on them with a
    span of 1e-3 of their size and no offset, and says the constant and its spread; True then."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if not v.size:
        return False
    mag, spread = float(np.max(np.abs(v))), float(np.ptp(v))
    if mag == 0 or spread >= STEADY_REL * mag:
        return False
    mid, half = float(np.mean(v)), 1e-3 * mag
    (ax.set_ylim if axis == "y" else ax.set_xlim)(mid - half, mid + half)
    ax.ticklabel_format(axis=axis, useOffset=False)
    ax.text(0.02, 0.04, "constant %.10g (spread %.1g: round-off)" % (mid, spread),
            transform=ax.transAxes, fontsize=8, color="0.3")
    return True


def coord_axis(name, dot=False, newline=False):
    """Axis label of a shape coordinate or its velocity, with its unit."""
    return with_unit(coord_label(name, dot), newline=newline)


def pretty_column(name):
    """A trajectory column for a label: the shape coordinates and their velocities in math text
    ('am3' -> $a_{-3}$, 'dbm2' -> $\\dot b_{-2}$), x, y, theta likewise; any other column as it is
    (the names of --events and events.csv)."""
    if re.fullmatch(r"d?[ab](1|m[0-9]+)", name):
        return coord_label(name)
    return {"x": "$x$", "y": "$y$", "theta": r"$\theta$"}.get(name, name)


def pretty_text(text):
    """Raw coordinate names of a scene's title in math text: 'c_-3' -> $c_{-3}$, 'c1' -> $c_1$
    (titles that already use math text, or contain a literal dollar, are left alone)."""
    if "$" in text:
        return text
    text = re.sub(r"(?<![A-Za-z0-9_])c_?(-?[0-9]+)(?![A-Za-z0-9_])", r"$c_{\1}$", text)
    return re.sub(r"(?<![A-Za-z0-9_])(d?[ab](?:1|m[0-9]+))(?![A-Za-z0-9_])",
                  lambda m: coord_label(m.group(1)), text)


def swim_binary():
    return os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")


def read_events(path):
    """Rows (t, column, kind, value) of an events.csv, sorted by time; [] when absent."""
    if not os.path.exists(path):
        return []
    events = []
    try:
        with open(path, "r", errors="replace") as fh:
            lines = fh.read().splitlines()
        head = [h.strip() for h in lines[0].split(",")] if lines else []
        if not all(k in head for k in ("t", "column", "kind")):
            warn("%s: header %s lacks t,column,kind; ignored" % (path, ",".join(head)))
            return []
        it, ic, ik = head.index("t"), head.index("column"), head.index("kind")
        iv = head.index("value") if "value" in head else None
        for line in lines[1:]:
            f = line.split(",")
            if len(f) != len(head):
                continue
            try:
                t = float(f[it])
                v = float(f[iv]) if iv is not None else math.nan
            except ValueError:
                continue
            if math.isfinite(t):
                events.append((t, f[ic].strip(), f[ik].strip(), v))
    except OSError as e:
        warn("%s: unreadable (%s)" % (path, e))
    events.sort(key=lambda e: e[0])
    return events


def event_label(col, kind):
    """'kinetic_rigid', 'max' -> 'kinetic_rigid max'; a coordinate column in math text
    ('am1', 'zero' -> '$a_{-1}$ zero')."""
    return "%s %s" % (pretty_column(col), kind)


def marks_from_events(events, limit=MAX_MARKS):
    """The distinct times of events (events closer than 1e-6 share a mark), the first `limit`
    of them (None: all), as (t, label); and how many distinct times were left out."""
    marks = []
    for t, col, kind, _ in events:
        label = event_label(col, kind)
        if marks and abs(marks[-1][0] - t) < 1e-6:
            marks[-1] = (marks[-1][0], marks[-1][1] + ", " + label)
        else:
            marks.append((t, label))
    if limit is None or len(marks) <= limit:
        return marks, 0
    return marks[:limit], len(marks) - limit


def select_events(events, spec):
    """The events that --events SPEC names: "all", or COLUMN:KIND pairs (KIND may be *)."""
    if spec == "all":
        return list(events)
    pairs = [tuple(p.split(":", 1)) for p in spec.split(",")]
    return [e for e in events if any(e[1] == c and (k == "*" or e[2] == k) for c, k in pairs)]


# the energy terms, impulses and phase curves use the tab: colours; the marks keep out of their way
MARK_STYLES = (("crimson", "-."), ("navy", "--"), ("darkgoldenrod", ":"), ("teal", "-."),
               ("magenta", "--"), ("0.45", ":"), ("saddlebrown", "-."), ("k", ":"))


def mark_groups(run):
    """The marks grouped by what they mark: [(label, colour, linestyle, times)], in the order of
    their first time. A label names the event (COLUMN KIND as events.csv has it) or says the
    time came from --mark, and lists the first times."""
    groups = {}
    for tm, lab in run.marks or []:
        groups.setdefault(lab or "", []).append(tm)
    out = []
    for i, (lab, times) in enumerate(groups.items()):
        colour, ls = MARK_STYLES[i % len(MARK_STYLES)]
        shown = ", ".join("%.3g" % tm for tm in times[:3]) + (", …" if len(times) > 3 else "")
        what = ("event: " + lab) if lab else "marked (--mark)"
        out.append(("%s ($t$ = %s)" % (what, shown), colour, ls, times))
    return out


def draw_marks(ax, run, t=None, legend=True):
    """Vertical lines at the marked times, one style per kind of mark; with legend, the first line
    of each kind carries its label (event name and times) for the legend."""
    for label, colour, ls, times in mark_groups(run):
        for i, tm in enumerate(times):
            ax.axvline(tm, color=colour, ls=ls, lw=0.9, alpha=0.85,
                       label=label if (legend and i == 0) else None)


# ---------------------------------------------------------------- context

class Run:
    def __init__(self, outdir):
        self.dir = outdir
        self.cols = None
        self.summary = {}
        self.snapshots = None
        self.csv_error = None
        self.snap_error = None

        sp = os.path.join(outdir, "summary.json")
        if os.path.exists(sp):
            try:
                s = read_json(sp)
                if isinstance(s, dict):
                    self.summary = s
                else:
                    warn("%s: not a JSON object, ignored" % sp)
            except Exception as e:  # noqa: BLE001 - any bad file is only a warning
                warn("%s: unreadable (%s), ignored" % (sp, e))
        else:
            warn("%s missing; titles use the directory name" % sp)

        tp = os.path.join(outdir, "trajectory.csv")
        try:
            self.cols = read_trajectory(tp)
        except Skip as e:
            self.csv_error = str(e)
        except Exception as e:  # noqa: BLE001
            self.csv_error = "%s: %s" % (tp, e)

        self.events = read_events(os.path.join(outdir, "events.csv"))
        self.marks = None   # list of (t, label); set by main()
        self._snapshots_loaded = False

    def load_snapshots(self):
        """DIR/snapshots.json, computed by `swim flow DIR` (and kept) when missing."""
        if self._snapshots_loaded:
            return
        self._snapshots_loaded = True
        np_ = os.path.join(self.dir, "snapshots.json")
        if not os.path.exists(np_):
            try:
                self.snapshots = self.flow(frames=10, out=np_)
            except Skip as e:
                self.snap_error = str(e)
            return
        try:
            s = read_json(np_)
            self.snapshots = s if isinstance(s, list) else None
            if self.snapshots is None:
                self.snap_error = "%s: not a JSON list" % np_
        except Exception as e:  # noqa: BLE001
            self.snap_error = "%s: unreadable (%s)" % (np_, e)

    def flow(self, times=None, frames=None, out=None):
        """Body pictures at the given times (or K evenly spaced frames) from `swim flow`."""
        swim = swim_binary()
        if not os.path.exists(os.path.join(self.dir, "scene.toml")):
            raise Skip("%s/scene.toml missing (run directory from an older swim run?)" % self.dir)
        tmp = None
        if out is None:
            fd, tmp = tempfile.mkstemp(suffix=".json", prefix="flow-", dir=self.dir)
            os.close(fd)
        cmd = [swim, "flow", self.dir, "--out", out or tmp]
        if times is not None:
            cmd += ["--times", ",".join("%.17g" % t for t in times)]
        elif frames is not None:
            cmd += ["--frames", str(int(frames))]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                raise Skip("swim flow failed: %s" % p.stderr.strip()[:300])
            s = read_json(out or tmp)
            if not isinstance(s, list):
                raise Skip("swim flow wrote no list")
            return s
        except OSError as e:
            raise Skip("cannot run %s: %s" % (swim, e))
        finally:
            if tmp and os.path.exists(tmp):
                os.remove(tmp)

    def name(self):
        title = self.summary.get("title")
        if isinstance(title, str) and title.strip():
            return title.strip()
        scene = self.summary.get("scene")
        if isinstance(scene, str) and scene.strip():
            return os.path.basename(scene.strip())
        return os.path.basename(os.path.normpath(self.dir))

    def suptitle(self, fig, what):
        name = pretty_text(self.name())
        # one line when it fits the figure's width (about 9 characters per inch at 12 pt)
        width = fig.get_size_inches()[0]
        sep = " — " if len(name) + len(what) + 3 <= 8.5 * width else "\n"
        text = "%s%s%s" % (name, sep, what)
        if self.summary.get("status") == "failed":
            reason = str(self.summary.get("reason", "")).strip()
            if len(reason) > 70:
                reason = reason[:67] + "..."
            tr = self.summary.get("t_reached")
            at = (" at t = %.4g" % tr) if isinstance(tr, (int, float)) else ""
            text += "\n[run failed%s%s]" % (at, (": " + reason) if reason else "")
        fig.suptitle(text)

    def free_coords(self):
        free = self.summary.get("free")
        if isinstance(free, list) and free:
            return [str(f) for f in free]
        # fall back to every shape coordinate that has a velocity column
        cols = self.cols or {}
        return [n for n in cols if n[:1] in "ab" and n[1:2] in "1m" and ("d" + n) in cols]


def save(fig, run, name):
    path = os.path.join(run.dir, name + ".png")
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def mark_failure(ax, run, t):
    """Red dotted line at the last computed time of a failed run."""
    if run.summary.get("status") == "failed" and finite_any(t):
        ax.axvline(np.nanmax(t), color="tab:red", ls=":", lw=1.2)


# ---------------------------------------------------------------- figures

def legend_below(fig, handles, labels, title=None, ncol_max=4):
    """One legend for the figure, centred under the panels, and the layout that leaves it room
    (measured, so long labels or several rows never run into the x-axis labels)."""
    ncol = min(len(labels), ncol_max) if labels else 1
    leg = fig.legend(handles, labels, loc="lower center", ncol=ncol, frameon=False,
                     bbox_to_anchor=(0.5, 0.0), title=title, title_fontsize=8.5)
    fig.canvas.draw()
    h = leg.get_window_extent(fig.canvas.get_renderer()).height / fig.bbox.height
    fig.tight_layout(rect=(0, min(h + 0.01, 0.5), 1, 1))
    return leg


def fig_trajectory(run):
    t, x, y = need(run.cols, "t", "x", "y")
    ok = np.isfinite(x) & np.isfinite(y)
    if not ok.any():
        raise Skip("x, y are all NaN")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=FIGSIZE,
                                   gridspec_kw={"width_ratios": [1, 1.4]})
    ax1.plot(x, y, color="k", lw=1.4, label="centre of mass")
    i0 = np.flatnonzero(ok)[0]
    i1 = np.flatnonzero(ok)[-1]
    ax1.plot(x[i0], y[i0], "o", color="tab:green", ms=8,
             label="start ($t$ = %.3g)" % t[i0])
    ax1.plot(x[i1], y[i1], "s", color="tab:red", ms=8,
             label="end ($t$ = %.3g)" % t[i1])
    ax1.set_aspect("equal", adjustable="datalim")
    # keep a sensible window when the path is (almost) a straight line or a point
    sx, sy = span(x), span(y)
    half = 0.5 * max(sx, sy, 1e-9) * 1.1
    ax1.set_xlim(np.nanmean([np.nanmin(x), np.nanmax(x)]) - half,
                 np.nanmean([np.nanmin(x), np.nanmax(x)]) + half)
    ax1.set_ylim(np.nanmean([np.nanmin(y), np.nanmax(y)]) - half,
                 np.nanmean([np.nanmin(y), np.nanmax(y)]) + half)
    ax1.set_xlabel(with_unit("$x$ of the centre of mass", LENGTH))
    ax1.set_ylabel(with_unit("$y$ of the centre of mass", LENGTH))
    ax1.set_title("Path of the centre of mass")
    ax1.grid(alpha=0.3)
    ax1.legend(loc="best")

    ax2.plot(t, y, color="tab:blue", lw=1.5, label="$y(t)$")
    if span(x) > 1e-3 * max(span(y), 1e-300) and span(x) > 1e-12:
        ax2.plot(t, x, color="tab:orange", lw=1.2, ls="--", label="$x(t)$")
        ax2.legend(loc="best")
        ax2.set_ylabel(with_unit("$y$, $x$ of the centre of mass", LENGTH))
        ax2.set_title("Centre of mass against time")
    else:
        ax2.set_ylabel(with_unit("$y$ of the centre of mass", LENGTH))
        ax2.set_title("$y$-coordinate of the centre of mass against time")
    mark_failure(ax2, run, t)
    ax2.set_xlabel(T_LABEL)
    ax2.grid(alpha=0.3)
    run.suptitle(fig, "trajectory")
    fig.tight_layout()
    return fig


def energy_parts(run):
    """The energy terms of the scene, [(label, values, colour)], and the labels of those left out
    because the scene has not that effect (summary.json "effects") or the term is zero throughout.
    Raises Skip when there is none."""
    cols = run.cols
    effects = run.summary.get("effects") if isinstance(run.summary.get("effects"), dict) else {}
    cand = [("kinetic_fluid", "kinetic, fluid", "tab:blue", True),
            ("kinetic_shape", "kinetic, body deformations", "tab:orange", True),
            ("kinetic_rigid", "kinetic, body rigid motion", "tab:green", True)]
    if "w1" in cols or "w2" in cols:
        cand += [("w1", "potential, elastic $W_1$", "tab:purple", effects.get("elastic", True)),
                 ("w2", "potential, barrier $W_2$", "tab:brown", effects.get("barrier", True))]
        if "W_law" in cols:   # [elastic] energy: the law's W = int_D U dz (docs/materials.md)
            cand.append(("W_law", "potential, law $W_{law}$", "tab:pink", True))
    else:
        cand += [("potential", "potential", "tab:purple",
                  effects.get("elastic", True) or effects.get("barrier", True))]
    present = []
    for name, label, colour, effect in cand:
        if name in cols:
            present.append((label, cols[name], colour, effect))
        elif name.startswith("kinetic") or name == "potential":
            warn("energy: column %s missing, left out" % name)
    if not present:
        raise Skip("no energy columns")
    scale = absmax(*[v for _, v, _, _ in present])
    parts, absent = [], []
    for label, v, colour, effect in present:
        # a term of an effect the scene lacks, or one that is zero throughout, is not drawn
        if effect and absmax(v) > 1e-12 * max(scale, 1e-300):
            parts.append((label, v, colour))
        else:
            absent.append(label)
    if not parts:   # at rest: draw the kinetic terms (zero) rather than nothing
        parts = [(label, v, colour) for label, v, colour, _ in present if label.startswith("kinetic")]
        absent = [a for a in absent if not a.startswith("kinetic")]
    return parts, absent


def fig_energy(run):
    cols = run.cols
    (t,) = need(cols, "t")
    parts, absent = energy_parts(run)
    stack = np.vstack([p[1] for p in parts])
    if not np.isfinite(stack).any():
        raise Skip("energy columns are all NaN")
    total = cols.get("energy")
    total_label = "total energy"
    if total is None or not finite_any(total):
        total = np.sum(stack, axis=0)
        total_label = "total (sum of parts)"

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=FIGSIZE)
    # absolute values, stacked
    lower = np.zeros_like(t)
    for label, v, colour in parts:
        upper = lower + v
        ax1.fill_between(t, lower, upper, color=colour, alpha=0.75, lw=0, label=label)
        lower = upper
    ax1.plot(t, total, color="k", lw=1.6, label=total_label)
    work = cols.get("work")
    if work is not None and absmax(work) > 1e-12 * max(absmax(total), 1e-300):
        ax1.plot(t, work, color="k", lw=1.0, ls=":",
                 label="work of the stroke" if "stroke" in run.summary else "work of forcing + damping")
    mark_failure(ax1, run, t)
    draw_marks(ax1, run)
    ax1.set_xlabel(T_LABEL)
    ax1.set_ylabel(with_unit("energy"))
    ax1.set_title("Distribution of energy (stacked)")
    ax1.grid(alpha=0.3)
    ax1.set_xlim(np.nanmin(t), np.nanmax(t)) if np.nanmax(t) > np.nanmin(t) else None

    # in percent of the total; rows with (near) zero total are left blank
    scale = absmax(total)
    good = np.isfinite(total) & (np.abs(total) > 1e-9 * max(scale, 1e-300)) & (scale > 0)
    if good.any():
        lower = np.zeros_like(t)
        for label, v, colour in parts:
            pct = np.where(good, 100.0 * v / np.where(good, total, 1.0), np.nan)
            upper = lower + pct
            ax2.fill_between(t, lower, upper, where=good, color=colour, alpha=0.75, lw=0,
                             interpolate=False)
            lower = upper
        ax2.set_ylim(0, max(100.0, np.nanmax(lower[good]) if np.isfinite(lower[good]).any()
                            else 100.0))
        if (np.isfinite(total) & ~good).any():
            ax2.text(0.01, 0.01, "blank: total energy ~ 0", transform=ax2.transAxes,
                     fontsize=9, va="bottom")
    else:
        ax2.text(0.5, 0.5, "total energy is ~0 at all times", ha="center",
                 transform=ax2.transAxes)
    mark_failure(ax2, run, t)
    draw_marks(ax2, run, legend=False)
    ax2.set_xlabel(T_LABEL)
    ax2.set_ylabel("share of total energy (%)")
    ax2.set_title("Distribution of energy (percent)")
    ax2.grid(alpha=0.3)
    if np.nanmax(t) > np.nanmin(t):
        ax2.set_xlim(np.nanmin(t), np.nanmax(t))
    h, lab = ax1.get_legend_handles_labels()
    run.suptitle(fig, "energy")
    legend_below(fig, h, lab, title=("not drawn (absent from the scene or zero throughout): "
                                     + "; ".join(absent)) if absent else None, ncol_max=3)
    return fig


def fig_impulse(run):
    cols = run.cols
    (t,) = need(cols, "t")
    kinds = (("impulse_body", "body", "tab:green"),
             ("impulse_fluid_rigid", "fluid (rigid motion)", "tab:blue"),
             ("impulse_fluid_shape", "fluid (shape changes)", "tab:orange"))
    comps = []
    for c in ("y", "x"):
        present = [(k, lab, col) for k, lab, col in kinds if "%s_%s" % (k, c) in cols]
        if present:
            comps.append((c, present))
    if not comps:
        raise Skip("missing impulse columns (impulse_body_y, ...)")
    ymax = absmax(*[cols["%s_y" % k] for k, _, _ in kinds if "%s_y" % k in cols])
    shown = []
    for c, present in comps:
        m = absmax(*[cols["%s_%s" % (k, c)] for k, _, _ in present])
        if c == "y" or (m > 1e-12 and m > 1e-3 * ymax):
            shown.append((c, present))
    shown = [(c, present) for c, present in shown
             if any(finite_any(cols["%s_%s" % (k, c)]) for k, _, _ in present)]
    if not shown:
        raise Skip("impulse columns are all NaN")
    fig, axes = plt.subplots(1, len(shown), figsize=FIGSIZE, squeeze=False)
    for j, (ax, (c, present)) in enumerate(zip(axes[0], shown)):
        total = np.zeros_like(t)
        for k, lab, col in present:
            v = cols["%s_%s" % (k, c)]
            ax.plot(t, v, color=col, lw=1.5, label=lab)
            total = total + v
        ax.plot(t, total, color="k", lw=1.2, ls=(0, (6, 3)), label="sum (should be 0)")
        ax.axhline(0, color="0.5", lw=0.6)
        mark_failure(ax, run, t)
        draw_marks(ax, run, legend=j == 0)
        ax.set_xlabel(T_LABEL)
        ax.set_ylabel(with_unit("$%s$-component of linear impulse" % c, newline=True))
        ax.set_title("Linear impulse, $%s$-component" % c)
        ax.grid(alpha=0.3)
    h, lab = axes[0][0].get_legend_handles_labels()
    run.suptitle(fig, "linear impulse")
    # a note, not an entry: a legend entry stands for something drawn
    legend_below(fig, h, lab, ncol_max=3,
                 title="$x$-components negligible, not shown" if len(shown) == 1 else None)
    return fig


def orbit_passes(q, dq):
    """Pass number (0, 1, ...) of every sample of a phase curve: how many whole turns the curve has
    made around the centre of its bounding box (in coordinates scaled to that box) since the start.
    A curve that does not turn stays at pass 0."""
    ok = np.isfinite(q) & np.isfinite(dq)
    passes = np.zeros(len(q), dtype=int)
    if ok.sum() < 2:
        return passes
    qc = 0.5 * (np.nanmin(q[ok]) + np.nanmax(q[ok]))
    dc = 0.5 * (np.nanmin(dq[ok]) + np.nanmax(dq[ok]))
    ang = np.arctan2((dq[ok] - dc) / max(span(dq), 1e-300), (q[ok] - qc) / max(span(q), 1e-300))
    turned = np.abs(np.unwrap(ang) - np.unwrap(ang)[0])
    passes[ok] = np.floor(turned / (2 * math.pi) + 1e-9).astype(int)
    # NaN rows take the pass of the row before
    idx = np.maximum.accumulate(np.where(ok, np.arange(len(q)), 0))
    return passes[idx]


def retraces(q, dq, passes):
    """Whether the later passes of a phase curve run (nearly) on top of the first: the median
    distance of their points to the first pass is below 2% of the curve's extent."""
    ok = np.isfinite(q) & np.isfinite(dq)
    sq, sd = max(span(q), 1e-300), max(span(dq), 1e-300)
    first = ok & (passes == 0)
    later = ok & (passes > 0)
    if first.sum() < 3 or not later.any():
        return False
    a = np.column_stack([q[first] / sq, dq[first] / sd])
    b = np.column_stack([q[later] / sq, dq[later] / sd])
    a = a[:: max(1, len(a) // 2000)]   # at most 2000 x 400 distances, for runs of any length
    b = b[:: max(1, len(b) // 400)]
    d = np.sqrt(((b[:, None, :] - a[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
    return float(np.median(d)) < 0.02


def fig_phase(run):
    """Phase portraits (q, q') of the most active free coordinates. A periodic orbit is traversed
    again and again: the curve is coloured by its pass (turn around the orbit), the first pass
    widest and underneath, so every pass shows where it departs from the others."""
    cols = run.cols
    (t,) = need(cols, "t")
    cand = []
    for name in run.free_coords():
        if name in cols and ("d" + name) in cols:
            s = span(cols[name])
            if s > 0 and finite_any(cols["d" + name]):
                cand.append((s, name))
        else:
            warn("phase: no columns for free coordinate %s" % name)
    if not cand:
        raise Skip("no free coordinate with a velocity column varies")
    cand.sort(key=lambda p: -p[0])
    names = [n for _, n in cand[:4]]
    # keep the order of the CSV so panels read a1, b1, am1, ... left to right
    order = list(cols.keys())
    names.sort(key=order.index)
    passes = {name: orbit_passes(cols[name], cols["d" + name]) for name in names}
    npass = max(int(p.max()) + 1 for p in passes.values())
    cmap = plt.get_cmap("viridis", max(npass, 2)) if npass <= 12 else plt.get_cmap("viridis")
    bounds = np.arange(-0.5, npass + 0.5, 1.0)
    from matplotlib.colors import BoundaryNorm
    # discrete colours for up to 12 passes; beyond, a continuous scale of the pass number
    norm = BoundaryNorm(bounds, cmap.N) if 1 < npass <= 12 else Normalize(-0.5, npass - 0.5)
    fig, axes = plt.subplots(1, len(names), figsize=FIGSIZE, squeeze=False)
    lc = None
    for ax, name in zip(axes[0], names):
        q, dq = cols[name], cols["d" + name]
        pas = passes[name]
        pts = np.column_stack([q, dq])
        segs = np.stack([pts[:-1], pts[1:]], axis=1) if len(pts) > 1 else np.zeros((0, 2, 2))
        keep = np.isfinite(segs).all(axis=(1, 2))
        seg_pass = pas[:-1] if len(pas) > 1 else np.zeros(0, dtype=int)
        # widths from the first pass of this panel down to its last: a pass that retraces the
        # ones before shows as a narrower band inside them
        n_here = int(pas.max()) + 1 if len(pas) else 1
        if n_here <= 1:
            lw_first, lw_last = 1.4, 1.4
        elif retraces(q, dq, pas):   # a periodic orbit: wide bands, or only the last pass shows
            lw_first, lw_last = min(1.0 + 1.6 * (n_here - 1), 8.0), 1.0
        else:                        # the passes differ anyway: colour tells them apart
            lw_first, lw_last = min(1.0 + 0.4 * (n_here - 1), 3.0), 1.0
        for k in range(n_here):
            sel = keep & (seg_pass == k)
            if not sel.any():
                continue
            lw = lw_first + (lw_last - lw_first) * (k / max(n_here - 1, 1))
            lc = LineCollection(segs[sel], cmap=cmap, norm=norm, lw=lw, zorder=2 + k,
                                capstyle="round", joinstyle="round")
            lc.set_array(np.full(int(sel.sum()), float(k)))
            ax.add_collection(lc)
        ok = np.isfinite(q) & np.isfinite(dq)
        if ok.any():
            i0 = np.flatnonzero(ok)[0]
            ax.plot(q[i0], dq[i0], "o", color="tab:red", ms=6, zorder=npass + 5,
                    label="start, $t$ = %.3g" % t[i0])
            ax.legend(loc="upper right", fontsize=8)
            pad_q = 0.06 * max(span(q), 1e-9)
            pad_d = 0.06 * max(span(dq), 1e-9)
            ax.set_xlim(np.nanmin(q[ok]) - pad_q, np.nanmax(q[ok]) + pad_q)
            ax.set_ylim(np.nanmin(dq[ok]) - pad_d, np.nanmax(dq[ok]) + pad_d)
        ax.set_xlabel(coord_axis(name))
        ax.set_ylabel(coord_axis(name, dot=True))
        ax.set_title("%s against %s" % (coord_label(name, dot=True), coord_label(name)))
        ax.grid(alpha=0.3)
    run.suptitle(fig, "phase portraits of the free shape coordinates")
    fig.tight_layout(rect=(0, 0, 0.9, 1))
    cax = fig.add_axes((0.915, 0.15, 0.015, 0.7))
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=norm)
    cb = fig.colorbar(sm, cax=cax)
    if npass <= 12:
        cb.set_ticks(np.arange(npass))
        cb.set_ticklabels([str(k + 1) for k in range(npass)])
    else:
        from matplotlib.ticker import FuncFormatter, MaxNLocator
        cb.locator = MaxNLocator(integer=True)
        cb.formatter = FuncFormatter(lambda v, _: "%d" % (v + 1))
        cb.update_ticks()
    cb.set_label("pass around the orbit (count; first pass widest)")
    return fig


def _arr2(v):
    a = np.asarray(v, dtype=float)
    if a.ndim != 2 or a.size == 0:
        raise ValueError("not a 2-D array")
    return a


def _close_polar(X, Y, R):
    """Append the first angle column when the grid does not already wrap around,
    so the filled body has no missing wedge."""
    gap = np.hypot(X[:, 0] - X[:, -1], Y[:, 0] - Y[:, -1])
    if X.shape[1] > 2:
        step = np.hypot(np.diff(X, axis=1), np.diff(Y, axis=1))
        if np.nanmax(gap) > 1e-9 * max(np.nanmax(step), 1e-300):
            X = np.hstack([X, X[:, :1]])
            Y = np.hstack([Y, Y[:, :1]])
            R = np.hstack([R, R[:, :1]])
    return X, Y, R


def parse_snapshots(raw):
    snaps = []
    for i, s in enumerate(raw):
        try:
            snap = {"t": float(s["t"])}
            b = s.get("boundary") or {}
            bx = np.asarray(b.get("X", []), dtype=float)
            by = np.asarray(b.get("Y", []), dtype=float)
            snap["boundary"] = (bx, by) if bx.size and bx.shape == by.shape else None
            d = s.get("density") or {}
            try:
                X, Y, R = _arr2(d["X"]), _arr2(d["Y"]), _arr2(d["rho"])
                if not (X.shape == Y.shape == R.shape):
                    raise ValueError("shape mismatch")
                snap["density"] = _close_polar(X, Y, R)
            except (KeyError, ValueError, TypeError):
                snap["density"] = None
            a = s.get("arrows") or {}
            try:
                arr = [np.asarray(a[k], dtype=float).ravel() for k in ("X", "Y", "U", "V")]
                if len({v.size for v in arr}) != 1 or arr[0].size == 0:
                    raise ValueError
                snap["arrows"] = arr
            except (KeyError, ValueError, TypeError):
                snap["arrows"] = None
            snap["pos"] = (float(s.get("x", math.nan)), float(s.get("y", math.nan)))
            snaps.append(snap)
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            warn("snapshots: entry %d unusable (%s), skipped" % (i, e))
    snaps = [s for s in snaps if s["boundary"] is not None or s["density"] is not None]
    if not snaps:
        raise Skip("no usable snapshot (no boundary nor density)")
    snaps.sort(key=lambda s: s["t"])
    tame_arrows(snaps)
    return snaps


def tame_arrows(snaps):
    """The fluid velocity grows without bound towards a sharp vertex of the body, and the arrow
    feet (on curves around the body) bunch up there: the arrows would crowd into a star hiding
    the body. So an arrow is not drawn (NaN; the count stays, as the animation moves a fixed set
    of arrows) when its foot is closer than half the typical foot spacing (the median distance
    to the nearest other foot) to an arrow kept before it, or than a quarter of it to the
    boundary, and none is drawn
    longer than the run's 98th percentile speed (the arrow key's speed)."""
    speeds = np.concatenate([np.hypot(s["arrows"][2], s["arrows"][3])
                             for s in snaps if s["arrows"] is not None] or [np.zeros(0)])
    speeds = speeds[np.isfinite(speeds)]
    vref = float(np.percentile(speeds, 98)) if speeds.size else 0.0
    for s in snaps:
        if s["arrows"] is None:
            continue
        X, Y, U, V = [a.copy() for a in s["arrows"]]
        foot = np.isfinite(X) & np.isfinite(Y)
        if foot.sum() > 2:
            P = np.column_stack([X, Y])
            D = np.hypot(P[:, None, 0] - P[None, :, 0], P[:, None, 1] - P[None, :, 1])
            D[~foot, :] = np.inf
            D[:, ~foot] = np.inf
            np.fill_diagonal(D, np.inf)
            gap = 0.5 * float(np.median(D.min(axis=1)[foot]))
            drop = ~foot
            if s["boundary"] is not None:
                bx, by = s["boundary"]
                ok = np.isfinite(bx) & np.isfinite(by)
                if ok.any():
                    db = np.min(np.hypot(X[:, None] - bx[ok][None, :], Y[:, None] - by[ok][None, :]), axis=1)
                    drop |= db < 0.5 * gap
            kept = []
            for i in range(X.size):
                if drop[i]:
                    continue
                if kept and D[i, kept].min() < gap:
                    drop[i] = True
                else:
                    kept.append(i)
            U[drop] = np.nan
            V[drop] = np.nan
        if vref > 0:
            sp = np.hypot(U, V)
            f = np.where(sp > vref, vref / np.where(sp > 0, sp, 1.0), 1.0)
            U, V = U * f, V * f
        s["arrows"] = [X, Y, U, V]


def fig_snapshots(run):
    run.load_snapshots()
    if run.snapshots is None:
        raise Skip(run.snap_error or "no snapshots")
    snaps = parse_snapshots(run.snapshots)
    if len(snaps) > 12:
        pick = np.unique(np.linspace(0, len(snaps) - 1, 12).round().astype(int))
        snaps = [snaps[i] for i in pick]
    return draw_panels(run, snaps, "snapshots",
                       "snapshots (colour: density of the body, arrows: fluid velocity)")


def fig_instants(run):
    if not run.marks:
        raise Skip("no marked instants (no --mark and no events.csv)")
    t = run.cols["t"] if run.cols is not None and "t" in run.cols else None
    times = [tm for tm, _ in run.marks]
    if t is not None and finite_any(t):
        times = [tm for tm in times if np.nanmin(t) - 1e-9 <= tm <= np.nanmax(t) + 1e-9]
    if not times:
        raise Skip("no marked instant inside the run")
    if len(times) > MAX_INSTANTS:
        warn("instants.png shows the first %d of %d marked instants (up to t = %.6g); choose "
             "others with --mark T,... or --events COLUMN:KIND" % (MAX_INSTANTS, len(times), times[MAX_INSTANTS - 1]))
        times = times[:MAX_INSTANTS]
    snaps = parse_snapshots(run.flow(times=times))
    labels = {round(tm, 6): lab for tm, lab in run.marks}
    for s in snaps:
        s["label"] = labels.get(round(s["t"], 6))
    return draw_panels(run, snaps, "instants",
                       "the body at the marked instants (colour: density, arrows: fluid velocity)")


def draw_density(ax, density, norm):
    X, Y, R = density
    if np.isfinite(R).all():
        return ax.pcolormesh(X, Y, R, shading="gouraud", cmap="viridis", norm=norm,
                             rasterized=True)
    if min(R.shape) > 1:
        # Gouraud shading cannot leave holes: use flat cells (mean of the four
        # corners) and leave blank the cells touching a NaN
        cell = 0.25 * (R[:-1, :-1] + R[1:, :-1] + R[:-1, 1:] + R[1:, 1:])
        return ax.pcolormesh(X, Y, np.ma.masked_invalid(cell), shading="flat",
                             cmap="viridis", norm=norm, rasterized=True)
    return None


def thin_x_ticks(ax, xlim, wy):
    """Tall narrow equal-aspect axes (a long straight path): fewer x ticks, or their labels
    collide; the narrowest keep one, a round number near the middle."""
    from matplotlib.ticker import FixedLocator, MaxNLocator
    wx = xlim[1] - xlim[0]
    if wx < 0.25 * wy:
        mid = 0.5 * (xlim[0] + xlim[1])
        step = 10.0 ** math.floor(math.log10(max(0.5 * wx, 1e-300)))
        ax.xaxis.set_major_locator(FixedLocator([round(mid / step) * step]))
    elif wx < 0.6 * wy:
        ax.xaxis.set_major_locator(MaxNLocator(3))


def draw_panels(run, snaps, name, title):
    # path of the centre of mass (may be absent)
    path = None
    if run.cols is not None and all(k in run.cols for k in ("t", "x", "y")):
        path = (run.cols["t"], run.cols["x"], run.cols["y"])

    # common window: every body, and the path up to the last snapshot
    xs, ys = [], []
    sizes = []
    for s in snaps:
        if s["boundary"] is not None:
            xs.append(s["boundary"][0]); ys.append(s["boundary"][1])
            sizes.append(max(span(s["boundary"][0]), span(s["boundary"][1])))
        if s["density"] is not None:
            xs.append(s["density"][0].ravel()); ys.append(s["density"][1].ravel())
            sizes.append(max(span(s["density"][0]), span(s["density"][1])))
        if np.isfinite(s["pos"]).all():
            xs.append(np.array([s["pos"][0]])); ys.append(np.array([s["pos"][1]]))
    if path is not None:
        m = path[0] <= snaps[-1]["t"] + 1e-12
        xs.append(path[1][m]); ys.append(path[2][m])
    allx = np.concatenate(xs); ally = np.concatenate(ys)
    allx = allx[np.isfinite(allx)]; ally = ally[np.isfinite(ally)]
    if not allx.size or not ally.size:
        raise Skip("snapshot coordinates are all NaN")
    body = max([v for v in sizes if np.isfinite(v)] or [1.0])
    margin = 0.35 * body
    xlim = [allx.min() - margin, allx.max() + margin]
    ylim = [ally.min() - margin, ally.max() + margin]

    norm = density_norm(snaps)

    # shared arrow scale: the longest arrow is ~12% of the window width
    speeds = np.concatenate([np.hypot(s["arrows"][2], s["arrows"][3])
                             for s in snaps if s["arrows"] is not None] or [np.zeros(0)])
    speeds = speeds[np.isfinite(speeds)]
    vref = float(np.percentile(speeds, 98)) if speeds.size else 0.0
    width = max(xlim[1] - xlim[0], ylim[1] - ylim[0])
    qscale = vref / (0.10 * width) if vref > 0 else None

    n = len(snaps)
    ncols = min(n, 5 if n != 6 else 3)
    if n in (7, 8) or (n > 8 and n % 4 == 0 and n % 5 != 0):
        ncols = 4
    nrows = int(math.ceil(n / ncols))
    wx, wy = xlim[1] - xlim[0], ylim[1] - ylim[0]
    panel_w = 11.0 / ncols
    height = min(max(nrows * panel_w * wy / wx + 1.2, 4.0), 11.0)
    fig, axes = plt.subplots(nrows, ncols, figsize=(12.0, height), squeeze=False,
                             sharex=True, sharey=True)
    mappable = None
    quiver_done = None
    for k, ax in enumerate(axes.ravel()):
        if k >= n:
            ax.set_visible(False)
            continue
        s = snaps[k]
        if s["density"] is not None:
            mappable = draw_density(ax, s["density"], norm) or mappable
        if s["boundary"] is not None:
            bx, by = s["boundary"]
            ax.plot(np.append(bx, bx[:1]), np.append(by, by[:1]), color="k", lw=1.2)
        if path is not None:
            m = path[0] <= s["t"] + 1e-12
            ax.plot(path[1][m], path[2][m], color="k", ls="--", lw=1.0)
        px, py = s["pos"]
        if not (np.isfinite(px) and np.isfinite(py)) and path is not None and len(path[0]):
            i = int(np.nanargmin(np.abs(path[0] - s["t"])))
            px, py = path[1][i], path[2][i]
        if np.isfinite(px) and np.isfinite(py):
            ax.plot(px, py, "o", color="k", ms=5, zorder=5)
        if s["arrows"] is not None and qscale is not None:
            X, Y, U, V = s["arrows"]
            ok = (np.isfinite(X) & np.isfinite(Y) & np.isfinite(U) & np.isfinite(V)
                  & (X >= xlim[0]) & (X <= xlim[1]) & (Y >= ylim[0]) & (Y <= ylim[1]))
            if ok.any():
                quiver_done = ax.quiver(X[ok], Y[ok], U[ok], V[ok], color="tab:green",
                                        angles="xy", scale_units="xy", scale=qscale,
                                        width=0.006, zorder=4)
        ax.set_xlim(xlim)
        ax.set_ylim(ylim)
        ax.set_aspect("equal")
        thin_x_ticks(ax, xlim, wy)
        if "label" in s:
            # an instant: what marks it (event name, or --mark) under its time, in the title so
            # that the layout makes room for it
            what = s["label"].replace(", ", "\n") if s.get("label") else "marked (--mark)"
            ax.set_title("$t$ = %.4g\n%s" % (s["t"], what), fontsize=9)
        else:
            ax.set_title("$t$ = %.3g" % s["t"])
        if k % ncols == 0:
            ax.set_ylabel(with_unit("$y$", LENGTH))
        if k // ncols == nrows - 1 or k + ncols >= n:
            ax.set_xlabel(with_unit("$x$", LENGTH))
            ax.tick_params(labelbottom=True)
    run.suptitle(fig, title)
    fig.tight_layout(rect=(0, 0.04 if quiver_done is not None else 0, 0.9, 1))
    if mappable is not None:
        cax = fig.add_axes((0.915, 0.15, 0.015, 0.7))
        rhos = density_values(snaps)
        lo = rhos.size and rhos.min() < norm.vmin
        hi = rhos.size and rhos.max() > norm.vmax
        cb = fig.colorbar(mappable, cax=cax,
                          extend={(0, 0): "neither", (1, 0): "min", (0, 1): "max"}.get(
                              (int(bool(lo)), int(bool(hi))), "both"))
        cb.set_label(with_unit(r"density $\rho = \rho_0 / J$"))
    if quiver_done is not None:
        ax0 = axes.ravel()[0]
        ax0.quiverkey(quiver_done, 0.5, 0.015, vref, "fluid speed %.3g (%s)" % (vref, DIMLESS),
                      coordinates="figure", labelpos="E", color="tab:green")
    return fig


def free_modes(run):
    """Complex modes with a free coordinate, as Fourier indices k (1, -1, -2, ...)."""
    ks = set()
    for name in run.free_coords():
        idx = name[1:]
        k = -int(idx[1:]) if idx.startswith("m") else int(idx)
        ks.add(k)
    return sorted(ks, key=lambda k: (k < 0, abs(k)))


def mode_weight(k):
    # The paper's Figs 4.24-4.25 weigh c_1 by 1 and c_-k by (k+1)^2: the square of the Fourier
    # index of the boundary term e^{-i(k+1)theta} times that of the derivative.
    return 1.0 if k == 1 else float((1 - k) ** 2)


def mode_name(k):
    return "1" if k == 1 else str(k)


def fig_modes(run):
    cols = run.cols
    (t,) = need(cols, "t")
    ks = free_modes(run)
    if len(ks) < 3:
        raise Skip("fewer than 3 free complex modes (%d)" % len(ks))
    amp = {}
    for k in ks:
        a = "a" + ("1" if k == 1 else "m%d" % -k)
        b = "b" + ("1" if k == 1 else "m%d" % -k)
        if a in cols and b in cols:
            amp[k] = mode_weight(k) * (cols[a] ** 2 + cols[b] ** 2)
    if len(amp) < 3:
        raise Skip("mode columns missing")
    low = [k for k in amp if k in (1, -1, -2)]
    high = [k for k in amp if k not in (1, -1, -2)]
    groups = [g for g in (low, high) if g]
    fig, axes = plt.subplots(1, len(groups), figsize=FIGSIZE, squeeze=False)
    colours = ["k", "tab:red", "tab:blue", "tab:purple", "tab:green", "tab:orange", "tab:brown",
               "tab:olive"]
    for ax, g in zip(axes[0], groups):
        for i, k in enumerate(g):
            w = mode_weight(k)
            lab = (r"$|c_{%s}|^2$" % mode_name(k)) if w == 1 else (r"$%d\,|c_{%s}|^2$" % (w, mode_name(k)))
            ax.plot(t, amp[k], color=colours[i % len(colours)], lw=1.3, label=lab)
        mark_failure(ax, run, t)
        ax.set_xlabel(T_LABEL)
        ax.set_ylabel(with_unit(r"weighted mode amplitude $(k+1)^2|c_{-k}|^2$", newline=True))
        ax.set_title("modes excited at $t$ = 0" if g is low and high else
                     ("modes not excited at $t$ = 0" if g is high else "mode amplitudes"))
        ax.grid(alpha=0.3)
    # one legend under the panels: inside an axes it would cover the curves
    handles, labels = [], []
    for ax in axes[0]:
        h, lab = ax.get_legend_handles_labels()
        handles += h
        labels += lab
    run.suptitle(fig, "amplitudes of the shape modes")
    legend_below(fig, handles, labels, ncol_max=5)
    return fig


def fig_phase3d(run):
    cols = run.cols
    (t,) = need(cols, "t")
    free = run.free_coords()
    if len(free) > 8:
        raise Skip("%d free coordinates: modes.png shows them" % len(free))
    cand = []
    for name in free:
        if name in cols and ("d" + name) in cols and span(cols[name]) > 1e-9:
            q, dq = cols[name], cols["d" + name]
            # a coordinate at rest at t = 0 that gets excited is what Fig. 4.19 is about
            at_rest = abs(q[0]) < 1e-12 and abs(dq[0]) < 1e-12
            cand.append((not at_rest, -span(q), name))
    if not cand:
        raise Skip("no free coordinate varies")
    cand.sort()
    names = [n for _, _, n in cand[:4]]
    order = list(cols.keys())
    names.sort(key=order.index)
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the 3d projection)
    from matplotlib.ticker import MaxNLocator
    # at most two 3-d panels a row: narrower ones crowd their tick and axis labels
    ncols = min(len(names), 2)
    nrows = int(math.ceil(len(names) / ncols))
    height = 5.4 * nrows
    fig = plt.figure(figsize=(12.0, height))
    for i, name in enumerate(names):
        ax = fig.add_subplot(nrows, ncols, i + 1, projection="3d")
        q, dq = cols[name], cols["d" + name]
        ok = np.isfinite(q) & np.isfinite(dq)
        ax.plot(q[ok], dq[ok], t[ok], color="tab:blue", lw=0.9)
        # labels on two lines (symbol, unit), away from the tick labels
        ax.set_xlabel(coord_axis(name, newline=True), labelpad=10, fontsize=8.5)
        ax.set_ylabel(coord_axis(name, dot=True, newline=True), labelpad=10, fontsize=8.5)
        ax.set_zlabel(with_unit("time $t$", newline=True), labelpad=8, fontsize=8.5)
        ax.tick_params(labelsize=7, pad=1)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(5))
        ax.view_init(elev=22, azim=-58)
        ax.set_box_aspect(None, zoom=0.88)
        # the panel's name inside the panel's box, under the figure title
        ax.text2D(0.5, 0.99, "(%s, %s, $t$)" % (coord_label(name), coord_label(name, dot=True)),
                  transform=ax.transAxes, ha="center", va="top", fontsize=10)
    run.suptitle(fig, "phase curves in time")
    title_h = 0.75 if fig._suptitle.get_text().count("\n") else 0.55   # inches the title takes
    fig.subplots_adjust(left=0.01, right=0.97, bottom=0.02, top=1.0 - title_h / height, wspace=0.12,
                        hspace=0.08)
    return fig


def fig_path(run):
    t, x, y = need(run.cols, "t", "x", "y")
    ok = np.isfinite(x) & np.isfinite(y)
    if not ok.any():
        raise Skip("x, y are all NaN")
    first = parse_snapshots(run.flow(times=[float(t[ok][0])]))[0]
    if first["boundary"] is None:
        raise Skip("no body outline")
    size = max(span(first["boundary"][0]), span(first["boundary"][1]))
    travel = float(np.hypot(x[ok] - x[ok][0], y[ok] - y[ok][0]).max())
    if travel < 0.6 * size:
        raise Skip("the centre of mass travels %.3g, less than 0.6 body diameters (%.3g)"
                   % (travel, size))
    count = int(min(16, max(4, round(4 * travel / size) + 1)))
    times = list(np.linspace(float(t[ok][0]), float(t[ok][-1]), count))
    snaps = parse_snapshots(run.flow(times=times))
    norm = density_norm(snaps)
    xs = np.concatenate([s["boundary"][0] for s in snaps if s["boundary"] is not None] + [x[ok]])
    ys = np.concatenate([s["boundary"][1] for s in snaps if s["boundary"] is not None] + [y[ok]])
    wx, wy = span(xs) + 0.4, span(ys) + 0.4
    height = min(max(11.0 * wy / max(wx, 1e-9) + 1.0, 3.5), 9.0)
    # a tall path: as wide as the picture plus its two colour bars (about 3.5 inches)
    width = 12.0 if height < 9.0 else min(12.0, max(6.0, 8.0 * wx / wy + 3.5))
    # constrained layout: it keeps the labels in the figure next to the equal-aspect axes and
    # makes room for the two colour bars
    fig, ax = plt.subplots(figsize=(width, height), layout="constrained")
    from matplotlib.colors import LinearSegmentedColormap
    base = plt.get_cmap("plasma")
    cmap = LinearSegmentedColormap.from_list("plasma_dark", base(np.linspace(0.0, 0.85, 256)))
    tnorm = Normalize(times[0], times[-1] if times[-1] > times[0] else times[0] + 1.0)
    mappable = None
    for i, s in enumerate(snaps):
        # the bodies overlap along the path: density only for the first and the last one
        if s["density"] is not None and i in (0, len(snaps) - 1):
            mappable = draw_density(ax, s["density"], norm) or mappable
        if s["boundary"] is not None:
            bx, by = s["boundary"]
            ax.plot(np.append(bx, bx[:1]), np.append(by, by[:1]), color=cmap(tnorm(s["t"])), lw=1.3)
    ax.plot(x, y, color="k", ls="--", lw=1.0, label="centre of mass")
    for s in snaps:
        px, py = s["pos"]
        ax.plot(px, py, "o", color="k", ms=3.5, zorder=5)
    ax.set_aspect("equal")
    ax.set_xlim(np.nanmin(xs) - 0.2, np.nanmax(xs) + 0.2)
    ax.set_ylim(np.nanmin(ys) - 0.2, np.nanmax(ys) + 0.2)
    thin_x_ticks(ax, ax.get_xlim(), span(ax.get_ylim()))
    ax.set_xlabel(with_unit("$x$", LENGTH))
    ax.set_ylabel(with_unit("$y$", LENGTH))
    ax.grid(alpha=0.25)
    # what the picture shows, under the figure's title (centred on the figure: a tall narrow path
    # leaves the axes too narrow for a title of their own)
    run.suptitle(fig, "the body along its path: %d instants from $t$ = %.3g to %.3g, every %.3g\n"
                 "(outline colour: time; density at the first and last)"
                 % (len(snaps), times[0], times[-1], times[1] - times[0]))
    # two colour scales: the time of each outline, the density of the two filled bodies
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=tnorm)
    cb_t = fig.colorbar(sm, ax=ax, shrink=0.8, aspect=30, pad=0.02)
    cb_t.set_ticks(times if len(times) <= 8 else times[::max(1, len(times) // 6)])
    cb_t.set_ticklabels(["%.3g" % v for v in (times if len(times) <= 8 else times[::max(1, len(times) // 6)])])
    cb_t.set_label(with_unit("time $t$ of the outline", newline=True))
    if mappable is not None:
        fig.colorbar(mappable, ax=ax, shrink=0.8, aspect=30, pad=0.02).set_label(
            with_unit(r"density $\rho = \rho_0 / J$", newline=True))
    return fig


def fig_stroke(run):
    """A prescribed stroke: the power P = dE/dt the body spends (positive part shaded) with the
    positive work so far, and per stroke the displacement (body frame at the stroke's start) and
    the positive work."""
    info = run.summary.get("stroke")
    if not isinstance(info, dict):
        raise Skip("not a prescribed stroke (no \"stroke\" in summary.json)")
    cols = run.cols
    t, power = need(cols, "t", "power")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=FIGSIZE)
    ax1.plot(t, power, color="k", lw=1.2, label="power $P = dE/dt$")
    ax1.fill_between(t, 0, np.maximum(power, 0), color="tab:red", alpha=0.3, lw=0, label="$P > 0$ (spent)")
    ax1.axhline(0, color="k", lw=0.6)
    if "work_positive" in cols:
        axw = ax1.twinx()
        axw.plot(t, cols["work_positive"], color="tab:red", lw=1.0, ls="--", label="positive work so far")
        axw.set_ylabel(with_unit("positive work so far", newline=True))
    mark_failure(ax1, run, t)
    ax1.set_xlabel(T_LABEL)
    ax1.set_ylabel(with_unit("power $P$"))
    ax1.set_title("Power of the stroke")
    ax1.grid(alpha=0.3)
    strokes = [s for s in info.get("strokes") or [] if isinstance(s, dict)]
    if strokes:
        k = np.array([s["stroke"] for s in strokes])
        bx = np.array([s["body_dx"] for s in strokes])
        by = np.array([s["body_dy"] for s in strokes])
        wp = np.array([s["work_positive"] for s in strokes])
        # a component that is zero for every stroke (a symmetric stroke) is said, not drawn
        dscale = absmax(bx, by)
        comps = [(bx, "tab:blue", r"$e^*_1$"), (by, "tab:green", r"$e^*_2$")]
        drawn = [c for c in comps if absmax(c[0]) > 1e-9 * max(dscale, 1e-300)] or comps
        for j, (v, colour, e) in enumerate(drawn):
            off = 0.0 if len(drawn) == 1 else (-0.2 if j == 0 else 0.2)
            ax2.bar(k + off, v, width=0.4 if len(drawn) > 1 else 0.5, color=colour,
                    label="displacement along " + e)
        not_drawn = ["along %s: 0, not drawn" % e for v, colour, e in comps if all(c[2] != e for c in drawn)]
        ax2.axhline(0, color="k", lw=0.6)
        ax2.set_xticks(k if len(k) <= 20 else k[::max(1, len(k) // 10)])
        ax2.set_xlabel("stroke number (count; period $T$ = %.6g, %s)"
                       % (info.get("period") or float("nan"), info.get("period_source")))
        ax2.set_ylabel(with_unit("displacement per stroke, body frame", LENGTH, newline=True))
        axp = ax2.twinx()
        axp.plot(k, wp, "o-", color="tab:red", label="positive work per stroke")
        axp.set_ylabel(with_unit("positive work per stroke", newline=True))
        axp.set_ylim(0, 1.2 * max(np.nanmax(wp), 1e-300))
        ax2.set_title("Per stroke")
    else:
        x, y = need(cols, "x", "y")
        ax2.plot(x, y, color="tab:blue")
        ax2.set_aspect("equal", adjustable="datalim")
        ax2.set_xlabel(with_unit("$x$", LENGTH))
        ax2.set_ylabel(with_unit("$y$", LENGTH))
        ax2.set_title("Path of the centre of mass (no period: no strokes to compare)")
    ax2.grid(alpha=0.3)
    run.suptitle(fig, "prescribed stroke" + (", $c_1$ completed" if info.get("completed_c1") else ""))
    # one legend under both panels (inside, it covered the curves); a component not drawn is said
    # in its title, not given an entry
    handles, labels = [], []
    for ax in fig.axes:
        h, lab = ax.get_legend_handles_labels()
        handles += h
        labels += lab
    legend_below(fig, handles, labels, ncol_max=3,
                 title="; ".join(not_drawn) if strokes and not_drawn else None)
    return fig


DRAW = {"trajectory": fig_trajectory, "energy": fig_energy, "impulse": fig_impulse,
        "phase": fig_phase, "snapshots": fig_snapshots, "instants": fig_instants,
        "phase3d": fig_phase3d, "modes": fig_modes, "path": fig_path, "stroke": fig_stroke}


# ---------------------------------------------------------------- main

def take_values(argv, name, needs, usage):
    """Removes every `--NAME V` and `--NAME=V` from argv; their values in order."""
    values, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a == "--" + name:
            if i + 1 >= len(argv):
                print("plot_run: --%s needs %s\n%s" % (name, needs, usage), file=sys.stderr)
                sys.exit(2)
            values.append(argv[i + 1])
            del argv[i:i + 2]
        elif a.startswith("--%s=" % name):
            values.append(a.split("=", 1)[1])
            del argv[i]
        else:
            i += 1
    return values


def parse_args(argv):
    usage = ("usage: swim plot DIR [--only NAME ...] [--mark t1,t2,...] [--events all|COLUMN:KIND,...]   (NAME: %s)"
             % ", ".join(FIGURES))
    outdir, only, mode, marks, events = None, [], None, None, None
    argv = list(argv)
    chosen = take_values(argv, "events", "all or COLUMN:KIND,...", usage)
    if len(chosen) > 1:
        print("plot_run: --events given twice (list every selection in one)", file=sys.stderr)
        sys.exit(2)
    for text in chosen:
        ok = text == "all" or (text and all(len(p.split(":")) == 2 and all(p.split(":")) for p in text.split(",")))
        if not ok:
            print("plot_run: --events: '%s' is not all or COLUMN:KIND,... (e.g. kinetic_rigid:max,potential:min)"
                  % text, file=sys.stderr)
            sys.exit(2)
        events = text
    for text in take_values(argv, "mark", "a list of times", usage):
        try:
            values = [float(x) for x in text.split(",")]
            if not values or not all(math.isfinite(v) for v in values):
                raise ValueError
            marks = (marks or []) + values
        except ValueError:
            print("plot_run: --mark: '%s' is not a list of finite numbers" % text, file=sys.stderr)
            sys.exit(2)
    for a in argv:
        if a in ("-h", "--help"):
            print(__doc__.strip())
            sys.exit(0)
        if a == "--only":
            mode = "only"
            continue
        if a.startswith("--only="):
            only.extend(x for x in a.split("=", 1)[1].split(",") if x)
            mode = "only"
            continue
        if mode == "only" and outdir is not None:
            only.extend(x for x in a.split(",") if x)
        elif outdir is None:
            outdir = a
        elif mode == "only":
            only.extend(x for x in a.split(",") if x)
        else:
            print(usage, file=sys.stderr)
            sys.exit(2)
    if outdir is None:
        print(usage, file=sys.stderr)
        sys.exit(2)
    if mode == "only" and not only:
        print("plot_run: --only needs at least one NAME\n" + usage, file=sys.stderr)
        sys.exit(2)
    return outdir, only, marks, events


def open_run(outdir, marks=None, events=None):
    """The Run of DIR with its marks set as `swim plot DIR [--mark ...] [--events ...]` sets them
    (marks: list of times or None; events: an --events SPEC or None)."""
    run = Run(outdir)
    run.marks = [(tm, None) for tm in sorted(marks or [])]
    if events is not None:
        chosen = select_events(run.events, events)
        if not chosen:
            warn("--events %s: no such events in %s/events.csv (it has: %s)" % (
                events, outdir, ", ".join(sorted({"%s:%s" % (e[1], e[2]) for e in run.events})) or "none"))
        run.marks += marks_from_events(chosen, None)[0]
    elif marks is None:
        run.marks, left = marks_from_events(run.events)
        if left:
            warn("marked the first %d of %d event times (t = %.4g ... %.4g); %d left out: --events all marks "
                 "every one, --events COLUMN:KIND a selection, --mark T,... chosen times"
                 % (len(run.marks), len(run.marks) + left, run.marks[0][0], run.marks[-1][0], left))
    run.marks.sort(key=lambda m: m[0])
    return run


def build_figure(run, name):
    """Figure NAME (one of FIGURES) of a Run (a directory is opened with open_run), as a matplotlib
    Figure, not saved; raises Skip when the figure says nothing about the run. The caller closes it."""
    if not isinstance(run, Run):
        run = open_run(run)
    base = name[:-4] if name.endswith(".png") else name
    if base not in DRAW:
        raise KeyError("unknown figure '%s' (known: %s)" % (name, ", ".join(FIGURES)))
    return DRAW[base](run)


def main(argv):
    outdir, only, marks, events = parse_args(argv)
    if not os.path.isdir(outdir):
        warn("%s is not a directory" % outdir)
        return 1
    wanted = []
    for name in only or FIGURES:
        base = name[:-4] if name.endswith(".png") else name
        if base in DRAW:
            if base not in wanted:
                wanted.append(base)
        else:
            warn("unknown figure '%s' (known: %s)" % (name, ", ".join(FIGURES)))
    run = open_run(outdir, marks, events)
    if run.csv_error:
        warn(run.csv_error)
    written = 0
    for name in wanted:
        try:
            path = save(build_figure(run, name), run, name)
            print(path)
            written += 1
        except Skip as e:
            warn("%s.png skipped: %s" % (name, e))
            stale = os.path.join(outdir, name + ".png")
            if not only and os.path.exists(stale):
                os.remove(stale)   # a figure from an earlier run of another scene
        except Exception as e:  # noqa: BLE001 - a plotting bug must not cost the other figures
            warn("%s.png skipped: %s: %s" % (name, type(e).__name__, e))
        finally:
            plt.close("all")
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
