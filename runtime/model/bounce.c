#include "model/bounce.h"

#include "shape/constraints.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int swim_bounce_along(const swim_dynamics *d, const double *y, const double *g, swim_bounce *b)
{
    const swim_scene *s = d->scene;
    const int n = d->n;
    const double *x = y + 3, *v = y + 3 + n;
    /* K (n x n), G (at most n + 2 rows), the right-hand sides [g, G^T] of K and the Schur
     * complement S = G K^-1 G^T with its right-hand side G K^-1 g */
    double *K = malloc(sizeof(double) * ((size_t)n * n + (size_t)n * (n + 2) + (size_t)n * (n + 3) +
                                         (size_t)(n + 2) * (n + 3)));
    if (!K) return -1;
    double *G = K + (size_t)n * n, *Y = G + (size_t)n * (n + 2), *S = Y + (size_t)n * (n + 3);
    int rc = -1;
    if (d->k->reduced(x, NULL, s->rho0, s->rhof, K, NULL, NULL) != 0) goto out;
    const int m = swim_constraint_rows(n, x, s->free_mask, G);
    /* Y = K^-1 [g, G^T] (row-major n x (m + 1)) */
    const int r = m + 1;
    for (int i = 0; i < n; i++) {
        Y[i * r] = g[i];
        for (int j = 0; j < m; j++) Y[i * r + 1 + j] = G[(size_t)j * n + i];
    }
    if (LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'U', n, K, n) != 0) goto out;
    if (LAPACKE_dpotrs(LAPACK_ROW_MAJOR, 'U', n, r, K, n, Y, r) != 0) goto out;
    /* S mu = G K^-1 g: the multipliers that keep the impulse's velocity on {G cdot = 0} */
    double mu[SWIM_NMAX + 2];
    for (int i = 0; i < m; i++) {
        mu[i] = 0.0;
        for (int k = 0; k < n; k++) mu[i] += G[(size_t)i * n + k] * Y[k * r];
        for (int j = 0; j < m; j++) {
            double t = 0.0;
            for (int k = 0; k < n; k++) t += G[(size_t)i * n + k] * Y[k * r + 1 + j];
            S[i * m + j] = t;
        }
    }
    if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', m, 1, S, m, mu, 1) != 0) goto out;
    double w[SWIM_NMAX], gw = 0.0, gv = 0.0;
    for (int i = 0; i < n; i++) {
        w[i] = Y[i * r];
        for (int j = 0; j < m; j++) w[i] -= Y[i * r + 1 + j] * mu[j];
        if (!s->free_mask[i]) w[i] = 0.0;   /* a lock holds it at 0 exactly, not to rounding */
        gw += g[i] * w[i];
        gv += g[i] * v[i];
    }
    if (!(gw > 0.0)) goto out;
    b->rate = gv;
    b->normal_kinetic = gv * gv / (2.0 * gw);
    for (int i = 0; i < n; i++) b->dv[i] = -2.0 * gv / gw * w[i];
    rc = 0;
out:
    free(K);
    return rc;
}
