"""C text of the generated files: the contract header, and the fixed-size assembly that every
kernel shares (Gram products, 3x3 Cholesky, Schur complement, product-rule derivatives).

The symbolic pieces (S, its derivatives, J, the inertia) are pasted in by emit.py. Sizes are
compile-time constants in every kernel, so loops have fixed trip counts the compiler unrolls
and vectorizes; matrix products stay loops rather than scalar expansions (scalar expansion of
dense algebra makes straight-line code that compilers choke on).
"""

from string import Template

HEADER = """\
/* swim_kernel.h -- contract between the generated kernels and the runtime.
 *
 * $banner
 *
 * Conventions (Munnier's model with shared/paper/ERRATA.md):
 *   x  = (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N), n = 2(N+1) real shape coordinates;
 *   generalized rigid velocity q* = (r*_1, r*_2, omega) in the body frame;
 *   matrices are row-major; rho0 = body density, rhof = fluid density (run-time values).
 *   Mr (3x3), Nc (3xn), Md (nxn) are the blocks of the mass matrix (3.14), with ERRATA A9;
 *   K = Md - Nc^T Mr^-1 Nc is the reduced mass matrix (section 4.1.2);
 *   Gamma[i][j][l] = (d_l K_ij + d_j K_il - d_i K_jl)/2, so that
 *   <Gamma(c), v, v>_i = sum_jl Gamma[i][j][l] v_j v_l = [D_v(K v)]_i - d_i(v^T K v)/2 (ERRATA C1).
 * The caller owns every array; kernels allocate nothing except reduced_deriv (freed before it returns).
 */
#ifndef SWIM_KERNEL_H
#define SWIM_KERNEL_H

#define SWIM_KERNEL_ABI 3
#define SWIM_KERNEL_MAX_MODES 20

typedef struct swim_kernel {
    int modes;  /* N */
    int dim;    /* n = 2(N+1) */
    /* Mr, Nc, Md at shape x; any output may be NULL. */
    void (*mass)(const double *x, double rho0, double rhof, double *Mr, double *Nc, double *Md);
    /* Partial derivatives with respect to x_r, stored as slice r: dMr[r*9 + ...],
     * dNc[r*3n + ...], dMd[r*n*n + ...]; any output may be NULL.
     * Returns 0, or -2 when out of memory. */
    int (*mass_deriv)(const double *x, double rho0, double rhof,
                      double *dMr, double *dNc, double *dMd);
    /* K (nxn, exactly symmetric), P = -Mr^-1 Nc (3xn, may be NULL) and, when v is not NULL,
     * gvv = <Gamma(c), v, v> (n) computed without forming the tensor.
     * Returns 0, or -1 when Mr is not positive definite. */
    int (*reduced)(const double *x, const double *v, double rho0, double rhof,
                   double *K, double *P, double *gvv);
    /* dK (slice r = d K / d x_r, n*n*n) and Gamma (n*n*n, [i][j][l]); either may be NULL.
     * Returns 0, -1 when Mr is not positive definite, -2 when out of memory. */
    int (*reduced_deriv)(const double *x, double rho0, double rhof, double *dK, double *Gamma);
    /* J(c) at z = e^{i theta} on the unit circle (2.4) and its gradient dJ (n, may be NULL);
     * cs[m] = cos(m theta), sn[m] = sin(m theta) for m = 0 .. N-1 (unused when N = 0). */
    void (*jacobian_circle)(const double *x, const double *cs, const double *sn,
                            double *J, double *dJ);
    /* Trapezoidal sums for W2 over Q nodes (tables cs, sn as for jacobian_circle, row q for node
     * q): *sum = sum_q J^-alpha, gsum (may be NULL) = sum_q J^(-1-alpha) dJ, *jlow = smallest J.
     * Returns 0, or -1 as soon as J <= 0 at a node. The runtime scales them (model/shape.c). */
    int (*barrier_sums)(const double *x, const double *cs, const double *sn, int Q, double alpha,
                        double *sum, double *gsum, double *jlow);
    /* sum_k |c_k|^2/(|k|+1) and its gradient (may be NULL); I(c) = pi rho0 times it (2.11). */
    double (*inertia)(const double *x, double *grad);
    /* S(x), 2(N+1) x (3+n) row-major: column p holds the Fourier data (s1_j, s2_j), j = 1..N+1,
     * of the potential of velocity component p (r*_1, r*_2, omega, x_0, ...). For a generalized
     * velocity X the fluid potential is xi = sum_j (-(S X)_{2j-2} cos j theta
     * + (S X)_{2j-1} sin j theta) r^-j (ERRATA A4). */
    void (*boundary_data)(const double *x, double *S);
} swim_kernel;

/* Codes returned by right-hand sides (generic: runtime/model/dynamics.c; scene kernels). */
enum { SWIM_RHS_OK = 0, SWIM_RHS_ENAN, SWIM_RHS_EBARRIER, SWIM_RHS_EMASS, SWIM_RHS_ECONSTRAINT };

/* Run-time parameters of a scene kernel. Vectors have the full length 2(N+1). */
typedef struct swim_scene_params {
    double rho0, rhof;
    const double *x_locked;     /* values of the locked coordinates (free entries ignored) */
    const double *stiffness, *reference, *damping, *direction;
    /* grad W2 on the kernel's coordinates at x (quadrature done by the runtime, which calls
     * back the kernel's barrier_sums); 0, or SWIM_RHS_EBARRIER when J <= 0 at a node. */
    int (*barrier)(const double *x, double *grad, void *ctx);
    void *barrier_ctx;
} swim_scene_params;

/* A kernel specialized to one scene structure (issue 5): it carries only the free coordinates.
 * State y = (r_1, r_2, theta, c_free, cdot_free, work), as in runtime/model/dynamics.h. */
typedef struct swim_scene_kernel {
    int abi;                    /* SWIM_KERNEL_ABI */
    int modes, nfull, nfree;
    const int *free_index;      /* nfree indices into the full shape vector */
    const char *structure;      /* the structure key it was generated for */
    int (*rhs)(double t, const double *y, double *dydt, const swim_scene_params *p);
    /* barrier_sums as in swim_kernel, gradient on the free coordinates (NULL without a barrier) */
    int (*barrier_sums)(const double *x, const double *cs, const double *sn, int Q, double alpha,
                        double *sum, double *gsum, double *jlow);
} swim_scene_kernel;

/* The kernel for N modes among those linked in, or NULL. */
const swim_kernel *swim_kernel_find(int modes);
/* Mode counts linked in, ascending; returns how many (at most cap written). */
int swim_kernel_list(int *modes, int cap);

#endif
"""

TABLE = Template("""\
/* swim_kernel_table.c -- the kernels linked into this build.
 *
 * $banner
 */
#include <stddef.h>
#include "swim_kernel.h"

$externs

static const swim_kernel *const table[] = {$entries};

const swim_kernel *swim_kernel_find(int modes)
{
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (table[i]->modes == modes)
            return table[i];
    return NULL;
}

int swim_kernel_list(int *modes, int cap)
{
    int count = (int)(sizeof table / sizeof table[0]);
    for (int i = 0; i < count && i < cap; i++)
        modes[i] = table[i]->modes;
    return count;
}
""")

# The pieces below are joined by emit.py: a generic kernel uses all of them; a scene kernel
# (issue 5) uses the symbolic core, the reduced assembly and SCENE_RHS.
KERNEL_HEAD = Template("""\
/* $filename -- $what
 *
 * $banner
 *
 * Velocity coordinates ($n): $columns.
 * S is the $R x $P boundary-data matrix of generator/swimgen/model.py (rows: Fourier modes j of
 * the potentials, columns: r*_1, r*_2, omega, then the velocity coordinates).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "swim_kernel.h"

#define NFULL $nfull   /* length of the shape vector x */
#define NX $n      /* velocity coordinates carried by this kernel */
#define NR $R
#define NP $P
#define KPI 3.14159265358979323846

""")

SYMBOLIC_CORE = Template("""\
/* ---- symbolic pieces (SymPy) ---------------------------------------------------------- */

/* S(x): the sequences mu_0, nu_0, alpha, mu_k, nu_k of (3.7)-(3.8), ERRATA A5-A6. */
static void boundary_data(const double *x, double S[NR][NP])
{
    memset(S, 0, sizeof(double) * NR * NP);
$S_body
}

/* D_v S = sum_r v_r dS/dx_r. */
static void boundary_data_dir(const double *x, const double *v, double D[NR][NP])
{
    memset(D, 0, sizeof(double) * NR * NP);
$D_body
}

/* g_i = sum_{row,col} w_row dS[row][col]/dx_i X_col. */
static void boundary_data_bigrad(const double *x, const double *w, const double *X, double *g)
{
$G_body
}

static double inertia(const double *x, double *grad)
{
    double I;
$I_body
    return I;
}

/* Body part of Md over pi rho0: 1/(|k|+1) (ERRATA A7). */
static const double body_shape[NX] = {$bodyw};

""")

SYMBOLIC_DERIV = Template("""\
/* dS[r][row][col] = dS[row][col]/dx_r (zero entries are not written: caller clears). */
static void boundary_data_deriv(const double *x, double *dS)
{
$dS_body
}

""")

SYMBOLIC_JACOBIAN = Template("""\
static void jacobian_circle(const double *x, const double *cs, const double *sn,
                            double *J, double *dJ)
{
$J_body
    if (dJ) {
$dJ_body
    }
}


static int barrier_sums(const double *x, const double *cs, const double *sn, int Q, double alpha,
                        double *sum, double *gsum, double *jlow)
{
    const int w = NFULL / 2 - 1 > 0 ? NFULL / 2 - 1 : 1;   /* max(N, 1) columns per node */
    double s = 0.0, lo = INFINITY, dJ[NX], J;
    if (gsum)
        for (int i = 0; i < NX; i++) gsum[i] = 0.0;
    for (int q = 0; q < Q; q++) {
        jacobian_circle(x, cs + (size_t)q * w, sn + (size_t)q * w, &J, gsum ? dJ : NULL);
        if (J < lo) lo = J;
        if (!(J > 0.0)) {
            *jlow = lo;
            return -1;
        }
        /* J^-alpha; alpha = 1/2 and 1 avoid pow() on the hot path */
        const double ja = alpha == 0.5 ? 1.0 / sqrt(J) : alpha == 1.0 ? 1.0 / J : pow(J, -alpha);
        s += ja;
        if (gsum) {
            const double t = ja / J;
            for (int i = 0; i < NX; i++) gsum[i] += t * dJ[i];
        }
    }
    *sum = s;
    *jlow = lo;
    return 0;
}
""")

ASSEMBLY_REDUCED = Template("""\
/* ---- assembly (fixed-size loops) ------------------------------------------------------ */

typedef struct {
    double S[NR][NP];   /* boundary data */
    double U[NR][NX];   /* S E with E = [P; I]: data of the reduced velocities */
    double P[3][NX];    /* -Mr^-1 Nc */
    double Mr[9], Nc[3 * NX], Ic, gI[NX];
} work_t;

/* The factor j of the weighted product u.s = sum_j j (u1_j s1_j + u2_j s2_j), per row of S. */
static const double weight[NR] = {$weights};

/* M = rho_f pi S^T W S + rho_0 pi diag(1, 1, I, 1/(|k|+1)) restricted to the rigid rows. */
static void rigid_blocks(work_t *w, double f, double b)
{
    double acc[3][NP];
    for (int p = 0; p < 3; p++) {
        double row[NP] = {0.0};   /* one output row held in registers across the sum over r */
        for (int r = 0; r < NR; r++) {
            const double t = f * weight[r] * w->S[r][p];
            for (int q = 0; q < NP; q++)
                row[q] += t * w->S[r][q];
        }
        memcpy(acc[p], row, sizeof row);
    }
    for (int p = 0; p < 3; p++) {
        for (int q = 0; q < 3; q++)
            w->Mr[3 * p + q] = acc[p < q ? p : q][p < q ? q : p];  /* exactly symmetric */
        for (int k = 0; k < NX; k++)
            w->Nc[NX * p + k] = acc[p][3 + k];
    }
    w->Mr[0] += b;
    w->Mr[4] += b;
    w->Mr[8] += b * w->Ic;
}

/* P = -Mr^-1 Nc by a 3x3 Cholesky factorization; -1 if Mr is not positive definite. */
static int schur_factor(work_t *w)
{
    const double *M = w->Mr;
    double l00 = M[0];
    if (!(l00 > 0.0)) return -1;
    l00 = sqrt(l00);
    double l10 = M[3] / l00, l20 = M[6] / l00;
    double l11 = M[4] - l10 * l10;
    if (!(l11 > 0.0)) return -1;
    l11 = sqrt(l11);
    double l21 = (M[7] - l20 * l10) / l11;
    double l22 = M[8] - l20 * l20 - l21 * l21;
    if (!(l22 > 0.0)) return -1;
    l22 = sqrt(l22);
    for (int k = 0; k < NX; k++) {
        double y0 = w->Nc[k] / l00;
        double y1 = (w->Nc[NX + k] - l10 * y0) / l11;
        double y2 = (w->Nc[2 * NX + k] - l20 * y0 - l21 * y1) / l22;
        double z2 = y2 / l22;
        double z1 = (y1 - l21 * z2) / l11;
        double z0 = (y0 - l10 * z1 - l20 * z2) / l00;
        w->P[0][k] = -z0;
        w->P[1][k] = -z1;
        w->P[2][k] = -z2;
    }
    for (int r = 0; r < NR; r++)
        for (int k = 0; k < NX; k++)
            w->U[r][k] = w->S[r][3 + k] + w->S[r][0] * w->P[0][k] + w->S[r][1] * w->P[1][k]
                       + w->S[r][2] * w->P[2][k];
    return 0;
}

static int setup(const double *x, double rho0, double rhof, work_t *w)
{
    boundary_data(x, w->S);
    w->Ic = inertia(x, w->gI);
    rigid_blocks(w, rhof * KPI, rho0 * KPI);
    return schur_factor(w);
}

/* K = E^T M E = rho_f pi U^T W U + P^T diag(b, b, b I) P + diag(b / (|k|+1)). */
static void reduced_matrix(const work_t *w, double f, double b, double *K)
{
    double acc[NX][NX];
    for (int i = 0; i < NX; i++) {
        double row[NX] = {0.0};   /* one output row held in registers across the sum over r */
        for (int r = 0; r < NR; r++) {
            const double t = f * weight[r] * w->U[r][i];
            for (int j = 0; j < NX; j++)
                row[j] += t * w->U[r][j];
        }
        memcpy(acc[i], row, sizeof row);
    }
    for (int i = 0; i < NX; i++)
        for (int j = i; j < NX; j++) {
            double s = acc[i][j] + b * (w->P[0][i] * w->P[0][j] + w->P[1][i] * w->P[1][j]
                                        + w->Ic * w->P[2][i] * w->P[2][j]);
            if (i == j) s += b * body_shape[i];
            K[NX * i + j] = K[NX * j + i] = s;
        }
}

static int reduced(const double *x, const double *v, double rho0, double rhof,
                   double *K, double *P, double *gvv)
{
    work_t w;
    const double f = rhof * KPI, b = rho0 * KPI;
    if (setup(x, rho0, rhof, &w) != 0) return -1;
    if (K) reduced_matrix(&w, f, b, K);
    if (P) memcpy(P, w.P, sizeof w.P);
    if (!v || !gvv) return 0;

    /* X = (q, v) with q = P v: the velocity that minimizes X^T M X for this v (Lemma 4.3). */
    double X[NP], ws[NR], dX[NR], a[NP], D[NR][NP];
    for (int p = 0; p < 3; p++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w.P[p][k] * v[k];
        X[p] = s;
    }
    for (int k = 0; k < NX; k++) X[3 + k] = v[k];
    for (int r = 0; r < NR; r++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w.U[r][k] * v[k];
        ws[r] = weight[r] * s;
    }
    boundary_data_dir(x, v, D);
    for (int q = 0; q < NP; q++) a[q] = 0.0;
    for (int r = 0; r < NR; r++) {
        double s = 0.0;
        for (int q = 0; q < NP; q++) {
            a[q] += D[r][q] * ws[r];
            s += D[r][q] * X[q];
        }
        dX[r] = weight[r] * s;
    }
    double g[NX];
    boundary_data_bigrad(x, ws, X, g);
    double dIv = 0.0;
    for (int k = 0; k < NX; k++) dIv += w.gI[k] * v[k];
    const double q2 = X[2];
    /* [D_v(K v)]_i = (E^T (D_v M) X)_i;  d_i(v^T K v)/2 = X^T (d_i M) X / 2 at fixed X. */
    for (int i = 0; i < NX; i++) {
        double s = a[3 + i] + w.P[0][i] * a[0] + w.P[1][i] * a[1] + w.P[2][i] * a[2];
        for (int r = 0; r < NR; r++) s += w.U[r][i] * dX[r];
        gvv[i] = f * (s - g[i]) + b * (dIv * q2 * w.P[2][i] - 0.5 * w.gI[i] * q2 * q2);
    }
    return 0;
}

""")

ASSEMBLY_FULL = Template("""\
static void mass(const double *x, double rho0, double rhof, double *Mr, double *Nc, double *Md)
{
    work_t w;
    const double f = rhof * KPI, b = rho0 * KPI;
    boundary_data(x, w.S);
    w.Ic = inertia(x, NULL);
    rigid_blocks(&w, f, b);
    if (Mr) memcpy(Mr, w.Mr, sizeof w.Mr);
    if (Nc) memcpy(Nc, w.Nc, sizeof w.Nc);
    if (Md) {
        double acc[NX][NX] = {{0.0}};
        for (int r = 0; r < NR; r++)
            for (int i = 0; i < NX; i++) {
                const double t = f * weight[r] * w.S[r][3 + i];
                for (int j = 0; j < NX; j++)
                    acc[i][j] += t * w.S[r][3 + j];
            }
        for (int i = 0; i < NX; i++)
            for (int j = i; j < NX; j++)
                Md[NX * i + j] = Md[NX * j + i] = acc[i][j] + (i == j ? b * body_shape[i] : 0.0);
    }
}

static int mass_deriv(const double *x, double rho0, double rhof,
                      double *dMr, double *dNc, double *dMd)
{
    const double f = rhof * KPI, b = rho0 * KPI;
    double S[NR][NP], gI[NX];
    double *dS = calloc((size_t)NX * NR * NP, sizeof(double));
    if (!dS) return -2;
    boundary_data(x, S);
    boundary_data_deriv(x, dS);
    inertia(x, gI);
    for (int r = 0; r < NX; r++) {
        const double (*dSr)[NP] = (const double (*)[NP])(dS + (size_t)r * NR * NP);
        for (int p = 0; p < NP; p++)
            for (int q = p; q < NP; q++) {
                double s = 0.0;
                for (int row = 0; row < NR; row++)
                    s += weight[row] * (dSr[row][p] * S[row][q] + S[row][p] * dSr[row][q]);
                s *= f;
                if (p == 2 && q == 2) s += b * gI[r];
                if (q < 3) {
                    if (dMr) dMr[9 * r + 3 * p + q] = dMr[9 * r + 3 * q + p] = s;
                } else if (p < 3) {
                    if (dNc) dNc[3 * NX * r + NX * p + q - 3] = s;
                } else if (dMd) {
                    dMd[(size_t)NX * NX * r + NX * (p - 3) + q - 3] = s;
                    dMd[(size_t)NX * NX * r + NX * (q - 3) + p - 3] = s;
                }
            }
    }
    free(dS);
    return 0;
}

static int reduced_deriv(const double *x, double rho0, double rhof, double *dK, double *Gamma)
{
    const double f = rhof * KPI, b = rho0 * KPI;
    work_t w;
    if (setup(x, rho0, rhof, &w) != 0) return -1;
    double *dS = calloc((size_t)NX * NR * NP, sizeof(double));
    double *dKw = dK ? dK : malloc(sizeof(double) * NX * NX * NX);
    if (!dS || !dKw) { free(dS); if (!dK) free(dKw); return -2; }
    boundary_data_deriv(x, dS);
    double V[NR][NX];
    /* d_r K = E^T (d_r M) E: the terms with d_r E cancel because M E = [0; K]. */
    for (int r = 0; r < NX; r++) {
        const double (*dSr)[NP] = (const double (*)[NP])(dS + (size_t)r * NR * NP);
        double *dKr = dKw + (size_t)NX * NX * r;
        for (int row = 0; row < NR; row++)
            for (int k = 0; k < NX; k++)
                V[row][k] = dSr[row][3 + k] + dSr[row][0] * w.P[0][k] + dSr[row][1] * w.P[1][k]
                          + dSr[row][2] * w.P[2][k];
        for (int i = 0; i < NX; i++)
            for (int j = i; j < NX; j++) {
                double s = 0.0;
                for (int row = 0; row < NR; row++)
                    s += weight[row] * (V[row][i] * w.U[row][j] + w.U[row][i] * V[row][j]);
                s = f * s + b * w.gI[r] * w.P[2][i] * w.P[2][j];
                dKr[NX * i + j] = dKr[NX * j + i] = s;
            }
    }
    if (Gamma)
        for (int i = 0; i < NX; i++)
            for (int j = 0; j < NX; j++)
                for (int l = 0; l < NX; l++)
                    Gamma[((size_t)NX * i + j) * NX + l] =
                        0.5 * (dKw[((size_t)NX * l + i) * NX + j] + dKw[((size_t)NX * j + i) * NX + l]
                               - dKw[((size_t)NX * i + j) * NX + l]);
    free(dS);
    if (!dK) free(dKw);
    return 0;
}

static void boundary_data_flat(const double *x, double *S)
{
    boundary_data(x, (double (*)[NP])S);
}

const swim_kernel swim_kernel_n$N = {
    .modes = $N,
    .dim = NX,
    .mass = mass,
    .mass_deriv = mass_deriv,
    .reduced = reduced,
    .reduced_deriv = reduced_deriv,
    .jacobian_circle = jacobian_circle,
    .barrier_sums = barrier_sums,
    .inertia = inertia,
    .boundary_data = boundary_data_flat,
};
""")

SCENE_RHS = Template("""\
/* ---- the scene's right-hand side ------------------------------------------------------ */

static const int free_index[NX] = {$free_index};

$forcing_fn
/* K a = b for the NX x NX Cholesky factor L (lower, in place of K). */
static void chol_solve(const double *L, const double *b, double *a)
{
    double z[NX];
    for (int i = 0; i < NX; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++) s -= L[NX * i + k] * z[k];
        z[i] = s / L[NX * i + i];
    }
    for (int i = NX - 1; i >= 0; i--) {
        double s = z[i];
        for (int k = i + 1; k < NX; k++) s -= L[NX * k + i] * a[k];
        a[i] = s / L[NX * i + i];
    }
}

static int chol_factor(double *K)
{
    for (int j = 0; j < NX; j++) {
        double d = K[NX * j + j];
        for (int k = 0; k < j; k++) d -= K[NX * j + k] * K[NX * j + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        K[NX * j + j] = d;
        for (int i = j + 1; i < NX; i++) {
            double s = K[NX * i + j];
            for (int k = 0; k < j; k++) s -= K[NX * i + k] * K[NX * j + k];
            K[NX * i + j] = s / d;
        }
    }
    return 0;
}
static int scene_rhs(double t, const double *y, double *dy, const swim_scene_params *p)
{
    double x[NFULL];
    memcpy(x, p->x_locked, sizeof x);
    for (int f = 0; f < NX; f++) x[free_index[f]] = y[3 + f];
    const double *v = y + 3 + NX;
    for (int i = 0; i < 4 + 2 * NX; i++)
        if (!isfinite(y[i])) return SWIM_RHS_ENAN;
    double K[NX * NX], P[3 * NX], g[NX], f[NX], power = 0.0;
    if (reduced(x, v, p->rho0, p->rhof, K, P, g) != 0) return SWIM_RHS_EMASS;
    for (int i = 0; i < NX; i++) f[i] = -g[i];
$force_terms
    (void)t;
    /* (4.10)-(4.12) on the free coordinates: locking by deletion equals locking by
     * multipliers (ERRATA C2); G1 (2.8) and G2 (2.14) restricted to the free coordinates. */
    if (chol_factor(K) != 0) return SWIM_RHS_EMASS;
    double a[NX], G[2][NX], Z[2][NX], curv = 0.0;
$constraint_rows
    chol_solve(K, f, a);
    chol_solve(K, G[0], Z[0]);
    chol_solve(K, G[1], Z[1]);
    double A[2][2], r[2], lam[2] = {0.0, 0.0};
    for (int i = 0; i < 2; i++) {
        r[i] = 0.0;
        for (int k = 0; k < NX; k++) r[i] -= G[i][k] * a[k];
        for (int j = 0; j < 2; j++) {
            A[i][j] = 0.0;
            for (int k = 0; k < NX; k++) A[i][j] += G[i][k] * Z[j][k];
        }
    }
    r[0] -= curv;
    /* A constraint whose row vanishes on the free coordinates holds trivially: drop it. */
    const double scale = fabs(A[0][0]) + fabs(A[1][1]) + 1e-300;
    const int use0 = A[0][0] > 1e-13 * scale, use1 = A[1][1] > 1e-13 * scale;
    if (use0 && use1) {
        const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
        if (!(fabs(det) > 1e-13 * A[0][0] * A[1][1])) return SWIM_RHS_ECONSTRAINT;
        lam[0] = (r[0] * A[1][1] - A[0][1] * r[1]) / det;
        lam[1] = (A[0][0] * r[1] - A[1][0] * r[0]) / det;
    } else if (use0) {
        lam[0] = r[0] / A[0][0];
    } else if (use1) {
        lam[1] = r[1] / A[1][1];
    }
    double qs[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < NX; k++) {
        dy[3 + k] = v[k];
        dy[3 + NX + k] = a[k] + lam[0] * Z[0][k] + lam[1] * Z[1][k];
        qs[0] += P[k] * v[k];
        qs[1] += P[NX + k] * v[k];
        qs[2] += P[2 * NX + k] * v[k];
    }
    /* (3.21) */
    const double ct = cos(y[2]), st = sin(y[2]);
    dy[0] = ct * qs[0] - st * qs[1];
    dy[1] = st * qs[0] + ct * qs[1];
    dy[2] = qs[2];
    dy[3 + 2 * NX] = power;
    for (int i = 0; i < 4 + 2 * NX; i++)
        if (!isfinite(dy[i])) return SWIM_RHS_ENAN;
    return SWIM_RHS_OK;
}

const swim_scene_kernel swim_scene_kernel_entry = {
    .abi = SWIM_KERNEL_ABI,
    .modes = $N,
    .nfull = NFULL,
    .nfree = NX,
    .free_index = free_index,
    .structure = "$structure",
    .rhs = scene_rhs,
    .barrier_sums = $barrier_entry,
};
""")


