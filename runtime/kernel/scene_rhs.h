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
 *                            by deleting them (equivalent, ERRATA C2);
 * and for the exact Jacobian (scene_jacobian, exported as swim_scene_kernel.jacobian):
 *   NDS, dS_row, dS_col, dS_start, boundary_data_partials(x, val)   the first partials of S,
 *                            sparse, by coordinate;
 *   NA2, a2_row, a2_r, a2_s, a2_val   the second partials of S (constants, alpha column only);
 *   NIH, ih_r, ih_s, ih_val  the Hessian of the inertia sum (constant);
 *   scene_forces_jac, scene_constraints_jac   the partials of scene_forces (at fixed g) and of
 *                            scene_constraints in x and v;
 *   the Hessian of W2 comes from p->barrier_hessian;
 *   SWIM_SCENE_MATERIAL      (optional) an energy law W = int_D U(I1, J) dz ([elastic] energy,
 *                            ERRATA B5): material_energy(x, p, &W, grad, hess) and
 *                            material_energy_dp(x, p, k, dgrad) (generator/swimgen/material.py).
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

/* a_r = K^-1 b_r for cnt right sides at once (cnt a constant at the call): each is solved with
 * the operations of chol_solve in the same order, so the results are the same to the bit, but
 * the cnt dependency chains of the substitutions (latency-bound, one division per row) overlap. */
SWIM_INLINE void chol_solve_many(const double *L, int n, int cnt, const double *const *b, double *const *a)
{
    double z[3][NX > SWIM_SCENE_MAX_ROWS ? NX : SWIM_SCENE_MAX_ROWS];
    for (int i = 0; i < n; i++) {
        double s[3];
        for (int r = 0; r < cnt; r++) s[r] = b[r][i];
        for (int k = 0; k < i; k++)
            for (int r = 0; r < cnt; r++) s[r] -= L[n * i + k] * z[r][k];
        for (int r = 0; r < cnt; r++) z[r][i] = s[r] / L[n * i + i];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s[3];
        for (int r = 0; r < cnt; r++) s[r] = z[r][i];
        for (int k = i + 1; k < n; k++)
            for (int r = 0; r < cnt; r++) s[r] -= L[n * k + i] * a[r][k];
        for (int r = 0; r < cnt; r++) a[r][i] = s[r] / L[n * i + i];
    }
}

/* The saddle-point system of (4.12) at one state, set up once and solved for the accelerations
 * and again, with other right sides, for each direction of the Jacobian (same K, same rows):
 *   K c'' = h + G^T lambda,  G c'' = s.
 * K = L L^T (the caller's Cholesky factor), Z = K^-1 G^T; A = G K^-1 G^T (its Cholesky factor
 * with multipliers; itself, with the rows used, with deletion). */
typedef struct {
    int m;                                      /* rows */
    double G[SWIM_SCENE_MAX_ROWS][NX], Z[SWIM_SCENE_MAX_ROWS][NX];
    double A[SWIM_SCENE_MAX_ROWS * SWIM_SCENE_MAX_ROWS];
    double r[SWIM_SCENE_MAX_ROWS];              /* s of the accelerations: -(DG[v]).v */
    int lock[SWIM_SCENE_MAX_ROWS];              /* k when the row is e_k (locked), else -1 */
    int which[SWIM_SCENE_MAX_ROWS];             /* 0: G1, 1: G2, -1: a lock */
    int use0, use1;                             /* deletion: rows kept (ERRATA C2) */
    double det;
} saddle_t;

#ifdef SWIM_SCENE_LOCK_MULTIPLIERS
/* The constraint rows of (4.12): G1 and G2 unless they vanish on the free coordinates (then they
 * hold trivially: locked velocities are 0), and e_i for every locked coordinate. Sets sd->m rows;
 * r[0..m) gets -(DG[v]).v. */
static void constraint_system(const double *x, const double *v, const swim_scene_params *p,
                              saddle_t *sd)
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
            memcpy(sd->G[m], G12[j], sizeof G12[j]);
            sd->lock[m] = -1;
            sd->which[m] = j;
            sd->r[m++] = j == 0 ? -curv : 0.0;   /* (DG2[v]).v = 0 (ERRATA C2) */
        }
    for (int k = 0; k < NX; k++)
        if (!p->free_mask[free_index[k]]) {
            memset(sd->G[m], 0, sizeof sd->G[m]);
            sd->G[m][k] = 1.0;
            sd->lock[m] = k;   /* the row is e_k: its products are entries */
            sd->which[m] = -1;
            sd->r[m++] = 0.0;
        }
    sd->m = m;
}

/* Rows, Z and the factor of G K^-1 G^T (positive definite when the rows are independent). */
static int saddle_setup(const double *L, const double *x, const double *v,
                        const swim_scene_params *p, saddle_t *sd)
{
    constraint_system(x, v, p, sd);
    const int m = sd->m;
    for (int j = 0; j < m; j++) chol_solve(L, NX, sd->G[j], sd->Z[j]);
    for (int i = 0; i < m; i++) {
        if (sd->lock[i] >= 0) {
            for (int j = 0; j < m; j++) sd->A[m * i + j] = sd->Z[j][sd->lock[i]];
            continue;
        }
        for (int j = 0; j < m; j++) {
            double s = 0.0;
            for (int k = 0; k < NX; k++) s += sd->G[i][k] * sd->Z[j][k];
            sd->A[m * i + j] = s;
        }
    }
    if (m == 0) return 0;
    if (chol_factor(sd->A, m) != 0) return SWIM_RHS_ECONSTRAINT;
    double dmin = INFINITY, dmax = 0.0;
    for (int i = 0; i < m; i++) {
        dmin = fmin(dmin, sd->A[m * i + i]);
        dmax = fmax(dmax, sd->A[m * i + i]);
    }
    if (!(dmin > 1e-7 * dmax)) return SWIM_RHS_ECONSTRAINT;   /* cond > 1e14 */
    return 0;
}

static int saddle_setup_h(const double *L, const double *x, const double *v,
                          const swim_scene_params *p, saddle_t *sd, const double *h, double *acc)
{
    const int rc = saddle_setup(L, x, v, p, sd);
    if (rc == 0 && h) chol_solve(L, NX, h, acc);
    return rc;
}

/* Given acc = K^-1 h: acc += K^-1 G^T lambda with (G K^-1 G^T) lambda = s - G acc (4.12). */
static void saddle_correct(const saddle_t *sd, const double *s, double *acc, double *lam)
{
    const int m = sd->m;
    double r[SWIM_SCENE_MAX_ROWS];
    for (int i = 0; i < m; i++) {
        r[i] = s[i];
        if (sd->lock[i] >= 0) r[i] -= acc[sd->lock[i]];
        else
            for (int k = 0; k < NX; k++) r[i] -= sd->G[i][k] * acc[k];
    }
    for (int i = 0; i < SWIM_SCENE_MAX_ROWS; i++) lam[i] = 0.0;
    if (m == 0) return;
    chol_solve(sd->A, m, r, lam);
    for (int k = 0; k < NX; k++)
        for (int j = 0; j < m; j++) acc[k] += lam[j] * sd->Z[j][k];
}
#else
/* The same with locks by deletion: the rows are G1 (2.8) and G2 (2.14) on the free coordinates;
 * one that vanishes there holds trivially and is dropped (ERRATA C2). */
static int saddle_setup_h(const double *L, const double *x, const double *v,
                          const swim_scene_params *p, saddle_t *sd, const double *h, double *acc);

static int saddle_setup(const double *L, const double *x, const double *v,
                        const swim_scene_params *p, saddle_t *sd)
{
    return saddle_setup_h(L, x, v, p, sd, NULL, NULL);
}

/* saddle_setup, and (h) acc = K^-1 h solved together with Z. */
static int saddle_setup_h(const double *L, const double *x, const double *v,
                          const swim_scene_params *p, saddle_t *sd, const double *h, double *acc)
{
    (void)p;
    double curv = 0.0;
    scene_constraints(x, v, sd->G, &curv);
    sd->m = 2;
    sd->r[0] = -curv;
    sd->r[1] = 0.0;   /* (DG2[v]).v = 0 (ERRATA C2) */
    for (int j = 0; j < 2; j++) {
        sd->lock[j] = -1;
        sd->which[j] = j;
    }
    const double *rhs[3] = {sd->G[0], sd->G[1], h};
    double *sol[3] = {sd->Z[0], sd->Z[1], acc};
    if (h) chol_solve_many(L, NX, 3, rhs, sol);
    else chol_solve_many(L, NX, 2, rhs, sol);
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double a = 0.0;
            for (int k = 0; k < NX; k++) a += sd->G[i][k] * sd->Z[j][k];
            sd->A[2 * i + j] = a;
        }
    const double *A = sd->A;
    const double scale = fabs(A[0]) + fabs(A[3]) + 1e-300;
    sd->use0 = A[0] > 1e-13 * scale;
    sd->use1 = A[3] > 1e-13 * scale;
    sd->det = A[0] * A[3] - A[1] * A[2];
    if (sd->use0 && sd->use1 && !(fabs(sd->det) > 1e-13 * A[0] * A[3])) return SWIM_RHS_ECONSTRAINT;
    return 0;
}

static void saddle_correct(const saddle_t *sd, const double *s, double *acc, double *lam)
{
    const double *A = sd->A;
    double r[2];
    for (int i = 0; i < 2; i++) {
        r[i] = 0.0;
        for (int k = 0; k < NX; k++) r[i] -= sd->G[i][k] * acc[k];
        r[i] += s[i];
    }
    lam[0] = lam[1] = 0.0;
    if (sd->use0 && sd->use1) {
        lam[0] = (r[0] * A[3] - A[1] * r[1]) / sd->det;
        lam[1] = (A[0] * r[1] - A[2] * r[0]) / sd->det;
    } else if (sd->use0) {
        lam[0] = r[0] / A[0];
    } else if (sd->use1) {
        lam[1] = r[1] / A[3];
    }
    for (int k = 0; k < NX; k++) acc[k] += lam[0] * sd->Z[0][k] + lam[1] * sd->Z[1][k];
}
#endif

/* acc = K^-1 (h + G^T lambda) with G acc = s (4.12), for the Cholesky factor L of K. */
static void saddle_solve(const double *L, const saddle_t *sd, const double *h, const double *s,
                         double *acc, double *lam)
{
    chol_solve(L, NX, h, acc);
    saddle_correct(sd, s, acc, lam);
}

/* acc = K^-1 (f + G^T lambda) with G acc = -(DG[v]).v (4.12), for the Cholesky factor L of K. */
static int accelerations(const double *L, const double *x, const double *v,
                         const swim_scene_params *p, const double *f, double *acc)
{
    saddle_t sd;
    double lam[SWIM_SCENE_MAX_ROWS];
    const int rc = saddle_setup_h(L, x, v, p, &sd, f, acc);
    if (rc != 0) return rc;
    saddle_correct(&sd, sd.r, acc, lam);
    return 0;
}

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
    if (p->kinetic) {   /* before chol_factor overwrites K */
        double T = 0.0;
        for (int i = 0; i < NX; i++) {
            double r = 0.0;
            for (int j = 0; j < NX; j++) r += K[NX * i + j] * v[j];
            T += v[i] * r;
        }
        *p->kinetic = 0.5 * T;
    }
    scene_forces(t, x, v, g, p, f, &power);
#ifdef SWIM_SCENE_BARRIER
    {   /* W2 (section 4.1.1): its gradient from the runtime's quadrature (shape/barrier.h) */
        double gW[NX];
        if (p->barrier(x, gW, p->barrier_ctx) != 0) return SWIM_RHS_EBARRIER;
        for (int i = 0; i < NX; i++) f[i] -= gW[i];
    }
#endif
#ifdef SWIM_SCENE_MATERIAL
    {   /* the energy law's W (ERRATA B5): -grad W joins the forces, like W1's */
        double Wm, gm[NX];
        if (material_energy(x, p, &Wm, gm, NULL) != 0) return SWIM_RHS_ENAN;
        for (int i = 0; i < NX; i++) f[i] -= gm[i];
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

/* ---- the exact Jacobian of scene_rhs ------------------------------------------------------ */

/* Workspace of scene_jacobian (allocated per call: ~15 NX^2 doubles). Names: X = E v = (P v, v),
 * Xa = E acc, W = diag(weight); a leading d is a derivative along one direction. */
typedef struct {
    work_t w;
    christoffel_t c;
    double L[NX * NX], g[NX], fs[NX], gW[NX], HW[NX * NX], acc[NX], lam[SWIM_SCENE_MAX_ROWS];
    double Fx[NX][NX], Fv[NX][NX], px[NX], pv[NX], Gx[2][NX][NX], cv[NX];
    double val[NDS > 0 ? NDS : 1];      /* d S / d x_r, sparse (boundary_data_partials) */
    double Xa[NP], ya[NR], c3[3], HIv[NX];
    double A2[NR][NX], A2ws[NX], H2[NX][NX], HI[NX][NX];
    double BX[NX][NR];                  /* bigrad(w', X) = BX w' */
    double Cws[NX][NP];                 /* bigrad(ws, X') = Cws X' */
    double DtWSR[NP][3], BXWSR[NX][3], DE[NR][NX], EtDtWU[NX][NX], BXWU[NX][NX], CwsE[NX][NX];
    double Ml[6];                       /* Cholesky factor of Mr */
    saddle_t sd;                        /* (4.12) at this state, solved again per direction */
    double B[NX][2 * NX];               /* right sides h of the tangent systems, by column */
    double S[2 * NX][SWIM_SCENE_MAX_ROWS];   /* and their constraint parts s */
} jac_work;

/* Mr = l l^T, l lower (l00, l10, l11, l20, l21, l22); Mr is positive definite (setup checked). */
static void mr_factor(const double *M, double *l)
{
    l[0] = sqrt(M[0]);
    l[1] = M[3] / l[0];
    l[2] = sqrt(M[4] - l[1] * l[1]);
    l[3] = M[6] / l[0];
    l[4] = (M[7] - l[3] * l[1]) / l[2];
    l[5] = sqrt(M[8] - l[3] * l[3] - l[4] * l[4]);
}

static void mr_solve(const double *l, const double *b, double *z)
{
    const double y0 = b[0] / l[0], y1 = (b[1] - l[1] * y0) / l[2];
    const double y2 = (b[2] - l[3] * y0 - l[4] * y1) / l[5];
    z[2] = y2 / l[5];
    z[1] = (y1 - l[4] * z[2]) / l[2];
    z[0] = (y0 - l[1] * z[1] - l[3] * z[2]) / l[0];
}

/* (E^T u)_i = u_{3+i} + sum_p P[p][i] u_p, added to out times `scale`. */
static void add_Et(const work_t *w, const double *u, double scale, double *out)
{
    for (int i = 0; i < NX; i++)
        out[i] += scale * (u[3 + i] + w->P[0][i] * u[0] + w->P[1][i] * u[1] + w->P[2][i] * u[2]);
}

/* What every direction shares: the tangents below are linear maps of these. */
static void jacobian_tables(jac_work *j, const double *x, const double *v, double f)
{
    const work_t *w = &j->w;
    const christoffel_t *c = &j->c;
    boundary_data_partials(x, j->val);
    for (int p = 0; p < 3; p++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w->P[p][k] * j->acc[k];
        j->Xa[p] = s;
    }
    for (int k = 0; k < NX; k++) j->Xa[3 + k] = j->acc[k];
    for (int r = 0; r < NR; r++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w->U[r][k] * j->acc[k];
        j->ya[r] = weight[r] * s;
    }
    /* (D_v M X)_{0..2} without the body term, which the caller adds */
    for (int p = 0; p < 3; p++) {
        double s = c->a[p];
        for (int r = 0; r < NR; r++) s += w->S[r][p] * c->dX[r];
        j->c3[p] = f * s;
    }
    /* second partials: D_{e_s} D_v S (alpha column), and the Hessian of ws^T S X */
    memset(j->A2, 0, sizeof j->A2);
    memset(j->H2, 0, sizeof j->H2);
    for (int k = 0; k < NA2; k++) {
        j->A2[a2_row[k]][a2_s[k]] += v[a2_r[k]] * a2_val[k];
        j->H2[a2_r[k]][a2_s[k]] += c->ws[a2_row[k]] * c->X[2] * a2_val[k];
    }
    for (int s = 0; s < NX; s++) {
        double t = 0.0;
        for (int r = 0; r < NR; r++) t += j->A2[r][s] * c->ws[r];
        j->A2ws[s] = t;
    }
    memset(j->HI, 0, sizeof j->HI);
    for (int k = 0; k < NIH; k++) j->HI[ih_r[k]][ih_s[k]] = ih_val[k];
    for (int r = 0; r < NX; r++) {
        double t = 0.0;
        for (int s = 0; s < NX; s++) t += j->HI[s][r] * v[s];
        j->HIv[r] = t;
    }
    /* the two contractions of d S: bigrad(w', X) = BX w', bigrad(ws, X') = Cws X' */
    memset(j->BX, 0, sizeof j->BX);
    memset(j->Cws, 0, sizeof j->Cws);
    for (int i = 0; i < NX; i++)
        for (int k = dS_start[i]; k < dS_start[i + 1]; k++) {
            j->BX[i][dS_row[k]] += c->X[dS_col[k]] * j->val[k];
            j->Cws[i][dS_col[k]] += c->ws[dS_row[k]] * j->val[k];
        }
    /* D^T W S_R, BX W S_R, D E, E^T D^T W U, BX W U, Cws E */
    for (int q = 0; q < NP; q++)
        for (int p = 0; p < 3; p++) {
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += c->D[r][q] * weight[r] * w->S[r][p];
            j->DtWSR[q][p] = s;
        }
    for (int i = 0; i < NX; i++)
        for (int p = 0; p < 3; p++) {
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += j->BX[i][r] * weight[r] * w->S[r][p];
            j->BXWSR[i][p] = s;
        }
    for (int r = 0; r < NR; r++)
        for (int k = 0; k < NX; k++)
            j->DE[r][k] = c->D[r][3 + k] + c->D[r][0] * w->P[0][k] + c->D[r][1] * w->P[1][k]
                        + c->D[r][2] * w->P[2][k];
    double (*DtWU)[NX] = j->EtDtWU;   /* E^T applied in place below: rows 0..2 kept apart */
    double top[3][NX];
    for (int k = 0; k < NX; k++) {
        double col[NP];
        for (int q = 0; q < NP; q++) {
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += c->D[r][q] * weight[r] * w->U[r][k];
            col[q] = s;
        }
        for (int p = 0; p < 3; p++) top[p][k] = col[p];
        for (int i = 0; i < NX; i++) DtWU[i][k] = col[3 + i];
    }
    for (int i = 0; i < NX; i++)
        for (int k = 0; k < NX; k++)
            j->EtDtWU[i][k] += w->P[0][i] * top[0][k] + w->P[1][i] * top[1][k] + w->P[2][i] * top[2][k];
    for (int i = 0; i < NX; i++) {
        double row[NR];
        for (int r = 0; r < NR; r++) row[r] = j->BX[i][r] * weight[r];
        for (int k = 0; k < NX; k++) {
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += row[r] * w->U[r][k];
            j->BXWU[i][k] = s;
            j->CwsE[i][k] = j->Cws[i][3 + k] + j->Cws[i][0] * w->P[0][k] + j->Cws[i][1] * w->P[1][k]
                          + j->Cws[i][2] * w->P[2][k];
        }
    }
}

/* dq = dP v: the change of the rigid velocity q* = P v (3.21) for a change dP of P. */
static void rigid_velocity_change(const double dP[3][NX], const double *v, double *dq)
{
    for (int p = 0; p < 3; p++) {
        double t = 0.0;
        for (int k = 0; k < NX; k++) t += dP[p][k] * v[k];
        dq[p] = t;
    }
}

/* What a change dP of P = -Mr^-1 Nc at fixed S adds to dg (dE = [dP; 0], dX = (dq, 0),
 * dq = dP v): dE^T (D_v M) X + T(dX), with T(Y) = E^T (D_v M) Y - grad(X^T M Y)|_{X,Y} (see
 * tangent_x). Collected as the caller does: u what f E^T maps, z what f U^T W maps (before the
 * weights), q the rest. */
static void tangent_rigid(const jac_work *j, const double dP[3][NX], const double *dq, double f,
                          double b, double *u, double *z, double *q)
{
    const work_t *w = &j->w;
    const christoffel_t *c = &j->c;
    for (int qq = 0; qq < NP; qq++)
        u[qq] += j->DtWSR[qq][0] * dq[0] + j->DtWSR[qq][1] * dq[1] + j->DtWSR[qq][2] * dq[2];
    for (int row = 0; row < NR; row++)
        z[row] += c->D[row][0] * dq[0] + c->D[row][1] * dq[1] + c->D[row][2] * dq[2];
    const double X2 = c->X[2];
    for (int i = 0; i < NX; i++)
        /* dE^T (D_v M) X: c3 plus the body term b dIv X2 on the third component; then T(dX) */
        q[i] += dP[0][i] * j->c3[0] + dP[1][i] * j->c3[1] + dP[2][i] * (j->c3[2] + b * c->dIv * X2)
              + b * c->dIv * dq[2] * w->P[2][i]
              - f * (j->Cws[i][0] * dq[0] + j->Cws[i][1] * dq[1] + j->Cws[i][2] * dq[2]
                     + j->BXWSR[i][0] * dq[0] + j->BXWSR[i][1] * dq[1] + j->BXWSR[i][2] * dq[2])
              - b * w->gI[i] * X2 * dq[2];
}

/* q += f E^T u + f U^T W z: the two maps tangent_x and tangent_rigid collect for. */
static void tangent_collect(const jac_work *j, const double *u, const double *z, double f, double *q)
{
    const work_t *w = &j->w;
    add_Et(w, u, f, q);
    for (int i = 0; i < NX; i++) {
        double t = 0.0;
        for (int row = 0; row < NR; row++) t += w->U[row][i] * weight[row] * z[row];
        q[i] += f * t;
    }
}

/* The right side (h, s) of the tangent saddle system for a change dx = e_r of the shape:
 * h = df_s - dg - dK acc + dG^T lambda, s = -dG acc (curv does not depend on x), and
 * dq = dP v, the change of the rigid velocity q* = P v (3.21). With dE = [dP; 0] and dD = D_{e_r} D_v S:
 *   dK acc = E^T (dM) Xa (the terms with dE cancel: M E = [0; K]),
 *   dg = dE^T (D_v M) X + E^T (D_{e_r} D_v M) X - (1/2) D_{e_r} grad(X^T M X)|_X + T(dX), dX = (dq, 0),
 *   T(Y) = E^T (D_v M) Y - grad(X^T M Y)|_{X,Y}: the part of dg from the change of X = E v. */
static void tangent_x(const jac_work *j, int r, const double *sX, const double *v, double f,
                      double b, double *h, double *s, double *dq)
{
    const work_t *w = &j->w;
    const christoffel_t *c = &j->c;
    /* dMr, dNc (Gram product rule) and dP = -Mr^-1 (dMr P + dNc) */
    double T[3][NP];
    memset(T, 0, sizeof T);
    for (int k = dS_start[r]; k < dS_start[r + 1]; k++) {
        const int row = dS_row[k], col = dS_col[k];
        const double fv = f * weight[row] * j->val[k];
        for (int p = 0; p < 3; p++) T[p][col] += fv * w->S[row][p];
        if (col < 3)
            for (int q = 0; q < NP; q++) T[col][q] += fv * w->S[row][q];
    }
    T[2][2] += b * w->gI[r];
    double dP[3][NX];
    for (int k = 0; k < NX; k++) {
        double rhs[3], z[3];
        for (int p = 0; p < 3; p++)
            rhs[p] = T[p][0] * w->P[0][k] + T[p][1] * w->P[1][k] + T[p][2] * w->P[2][k] + T[p][3 + k];
        mr_solve(j->Ml, rhs, z);
        for (int p = 0; p < 3; p++) dP[p][k] = -z[p];
    }
    rigid_velocity_change((const double (*)[NX])dP, v, dq);
    /* u collects what E^T maps, z what U^T W maps, q the rest: dg + dK acc = f E^T u + f U^T W z + q */
    double u[NP], z[NR], q[NX];
    for (int i = 0; i < NP; i++) u[i] = 0.0;
    double sXa[NR];
    for (int i = 0; i < NR; i++) sXa[i] = 0.0;
    for (int k = dS_start[r]; k < dS_start[r + 1]; k++) {
        const int row = dS_row[k], col = dS_col[k];
        const double d = j->val[k];
        u[col] += d * (j->ya[row] + c->dX[row]);   /* dS^T W S Xa, dS^T W D X */
        sXa[row] += d * j->Xa[col];
    }
    u[2] += j->A2ws[r];                            /* dD^T W S X */
    for (int qq = 0; qq < NP; qq++) {              /* D^T W dS X */
        double t = 0.0;
        for (int row = 0; row < NR; row++) t += c->D[row][qq] * weight[row] * sX[row];
        u[qq] += t;
    }
    for (int row = 0; row < NR; row++)             /* dS Xa, dD X */
        z[row] = sXa[row] + j->A2[row][r] * c->X[2];
    const double X2 = c->X[2];
    for (int i = 0; i < NX; i++) {
        double t = 0.0;
        for (int row = 0; row < NR; row++) t += j->BX[i][row] * weight[row] * sX[row];
        q[i] = b * w->gI[r] * j->Xa[2] * w->P[2][i]                         /* body part of dK acc */
             + b * j->HIv[r] * X2 * w->P[2][i]                              /* body part of dD_v M */
             - f * (t + j->H2[i][r]) - 0.5 * b * X2 * X2 * j->HI[i][r];     /* -(1/2) D grad(X^T M X) */
    }
    tangent_rigid(j, (const double (*)[NX])dP, dq, f, b, u, z, q);   /* dE^T (D_v M) X, T(dX) */
    tangent_collect(j, u, z, f, q);
    for (int i = 0; i < NX; i++) h[i] = j->Fx[i][r] - j->HW[NX * i + r] - q[i];
    for (int m = 0; m < SWIM_SCENE_MAX_ROWS; m++) s[m] = 0.0;
    for (int m = 0; m < j->sd.m; m++) {
        const int jj = j->sd.which[m];
        if (jj < 0) continue;   /* a lock: its row e_k does not move */
        double t = 0.0;
        for (int k = 0; k < NX; k++) {
            h[k] += j->Gx[jj][k][r] * j->lam[m];
            t += j->Gx[jj][k][r] * j->acc[k];
        }
        s[m] = -t;
    }
}

/* The same for a change dv = e_r of the velocity: dg = 2 Gamma(v, e_r)
 * = T(E e_r) + E^T (D_{e_r} M) X; K, P, G do not move; s = -d curv. */
static void tangent_v(const jac_work *j, int r, const double *sX, double f, double b, double *h,
                      double *s)
{
    const work_t *w = &j->w;
    const christoffel_t *c = &j->c;
    const double X2 = c->X[2], Pr = w->P[2][r];
    double u[NP], z[NR], q[NX];
    for (int i = 0; i < NP; i++) u[i] = 0.0;
    for (int k = dS_start[r]; k < dS_start[r + 1]; k++) u[dS_col[k]] += j->val[k] * c->ws[dS_row[k]];
    for (int row = 0; row < NR; row++) z[row] = j->DE[row][r] + sX[row];
    for (int i = 0; i < NX; i++)
        q[i] = f * (j->EtDtWU[i][r] - j->CwsE[i][r] - j->BXWU[i][r])
             + b * (c->dIv * Pr * w->P[2][i] - w->gI[i] * X2 * Pr + w->gI[r] * X2 * w->P[2][i]);
    tangent_collect(j, u, z, f, q);
    for (int i = 0; i < NX; i++) h[i] = j->Fv[i][r] - q[i];
    for (int m = 0; m < SWIM_SCENE_MAX_ROWS; m++) s[m] = 0.0;
    for (int m = 0; m < j->sd.m; m++)
        if (j->sd.which[m] == 0) s[m] = -j->cv[r];
}

/* B = K^-1 B in place for the 2 NX columns of B (B[k][d], d the direction), K = L L^T: the
 * substitutions run along rows of B, contiguous, where one right side at a time would walk
 * down the columns of L. */
static void chol_solve_columns(const double *L, double B[NX][2 * NX])
{
    for (int i = 0; i < NX; i++) {
        double *bi = B[i];
        for (int k = 0; k < i; k++) {
            const double l = L[NX * i + k], *bk = B[k];
            for (int d = 0; d < 2 * NX; d++) bi[d] -= l * bk[d];
        }
        const double inv = 1.0 / L[NX * i + i];
        for (int d = 0; d < 2 * NX; d++) bi[d] *= inv;
    }
    for (int i = NX - 1; i >= 0; i--) {
        double *bi = B[i];
        for (int k = i + 1; k < NX; k++) {
            const double l = L[NX * k + i], *bk = B[k];
            for (int d = 0; d < 2 * NX; d++) bi[d] -= l * bk[d];
        }
        const double inv = 1.0 / L[NX * i + i];
        for (int d = 0; d < 2 * NX; d++) bi[d] *= inv;
    }
}

/* h -> K^-1 (h + G^T dl) with G da = 0: the tangent of the accelerations for a change of the
 * right side h alone (K and G fixed). */
static void tangent_solve(const jac_work *j, const double *h, double *da)
{
    double zero[SWIM_SCENE_MAX_ROWS] = {0.0}, dl[SWIM_SCENE_MAX_ROWS];
    chol_solve(j->L, NX, h, da);
    saddle_correct(&j->sd, zero, da, dl);
}

/* d rhs / d b, b = pi rho0, at the state j was set up for. The body's mass matrix
 * M_b = diag(1, 1, I, 1/(|k|+1)) enters Mr and Md only (assembly.h), so dNc = 0,
 * dP = -Mr^-1 diag(1, 1, I) P, dK acc = E^T M_b E acc (the dE terms cancel: M E = [0; K]) and
 * dg = E^T (D_v M_b) X - (1/2) grad(X^T M_b X) + [what dP brings: tangent_rigid]. */
static void partial_body(const jac_work *j, const double *v, double f, double b, double ct,
                         double st, double *out)
{
    enum { DIM = 4 + 2 * NX };
    const work_t *w = &j->w;
    const christoffel_t *c = &j->c;
    double dP[3][NX], dq[3];
    for (int k = 0; k < NX; k++) {
        const double rhs[3] = {w->P[0][k], w->P[1][k], w->Ic * w->P[2][k]};
        double z[3];
        mr_solve(j->Ml, rhs, z);
        for (int p = 0; p < 3; p++) dP[p][k] = -z[p];
    }
    rigid_velocity_change((const double (*)[NX])dP, v, dq);
    double u[NP], z[NR], q[NX], h[NX], da[NX];
    for (int i = 0; i < NP; i++) u[i] = 0.0;
    for (int i = 0; i < NR; i++) z[i] = 0.0;
    for (int i = 0; i < NX; i++) q[i] = 0.0;
    tangent_rigid(j, (const double (*)[NX])dP, dq, f, b, u, z, q);
    tangent_collect(j, u, z, f, q);
    const double X2 = c->X[2];
    for (int i = 0; i < NX; i++) {
        q[i] += c->dIv * X2 * w->P[2][i] - 0.5 * w->gI[i] * X2 * X2
              + w->P[0][i] * j->Xa[0] + w->P[1][i] * j->Xa[1] + w->Ic * w->P[2][i] * j->Xa[2]
              + body_shape[i] * j->acc[i];
        h[i] = -q[i];   /* the forces do not depend on rho0 */
    }
    tangent_solve(j, h, da);
    memset(out, 0, sizeof(double) * DIM);
    out[0] = ct * dq[0] - st * dq[1];   /* R(theta) dP v (3.21) */
    out[1] = st * dq[0] + ct * dq[1];
    out[2] = dq[2];
    for (int i = 0; i < NX; i++) out[3 + NX + i] = da[i];
}

/* d rhs / d param at the state j was set up for (out: DIM entries). The densities: rho0 from
 * partial_body; rhof from homogeneity -- scaling both densities by s scales K and <Gamma, v, v>
 * by s and keeps P, so f d/df + b d/db of the accelerations is -K^-1 F (F the forces without
 * inertia, on the constraints) and 0 elsewhere. The forces' parameters: K^-1 dF on the
 * constraints, and d power. */
static int partial_param(const jac_work *j, double t, const double *x, const double *v, double f,
                         double b, double ct, double st, const swim_scene_params *p,
                         swim_param param, double *out)
{
    enum { DIM = 4 + 2 * NX };
    double dF[NX], da[NX], dpow = 0.0;
    memset(out, 0, sizeof(double) * DIM);
    for (int i = 0; i < NX; i++) dF[i] = 0.0;
    switch (param.kind) {
    case SWIM_PARAM_RHO0:
        partial_body(j, v, f, b, ct, st, out);
        for (int i = 0; i < DIM; i++) out[i] *= KPI;
        return 0;
    case SWIM_PARAM_RHOF:
        if (!(f > 0.0)) return SWIM_RHS_ENAN;
        partial_body(j, v, f, b, ct, st, out);
        for (int i = 0; i < NX; i++) dF[i] = j->fs[i] + j->g[i];
        tangent_solve(j, dF, da);
        for (int i = 0; i < DIM; i++) out[i] = -b * out[i] / f;
        for (int i = 0; i < NX; i++) out[3 + NX + i] -= da[i] / f;
        for (int i = 0; i < DIM; i++) out[i] *= KPI;
        return 0;
    case SWIM_PARAM_BARRIER_SCALE:
#ifdef SWIM_SCENE_BARRIER
        for (int i = 0; i < NX; i++) dF[i] = -j->gW[i];   /* eps d/d eps of -grad W2 */
#endif
        break;
    default: {
        int reads = scene_forces_dp(t, x, v, p, param.kind, param.index, dF, &dpow);
#ifdef SWIM_SCENE_MATERIAL
        if (param.kind == SWIM_PARAM_LAW) {   /* the energy law's parameters: -d grad W / d p */
            double dg[NX];
            if (material_energy_dp(x, p, param.index, dg)) {
                for (int i = 0; i < NX; i++) dF[i] -= dg[i];
                reads = 1;
            }
        }
#endif
        if (!reads) return 0;
        break;
    }
    }
    tangent_solve(j, dF, da);
    for (int i = 0; i < NX; i++) out[3 + NX + i] = da[i];
    out[3 + 2 * NX] = dpow;
    return 0;
}

static int scene_jacobian_params(double t, const double *y, double *J, int np, const swim_param *param,
                                 double *dp, const swim_scene_params *p)
{
    enum { DIM = 4 + 2 * NX };
    double x[NFULL];
    memcpy(x, p->x_locked, sizeof x);
    for (int k = 0; k < NX; k++) x[free_index[k]] = y[3 + k];
    const double *v = y + 3 + NX;
    for (int i = 0; i < DIM; i++)
        if (!isfinite(y[i])) return SWIM_RHS_ENAN;
    const double f = p->rhof * KPI, b = p->rho0 * KPI;
    jac_work *j = malloc(sizeof *j);
    double *Jown = J ? NULL : malloc(sizeof(double) * DIM * DIM);
    if (!j || (!J && !Jown)) {
        free(j);
        free(Jown);
        return -1;
    }
    if (!J) J = Jown;
    int rc = SWIM_RHS_OK;
    double power = 0.0;
    if (setup(x, p->rho0, p->rhof, &j->w) != 0) { rc = SWIM_RHS_EMASS; goto done; }
    reduced_matrix(&j->w, f, b, j->L);
    christoffel_vv(&j->w, x, v, f, b, &j->c, j->g);
    scene_forces(t, x, v, j->g, p, j->fs, &power);
    memset(j->HW, 0, sizeof j->HW);
#ifdef SWIM_SCENE_BARRIER
    if (!p->barrier_hessian) { rc = -1; goto done; }
    if (p->barrier_hessian(x, j->gW, j->HW, p->barrier_ctx) != 0) { rc = SWIM_RHS_EBARRIER; goto done; }
    for (int i = 0; i < NX; i++) j->fs[i] -= j->gW[i];
#endif
#ifdef SWIM_SCENE_MATERIAL
    {   /* the energy law: its gradient into the forces, its Hessian next to W2's */
        double Wm, gm[NX], *Hm = malloc(sizeof(double) * NX * NX);
        if (!Hm) { rc = -1; goto done; }
        const int bad = material_energy(x, p, &Wm, gm, Hm);
        for (int i = 0; i < NX; i++) {
            j->fs[i] -= gm[i];
            for (int k = 0; k < NX; k++) j->HW[NX * i + k] += Hm[NX * i + k];
        }
        free(Hm);
        if (bad) { rc = SWIM_RHS_ENAN; goto done; }
    }
#endif
    if (chol_factor(j->L, NX) != 0) { rc = SWIM_RHS_EMASS; goto done; }
    if ((rc = saddle_setup(j->L, x, v, p, &j->sd)) != 0) goto done;
    saddle_solve(j->L, &j->sd, j->fs, j->sd.r, j->acc, j->lam);
    mr_factor(j->w.Mr, j->Ml);
    memset(j->Fx, 0, sizeof j->Fx);
    memset(j->Fv, 0, sizeof j->Fv);
    memset(j->px, 0, sizeof j->px);
    memset(j->pv, 0, sizeof j->pv);
    memset(j->Gx, 0, sizeof j->Gx);
    memset(j->cv, 0, sizeof j->cv);
    scene_forces_jac(t, x, v, p, j->Fx, j->Fv, j->px, j->pv);
    scene_constraints_jac(x, v, j->Gx, j->cv);
    jacobian_tables(j, x, v, f);

    memset(J, 0, sizeof(double) * DIM * DIM);
    const double ct = cos(y[2]), st = sin(y[2]);
    double qs[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < NX; k++)
        for (int i = 0; i < 3; i++) qs[i] += j->w.P[i][k] * v[k];
    J[DIM * 0 + 2] = -st * qs[0] - ct * qs[1];   /* d R(theta) q* / d theta (3.21) */
    J[DIM * 1 + 2] = ct * qs[0] - st * qs[1];
    /* right sides of the tangent systems: direction d = r (x_r) and d = NX + r (v_r), as the
     * columns of B; then K^-1 on all of them at once, then the constraint correction of each */
    for (int r = 0; r < NX; r++) {
        double sX[NR], h[NX], dq[3];
        for (int i = 0; i < NR; i++) sX[i] = 0.0;   /* (d S / d x_r) X */
        for (int k = dS_start[r]; k < dS_start[r + 1]; k++) sX[dS_row[k]] += j->val[k] * j->c.X[dS_col[k]];
        tangent_x(j, r, sX, v, f, b, h, j->S[r], dq);
        for (int i = 0; i < NX; i++) j->B[i][r] = h[i];
        const int cx = 3 + r, cvr = 3 + NX + r;
        J[DIM * 0 + cx] = ct * dq[0] - st * dq[1];   /* R(theta) dP v (3.21) */
        J[DIM * 1 + cx] = st * dq[0] + ct * dq[1];
        J[DIM * 2 + cx] = dq[2];
        J[DIM * (3 + 2 * NX) + cx] = j->px[r];
        tangent_v(j, r, sX, f, b, h, j->S[NX + r]);
        for (int i = 0; i < NX; i++) j->B[i][NX + r] = h[i];
        J[DIM * 0 + cvr] = ct * j->w.P[0][r] - st * j->w.P[1][r];   /* R(theta) P e_r */
        J[DIM * 1 + cvr] = st * j->w.P[0][r] + ct * j->w.P[1][r];
        J[DIM * 2 + cvr] = j->w.P[2][r];
        J[DIM * (3 + r) + cvr] = 1.0;
        J[DIM * (3 + 2 * NX) + cvr] = j->pv[r];
    }
    chol_solve_columns(j->L, j->B);
    for (int d = 0; d < 2 * NX; d++) {
        double da[NX], dl[SWIM_SCENE_MAX_ROWS];
        for (int i = 0; i < NX; i++) da[i] = j->B[i][d];
        saddle_correct(&j->sd, j->S[d], da, dl);
        const int col = 3 + d;   /* x_r for d < NX, v_r after */
        for (int i = 0; i < NX; i++) J[DIM * (3 + NX + i) + col] = da[i];
    }
    for (int i = 0; i < DIM * DIM; i++)
        if (!isfinite(J[i])) { rc = SWIM_RHS_ENAN; break; }
    for (int k = 0; k < np && rc == SWIM_RHS_OK; k++) {
        double *out = dp + (size_t)k * DIM;
        rc = partial_param(j, t, x, v, f, b, ct, st, p, param[k], out);
        for (int i = 0; i < DIM && rc == SWIM_RHS_OK; i++)
            if (!isfinite(out[i])) rc = SWIM_RHS_ENAN;
    }
done:
    free(j);
    free(Jown);
    return rc;
}

static int scene_jacobian(double t, const double *y, double *J, const swim_scene_params *p)
{
    return scene_jacobian_params(t, y, J, 0, NULL, NULL, p);
}

#ifdef SWIM_SCENE_MATERIAL
/* The energy law's W, gradient and Hessian at the full shape x (kernel/swim_kernel.h, material). */
static int scene_material(const double *x, const swim_scene_params *p, double *W, double *grad, double *hess)
{
    double g[NX];
    return material_energy(x, p, W, grad ? grad : g, hess);
}
#endif

const swim_scene_kernel swim_scene_kernel_entry = {
    .abi = SWIM_KERNEL_ABI,
    .modes = NFULL / 2 - 1,
    .nfull = NFULL,
    .nfree = NX,
    .free_index = free_index,
    .structure = SWIM_SCENE_STRUCTURE,
    .rhs = scene_rhs,
    .jacobian = scene_jacobian,
    .jacobian_params = scene_jacobian_params,
#ifdef SWIM_SCENE_MATERIAL
    .material = scene_material,
#endif
};

#endif
