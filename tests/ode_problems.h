/* Test problems with known answers, shared by tests/test_ode.c and tests/bench/bench_ode.c
 * (swim_ode_func form; params unused). */
#ifndef SWIM_TESTS_ODE_PROBLEMS_H
#define SWIM_TESTS_ODE_PROBLEMS_H

#include <math.h>

/* Harmonic oscillator y'' = -y: y = (cos t, -sin t) from (1, 0). */
static inline int ho_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    f[0] = y[1];
    f[1] = -y[0];
    return 0;
}

/* Kepler problem (x, y, x', y'), mu = 1. */
static inline int kepler_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    double r2 = y[0] * y[0] + y[1] * y[1];
    double r3 = r2 * sqrt(r2);
    f[0] = y[2];
    f[1] = y[3];
    f[2] = -y[0] / r3;
    f[3] = -y[1] / r3;
    return 0;
}

#endif
