#!/usr/bin/env python3
"""Energy laws ([elastic] energy = U(I1, J), docs/materials.md), end to end.

Asserts: `swim inspect --energy "a*I1"` is the closed form 2 pi a (|c_1|^2 + sum k |c_-k|^2) of
ERRATA B5 to round-off at random shapes; a law with ln J (a quadrature in the kernel) agrees with
an independent polar quadrature written here to 1e-10 (value) and 1e-7 (gradient, central
differences of it); the Hessian agrees with central differences of the kernel's gradient, for a
closed-form law and a quadrature law; Example 3 with the compressible neo-Hookean law and no
W1 keeps its energy to 1e-8 at rtol 1e-11 over T = 10, and trajectory.csv's W_law at t = 0 is
the law's integral at c0; --sensitivity parameters.mu agrees with central differences of two
runs to 1e-5; bad laws are one line naming file, line, key and law, exit 2, nothing written.
Prints "test_materials: P passed, F failed".
"""

import csv
import json
import math
import os
import subprocess
import sys

import numpy as np

from swimtest import ROOT, TMP, check, main, run, scene, swim

CNH = "mu/2*(I1 - 2) - mu*log(J) + lam/2*log(J)^2"
MU, LAM = 0.3, 0.5


def inspect(shape, law, *params):
    args = ["inspect", "--modes", str(len(shape) // 2 - 1), "--shape", ",".join(repr(v) for v in shape),
            "--energy", law]
    for p in params:
        args += ["--param", p]
    p = swim(*args)
    check(p.returncode == 0, "inspect %s: %s" % (law, p.stderr.strip()))
    if p.returncode != 0:
        return None
    return json.loads(p.stdout)


def random_shape(rng, modes, size=0.08):
    """A shape well inside D: c_1 near 1, small c_-k."""
    c = rng.uniform(-size, size, 2 * (modes + 1)) / max(1, modes) ** 2
    c[0] += 1.0
    return [float(v) for v in c]


def invariants(c, z):
    """I1, J at the points z (numpy, complex) of shape c, from (2.4) with h of ERRATA B2."""
    h = np.zeros_like(z)
    for m in range(1, len(c) // 2):
        h = h + m * (c[2 * m] + 1j * c[2 * m + 1]) * np.conj(z) ** (m - 1)
    A = c[0] ** 2 + c[1] ** 2
    H = np.abs(h) ** 2
    return 2 * (A + H), A - H


def independent_W(c, mu=MU, lam=LAM):
    """int_D U dz by 80-point Gauss-Legendre in r and a 400-point trapezoid in theta."""
    x, w = np.polynomial.legendre.leggauss(80)
    r, wr = 0.5 * (x + 1), 0.5 * w * 0.5 * (x + 1)
    th = 2 * np.pi * np.arange(400) / 400
    z = r[:, None] * np.exp(1j * th[None, :])
    I1, J = invariants(c, z)
    U = mu / 2 * (I1 - 2) - mu * np.log(J) + lam / 2 * np.log(J) ** 2
    return float(np.sum(wr[:, None] * U) * 2 * np.pi / 400)


def test_neo_hookean_closed_form():
    rng = np.random.default_rng(34)
    for modes in (1, 4):
        for _ in range(3):
            c = random_shape(rng, modes)
            out = inspect(c, "a*I1", "a=0.7")
            if out is None:
                return
            want = 2 * math.pi * 0.7 * (c[0] ** 2 + c[1] ** 2
                                        + sum(k * (c[2 * k] ** 2 + c[2 * k + 1] ** 2) for k in range(1, modes + 1)))
            check(abs(out["W_law"] - want) <= 1e-15 * want, "N = %d: W %r, B5 %r" % (modes, out["W_law"], want))
            grad = [2 * math.pi * 0.7 * 2 * c[i] * (1 if i < 2 else i // 2) for i in range(len(c))]
            err = max(abs(a - b) for a, b in zip(out["grad_W_law"], grad))
            check(err <= 1e-15 * max(map(abs, grad)), "N = %d: grad differs by %.2g" % (modes, err))


def test_log_law_against_independent_quadrature():
    rng = np.random.default_rng(7)
    for modes in (3,):
        c = random_shape(rng, modes, 0.1)
        out = inspect(c, CNH, "mu=%r" % MU, "lam=%r" % LAM)
        if out is None:
            return
        W = independent_W(c)
        check(abs(out["W_law"] - W) <= 1e-10 * abs(W), "N = %d: W %r, independent %r" % (modes, out["W_law"], W))
        h = 1e-6
        for i in range(len(c)):
            cp, cm = list(c), list(c)
            cp[i] += h
            cm[i] -= h
            d = (independent_W(cp) - independent_W(cm)) / (2 * h)
            check(abs(out["grad_W_law"][i] - d) <= 1e-7 * max(1.0, abs(d)),
                  "N = %d: dW/dx%d %r, differences %r" % (modes, i, out["grad_W_law"][i], d))


def test_graded_rule_near_the_boundary():
    """c = (1, 0, 0, 0, b, 0): J = 1 - 4 b^2 r^2 depends on r alone, so W = 2 pi int_0^1 U r dr and
    dW/db = 2 pi int_0^1 (2 U_I - U_J) 8 b r^2 r dr, here by Gauss-Legendre panels geometric
    towards r = 1; the kernel grades its rule below min J = 0.15."""
    x, w = np.polynomial.legendre.leggauss(30)
    edges = [0.0] + [1 - 0.5 ** j for j in range(1, 45)] + [1.0]
    r = np.concatenate([0.5 * (b - a) * x + 0.5 * (a + b) for a, b in zip(edges[:-1], edges[1:])])
    wr = np.concatenate([0.5 * (b - a) * w for a, b in zip(edges[:-1], edges[1:])]) * r
    for jmin in (0.1, 1e-3, 1e-5):
        b = math.sqrt((1 - jmin) / 4)
        J, I1 = 1 - 4 * b * b * r * r, 2 * (1 + 4 * b * b * r * r)
        U = MU / 2 * (I1 - 2) - MU * np.log(J) + LAM / 2 * np.log(J) ** 2
        UI, UJ = MU / 2, -MU / J + LAM * np.log(J) / J
        W = 2 * np.pi * np.sum(wr * U)
        dWdb = 2 * np.pi * np.sum(wr * (2 * UI - UJ) * 8 * b * r * r)
        out = inspect([1.0, 0.0, 0.0, 0.0, 0.0, b], CNH, "mu=%r" % MU, "lam=%r" % LAM)
        if out is None:
            return
        check(abs(out["W_law"] - W) <= 1e-12 * abs(W), "min J %g: W %r, reference %r" % (jmin, out["W_law"], W))
        check(abs(out["grad_W_law"][5] - dWdb) <= 1e-10 * abs(dWdb),
              "min J %g: dW/db %r, reference %r" % (jmin, out["grad_W_law"][5], dWdb))


def test_hessian_against_gradient_differences():
    rng = np.random.default_rng(11)
    c = random_shape(rng, 3, 0.1)
    for law in ("a*I1 + b*J^3 - a*J*I1", CNH):
        params = ("a=0.4", "b=0.3") if "b" in law else ("mu=%r" % MU, "lam=%r" % LAM)
        out = inspect(c, law, *params)
        if out is None:
            return
        H, h = np.array(out["hess_W_law"]), 1e-5
        check(np.array_equal(H, H.T), "%s: Hessian symmetric" % law)
        worst = 0.0
        for i in range(len(c)):
            cp, cm = list(c), list(c)
            cp[i] += h
            cm[i] -= h
            gp, gm = inspect(cp, law, *params), inspect(cm, law, *params)
            if gp is None or gm is None:
                return
            col = (np.array(gp["grad_W_law"]) - np.array(gm["grad_W_law"])) / (2 * h)
            worst = max(worst, float(np.max(np.abs(col - H[:, i]))))
        check(worst <= 1e-6 * max(1.0, float(np.max(np.abs(H)))), "%s: Hessian vs differences %.2g" % (law, worst))


EX3 = open(os.path.join(ROOT, "models", "example3.toml")).read()


def law_scene(name, t_end, rtol=1e-11, mu=MU, law=CNH):
    """Example 3 with the energy law instead of W1 (stiffness 0), no damping, no forcing."""
    text = EX3.replace("t_end = 30.0", "t_end = %r" % t_end).replace("rtol = 1e-10", "rtol = %r" % rtol)
    text = text.replace("atol = 1e-12", "atol = 1e-13")
    text = text.replace("stiffness = [ 0, 0, 1,      1, 2, 2,", "stiffness = [ 0, 0, 0,      0, 0, 0,")
    text = text.replace("[elastic]\n", '[elastic]\nenergy = "%s"\n' % law)
    text += "\n[parameters]\nmu = %r\nlam = %r\n" % (mu, LAM)
    return scene(name, text)


def test_energy_conserved_and_initial_W():
    path = law_scene("cnh_conservative", 10.0)
    p, rows, s = run(path, "cnh_conservative")
    check(p.returncode == 0 and rows is not None, "run: %s" % p.stderr.strip())
    if rows is None:
        return
    e = rows["energy"]
    drift = float(np.max(np.abs(e - e[0])) / abs(e[0]))
    check(drift <= 1e-8, "energy kept to %.2g over T = 10 at rtol 1e-11" % drift)
    check(float(np.max(np.abs(rows["work"]))) == 0.0, "no work without damping or forcing")
    c0 = [float(rows[n][0]) for n in ("a1", "b1", "am1", "bm1", "am2", "bm2", "am3", "bm3", "am4", "bm4",
                                          "am5", "bm5", "am6", "bm6", "am7", "bm7")]
    W0 = independent_W(c0)
    check(abs(rows["W_law"][0] - W0) <= 1e-10 * abs(W0), "W_law(0) %r, the integral at c0 %r" % (rows["W_law"][0], W0))
    ins = inspect(c0, CNH, "mu=%r" % MU, "lam=%r" % LAM)
    if ins:
        check(abs(rows["W_law"][0] - ins["W_law"]) <= 1e-14 * abs(W0), "W_law(0) is inspect's W_law at c0")
    check(np.allclose(rows["potential"], rows["w1"] + rows["w2"] + rows["W_law"], rtol=1e-15, atol=0),
          "potential = w1 + w2 + W_law")


def test_sensitivity_against_two_runs():
    path = law_scene("cnh_sens", 2.0, rtol=1e-12)
    out = os.path.join(TMP, "cnh_sens_exact")
    p = swim("run", path, "--out", out, "--quiet", "--sensitivity", "parameters.mu")
    check(p.returncode == 0, "sensitivity run: %s" % p.stderr.strip())
    if p.returncode != 0:
        return
    with open(os.path.join(out, "sensitivity.csv")) as fh:
        sens = list(csv.DictReader(fh))[-1]
    h, ends = 1e-4, []
    for sign in (1, -1):
        _, rows, _ = run(path, "cnh_sens_%d" % sign, "--set", "parameters.mu=%r" % (MU + sign * h))
        if rows is None:
            check(False, "difference run")
            return
        ends.append(rows[-1])
    for col in ("y", "am1", "bm2", "dam1"):
        d = (ends[0][col] - ends[1][col]) / (2 * h)
        exact = float(sens["d%s/dparameters.mu" % col])
        check(abs(exact - d) <= 1e-5 * max(abs(d), 1e-3), "d%s/dmu exact %r, runs %r" % (col, exact, d))


def test_printer_denominators():
    """The laws' second partials have powers in denominators (mu/J^2): C must read a/(J*J), not
    a/J*J = (a/J)*J (the printer writes small powers as products)."""
    code = ("import sys; sys.path.insert(0, %r)\n"
            "import sympy as sp\n"
            "from swimgen.cprint import KernelPrinter\n"
            "a, J, t = sp.symbols('a J t')\n"
            "pr = KernelPrinter({})\n"
            "print(pr.doprint(a / J**2)); print(pr.doprint(sp.diff(1 / (2 + t), t)))\n"
            % os.path.join(ROOT, "generator"))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    lines = p.stdout.splitlines()
    check(p.returncode == 0 and lines[:1] == ["a/(J*J)"], "a/J^2 printed %r" % p.stdout)
    check(len(lines) == 2 and "/((t + 2)*(t + 2))" in lines[1], "d/dt 1/(2+t) printed %r" % p.stdout)


def test_bad_laws_refused():
    cases = [("mu*I1 + foo", "unknown name 'foo'"),
             ("mu*log(J - 0.9)", "not finite at c0"),
             ("mu*step(J - 1)", "not twice differentiable"),
             ("mu*I1*t", "not of t"),
             ("mu*abs(J - 1)", "not twice differentiable")]
    for i, (law, want) in enumerate(cases):
        path = law_scene("bad%d" % i, 1.0, law=law)
        out = os.path.join(TMP, "bad%d" % i)
        p = swim("run", path, "--out", out, "--quiet")
        line = p.stderr.strip()
        check(p.returncode == 2 and len(line.splitlines()) == 1 and want in line
              and "bad%d.toml:" % i in line and "elastic.energy" in line and law in line,
              "%s: exit 2 and one line naming file, line, key and law (%d %r)" % (law, p.returncode, line))
        check(not os.path.exists(out), "%s: nothing written" % law)
    path = law_scene("badname", 1.0).replace(".toml", "")
    text = open(path + ".toml").read().replace("lam = ", "J = 1\nlam = ")
    p = swim("run", scene("badname2", text), "--out", os.path.join(TMP, "badname2"), "--quiet")
    check(p.returncode == 2 and "invariant" in p.stderr, "a parameter named J is refused (%r)" % p.stderr)


if __name__ == "__main__":
    sys.exit(main(globals(), "test_materials"))
