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

/* A mode's share of mu^2, as swim_area_constant adds it; +-0 for a mode at 0 */
static inline double area_term(int k, double a, double b) { return k * (a * a + b * b); }

double swim_area_constant_moving(int n, const double *c)
{
    double mu2 = 0.0;
    for (int i = 0; i < n; i += 2)
        if (!(c[i] == 0.0 && c[i + 1] == 0.0)) mu2 += area_term(swim_coord_mode(i), c[i], c[i + 1]);
    return mu2;
}

void swim_constraint_residuals_at(int n, const double *c, const double *v, const double *c0, double mu0,
                                  const int *free_mask, swim_constraint_residuals *r)
{
    /* One pass over the modes (this runs at every step), each sum in the order of its own loop:
     * mu^2 as swim_area_constant_moving; G1.v and G2.v with the rows of swim_constraint_rows
     * formed term by term, in its order (the same sums to the bit), without writing G; the
     * locks in increasing i. */
    double mu2 = 0.0, rate = 0.0, ang = 0.0, locks = 0.0;
    for (int i = 0; i < n; i += 2) {
        const int k = swim_coord_mode(i), ak = abs(k);
        const double a = c[i], b = c[i + 1], va = v[i], vb = v[i + 1];
        if (!(a == 0.0 && b == 0.0)) mu2 += area_term(k, a, b);
        /* a mode at rest (v = 0, c finite: the locked ones) adds four signed zeros to sums that
         * start at +0, which changes no bit: its two divisions are skipped */
        if (!(va == 0.0 && vb == 0.0 && isfinite(a) && isfinite(b))) {
            rate += (k * a) * va;
            rate += (k * b) * vb;
            ang += (b / (ak + 1)) * va;
            ang += (-a / (ak + 1)) * vb;
        }
        /* fmax(locks, e) without the library call: a NaN e is skipped */
        if (!free_mask[i]) {
            const double e = fabs(a - c0[i]) + fabs(va);
            if (e > locks) locks = e;
        }
        if (!free_mask[i + 1]) {
            const double e = fabs(b - c0[i + 1]) + fabs(vb);
            if (e > locks) locks = e;
        }
    }
    r->volume = mu2 - mu0;
    r->volume_rate = rate;
    r->angular = ang;
    r->locks = locks;
}
