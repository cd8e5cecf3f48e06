#!/usr/bin/env python3
"""The numbers and the figure of docs/materials.md (energy laws, ERRATA B5).

    /usr/bin/python3 tools/materials/study.py [--out docs/figures/materials_sweep.png]

1. Accuracy of the kernel's disk quadrature (swim inspect --energy, N = 2) for the compressible
   neo-Hookean law on the family c = (1, 0, t/2, 0, t/4, 0), whose min J = 1 - t^2 sits at
   z = 1, against a graded reference quadrature written here (composite Gauss-Legendre,
   geometric toward r = 1 and toward theta = 0): relative error of W and of grad W.
2. Finiteness at the boundary of D on the same family: int_D -ln J dz and int_D 1/J dz
   against W2/eps = (1/(2 alpha)) int J^-alpha d theta on the circle (alpha = 1/2), as min J -> 0.
3. Example 3 (models/example3.toml, its W1 kept) plus a neo-Hookean or a compressible
   neo-Hookean body of the same shear modulus mu (lam = mu): the period (mean spacing of the
   maxima of a_-1) and the displacement per period, against mu; printed and plotted.
Uses bin/swim and the kernel cache ($SWIM_CACHE)."""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWIM = os.path.join(ROOT, "bin", "swim")
CNH = "mu/2*(I1 - 2) - mu*log(J) + lam/2*log(J)^2"
MU, LAM = 0.3, 0.5


def family(t):
    return [1.0, 0.0, t / 2, 0.0, t / 4, 0.0]


def graded_nodes(edges, k=24):
    """Composite k-point Gauss-Legendre on consecutive intervals of `edges`."""
    x, w = np.polynomial.legendre.leggauss(k)
    nodes, weights = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        nodes.append(0.5 * (b - a) * x + 0.5 * (a + b))
        weights.append(0.5 * (b - a) * w)
    return np.concatenate(nodes), np.concatenate(weights)


def geometric(a, b, levels=40):
    """a, then points accumulating at b: b - (b - a) 2^-j."""
    return [a] + [b - (b - a) * 0.5 ** j for j in range(1, levels)] + [b]


def disk_points():
    r, wr = graded_nodes(geometric(0.0, 1.0))
    half = [np.pi - e for e in geometric(0.0, np.pi)]   # accumulating at theta = 0, where min J is
    th_edges = sorted(set([-x for x in half] + half))
    th, wt = graded_nodes(th_edges)
    z = r[:, None] * np.exp(1j * th[None, :])
    return z, (wr * r)[:, None] * wt[None, :]


def fields(c, z):
    h = np.zeros_like(z)
    dh = []
    for m in range(1, len(c) // 2):
        e = m * np.conj(z) ** (m - 1)
        h = h + (c[2 * m] + 1j * c[2 * m + 1]) * e
        dh += [e, 1j * e]
    return c[0] ** 2 + c[1] ** 2, h, dh


def reference_W(c, z, w):
    A, h, dh = fields(c, z)
    H = np.abs(h) ** 2
    I1, J = 2 * (A + H), A - H
    U = MU / 2 * (I1 - 2) - MU * np.log(J) + LAM / 2 * np.log(J) ** 2
    UI, UJ = MU / 2, -MU / J + LAM * np.log(J) / J
    UA, UH = 2 * UI + UJ, 2 * UI - UJ
    grad = [np.sum(w * UA * 2 * c[0]), np.sum(w * UA * 2 * c[1])]
    for d in dh:
        grad.append(np.sum(w * UH * 2 * np.real(np.conj(h) * d)))
    return float(np.sum(w * U)), np.array(grad, dtype=float)


def inspect(c, law, params):
    args = [SWIM, "inspect", "--modes", str(len(c) // 2 - 1), "--shape", ",".join(repr(v) for v in c),
            "--energy", law] + sum((["--param", p] for p in params), [])
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    return json.loads(p.stdout)


def accuracy_and_finiteness():
    z, w = disk_points()
    print("1. kernel quadrature (N = 2: 20 x 48 nodes) against a graded reference, compressible neo-Hookean")
    print("%10s %12s %14s %14s" % ("min J", "W", "rel. err W", "rel. err grad"))
    for t in (0.5, 0.9, 0.99, 0.999, 0.9999, 0.99999):
        c = family(t)
        Wr, gr = reference_W(c, z, w)
        k = inspect(c, CNH, ["mu=%r" % MU, "lam=%r" % LAM])
        eW = abs(k["W_law"] - Wr) / abs(Wr)
        eg = np.max(np.abs(np.array(k["grad_W_law"]) - gr)) / np.max(np.abs(gr))
        print("%10.1e %12.8f %14.2e %14.2e" % (1 - t * t, Wr, eW, eg))
    print("\n2. at the boundary of D: area integrals stay finite, the barrier does not (alpha = 1/2)")
    print("%10s %16s %16s %18s" % ("min J", "int_D -ln J dz", "int_D 1/J dz", "W2/eps (circle)"))
    for t in (0.9, 0.99, 0.999, 0.9999, 0.99999, 1.0):
        c = family(t)
        A, h, _ = fields(c, z)
        J = A - np.abs(h) ** 2
        half = [np.pi - e for e in geometric(0.0, np.pi)]
        th, wt = graded_nodes(sorted(set([-x for x in half] + half)))
        _, hc, _ = fields(c, np.exp(1j * th))
        Jc = A - np.abs(hc) ** 2
        W2 = np.sum(wt * Jc ** -0.5) if t < 1 else np.inf   # (1/(2 alpha)) = 1 at alpha = 1/2
        print("%10.1e %16.10f %16.10f %18.6g" % (1 - t * t, np.sum(w * -np.log(J)), np.sum(w * 1 / J), W2))


def events(scene, sets, tmp, tag):
    out = os.path.join(tmp, tag)
    args = [SWIM, "run", scene, "--out", out, "--quiet", "--event", "am1:max"]
    for s in sets:
        args += ["--set", s]
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        raise RuntimeError(p.stderr)
    ev = np.genfromtxt(os.path.join(out, "events.csv"), delimiter=",", names=True, dtype=None, encoding=None)
    rows = np.genfromtxt(os.path.join(out, "trajectory.csv"), delimiter=",", names=True)
    t = np.atleast_1d(ev["t"])
    periods = np.diff(t)
    # y at the maxima, interpolated from the rows (output step 0.05; y is smooth and slow)
    y = np.interp(t, rows["t"], rows["y"])
    return float(np.mean(periods)), float((y[-1] - y[0]) / (len(t) - 1))


def sweep(out_png):
    mus = [0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8]
    laws = {"neo-Hookean  mu/2 (I1 - 2)": "mu/2*(I1 - 2)",
            "compressible neo-Hookean (lam = mu)": "mu/2*(I1 - 2) - mu*log(J) + mu/2*log(J)^2"}
    base = open(os.path.join(ROOT, "models", "example3.toml")).read()
    res = {}
    with tempfile.TemporaryDirectory(prefix="swim-materials-") as tmp:
        for name, law in laws.items():
            path = os.path.join(tmp, "%d.toml" % len(res))
            with open(path, "w") as fh:
                fh.write(base.replace("[elastic]\n", '[elastic]\nenergy = "%s"\n' % law)
                         + "\n[parameters]\nmu = 0.1\n")
            res[name] = [events(path, ["parameters.mu=%r" % m], tmp, "%d_%d" % (len(res), i))
                         for i, m in enumerate(mus)]
    print("\n3. Example 3 with W1 plus a law of shear modulus mu: period and displacement per period")
    print("%-38s" % "law" + "".join("%10s" % ("mu=%g" % m) for m in mus))
    for name, vals in res.items():
        print("%-38s" % (name + ", period") + "".join("%10.5f" % p for p, _ in vals))
        print("%-38s" % (name + ", dy/period") + "".join("%10.5f" % d for _, d in vals))
    if out_png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(9, 3.4))
        for (name, vals), mk in zip(res.items(), ("s-", "o-")):
            ax[0].plot(mus, [p for p, _ in vals], mk, label=name)
            ax[1].plot(mus, [d for _, d in vals], mk, label=name)
        ax[0].set_xlabel("shear modulus $\\mu$")
        ax[0].set_ylabel("period (maxima of $a_{-1}$)")
        ax[1].set_xlabel("shear modulus $\\mu$")
        ax[1].set_ylabel("displacement in $y$ per period")
        # y at the maxima comes from the rows (step 0.05) by interpolation: ~1e-5; show 2 %
        mid = res[next(iter(res))][0][1]
        ax[1].set_ylim(0.99 * mid, 1.01 * mid)
        ax[1].ticklabel_format(useOffset=False)
        ax[0].legend(fontsize=7)
        fig.suptitle("Example 3 (with $W_1$) plus an energy law: $\\mu = 0$ is the quadratic $W_1$ alone",
                     fontsize=9)
        fig.tight_layout()
        fig.savefig(out_png, dpi=110)
        print("wrote", out_png)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "figures", "materials_sweep.png"))
    args = ap.parse_args()
    accuracy_and_finiteness()
    sweep(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
