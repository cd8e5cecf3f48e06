/* assembly.h -- the fixed-size assembly every generated kernel shares (included, not linked).
 *
 * A generated kernel (generated/swim_kernel_n*.c, or a scene kernel from the run-time cache)
 * defines the sizes and the symbolic pieces SymPy derived, then includes this file:
 *   NFULL  length of the shape vector x;  NX  velocity coordinates carried (free ones);
 *   NR, NP rows and columns of the boundary-data matrix S (generator/swimgen/model.py);
 *   weight[NR]      the factor j of the weighted product u.s = sum_j j (u1_j s1_j + u2_j s2_j);
 *   body_shape[NX]  body part of Md over pi rho0: 1/(|k|+1) (ERRATA A7);
 *   boundary_data(x, S), boundary_data_dir(x, v, D) = D_v S, boundary_data_bigrad(x, w, X, g)
 *   (g_i = w^T (d_i S) X), inertia(x, grad) = sum_k |c_k|^2/(|k|+1) and its gradient;
 *   with SWIM_KERNEL_JACOBIAN: jacobian_circle(x, cs, sn, J, dJ) (2.4);
 *   with SWIM_KERNEL_FULL (all coordinates free, nothing folded, and SWIM_KERNEL_JACOBIAN):
 *   boundary_data_deriv(x, dS) and SWIM_KERNEL_NAME, the exported swim_kernel (mass matrices,
 *   their derivatives, Gamma).
 * Sizes are compile-time constants, so the loops have fixed trip counts the compiler unrolls and
 * vectorizes; matrix products stay loops (scalar expansion of dense algebra makes straight-line
 * code that compilers choke on).
 */
#ifndef SWIM_KERNEL_ASSEMBLY_H
#define SWIM_KERNEL_ASSEMBLY_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/swim_kernel.h"

#if !defined(NFULL) || !defined(NX) || !defined(NR) || !defined(NP)
#error "define NFULL, NX, NR and NP before including kernel/assembly.h"
#endif
#if defined(SWIM_KERNEL_FULL) && (!defined(SWIM_KERNEL_JACOBIAN) || NX != NFULL)
#error "a full kernel carries every coordinate and J on the circle"
#endif

#define KPI 3.14159265358979323846

typedef struct {
    double S[NR][NP];   /* boundary data */
    double U[NR][NX];   /* S E with E = [P; I]: data of the reduced velocities */
    double P[3][NX];    /* -Mr^-1 Nc */
    double Mr[9], Nc[3 * NX], Ic, gI[NX];
} work_t;

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

/* P = -Mr^-1 Nc by a 3x3 Cholesky factorization, for the ncol columns of Nc and P (3 x ncol,
 * row-major); -1 if Mr is not positive definite. Each column by the same operations whatever
 * ncol is (row_blocks solves a few of them). */
static int schur_cols(const double *M, const double *Nc, int ncol, double *P)
{
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
    for (int k = 0; k < ncol; k++) {
        double y0 = Nc[k] / l00;
        double y1 = (Nc[ncol + k] - l10 * y0) / l11;
        double y2 = (Nc[2 * ncol + k] - l20 * y0 - l21 * y1) / l22;
        double z2 = y2 / l22;
        double z1 = (y1 - l21 * z2) / l11;
        double z0 = (y0 - l10 * z1 - l20 * z2) / l00;
        P[k] = -z0;
        P[ncol + k] = -z1;
        P[2 * ncol + k] = -z2;
    }
    return 0;
}

/* P, then U = S E (the data of the reduced velocities). */
static int schur_factor(work_t *w)
{
    if (schur_cols(w->Mr, w->Nc, NX, &w->P[0][0]) != 0) return -1;
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
        /* the rigid part along the whole row (a vector loop; the entries left of the diagonal
         * are not used: K takes its upper triangle, below) */
        const double p0 = w->P[0][i], p1 = w->P[1][i], p2 = w->Ic * w->P[2][i];
        for (int j = 0; j < NX; j++)
            acc[i][j] = row[j] + b * (p0 * w->P[0][j] + p1 * w->P[1][j] + p2 * w->P[2][j]);
        acc[i][i] += b * body_shape[i];
    }
    for (int i = 0; i < NX; i++) {
        for (int j = 0; j < i; j++) K[NX * i + j] = acc[j][i];
        for (int j = i; j < NX; j++) K[NX * i + j] = acc[i][j];
    }
}

/* What <Gamma, v, v> is computed from, kept for its derivatives (kernel/scene_rhs.h). */
typedef struct {
    double X[NP];       /* X = (P v, v): the velocity that minimizes X^T M X for this v (Lemma 4.3) */
    double ws[NR];      /* W S X */
    double D[NR][NP];   /* D_v S */
    double dX[NR];      /* W (D_v S) X */
    double a[NP];       /* (D_v S)^T W S X */
    double dIv;         /* D_v I (over pi rho0) */
} christoffel_t;

/* gvv = <Gamma(c), v, v> from the blocks in w, without the tensor. */
static void christoffel_vv(const work_t *w, const double *x, const double *v, double f, double b,
                           christoffel_t *c, double *gvv)
{
    double *X = c->X, *ws = c->ws, *dX = c->dX, *a = c->a;
    for (int p = 0; p < 3; p++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w->P[p][k] * v[k];
        X[p] = s;
    }
    for (int k = 0; k < NX; k++) X[3 + k] = v[k];
    for (int r = 0; r < NR; r++) {
        double s = 0.0;
        for (int k = 0; k < NX; k++) s += w->U[r][k] * v[k];
        ws[r] = weight[r] * s;
    }
    boundary_data_dir(x, v, c->D);
    for (int q = 0; q < NP; q++) a[q] = 0.0;
    for (int r = 0; r < NR; r++) {
        double s = 0.0;
        for (int q = 0; q < NP; q++) {
            a[q] += c->D[r][q] * ws[r];
            s += c->D[r][q] * X[q];
        }
        dX[r] = weight[r] * s;
    }
    double g[NX];
    boundary_data_bigrad(x, ws, X, g);
    double dIv = 0.0;
    for (int k = 0; k < NX; k++) dIv += w->gI[k] * v[k];
    c->dIv = dIv;
    const double q2 = X[2];
    /* [D_v(K v)]_i = (E^T (D_v M) X)_i;  d_i(v^T K v)/2 = X^T (d_i M) X / 2 at fixed X. */
    for (int i = 0; i < NX; i++) {
        double s = a[3 + i] + w->P[0][i] * a[0] + w->P[1][i] * a[1] + w->P[2][i] * a[2];
        for (int r = 0; r < NR; r++) s += w->U[r][i] * dX[r];
        gvv[i] = f * (s - g[i]) + b * (dIv * q2 * w->P[2][i] - 0.5 * w->gI[i] * q2 * q2);
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
    christoffel_t c;
    christoffel_vv(&w, x, v, f, b, &c, gvv);
    return 0;
}

#ifdef SWIM_KERNEL_FULL
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

/* The blocks the row diagnostics read (swim_kernel.row_blocks): from one evaluation of the
 * boundary data Mr, and the columns of Nc, P and Md where v is not 0, each entry by the same
 * operations as rigid_blocks, mass and reduced (the same bits: a column of the Gram product is
 * a sum over the rows of S of its own). */
static int row_blocks(const double *x, const double *v, double rho0, double rhof, double *Mr, double *Nc,
                      double *P, int *idx, double *Md)
{
    double S[NR][NP];
    const double f = rhof * KPI, b = rho0 * KPI;
    boundary_data(x, S);
    const double Ic = inertia(x, NULL);
    int m = 0;
    for (int i = 0; i < NX; i++)
        if (v[i] != 0.0) idx[m++] = i;
    double t[3][NR], acc[3][3] = {{0.0}};   /* t: the factors of rigid_blocks' sums */
    for (int p = 0; p < 3; p++)
        for (int r = 0; r < NR; r++) t[p][r] = f * weight[r] * S[r][p];
    for (int r = 0; r < NR; r++)
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++) acc[p][q] += t[p][r] * S[r][q];
    for (int p = 0; p < 3; p++) {
        for (int q = 0; q < 3; q++) Mr[3 * p + q] = acc[p < q ? p : q][p < q ? q : p];
        for (int a = 0; a < m; a++) {
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += t[p][r] * S[r][3 + idx[a]];
            Nc[m * p + a] = s;
        }
    }
    Mr[0] += b;
    Mr[4] += b;
    Mr[8] += b * Ic;
    for (int a = 0; a < m; a++)
        for (int c = a; c < m; c++) {
            const int i = idx[a], j = idx[c];   /* i <= j: mass sums the upper triangle */
            double s = 0.0;
            for (int r = 0; r < NR; r++) s += f * weight[r] * S[r][3 + i] * S[r][3 + j];
            Md[m * a + c] = Md[m * c + a] = s + (i == j ? b * body_shape[i] : 0.0);
        }
    return schur_cols(Mr, Nc, m, P) != 0 ? -1 : m;
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

const swim_kernel SWIM_KERNEL_NAME = {
    .modes = NFULL / 2 - 1,
    .dim = NX,
    .mass = mass,
    .row_blocks = row_blocks,
    .mass_deriv = mass_deriv,
    .reduced = reduced,
    .reduced_deriv = reduced_deriv,
    .jacobian_circle = jacobian_circle,
    .inertia = inertia,
    .boundary_data = boundary_data_flat,
};
#endif

#endif
