#!/usr/bin/env python3
"""The paper's companion page, reproduced: runs every paper scene and writes OUT/index.html.

Usage: build_paper.py [--out DIR] [--scenes a,b,...] [--t-end T] [--fps F] [--duration S]
                      [--families all|none|fig-4-1,fig-4-2,...]
                      [--work-precision auto|quick|none|CSV]

Part 1, one section per figure of sections 4-5 of Munnier's paper: the paper's caption (quoted
briefly), our figure and caption, and a table of the numbers the paper states (caption or the
text next to the figure) beside ours with the difference -- or the statement that the paper
gives no numbers for the figure. Part 2, one section per scene of models/ and models/control/
(models/hard/ is listed, not run): what it is, our figures, animation, scene file and the key
numbers of its summary.json. Part 3, the work-precision figure, made from the current build by
tools/paper/work_precision.py (--work-precision: auto = make bench-accuracy's table when it is
newer than the binary, else a quick measurement; quick; none; or a CSV of bench_accuracy.py).
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

PAPER_SCENES = ["example1", "example2a", "example2b", "example2c", "example3", "example4",
                "example5", "example6", "example7", "selfpropelled"]
TITLES = {
    "example1": "Example 1: a swimmer without elasticity",
    "example2a": "Example 2, Fig. 4.5 data", "example2b": "Example 2, Fig. 4.6 data",
    "example2c": "Example 2, Fig. 4.7 data",
    "example3": "Example 3: energy and impulse exchange", "example4": "Example 4: a curved path",
    "example5": "Example 5: c1 unlocked", "example6": "Example 6: hydrodynamical coupling",
    "example7": "Example 7: a softer body", "selfpropelled": "Section 5.2: a self-propelled ball",
}
# The folders of models/ the page runs: the top level (the paper's scenes and the prescribed
# strokes) and control/ (the scenes of swim optimize). models/hard/ is listed, not run: its
# scenes are the integrators' stress tests (T = 1000 runs, N = 20 kernels), made by
# `make bench-hard`, minutes each.
RUN_FOLDERS = ["", "control"]
LISTED_FOLDERS = ["hard"]


def scenes_in(folder):
    d = os.path.join(ROOT, "models", folder)
    if not os.path.isdir(d):
        return []
    return sorted((folder + "/" if folder else "") + f[:-5] for f in os.listdir(d)
                  if f.endswith(".toml"))


def discover_scenes():
    """Every scene the page runs: the paper's in the paper's order, then the other top-level
    scenes, then those of control/."""
    found = [n for fo in RUN_FOLDERS for n in scenes_in(fo)]
    return [n for n in PAPER_SCENES if n in found] + [n for n in found if n not in PAPER_SCENES]


SCENES = discover_scenes()


def scene_path(name):
    return os.path.join(ROOT, "models", name + ".toml")


def scene_header(name):
    """(title, the comment block at the top of the scene file, joined into one text)."""
    title, lines = None, []
    with open(scene_path(name)) as fh:
        for ln in fh:
            st = ln.strip()
            if st.startswith("title") and title is None:
                title = st.split("=", 1)[1].strip().strip('"')
                continue
            if st.startswith("#"):
                lines.append(st.lstrip("#").strip())
                continue
            if st.startswith("["):
                break
            if st == "" and lines:
                continue
    return title or name, " ".join(x for x in lines if x)


def title_of(name):
    return TITLES.get(name) or scene_header(name)[0]


def section_id(name):
    return "scene-" + name.replace("/", "-")


def log(msg):
    print("build_paper: " + msg, file=sys.stderr, flush=True)


def parse_args(argv):
    opts = {"out": os.path.join(ROOT, "out", "paper"), "scenes": ",".join(SCENES),
            "t-end": None, "fps": "15", "duration": None, "families": "all",
            "work-precision": "auto"}
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
        # draw_panels returns the figure; saving is the caller's (plot_run's main loop saves
        # its own figures the same way)
        plot_run.save(plot_run.draw_panels(run, snaps, name, title), run, name)
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


def promised_images(d, rel, names, what, missing):
    """Page paths REL/NAME of the NAMES made (non-empty files) in folder D; each one not made is
    appended to MISSING as "WHAT: D/NAME" (the page promised it: the build must fail)."""
    got = []
    for i in names:
        path = os.path.join(d, i)
        if os.path.isfile(path) and os.path.getsize(path) > 0:
            got.append("%s/%s" % (rel, i))
        else:
            missing.append("%s: %s" % (what, path))
    return got


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
        kept = [m for m in self.members if m["traj"] is not None]
        if not kept:
            return []
        return wells_of(os.path.join(ROOT, self.sweep["scene"]), self.sweep.get("set", []),
                        plot_family.beta_of(kept[0]["traj"])[2])


def wells_of(path, overrides, gamma):
    """Local minima of V(beta) = 1/2 (c(beta) - cref)^T R (c(beta) - cref) on the curve (4.17) of
    radius GAMMA, for the scene file PATH with the KEY=VALUE OVERRIDES; [] when V is constant."""
    import tomllib
    with open(path, "rb") as fh:
        scene = tomllib.load(fh)
    for kv in overrides:
        k, v = kv.split("=", 1)
        plot_family.apply_key(scene, k, float(v))
    el = scene.get("elastic")
    if not el:
        return []
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
    if x is None:
        return "—"
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


# ------------------------------------------------------- the paper's numbers beside ours
#
# Each function returns the rows (quantity, the paper, ours, difference) of a figure's numbers
# table, from the numbers the paper states in the figure's caption or the text next to it; None
# when the paper gives only a picture; [] when it gives numbers this (shortened) run cannot meet.

NO_NUMBERS = "The paper gives no numbers for this figure; compare by eye."

# The paper's captions, quoted briefly (with what its text next to the figure adds).
PAPER_CAPTION = {
    "4.1": "“Phase portrait of the ODE solved by the function β, introduced in Example 1 … Any "
           "solution β : R → R/2π is time periodic and ranges from −π to π.”",
    "4.2": "“… the y-coordinate of the center of mass of the body with respect to the time for "
           "different initial data. For all of the curves, γ = 0.5 and β0 = 0. The initial "
           "velocity is, from the bottom to the top, β̇0 = 2, 1.55, 1.1, 0.65, 0.2, −0.2, −0.65, "
           "−1.1, −1.55, −2.” (printed axes t ∈ [0, 30], y ∈ [−4, 4], ERRATA E1)",
    "4.3": "“Screenshots of the swimmer (as described in Example 1) over a stroke. Here γ = 0.5 "
           "and the initial data are β0 = 0 and β̇0 = −1.” Frames (a)–(j) at t = 0, 0.9, …, 8.1; "
           "frame (i), t = 7.2, is the reference shape of Fig. 4.7, β = π/3.",
    "4.4": "“Distribution of energy … (Example 1) … the overall energy is constant … The dashed "
           "line corresponds to a time at which the rigid velocity of the swimmer is null.”",
    "4.5": "“… γ = 0.5 and κj = 0.5 … the center of the well of potential is centered at the "
           "point β = 0, β̇ = 0.”",
    "4.6": "“One can observe two wells of potential … κ3 = κ4 = 0.2 and κ5 = κ6 = 2 … So the "
           "wells are centered at the points (0, 0) and (π, 0).”",
    "4.7": "“… reference configuration, that pictured on Subfigure 4.3(i) … corresponds to β = "
           "π/3 and … the well of potential is precisely centered at the point (π/3, 0). All the "
           "trapped solutions result in flapping motion.”",
    "4.8": "“Screenshots of the swimmer of Example 3 at the times t = 3.17, 3.95, 6.07 and 9.50 "
           "corresponding to instants which are relevant to the energy and linear impulse "
           "distribution.”",
    "4.9": "“y-coordinate of the center of mass of the swimmer (Example 3) with respect to time. "
           "In this case, the strokes causing the displacement are time periodic.”",
    "4.10": "“Phase portraits of the components a−1 := ℜ(c−1) and b−2 := ℑ(c−2) for the swimmer "
            "of Example 3 (t ∈ [0, 30]). Both components are time periodic.”",
    "4.11": "“Distribution of energy (in percents) with respect to the time for the swimmer of "
            "Example 3 … The vertical dashed straight lines highlight 4 instants of interest … "
            "detailed on Fig. 4.8.” The text: “The total energy of the system is conserved.”",
    "4.12": "“… the x-component of the linear impulse of the fluid is equal to zero for all "
            "times. The y-linear impulse of the fluid-swimmer system can be decomposed into the "
            "sum of the linear impulse of the fluid … and the impulse of the body.”",
    "4.13": "“Screenshots of the motion of the swimmer (Example 4) over the time interval "
            "[0, 60]. The dashed black line shows the trajectory of the center of mass.”",
    "4.14": "“Phase portraits of the variables a−1, b−1, a−2 and b−2 for the swimmer of "
            "Example 4 (t ∈ [0, 60]). None of them seem to be time periodic.”",
    "4.15": "“Screenshots of the motion of the body described in Example 5 over the time "
            "interval [0, 8] … The shape changes are not time periodic.”",
    "4.16": "“Each peak corresponds to a stroke … the peaks are different … Compared to Example "
            "3, the percentage of the body’s kinetic energy (relating to the rigid displacement) "
            "is smaller.”",
    "4.17": "“y-coordinate of the center of mass of the body (Example 5) with respect to time.”",
    "4.18": "“Screenshots of the motion of the swimmer of Example 6 over the time interval "
            "[0, 6]. The strokes are clearly not periodic.”",
    "4.19": "“Phase portrait of the component c−3 (t ∈ [0, 15]) … Although not excited at the "
            "initial time, this mode gets excited because of the hydrodynamical coupling.”",
    "4.20": "“Time evolution of the distribution of energy (in percentage) for the swimmer of "
            "Example 6. The strokes … correspond to the peaks. They are clearly not time "
            "periodic.” The text: “the distribution of energy during a little more than 2 "
            "strokes.”",
    "4.21": "“y-coordinates of the center of mass of the body (Example 6) with respect to the "
            "time.”",
    "4.22": "“Screenshots of the motion of the swimmer (Example 7) at the times t = 0, 2.5, 5, 7.5 "
            "and 10.” The text: “only three strokes are possible before the total amount of "
            "energy becomes insufficient for the body to swim.”",
    "4.23": "“y-coordinate of the center of mass of the swimmer (Example 7) with respect to the "
            "time.” (The text: three strokes, see Fig. 4.22.)",
    "4.24–4.25": "“|c1(t)|², 4|c−1(t)|² and 9|c−2(t)|²” (Fig. 4.24) and “16|c−3(t)|², … "
                 "64|c−7(t)|² … These modes are not excited at the time t = 0. They get excited "
                 "through W2 and the influence of the fluid which couples all of the modes.” "
                 "(Fig. 4.25)",
    "5.1": "“Screenshots of the motion of the body over the time interval [0, 25] "
           "(self-propelled swimmer).”",
    "5.2": "“y-coordinate of the center of mass of the self-propelled swimmer with respect to the "
           "time.”",
    "5.3": "“Due to the action of the internal forces, the overall energy of the fluid-body "
           "system is not constant any more. The system is at rest at the time t = 0.” §5: “the "
           "energy of the overall system is equal to 0” at rest; (5.3): dE/dt = (F, ċ).",
}


def d(x, digits=3):
    """A signed difference."""
    return (("%+." + str(digits) + "g") % x).replace("-", "−")


def ours_period(r):
    p = strokes(r)
    return p["period"] if p else None


def beta_run(r):
    """beta(t) of a run of the form (4.17), unwrapped."""
    return plot_family.beta_of(r.rows)[0]


def num_fig41_family(f):
    kinds, _, _ = family_numbers(f)
    n = len(f.rows)
    w = f.wells()
    return [("wells of the potential", "none (no elasticity)", "%d" % len(w),
             "same" if not w else "%+d" % len(w)),
            ("solutions that turn β through (−π, π)", "every one", "%d of %d members"
             % (kinds["passing"], n), "same" if kinds["passing"] == n else
             "%d do not" % (n - kinds["passing"]))]


def num_fig41_run(r):
    b = beta_run(r)
    turns = abs(b[-1] - b[0]) / (2 * np.pi)
    return [("solutions that turn β through (−π, π)", "every one",
             "the scene's one: %.2f turns over [0, %s]" % (turns, fmt(r.col("t")[-1])),
             "same" if turns >= 1 else "not a whole turn in this run")]


def num_fig42_family(f):
    pairs = sorted((float(r["y"]), b) for r, b in zip(f.rows, f.betadots()) if r["y"])
    if not pairs:
        return []
    T = max(float(r["t_reached"]) for r in f.rows)
    big = max(abs(y) for y, _ in pairs)
    order = [b for _, b in pairs]
    same = all(order[i] >= order[i + 1] for i in range(len(order) - 1))
    return [("largest |y(%s)| of the ten curves" % fmt(T), "< 4 (inside the printed y-axis "
             "[−4, 4])", fmt(big, 4), "inside, %s below 4" % fmt(4 - big, 3) if big < 4 else
             "outside by %s" % fmt(big - 4, 3)),
            ("β̇₀ of the curves from bottom to top", "2, 1.55, …, −2",
             ("%s, …, %s" % (fmt(order[0], 3), fmt(order[-1], 3))).replace("-", "−"),
             "same order" if same else
             "different order")]


def num_fig42_run(r):
    y = r.col("y")
    big = float(np.abs(y).max())
    return [("largest |y| over [0, %s] (β̇₀ = −1)" % fmt(r.col("t")[-1]),
             "< 4 (inside the printed y-axis [−4, 4])", fmt(big, 4),
             "inside" if big < 4 else "outside by %s" % fmt(big - 4, 3))]


def num_fig43(r):
    rows = []
    p = ours_period(r)
    if p is not None:
        rows.append(("stroke period (frames t = 0 … 8.1, 0.9 apart, span one stroke)",
                     "8.1 … 9.0 (implied)", fmt(p, 6),
                     "inside" if 8.1 <= p <= 9.0 else "outside by %s"
                     % fmt(min(abs(p - 8.1), abs(p - 9.0)), 3)))
    t = r.col("t")
    if t[-1] >= 7.2:
        b = beta_run(r)
        b72 = float(np.interp(7.2, t, b))
        want = np.pi / 3
        gap = float(np.angle(np.exp(1j * (b72 - want))))
        rows.append(("β at t = 7.2 (frame (i)), mod 2π", "π/3 = 1.0472", "%.4f" % (b72 % (2 * np.pi)),
                     d(gap, 3)))
        # the instant nearest 7.2 at which beta = pi/3 (mod 2 pi)
        hits = []
        for k in range(int(np.floor(b.min() / (2 * np.pi))) - 1,
                       int(np.ceil(b.max() / (2 * np.pi))) + 1):
            v = want + 2 * np.pi * k
            s = b - v
            for i in np.nonzero(s[:-1] * s[1:] < 0)[0]:
                hits.append(t[i] + (t[i + 1] - t[i]) * s[i] / (s[i] - s[i + 1]))
        if hits:
            th = min(hits, key=lambda x: abs(x - 7.2))
            rows.append(("time at which the shape is frame (i)'s (β ≡ π/3)", "7.2",
                         "%.4f" % th, d(th - 7.2, 3)))
    return rows


def num_fig44(r):
    z = rigid_rest(r)
    rows = []
    if z and z[0][1] == z[0][1]:
        rows.append(("t†, the dashed line", "not given (drawn only)", fmt(z[0][0], 8), "—"))
        rows.append(("rigid kinetic energy at t†", "0 (rigid velocity null)", fmt(z[0][1], 2),
                     d(z[0][1], 2)))
    drift = r.summary.get("energy_drift_rel", float("nan"))
    rows.append(("total energy, relative change over the run", "0 (constant)", fmt(drift, 2),
                 d(drift, 2)))
    return rows


WELLS_WANT = {"4.5": [("0", 0.0)], "4.6": [("0", 0.0), ("π", np.pi)],
              "4.7": [("π/3 = 1.0472", np.pi / 3)]}


def wells_rows(which, wells):
    rows = []
    wrapped = [np.pi - (np.pi - b) % (2 * np.pi) for b in wells]
    for label, want in WELLS_WANT[which]:
        if not wrapped:
            rows.append(("well at β (β̇ = 0)", label, "none found", "missing"))
            continue
        got = min(wrapped, key=lambda a: abs(np.angle(np.exp(1j * (a - want)))))
        gap = float(np.angle(np.exp(1j * (got - want))))
        rows.append(("well at β (β̇ = 0)", label, "%.6f" % got,
                     "|Δ| ≤ 1e-16" if abs(gap) < 1e-16 else d(gap, 2)))
    extra = len(wrapped) - len(WELLS_WANT[which])
    if extra > 0:
        rows.append(("other wells", "none", "%d" % extra, "%+d" % extra))
    return rows


def num_wells_family(f, which):
    rows = wells_rows(which, f.wells())
    _, dy, _ = family_numbers(f)
    if dy["trapped"]:
        m = float(np.abs(dy["trapped"]).max())
        rows.append(("trapped members: net |Δy| per period (%d members)" % len(dy["trapped"]),
                     "0 (flapping, no locomotion)", fmt(m, 2), d(m, 2)))
    return rows


def num_wells_run(r, which):
    """Without the family: the wells from the scene itself, gamma from the run's first row."""
    g = plot_family.beta_of(r.rows)[2]
    return wells_rows(which, wells_of(scene_path(r.name), [], g))


def num_instants(r):
    rows = []
    for (paper, col, kind), ours in zip(FIG48, r.marks or []):
        rows.append(("%s %s" % (col.replace("_", " "), kind), "%.2f" % paper, "%.4f" % ours,
                     d(ours - paper, 2)))
    return rows


def num_fig411(r):
    rows = num_instants(r)
    drift = r.summary.get("energy_drift_rel", float("nan"))
    rows.append(("total energy, relative change over the run", "0 (conserved)", fmt(drift, 2),
                 d(drift, 2)))
    return rows


def num_fig412(r):
    cols = ["impulse_body_x", "impulse_fluid_rigid_x", "impulse_fluid_shape_x"]
    mx = max(float(np.abs(r.col(c)).max()) for c in cols)
    tot = float(np.abs(r.col("impulse_body_y") + r.col("impulse_fluid_rigid_y")
                       + r.col("impulse_fluid_shape_y")).max())
    return [("x-impulses (body, fluid), largest |·| over the run", "0 for all times",
             fmt(mx, 2), d(mx, 2)),
            ("body + fluid y-impulse, largest |·|", "0 (zero total impulse, (3.20))",
             fmt(tot, 2), d(tot, 2))] + num_instants(r)


def num_fig420(r):
    p = strokes(r)
    if not p:
        return []
    T = float(r.col("t")[-1])
    return [("strokes shown", "a little more than 2 (the plotted interval is not given)",
             "a₋₁ period %s (spread %s): 2 strokes take %s; [0, %s] holds %.2f"
             % (fmt(p["period"], 4), fmt(p["spread"], 2), fmt(2 * p["period"], 3), fmt(T),
                T / p["period"]),
             "not computable without the paper's interval")]


def num_ex7_strokes(r):
    p = strokes(r)
    if not p:
        return []
    t, e = r.col("t"), r.col("energy")
    T = float(t[-1])
    n = T / p["period"]
    return [("strokes before the body stops swimming", "3",
             "%.2f a₋₁ periods in [0, %s] (period %s); still swimming at t = %s: Δy = %s over "
             "the last period, %s %% of E₀ left" % (n, fmt(T), fmt(p["period"], 4), fmt(T),
                                                     fmt(p["dy"], 3), fmt(100 * e[-1] / e[0], 2)),
             "%s, and ours has not stopped at t = %s" % (d(n - 3, 2), fmt(T)))]


def num_fig53(r):
    e, w = r.col("energy"), r.col("work")
    bal = float(np.abs(e - e[0] - w).max())
    return [("E(0), the system at rest", "0", fmt(e[0], 4),
             "%s (the barrier energy W₂ of the disc, W₂(0) = %s, which the paper does not count)"
             % (d(e[0], 3), fmt(r.col("w2")[0], 4))),
            ("E(t) − E(0) − work of F and damping, largest |·| ((5.3))", "0", fmt(bal, 2),
             d(bal, 2))]


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
table.cmp td,table.cmp th{text-align:left;vertical-align:top}table.cmp td:nth-child(4){font-weight:600}
pre{background:#fff;border:1px solid #ddd;padding:.5rem;overflow:auto;font-size:.8rem;max-height:22rem}
pre.cmd{white-space:pre-wrap;word-break:break-all}
nav{font-size:.9rem;line-height:1.7;columns:3}nav a{display:block}
.run{background:#f0f4f8;border:1px solid #cdd;padding:.6rem 1rem;margin:1rem 0}
.paper{background:#fff8e6;border-left:4px solid #e0b040;padding:.4rem .8rem;font-size:.95rem;line-height:1.45}
.nonumbers{font-style:italic}
.note{color:#555;font-size:.9rem}
.grid2{display:grid;grid-template-columns:1fr 1fr;gap:.6rem}
"""


def esc(s):
    return html.escape(str(s))


def numbers_block(rows):
    """The numbers table (the paper beside ours, with the difference), or the statement that the
    paper gives only a picture (None), or that this run does not reach the paper's numbers ([])."""
    if rows is None:
        return '<p class="nonumbers">%s</p>' % NO_NUMBERS
    if not rows:
        return ('<p class="nonumbers">The paper gives numbers for this figure, but this shortened '
                'run does not reach them; compare by eye.</p>')
    return ('<table class="cmp"><tr><th>quantity</th><th>the paper</th><th>ours</th>'
            '<th>difference</th></tr>%s</table>' % "".join(
                "<tr>%s</tr>" % "".join("<td>%s</td>" % esc(c) for c in row) for row in rows))


def key_numbers(r):
    """The run's key numbers, from its summary.json."""
    s = r.summary
    st = s.get("stats", {})
    nan = float("nan")
    fs = s.get("final_state", {}) or {}
    rows = [("status", "%s (%s)" % (s.get("status"), s.get("reason"))),
            ("t reached", fmt(s.get("t_reached", nan), 6)),
            ("integrator, rtol, atol", "%s, %s, %s" % (s.get("integrator"), s.get("rtol"),
                                                      s.get("atol"))),
            ("steps", st.get("steps")), ("RHS evaluations", st.get("rhs_evaluations")),
            ("rejected steps", st.get("rejected_steps")),
            ("time (s)", "%.3f (integration %.3f)" % (st.get("wall_seconds", nan),
                                                     st.get("integrate_seconds", nan))),
            ("final position x, y, θ", "%s, %s, %s" % (fmt(fs.get("x", nan), 6),
                                                       fmt(fs.get("y", nan), 6),
                                                       fmt(fs.get("theta", nan), 4))),
            ("energy E(0)", fmt(s.get("energy_initial", nan), 6)),
            ("energy drift (abs, rel)", "%s, %s" % (fmt(s.get("energy_drift_abs", nan), 2),
                                                   fmt(s.get("energy_drift_rel", nan), 2)))]
    if s.get("forcing_work") is not None:
        rows.append(("work of forcing and damping", fmt(s["forcing_work"], 6)))
    rows.append(("min J (at t)", "%s (t = %s)" % (fmt(s.get("jmin", nan), 4),
                                                  fmt(s.get("jmin_t", nan), 4))))
    for p in s.get("periodic", []) or []:
        if (p.get("column"), p.get("kind")) == STROKE:
            rows.append(("strokes (maxima of a₋₁)", "%d periods, period %s (spacings %s … %s), "
                         "Δy per period %s" % (p["periods"], fmt(p["period"], 6),
                                               fmt(p["period_min"], 6), fmt(p["period_max"], 6),
                                               fmt(p["displacement_per_period"]["y"], 6))))
    sk = s.get("stroke")
    if sk:
        st_ = sk.get("strokes", [])
        rows.append(("prescribed stroke", "period %s (%s), %d stroke%s, c₁ %s" % (
            fmt(sk.get("period", nan), 6), sk.get("period_source"), len(st_),
            "" if len(st_) == 1 else "s",
            "completed from (2.5), (2.14)" if sk.get("completed_c1") else "prescribed")))
        if st_:
            rows.append(("displacement per stroke (Δx, Δy, Δθ)", "; ".join(
                "%s, %s, %s" % (fmt(x["dx"], 6), fmt(x["dy"], 6), fmt(x["dtheta"], 4))
                for x in st_)))
            rows.append(("work per stroke (positive part)", "; ".join(
                "%s (%s)" % (fmt(x["work"], 3), fmt(x["work_positive"], 4)) for x in st_)))
    imp = (s.get("impacts") or {})
    if imp.get("enabled"):
        rows.append(("impacts", imp.get("count")))
    if s.get("stiff_switch"):
        rows.append(("stiff switch", s["stiff_switch"]))
    rows.append(("events", "%d (events.csv)" % len(r.events) if r.events_source else "none asked"))
    return ('<table class="keys">' + "".join("<tr><th>%s</th><td>%s</td></tr>" % (esc(k), esc(v))
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
            '<a href="%s/summary.json">summary.json</a>, <a href="%s/trajectory.csv">trajectory.csv</a>)</h3>%s'
            '<h3>Key numbers (summary.json)</h3>%s'
            '<details><summary>scene file</summary><pre>%s</pre></details></div>' % (
                r.name.replace("/", "-"), esc(title_of(r.name)), r.rel, r.rel, r.rel, video,
                key_numbers(r), esc(scene)))


# the figures a scene's own section shows: for the paper's scenes the overview (their other
# figures are in the figure sections), for the others what `swim plot` draws of them
SCENE_FIGS_PAPER = ["snapshots.png"]
SCENE_FIGS_OTHER = ["trajectory.png", "stroke.png", "energy.png", "snapshots.png"]


def scene_section(r, figs_of_scene):
    title, about = scene_header(r.name)
    out = ['<section id="%s" class="scene"><h2>Scene models/%s.toml — %s</h2>' % (
        section_id(r.name), esc(r.name), esc(title_of(r.name)))]
    out.append('<p><b>What it is:</b> %s%s</p>' % (
        esc(title) + ". " if title_of(r.name) != title else "", esc(about)))
    if figs_of_scene:
        out.append('<p>The paper\'s figures from this scene: %s.</p>' % ", ".join(
            '<a href="#fig%s">Fig. %s</a>' % (f.replace("–", "-"), f) for f in figs_of_scene))
    else:
        out.append('<p class="note">Not one of the paper\'s figures: no paper numbers to compare; '
                   'its own numbers below.</p>')
    want = SCENE_FIGS_PAPER if figs_of_scene else SCENE_FIGS_OTHER
    imgs = [i for i in want if i in getattr(r, "figures", []) or
            os.path.exists(os.path.join(r.dir, i))]
    for i in imgs:
        out.append('<figure><img src="%s/%s" alt="%s: %s" loading="lazy"></figure>' % (
            r.rel, i, esc(r.name), i))
    out.append(run_block(r))
    out.append('</section>')
    return "\n".join(out)


def hard_section():
    rows = []
    for name in scenes_in("hard"):
        title, _ = scene_header(name)
        rows.append('<tr id="%s"><td>models/%s.toml</td><td>%s</td></tr>' % (
            section_id(name), esc(name), esc(title)))
    if not rows:
        return ""
    return ('<section id="scenes-hard"><h2>Scenes of models/hard/ — listed, not run</h2>'
            '<p>The page runs every scene of models/ and models/control/. The %d scenes of '
            'models/hard/ are the integrators\' stress tests, not the paper\'s: runs to T = 1000, '
            'N = 20 kernels, barrier bounces, stiff modes, minutes each. <code>make bench-hard</code> '
            'runs them at their own settings and at rtol 1e-10 (build/bench/hard/table.md, see '
            'docs/accuracy.md).</p><table><tr><th>scene</th><th>what it stresses</th></tr>%s'
            '</table></section>' % (len(rows), "".join(rows)))


def work_precision_section(out, opts, runs):
    """The work-precision figure from the current build (tools/paper/work_precision.py), or None."""
    if opts["work-precision"] == "none":
        return None, {}
    import work_precision
    scenes = [n for n in opts["scenes"] if n in PAPER_SCENES] or PAPER_SCENES
    wdir = os.path.join(out, "work_precision")
    try:
        info = work_precision.make(wdir, scenes, SWIM, PYTHON, opts["work-precision"])
    except Exception as e:  # noqa: BLE001 - the page is still made, and says why
        log("work-precision failed: %s" % e)
        return ('<section id="work-precision"><h2>Work-precision per scene</h2><p class="note">'
                'Not made: %s</p></section>' % esc(str(e)[-400:])), {}
    table = None
    if info.get("table"):
        table = os.path.join(wdir, "table.md")
        if os.path.abspath(info["table"]) != os.path.abspath(table):
            shutil.copy(info["table"], table)
    if info["source"] == "quick":
        how = ("a quick measurement made for this page, with the swim the page is built with "
               "(tests/bench/bench_accuracy.py --quick on the %d paper scene%s on the page: rtol "
               "1e-4, 1e-7, 1e-10 per integrator, atol = rtol·1e-2, one repetition, errors against "
               "the abm reference at rtol 1e-13; %.0f s). One repetition on a shared machine: read CPU "
               "differences below ~30 %% as ties (the RHS evaluations, in accuracy.csv, are exact). "
               "<code>make bench-accuracy</code> (~9 "
               "min, rtol 1e-3 … 1e-13, 5 repetitions) makes the full table; when its "
               "build/bench/accuracy/accuracy.csv is newer than the binary, the page draws that "
               "instead." % (len(scenes), "" if len(scenes) == 1 else "s",
                             info["measure_seconds"]))
    else:
        how = ("the latest table of <code>make bench-accuracy</code> (%s), newer than the "
               "binary." % esc(os.path.relpath(info["csv"], ROOT)))
    sec = ('<section id="work-precision"><h2>Work-precision per scene</h2><figure>'
           '<img src="work_precision/work_precision.png" alt="work-precision diagrams" '
           'loading="lazy"><figcaption>Max error over the output grid (T = min(t_end, 10), '
           'T/100 apart) against CPU time inside the integrator, per integrator and tolerance; '
           'dotted: the reference\'s own uncertainty (abm against rk8pd at 1e-13). From %s '
           'Drawn %d panels, three a row, for this page\'s width.%s</figcaption></figure>'
           '</section>' % (how, info["panels"],
                           ' Table: <a href="work_precision/table.md">table.md</a>, '
                           '<a href="work_precision/accuracy.csv">accuracy.csv</a>.'
                           if table and os.path.exists(os.path.join(wdir, "accuracy.csv"))
                           else ""))
    if info["source"] != "quick":
        shutil.copy(info["csv"], os.path.join(wdir, "accuracy.csv"))
    return sec, info


def main(argv):
    opts = parse_args(argv)
    out = opts["out"]
    clock = time.time()
    phase = {}
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    with_events = run_help_lists_event()
    log("swim run %s --event; building %s" % ("takes" if with_events else "does not take", out))
    runs = {}
    t0 = time.time()
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
    phase["scenes (runs, figures, animations)"] = time.time() - t0

    t0 = time.time()
    fams = {}
    for fig, target, dirname, image, scene in FAMILIES:
        if target in opts["families"]:
            f = Family(fig, target, dirname, image, scene, out)
            if f.make():
                fams[fig] = f
                log("%s: %d members, make %s %.1f s" % (dirname, len(f.rows), target, f.seconds))
    phase["families"] = time.time() - t0
    t0 = time.time()

    # each: dict(fig, title, scene, imgs, caption, fam, numbers)
    sections = []
    # figure sections whose promised image was not made: the page is still written (nothing
    # lost), but the build fails naming them
    missing = []

    def present(d, rel, names, fig):
        return promised_images(d, rel, names, "Fig. %s" % fig, missing)

    def add(fig, title, scene, images, caption, numbers=None):
        if scene in runs:
            r = runs[scene]
            imgs = present(r.dir, r.rel, images, fig)
            sections.append(dict(fig=fig, title=title, scene=scene, imgs=imgs,
                                 caption=caption(r), fam=None,
                                 numbers=numbers(r) if numbers else None))

    def add_family(fig, title, run_images, caption, numbers):
        """Fig. FIG from its family when the sweep was made, with the scene run's RUN_IMAGES
        after it; otherwise False."""
        f = fams.get(fig)
        if f is None:
            return False
        r = runs.get(f.scene)
        imgs = present(f.dir, f.rel, [f.image], fig)
        if r is not None:
            imgs += present(r.dir, r.rel, run_images, fig)
        sections.append(dict(fig=fig, title=title, scene=f.scene, imgs=imgs,
                             caption=caption(f, r), fam=f, numbers=numbers(f)))
        return True

    if not add_family("4.1", "Phase portrait of β (Example 1, a family)", [],
                      lambda f, r: cap_family41(f), num_fig41_family):
        add("4.1", "Phase portrait of β (Example 1)", "example1", ["phase.png"], cap_fig41,
            num_fig41_run)
    if not add_family("4.2", "y(t) for ten initial velocities (Example 1, a family)", [],
                      cap_family42, num_fig42_family):
        add("4.2", "y(t) of the centre of mass (Example 1)", "example1", ["trajectory.png"],
            cap_fig42, num_fig42_run)
    if "example1" in runs:
        runs["example1"].fig43 = runs["example1"].panels(
            "fig4_3", [0.9 * k for k in range(10)], "one stroke (Fig. 4.3 times)")
    add("4.3", "Screenshots over a stroke (Example 1)", "example1", ["fig4_3.png"], cap_fig43,
        num_fig43)
    add("4.4", "Distribution of energy (Example 1)", "example1", ["energy.png"], cap_fig44,
        num_fig44)
    for fig, scene, title in (("4.5", "example2a", "Phase portrait, one well (Example 2)"),
                              ("4.6", "example2b", "Phase portrait, two wells (Example 2)"),
                              ("4.7", "example2c", "Phase portrait, well at π/3 (Example 2)")):
        if not add_family(fig, title + ", a family", ["trajectory.png"],
                          lambda f, r, fig=fig: cap_family_wells(f, fig, r),
                          lambda f, fig=fig: num_wells_family(f, fig)):
            add(fig, title, scene, ["phase.png", "trajectory.png"],
                lambda r, fig=fig: cap_fig45(r, fig), lambda r, fig=fig: num_wells_run(r, fig))
    if "example3" in runs and runs["example3"].marks:
        add("4.8", "Four instants of Example 3", "example3", ["instants.png"],
            lambda r: cap_fig48(r, r.marks), num_instants)
    add("4.9", "y(t) (Example 3)", "example3", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: periodic strokes, a net displacement along y."))
    add("4.10", "Phase curves (Re c, Re ċ, t) (Example 3)", "example3", ["phase3d.png"],
        lambda r: cap_phase3d(r, "The paper: the curves of a₋₁ and b₋₂ in (c, ċ, t) repeat — "
                                 "periodic components.", ["am1", "bm2"]))
    add("4.11", "Distribution of energy in percent (Example 3)", "example3", ["energy.png"],
        lambda r: cap_energy(r, "The paper stacks fluid, deformation, rigid-motion kinetic and "
                                "potential energy in percent, with the four instants of Fig. 4.8 "
                                "dashed."),
        lambda r: num_fig411(r) if r.marks else [])
    add("4.12", "Linear impulses (Example 3)", "example3", ["impulse.png"], cap_impulse,
        num_fig412)
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
                                "not periodic."), num_fig420)
    add("4.21", "y(t) (Example 6)", "example6", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: locomotion along y."))
    if "example7" in runs:
        runs["example7"].panels("fig4_22", [0, 2.5, 5, 7.5, 10], "Fig. 4.22 times")
    add("4.22", "Screenshots (Example 7)", "example7", ["fig4_22.png"], cap_fig422,
        num_ex7_strokes)
    add("4.23", "y(t) (Example 7)", "example7", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: about three strokes, then the damped body stops "
                              "swimming."), num_ex7_strokes)
    add("4.24–4.25", "Mode amplitudes (Example 7)", "example7", ["modes.png"], cap_modes)
    if "selfpropelled" in runs:
        runs["selfpropelled"].panels("fig5_1", [25.0 * k / 15 for k in range(16)],
                                     "Fig. 5.1 times")
    add("5.1", "Screenshots of the self-propelled ball", "selfpropelled", ["fig5_1.png"], cap_fig51)
    add("5.2", "y(t) (self-propelled)", "selfpropelled", ["trajectory.png"],
        lambda r: cap_traj(r, "The paper: the ball starts at rest and swims along y."))
    add("5.3", "Distribution of energy (self-propelled)", "selfpropelled", ["energy.png"],
        cap_fig53, num_fig53)
    phase["figure sections (screenshot panels, numbers)"] = time.time() - t0

    t0 = time.time()
    wp_sec, wp_info = work_precision_section(out, opts, runs)
    phase["work-precision"] = time.time() - t0

    figs_of = {}
    for s in sections:
        figs_of.setdefault(s["scene"], []).append(s["fig"])
    reduced = sorted(opts["scenes"]) != sorted(SCENES)
    n_tables = sum(1 for s in sections if s["numbers"])
    body = ['<h1>Passive and self-propelled locomotion of an elastic swimmer — the figures '
            'reproduced by swim</h1>',
            '<p>Part 1: each section is one figure of sections 4–5 of Munnier\'s paper: the '
            'paper\'s caption (quoted briefly), our figure and what it shows, then the numbers '
            'the paper states in the caption or the text next to the figure beside ours, with '
            'the difference — or, where the paper gives only a picture, a plain statement that '
            'it gives no numbers (%d of %d figure sections have a numbers table). '
            'Part 2: every scene of models/ and models/control/ (%d runs%s): what it is, our '
            'figures, the animation (body coloured by density ρ₀/J, fluid velocity, path of the '
            'centre of mass, energy with a time cursor), the scene file and the key numbers of '
            'its summary.json; the scenes of models/hard/ are listed, not run. Part 3: the '
            'work-precision figure, made from this build. %sMarked instants come from %s.</p>' % (
                n_tables, len(sections), len(runs),
                ", a reduced page: %s" % ", ".join(opts["scenes"]) if reduced else "",
                ("Figs %s are families of runs, each one <code>swim sweep</code> (the make "
                 "target named in its section) drawn by <code>swim plot</code>; their sections "
                 "carry the sweep's definition and summary. " % ", ".join(sorted(fams)))
                if fams else "",
                "the runs' events.csv (swim run --event)" if with_events else
                "the output rows (this swim run has no --event; extremes by parabolic "
                "interpolation between rows)"),
            '<h3>The paper\'s figures</h3><nav>' + "".join('<a href="#fig%s">Fig. %s — %s</a>' % (
                s["fig"].replace("–", "-"), s["fig"], esc(s["title"])) for s in sections) +
            '</nav><h3>The scenes</h3><nav>' + "".join(
                '<a href="#%s">models/%s.toml</a>' % (section_id(n), esc(n)) for n in runs) +
            ('<a href="#scenes-hard">models/hard/ (listed)</a>' if scenes_in("hard") else "") +
            ('<a href="#work-precision">Work-precision per scene</a>' if wp_sec else "") + '</nav>']
    for s in sections:
        fig, fam, imgs = s["fig"], s["fam"], s["imgs"]
        body.append('<section id="fig%s" class="paperfig"><h2>Fig. %s — %s</h2>' % (
            fig.replace("–", "-"), fig, esc(s["title"])))
        body.append('<p class="paper"><b>The paper, Fig. %s:</b> %s</p>' % (
            fig, esc(PAPER_CAPTION.get(fig, ""))))
        # a family: its figure, the caption and the sweep, then the scene's own run
        first = imgs[:1] if fam is not None else imgs
        for i in first:
            body.append('<figure><img src="%s" alt="Fig. %s, ours: %s" loading="lazy">'
                        '</figure>' % (i, fig, esc(os.path.basename(i))))
        body.append('<figcaption><b>Ours:</b> %s</figcaption>' % esc(s["caption"]))
        if fam is not None:
            body.append(sweep_block(fam))
            for i in imgs[1:]:
                body.append('<figure><img src="%s" alt="the scene\'s own run: %s" '
                            'loading="lazy"></figure>' % (i, esc(os.path.basename(i))))
        body.append('<h3>Numbers: the paper and ours</h3>' + numbers_block(s["numbers"]))
        if s["scene"] in runs:
            body.append('<p class="note">Run: <a href="#%s">models/%s.toml</a> (animation, '
                        'scene file, key numbers).</p>' % (section_id(s["scene"]),
                                                           esc(s["scene"])))
        body.append('</section>')
    body.append('<h2 id="scenes">The scenes of models/</h2>')
    for name, r in runs.items():
        body.append(scene_section(r, figs_of.get(name, [])))
    body.append(hard_section())
    if wp_sec:
        body.append(wp_sec)
    total = time.time() - clock
    body.append('<p class="note">Built by tools/paper/build_paper.py in %.0f s (%s; per scene: '
                '%s).</p>' % (total, ", ".join("%s %.0f s" % kv for kv in phase.items()),
                              ", ".join(["%s %.0f s" % (n, sum(r.timings.values()))
                                         for n, r in runs.items()] +
                                        ["make %s %.0f s" % (f.target, f.seconds)
                                         for f in fams.values()])))
    page = ('<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            '<meta name="swim-page" content="%s">'
            '<meta name="swim-scenes" content="%s">'
            '<title>swim — the paper\'s figures reproduced</title><style>%s</style></head>'
            '<body><main>%s</main></body></html>\n' % (
                "reduced" if reduced else "full", ",".join(runs), CSS, "\n".join(body)))
    with open(os.path.join(out, "index.html"), "w") as fh:
        fh.write(page)
    log("wrote %s (%d figure sections, %d scene sections) in %.1f s (%s)" % (
        os.path.join(out, "index.html"), len(sections), len(runs), total,
        ", ".join("%s %.1f s" % kv for kv in phase.items())))
    print(os.path.join(out, "index.html"))
    if missing:
        log("error: %d promised figure(s) not made: %s" % (len(missing), "; ".join(missing)))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
