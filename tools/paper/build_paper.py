#!/usr/bin/env python3
"""The paper's companion page, reproduced: runs every paper scene and writes OUT/index.html.

Usage: build_paper.py [--out DIR] [--scenes a,b,...] [--t-end T] [--fps F] [--duration S]
                      [--families all|none|fig-4-1,fig-4-2,...]

One section per figure of sections 4-5 of Munnier's paper, each with our figure and a caption
saying what the paper's figure shows and what ours shows, in numbers where there are numbers;
for each scene its animation, scene file and run summary; and the work-precision figure.
The page is static and self-contained: every link is relative, nothing is fetched.

--scenes, --t-end, --fps and --duration make a reduced page through the same code (the browser
test builds one); a section whose scene is left out is left out. `swim run` gets --event options
when it lists them in `swim run --help`; the marked instants then come from DIR/events.csv,
otherwise from the output rows (said so on the page).

The paper's families (Figs 4.1, 4.2, 4.5, 4.6, 4.7) are the sweeps of the Makefile's fig-4-N
targets (runtime/sweep/module.mk), made fresh into OUT/families/ with
`make fig-4-N FAMILIES=OUT/families`; each becomes its section, with the sweep's definition and
summary. Without a family (--families none, or its target failed) the section shows the scene's
single run instead and says so. --t-end does not apply to the families (their targets fix it).
"""
import html
import json
import os
import shutil
import subprocess
import sys
import time

import re

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "runtime", "plot"))
import plot_run  # noqa: E402  (figures are drawn by the code behind `swim plot`)
import plot_family  # noqa: E402  (the sweep directories' reader and the curve (4.17))

SWIM = os.environ.get("SWIM_BIN") or os.path.join(ROOT, "bin", "swim")
PYTHON = os.environ.get("PYTHON") or "/usr/bin/python3"

# Events asked of `swim run` per scene (COLUMN:KIND): the instants the paper's figures mark,
# and for every scene the maxima of a_-1, the most active coordinate of every paper scene, whose
# spacing is the period of a stroke (and the displacement between them the gain per stroke).
STROKE = ("am1", "max")
EVENTS = {
    # Fig. 4.4: the dashed line is where the rigid velocity vanishes: a minimum of the rigid
    # kinetic energy of value 0 (it touches 0 without changing sign, so not a `zero` event);
    # the motion is along y, so the body's y-impulse (mass x velocity) has a zero there too,
    # asked as an independent check of the same instant.
    "example1": ["kinetic_rigid:min", "impulse_body_y:zero"],
    # Fig. 4.8: max and min of the rigid kinetic energy, min and max of the potential energy.
    "example3": ["kinetic_rigid:max", "kinetic_rigid:min", "potential:min", "potential:max"],
}
# The four instants of Fig. 4.8 as printed, with the event that defines each.
FIG48 = [(3.17, "kinetic_rigid", "max"), (3.95, "potential", "min"),
         (6.07, "kinetic_rigid", "min"), (9.50, "potential", "max")]

# The paper's families: (figure, make target of runtime/sweep/module.mk, directory it writes
# under FAMILIES, the figure it draws, the scene).
FAMILIES = [("4.1", "fig-4-1", "fig4_1", "phase.png", "example1"),
            ("4.2", "fig-4-2", "fig4_2", "family.png", "example1"),
            ("4.5", "fig-4-5", "fig4_5", "phase.png", "example2a"),
            ("4.6", "fig-4-6", "fig4_6", "phase.png", "example2b"),
            ("4.7", "fig-4-7", "fig4_7", "phase.png", "example2c")]

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
            "t-end": None, "fps": "15", "duration": None, "families": "all"}
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
    targets = [f[1] for f in FAMILIES]
    fam = opts["families"]
    fam = targets if fam == "all" else [] if fam == "none" else [x for x in fam.split(",") if x]
    for f in fam:
        if f not in targets:
            print("build_paper: --families: unknown family '%s' (all, none or some of %s)"
                  % (f, ",".join(targets)), file=sys.stderr)
            sys.exit(2)
    opts["families"] = fam
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


# ---------------------------------------------------------------- one family

class Family:
    """One of the paper's families: the sweep of a Makefile fig-4-N target, made into
    OUT/families/DIRNAME, and what its files say."""

    def __init__(self, fig, target, dirname, image, scene, out):
        self.fig, self.target, self.scene, self.image = fig, target, scene, image
        self.root = os.path.join(out, "families")
        self.dir = os.path.join(self.root, dirname)
        self.rel = "families/%s" % dirname
        self.log = os.path.join(self.root, dirname + ".log")
        self.ok = False

    def make(self):
        """Runs the target into a fresh directory (a sweep of an earlier binary is not reused),
        timing it; the target's output (its commands, the sweep's summary line) goes to the log."""
        if os.path.isdir(self.dir):
            shutil.rmtree(self.dir)
        os.makedirs(self.root, exist_ok=True)
        cmd = ["make", "-C", ROOT, "--no-print-directory", "FAMILIES=" + self.root]
        rel_bin = os.path.relpath(os.path.dirname(os.path.abspath(SWIM)), ROOT)
        if not rel_bin.startswith(".."):
            # the binary this page is built with, and never rebuilt from here (-o)
            cmd += ["BIN=" + rel_bin, "-o", os.path.join(rel_bin, "swim")]
        cmd.append(self.target)
        # a make above us (make paper, make test) must not lend its jobserver to this one
        env = {k: v for k, v in os.environ.items()
               if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES")}
        env["SWIM_BIN"] = SWIM
        t = time.time()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        self.seconds = time.time() - t
        self.output = p.stdout + p.stderr
        with open(self.log, "w") as fh:
            fh.write("$ %s\n%s" % (" ".join(cmd), self.output))
        if p.returncode != 0 or not os.path.exists(os.path.join(self.dir, self.image)):
            log("%s failed (status %d), see %s: %s" % (self.target, p.returncode, self.log,
                                                       self.output.strip()[-300:]))
            return False
        self.load()
        self.ok = True
        return True

    def load(self):
        self.sweep, self.members = plot_family.load_sweep(self.dir)
        self.rows = [m["row"] for m in self.members]
        self.periods = []
        pp = os.path.join(self.dir, "periods.csv")
        if os.path.exists(pp):
            self.periods = plot_family.read_csv(pp)
        # the sweep's own account: "... (N ran now in S s, R members/s with J jobs)"
        m = re.search(r"(\d+) ran now in ([0-9.]+) s, ([0-9.]+) members/s with (\d+) jobs",
                      self.output)
        self.sweep_seconds = float(m.group(2)) if m else None
        self.jobs = int(m.group(4)) if m else None
        echoed = self.output.replace("\\\n", " ")    # make echoes continued lines as is
        cmd = [ln for ln in echoed.splitlines() if " sweep " in ln and "--out" in ln]
        self.command = re.sub(r"\s+", " ", cmd[0].strip()) if cmd else "make %s" % self.target

    def total(self, column):
        return sum(float(r[column]) for r in self.rows if r.get(column))

    def betadots(self):
        """beta'(0) of every kept member (they follow (4.17))."""
        out = []
        for m in self.members:
            if m["traj"] is not None and plot_family.follows_reduction(m["traj"]):
                out.append(float(plot_family.beta_of(m["traj"])[1][0]))
        return out

    def wells(self):
        """Local minima of the potential V(beta) = W1(c(beta)) on the curve (4.17), from the scene
        (with the sweep's fixed overrides): where the paper's wells must be. [] without
        elasticity (V constant)."""
        import tomllib
        with open(os.path.join(ROOT, self.sweep["scene"]), "rb") as fh:
            scene = tomllib.load(fh)
        for kv in self.sweep.get("set", []):
            k, v = kv.split("=", 1)
            plot_family.apply_key(scene, k, float(v))
        el = scene.get("elastic")
        kept = [m for m in self.members if m["traj"] is not None]
        if not el or not kept:
            return []
        gamma = plot_family.beta_of(kept[0]["traj"])[2]
        n = 2 * (scene["model"]["modes"] + 1)
        R = np.array(el["stiffness"], float)
        cref = np.array(el["reference"], float)
        grid = np.linspace(-np.pi, np.pi, 3600, endpoint=False)
        V = np.array([0.5 * (c - cref) @ (R * (c - cref))
                      for c in (plot_family.curve(gamma, b, n)[0] for b in grid)])
        if V.max() - V.min() < 1e-12 * max(1.0, abs(V).max()):
            return []
        out = []
        h = grid[1] - grid[0]
        for i in range(len(V)):
            a, b, c = V[i - 1], V[i], V[(i + 1) % len(V)]
            if b < a and b <= c:
                den = a - 2 * b + c
                out.append(grid[i] + (0.5 * h * (a - c) / den if den else 0.0))
        return sorted(out)


def angle_text(b):
    """beta as a number and, when it is one, as a multiple of pi/6."""
    k = round(b / (np.pi / 6))
    names = {0: "0", 2: "π/3", 3: "π/2", 4: "2π/3", 6: "π", -2: "−π/3", -3: "−π/2",
             -4: "−2π/3", -6: "π"}
    if abs(b - k * np.pi / 6) < 2e-3 and k in names:
        return "%.4f (%s)" % (b, names[k]) if k else "0.0000"
    return "%.4f" % b


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
    elif np.abs(x).max() == 0:
        s += " with x = 0 throughout (exactly)"
    else:
        s += " with x = 0 throughout (|x| ≤ %s)" % fmt(np.abs(x).max(), 2)
    return s


def strokes(r):
    """The strokes, from the maxima of a_-1: summary.json's "periodic" entry of the am1:max
    events when swim run made one (period = mean spacing, displacement between successive
    events located on the interpolant); else spacing of the events found and y interpolated
    between output rows. None with fewer than two maxima."""
    for p in (getattr(r, "summary", None) or {}).get("periodic", []) or []:
        if (p.get("column"), p.get("kind")) == STROKE:
            d = p["displacement_per_period"]
            return {"period": p["period"], "count": p["periods"] + 1, "dy": d["y"], "dx": d["x"],
                    "spread": p["period_max"] - p["period_min"], "source": "summary.json"}
    ev = r.find_events(*STROKE)
    if len(ev) < 2:
        return None
    y = np.interp(ev, r.col("t"), r.col("y"))
    x = np.interp(ev, r.col("t"), r.col("x"))
    sp = np.diff(ev)
    return {"period": float(np.mean(sp)), "count": len(ev), "dy": float(np.mean(np.diff(y))),
            "dx": float(np.mean(np.diff(x))), "spread": float(sp.max() - sp.min()),
            "source": "the output rows"}


def stroke_text(r):
    p = strokes(r)
    if not p:
        return ""
    s = (" Strokes (maxima of a₋₁, %d of them, from %s): period %s" % (
        p["count"], p["source"], fmt(p["period"], 6)))
    if p["count"] > 2:
        s += (" (spacings within %s: periodic)" % fmt(p["spread"], 2) if
              p["spread"] <= 1e-6 * p["period"] else
              " on average (spacings spread over %s: not periodic)" % fmt(p["spread"], 3))
    s += ", displacement per stroke Δy = %s" % fmt(p["dy"], 6)
    if abs(p["dx"]) > 1e-9:
        s += ", Δx = %s" % fmt(p["dx"], 4)
    return s + "."


def cap_fig41(r):
    return ("The paper draws the phase portrait of the scalar ODE for β that the shape obeys in "
            "the form (4.17): closed curves, every solution periodic, β ranging over (−π, π). We "
            "show the one solution of the scene's data (β₀ = 0, β̇₀ = −1) through the free "
            "coordinates; a closed curve traced over and over means periodic strokes, as in the "
            "paper. ")


def cap_fig42(r):
    s = ("The paper plots y(t) for ten initial velocities β̇₀ from −2 to 2. Ours is the one "
         "curve β̇₀ = −1 (the family's sweep was not made for this page: --families): %s."
         % y_text(r))
    return s + stroke_text(r)


def cap_fig43(r):
    return ("The paper shows ten screenshots over one stroke, t = 0 … 8.1: the body, its density "
            "(compression mainly along the boundary) and the fluid velocity. Ours at the same "
            "times: the same sequence, density highest near the boundary (max ρ₀/J over the run "
            "%s, min J = %s).%s" % (fmt(1.0 / r.summary["jmin"]), fmt(r.summary["jmin"]),
                                    stroke_text(r)))


def rigid_rest(r):
    """[(t, value)] of the instants t > 0 where the rigid velocity vanishes: minima of the rigid
    kinetic energy whose value is 0 to rounding (events.csv); without those, zeros of the body's
    y-impulse (events.csv, else the output rows), value NaN."""
    scale = max(float(np.abs(r.col("kinetic_rigid")).max()), 1e-300)
    ev = [(e[0], e[3]) for e in r.events if e[1] == "kinetic_rigid" and e[2] == "min"
          and e[0] > 1e-6 and abs(e[3]) <= 1e-12 * scale]
    if ev:
        return ev
    return [(t, float("nan")) for t in r.find_events("impulse_body_y", "zero") if t > 1e-6]


def cap_fig44(r):
    z = rigid_rest(r)
    src = "events.csv" if r.events_source else "the output rows (no events.csv)"
    s = ("The paper stacks the kinetic energies of the fluid, of the deformations and of the "
         "rigid motion (their sum is constant, no elasticity) and marks with a dashed line an "
         "instant t† where the rigid kinetic energy, hence the rigid velocity, is zero. ")
    if z:
        t0, v0 = z[0]
        if v0 == v0:
            s += ("Ours: the dashed line at t† = %s, the first minimum of the rigid kinetic "
                  "energy after t = 0, of value %s (zero to rounding; from %s)" % (
                      fmt(t0, 8), fmt(v0, 2), src))
            imp = [t for t in r.find_events("impulse_body_y", "zero") if t > 1e-6]
            if imp:
                d = min(abs(t - t0) for t in imp)
                s += "; the body's y-impulse vanishes at the same instant to |Δt| = %s" % fmt(d, 2)
            s += "; %d such instants over the run. " % len(z)
        else:
            s += ("Ours: the dashed line at t = %s, the first zero of the body's y-impulse after "
                  "t = 0 (from %s); %d such zeros over the run. " % (fmt(t0, 4), src, len(z)))
    s += "Energy drift %s of E₀." % fmt(r.summary.get("energy_drift_rel", float("nan")), 2)
    return s + stroke_text(r)


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
                                                        fmt(ours, 5), "%.2f" % paper,
                                                        fmt(ours - paper, 2)))
    return s + "; ".join(parts) + "."


def fig48_marks(r):
    """The four instants, each the event of its kind nearest the paper's time; None when one is
    missing or the run ends before the paper's time (a shortened run would pick another)."""
    t_end = float(r.col("t")[-1])
    marks = []
    for paper, col, kind in FIG48:
        ev = r.find_events(col, kind)
        if ev and t_end >= paper:
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


# ------------------------------------------------------- family captions

def family_numbers(f):
    """Counts per kind and the displacement per period of the passing and trapped members
    (periods.csv of swim plot)."""
    kinds = {"passing": 0, "trapped": 0, "open": 0}
    dy = {"passing": [], "trapped": []}
    per = {"passing": [], "trapped": []}
    for p in f.periods:
        kinds[p["kind"]] = kinds.get(p["kind"], 0) + 1
        if p["kind"] in dy and p["dy_per_period"]:
            dy[p["kind"]].append(float(p["dy_per_period"]))
            per[p["kind"]].append(float(p["period"]))
    return kinds, dy, per


def passing_text(dy, per):
    if not dy["passing"]:
        return ""
    a = np.abs(dy["passing"])
    return ("passing members move by |Δy| = %s … %s per period (one turn of β, periods %s … "
            "%s), whatever their energy, in the direction opposite to β̇" % (
                fmt(a.min(), 6), fmt(a.max(), 6), fmt(min(per["passing"]), 4),
                fmt(max(per["passing"]), 4)))


def cap_family41(f):
    kinds, dy, per = family_numbers(f)
    bd = f.betadots()
    n = len(f.rows)
    s = ("The paper's phase portrait (β from −π to π, β̇ from −1.5 to 1.5 on its axes): arrows "
         "(β̇, β̈), solutions that are also level sets of the energy; no elasticity, so no well: "
         "every solution is periodic and turns β through the whole circle. Ours: %d members "
         "starting at β₀ = 0 with β̇₀ from %s to %s, run to t = %s; arrows and energy level sets "
         "from the model (projection of the equations on the curve (4.17)), the members' "
         "computed curves on top. The potential is constant (%s). %d of %d pass (blue: swim), "
         "%d trapped" % (n, fmt(min(bd)), fmt(max(bd)), fmt(f.total("t_reached") / max(n, 1)),
                         "no wells" if not f.wells() else "wells?!", kinds["passing"], n,
                         kinds["trapped"]))
    s += "; " + passing_text(dy, per) if dy["passing"] else ""
    return s + " (right panel)."


def cap_family42(f, r1):
    ys = [(float(r["y"]), b) for r, b in zip(f.rows, f.betadots()) if r["y"]]
    ys.sort()
    s = ("The paper plots y(t) of the centre of mass for β̇₀ = 2, 1.55, 1.1, 0.65, 0.2, −0.2, "
         "−0.65, −1.1, −1.55, −2 (γ = 0.5, β₀ = 0), from the bottom curve to the top one, on "
         "axes t ∈ [0, 30], y ∈ [−4, 4]: periodic strokes, a net displacement along y growing "
         "with |β̇₀|. Ours: one sweep of %d members (the same β̇₀, through ḃ₋₂(0) = γβ̇₀/√2), "
         "one curve each: " % len(f.rows))
    if ys:
        T = max(float(r["t_reached"]) for r in f.rows)
        s += ("y(%s) runs from %s (β̇₀ = %s, bottom) to %s (β̇₀ = %s, top), the same order as "
              "the paper's and inside its y-range; ±β̇₀ mirror each other (largest |y(T; v) + "
              "y(T; −v)| = %s)" % (fmt(T), fmt(ys[0][0], 4), fmt(ys[0][1]), fmt(ys[-1][0], 4),
                                   fmt(ys[-1][1]), fmt(mirror_gap(f), 2)))
    kinds, dy, per = family_numbers(f)
    if dy["passing"]:
        s += "; " + passing_text(dy, per)
    s += ". x stays 0 and every member swims (no potential, no well)."
    if r1 is not None:
        p = strokes(r1)
        if p:
            s += (" The scene's own run (β̇₀ = −1, animated in Fig. 4.3's section): stroke period "
                  "%s, Δy = %s "
                  "per stroke (summary.json, periodic)." % (fmt(p["period"], 6), fmt(p["dy"], 6)))
    return s


def mirror_gap(f):
    by = {}
    for r, b in zip(f.rows, f.betadots()):
        by[round(b, 9)] = float(r["y"])
    gaps = [abs(y + by[-b]) for b, y in by.items() if -b in by]
    return max(gaps) if gaps else float("nan")


WELLS_PAPER = {"4.5": ("one well, at (0, 0): κⱼ = 0.5, reference the ellipse cref = (1, 0, γ, 0, …), "
                       "β = 0", [0.0]),
               "4.6": ("two wells, at (0, 0) and (π, 0): κ₃ = κ₄ = 0.2, κ₅ = κ₆ = 2, the ellipse "
                       "c = (1, 0, −γ, 0, …) (β = π) a second minimum of W₁", [0.0, np.pi]),
               "4.7": ("one well, at (π/3, 0): κⱼ = 0.5, reference the shape of Fig. 4.3(i), "
                       "β = π/3", [np.pi / 3])}


def cap_family_wells(f, which, r):
    txt, want = WELLS_PAPER[which]
    kinds, dy, per = family_numbers(f)
    w = f.wells()
    wrapped = sorted(np.pi - (np.pi - b) % (2 * np.pi) for b in w)    # in (-pi, pi]
    miss = max((min(abs(np.angle(np.exp(1j * (a - b)))) for a in wrapped) for b in want),
               default=float("nan")) if wrapped else float("nan")
    s = ("The paper's phase portrait shows %s; solutions near a well stay in it and only flap "
         "(Purcell's scallop: no net motion), the others swim like Example 1. Ours: %d members "
         "(β̇₀ from %s to %s), wells of the potential V(β) = W₁(c(β)) at β = %s, β̇ = 0 (%s). "
         "%d trapped (red), %d passing (blue)%s. " % (
             txt, len(f.rows), fmt(min(f.betadots())), fmt(max(f.betadots())),
             ", ".join(angle_text(b) for b in wrapped) or "none",
             "where the paper puts them: |Δβ| ≤ %s" % fmt(max(miss, 1e-16), 1) if miss < 1e-3 else
             "NOT where the paper puts them: %s away" % fmt(miss, 3),
             kinds["trapped"], kinds["passing"],
             ", %d without a whole period in the run (dashed)" % kinds["open"]
             if kinds.get("open") else ""))
    if dy["trapped"]:
        s += ("Net displacement per period: trapped |Δy| ≤ %s (zero up to the interpolation "
              "between output rows: flapping)" %
              fmt(np.abs(dy["trapped"]).max(), 2))
        s += "; " + passing_text(dy, per) if dy["passing"] else ""
        s += " (right panel). "
    elif dy["passing"]:
        s += passing_text(dy, per) + " (right panel). "
    if r is not None:
        y = r.col("y")
        s += ("The scene's own run (below the sweep): it %s; %s.%s" % (
            "swims" if abs(y[-1]) > 0.5 else "stays trapped and flaps", y_text(r),
            stroke_text(r)))
    return s


def sweep_block(f):
    sw = f.sweep
    rows = f.rows
    done = sum(r["status"] == "completed" for r in rows)
    rhs = [int(r["rhs_evaluations"]) for r in rows if r.get("rhs_evaluations")]
    vary = "; ".join("%s: %d values, %s … %s" % (v["key"], len(v["values"]),
                                                  fmt(v["values"][0], 4), fmt(v["values"][-1], 4))
                     for v in sw["vary"]) + (" (zipped)" if sw.get("zip") else "")
    items = [("members", "%d (%d completed, %d failed)" % (len(rows), done, len(rows) - done)),
             ("scene", sw["scene"]), ("varied", vary),
             ("fixed overrides", ", ".join(sw.get("set", [])) or "none"),
             ("t reached", ", ".join(sorted({fmt(float(r["t_reached"]), 4) for r in rows}))),
             ("steps (all members)", "%d" % f.total("steps")),
             ("RHS evaluations", "%d in all, %d … %d per member" % (sum(rhs), min(rhs), max(rhs))
              if rhs else "—"),
             ("integration (all members)", "%.3f s" % f.total("integrate_seconds")),
             ("members' swim run time", "%.2f s in all" % f.total("wall_seconds")),
             ("sweep", "%.2f s with %d jobs" % (f.sweep_seconds, f.jobs)
              if f.sweep_seconds is not None else "—"),
             ("make %s (sweep + swim plot)" % f.target, "%.1f s" % f.seconds)]
    links = ", ".join('<a href="%s/%s">%s</a>' % (f.rel, n, n)
                      for n in ("sweep.json", "members.csv", "periods.csv")
                      if os.path.exists(os.path.join(f.dir, n)))
    links += ', <a href="%s.log">build log</a>' % f.rel
    return ('<div class="run sweep" id="sweep-%s"><h3>Sweep: <code>make %s</code> (%s)</h3>'
            '<pre class="cmd">%s</pre><table>%s</table></div>' % (
                f.target, f.target, links, esc(f.command),
                "".join("<tr><th>%s</th><td>%s</td></tr>" % (esc(k), esc(v)) for k, v in items)))


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
pre.cmd{white-space:pre-wrap;word-break:break-all}
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
            marks = [t for t, _ in rigid_rest(r)[:1]]
        r.marks = marks
        r.plots(marks)
        r.animate()
        runs[name] = r
        log("%s: run %.1f s, plots %.1f s, animation %.1f s" % (
            name, r.timings["run"], r.timings["plot"], r.timings.get("animate", 0)))

    fams = {}
    for fig, target, dirname, image, scene in FAMILIES:
        if target in opts["families"]:
            f = Family(fig, target, dirname, image, scene, out)
            if f.make():
                fams[fig] = f
                log("%s: %d members, make %s %.1f s" % (dirname, len(f.rows), target, f.seconds))

    # (id, title, scene, [images relative to out], caption, family or None, show the run)
    sections = []

    def add(fig, title, scene, images, caption):
        if scene in runs:
            r = runs[scene]
            imgs = ["%s/%s" % (r.rel, i) for i in images
                    if i and os.path.exists(os.path.join(r.dir, i))]
            sections.append((fig, title, scene, imgs, caption(r), None, True))

    def add_family(fig, title, run_images, caption):
        """Fig. FIG from its family when the sweep was made, with the scene run's RUN_IMAGES
        (and its run block) after it; otherwise False."""
        f = fams.get(fig)
        if f is None:
            return False
        r = runs.get(f.scene)
        imgs = ["%s/%s" % (f.rel, f.image)]
        if r is not None:
            imgs += ["%s/%s" % (r.rel, i) for i in run_images
                     if os.path.exists(os.path.join(r.dir, i))]
        sections.append((fig, title, f.scene, imgs, caption(f, r), f,
                         r is not None and bool(run_images)))
        return True

    if not add_family("4.1", "Phase portrait of β (Example 1, a family)", [],
                      lambda f, r: cap_family41(f)):
        add("4.1", "Phase portrait of β (Example 1)", "example1", ["phase.png"], cap_fig41)
    if not add_family("4.2", "y(t) for ten initial velocities (Example 1, a family)", [],
                      cap_family42):
        add("4.2", "y(t) of the centre of mass (Example 1)", "example1", ["trajectory.png"],
            cap_fig42)
    if "example1" in runs:
        runs["example1"].fig43 = runs["example1"].panels(
            "fig4_3", [0.9 * k for k in range(10)], "one stroke (Fig. 4.3 times)")
    add("4.3", "Screenshots over a stroke (Example 1)", "example1", ["fig4_3.png"], cap_fig43)
    add("4.4", "Distribution of energy (Example 1)", "example1", ["energy.png"], cap_fig44)
    for fig, scene, title in (("4.5", "example2a", "Phase portrait, one well (Example 2)"),
                              ("4.6", "example2b", "Phase portrait, two wells (Example 2)"),
                              ("4.7", "example2c", "Phase portrait, well at π/3 (Example 2)")):
        if not add_family(fig, title + ", a family", ["trajectory.png"],
                          lambda f, r, fig=fig: cap_family_wells(f, fig, r)):
            add(fig, title, scene, ["phase.png", "trajectory.png"],
                lambda r, fig=fig: cap_fig45(r, fig))
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
            'summary. %sMarked instants come from %s.</p>' % (
                ("Figs %s are families of runs, each one <code>swim sweep</code> (the make "
                 "target named in its section) drawn by <code>swim plot</code>; their sections "
                 "carry the sweep's definition and summary. " % ", ".join(sorted(fams)))
                if fams else "",
                "the runs' events.csv (swim run --event)" if with_events else
                "the output rows (this swim run has no --event; extremes by parabolic "
                "interpolation between rows)"),
            '<nav>' + "".join('<a href="#fig%s">Fig. %s — %s</a>' % (
                f.replace("–", "-"), f, esc(t)) for f, t, *_ in sections) +
            ('<a href="#work-precision">Work-precision per scene</a>' if wp else "") + '</nav>']
    shown = set()
    for fig, title, scene, imgs, caption, fam, show_run in sections:
        body.append('<section id="fig%s"><h2>Fig. %s — %s</h2>' % (fig.replace("–", "-"), fig,
                                                                   esc(title)))
        # a family: its figure, the caption and the sweep, then the scene's own run
        first = imgs[:1] if fam is not None else imgs
        for i in first:
            body.append('<figure><img src="%s" alt="Fig. %s, ours: %s" loading="lazy">'
                        '</figure>' % (i, fig, esc(os.path.basename(i))))
        body.append('<figcaption>%s</figcaption>' % esc(caption))
        if fam is not None:
            body.append(sweep_block(fam))
            for i in imgs[1:]:
                body.append('<figure><img src="%s" alt="the scene\'s own run: %s" '
                            'loading="lazy"></figure>' % (i, esc(os.path.basename(i))))
        if not show_run:
            pass
        elif scene in shown:
            body.append('<p class="note">Run: <a href="#run-%s">%s</a> (animation, scene, '
                        'summary above).</p>' % (scene, esc(TITLES[scene])))
        else:
            body.append(run_block(runs[scene]))
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
                % (total, ", ".join(["%s %.0f s" % (n, sum(r.timings.values()))
                                     for n, r in runs.items()] +
                                    ["make %s %.0f s" % (f.target, f.seconds)
                                     for f in fams.values()])))
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
