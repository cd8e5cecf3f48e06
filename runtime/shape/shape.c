#include "shape/shape.h"

#include "kernel/coords.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TWO_PI 6.28318530717958647692

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
