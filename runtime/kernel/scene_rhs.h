/* scene_rhs.h -- the right-hand side of (4.10)-(4.12), (4.15), (5.1)-(5.2), (3.21) for one scene
 * structure (included by a generated scene kernel after kernel/assembly.h).
 *
 * The generated file defines, besides what assembly.h needs:
 *   free_index[NX]           the coordinates the kernel carries, into the full shape vector;
 *   SWIM_SCENE_STRUCTURE     the structure key it was generated for (a string);
 *   scene_forces(t, x, v, g, p, f, &power)   f = -g - grad W1 - D v + F(t) and the power
 *                            F.v - v^T D v of the effects present (SymPy, generator/swimgen);
 *   scene_constraints(x, v, G, &curv)   the rows of G1 (2.8) and G2 (2.14) on the carried
 *                            coordinates and curv = (DG1[v]).v (ERRATA C2);
 *   SWIM_SCENE_BARRIER       (optional) W2 is present: its gradient comes from p->barrier;
 *   SWIM_SCENE_LOCK_MULTIPLIERS (optional) the kernel carries every coordinate and holds the
 *                            locked ones (p->free_mask) by multipliers of (4.12), rather than
 *                            by deleting them (equivalent, ERRATA C2).
 */
#ifndef SWIM_KERNEL_SCENE_RHS_H
#define SWIM_KERNEL_SCENE_RHS_H

#include "coords.h"

#ifdef SWIM_SCENE_LOCK_MULTIPLIERS
#define SWIM_SCENE_MAX_ROWS (2 + NX)
#else
#define SWIM_SCENE_MAX_ROWS 2
#endif

/* Inlined at each call so that n is a compile-time constant there (NX for K): fixed trip counts
 * the compiler unrolls, as in kernel/assembly.h. */
#if defined(__GNUC__)
#define SWIM_INLINE static inline __attribute__((always_inline))
#else
#define SWIM_INLINE static inline
#endif

/* K = L L^T in place (L lower, row-major); -1 when K is not positive definite. */
SWIM_INLINE int chol_factor(double *K, int n)
{
    for (int j = 0; j < n; j++) {
        double d = K[n * j + j];
        for (int k = 0; k < j; k++) d -= K[n * j + k] * K[n * j + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        K[n * j + j] = d;
        for (int i = j + 1; i < n; i++) {
            double s = K[n * i + j];
            for (int k = 0; k < j; k++) s -= K[n * i + k] * K[n * j + k];
            K[n * i + j] = s / d;
        }
    }
    return 0;
}

/* a = K^-1 b for the Cholesky factor L of chol_factor. */
SWIM_INLINE void chol_solve(const double *L, int n, const double *b, double *a)
{
    double z[NX > SWIM_SCENE_MAX_ROWS ? NX : SWIM_SCENE_MAX_ROWS];
    for (int i = 0; i < n; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++) s -= L[n * i + k] * z[k];
        z[i] = s / L[n * i + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = z[i];
        for (int k = i + 1; k < n; k++) s -= L[n * k + i] * a[k];
        a[i] = s / L[n * i + i];
    }
}

#ifdef SWIM_SCENE_LOCK_MULTIPLIERS
/* The constraint rows of (4.12): G1 and G2 unless they vanish on the free coordinates (then they
 * hold trivially: locked velocities are 0), and e_i for every locked coordinate. Returns the
 * number of rows m; r[0..m) gets -(DG[v]).v. */
static int constraint_system(const double *x, const double *v, const swim_scene_params *p,
                             double G[][NX], double *r, int *lock)
{
    double G12[2][NX], curv = 0.0, norm[2] = {0.0, 0.0};
    scene_constraints(x, v, G12, &curv);
    int m = 0;
    for (int j = 0; j < 2; j++)
        for (int k = 0; k < NX; k++)
            if (p->free_mask[free_index[k]]) norm[j] += G12[j][k] * G12[j][k];
    const double scale = norm[0] + norm[1] + 1e-300;
    for (int j = 0; j < 2; j++)
        if (norm[j] > 1e-26 * scale) {
            memcpy(G[m], G12[j], sizeof G12[j]);
            lock[m] = -1;
            r[m++] = j == 0 ? -curv : 0.0;   /* (DG2[v]).v = 0 (ERRATA C2) */
        }
    for (int k = 0; k < NX; k++)
        if (!p->free_mask[free_index[k]]) {
            memset(G[m], 0, sizeof G[m]);
            G[m][k] = 1.0;
            lock[m] = k;   /* the row is e_k: its products are entries */
            r[m++] = 0.0;
        }
    return m;
}

/* acc = K^-1 (f + G^T lambda) with (G K^-1 G^T) lambda = -(DG[v]).v - G K^-1 f (4.12), for the
 * Cholesky factor L of K. */
static int accelerations(const double *L, const double *x, const double *v,
                         const swim_scene_params *p, const double *f, double *acc)
{
    double G[SWIM_SCENE_MAX_ROWS][NX], Z[SWIM_SCENE_MAX_ROWS][NX];
    double A[SWIM_SCENE_MAX_ROWS * SWIM_SCENE_MAX_ROWS], r[SWIM_SCENE_MAX_ROWS];
    double lam[SWIM_SCENE_MAX_ROWS];
    int lock[SWIM_SCENE_MAX_ROWS];
    const int m = constraint_system(x, v, p, G, r, lock);
    chol_solve(L, NX, f, acc);
    for (int j = 0; j < m; j++) chol_solve(L, NX, G[j], Z[j]);
    for (int i = 0; i < m; i++) {
        if (lock[i] >= 0) {
            r[i] -= acc[lock[i]];
            for (int j = 0; j < m; j++) A[m * i + j] = Z[j][lock[i]];
            continue;
        }
        for (int k = 0; k < NX; k++) r[i] -= G[i][k] * acc[k];
        for (int j = 0; j < m; j++) {
            double s = 0.0;
            for (int k = 0; k < NX; k++) s += G[i][k] * Z[j][k];
            A[m * i + j] = s;
        }
    }
    if (m == 0) return 0;
    /* G K^-1 G^T is positive definite when the rows are independent */
    if (chol_factor(A, m) != 0) return SWIM_RHS_ECONSTRAINT;
    double dmin = INFINITY, dmax = 0.0;
    for (int i = 0; i < m; i++) {
        dmin = fmin(dmin, A[m * i + i]);
        dmax = fmax(dmax, A[m * i + i]);
    }
    if (!(dmin > 1e-7 * dmax)) return SWIM_RHS_ECONSTRAINT;   /* cond > 1e14 */
    chol_solve(A, m, r, lam);
    for (int k = 0; k < NX; k++)
        for (int j = 0; j < m; j++) acc[k] += lam[j] * Z[j][k];
    return 0;
}
#else
/* The same with locks by deletion: the rows are G1 (2.8) and G2 (2.14) on the free coordinates;
 * one that vanishes there holds trivially and is dropped (ERRATA C2). */
static int accelerations(const double *L, const double *x, const double *v,
                         const swim_scene_params *p, const double *f, double *acc)
{
    (void)p;
    double G[2][NX], Z[2][NX], curv = 0.0;
    scene_constraints(x, v, G, &curv);
    chol_solve(L, NX, f, acc);
    chol_solve(L, NX, G[0], Z[0]);
    chol_solve(L, NX, G[1], Z[1]);
    double A[2][2], r[2], lam[2] = {0.0, 0.0};
    for (int i = 0; i < 2; i++) {
        r[i] = 0.0;
        for (int k = 0; k < NX; k++) r[i] -= G[i][k] * acc[k];
        for (int j = 0; j < 2; j++) {
            A[i][j] = 0.0;
            for (int k = 0; k < NX; k++) A[i][j] += G[i][k] * Z[j][k];
        }
    }
    r[0] -= curv;
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
    for (int k = 0; k < NX; k++) acc[k] += lam[0] * Z[0][k] + lam[1] * Z[1][k];
    return 0;
}
#endif

static int scene_rhs(double t, const double *y, double *dy, const swim_scene_params *p)
{
    double x[NFULL];
    memcpy(x, p->x_locked, sizeof x);
    for (int k = 0; k < NX; k++) x[free_index[k]] = y[3 + k];
    const double *v = y + 3 + NX;
    for (int i = 0; i < 4 + 2 * NX; i++)
        if (!isfinite(y[i])) return SWIM_RHS_ENAN;
    double K[NX * NX], P[3 * NX], g[NX], f[NX], power = 0.0;
    if (reduced(x, v, p->rho0, p->rhof, K, P, g) != 0) return SWIM_RHS_EMASS;
    scene_forces(t, x, v, g, p, f, &power);
#ifdef SWIM_SCENE_BARRIER
    {   /* W2 (section 4.1.1): its gradient from the runtime's quadrature (shape/barrier.h) */
        double gW[NX];
        if (p->barrier(x, gW, p->barrier_ctx) != 0) return SWIM_RHS_EBARRIER;
        for (int i = 0; i < NX; i++) f[i] -= gW[i];
    }
#endif
    /* (4.10)-(4.12): K c'' = f + G^T lambda, G c'' = -(DG[v]).v */
    if (chol_factor(K, NX) != 0) return SWIM_RHS_EMASS;
    double acc[NX];
    const int rc = accelerations(K, x, v, p, f, acc);
    if (rc != 0) return rc;
    double qs[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < NX; k++) {
        dy[3 + k] = v[k];
        dy[3 + NX + k] = acc[k];
        qs[0] += P[k] * v[k];
        qs[1] += P[NX + k] * v[k];
        qs[2] += P[2 * NX + k] * v[k];
    }
    swim_to_fixed_frame(y[2], qs, dy);   /* (3.21): q' = R(theta) q*, q* = -Mr^-1 N v */
    dy[3 + 2 * NX] = power;
    for (int i = 0; i < 4 + 2 * NX; i++)
        if (!isfinite(dy[i])) return SWIM_RHS_ENAN;
    return SWIM_RHS_OK;
}

const swim_scene_kernel swim_scene_kernel_entry = {
    .abi = SWIM_KERNEL_ABI,
    .modes = NFULL / 2 - 1,
    .nfull = NFULL,
    .nfree = NX,
    .free_index = free_index,
    .structure = SWIM_SCENE_STRUCTURE,
    .rhs = scene_rhs,
};

#endif
