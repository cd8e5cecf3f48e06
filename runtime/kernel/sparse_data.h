/* sparse_data.h -- the boundary data S(x) of large kernels and its first derivatives, by loops
 * over a generated table of monomials (included by a generated kernel, not linked).
 *
 * Every entry of S is a short polynomial in x: linear in the mu and nu columns (two terms),
 * quadratic in the alpha column (generator/swimgen/model.py). Printed by SymPy as straight-line C
 * (with cse), S, its derivatives and their contractions grow to tens of thousands of statements
 * at N = 32, which took the generator and the compiler most of a kernel's first use; as a table
 * they are data, printed and compiled in no time, and each function below is one pass over it.
 * Kernels of N <= 7 keep SymPy's straight-line code (generator/swimgen/emit.py, TABLE_ABOVE).
 *
 * The generated file defines, before including this file, besides NFULL, NX, NR, NP (xo is x
 * followed by a 1 at index NFULL):
 *   SD_NL, SD_W, sl_at[SD_NL], sl_c[SD_W][SD_NL], sl_i[SD_W][SD_NL]   the linear terms: entry
 *                            S[sl_at[e] / NP][sl_at[e] % NP] has the terms sl_c[w][e] * x[sl_i[w][e]],
 *                            w < SD_W, padded with coefficient 0 at index NFULL (a fixed count
 *                            per entry: the loop has no data-dependent branch);
 *   SD_NQE, SD_NQ, sq_at[SD_NQE], sq_start[SD_NQE + 1], sq_c[SD_NQ], sq_i[SD_NQ], sq_k[SD_NQ]
 *                            the quadratic terms, entry by entry: sq_c[t] * x[sq_i[t]] * x[sq_k[t]];
 *   sd_pos[NFULL + 1]        the velocity position of each coordinate, -1 when it is locked (and
 *                            for the 1);
 *   with SWIM_SPARSE_LOOPS: sg_start[NX + 1], sg_c[], sg_at[], sg_k[]   the first partials term by
 *                            term, coordinate by coordinate: d S.flat[sg_at[t]] / dx_r has the term
 *                            sg_c[t] * xo[sg_k[t]] for sg_start[r] <= t < sg_start[r + 1];
 *   with SWIM_SPARSE_PARTIALS: SD_NKEYS (NDS), sl_key[SD_W][SD_NL], sq_ki[SD_NQ], sq_kk[SD_NQ]
 *                            the index, in the sorted first partials of scene_rhs.h (dS_row,
 *                            dS_col, dS_start), of the derivative of a linear term and of the
 *                            derivatives in x_i and x_k of a quadratic one, -1 when that
 *                            coordinate is locked (or is padding).
 * It defines what the symbolic wrappers call: sparse_outer (the products w_row X_col the
 * bigradient weighs its terms with); with SWIM_SPARSE_LOOPS (the kernel of N modes, which serves
 * diagnostics, not the integration) sparse_boundary_data, sparse_boundary_data_dir and
 * sparse_boundary_data_bigrad (a scene kernel prints these three from the monomials, still
 * without SymPy: one statement per entry of S and D_v S, one sum per coordinate of the
 * bigradient; they run in half the time or less of these loops and compile in a few seconds at
 * N = 32); and sparse_boundary_data_deriv (SWIM_KERNEL_FULL) or sparse_boundary_data_partials
 * (SWIM_SPARSE_PARTIALS).
 */
#ifndef SWIM_KERNEL_SPARSE_DATA_H
#define SWIM_KERNEL_SPARSE_DATA_H

#include <string.h>

static void sparse_extend(const double *x, double *xo)
{
    memcpy(xo, x, sizeof(double) * NFULL);
    xo[NFULL] = 1.0;
}

/* wx[row * NP + col] = w_row X_col, what the terms of the bigradient weigh. */
static void sparse_outer(const double *w, const double *X, double *wx)
{
    for (int r = 0; r < NR; r++)
        for (int q = 0; q < NP; q++) wx[r * NP + q] = w[r] * X[q];
}

#ifdef SWIM_SPARSE_LOOPS
/* The entries of a polynomial table at xo (S) or its directional derivative (yo: the direction
 * on the carried coordinates, 0 elsewhere): out is cleared by the caller. */
static void sparse_eval(const double *xo, const double *yo, double *out)
{
    const double *lin = yo ? yo : xo;   /* a linear term's derivative along y is its value at y */
    for (int e = 0; e < SD_NL; e++) {
        double acc = 0.0;
        for (int w = 0; w < SD_W; w++) acc += sl_c[w][e] * lin[sl_i[w][e]];
        out[sl_at[e]] = acc;
    }
    for (int e = 0; e < SD_NQE; e++) {
        double acc = 0.0;
        if (yo)   /* product rule: d(x_i x_k)[y] = y_i x_k + x_i y_k */
            for (int t = sq_start[e]; t < sq_start[e + 1]; t++)
                acc += sq_c[t] * (yo[sq_i[t]] * xo[sq_k[t]] + xo[sq_i[t]] * yo[sq_k[t]]);
        else
            for (int t = sq_start[e]; t < sq_start[e + 1]; t++)
                acc += sq_c[t] * xo[sq_i[t]] * xo[sq_k[t]];
        out[sq_at[e]] += acc;
    }
}

static void sparse_boundary_data(const double *x, double S[NR][NP])
{
    double xo[NFULL + 1];
    sparse_extend(x, xo);
    sparse_eval(xo, NULL, &S[0][0]);
}

/* D_v S; D is cleared by the caller. */
static void sparse_boundary_data_dir(const double *x, const double *v, double D[NR][NP])
{
    double xo[NFULL + 1], yo[NFULL + 1];
    sparse_extend(x, xo);
    for (int i = 0; i <= NFULL; i++) yo[i] = sd_pos[i] >= 0 ? v[sd_pos[i]] : 0.0;
    sparse_eval(xo, yo, &D[0][0]);
}

/* g_r = sum_{row,col} w_row X_col dS[row][col]/dx_r, coordinate by coordinate from the terms of
 * the first partials (sg_*), two sums in turn so that the additions do not wait on each other. */
static void sparse_boundary_data_bigrad(const double *x, const double *w, const double *X, double *g)
{
    double xo[NFULL + 1], wx[NR * NP];
    sparse_extend(x, xo);
    sparse_outer(w, X, wx);
    for (int r = 0; r < NX; r++) {
        double a0 = 0.0, a1 = 0.0;
        int t = sg_start[r];
        for (; t + 1 < sg_start[r + 1]; t += 2) {
            a0 += sg_c[t] * wx[sg_at[t]] * xo[sg_k[t]];
            a1 += sg_c[t + 1] * wx[sg_at[t + 1]] * xo[sg_k[t + 1]];
        }
        if (t < sg_start[r + 1]) a0 += sg_c[t] * wx[sg_at[t]] * xo[sg_k[t]];
        g[r] = a0 + a1;
    }
}
#endif

#ifdef SWIM_KERNEL_FULL
/* dS[r][row][col] = dS[row][col]/dx_r; the caller clears dS. */
static void sparse_boundary_data_deriv(const double *x, double *dS)
{
    double xo[NFULL + 1];
    sparse_extend(x, xo);
    for (int e = 0; e < SD_NL; e++)
        for (int k = 0; k < SD_W; k++)
            if (sd_pos[sl_i[k][e]] >= 0) dS[(size_t)sd_pos[sl_i[k][e]] * NR * NP + sl_at[e]] += sl_c[k][e];
    for (int e = 0; e < SD_NQE; e++)
        for (int t = sq_start[e]; t < sq_start[e + 1]; t++) {
            const int i = sq_i[t], k = sq_k[t];
            if (sd_pos[i] >= 0) dS[(size_t)sd_pos[i] * NR * NP + sq_at[e]] += sq_c[t] * xo[k];
            if (sd_pos[k] >= 0) dS[(size_t)sd_pos[k] * NR * NP + sq_at[e]] += sq_c[t] * xo[i];
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
    for (int e = 0; e < SD_NL; e++)
        for (int k = 0; k < SD_W; k++)
            if (sl_key[k][e] >= 0) val[sl_key[k][e]] += sl_c[k][e];
    for (int t = 0; t < SD_NQ; t++) {
        if (sq_ki[t] >= 0) val[sq_ki[t]] += sq_c[t] * xo[sq_k[t]];
        if (sq_kk[t] >= 0) val[sq_kk[t]] += sq_c[t] * xo[sq_i[t]];
    }
}
#endif

#endif
