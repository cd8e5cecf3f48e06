"""Symbolic model of the N-mode swimmer (Munnier, sections 2-4, with shared/paper/ERRATA.md).

Everything the kernels need is built here as SymPy expressions; nothing here prints C.

Coordinates. The real shape vector is x = (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N), c_k = a_k + i b_k.
The generalized velocity of the whole system is (r*_1, r*_2, omega, xdot).

Boundary data. Every elementary potential (3.6) is determined by a pair of real sequences
s = (s1_j, s2_j), j = 1..N+1 (all sequences vanish for j > N+1, ERRATA A6). Stack them as the
columns of a matrix S with 2(N+1) rows (row 2(j-1) holds s1_j, row 2(j-1)+1 holds s2_j) and
3 + n columns in the order of the generalized velocity: mu_0, nu_0, alpha, then mu_k for a_k and
nu_k for b_k. With the weighted product u.s = sum_j j (u1_j s1_j + u2_j s2_j) of section 3.2.5,
the whole fluid mass matrix is the Gram matrix

    M_fluid = rho_f pi S^T W S,    W = diag(j),                              (ERRATA A9)

and the full mass matrix (3.14) is M = M_fluid + rho_0 pi diag(1, 1, I(c), 1/(|k|+1) ...).
The columns mu_k, nu_k are linear in x and alpha is quadratic, so S and all of its derivatives
are small sparse polynomials: only they are differentiated symbolically. The Gram products,
the Schur complement K = Md - N^T Mr^-1 N and the Christoffel symbol are assembled from them by
the exact product rule in the emitted C (see template.py).
"""

import sympy as sp


def _diff_polynomial(e, sym):
    """d e / d sym for an expanded polynomial, term by term: the entries of S are multilinear
    (sym appears to the first power), which this handles without SymPy's general machinery;
    any other term goes through sp.diff."""
    out = []
    for term in sp.Add.make_args(e):
        factors = list(sp.Mul.make_args(term))
        if sym in factors:
            factors.remove(sym)
            if not any(f.has(sym) for f in factors):
                out.append(sp.Mul(*factors))
                continue
            factors.append(sym)
        if term.has(sym):
            out.append(sp.diff(term, sym))
    return sp.Add(*out)


def diff(e, sym):
    """sp.diff(e, sym), with the common case of a symbol e does not contain answered without
    SymPy's machinery (the same zero; the kernels' Jacobian tables ask O(n^2) such questions)."""
    if sym not in e.free_symbols:
        return sp.Integer(0)
    return sp.diff(e, sym)


class SwimmerModel:
    """Symbols and exact expressions for one mode count N."""

    def __init__(self, modes, free=None, zero=()):
        """`free`: indices of the coordinates that move (default: all); the others are locked.
        `zero`: locked coordinates whose value is 0, folded into the expressions. Locked
        coordinates that are not in `zero` stay symbols (run-time parameters)."""
        if modes < 0:
            raise ValueError("mode count must be >= 0")
        self.N = modes
        self.nfull = 2 * (modes + 1)      # real shape coordinates
        self.free = list(range(self.nfull)) if free is None else sorted(free)
        self.zero = set(zero)
        if self.zero & set(self.free):
            raise ValueError("a coordinate cannot be both free and locked at zero")
        self.n = len(self.free)           # velocity coordinates carried by the kernel
        self.ncols = 3 + self.n           # columns of S: rigid velocities, then free coordinates
        self.x = sp.symbols("x0:%d" % self.nfull, real=True)
        self._xi = {s: i for i, s in enumerate(self.x)}   # a dict: tuple.index compares with ==
        self._free_at = {i: r for r, i in enumerate(self.free)}
        self.ks = [1] + [-m for m in range(1, modes + 1)]
        self._S = None
        self._rows = None
        self._dS = None
        self._mono = None

    # -- shape coefficients -------------------------------------------------------------
    def index(self, k):
        """Storage index of a_k (b_k is the next one)."""
        return 0 if k == 1 else 2 * (-k)

    def coord(self, i):
        return sp.Integer(0) if i in self.zero else self.x[i]

    def a(self, k):
        return self.coord(self.index(k)) if k in self.ks else sp.Integer(0)

    def b(self, k):
        return self.coord(self.index(k) + 1) if k in self.ks else sp.Integer(0)

    # -- the sequences of (3.7)-(3.8), corrected by ERRATA A5-A6 ------------------------
    def mu(self, k, j):
        p, q = sp.Rational(k, j) + 1, sp.Rational(k, j) - 1
        return (p * self.a(k + j) + q * self.a(k - j),
                p * self.b(k + j) - q * self.b(k - j))

    def nu(self, k, j):
        p, q = sp.Rational(k, j) + 1, sp.Rational(k, j) - 1
        return (p * self.b(k + j) + q * self.b(k - j),
                -p * self.a(k + j) + q * self.a(k - j))

    def alpha(self, j):
        s1 = sum((self.a(i) * self.b(i + j) - self.b(i) * self.a(i + j) for i in self.ks),
                 sp.Integer(0))
        s2 = -sum((self.a(i) * self.a(i + j) + self.b(i) * self.b(i + j) for i in self.ks),
                  sp.Integer(0))
        return (s1, s2)

    def column(self, col, j):
        if col == 0:
            return self.mu(0, j)
        if col == 1:
            return self.nu(0, j)
        if col == 2:
            return self.alpha(j)
        r = self.free[col - 3]
        k = 1 if r < 2 else -(r // 2)
        return self.mu(k, j) if r % 2 == 0 else self.nu(k, j)

    def S(self):
        """Boundary-data matrix as a list of rows of expanded expressions. Rows that vanish
        identically (high Fourier modes when the high coordinates are locked at zero) are
        dropped; weight(row) gives the j of each kept row."""
        if self._S is None:
            rows, keep = [], []
            for j in range(1, self.N + 2):
                for part in (0, 1):
                    row = [sp.expand(self.column(col, j)[part]) for col in range(self.ncols)]
                    if any(e != 0 for e in row):
                        rows.append(row)
                        keep.append(j)
            self._S, self._rows = rows, keep
        return self._S

    @property
    def nrows(self):
        return len(self.S())

    def weight(self, row):
        """The factor j of the weighted product for a row of S."""
        self.S()
        return self._rows[row]

    def free_position(self, sym):
        """Position in the velocity vector of the coordinate `sym`, or None if it is locked."""
        return self._free_at.get(self._xi[sym])

    def dS(self):
        """Exact partial derivatives with respect to the free coordinates:
        dict (r, row, col) -> d S[row][col] / d x_free[r], non-zeros only."""
        if self._dS is None:
            S = self.S()
            out = {}
            for row in range(self.nrows):
                for col in range(self.ncols):
                    e = S[row][col]
                    if e == 0:
                        continue
                    for sym in sorted(e.free_symbols, key=self._xi.__getitem__):
                        r = self.free_position(sym)
                        if r is None:
                            continue
                        d = _diff_polynomial(e, sym)
                        if d != 0:
                            out[(r, row, col)] = d
            self._dS = out
        return self._dS

    def second_dS(self):
        """Exact second partial derivatives with respect to the free coordinates:
        dict (row, col, r, s) -> d^2 S[row][col] / d x_free[r] d x_free[s], non-zeros only.
        Every column but alpha is linear in x and alpha is quadratic, so these are constants."""
        out = {}
        for (r, row, col), d in self.dS().items():
            for sym in sorted(d.free_symbols, key=self._xi.__getitem__):
                s = self.free_position(sym)
                if s is None:
                    continue
                d2 = _diff_polynomial(d, sym)
                if d2 != 0:
                    out[(row, col, r, s)] = d2
        return out

    def directional_dS(self, v):
        """D_v S = sum_r v_r dS/dx_r, as rows of expressions in x and the symbols v."""
        terms = [[[] for _ in range(self.ncols)] for _ in range(self.nrows)]
        for (r, row, col), d in self.dS().items():
            terms[row][col].append(v[r] * d)
        return [[sp.Add(*t) for t in row] for row in terms]   # one Add: sums are built once

    def bilinear_gradient(self, w, X):
        """Gradient in x of f = sum_{row,col} w_row S[row][col] X_col at fixed w, X.

        With w = W S X this is (S X)^T W (d_i S) X, so that the identity
        d_i (v^T K v) = X^T (d_i M) X at fixed X = (-Mr^-1 N v, v) needs no tensor.
        """
        terms = [[] for _ in range(self.n)]
        for (r, row, col), d in self.dS().items():
            terms[r].append(w[row] * X[col] * d)
        return [sp.Add(*t) for t in terms]

    # -- body terms (2.11), (2.17) ------------------------------------------------------
    def inertia_sum(self):
        """sum_k |c_k|^2 / (|k| + 1); the moment of inertia (2.11) is pi rho0 times this."""
        return sum(((self.a(k) ** 2 + self.b(k) ** 2) / (abs(k) + 1) for k in self.ks),
                   sp.Integer(0))

    def gradient(self, expr):
        """Partial derivatives of expr with respect to the free coordinates."""
        return [diff(expr, self.x[i]) for i in self.free]

    def hessian(self, expr):
        """Second partial derivatives of expr with respect to the free coordinates:
        dict (r, s) -> d^2 expr / d x_free[r] d x_free[s], non-zeros only."""
        out = {}
        for r, dr in enumerate(self.gradient(expr)):
            for s, i in enumerate(self.free):
                d2 = diff(dr, self.x[i])
                if d2 != 0:
                    out[(r, s)] = d2
        return out

    def mode_of(self, i):
        """The mode k of real coordinate i (a_k or b_k)."""
        return 1 if i < 2 else -(i // 2)

    def body_shape_weights(self):
        """Diagonal of the body part of Md over pi rho0: 1/(|k|+1) (ERRATA A7), free coordinates."""
        return [sp.Rational(1, abs(self.mode_of(i)) + 1) for i in self.free]

    # -- J on the unit circle (2.4) with ERRATA B2 ----------------------------------------
    def jacobian_circle(self, cs, sn):
        """J = |c_1|^2 - |h|^2, h = sum_{m=1}^N m c_-m conj(z)^(m-1), with z = e^{i theta}
        and cs[m] = cos(m theta), sn[m] = sin(m theta)."""
        re_h = sp.Integer(0)
        im_h = sp.Integer(0)
        for m in range(1, self.N + 1):
            a, b = self.a(-m), self.b(-m)
            re_h += m * (a * cs[m - 1] + b * sn[m - 1])
            im_h += m * (b * cs[m - 1] - a * sn[m - 1])
        return self.a(1) ** 2 + self.b(1) ** 2 - re_h ** 2 - im_h ** 2

    # -- S as a table of monomials (large kernels: emit.py, kernel/sparse_data.h) -----------
    def S_monomials(self):
        """S as a sparse polynomial table: a list of (row, col, terms) for the non-zero entries,
        terms = [(coefficient, i, k)] meaning coefficient * x_i * x_k, k = None for a linear
        term (every entry is linear in x except alpha's, which are quadratic: section 3.2)."""
        if self._mono is not None:
            return self._mono
        out = []
        for row, entries in enumerate(self.S()):
            for col, e in enumerate(entries):
                if e == 0:
                    continue
                terms = []
                for term in sp.Add.make_args(e):
                    c, rest = term.as_coeff_Mul()
                    idx = []
                    for f in sp.Mul.make_args(rest):
                        if f.is_Pow and f.exp == 2 and f.base in self._xi:
                            idx += [self._xi[f.base]] * 2
                        elif f in self._xi:
                            idx.append(self._xi[f])
                        elif f != 1:
                            raise ValueError("S[%d][%d] is not a polynomial of degree <= 2 in x"
                                             % (row, col))
                    if not c.is_Rational or not 1 <= len(idx) <= 2:
                        raise ValueError("S[%d][%d] is not a homogeneous polynomial of degree 1 "
                                         "or 2 in x" % (row, col))
                    terms.append((c, idx[0], idx[1] if len(idx) == 2 else None))
                out.append((row, col, terms))
        self._mono = out
        return out

    def monomial_partials(self, i, k):
        """The first partials of x_i x_k (k = None: of x_i) with respect to the free
        coordinates: [(r, j)] meaning d/dx_free[r] = x_j (j = None: 1), locked ones left out."""
        out = []
        ri = self.free_position(self.x[i])
        if k is None:
            return [(ri, None)] if ri is not None else []
        rk = self.free_position(self.x[k])
        if ri is not None:
            out.append((ri, k))
        if rk is not None:
            out.append((rk, i))   # i == k: twice, d/dx_i x_i^2 = 2 x_i
        return out

    def second_dS_monomials(self):
        """second_dS() from S_monomials(), without differentiating expressions:
        dict (row, col, r, s) -> constant, non-zeros only."""
        out = {}
        for row, col, terms in self.S_monomials():
            for c, i, k in terms:
                if k is None:
                    continue
                ri, rk = self.free_position(self.x[i]), self.free_position(self.x[k])
                if ri is None or rk is None:
                    continue
                for key in ((row, col, ri, rk), (row, col, rk, ri)):
                    out[key] = out.get(key, 0) + c
        return {key: c for key, c in out.items() if c != 0}
