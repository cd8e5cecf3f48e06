#!/usr/bin/env python3
"""Figures of one `swim sweep` directory (run by `swim plot DIR` when DIR holds sweep.json).

Usage: plot_family.py DIR [--swim BIN] [--title TEXT]

Writes into DIR, printing each path written:

  family.png   with kept trajectories (--keep trajectories): y(t) of every member, labelled by
               its varied values, or by beta'(0) when the members follow the reduction (4.17)
               (paper Fig. 4.2); without trajectories: the members.csv columns final y, min J and
               RHS evaluations against the first varied key.
  phase.png    when the kept trajectories follow the reduction (4.17) -- c = (1, 0, g cos b, 0, 0,
               g sin b / sqrt 2, 0, ...), b_-1 = a_-2 = 0 -- the phase portrait in the plane
               (beta, beta') with beta = atan2(sqrt 2 b_-2, a_-1) (paper Figs 4.1, 4.5-4.7):
               the vector field (beta', beta'') as arrows and the level sets of the energy, both
               computed from the model (below), the members' computed trajectories on top,
               trapped (flapping) solutions and passing (swimming) ones drawn differently; second
               panel: the net displacement per period of each member against its energy.

The reduced one-degree-of-freedom model. On the curve c(beta), v = dc/dbeta is tangent to the
volume constraint and zero on the locked coordinates, so projecting K c'' + <Gamma, c', c'> =
-grad W onto v removes every constraint force and leaves
    m(beta) beta'' + k(beta) beta'^2 = -V'(beta),
with m = v^T K v, k = v^T K v_beta + v^T <Gamma, v, v> (= m'/2) and V = W1(c(beta)). K and
<Gamma, v, v> come from the generated kernels through `swim inspect`; W1 = 1/2 (c - cref)^T R
(c - cref) (ERRATA E2) from the scene. The energy is E = m beta'^2 / 2 + V. The script checks
k against m'/2 by differences and prints the largest mismatch.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tomllib

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 110
SQ2 = math.sqrt(2.0)
GRID = 48   # points of the reduced model on [-pi, pi): smooth and 2 pi-periodic, so interpolated spectrally


class Trig:
    """Trigonometric interpolant of samples f(-pi + 2 pi j / n), j = 0..n-1 (spectral accuracy for
    the smooth periodic functions of the reduction), with its derivative."""

    def __init__(self, samples):
        n = len(samples)
        self.n = n
        self.c = np.fft.fft(samples) / n
        self.k = np.fft.fftfreq(n, 1.0 / n)
        if n % 2 == 0:          # split the Nyquist term so the interpolant is real
            self.c[n // 2] *= 0.5
            self.c = np.append(self.c, self.c[n // 2])
            self.k = np.append(self.k, -self.k[n // 2])

    def __call__(self, x, d=0):
        x = np.asarray(x, float)
        ph = np.exp(1j * np.multiply.outer(x + math.pi, self.k))
        return np.real(ph @ (self.c * (1j * self.k) ** d))

    def derivative(self, x):
        return self(x, 1)


def warn(msg):
    print("plot_family: " + msg, file=sys.stderr)


# ---------------------------------------------------------------- input

def read_csv(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


def read_trajectory(path):
    with open(path) as fh:
        head = fh.readline().strip().split(",")
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    data = np.atleast_2d(data)
    return {name: data[:, i] for i, name in enumerate(head)}


def coord_index(name):
    if name in ("a1", "b1"):
        return 0 if name == "a1" else 1
    return 2 * int(name[2:]) + (name[0] == "b")


def apply_key(scene, key, value):
    """An override KEY=VALUE (swim's --set syntax) on the parsed scene."""
    table, rest = key.split(".", 1)
    if "[" in rest:
        k, idx = rest[:-1].split("[")
        scene[table][k][int(idx)] = value
    elif "." in rest:
        k, name = rest.split(".")
        scene[table][k][coord_index(name)] = value
    else:
        scene[table][rest] = value


def load_sweep(d):
    with open(os.path.join(d, "sweep.json")) as fh:
        sweep = json.load(fh)
    rows = sorted(read_csv(os.path.join(d, "members.csv")), key=lambda r: int(r["id"]))
    members = []
    for r in rows:
        m = {"id": int(r["id"]), "row": r, "traj": None}
        tp = os.path.join(d, "members", "%05d" % m["id"], "trajectory.csv")
        if os.path.exists(tp) and os.path.getsize(tp) > 0:
            try:
                m["traj"] = read_trajectory(tp)
            except ValueError as exc:
                warn("%s: %s" % (tp, exc))
        members.append(m)
    return sweep, members


# ------------------------------------------------------ reduction (4.17)

def follows_reduction(tr):
    need = ("am1", "bm1", "am2", "bm2", "dam1", "dbm2", "a1", "b1")
    if tr is None or any(k not in tr for k in need):
        return False
    others = [k for k in tr if (k.startswith("am") or k.startswith("bm")) and k not in ("am1", "bm2")]
    small = all(np.nanmax(np.abs(tr[k])) < 1e-9 for k in others)
    return small and np.allclose(tr["a1"], 1.0) and np.allclose(tr["b1"], 0.0)


def beta_of(tr):
    """beta, beta' and gamma along a trajectory of the form (4.17)."""
    a, b, da, db = tr["am1"], tr["bm2"], tr["dam1"], tr["dbm2"]
    g2 = a * a + 2.0 * b * b
    beta = np.unwrap(np.arctan2(SQ2 * b, a))
    dbeta = SQ2 * (db * a - da * b) / g2
    return beta, dbeta, math.sqrt(float(g2[0]))


def curve(gamma, beta, n):
    c = np.zeros(n)
    c[0] = 1.0
    c[2] = gamma * math.cos(beta)
    c[5] = gamma * math.sin(beta) / SQ2
    v = np.zeros(n)
    v[2] = -gamma * math.sin(beta)
    v[5] = gamma * math.cos(beta) / SQ2
    vb = np.zeros(n)   # dv/dbeta
    vb[2] = -gamma * math.cos(beta)
    vb[5] = -gamma * math.sin(beta) / SQ2
    return c, v, vb


def reduced_model(swim, scene, gamma, betas):
    """m, k, V, V' on the grid betas, from the kernels (swim inspect) and the scene's W1."""
    modes = scene["model"]["modes"]
    n = 2 * (modes + 1)
    rho0 = scene["model"]["rho0"]
    rhof = scene["model"]["rhof"]
    el = scene.get("elastic")
    R = np.array(el["stiffness"], float) if el else np.zeros(n)
    cref = np.array(el["reference"], float) if el else np.zeros(n)
    m, k, V, dV = (np.zeros(len(betas)) for _ in range(4))
    for i, b in enumerate(betas):
        c, v, vb = curve(gamma, b, n)
        out = subprocess.run([swim, "inspect", "--modes", str(modes), "--rho0", repr(float(rho0)),
                              "--rhof", repr(float(rhof)), "--shape", ",".join(repr(x) for x in c),
                              "--velocity", ",".join(repr(x) for x in v)],
                             capture_output=True, text=True, check=True).stdout
        j = json.loads(out)
        K = np.array(j["mass_reduced"], float)
        G = np.array(j["christoffel_vv"], float)
        m[i] = v @ K @ v
        k[i] = v @ K @ vb + v @ G
        V[i] = 0.5 * (c - cref) @ (R * (c - cref))
        dV[i] = v @ (R * (c - cref))
    return m, k, V, dV


# ------------------------------------------------------------- analysis

def classify(beta, dbeta):
    """'passing' (beta turned by 2 pi: a stroke that swims), 'trapped' (beta' changed sign and
    beta stayed within a well: flapping) or 'open' (neither within the run)."""
    if np.nanmax(beta) - np.nanmin(beta) >= 2 * math.pi:
        return "passing"
    if np.any(dbeta > 0) and np.any(dbeta < 0):
        return "trapped"
    return "open"


def crossing_times(t, f, level, direction):
    """Times where f crosses level in the given direction (+1 upward, -1 downward), interpolated."""
    g = (f - level) * direction
    i = np.nonzero((g[:-1] < 0) & (g[1:] >= 0))[0]
    return t[i] + (t[i + 1] - t[i]) * (-g[i]) / (g[i + 1] - g[i])


def per_period(tr, beta, dbeta, kind):
    """(period, net displacement along y, along x) over the first whole period, or None."""
    t = tr["t"]
    if kind == "passing":
        s = 1.0 if beta[-1] > beta[0] else -1.0
        tc = crossing_times(t, s * (beta - beta[0]), 2 * math.pi, 1)
        if len(tc) == 0:
            return None
        t0, t1 = 0.0, tc[0]
    elif kind == "trapped":
        tc = crossing_times(t, dbeta, 0.0, -1)   # beta' from + to -: one per period
        if len(tc) < 2:
            return None
        t0, t1 = tc[0], tc[1]
    else:
        return None
    y0, y1 = np.interp([t0, t1], t, tr["y"])
    x0, x1 = np.interp([t0, t1], t, tr["x"])
    return t1 - t0, y1 - y0, x1 - x0


DIMLESS = "dimensionless, paper's scaling"   # the paper's units: the reference body is the unit disc
LENGTH = "reference-disc radii"


def coord_label(name, dot=False):
    """'am2' -> $a_{-2}$, dot: $\\dot a_{-2}$ (math text)."""
    letter, idx = name[0], name[1:]
    if idx.startswith("m"):
        idx = "-" + idx[1:]
    return r"$%s_{%s}$" % ((r"\dot " if dot else "") + letter, idx)


def key_label(key):
    """A varied scene key for a label: shape.c0.am1 -> 'initial $a_{-1}$', shape.dc0.bm2 ->
    'initial $\\dot b_{-2}$'; any other key as swim's --vary spells it."""
    parts = key.split(".")
    if len(parts) == 3 and parts[0] == "shape" and parts[1] in ("c0", "dc0") and parts[2][:1] in "ab":
        return "initial " + coord_label(parts[2], dot=parts[1] == "dc0")
    return key


def label(sweep, row):
    return ", ".join("%s = %.4g" % (key_label(v["key"]), float(row[v["key"]])) for v in sweep["vary"])


# --------------------------------------------------------------- figures

def pi_third(k):
    """Tick label of k pi/3 in math text: 0, $\\pi/3$, $-2\\pi/3$, $\\pi$, ..."""
    if k == 0:
        return "0"
    num, den = (k // 3, "") if k % 3 == 0 else (k, "/3")
    sign = "-" if num < 0 else ""
    num = abs(num)
    return r"$%s%s\pi%s$" % (sign, "" if num == 1 else str(num), den)


def finish(fig, path, collect):
    """Saves fig to path (printing the path), or with collect (a list) appends (name, fig) to it
    unsaved: how tests/test_figure_text.py gets the Figures `swim plot` would save."""
    if collect is not None:
        collect.append((os.path.basename(path)[:-4], fig))
        return
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print(path)


def plot_family(d, sweep, members, title, collect=None):
    path = os.path.join(d, "family.png")
    kept = [m for m in members if m["traj"] is not None]
    fig, ax = plt.subplots(figsize=(9.5, 5.5), layout="constrained")
    if kept:
        reduction = all(follows_reduction(m["traj"]) for m in kept)
        cmap = plt.get_cmap("coolwarm")
        vals = []
        for m in kept:
            if reduction:
                beta, dbeta, g = beta_of(m["traj"])
                vals.append(dbeta[0])
            else:
                vals.append(float(m["row"][sweep["vary"][0]["key"]]))
        lo, hi = min(vals), max(vals)
        for m, val in sorted(zip(kept, vals), key=lambda p: -p[1]):
            tr = m["traj"]
            lab = (r"$\dot\beta(0)$ = %.3g" % val) if reduction else label(sweep, m["row"])
            if m["row"]["status"] != "completed":
                lab += " (%s)" % m["row"]["status"]
            col = cmap(0.5 if hi == lo else (val - lo) / (hi - lo))
            ax.plot(tr["t"], tr["y"], color=col, lw=1.4, label=lab)
        ax.set_xlabel("time $t$ (%s)" % DIMLESS)
        ax.set_ylabel("$y$ of the centre of mass (%s)" % LENGTH)
        if len(kept) <= 14:
            ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
        # the colour scale of the members (under the axes, the legend takes the right)
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(lo, hi if hi > lo else lo + 1.0))
        fig.colorbar(sm, ax=ax, location="bottom", shrink=0.6, aspect=40, pad=0.02,
                     label=(r"$\dot\beta(0)$ (rad per unit time, paper's scaling)" if reduction
                            else "%s (%s)" % (key_label(sweep["vary"][0]["key"]), DIMLESS)))
        ax.set_title(title or "%s: $y(t)$ of %d members" % (sweep["scene"], len(kept)))
        ax.grid(alpha=0.3)
    else:
        key = sweep["vary"][0]["key"]
        x = [float(m["row"][key]) for m in members]
        y = [float(m["row"]["y"]) if m["row"]["y"] else math.nan for m in members]
        ok = [m["row"]["status"] == "completed" for m in members]
        ax.plot([a for a, o in zip(x, ok) if o], [b for b, o in zip(y, ok) if o], "o-", ms=3, label="completed")
        bad = [(a, b) for a, b, o in zip(x, y, ok) if not o]
        if bad:
            ax.plot(*zip(*bad), "rx", label="failed")
        # the time the final y is taken at (members.csv t_reached): one t, or the range
        reached = sorted({float(m["row"]["t_reached"]) for m in members
                          if m["row"].get("t_reached") not in (None, "")})
        at = ("at $t$ = %.6g" % reached[0] if len(reached) == 1 else
              "at each member's last $t$ (%.6g to %.6g)" % (reached[0], reached[-1]) if reached else
              "at each member's last $t$")
        ax.set_xlabel("%s (%s)" % (key_label(key), DIMLESS))
        ax.set_ylabel("final $y$ of the centre of mass\n%s (%s)" % (at, LENGTH))
        if bad:
            ax.legend()
        ax.set_title(title or "%s: final $y$ of %d members, %s" % (sweep["scene"], len(members), at))
        ax.grid(alpha=0.3)
    finish(fig, path, collect)


def plot_phase(d, sweep, members, swim, title, collect=None):
    kept = [m for m in members if m["traj"] is not None and m["row"]["status"] == "completed"]
    if not kept or not all(follows_reduction(m["traj"]) for m in kept):
        return False
    with open(sweep["scene"], "rb") as fh:
        scene = tomllib.load(fh)
    for s in sweep["set"]:
        k, v = s.split("=")
        apply_key(scene, k, float(v))
    if any(v["key"].split(".")[0] in ("elastic", "model") for v in sweep["vary"]):
        warn("phase.png: the members differ in their model (a varied elastic/model key): no single portrait")
        return False
    curves = [beta_of(m["traj"]) for m in kept]
    gammas = [g for _, _, g in curves]
    gamma = float(np.median(gammas))
    if max(abs(g - gamma) for g in gammas) > 1e-6:
        warn("phase.png: the members have different gamma (%.4g..%.4g); the field is drawn for %.4g"
             % (min(gammas), max(gammas), gamma))
    grid = -math.pi + 2 * math.pi * np.arange(GRID) / GRID
    m, k, V, dV = reduced_model(swim, scene, gamma, grid)
    fm, fk, fV, fdV = (Trig(f) for f in (m, k, V, dV))
    fine = np.linspace(-math.pi, math.pi, 1001)
    mismatch = float(np.max(np.abs(fk(fine) - 0.5 * fm.derivative(fine))) / np.max(np.abs(fk(fine))))
    print("plot_family: reduced model of (4.17): m in [%.4g, %.4g], V in [%.4g, %.4g]; "
          "k = m'/2 to %.1e (relative; m' by trigonometric interpolation on %d points)"
          % (m.min(), m.max(), V.min(), V.max(), mismatch, GRID))
    # window: [w, w + 2 pi] with w the top of the potential, put in (-pi, 0] (the wells inside)
    w = -math.pi
    if V.max() - V.min() > 1e-12:
        w = float(grid[np.argmax(V[:-1])])
        w = (w + math.pi) % (2 * math.pi) - math.pi
        if w > 0:
            w -= 2 * math.pi
        if w <= -math.pi + 1e-9:
            w = -math.pi

    def wrap(b):
        return (b - w) % (2 * math.pi) + w

    def model_at(b):
        return [f(np.asarray(b, float)) for f in (fm, fk, fV, fdV)]

    dmax = max(float(np.nanmax(np.abs(db))) for _, db, _ in curves) * 1.15
    B, D = np.meshgrid(np.linspace(w, w + 2 * math.pi, 241), np.linspace(-dmax, dmax, 201))
    mm, kk, VV, dVV = model_at(B)
    E = 0.5 * mm * D ** 2 + VV
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(14, 5.8), gridspec_kw={"width_ratios": [1.6, 1]})
    levels = np.quantile(E, np.linspace(0.02, 0.9, 18))
    ax.contour(B, D, E, levels=levels, colors="0.75", linewidths=0.7)
    Bq, Dq = np.meshgrid(np.linspace(w, w + 2 * math.pi, 25), np.linspace(-dmax, dmax, 17))
    mq, kq, Vq, dVq = model_at(Bq)
    acc = -(kq * Dq ** 2 + dVq) / mq
    norm = np.hypot(Dq / dmax, acc / (np.abs(acc).max() + 1e-300)) + 1e-12
    ax.quiver(Bq, Dq, Dq / dmax / norm, acc / (np.abs(acc).max() + 1e-300) / norm, color="0.45",
              angles="xy", scale=40, width=0.0022)
    styles = {"passing": dict(color="tab:blue", lw=1.3), "trapped": dict(color="tab:red", lw=1.3),
              "open": dict(color="tab:gray", lw=1.0, ls="--")}
    counts = {"passing": 0, "trapped": 0, "open": 0}
    results = []
    for mem, (beta, dbeta, g) in zip(kept, curves):
        kind = classify(beta, dbeta)
        counts[kind] += 1
        b = wrap(beta)
        jump = np.nonzero(np.abs(np.diff(b)) > math.pi)[0] + 1
        for seg_b, seg_d in zip(np.split(b, jump), np.split(dbeta, jump)):
            ax.plot(seg_b, seg_d, **styles[kind])
        mb, kb, Vb, dVb = model_at(beta[0])
        e = 0.5 * mb * dbeta[0] ** 2 + Vb
        results.append((kind, e, per_period(mem["traj"], beta, dbeta, kind), dbeta[0]))
    for kind in styles:
        if counts[kind]:
            ax.plot([], [], label="%s (%d)" % ({"passing": "passing: swims", "trapped": "trapped: flaps",
                                                  "open": "no whole period in the run"}[kind], counts[kind]),
                    **styles[kind])
    ax.set_xlim(w, w + 2 * math.pi)
    ax.set_ylim(-dmax, dmax)
    ax.set_xlabel(r"$\beta = \mathrm{atan2}(\sqrt{2}\,b_{-2},\ a_{-1})$ (rad)")
    ax.set_ylabel(r"$\dot\beta$ (rad per unit time, paper's scaling)")
    ticks = np.arange(math.ceil(w / (math.pi / 3) - 1e-9), math.floor((w + 2 * math.pi) / (math.pi / 3) + 1e-9) + 1)
    ax.set_xticks(ticks * math.pi / 3)
    ax.set_xticklabels([pi_third(t) for t in ticks.astype(int)])
    ax.set_title(title or r"phase portrait of $\beta$, %s ($\gamma$ = %.3g)" % (os.path.basename(sweep["scene"]), gamma))
    for kind, mk in (("passing", "o"), ("trapped", "s")):
        pts = [(e, r[1]) for k_, e, r, _ in results if k_ == kind and r is not None]
        if pts:
            ax2.plot(*zip(*sorted(pts)), mk, color=styles[kind]["color"], label=kind)
    ax2.axhline(0, color="0.6", lw=0.8)
    ax2.set_xlabel(r"energy $E = m(\beta)\,\dot\beta^2/2 + V(\beta)$ (%s)" % DIMLESS)
    ax2.set_ylabel("net displacement per period along $y$\n(%s)" % LENGTH)
    ax2.set_title("net displacement per period (along $x$: 0 by symmetry)")
    ax2.grid(alpha=0.3)
    # one legend under both panels: inside the portrait it covers the curves
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.legend(h1 + h2, l1 + ["per period: " + x for x in l2], loc="lower center", ncol=5,
               fontsize=8, frameon=False)
    finish(fig, os.path.join(d, "phase.png"), collect)
    with open(os.path.join(d, "periods.csv"), "w") as fh:
        fh.write("id,betadot0,kind,energy,energy_swim,energy_mismatch,period,dy_per_period,dx_per_period\n")
        for mem, (beta, dbeta, g), (kind, e, r, bd0) in zip(kept, curves, results):
            # the reduced energy along the computed trajectory against swim's own energy column:
            # checks m(beta) and V(beta) of the reduction at every row
            mb, _, Vb, _ = model_at(beta)
            e_red = 0.5 * mb * dbeta ** 2 + Vb
            tr = mem["traj"]
            e_swim = tr["energy"] if "energy" in tr else np.full_like(e_red, np.nan)
            mis = float(np.nanmax(np.abs(e_red - e_swim)) / max(abs(e), 1e-300))
            fh.write("%d,%.17g,%s,%.17g,%.17g,%.3g,%s\n" % (mem["id"], bd0, kind, e, e_swim[0], mis,
                                                            ",".join("%.17g" % x for x in r) if r else ",,"))
    print(os.path.join(d, "periods.csv"))
    return True


def main(argv):
    args = argv[1:]
    swim = os.environ.get("SWIM_BIN") or os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "bin", "swim")
    title = None
    if "--swim" in args:
        i = args.index("--swim")
        swim = args[i + 1]
        del args[i:i + 2]
    if "--title" in args:
        i = args.index("--title")
        title = args[i + 1]
        del args[i:i + 2]
    if len(args) != 1:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    d = args[0]
    sweep, members = load_sweep(d)
    if not members:
        warn("%s/members.csv has no finished member yet" % d)
        return 1
    plot_family(d, sweep, members, title)
    plot_phase(d, sweep, members, swim, title)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
