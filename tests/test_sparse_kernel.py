#!/usr/bin/env python3
"""Kernels above N = 7 take S and its derivatives from a table of monomials: the first partials
by the loops of runtime/kernel/sparse_data.h, and S, D_v S and the bigradient either by those
loops too (the kernel of N modes) or printed from the table as one statement per entry (scene
kernels); N <= 7 keeps SymPy's straight-line code. The three emissions of the kernel of N = 9
modes are generated, compiled and loaded side by side, and every function of the kernel (mass,
mass_deriv, reduced with <Gamma, v, v>, reduced_deriv, jacobian_circle, inertia, boundary_data)
must agree at random shapes to round-off (1e-13 relative to each output's largest entry; they
differ only in the order of the sums). The emitted text must show the table exactly when asked
for.
(Scene kernels above N = 7 are checked against the independent loop reference by
tests/test_rhs.c and tests/test_jacobian.c.)
Prints "test_sparse_kernel: P passed, F failed".
"""

import ctypes
import os
import random
import subprocess
import sys

import swimtest
from swimtest import ROOT, TMP, check, main

sys.path.insert(0, os.path.join(ROOT, "generator"))
from swimgen.emit import kernel_source  # noqa: E402

N = 9
n = 2 * (N + 1)
CC = os.environ.get("SWIM_CC", "cc")
D = ctypes.POINTER(ctypes.c_double)


class Kernel(ctypes.Structure):
    _fields_ = [("modes", ctypes.c_int), ("dim", ctypes.c_int),
                ("mass", ctypes.CFUNCTYPE(None, D, ctypes.c_double, ctypes.c_double, D, D, D)),
                ("mass_deriv", ctypes.CFUNCTYPE(ctypes.c_int, D, ctypes.c_double, ctypes.c_double,
                                                D, D, D)),
                ("reduced", ctypes.CFUNCTYPE(ctypes.c_int, D, D, ctypes.c_double, ctypes.c_double,
                                             D, D, D)),
                ("reduced_deriv", ctypes.CFUNCTYPE(ctypes.c_int, D, ctypes.c_double,
                                                   ctypes.c_double, D, D)),
                ("jacobian_circle", ctypes.CFUNCTYPE(None, D, D, D, D, D)),
                ("inertia", ctypes.CFUNCTYPE(ctypes.c_double, D, D)),
                ("boundary_data", ctypes.CFUNCTYPE(None, D, D))]


def build(tabled, loops=True):
    name = ("loops" if loops else "printed") if tabled else "straight"
    text = kernel_source(N, "tests/test_sparse_kernel.py", tabled=tabled, loops=loops)
    src = os.path.join(TMP, "%s.c" % name)
    with open(src, "w") as fh:
        fh.write(text)
    so = os.path.join(TMP, "%s.so" % name)
    p = subprocess.run([CC, "-O1", "-std=c11", "-fPIC", "-shared", "-I", os.path.join(ROOT, "runtime"),
                        src, "-o", so, "-lm"], capture_output=True, text=True)
    check(p.returncode == 0, "%s kernel compiles: %s" % (name, p.stderr[-400:]))
    return text, Kernel.in_dll(ctypes.CDLL(so), "swim_kernel_n%d" % N)


def arr(size, values=None):
    a = (ctypes.c_double * size)()
    if values is not None:
        for i, v in enumerate(values):
            a[i] = v
    return a


def rel(a, b):
    scale = max((abs(v) for v in b), default=0.0)
    diff = max((abs(x - y) for x, y in zip(a, b)), default=0.0)
    return diff / scale if scale > 0 else diff


def outputs(k, x, v, cs, sn):
    """Every output of every function of kernel k at (x, v, theta), as named lists."""
    out = {}
    Mr, Nc, Md = arr(9), arr(3 * n), arr(n * n)
    k.mass(x, 1.3, 0.9, Mr, Nc, Md)
    out.update(Mr=Mr, Nc=Nc, Md=Md)
    dMr, dNc, dMd = arr(9 * n), arr(3 * n * n), arr(n * n * n)
    check(k.mass_deriv(x, 1.3, 0.9, dMr, dNc, dMd) == 0, "mass_deriv returns 0")
    out.update(dMr=dMr, dNc=dNc, dMd=dMd)
    K, P, g = arr(n * n), arr(3 * n), arr(n)
    check(k.reduced(x, v, 1.3, 0.9, K, P, g) == 0, "reduced returns 0")
    out.update(K=K, P=P, gvv=g)
    dK, G = arr(n * n * n), arr(n * n * n)
    check(k.reduced_deriv(x, 1.3, 0.9, dK, G) == 0, "reduced_deriv returns 0")
    out.update(dK=dK, Gamma=G)
    J, dJ = arr(1), arr(n)
    k.jacobian_circle(x, cs, sn, J, dJ)
    out.update(J=J, dJ=dJ)
    gI = arr(n)
    out["I"] = [k.inertia(x, gI)]
    out["gradI"] = gI
    S = arr(2 * (N + 1) * (n + 3))
    k.boundary_data(x, S)
    out["S"] = S
    return {key: list(val) for key, val in out.items()}


def test_emission():
    straight = kernel_source(N, "t", tabled=False)
    tabled = kernel_source(N, "t", tabled=True)
    check("kernel/sparse_data.h" in tabled and "sparse_boundary_data(x, S);" in tabled,
          "the tabled kernel includes sparse_data.h and calls its loops")
    check("sparse_data.h" not in straight and "S[0][0] = " in straight,
          "the straight-line kernel prints S")
    check(kernel_source(N, "t") == tabled, "N = %d is tabled by default" % N)
    printed = kernel_source(N, "t", tabled=True, loops=False)
    check("kernel/sparse_data.h" in printed and "sparse_boundary_data(x, S);" not in printed
          and "S[0][0] = " in printed and "SWIM_SPARSE_LOOPS" not in printed,
          "the printed tabled kernel prints S and includes sparse_data.h for its partials")
    check("sparse_data.h" not in kernel_source(7, "t"), "N = 7 keeps the straight-line code")


def test_agree():
    _, a = build(False)
    for loops in (True, False):
        agree(a, build(True, loops)[1], "loops" if loops else "printed")


def agree(a, b, what):
    import math
    rng = random.Random(7)
    worst = {}
    for trial in range(6):
        x = [1.0 + 0.3 * rng.random(), 0.2 * rng.random()] + [
            (rng.random() - 0.5) * 0.4 / (i // 2 + 1) ** 2 for i in range(2, n)]
        v = [rng.random() - 0.5 for _ in range(n)]
        theta = 2 * math.pi * rng.random()
        cs = arr(N, [math.cos(m * theta) for m in range(1, N + 1)])
        sn = arr(N, [math.sin(m * theta) for m in range(1, N + 1)])
        oa = outputs(a, arr(n, x), arr(n, v), cs, sn)
        ob = outputs(b, arr(n, x), arr(n, v), cs, sn)
        for key in oa:
            worst[key] = max(worst.get(key, 0.0), rel(ob[key], oa[key]))
    for key, r in sorted(worst.items()):
        print("  N = %d %-6s tabled (%s) vs SymPy's straight-line: max relative difference %.1e"
              % (N, key, what, r))
        check(r <= 1e-13, "%s (%s) agrees to round-off (%.1e)" % (key, what, r))
    check(worst["K"] > 0 or worst["gvv"] > 0 or worst["S"] == 0,
          "the comparison ran on computed values")


if __name__ == "__main__":
    sys.exit(main(globals(), "test_sparse_kernel"))
