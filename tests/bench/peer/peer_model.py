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


def mode_of(i):
    """Mode k of storage index i: 0, 1 -> c_1; 2, 3 -> c_-1; ..."""
    return 1 if i < 2 else -(i // 2)


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
        self.w = 4.0 * np.pi * rhof / np.arange(1, nF + 1)          # 4 pi rho_f / n (A9)
        # Linear columns: L[n, v, l] with v over (r*_1, r*_2, c'_0 .. c'_{nx-1}) (omega removed).
        lin_v = [0, 1] + list(range(3, 3 + nx))
        self.L = np.zeros((nF, len(lin_v), nx), complex)
        for iv, vv in enumerate(lin_v):
            V = np.zeros(3 + nx)
            V[vv] = 1.0
            for l in range(nx):
                xl = np.zeros(nx)
                xl[l] = 1.0
                self.L[:, iv, l] = g_formula(xl, V, N)
        # Omega's column: g_n = x^T Q_n x with Q_n symmetric (polarisation of a quadratic form).
        Vw = np.zeros(3 + nx)
        Vw[2] = 1.0
        diag = [g_formula(np.eye(nx)[l], Vw, N) for l in range(nx)]
        Q = np.zeros((nF, nx, nx), complex)
        for l in range(nx):
            Q[:, l, l] = diag[l]
            for m in range(l + 1, nx):
                q = 0.5 * (g_formula(np.eye(nx)[l] + np.eye(nx)[m], Vw, N) - diag[l] - diag[m])
                Q[:, l, m] = Q[:, m, l] = q
        self.Q2 = 2.0 * Q.reshape(nF * nx, nx)      # d(x^T Q x)/dx = 2 Q x
        self.Lx = self.L.transpose(0, 2, 1).reshape(nF * nx, len(lin_v))   # for dg/dx at fixed V
        self.Lc = self.L.reshape(nF * len(lin_v), nx)                       # for G(c)
        # Constraints (C2): G1 = (k a_k, k b_k), G2 = (b_k, -a_k)/(|k|+1), on the free coordinates.
        f = self.free
        self.k_free = self.kmode[f]
        swap = np.zeros((nx, nx))
        for j in range(N + 1):
            swap[2 * j, 2 * j + 1] = 1.0 / (abs(mode_of(2 * j)) + 1)
            swap[2 * j + 1, 2 * j] = -1.0 / (abs(mode_of(2 * j)) + 1)
        self.G2full = swap[f]
        # Barrier nodes (trapezoidal rule on [0, 2 pi), B2-B4): conj(z)^(m-1), m = 1..N.
        if eps > 0:
            th = 2.0 * np.pi * np.arange(nodes) / nodes
            m = np.arange(1, N + 1)
            self.Zc = np.exp(-1j * np.outer(th, m - 1))                  # (nodes, N)
            self.Zt = np.conj(self.Zc).T.copy()                           # z^(m-1), (N, nodes)
            self.m = m.astype(float)
            self.dth = 2.0 * np.pi / nodes

    # -- pieces --------------------------------------------------------------------------------
    def G(self, x):
        """G(c): g = G V for V = (r*_1, r*_2, omega, c'), shape (N+1, 3+nx); and 2 Q x."""
        nF, nx = self.nF, self.nx
        lin = (self.Lc @ x).reshape(nF, nx + 2)
        Qx2 = (self.Q2 @ x).reshape(nF, nx)
        G = np.empty((nF, nx + 3), complex)
        G[:, :2] = lin[:, :2]
        G[:, 2] = 0.5 * (Qx2 @ x)
        G[:, 3:] = lin[:, 2:]
        return G, Qx2

    def mass(self, x):
        """Full mass matrix M(c) (3.14) of (r*_1, r*_2, omega, c), 2 Q x and G."""
        G, Qx2 = self.G(x)
        M = np.real(np.conj(G.T) @ (self.w[:, None] * G))
        M[0, 0] += self.rho0 * np.pi
        M[1, 1] += self.rho0 * np.pi
        M[2, 2] += self.Dw @ (x * x)
        M[3:, 3:] += np.diag(self.Dw)
        return M, G, Qx2

    def K(self, x):
        M, _, _ = self.mass(x)
        Mr, Nm, Md = M[:3, :3], M[:3, 3:], M[3:, 3:]
        return Md - Nm.T @ np.linalg.solve(Mr, Nm)

    def J(self, x):
        """J on the barrier's nodes (2.4, B2)."""
        cm = x[2::2] + 1j * x[3::2]
        h = self.Zc @ (self.m * cm)
        return x[0] ** 2 + x[1] ** 2 - np.abs(h) ** 2, h

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
            J, h = self.J(x)
            wJ = self.dth * J ** (-1.0 - self.alpha)
            s0 = np.sum(wJ)
            g[0] -= self.eps * x[0] * s0
            g[1] -= self.eps * x[1] * s0
            t = self.Zt @ (h * wJ)                   # int z^(m-1) h J^(-1-alpha), m = 1..N
            g[2::2] += self.eps * self.m * t.real
            g[3::2] += self.eps * self.m * t.imag
        return g

    def energies(self, x, xd):
        """(fluid, shape-body, rigid-body kinetic energy, W1 + W2) at (c, c')."""
        M, G, _ = self.mass(x)
        Mr, Nm = M[:3, :3], M[:3, 3:]
        V = np.concatenate([-np.linalg.solve(Mr, Nm @ xd), xd])
        g = G @ V
        fluid = 0.5 * np.sum(self.w * np.abs(g) ** 2)
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
        nF, nx = self.nF, self.nx
        M, G, Qx2 = self.mass(x)
        Mr, Nm = M[:3, :3], M[:3, 3:]
        P = np.linalg.solve(Mr, Nm)                  # Mr^-1 N
        K = M[3:, 3:] - Nm.T @ P
        qs = -P @ xd                                 # (3.21)
        V = np.concatenate([qs, xd])
        omega = qs[2]
        Vlin = np.concatenate([V[:2], xd])
        wg = self.w * (G @ V)                        # 4 pi rho_f/n g_n
        # dg/dc at fixed V, and its contraction with c' (= Gdot V)
        Jx = (self.Lx @ Vlin).reshape(nF, nx) + omega * Qx2
        gdot = Jx @ xd
        Gdot_lin = (self.Lc @ xd).reshape(nF, nx + 2)
        Gdot = np.empty((nF, nx + 3), complex)
        Gdot[:, :2] = Gdot_lin[:, :2]
        Gdot[:, 2] = Qx2 @ xd
        Gdot[:, 3:] = Gdot_lin[:, 2:]
        MdotV = np.real(np.conj(Gdot.T) @ wg + np.conj(G.T) @ (self.w * gdot))
        MdotV[2] += 2.0 * (self.Dw @ (x * xd)) * omega
        half_grad = np.real(np.conj(Jx.T) @ wg) + omega * omega * self.Dw * x
        Gamma = MdotV[3:] - P.T @ MdotV[:3] - half_grad          # C1
        rhs = -Gamma - self.gradW(x) - self.D * xd
        if self.forcing is not None:
            rhs = rhs + self.forcing(t)
        f = self.free
        Kf = K[np.ix_(f, f)]
        Gc = np.vstack([self.k_free * x[f], self.G2full @ x])   # (2, nfree)
        quad = np.array([np.sum(self.k_free * xd[f] ** 2), 0.0])
        cho = np.linalg.cholesky(Kf)
        B = np.column_stack([rhs[f], Gc.T])
        Y = np.linalg.solve(cho.T, np.linalg.solve(cho, B))      # Kf^-1 [rhs, G^T]
        lam = np.linalg.solve(Gc @ Y[:, 1:], -(Gc @ Y[:, 0]) - quad)   # (4.12)
        xdd = np.zeros(nx)
        xdd[f] = Y[:, 0] + Y[:, 1:] @ lam
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
NAMES = None


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
