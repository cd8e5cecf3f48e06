#!/usr/bin/env python3
"""The paper's companion page, reproduced: runs every paper scene and writes OUT/index.html.

Usage: build_paper.py [--out DIR] [--scenes a,b,...] [--t-end T] [--fps F] [--duration S]

One section per figure of sections 4-5 of Munnier's paper, each with our figure and a caption
saying what the paper's figure shows and what ours shows, in numbers where there are numbers;
for each scene its animation, scene file and run summary; and the work-precision figure.
The page is static and self-contained: every link is relative, nothing is fetched.

--scenes, --t-end, --fps and --duration make a reduced page through the same code (the browser
test builds one); a section whose scene is left out is left out. `swim run` gets --event options
when it lists them in `swim run --help`; the marked instants then come from DIR/events.csv,
otherwise from the output rows (said so on the page).
"""
import html
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "runtime", "plot"))
import plot_run  # noqa: E402  (figures are drawn by the code behind `swim plot`)

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
PYTHON = os.environ.get("PYTHON") or "/usr/bin/python3"

# Events asked of `swim run` per scene (COLUMN:KIND): the instants the paper's figures mark,
# and for every scene the maxima of a_-1, the most active coordinate of every paper scene, whose
# spacing is the period of a stroke (and the displacement between them the gain per stroke).
STROKE = ("am1", "max")
EVENTS = {
    # Fig. 4.4: the dashed line is where the rigid velocity vanishes; the motion is along y, so
    # that is a zero of the body's y-impulse (impulse = mass x velocity).
    "example1": ["impulse_body_y:zero"],
    # Fig. 4.8: max and min of the rigid kinetic energy, min and max of the potential energy.
    "example3": ["kinetic_rigid:max", "kinetic_rigid:min", "potential:min", "potential:max"],
}
# The four instants of Fig. 4.8 as printed, with the event that defines each.
FIG48 = [(3.17, "kinetic_rigid", "max"), (3.95, "potential", "min"),
         (6.07, "kinetic_rigid", "min"), (9.50, "potential", "max")]

SCENES = ["example1", "example2a", "example2b", "example2c", "example3", "example4", "example5",
          "example6", "example7", "selfpropelled"]
TITLES = {
    "example1": "Example 1: a swimmer without elasticity",
    "example2a": "Example 2, Fig. 4.5 data", "example2b": "Example 2, Fig. 4.6 data",
    "example2c": "Example 2, Fig. 4.7 data",
    "example3": "Example 3: energy and impulse exchange", "example4": "Example 4: a curved path",
    "example5": "Example 5: c1 unlocked", "example6": "Example 6: hydrodynamical coupling",
    "example7": "Example 7: a softer body", "selfpropelled": "Section 5.2: a self-propelled ball",
}


def log(msg):
    print("build_paper: " + msg, file=sys.stderr, flush=True)


def parse_args(argv):
    opts = {"out": os.path.join(ROOT, "out", "paper"), "scenes": ",".join(SCENES),
            "t-end": None, "fps": "15", "duration": None}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-h", "--help"):
            print(__doc__.strip())
            sys.exit(0)
        name, eq, val = a[2:].partition("=")
        if not a.startswith("--") or name not in opts:
            print("build_paper: unknown argument '%s'" % a, file=sys.stderr)
            sys.exit(2)
        if not eq:
            if i + 1 >= len(argv):
                print("build_paper: --%s needs a value" % name, file=sys.stderr)
                sys.exit(2)
            i += 1
            val = argv[i]
        opts[name] = val
        i += 1
    scenes = [s for s in opts["scenes"].split(",") if s]
    for s in scenes:
        if s not in SCENES:
            print("build_paper: --scenes: unknown scene '%s' (%s)" % (s, ", ".join(SCENES)),
                  file=sys.stderr)
            sys.exit(2)
    opts["scenes"] = scenes
    return opts


def run_help_lists_event():
    p = subprocess.run([SWIM, "run", "--help"], capture_output=True, text=True)
    return "--event" in p.stdout + p.stderr


# ---------------------------------------------------------------- one scene

class SceneRun:
    """A scene run into OUT/runs/NAME, its data and its figures."""

    def __init__(self, name, out, opts, with_events):
        self.name = name
        self.dir = os.path.join(out, "runs", name)
        self.rel = "runs/%s" % name
        self.opts = opts
        self.with_events = with_events
        self.timings = {}

    def simulate(self):
        if os.path.isdir(self.dir):
            shutil.rmtree(self.dir)
        cmd = [SWIM, "run", os.path.join(ROOT, "models", self.name + ".toml"), "--out", self.dir,
               "--quiet"]
        if self.opts["t-end"]:
            cmd += ["--t-end", self.opts["t-end"]]
        if self.with_events:
            for e in EVENTS.get(self.name, []) + [":".join(STROKE)]:
                cmd += ["--event", e]
        t = time.time()
        p = subprocess.run(cmd, capture_output=True, text=True)
        self.timings["run"] = time.time() - t
        self.run_stdout = p.stdout
        if p.returncode not in (0, 1):
            raise RuntimeError("swim run %s failed: %s" % (self.name, p.stderr.strip()))
        with open(os.path.join(self.dir, "summary.json")) as fh:
            self.summary = json.load(fh)
        self.rows = np.atleast_1d(np.genfromtxt(os.path.join(self.dir, "trajectory.csv"),
                                                delimiter=",", names=True))
        self.events = plot_run.read_events(os.path.join(self.dir, "events.csv"))
        self.events_source = "events.csv" if os.path.exists(os.path.join(self.dir, "events.csv")) \
            else None

    def col(self, name):
        return self.rows[name]

    def find_events(self, column, kind):
        """Times of (column, kind): from events.csv, else from the output rows (fallback)."""
        ev = [e[0] for e in self.events if e[1] == column and e[2] == kind]
        if ev or self.events_source:
            return ev
        return row_events(self.col("t"), self.col(column), kind)

    def plots(self, marks=None):
        t = time.time()
        cmd = [PYTHON, os.path.join(ROOT, "runtime", "plot", "plot_run.py"), self.dir]
        if marks:
            cmd += ["--mark", ",".join("%.10g" % m for m in marks)]
        env = dict(os.environ, SWIM_BIN=SWIM)
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        self.figures = [os.path.basename(x) for x in p.stdout.split()]
        self.timings["plot"] = time.time() - t

    def panels(self, name, times, title):
        """Custom snapshot panels at the paper's times (the paper's screenshot figures)."""
        t_end = float(self.col("t")[-1])
        times = [x for x in times if x <= t_end + 1e-9]
        if not times:
            return None
        run = plot_run.Run(self.dir)
        os.environ["SWIM_BIN"] = SWIM
        snaps = plot_run.parse_snapshots(run.flow(times=times))
        plot_run.draw_panels(run, snaps, name, title)
        plot_run.plt.close("all")
        return name + ".png"

    def animate(self):
        t = time.time()
        cmd = [SWIM, "animate", self.dir, "--fps", self.opts["fps"]]
        t_span = float(self.col("t")[-1] - self.col("t")[0])
        duration = self.opts["duration"] or "%g" % min(max(t_span / 2.0, 4.0), 16.0)
        cmd += ["--duration", duration]
        p = subprocess.run(cmd, capture_output=True, text=True)
        self.timings["animate"] = time.time() - t
        self.animation = "animation.mp4" if p.returncode == 0 else None
        if p.returncode != 0:
            log("%s: animation failed: %s" % (self.name, p.stderr.strip()[-300:]))


def row_events(t, v, kind):
    """Fallback without events.csv: zeros by linear interpolation between rows, extremes by the
    vertex of the parabola through three rows."""
    out = []
    if kind == "zero":
        for i in range(len(v) - 1):
            if v[i] == 0 or v[i] * v[i + 1] < 0:
                out.append(t[i] + (t[i + 1] - t[i]) * v[i] / (v[i] - v[i + 1]) if v[i] != v[i + 1]
                           else t[i])
        return out
    d = np.diff(v)
    for i in range(1, len(v) - 1):
        if (kind == "max" and d[i - 1] > 0 >= d[i]) or (kind == "min" and d[i - 1] < 0 <= d[i]):
            den = v[i - 1] - 2 * v[i] + v[i + 1]
            h = t[i + 1] - t[i]
            out.append(t[i] + (0.5 * h * (v[i - 1] - v[i + 1]) / den if den != 0 else 0.0))
    return out


# ---------------------------------------------------------------- captions

def fmt(x, digits=3):
    return ("%%.%dg" % digits) % x


def shares(r):
    """Mean share (%) of each energy part over the run, where the total is not ~0."""
    e = r.col("energy")
    good = np.abs(e) > 1e-9 * max(np.abs(e).max(), 1e-300)
    out = {}
    for c in ("kinetic_fluid", "kinetic_shape", "kinetic_rigid", "potential"):
        out[c] = float(np.mean(100 * r.col(c)[good] / e[good])) if good.any() else float("nan")
    return out


def y_text(r):
    y, x = r.col("y"), r.col("x")
    t = r.col("t")
    s = "y(%s) = %s" % (fmt(t[-1]), fmt(y[-1]))
    if np.abs(x).max() > 1e-6:
        s += ", x(%s) = %s" % (fmt(t[-1]), fmt(x[-1]))
    else:
        s += " with x = 0 throughout (|x| ≤ %s)" % fmt(np.abs(x).max(), 2)
    return s


def strokes(r):
    """(mean period, count, mean displacement) of the strokes, from the maxima of a_-1."""
    ev = r.find_events(*STROKE)
    if len(ev) < 2:
        return None
    y = np.interp(ev, r.col("t"), r.col("y"))
    return float(np.mean(np.diff(ev))), len(ev), float(np.mean(np.diff(y)))


def stroke_text(r):
    p = strokes(r)
    if not p:
        return ""
    return (" %d maxima of a₋₁ (strokes) spaced %s on average, the centre gaining %s in y "
            "between them." % (p[1], fmt(p[0]), fmt(p[2])))


def cap_fig41(r):
    return ("The paper draws the phase portrait of the scalar ODE for β that the shape obeys in "
            "the form (4.17): closed curves, every solution periodic, β ranging over (−π, π). We "
            "show the one solution of the scene's data (β₀ = 0, β̇₀ = −1) through the free "
            "coordinates; a closed curve traced over and over means periodic strokes, as in the "
            "paper. ")


def cap_fig42(r):
    p = strokes(r)
    s = ("The paper plots y(t) for ten initial velocities β̇₀ from −2 to 2. Ours is the one "
         "curve β̇₀ = −1 (the family of runs is not built here): %s." % y_text(r))
    return s + stroke_text(r)


def cap_fig43(r):
    return ("The paper shows ten screenshots over one stroke, t = 0 … 8.1: the body, its density "
            "(compression mainly along the boundary) and the fluid velocity. Ours at the same "
            "times: the same sequence, density highest near the boundary (max ρ₀/J over the run "
            "%s, min J = %s).%s" % (fmt(1.0 / r.summary["jmin"]), fmt(r.summary["jmin"]),
                                    stroke_text(r)))


def cap_fig44(r):
    z = [t for t in r.find_events("impulse_body_y", "zero") if t > 1e-6]
    src = "events.csv" if r.events_source else "the output rows (no events.csv)"
    s = ("The paper stacks the kinetic energies of the fluid, of the deformations and of the "
         "rigid motion (their sum is constant, no elasticity) and marks with a dashed line an "
         "instant where the rigid velocity vanishes. ")
    if z:
        s += ("Ours: the dashed line at t = %s, the first zero of the body's y-impulse after "
              "t = 0 (from %s); %d such zeros over the run. " % (fmt(z[0], 4), src, len(z)))
    s += "Energy drift %s of E₀." % fmt(r.summary.get("energy_drift_rel", float("nan")), 2)
    return s


def cap_fig45(r, which):
    txt = {"4.5": "one potential well centred at β = 0 (κ = 0.5, reference the ellipse γ = 0.5)",
           "4.6": "two wells, at β = 0 and β = π (κ₃ = κ₄ = 0.2, κ₅ = κ₆ = 2)",
           "4.7": "one well centred at β = π/3 (reference shape of Fig. 4.3(i))"}[which]
    y = r.col("y")
    moves = abs(y[-1]) > 0.5
    return ("The paper's phase portrait of the β ODE shows %s; solutions near a well are trapped "
            "and only flap (no locomotion), the others swim along y. Our run of the scene's data "
            "%s: %s, largest |y| %s." % (txt, "swims" if moves else "stays trapped and flaps",
                                          y_text(r), fmt(np.abs(y).max())))


def cap_fig48(r, marks):
    s = ("The paper shows the body at t = 3.17, 3.95, 6.07 and 9.50, instants chosen from the "
         "energy and impulse curves (max and min of the rigid kinetic energy, min and max of the "
         "potential energy). Ours, from %s: " % ("events.csv" if r.events_source else
                                                "the output rows (no events.csv)"))
    parts = []
    for (paper, col, kind), ours in zip(FIG48, marks):
        parts.append("%s %s at %s (paper %s, Δ = %s)" % (col.replace("_", " "), kind,
                                                        fmt(ours, 4), "%.2f" % paper,
                                                        fmt(ours - paper, 2)))
    return s + "; ".join(parts) + "."


def fig48_marks(r):
    marks = []
    for paper, col, kind in FIG48:
        ev = r.find_events(col, kind)
        if ev:
            marks.append(min(ev, key=lambda t: abs(t - paper)))
    return marks if len(marks) == 4 else None


def cap_traj(r, paper):
    return "%s Ours: %s.%s" % (paper, y_text(r), stroke_text(r))


def cap_energy(r, paper):
    sh = shares(r)
    return ("%s Ours, mean shares over the run: fluid %s %%, deformations %s %%, rigid motion %s "
            "%%, potential %s %%; energy drift %s of E₀." % (
                paper, fmt(sh["kinetic_fluid"]), fmt(sh["kinetic_shape"]),
                fmt(sh["kinetic_rigid"]), fmt(sh["potential"]),
                fmt(r.summary.get("energy_drift_rel", float("nan")), 2)))


def cap_impulse(r):
    cols = ["impulse_body_x", "impulse_fluid_rigid_x", "impulse_fluid_shape_x"]
    mx = max(float(np.abs(r.col(c)).max()) for c in cols)
    tot = np.abs(r.col("impulse_body_y") + r.col("impulse_fluid_rigid_y")
                 + r.col("impulse_fluid_shape_y")).max()
    return ("The paper splits the y-impulse into the body's and the fluid's (from the rigid motion "
            "and from the deformations), which sum to zero, and notes that by symmetry the "
            "x-impulses vanish. Ours: |x-impulses| ≤ %s, |sum of the y-impulses| ≤ %s; same "
            "dashed instants as Fig. 4.11." % (fmt(mx, 2), fmt(tot, 2)))


def cap_fig413(r):
    return ("The paper shows the body over [0, 60] along a curved path (dashed). Ours: %s — a "
            "curved path as well; the body drawn at evenly spaced instants along it." % y_text(r))


def cap_phase3d(r, paper, coords):
    s = paper + " Ours: "
    parts = []
    for c in coords:
        v = r.col(c)
        parts.append("%s ranges over [%s, %s]" % (c, fmt(v.min()), fmt(v.max())))
    return s + "; ".join(parts) + "."


def cap_fig416(r, r3):
    sh = shares(r)
    s = ("The paper: each peak is a stroke, the peaks differ (strokes not periodic), and the "
         "rigid-motion share is smaller than in Example 3, a less efficient swimmer. Ours: mean "
         "rigid-motion share %s %%" % fmt(sh["kinetic_rigid"]))
    if r3 is not None:
        s += " against %s %% for Example 3" % fmt(shares(r3)["kinetic_rigid"])
    p = r.find_events("kinetic_rigid", "max")
    if len(p) > 2:
        peaks = np.interp(p, r.col("t"), r.col("kinetic_rigid"))
        s += "; the maxima of the rigid kinetic energy range from %s to %s" % (
            fmt(peaks.min()), fmt(peaks.max()))
    return s + "."


def cap_fig419(r):
    a = np.hypot(r.col("am3"), r.col("bm3"))
    return ("The paper shows that c₋₃, at rest at t = 0 and uncoupled from the others by the "
            "diagonal rigidity, gets excited through the fluid. Ours: |c₋₃| reaches %s (at t = "
            "%s) from 0." % (fmt(a.max()), fmt(r.col("t")[int(np.argmax(a))])))


def cap_fig422(r):
    return ("The paper shows the body at t = 0, 2.5, 5, 7.5, 10: damping lets about three "
            "strokes happen before the energy is too low to swim. Ours at the same times; the "
            "energy falls from %s to %s (%s %% left), %s." % (
                fmt(r.col("energy")[0]), fmt(r.col("energy")[-1]),
                fmt(100 * r.col("energy")[-1] / r.col("energy")[0]), y_text(r)))


def cap_modes(r):
    t = r.col("t")
    hi = []
    for k in range(3, 8):
        a = (k + 1) ** 2 * (r.col("am%d" % k) ** 2 + r.col("bm%d" % k) ** 2)
        hi.append((a.max(), k))
    big = max(hi)
    return ("The paper plots |c₁|², 4|c₋₁|², 9|c₋₂|² (Fig. 4.24) and 16|c₋₃|² … 64|c₋₇|² "
            "(Fig. 4.25): the modes not excited at t = 0 get excited through W₂ and the fluid. "
            "Ours, the same weights: all of c₋₃ … c₋₇ leave 0; the largest is %d|c₋%d|² = %s "
            "(at most %s for the others), against ~1 for the low modes." % (
                (big[1] + 1) ** 2, big[1], fmt(big[0]), fmt(min(hi)[0])) +
            " Run over t ∈ [0, %s]." % fmt(t[-1]))


def cap_fig51(r):
    t, y = r.col("t"), r.col("y")
    return ("The paper shows sixteen screenshots over [0, 25]: the ball, at rest at t = 0, "
            "deforms under the internal forces and swims along y. Ours at the same times: "
            "y(25) = %s; over the whole run %s." % (fmt(np.interp(25.0, t, y)), y_text(r)))


def cap_fig53(r):
    e, w = r.col("energy"), r.col("work")
    return ("The paper: the energy is not conserved any more, it starts at 0 (rest) and follows "
            "the work of the internal forces. Ours: E(0) = %s, all of it the barrier energy W₂ of "
            "the disc at rest (W₂(0) = %s), which the paper, saying the energy is 0 at rest, does "
            "not count; E(T) = %s, "
            "work of forcing and damping %s, and |E − E(0) − work| ≤ %s over the run (5.3)." % (
                fmt(e[0], 3), fmt(r.col("w2")[0], 3), fmt(e[-1], 3), fmt(w[-1], 3),
                fmt(np.abs(e - e[0] - w).max(), 2)))


# ---------------------------------------------------------------- page

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0;background:#fafafa;color:#222}
main{max-width:1100px;margin:0 auto;padding:1rem 1.5rem 4rem}
h1{font-size:1.6rem;margin:.6rem 0}h2{font-size:1.25rem;margin:2rem 0 .4rem;border-top:1px solid #ccc;padding-top:1rem}
h3{font-size:1.05rem;margin:1.2rem 0 .3rem}
figure{margin:.5rem 0}figure img{width:100%;height:auto;background:#fff;border:1px solid #ddd}
figcaption{font-size:.95rem;line-height:1.45;margin-top:.4rem}
video{width:100%;max-width:960px;background:#000;display:block}
table{border-collapse:collapse;font-size:.9rem;margin:.4rem 0}td,th{border:1px solid #ccc;padding:.2rem .5rem;text-align:right}
th{background:#eee}td:first-child,th:first-child{text-align:left}
pre{background:#fff;border:1px solid #ddd;padding:.5rem;overflow:auto;font-size:.8rem;max-height:22rem}
nav{font-size:.9rem;line-height:1.7;columns:3}nav a{display:block}
.run{background:#f0f4f8;border:1px solid #cdd;padding:.6rem 1rem;margin:1rem 0}
.note{color:#555;font-size:.9rem}
"""


def esc(s):
    return html.escape(str(s))


def summary_table(r):
    s = r.summary
    st = s.get("stats", {})
    rows = [("status", "%s (%s)" % (s.get("status"), s.get("reason"))),
            ("t_end", fmt(s.get("t_reached", float("nan")), 4)),
            ("integrator, rtol", "%s, %s" % (s.get("integrator"), s.get("rtol"))),
            ("steps", st.get("steps")), ("RHS evaluations", st.get("rhs_evaluations")),
            ("rejected steps", st.get("rejected_steps")),
            ("time (s)", "%.3f (integration %.3f)" % (st.get("wall_seconds", float("nan")),
                                                     st.get("integrate_seconds", float("nan")))),
            ("energy drift (abs, rel)", "%s, %s" % (fmt(s.get("energy_drift_abs", float("nan")), 2),
                                                   fmt(s.get("energy_drift_rel", float("nan")), 2))),
            ("min J", fmt(s.get("jmin", float("nan")), 4)),
            ("events", "%d (events.csv)" % len(r.events) if r.events_source else "none asked")]
    return ("<table>" + "".join("<tr><th>%s</th><td>%s</td></tr>" % (esc(k), esc(v))
                                for k, v in rows) + "</table>")


def run_block(r):
    with open(os.path.join(r.dir, "scene.toml")) as fh:
        scene = fh.read()
    poster = os.path.splitext(r.animation or "")[0] + ".png"
    has_poster = r.animation and os.path.exists(os.path.join(r.dir, poster))
    video = ('<video controls preload="metadata" src="%s/%s"%s></video>' % (
        r.rel, r.animation, ' poster="%s/%s"' % (r.rel, poster) if has_poster else "")
             if r.animation else '<p class="note">animation failed (see the build log)</p>')
    return ('<div class="run" id="run-%s"><h3>Run: %s (<a href="%s/scene.toml">scene file</a>, '
            '<a href="%s/summary.json">summary.json</a>, <a href="%s/trajectory.csv">trajectory.csv</a>)</h3>%s%s'
            '<details><summary>scene file</summary><pre>%s</pre></details></div>' % (
                r.name, esc(TITLES[r.name]), r.rel, r.rel, r.rel, video, summary_table(r),
                esc(scene)))


def main(argv):
    opts = parse_args(argv)
    out = opts["out"]
    clock = time.time()
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    with_events = run_help_lists_event()
    log("swim run %s --event; building %s" % ("takes" if with_events else "does not take", out))
    runs = {}
    for name in opts["scenes"]:
        r = SceneRun(name, out, opts, with_events)
        r.simulate()
        marks = None
        if name == "example3":
            marks = fig48_marks(r)
        elif name == "example1":
            z = [t for t in r.find_events("impulse_body_y", "zero") if t > 1e-6]
            marks = z[:1]
        r.marks = marks
        r.plots(marks)
        r.animate()
        runs[name] = r
        log("%s: run %.1f s, plots %.1f s, animation %.1f s" % (
            name, r.timings["run"], r.timings["plot"], r.timings.get("animate", 0)))

    sections = []   # (id, title, scene, [images], caption)

    def add(fig, title, scene, images, caption):
        if scene in runs:
            imgs = [i for i in images if i and os.path.exists(os.path.join(runs[scene].dir, i))]
            sections.append((fig, title, scene, imgs, caption(runs[scene])))

    add("4.1", "Phase portrait of β (Example 1)", "example1", ["phase.png"], cap_fig41)
    add("4.2", "y(t) of the centre of mass (Example 1)", "example1", ["trajectory.png"], cap_fig42)
    if "example1" in runs:
        runs["example1"].fig43 = runs["example1"].panels(
            "fig4_3", [0.9 * k for k in range(10)], "one stroke (Fig. 4.3 times)")
    add("4.3", "Screenshots over a stroke (Example 1)", "example1", ["fig4_3.png"], cap_fig43)
    add("4.4", "Distribution of energy (Example 1)", "example1", ["energy.png"], cap_fig44)
    add("4.5", "Phase portrait, one well (Example 2)", "example2a", ["phase.png", "trajectory.png"],
        lambda r: cap_fig45(r, "4.5"))
    add("4.6", "Phase portrait, two wells (Example 2)", "example2b", ["phase.png", "trajectory.png"],
        lambda r: cap_fig45(r, "4.6"))
    add("4.7", "Phase portrait, well at π/3 (Example 2)", "example2c",
        ["phase.png", "trajectory.png"], lambda r: cap_fig45(r, "4.7"))
    if "example3" in runs and runs["example3"].marks:
        add("4.8", "Four instants of Example 3", "example3", ["instants.png"],
            lambda r: cap_fig48(r, r.marks))
    add("4.9", "y(t) (Example 3)", "example3", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: periodic strokes, a net displacement along y."))
    add("4.10", "Phase curves (Re c, Re ċ, t) (Example 3)", "example3", ["phase3d.png"],
        lambda r: cap_phase3d(r, "The paper: the curves of a₋₁ and b₋₂ in (c, ċ, t) repeat — "
                                 "periodic components.", ["am1", "bm2"]))
    add("4.11", "Distribution of energy in percent (Example 3)", "example3", ["energy.png"],
        lambda r: cap_energy(r, "The paper stacks fluid, deformation, rigid-motion kinetic and "
                                "potential energy in percent, with the four instants of Fig. 4.8 "
                                "dashed."))
    add("4.12", "Linear impulses (Example 3)", "example3", ["impulse.png"], cap_impulse)
    add("4.13", "The body along a curved path (Example 4)", "example4", ["path.png"], cap_fig413)
    add("4.14", "Phase curves (Example 4)", "example4", ["phase3d.png"],
        lambda r: cap_phase3d(r, "The paper: none of a₋₁, b₋₁, a₋₂, b₋₂ is periodic.",
                              ["am1", "bm1", "am2", "bm2"]))
    if "example5" in runs:
        runs["example5"].panels("fig4_15", [1.6 * k for k in range(6)], "Fig. 4.15 times")
    add("4.15", "Screenshots (Example 5)", "example5", ["fig4_15.png"],
        lambda r: "The paper: six screenshots over [0, 8]; the strokes look periodic but are "
                  "not. Ours at the same times; %s." % y_text(r))
    add("4.16", "Distribution of energy in percent (Example 5)", "example5", ["energy.png"],
        lambda r: cap_fig416(r, runs.get("example3")))
    add("4.17", "y(t) (Example 5)", "example5", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: passive locomotion along y."))
    if "example6" in runs:
        runs["example6"].panels("fig4_18", [0, 0.9, 1.7, 2.6, 3.4, 4.3, 5.1, 6.0],
                                "Fig. 4.18 times")
    add("4.18", "Screenshots (Example 6)", "example6", ["fig4_18.png"],
        lambda r: "The paper: eight screenshots over [0, 6], strokes clearly not periodic. Ours "
                  "at the same times; %s." % y_text(r))
    add("4.19", "Phase curve of c₋₃ (Example 6)", "example6", ["phase3d.png"], cap_fig419)
    add("4.20", "Distribution of energy in percent (Example 6)", "example6", ["energy.png"],
        lambda r: cap_energy(r, "The paper: a little more than two strokes, the peaks (strokes) "
                                "not periodic."))
    add("4.21", "y(t) (Example 6)", "example6", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: locomotion along y."))
    if "example7" in runs:
        runs["example7"].panels("fig4_22", [0, 2.5, 5, 7.5, 10], "Fig. 4.22 times")
    add("4.22", "Screenshots (Example 7)", "example7", ["fig4_22.png"], cap_fig422)
    add("4.23", "y(t) (Example 7)", "example7", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: about three strokes, then the damped body stops "
                              "swimming."))
    add("4.24–4.25", "Mode amplitudes (Example 7)", "example7", ["modes.png"], cap_modes)
    if "selfpropelled" in runs:
        runs["selfpropelled"].panels("fig5_1", [25.0 * k / 15 for k in range(16)],
                                     "Fig. 5.1 times")
    add("5.1", "Screenshots of the self-propelled ball", "selfpropelled", ["fig5_1.png"], cap_fig51)
    add("5.2", "y(t) (self-propelled)", "selfpropelled", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: the ball starts at rest and swims along y."))
    add("5.3", "Distribution of energy (self-propelled)", "selfpropelled", ["energy.png"],
        cap_fig53)

    wp_src = os.path.join(ROOT, "docs", "figures", "scenes_work_precision_cpu.png")
    wp = None
    if os.path.exists(wp_src):
        shutil.copy(wp_src, os.path.join(out, "work_precision.png"))
        wp = "work_precision.png"

    body = ['<h1>Passive and self-propelled locomotion of an elastic swimmer — the figures '
            'reproduced by swim</h1>',
            '<p>Each section below is one figure of sections 4–5 of Munnier\'s paper: our figure, '
            'what the paper\'s figure shows and what ours shows. The first section of each scene '
            'carries its run: the animation (body coloured by density ρ₀/J, fluid velocity, path '
            'of the centre of mass, energy with a time cursor), the scene file and the run '
            'summary. Marked instants come from %s.</p>' % (
                "the runs' events.csv (swim run --event)" if with_events else
                "the output rows (this swim run has no --event; extremes by parabolic "
                "interpolation between rows)"),
            '<nav>' + "".join('<a href="#fig%s">Fig. %s — %s</a>' % (
                f.replace("–", "-"), f, esc(t)) for f, t, _, _, _ in sections) +
            ('<a href="#work-precision">Work-precision per scene</a>' if wp else "") + '</nav>']
    shown = set()
    for fig, title, scene, imgs, caption in sections:
        r = runs[scene]
        body.append('<section id="fig%s"><h2>Fig. %s — %s</h2>' % (fig.replace("–", "-"), fig,
                                                                   esc(title)))
        for i in imgs:
            body.append('<figure><img src="%s/%s" alt="Fig. %s, ours: %s" loading="lazy">'
                        '</figure>' % (r.rel, i, fig, esc(i)))
        body.append('<figcaption>%s</figcaption>' % esc(caption))
        if scene in shown:
            body.append('<p class="note">Run: <a href="#run-%s">%s</a> (animation, scene, '
                        'summary above).</p>' % (scene, esc(TITLES[scene])))
        else:
            body.append(run_block(r))
            shown.add(scene)
        body.append('</section>')
    if wp:
        body.append('<section id="work-precision"><h2>Work-precision per scene</h2><figure>'
                    '<img src="%s" alt="work-precision diagrams" loading="lazy"></figure>'
                    '<figcaption>CPU time against the error reached over T = min(t_end, 10) for '
                    'each integrator and tolerance (make bench-accuracy; '
                    'docs/figures/scenes_work_precision_cpu.png).</figcaption></section>' % wp)
    total = time.time() - clock
    body.append('<p class="note">Built by tools/paper/build_paper.py in %.0f s (%s).</p>'
                % (total, ", ".join("%s %.0f s" % (n, sum(r.timings.values()))
                                    for n, r in runs.items())))
    page = ('<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            '<title>swim — the paper\'s figures reproduced</title><style>%s</style></head>'
            '<body><main>%s</main></body></html>\n' % (CSS, "\n".join(body)))
    with open(os.path.join(out, "index.html"), "w") as fh:
        fh.write(page)
    log("wrote %s (%d sections) in %.1f s" % (os.path.join(out, "index.html"), len(sections),
                                               total))
    print(os.path.join(out, "index.html"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
