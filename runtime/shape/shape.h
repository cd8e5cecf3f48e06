/* shape.h -- quantities on the unit circle: J(c) (2.4) and admissibility (4.1). The barrier W2
 * built on J is in shape/barrier.h.
 *
 * On the circle z = e^{i theta}, J(theta) = |c_1|^2 - |P(e^{-i theta})|^2 with
 * P(w) = sum_{m=1..N} m c_{-m} w^{m-1}: a trigonometric polynomial of degree N-1 in theta.
 */
#ifndef SWIM_SHAPE_SHAPE_H
#define SWIM_SHAPE_SHAPE_H

#include "kernel/swim_kernel.h"

/* min over the closed disk of J (on the circle by the maximum principle, (4.1)). NaN when x holds
 * NaN. See swim_shape_jmin_at. */
double swim_shape_jmin(int modes, const double *x);

/* The same, with the angle theta of the minimum in *theta (may be NULL). J is sampled at 8(N+1)
 * points; every sampled local minimum that may hide the global one (within the largest possible
 * dip between two samples, from a bound on |J''|) is refined by a safeguarded Newton iteration on
 * J'(theta) = 0, so the value is the minimum to rounding, not a sample. */
double swim_shape_jmin_at(int modes, const double *x, double *theta);

/* d/dt J(c(t), theta) at fixed theta along the shape velocity v = c'(t). At the angle of the
 * minimum this is the time derivative of min J (envelope theorem: J' = 0 there), which is what
 * locates the minimum of J in time between integration steps. */
double swim_shape_j_rate(int modes, const double *x, const double *v, double theta);

/* min J and its time derivative along v together, without the angle, where both have a closed
 * form: P of degree <= 1 in w after dropping zero top modes (min J = |c_1|^2 - (|p_1| + |p_2|)^2,
 * so d/dt min J = 2 Re(conj(c_1) c_1') - 2 (|p_1| + |p_2|) (|p_1|' + |p_2|')). Returns 1 with
 * *J (the bits of swim_shape_jmin_at) and *rate set, or 0 -- a higher degree, or p_1 = 0 where
 * |p_1| has no derivative -- and then the caller takes the angle and swim_shape_j_rate. */
int swim_shape_jmin_rate(int modes, const double *x, const double *v, double *J, double *rate);

/* J(theta) and (J1 != NULL) J'(theta) in double-double arithmetic (106 bits, about 1e-31 of
 * |c_1|^2) at the shape x + lo (lo may be NULL: x), rounded to double at the end. Near a zero of J
 * the double value carries the cancellation error of |c_1|^2 - |P|^2 (absolute 1e-16: relative
 * 1e-6 at J = 1e-10), and lo -- what a shape carried as origin + u lost when rounded to x -- moves
 * J by as much; here both are kept (test_barrier: within 1e-31 of rounding down to J = 1e-15). */
double swim_shape_j_precise(int modes, const double *x, const double *lo, double theta, double *J1);

/* 1 when the shape lies in D (min J > 0), else 0 (NaN counts as outside). Cheap when the shape
 * is far from the boundary: |c_1| > sum m |c_{-m}| implies J > 0 everywhere (triangle
 * inequality); otherwise the samples of swim_shape_jmin_at decide unless the smallest lies
 * within the largest possible dip between samples of 0, and only then is min J refined. */
int swim_shape_in_D(int modes, const double *x);

#endif
