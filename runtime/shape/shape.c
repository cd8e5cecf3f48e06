#include "shape/shape.h"

#include "kernel/coords.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692

static int fill(double *cs, double *sn, int nodes, int w)
{
    for (int q = 0; q < nodes; q++)
        for (int m = 0; m < w; m++) {
            double th = TWO_PI * q / nodes;
            cs[q * w + m] = cos(m * th);
            sn[q * w + m] = sin(m * th);
        }
    return 0;
}

int swim_circle_init(swim_circle *c, int modes, int nodes)
{
    int w = modes > 0 ? modes : 1;
    memset(c, 0, sizeof *c);
    c->modes = modes;
    c->nodes = nodes;
    for (int q = nodes; c->levels < 20; q /= 2) {
        int l = c->levels++;
        c->lcs[l] = malloc(sizeof(double) * (size_t)q * (size_t)w);
        c->lsn[l] = malloc(sizeof(double) * (size_t)q * (size_t)w);
        if (!c->lcs[l] || !c->lsn[l]) {
            swim_circle_free(c);
            return -1;
        }
        fill(c->lcs[l], c->lsn[l], q, w);
        if (q <= SWIM_BARRIER_NODES || q % 2) break;
    }
    c->cs = c->lcs[0];
    c->sn = c->lsn[0];
    return 0;
}

void swim_circle_free(swim_circle *c)
{
    for (int l = 0; l < c->levels; l++) {
        free(c->lcs[l]);
        free(c->lsn[l]);
        c->lcs[l] = c->lsn[l] = NULL;
    }
    c->levels = 0;
    c->cs = c->sn = NULL;
}

/* J(c) at z = e^{i theta} (2.4), ERRATA B2: |c_1|^2 - |h|^2, h = sum_{m=1}^N m c_-m conj(z)^(m-1). */
static double j_at(int modes, const double *x, double theta)
{
    const double c1 = cos(theta), s1 = sin(theta);
    double cm = 1.0, sm = 0.0, re = 0.0, im = 0.0;   /* cos, sin of (m-1) theta by rotation */
    for (int m = 1; m <= modes; m++) {
        const int i = swim_coord_index(-m);
        re += m * (x[i] * cm + x[i + 1] * sm);
        im += m * (x[i + 1] * cm - x[i] * sm);
        const double c = cm * c1 - sm * s1;
        sm = sm * c1 + cm * s1;
        cm = c;
    }
    return x[0] * x[0] + x[1] * x[1] - re * re - im * im;
}

double swim_shape_jmin(int modes, const double *x)
{
    const int samples = 64 * (modes + 1);
    double best = INFINITY, tbest = 0.0;
    for (int q = 0; q < samples; q++) {
        double th = TWO_PI * q / samples, J = j_at(modes, x, th);
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
    double c = b - g * (b - a), d = a + g * (b - a), fc = j_at(modes, x, c), fd = j_at(modes, x, d);
    for (int it = 0; it < 60; it++) {
        if (fc < fd) { b = d; d = c; fd = fc; c = b - g * (b - a); fc = j_at(modes, x, c); }
        else         { a = c; c = d; fc = fd; d = a + g * (b - a); fd = j_at(modes, x, d); }
    }
    double fm = fc < fd ? fc : fd;
    return fm < best ? fm : best;
}

/* W2 and its gradient with the Q-node rule (Q = circle->nodes >> l for some level l). */
static double barrier_rule(const swim_circle *circle, int Q, swim_barrier_sums_fn sums, int ngrad,
                           const double *x, double eps, double alpha, double *grad, double *jlow)
{
    const double *cs = circle->cs, *sn = circle->sn;
    for (int l = 0; l < circle->levels; l++)
        if ((circle->nodes >> l) == Q) {
            cs = circle->lcs[l];
            sn = circle->lsn[l];
        }
    double sum;
    if (sums(x, cs, sn, Q, alpha, &sum, grad, jlow) != 0) return INFINITY;
    const double h = TWO_PI / Q;
    if (grad)   /* dW2 = eps/(2 alpha) * (-alpha) int J^(-1-alpha) dJ */
        for (int i = 0; i < ngrad; i++) grad[i] *= -0.5 * eps * h;
    return eps / (2.0 * alpha) * h * sum;
}

double swim_barrier(const swim_circle *circle, swim_barrier_sums_fn sums, int ngrad, const double *x,
                    double eps, double alpha, double *grad, double *jnodes)
{
    double jlow;
    double W = barrier_rule(circle, circle->nodes, sums, ngrad, x, eps, alpha, grad, &jlow);
    if (jnodes) *jnodes = jlow;
    return W;
}

double swim_barrier_adaptive(const swim_circle *circle, swim_barrier_sums_fn sums, int ngrad,
                             const double *x, double eps, double alpha, double *grad,
                             double *jnodes, int *nodes_used)
{
    int Q = circle->nodes < SWIM_BARRIER_NODES ? circle->nodes : SWIM_BARRIER_NODES;
    double jlow, W;
    for (;;) {
        W = barrier_rule(circle, Q, sums, ngrad, x, eps, alpha, grad, &jlow);
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
