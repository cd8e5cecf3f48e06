#include "shape/shape.h"

#include "kernel/coords.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692

/* J(theta) = |c_1|^2 - |h|^2 with h(z) = sum_{j=0}^{N-1} a_j z^j, z = e^{-i theta},
 * a_j = (j+1) c_{-(j+1)} (ERRATA B2). */
typedef struct {
    int deg;                                   /* N - 1 */
    double c1sq;                               /* |c_1|^2 */
    double complex a[SWIM_KERNEL_MAX_MODES];   /* a_j */
} circle_poly;

static void circle_poly_init(circle_poly *p, int modes, const double *x)
{
    p->deg = modes - 1;
    p->c1sq = x[0] * x[0] + x[1] * x[1];
    for (int m = 1; m <= modes; m++) {
        const int i = swim_coord_index(-m);
        p->a[m - 1] = m * (x[i] + I * x[i + 1]);
    }
}

/* J and its first two theta-derivatives at theta (d/dtheta z^j = -i j z^j). */
static void j_derivs(const circle_poly *p, double theta, double *J, double *J1, double *J2)
{
    /* Horner for h, h', h'' together, in real arithmetic (C's complex product is slow) */
    const double zr = cos(theta), zi = -sin(theta);
    double hr = 0.0, hi = 0.0, h1r = 0.0, h1i = 0.0, h2r = 0.0, h2i = 0.0;
    for (int j = p->deg; j >= 0; j--) {
        const double ar = creal(p->a[j]), ai = cimag(p->a[j]);
        double t = hr * zr - hi * zi + ar;
        hi = hr * zi + hi * zr + ai;
        hr = t;
        t = h1r * zr - h1i * zi + j * ai;      /* (-i j) a_j */
        h1i = h1r * zi + h1i * zr - j * ar;
        h1r = t;
        t = h2r * zr - h2i * zi - (double)j * j * ar;   /* (-j^2) a_j */
        h2i = h2r * zi + h2i * zr - (double)j * j * ai;
        h2r = t;
    }
    *J = p->c1sq - (hr * hr + hi * hi);
    *J1 = -2.0 * (hr * h1r + hi * h1i);
    *J2 = -2.0 * (h1r * h1r + h1i * h1i + hr * h2r + hi * h2i);
}

/* The minimum of J in [lo, hi], which holds a discrete minimum of the samples: safeguarded
 * Newton on J' = 0 (bisection on the sign of J' whenever Newton would leave the bracket or J''
 * is not positive). Returns the smallest J seen, so it never exceeds the sample it started at. */
static double refine_minimum(const circle_poly *p, double lo, double hi, double start, double best)
{
    double th = start;
    for (int it = 0; it < 60; it++) {
        double J, J1, J2;
        j_derivs(p, th, &J, &J1, &J2);
        if (J < best) best = J;
        if (J1 > 0.0) hi = th; else lo = th;
        double next = J2 > 0.0 ? th - J1 / J2 : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        /* a step below 1e-9 leaves J'' 1e-18 / 2 above the minimum: one last value and done */
        const int last = fabs(next - th) <= 1e-9 || hi - lo <= 1e-9;
        th = next;
        if (last) {
            j_derivs(p, th, &J, &J1, &J2);
            if (J < best) best = J;
            break;
        }
    }
    return best;
}

double swim_shape_jmin(int modes, const double *x)
{
    if (modes <= 1) {   /* h is constant: J does not depend on theta */
        double J = x[0] * x[0] + x[1] * x[1];
        if (modes == 1) J -= x[2] * x[2] + x[3] * x[3];
        return J;
    }
    circle_poly p;
    circle_poly_init(&p, modes, x);
    /* Samples on a grid of spacing dt; z^q by one complex rotation per sample (the drift of the
     * rotation, ~q eps, only moves the sample points, which the refinement does not rely on). */
    const int samples = 16 * (modes + 1);
    const double dt = TWO_PI / samples;
    double Js[16 * (SWIM_KERNEL_MAX_MODES + 1)];
    const double wr = cos(dt), wi = -sin(dt);
    double zr = 1.0, zi = 0.0;
    double range_lo = INFINITY, range_hi = -INFINITY;
    for (int q = 0; q < samples; q++) {
        /* Horner in real arithmetic: C's complex product checks for infinities (slow) */
        double hr = 0.0, hi = 0.0;
        for (int j = p.deg; j >= 0; j--) {
            const double t = hr * zr - hi * zi + creal(p.a[j]);
            hi = hr * zi + hi * zr + cimag(p.a[j]);
            hr = t;
        }
        Js[q] = p.c1sq - (hr * hr + hi * hi);
        const double t = zr * wr - zi * wi;
        zi = zr * wi + zi * wr;
        zr = t;
        if (isnan(Js[q])) return NAN;
        range_lo = fmin(range_lo, Js[q]);
        range_hi = fmax(range_hi, Js[q]);
    }
    /* Between samples J can fall below the samples by at most max|J'| dt/2, and
     * max|J'| <= (N-1) max|J - mean J| (Bernstein's inequality, degree N-1): every discrete
     * local minimum within that margin of the best sample is refined. */
    const double margin = (modes - 1) * (range_hi - range_lo) * dt;
    double best = range_lo;
    for (int q = 0; q < samples; q++) {
        const double Jq = Js[q], Jl = Js[(q + samples - 1) % samples], Jr = Js[(q + 1) % samples];
        if (Jq <= Jl && Jq <= Jr && Jq <= range_lo + margin)
            best = refine_minimum(&p, (q - 1) * dt, (q + 1) * dt, q * dt, best);
    }
    return best;
}
