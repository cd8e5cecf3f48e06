/* sparse_data.h -- the boundary data S(x) of large kernels and its first derivatives, by loops
 * over a generated table of monomials (included by a generated kernel, not linked).
 *
 * Every entry of S is a short polynomial in x: linear in the mu and nu columns (two terms),
 * quadratic in the alpha column (generator/swimgen/model.py). Printed as straight-line C, their
 * derivatives and contractions grow to tens of thousands of statements at N = 32, which take the
 * compiler most of a kernel's first use; as a table they are data, compiled in no time, and each
 * function below is one pass over it. Kernels of N <= 7 keep the straight-line code
 * (generator/swimgen/emit.py, TABLE_ABOVE).
 *
 * The generated file defines, before including this file, besides NFULL, NX, NR, NP:
 *   SD_NE, sd_at[SD_NE], sd_start[SD_NE + 1]   the non-zero entries of S (flat index row * NP +
 *                            col) and where their terms start;
 *   SD_NT, sd_c[SD_NT], sd_i[SD_NT], sd_k[SD_NT]   term t is sd_c[t] * xo[sd_i[t]] * xo[sd_k[t]],
 *                            where xo is x followed by a 1 (index NFULL: a linear term);
 *   sd_pos[NFULL + 1]        the velocity position of each coordinate, -1 when it is locked;
 *   with SWIM_SPARSE_PARTIALS: SD_NKEYS (NDS) and sd_ki[SD_NT], sd_kk[SD_NT]   the index, in
 *                            the sorted first partials of scene_rhs.h (dS_row, dS_col, dS_start),
 *                            of d/dx_i and of d/dx_k of term t, -1 when that coordinate is locked
 *                            (or is the 1).
 * It defines the bodies the symbolic wrappers call: sparse_boundary_data, _dir, _bigrad, and
 * sparse_boundary_data_deriv (SWIM_KERNEL_FULL) or sparse_boundary_data_partials.
 */
#ifndef SWIM_KERNEL_SPARSE_DATA_H
#define SWIM_KERNEL_SPARSE_DATA_H

#include <string.h>

static void sparse_extend(const double *x, double *xo)
{
    memcpy(xo, x, sizeof(double) * NFULL);
    xo[NFULL] = 1.0;
}

/* S = sum over terms; S is cleared by the caller. */
static void sparse_boundary_data(const double *x, double S[NR][NP])
{
    double xo[NFULL + 1];
    sparse_extend(x, xo);
    double *s = &S[0][0];
    for (int e = 0; e < SD_NE; e++) {
        double acc = 0.0;
        for (int t = sd_start[e]; t < sd_start[e + 1]; t++)
            acc += sd_c[t] * xo[sd_i[t]] * xo[sd_k[t]];
        s[sd_at[e]] = acc;
    }
}

/* D_v S: the product rule on each term, d(x_i x_k)[v] = y_i x_k + x_i y_k with y = v on the
 * carried coordinates, 0 on the locked ones and on the 1. D is cleared by the caller. */
static void sparse_boundary_data_dir(const double *x, const double *v, double D[NR][NP])
{
    double xo[NFULL + 1], yo[NFULL + 1];
    sparse_extend(x, xo);
    for (int i = 0; i <= NFULL; i++) yo[i] = sd_pos[i] >= 0 ? v[sd_pos[i]] : 0.0;
    double *d = &D[0][0];
    for (int e = 0; e < SD_NE; e++) {
        double acc = 0.0;
        for (int t = sd_start[e]; t < sd_start[e + 1]; t++) {
            const int i = sd_i[t], k = sd_k[t];
            acc += sd_c[t] * (yo[i] * xo[k] + xo[i] * yo[k]);
        }
        d[sd_at[e]] = acc;
    }
}

/* g_r = sum_{row,col} w_row X_col dS[row][col]/dx_r: each term scatters into the gradient of its
 * two factors (the 1 and the locked coordinates collect what is then dropped). */
static void sparse_boundary_data_bigrad(const double *x, const double *w, const double *X, double *g)
{
    double xo[NFULL + 1], gf[NFULL + 1];
    sparse_extend(x, xo);
    memset(gf, 0, sizeof gf);
    for (int e = 0; e < SD_NE; e++) {
        const double wx = w[sd_at[e] / NP] * X[sd_at[e] % NP];
        for (int t = sd_start[e]; t < sd_start[e + 1]; t++) {
            const int i = sd_i[t], k = sd_k[t];
            const double cw = sd_c[t] * wx;
            gf[i] += cw * xo[k];
            gf[k] += cw * xo[i];
        }
    }
    for (int i = 0; i < NFULL; i++)
        if (sd_pos[i] >= 0) g[sd_pos[i]] = gf[i];
}

#ifdef SWIM_KERNEL_FULL
/* dS[r][row][col] = dS[row][col]/dx_r; the caller clears dS. */
static void sparse_boundary_data_deriv(const double *x, double *dS)
{
    double xo[NFULL + 1];
    sparse_extend(x, xo);
    for (int e = 0; e < SD_NE; e++)
        for (int t = sd_start[e]; t < sd_start[e + 1]; t++) {
            const int i = sd_i[t], k = sd_k[t];
            if (sd_pos[i] >= 0) dS[(size_t)sd_pos[i] * NR * NP + sd_at[e]] += sd_c[t] * xo[k];
            if (sd_pos[k] >= 0) dS[(size_t)sd_pos[k] * NR * NP + sd_at[e]] += sd_c[t] * xo[i];
        }
}
#endif

#ifdef SWIM_SPARSE_PARTIALS
/* val[key] = d S[dS_row[key]][dS_col[key]] / dx_r (kernel/scene_rhs.h's sparse first partials). */
static void sparse_boundary_data_partials(const double *x, double *val)
{
    double xo[NFULL + 1];
    sparse_extend(x, xo);
    memset(val, 0, sizeof(double) * SD_NKEYS);
    for (int t = 0; t < SD_NT; t++) {
        if (sd_ki[t] >= 0) val[sd_ki[t]] += sd_c[t] * xo[sd_k[t]];
        if (sd_kk[t] >= 0) val[sd_kk[t]] += sd_c[t] * xo[sd_i[t]];
    }
}
#endif

#endif
