#include "shape/constraints.h"

#include "kernel/coords.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int swim_constraint_rows(int n, const double *x, const int *free_mask, double *G)
{
    int m = 2;
    memset(G, 0, sizeof(double) * (size_t)n * (size_t)(n + 2));
    for (int i = 0; i < n; i += 2) {
        const int k = swim_coord_mode(i), ak = abs(k);
        G[i] = k * x[i];
        G[i + 1] = k * x[i + 1];
        G[n + i] = x[i + 1] / (ak + 1);
        G[n + i + 1] = -x[i] / (ak + 1);
    }
    for (int i = 0; i < n; i++)
        if (!free_mask[i]) G[(size_t)n * m++ + i] = 1.0;
    return m;
}

int swim_constraint_locked_index(int n, const int *free_mask, int row)
{
    int r = 2;
    for (int i = 0; i < n; i++)
        if (!free_mask[i] && r++ == row) return i;
    return -1;
}

int swim_constraint_project(int n, int m, const double *G, double *v)
{
    double *A = malloc(sizeof(double) * (size_t)(m * m + m));
    if (!A) return -1;
    double *b = A + m * m;
    for (int i = 0; i < m; i++) {
        b[i] = 0.0;
        for (int k = 0; k < n; k++) b[i] += G[i * n + k] * v[k];
        for (int j = 0; j < m; j++) {
            double s = 0.0;
            for (int k = 0; k < n; k++) s += G[i * n + k] * G[j * n + k];
            A[i * m + j] = s;
        }
    }
    int rc = LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', m, 1, A, m, b, 1) == 0 ? 0 : -1;
    if (rc == 0)
        for (int i = 0; i < m; i++)
            for (int k = 0; k < n; k++) v[k] -= G[i * n + k] * b[i];
    free(A);
    return rc;
}

double swim_area_constant_moving(int n, const double *c)
{
    double mu2 = 0.0;
    for (int i = 0; i < n; i += 2) {
        if (c[i] == 0.0 && c[i + 1] == 0.0) continue;   /* k (0 + 0) = +-0 */
        mu2 += swim_coord_mode(i) * (c[i] * c[i] + c[i + 1] * c[i + 1]);
    }
    return mu2;
}

void swim_constraint_residuals_at(int n, const double *c, const double *v, const double *c0, double mu0,
                                  const int *free_mask, swim_constraint_residuals *r)
{
    r->volume = swim_area_constant_moving(n, c) - mu0;
    /* G1.v and G2.v with the rows of swim_constraint_rows formed term by term, in its order (the
     * same sums to the bit), without writing G: this runs at every step */
    double rate = 0.0, ang = 0.0, locks = 0.0;
    for (int i = 0; i < n; i += 2) {
        /* a mode at rest (v = 0, c finite: the locked ones) adds four signed zeros to sums that
         * start at +0, which changes no bit: its two divisions are skipped */
        if (v[i] == 0.0 && v[i + 1] == 0.0 && isfinite(c[i]) && isfinite(c[i + 1])) continue;
        const int k = swim_coord_mode(i), ak = abs(k);
        rate += (k * c[i]) * v[i];
        rate += (k * c[i + 1]) * v[i + 1];
        ang += (c[i + 1] / (ak + 1)) * v[i];
        ang += (-c[i] / (ak + 1)) * v[i + 1];
    }
    for (int i = 0; i < n; i++)
        if (!free_mask[i]) {
            const double e = fabs(c[i] - c0[i]) + fabs(v[i]);
            if (e > locks) locks = e;   /* fmax(locks, e) without the library call: a NaN e is skipped */
        }
    r->volume_rate = rate;
    r->angular = ang;
    r->locks = locks;
}
