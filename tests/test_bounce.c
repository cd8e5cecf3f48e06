/* The impact of model/bounce.h on random states: what the reflection must keep and reverse,
 * and the normal kinetic energy as the least energy of a velocity with the same rate. */
#include "check.h"
#include "model/bounce.h"
#include "model/dynamics.h"
#include "shape/constraints.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double urand(void) { return 2.0 * rand() / (double)RAND_MAX - 1.0; }

/* 1/2 v^T K v with K the reduced mass matrix at shape x. */
static double kinetic(const swim_kernel *k, const swim_scene *s, const double *x, const double *v)
{
    double K[SWIM_NMAX * SWIM_NMAX], e = 0.0;
    if (k->reduced(x, NULL, s->rho0, s->rhof, K, NULL, NULL) != 0) return NAN;
    for (int i = 0; i < s->n; i++)
        for (int j = 0; j < s->n; j++) e += 0.5 * v[i] * K[i * s->n + j] * v[j];
    return e;
}

static void test_reflection(int N, int lock)
{
    const swim_kernel *k = swim_kernel_find(N);
    CHECK(k != NULL, "kernel N = %d linked in", N);
    if (!k) return;
    static swim_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.modes = N;
    sc.n = 2 * (N + 1);
    sc.rho0 = 0.8;
    sc.rhof = 1.1;
    for (int i = 0; i < sc.n; i++) sc.free_mask[i] = 1;
    if (lock) sc.free_mask[sc.n - 1] = 0;   /* b_-N locked */
    sc.c0[0] = 1.0;
    swim_dynamics d;
    CHECK(swim_dynamics_init(&d, &sc, k) == 0, "dynamics N = %d", N);
    const int n = sc.n;
    double worst_e = 0.0, worst_g = 0.0, worst_r = 0.0, worst_min = 0.0;
    int locks_kept = 1, ok = 1;
    for (int trial = 0; trial < 20; trial++) {
        double y[3 + 2 * SWIM_NMAX + 1] = {0.0}, *x = y + 3, *v = y + 3 + n, g[SWIM_NMAX], G[SWIM_NMAX * (SWIM_NMAX + 2)];
        x[0] = 1.0 + 0.1 * urand();
        x[1] = 0.1 * urand();
        for (int i = 2; i < n; i++) x[i] = 0.2 * urand() / (i / 2);   /* well inside D */
        for (int i = 0; i < n; i++) {
            v[i] = sc.free_mask[i] ? urand() : 0.0;
            g[i] = urand();
        }
        if (lock) x[n - 1] = 0.0;
        const int m = swim_constraint_rows(n, x, sc.free_mask, G);
        swim_constraint_project(n, m, G, v);   /* a velocity the constraints allow */
        for (int i = 0; i < n; i++)
            if (!sc.free_mask[i]) v[i] = 0.0;   /* exactly, as the integrator holds it */
        swim_bounce b;
        if (swim_bounce_along(&d, y, g, &b) != 0) {
            ok = 0;
            continue;
        }
        double vp[SWIM_NMAX], gv = 0.0, gvp = 0.0;
        for (int i = 0; i < n; i++) {
            vp[i] = v[i] + b.dv[i];
            gv += g[i] * v[i];
            gvp += g[i] * vp[i];
            if (!sc.free_mask[i] && b.dv[i] != 0.0) locks_kept = 0;
        }
        const double E = kinetic(k, &sc, x, v), Ep = kinetic(k, &sc, x, vp);
        worst_e = fmax(worst_e, fabs(Ep - E) / E);
        for (int r = 0; r < m; r++) {   /* G v+ = 0 */
            double s = 0.0, a = 0.0;
            for (int i = 0; i < n; i++) {
                s += G[r * n + i] * vp[i];
                a += fabs(G[r * n + i] * vp[i]);
            }
            worst_g = fmax(worst_g, fabs(s) / (a + 1e-300));
        }
        worst_r = fmax(worst_r, fabs(gvp + gv) / fabs(gv));
        CHECK(fabs(b.rate - gv) <= 1e-14 * fabs(gv) + 1e-15, "rate is g.cdot");
        CHECK(b.normal_kinetic <= E * (1 + 1e-12), "T_n %.6g <= kinetic energy %.6g", b.normal_kinetic, E);
        /* T_n is the least kinetic energy with the rate g.cdot: the velocity that is left when the
         * part along w (the impulse's velocity, dv is a multiple of it) is taken out of v has rate
         * 0, and the energy it carries is E - T_n */
        double v0[SWIM_NMAX], g0 = 0.0;
        for (int i = 0; i < n; i++) v0[i] = v[i] + 0.5 * b.dv[i];
        for (int i = 0; i < n; i++) g0 += g[i] * v0[i];
        const double E0 = kinetic(k, &sc, x, v0);
        worst_min = fmax(worst_min, fabs(E - b.normal_kinetic - E0) / E);
        CHECK(fabs(g0) <= 1e-12 * fabs(gv) * 10 + 1e-14, "the midpoint velocity has rate 0 (%.3g of %.3g)", g0, gv);
    }
    CHECK(ok, "N = %d: every impact computed", N);
    CHECK(locks_kept, "N = %d: locked coordinates keep cdot = 0 exactly", N);
    CHECK(worst_e <= 1e-13, "N = %d: kinetic energy kept to %.3g", N, worst_e);
    CHECK(worst_g <= 1e-13, "N = %d: constraints G cdot+ = 0 to %.3g", N, worst_g);
    CHECK(worst_r <= 1e-12, "N = %d: g.cdot reversed to %.3g", N, worst_r);
    CHECK(worst_min <= 1e-12, "N = %d: E = T_n + energy of the rate-0 part, to %.3g", N, worst_min);
    swim_dynamics_free(&d);
}

int main(void)
{
    srand(7);
    test_reflection(2, 0);
    test_reflection(4, 1);
    test_reflection(7, 0);
    return check_report("test_bounce");
}
