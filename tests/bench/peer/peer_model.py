"""An independent NumPy implementation of the swimmer model, the peer that `bench_peer.py` runs
with SciPy's solve_ivp to compare against swim.

Written from Munnier's paper (Sections 2-5) and shared/paper/ERRATA.md only, not from swim's
generator or runtime: the formulas below cite the paper's equations and the errata items.

State y = (x, y, theta, c, c'), c in storage order (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N), the
same order as the columns of swim's trajectory.csv.

The model:
* fluid kinetic energy from the complex form of ERRATA A9: for a generalised velocity
  V = (r*_1, r*_2, omega, c'), g_n = G(c) V (n = 1..N+1) and T_fluid = 1/2 sum 4 pi rho_f/n |g_n|^2,
  so the fluid part of the full mass matrix M(c) (3.14) is 4 pi rho_f Re(G^H diag(1/n) G);
  the body part is diag(m, m, I(c), rho0 pi/(|k|+1)) ((2.9), (2.11), A7);
* K = Md - N^T Mr^-1 N (Section 4.2) and the rigid velocity q* = -Mr^-1 N c' (3.21, C4);
* the Christoffel term of C1, Gamma(c', c') = d/dt(K) c' - 1/2 grad_c (c'^T K c'). With
  E = [-Mr^-1 N; I] and V = E c' one has K = E^T M E, d/dt(K) c' = E^T Mdot V and, because q*
  minimises V^T M V, grad_c(c'^T K c') = grad_c(V^T M V) at fixed V: both come from g and its
  derivatives without forming the derivative tensors of K;
* W1 = 1/2 (c - cref)^T R (c - cref) (B1 with the normalisation of E2) and the barrier
  W2 = eps/(2 alpha) int J^-alpha dtheta with the gradient of B3 (trapezoidal rule, B4);
* K c'' + Gamma + grad W = sum lambda_j G_j - D c' + F(t) (C3), locked coordinates deleted (C2),
  the multipliers from (4.12) with the quadratic terms of C2.

G(c) is linear in c in every column but omega's, which is quadratic: both are tabulated once per
number of modes (construction time, plain loops over the formula of A9); the right-hand side is
then a handful of small dense products.
"""

import numpy as np
from scipy.linalg.lapack import dposv


def mode_of(i):
    """Mode k of storage index i: 0, 1 -> c_1; 2, 3 -> c_-1; ..."""
    return 1 if i < 2 else -(i // 2)


def inv3(a):
    """Inverse of a symmetric 3 x 3 matrix by cofactors (no LAPACK call for so small a system)."""
    (p, q, r), (_, s, u), (_, _, v) = a.tolist()
    c00, c01, c02 = s * v - u * u, r * u - q * v, q * u - r * s
    det = p * c00 + q * c01 + r * c02
    return np.array([[c00, c01, c02], [c01, p * v - r * r, q * r - p * u],
                     [c02, q * r - p * u, p * s - q * q]]) / det


def g_formula(x, v, N):
    """g_n (n = 1..N+1) of ERRATA A9 for shape x and generalised velocity v = (r*_1, r*_2, omega,
    c'), evaluated term by term (construction time only)."""
    c = {mode_of(2 * j): x[2 * j] + 1j * x[2 * j + 1] for j in range(N + 1)}
    u = {0: v[0] + 1j * v[1]}
    u.update({mode_of(2 * j): v[3 + 2 * j] + 1j * v[4 + 2 * j] for j in range(N + 1)})
    omega = v[2]

    def C(k):
        return c.get(k, 0.0)

    g = np.zeros(N + 1, complex)
    for n in range(1, N + 2):
        s = 0.0
        for m, um in u.items():
            s += -0.5 * (um * (m - n) * np.conj(C(m - n)) + np.conj(um) * (m + n) * C(m + n))
        s += 0.5j * omega * n * sum(np.conj(C(p)) * C(p + n) for p in range(-N, 2))
        g[n - 1] = s
    return g


class Scene:
    """A scene's parameters (from a swim scene file's keys, see docs) and its right-hand side."""

    def __init__(self, N, rho0, rhof, free, stiffness, reference, damping=None, eps=0.0,
                 alpha=0.5, nodes=256, forcing=None):
        self.N = N
        nx = self.nx = 2 * (N + 1)
        self.rho0, self.rhof = rho0, rhof
        self.free = np.array(sorted(free), dtype=int)
        self.R = np.asarray(stiffness, float)
        self.cref = np.asarray(reference, float)
        self.D = np.zeros(nx) if damping is None else np.asarray(damping, float)
        self.eps, self.alpha = eps, alpha
        self.forcing = forcing            # None or f(t) -> array of nx
        self.kmode = np.array([mode_of(i) for i in range(nx)], float)
        self.Dw = rho0 * np.pi / (np.abs(self.kmode) + 1.0)       # body weights (2.11), A7
        nF = self.nF = N + 1
        w = 4.0 * np.pi * rhof / np.arange(1, nF + 1)                # 4 pi rho_f / n (A9)
        self.w2 = np.concatenate([w, w])     # G is kept real: rows Re g_1..g_nF, Im g_1..g_nF
        nv = nx + 3
        # Linear columns: L[n, v, l] = dg_n/dx_l for V = e_v, v != omega (omega's column is 0).
        L = np.zeros((nF, nv, nx), complex)
        for v in [0, 1] + list(range(3, nv)):
            V = np.zeros(nv)
            V[v] = 1.0
            for l in range(nx):
                L[:, v, l] = g_formula(np.eye(nx)[l], V, N)
        # Omega's column: g_n = x^T Q_n x with Q_n symmetric (polarisation of a quadratic form).
        Vw = np.zeros(nv)
        Vw[2] = 1.0
        diag = [g_formula(np.eye(nx)[l], Vw, N) for l in range(nx)]
        Q = np.zeros((nF, nx, nx), complex)
        for l in range(nx):
            Q[:, l, l] = diag[l]
            for m in range(l + 1, nx):
                q = 0.5 * (g_formula(np.eye(nx)[l] + np.eye(nx)[m], Vw, N) - diag[l] - diag[m])
                Q[:, l, m] = Q[:, m, l] = q
        Lr = np.concatenate([L.real, L.imag])                         # (2 nF, nv, nx)
        Qr = np.concatenate([Q.real, Q.imag])                         # (2 nF, nx, nx)
        self.Lc = Lr.reshape(2 * nF * nv, nx).copy()                  # G(c) = Lc x (+ omega's)
        self.Ln = Lr.reshape(2 * nF, nv * nx).copy()                  # w^T L in one product
        self.Q2 = 2.0 * Qr.reshape(2 * nF * nx, nx)                   # d(x^T Q x)/dx = 2 Q x
        self.sw = np.sqrt(self.w2)[:, None]
        self.body = np.diag(np.concatenate([[rho0 * np.pi, rho0 * np.pi, 0.0], self.Dw]))
        # Constraints (C2): G1 = (k a_k, k b_k), G2 = (b_k, -a_k)/(|k|+1), on the free coordinates.
        f = self.free
        self.all_free = len(f) == nx
        # contiguous free coordinates (Example 3's c_-1, c_-2) are a slice, not a gather
        self.fsel = slice(f[0], f[-1] + 1) if np.all(np.diff(f) == 1) else f
        self.k_free = self.kmode[f]
        swap = np.zeros((nx, nx))
        for j in range(N + 1):
            swap[2 * j, 2 * j + 1] = 1.0 / (abs(mode_of(2 * j)) + 1)
            swap[2 * j + 1, 2 * j] = -1.0 / (abs(mode_of(2 * j)) + 1)
        self.G2full = swap[f]
        # Barrier nodes (trapezoidal rule on [0, 2 pi), B2-B4), in real form:
        # (Re h, Im h) = A (m a_-m, m b_-m) with h = sum m c_-m conj(z)^(m-1).
        if eps > 0:
            th = 2.0 * np.pi * np.arange(nodes) / nodes
            m = np.arange(1, N + 1)
            Cs, Sn = np.cos(np.outer(th, m - 1)), np.sin(np.outer(th, m - 1))
            self.A = np.block([[Cs, Sn], [-Sn, Cs]])                  # (2 nodes, 2 N)
            self.At = self.A.T.copy()
            self.m2 = np.concatenate([m, m]).astype(float)
            self.nodes = nodes
            self.dth = 2.0 * np.pi / nodes

    # -- pieces --------------------------------------------------------------------------------
    def G(self, x):
        """G(c) in real form: g = G V (rows Re g_n, then Im g_n) for V = (r*_1, r*_2, omega, c');
        and 2 Q x (rows as G's, one column per coordinate)."""
        n2 = 2 * self.nF
        G = (self.Lc @ x).reshape(n2, self.nx + 3)
        Qx2 = (self.Q2 @ x).reshape(n2, self.nx)
        G[:, 2] = 0.5 * (Qx2 @ x)
        return G, Qx2

    def mass(self, x):
        """Full mass matrix M(c) (3.14) of (r*_1, r*_2, omega, c), G and 2 Q x."""
        G, Qx2 = self.G(x)
        Gs = self.sw * G
        M = Gs.T @ Gs + self.body
        M[2, 2] += self.Dw @ (x * x)                 # I(c) (2.11)
        return M, G, Qx2

    def K(self, x):
        M, _, _ = self.mass(x)
        Mr, Nm, Md = M[:3, :3], M[:3, 3:], M[3:, 3:]
        return Md - Nm.T @ np.linalg.solve(Mr, Nm)

    def J(self, x):
        """J on the barrier's nodes (2.4, B2) and (Re h, Im h) stacked."""
        H = self.A @ (self.m2 * np.concatenate([x[2::2], x[3::2]]))
        n = self.nodes
        return x[0] * x[0] + x[1] * x[1] - H[:n] ** 2 - H[n:] ** 2, H

    def W(self, x):
        """W1 + W2 (B1 with E2's 1/2, B2)."""
        d = x - self.cref
        w = 0.5 * d @ (self.R * d)
        if self.eps > 0:
            J, _ = self.J(x)
            w += self.eps / (2 * self.alpha) * self.dth * np.sum(J ** -self.alpha)
        return w

    def gradW(self, x):
        g = self.R * (x - self.cref)
        if self.eps > 0:
            J, H = self.J(x)
            if self.alpha == 0.5:                    # J^-1.5 without a general power
                wJ = self.dth / (J * np.sqrt(J))
            else:
                wJ = self.dth * J ** (-1.0 - self.alpha)
            s0 = np.sum(wJ)
            g[0] -= self.eps * x[0] * s0
            g[1] -= self.eps * x[1] * s0
            # (Re, Im) of int z^(m-1) h J^(-1-alpha) dtheta, m = 1..N (B3)
            t = self.eps * self.m2 * (self.At @ (H * np.concatenate([wJ, wJ])))
            N = self.N
            g[2::2] += t[:N]
            g[3::2] += t[N:]
        return g

    def energies(self, x, xd):
        """(fluid, shape-body, rigid-body kinetic energy, W1 + W2) at (c, c')."""
        M, G, _ = self.mass(x)
        Mr, Nm = M[:3, :3], M[:3, 3:]
        V = np.concatenate([-np.linalg.solve(Mr, Nm @ xd), xd])
        g = G @ V
        fluid = 0.5 * np.sum(self.w2 * g * g)
        shape = 0.5 * np.sum(self.Dw * xd * xd)
        rigid = 0.5 * (self.rho0 * np.pi * (V[0] ** 2 + V[1] ** 2) + (self.Dw @ (x * x)) * V[2] ** 2)
        return fluid, shape, rigid, self.W(x)

    def project_velocity(self, x, xd):
        """l2-orthogonal projection of c' onto G1 . c' = G2 . c' = 0 (ERRATA D5)."""
        f = self.free
        Gc = np.vstack([self.k_free * x[f], self.G2full @ x])
        out = np.zeros_like(xd)
        v = xd[f]
        out[f] = v - Gc.T @ np.linalg.solve(Gc @ Gc.T, Gc @ v)
        return out

    # -- right-hand side ------------------------------------------------------------------------
    def accel(self, t, x, xd):
        """(c'' on all coordinates, q* = (r*_1, r*_2, omega))."""
        nx = self.nx
        n2 = 2 * self.nF
        M, G, Qx2 = self.mass(x)
        Mr, Nm = M[:3, :3], M[:3, 3:]
        P = inv3(Mr) @ Nm                            # Mr^-1 N
        K = M[3:, 3:] - Nm.T @ P
        qs = -P @ xd                                 # (3.21)
        V = np.concatenate([qs, xd])
        omega = qs[2]
        wg = self.w2 * (G @ V)                       # 4 pi rho_f/n g_n
        # With T[n, v, l] = dG[n, v]/dx_l (omega's column apart): Gdot = T c' (+ omega's Q2x c'),
        # dg/dx at fixed V = T V + omega Q2x, and A = wg^T T serves both contractions with wg.
        A = (wg @ self.Ln).reshape(nx + 3, nx)
        Gdot = (self.Lc @ xd).reshape(n2, nx + 3)
        q = Qx2 @ xd
        gdot = Gdot @ V + omega * q                  # d/dt g at fixed V
        MdotV = A @ xd + G.T @ (self.w2 * gdot)
        MdotV[2] += wg @ q + 2.0 * (self.Dw @ (x * xd)) * omega
        # C1: Gamma = d/dt(K) c' - 1/2 grad_c(c'^T K c') = E^T Mdot V - 1/2 grad_c(V^T M V)
        Gamma = MdotV[3:] - P.T @ MdotV[:3] - (V @ A + omega * (wg @ Qx2) + (omega * omega) * self.Dw * x)
        rhs = -Gamma - self.gradW(x) - self.D * xd
        if self.forcing is not None:
            rhs = rhs + self.forcing(t)
        f = self.fsel
        if self.all_free:
            Kf, xf, vf, rf = K, x, xd, rhs
        elif isinstance(f, slice):
            Kf, xf, vf, rf = K[f, f], x[f], xd[f], rhs[f]
        else:
            Kf, xf, vf, rf = K[np.ix_(f, f)], x[f], xd[f], rhs[f]
        Gc = np.vstack([self.k_free * xf, self.G2full @ x])     # (2, nfree)
        _, Y, info = dposv(Kf, np.column_stack([rf, Gc.T]))     # Kf^-1 [rhs, G^T], K > 0 (4.9)
        if info != 0:
            raise np.linalg.LinAlgError("K(c) is not positive definite (dposv info %d)" % info)
        S = Gc @ Y[:, 1:]
        b = -(Gc @ Y[:, 0])
        b[0] -= np.sum(self.k_free * vf * vf)                    # (DG1[c']) . c' (C2)
        det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]              # (4.12), 2 x 2
        l0 = (S[1, 1] * b[0] - S[0, 1] * b[1]) / det
        l1 = (S[0, 0] * b[1] - S[1, 0] * b[0]) / det
        af = Y[:, 0] + l0 * Y[:, 1] + l1 * Y[:, 2]
        if self.all_free:
            return af, qs
        xdd = np.zeros(nx)
        xdd[self.free] = af
        return xdd, qs

    def rhs(self, t, y):
        nx = self.nx
        x = y[3:3 + nx]
        xd = y[3 + nx:]
        xdd, qs = self.accel(t, x, xd)
        th = y[2]
        ct, st = np.cos(th), np.sin(th)
        out = np.empty_like(y)
        out[0] = ct * qs[0] - st * qs[1]               # dr/dt = R(theta) r* (3.21)
        out[1] = st * qs[0] + ct * qs[1]
        out[2] = qs[2]
        out[3:3 + nx] = xd
        out[3 + nx:] = xdd
        return out


# -- scenes from swim's scene files -------------------------------------------------------------


def coord_names(N):
    names = ["a1", "b1"]
    for j in range(1, N + 1):
        names += ["am%d" % j, "bm%d" % j]
    return names


def load_scene(path, nodes=256):
    """(Scene, y0, t_end) from a swim scene file (keys as docs/ describe them)."""
    import tomllib
    with open(path, "rb") as fh:
        s = tomllib.load(fh)
    N = int(s["model"]["modes"])
    nx = 2 * (N + 1)
    names = coord_names(N)
    free = s["shape"].get("free", "all")
    free_idx = list(range(nx)) if free == "all" else [names.index(n) for n in free]
    el = s.get("elastic", {})
    bar = s.get("barrier", {})
    damp = s.get("damping", {})
    for key in ("forcing", "control", "stroke"):
        if key in s:
            raise ValueError("%s: [%s] is not modelled by the peer" % (path, key))
    sc = Scene(N, float(s["model"]["rho0"]), float(s["model"]["rhof"]), free_idx,
               el.get("stiffness", [0.0] * nx), el.get("reference", [0.0] * nx),
               damping=damp.get("diagonal"), eps=float(bar.get("epsilon", 0.0)),
               alpha=float(bar.get("alpha", 0.5)), nodes=nodes)
    c0 = np.array(s["shape"]["c0"], float)
    dc0 = np.array(s["shape"]["dc0"], float)
    if s.get("run", {}).get("project_initial", False):
        dc0 = sc.project_velocity(c0, dc0)
    y0 = np.concatenate([[0.0, 0.0, 0.0], c0, dc0])
    return sc, y0, float(s.get("run", {}).get("t_end", 10.0))
