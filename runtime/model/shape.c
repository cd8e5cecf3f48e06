#include "model/shape.h"

#include <math.h>
#include <stdlib.h>

#define TWO_PI 6.28318530717958647692

int swim_circle_init(swim_circle *c, int modes, int nodes)
{
    int w = modes > 0 ? modes : 1;
    c->modes = modes;
    c->nodes = nodes;
    c->cs = malloc(sizeof(double) * (size_t)nodes * (size_t)w);
    c->sn = malloc(sizeof(double) * (size_t)nodes * (size_t)w);
    if (!c->cs || !c->sn) {
        swim_circle_free(c);
        return -1;
    }
    for (int q = 0; q < nodes; q++)
        for (int m = 0; m < w; m++) {
            double th = TWO_PI * q / nodes;
            c->cs[q * w + m] = cos(m * th);
            c->sn[q * w + m] = sin(m * th);
        }
    return 0;
}

void swim_circle_free(swim_circle *c)
{
    free(c->cs);
    free(c->sn);
    c->cs = c->sn = NULL;
}

static double j_at(const swim_kernel *k, const double *x, double theta)
{
    double cs[SWIM_KERNEL_MAX_MODES + 1], sn[SWIM_KERNEL_MAX_MODES + 1], J;
    const double c1 = cos(theta), s1 = sin(theta);
    cs[0] = 1.0;
    sn[0] = 0.0;
    for (int m = 1; m < k->modes; m++) {   /* e^{i m theta} by repeated rotation */
        cs[m] = cs[m - 1] * c1 - sn[m - 1] * s1;
        sn[m] = sn[m - 1] * c1 + cs[m - 1] * s1;
    }
    k->jacobian_circle(x, cs, sn, &J, NULL);
    return J;
}

double swim_shape_jmin(const swim_kernel *k, const double *x)
{
    const int samples = 64 * (k->modes + 1);
    double best = INFINITY, tbest = 0.0;
    for (int q = 0; q < samples; q++) {
        double th = TWO_PI * q / samples, J = j_at(k, x, th);
        if (!(J >= best)) {   /* also catches NaN */
            best = J;
            tbest = th;
        }
    }
    if (isnan(best)) return NAN;
    /* J is a trigonometric polynomial of degree <= N-1: the bracket of one sample
     * spacing around the best sample holds the minimum for any sensible N. */
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    double a = tbest - TWO_PI / samples, b = tbest + TWO_PI / samples;
    double c = b - g * (b - a), d = a + g * (b - a), fc = j_at(k, x, c), fd = j_at(k, x, d);
    for (int it = 0; it < 60; it++) {
        if (fc < fd) { b = d; d = c; fd = fc; c = b - g * (b - a); fc = j_at(k, x, c); }
        else         { a = c; c = d; fc = fd; d = a + g * (b - a); fd = j_at(k, x, d); }
    }
    double fm = fc < fd ? fc : fd;
    return fm < best ? fm : best;
}

/* Trapezoidal sums over every `stride`-th node: W2, and its gradient into grad. */
static double barrier_rule(const swim_circle *circle, int stride, swim_jacobian_fn jac, int ngrad,
                           const double *x, double eps, double alpha, double *grad, double *jlow)
{
    const int w = circle->modes > 0 ? circle->modes : 1, Q = circle->nodes / stride;
    double dJ[2 * (SWIM_KERNEL_MAX_MODES + 1)];
    double sum = 0.0;
    *jlow = INFINITY;
    if (grad)
        for (int i = 0; i < ngrad; i++) grad[i] = 0.0;
    for (int q = 0; q < circle->nodes; q += stride) {
        double J;
        jac(x, circle->cs + (size_t)q * w, circle->sn + (size_t)q * w, &J, grad ? dJ : NULL);
        if (J < *jlow) *jlow = J;
        if (!(J > 0.0)) return INFINITY;
        /* J^-alpha; alpha = 1/2 and 1 avoid pow() on the hot path. */
        double ja = alpha == 0.5 ? 1.0 / sqrt(J) : alpha == 1.0 ? 1.0 / J : pow(J, -alpha);
        sum += ja;
        if (grad) {
            double s = ja / J;   /* J^(-1-alpha) */
            for (int i = 0; i < ngrad; i++) grad[i] += s * dJ[i];
        }
    }
    const double h = TWO_PI / Q;
    if (grad)   /* dW2 = eps/(2 alpha) * (-alpha) int J^(-1-alpha) dJ */
        for (int i = 0; i < ngrad; i++) grad[i] *= -0.5 * eps * h;
    return eps / (2.0 * alpha) * h * sum;
}

double swim_barrier(const swim_circle *circle, swim_jacobian_fn jac, int ngrad, const double *x,
                    double eps, double alpha, double *grad, double *jnodes)
{
    double jlow;
    double W = barrier_rule(circle, 1, jac, ngrad, x, eps, alpha, grad, &jlow);
    if (jnodes) *jnodes = jlow;
    return W;
}

double swim_barrier_adaptive(const swim_circle *circle, swim_jacobian_fn jac, int ngrad,
                             const double *x, double eps, double alpha, double *grad,
                             double *jnodes, int *nodes_used)
{
    int Q = circle->nodes < SWIM_BARRIER_NODES ? circle->nodes : SWIM_BARRIER_NODES;
    double jlow, W;
    for (;;) {
        W = barrier_rule(circle, circle->nodes / Q, jac, ngrad, x, eps, alpha, grad, &jlow);
        if (!isfinite(W)) break;
        /* Keep the resolution that 256 nodes have at min J = 0.008 (ERRATA B4). */
        double need = jlow < 0.008 ? SWIM_BARRIER_NODES * sqrt(0.008 / jlow) : 0.0;
        if (need <= Q || Q >= circle->nodes) break;
        while (Q < need && Q < circle->nodes) Q *= 2;
    }
    if (jnodes) *jnodes = jlow;
    if (nodes_used) *nodes_used = Q;
    return W;
}
