"""The strain energy of a hyperelastic law U(I1, J) (Section 4.1.1, ERRATA B5) as C.

    W(c) = int_D U(I1, J) dz,   I1 = 2 (|c_1|^2 + |h|^2),   J = |c_1|^2 - |h|^2,
    h(z) = sum_{m=1}^N m c_-m conj(z)^(m-1)                                         (2.4), B2

A law is the text of a scene's `[elastic] energy`, in the forcing-law grammar (law.py) with the
names I1, J, I1bar = I1/J and those of the scene's [parameters] (run-time values, read as
p->law_params[k], so changing them never regenerates a kernel).

Two ways, chosen by the law:
* U a polynomial in I1 and J (coefficients: any functions of the parameters): exactly. With
  A = |c_1|^2 and H = |h|^2, U = sum u_ij A^i H^j, and int_D H^j dz = sum_p |e_p|^2 pi/(p+1),
  e_p the coefficients of h^j as a polynomial in conj(z) (the monomials conj(z)^p are
  orthogonal on D: int_D |z|^(2p) dz = pi/(p+1)). W, its gradient and Hessian are polynomials
  in the shape coordinates, which SymPy differentiates.
* Any other law: a product rule over the disk, Gauss-Legendre in r (weight r dr, NR nodes) and
  the trapezoid rule in theta (NT nodes, exact for trigonometric polynomials of degree < NT),
  in kernel/material.h, graded towards the angle of min J and r = 1 when min J is small; the
  generator supplies U and its first and second partials in I1, J
  (and their partials in each parameter) at one point.

Both give the kernel the same functions (kernel/material.h lists them). A law is refused
(MaterialError) when it uses t or a function that is not twice differentiable (step, abs).
"""

import math

import sympy as sp

from .cprint import KernelPrinter, emit_assignments
from .law import LawError, parameter_symbols, parse

INVARIANTS = ("I1", "J", "I1bar")
GRADED_POINTS = 10   # Gauss-Legendre points per panel of the graded rule (kernel/material.h)


class MaterialError(LawError):
    pass


def _uses(node, kinds):
    """1 when the law tree contains t or one of the functions in `kinds`."""
    kind = node[0]
    if kind == "t":
        return "t"
    if kind == "fun":
        return node[1] if node[1] in kinds else _uses(node[2], kinds)
    if kind == "neg":
        return _uses(node[1], kinds)
    if kind == "op":
        return _uses(node[2], kinds) or _uses(node[3], kinds)
    return None


def law_expression(text, pnames):
    """U as a SymPy expression in the symbols I1, J and the parameter symbols; returns
    (U, I1, J, {name: symbol})."""
    theta = parameter_symbols(pnames)
    for name in INVARIANTS:
        if name in theta:
            raise MaterialError("'%s' names an invariant of the energy law: choose another "
                                "parameter name" % name)
    law = parse(text, list(INVARIANTS) + list(pnames))
    bad = _uses(law.tree, ("step", "abs"))
    if bad == "t":
        raise MaterialError("\"%s\": an energy law is a function of I1, J, I1bar and "
                            "[parameters], not of t" % text)
    if bad:
        raise MaterialError("\"%s\": %s is not twice differentiable where it switches: the "
                            "Hessian of W is needed" % (text, bad))
    I1, J = sp.symbols("I1 J", positive=True)
    names = dict(theta)
    names.update(I1=I1, J=J, I1bar=I1 / J)
    return law.sympy(sp.Symbol("t", real=True), names), I1, J, theta


def _h_powers(m, jmax):
    """[re, im] coefficient lists of h^j as polynomials in conj(z), j = 0..jmax."""
    h = [(sp.Integer(mm) * m.a(-mm), sp.Integer(mm) * m.b(-mm)) for mm in range(1, m.N + 1)]
    powers = [[(sp.Integer(1), sp.Integer(0))]]
    for _ in range(jmax):
        prev, out = powers[-1], {}
        for p, (ar, ai) in enumerate(prev):
            for q, (br, bi) in enumerate(h):
                r0, i0 = out.get(p + q, (0, 0))
                out[p + q] = (r0 + ar * br - ai * bi, i0 + ar * bi + ai * br)
        powers.append([(sp.expand(out[k][0]), sp.expand(out[k][1]))
                       for k in range(max(out) + 1)] if out else [(0, 0)])
    return powers


def closed_form(m, U, I1, J):
    """W(c) = int_D U dz as a polynomial in the shape coordinates, or None when U is not a
    polynomial in I1 and J."""
    if not U.is_polynomial(I1, J):
        return None
    A, H = sp.symbols("A H", real=True)
    poly = sp.Poly(sp.expand(U.subs({I1: 2 * (A + H), J: A - H})), A, H)
    jmax = max((mon[1] for mon in poly.monoms()), default=0)
    hp = _h_powers(m, jmax) if m.N > 0 else None
    disk = []   # int_D H^j dz
    for j in range(jmax + 1):
        if j == 0:
            disk.append(sp.pi)
        elif hp is None:
            disk.append(sp.Integer(0))
        else:
            disk.append(sp.expand(sum((re ** 2 + im ** 2) * sp.pi / (p + 1)
                                      for p, (re, im) in enumerate(hp[j]))))
    Aval = m.a(1) ** 2 + m.b(1) ** 2
    return sp.expand(sum(coef * Aval ** i * disk[j] for (i, j), coef in poly.terms()))


def _names(e, theta, pnames):
    names = dict(e.names)
    for k, name in enumerate(pnames):
        names[theta[name]] = "p->law_params[%d]" % k
    return names


def _unused(lines, args):
    import re
    used = "".join(lines)
    return ["    (void)%s;" % a for a in args
            if not re.search(r"(?<![A-Za-z0-9_>])%s(?![A-Za-z0-9_])" % a, used)]


def _closed_source(e, m, W, theta, pnames):
    names = _names(e, theta, pnames)
    pr = KernelPrinter(names)
    grad = m.gradient(W)
    first = emit_assignments([("*W", W)] + [("grad[%d]" % k, g) for k, g in enumerate(grad)], pr)
    hess = emit_assignments([("hess[%d]" % (m.n * r + s), d2) for (r, s), d2 in
                             sorted(m.hessian(W).items())], pr, indent="        ")
    body = _unused(first + hess, ("x", "p")) + first
    out = ["#define SWIM_MATERIAL_CLOSED_FORM",
           "/* W = int_D U dz in closed form, its gradient on the carried coordinates and (hess not",
           " * NULL) its Hessian, NX x NX row-major; 0, or nonzero when not finite. */",
           "static int material_energy(const double *x, const swim_scene_params *p, double *W,",
           "                           double *grad, double *hess)", "{"] + body
    out += ["    if (hess) {", "        memset(hess, 0, sizeof(double) * NX * NX);"] + hess + ["    }"]
    out += ["    if (!isfinite(*W)) return 1;",
            "    for (int i = 0; i < NX; i++)",
            "        if (!isfinite(grad[i])) return 1;",
            "    return 0;", "}", "",
            "/* d grad W / d law_params[k] (NX entries); 1, or 0 when W does not depend on it. */",
            "static int material_energy_dp(const double *x, const swim_scene_params *p, int k,",
            "                              double *dgrad)", "{"]
    cases = []
    for k, name in enumerate(pnames):
        dg = [sp.diff(g, theta[name]) for g in grad]
        if all(d == 0 for d in dg):
            continue
        lines = emit_assignments([("dgrad[%d]" % i, d) for i, d in enumerate(dg)], pr,
                                 indent="        ")
        cases += ["    case %d: {" % k] + lines + ["        return 1;", "    }"]
    if cases:
        out += _unused(cases, ("x", "p")) + ["    switch (k) {"] + cases + ["    }"]
    else:
        out += ["    (void)x;", "    (void)p;", "    (void)k;", "    (void)dgrad;"]
    out += ["    return 0;", "}", ""]
    return "\n".join(out)


def quadrature_nodes(modes):
    """Radial Gauss-Legendre nodes and weights for int_0^1 g(r) r dr, and the number of theta
    nodes, for h of degree modes - 1: NT = 8 modes + 32 (a polynomial law's integrand has degree
    2 (modes - 1) deg U in theta), NR = 2 modes + 16 (docs/materials.md measures the error)."""
    nr = 2 * modes + 16
    nt = 8 * modes + 32
    xg, wg = _gauss_legendre(nr)
    r = [0.5 * (x + 1.0) for x in xg]
    w = [0.5 * wk * rk for wk, rk in zip(wg, r)]
    return r, w, nt


def _gauss_legendre(n):
    """Nodes and weights of n-point Gauss-Legendre on [-1, 1]: Newton on P_n from the
    Chebyshev-like guesses, in Python floats (deterministic, no numpy needed)."""
    xs, ws = [], []
    for i in range(1, n + 1):
        x = math.cos(math.pi * (i - 0.25) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1.0)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-16:
                break
        p0, p1 = 1.0, x
        for k in range(2, n + 1):
            p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
        dp = n * (x * p1 - p0) / (x * x - 1.0)
        xs.append(x)
        ws.append(2.0 / ((1.0 - x * x) * dp * dp))
    return xs[::-1], ws[::-1]


def _quadrature_source(e, m, U, I1, J, theta, pnames):
    names = _names(e, theta, pnames)
    names[I1] = "I1"
    names[J] = "J"
    pr = KernelPrinter(names)
    parts = [U, sp.diff(U, I1), sp.diff(U, J), sp.diff(U, I1, 2), sp.diff(U, I1, J),
             sp.diff(U, J, 2)]
    lines = emit_assignments([("u[%d]" % i, d) for i, d in enumerate(parts)], pr)
    # the highest mode that can be nonzero: coordinates locked at 0 are folded away, so h has
    # degree top - 1 in conj(z) and the integrand's angular frequencies grow with top, not N
    top = max([m.mode_of(i) * -1 for i in range(2, m.nfull) if i not in m.zero] or [0])
    r, w, nt = quadrature_nodes(top)
    gx, gw = _gauss_legendre(GRADED_POINTS)
    out = ["#define SWIM_MATERIAL_QUADRATURE", "#define MATERIAL_TOP %d" % top,
           "#define MATERIAL_NR %d" % len(r), "#define MATERIAL_NT %d" % nt,
           "static const double material_r[MATERIAL_NR] = {%s};" % ", ".join(repr(v) for v in r),
           "static const double material_w[MATERIAL_NR] = {%s};" % ", ".join(repr(v) for v in w),
           "#define MATERIAL_GK %d" % GRADED_POINTS,
           "static const double material_gx[MATERIAL_GK] = {%s};" % ", ".join(repr(v) for v in gx),
           "static const double material_gw[MATERIAL_GK] = {%s};" % ", ".join(repr(v) for v in gw),
           "static const double material_c[MATERIAL_NT] = {%s};" % ", ".join(
               repr(math.cos(2 * math.pi * l / nt)) for l in range(nt)),
           "static const double material_s[MATERIAL_NT] = {%s};" % ", ".join(
               repr(math.sin(2 * math.pi * l / nt)) for l in range(nt)),
           "/* U, U_I, U_J, U_II, U_IJ, U_JJ at one point (I1, J) */",
           "static void material_density(double I1, double J, const swim_scene_params *p, double *u)",
           "{"] + _unused(lines, ("I1", "J", "p")) + lines + ["}", "",
           "/* d/d law_params[k] of U, U_I, U_J at (I1, J); 1, or 0 when U does not depend on it. */",
           "static int material_density_dp(double I1, double J, const swim_scene_params *p, int k,",
           "                               double *u)", "{"]
    cases = []
    for k, name in enumerate(pnames):
        d = [sp.diff(q, theta[name]) for q in parts[:3]]
        if all(v == 0 for v in d):
            continue
        cl = emit_assignments([("u[%d]" % i, v) for i, v in enumerate(d)], pr, indent="        ")
        cases += ["    case %d: {" % k] + cl + ["        return 1;", "    }"]
    if cases:
        out += _unused(cases, ("I1", "J", "p")) + ["    switch (k) {"] + cases + ["    }"]
    else:
        out += ["    (void)I1;", "    (void)J;", "    (void)p;", "    (void)k;", "    (void)u;"]
    out += ["    return 0;", "}", '#include "kernel/material.h"', ""]
    return "\n".join(out)


def material_source(e, m, energy):
    """The C of a scene's energy law (energy = {"law": text, "parameters": [names]}), defining
    what kernel/scene_rhs.h reads under SWIM_SCENE_MATERIAL; and how it is computed."""
    pnames = list(energy.get("parameters", []))
    U, I1, J, theta = law_expression(energy["law"], pnames)
    W = closed_form(m, U, I1, J)
    if W is not None:
        return _closed_source(e, m, W, theta, pnames), "closed form"
    return _quadrature_source(e, m, U, I1, J, theta, pnames), "quadrature"
