/* coords.h -- the shape coordinates, in the one place that knows how they are stored.
 *
 * x = (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N), n = 2(N+1) reals, c_k = a_k + i b_k (section 2).
 * Static inline so that the runtime and every generated kernel (which includes it through
 * kernel/scene_rhs.h) share one definition without linking to each other.
 */
#ifndef SWIM_COORDS_H
#define SWIM_COORDS_H

#include <math.h>
#include <stdio.h>

/* The mode k of real coordinate i (a_k for even i, b_k for odd i): 1, then -1, -2, ..., -N. */
static inline int swim_coord_mode(int i) { return i < 2 ? 1 : -(i / 2); }

/* Storage index of a_k (b_k is the next one). */
static inline int swim_coord_index(int k) { return k == 1 ? 0 : -2 * k; }

/* Name of real coordinate i in CSV headers and scenes: a1, b1, am1, bm1, am2, ... */
static inline void swim_coord_name(int i, char *buf, int len)
{
    const int k = swim_coord_mode(i);
    if (k == 1) snprintf(buf, (size_t)len, "%c1", i % 2 ? 'b' : 'a');
    else snprintf(buf, (size_t)len, "%cm%d", i % 2 ? 'b' : 'a', -k);
}

/* mu^2 = sum_k k |c_k|^2 (2.5)/pi: the area constant of the shape. */
static inline double swim_area_constant(int n, const double *x)
{
    double mu2 = 0.0;
    for (int i = 0; i < n; i += 2) mu2 += swim_coord_mode(i) * (x[i] * x[i] + x[i + 1] * x[i + 1]);
    return mu2;
}

/* (3.21): a vector (u_1, u_2, omega) of the body frame to the fixed frame, R(theta) on the first
 * two components. */
static inline void swim_to_fixed_frame(double theta, const double *body, double *fixed)
{
    const double ct = cos(theta), st = sin(theta);
    const double u = body[0], w = body[1];
    fixed[0] = ct * u - st * w;
    fixed[1] = st * u + ct * w;
    fixed[2] = body[2];
}

#endif
