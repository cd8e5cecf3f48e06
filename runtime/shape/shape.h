/* shape.h -- quantities on the unit circle: J(c) (2.4), admissibility (4.1), the barrier W2.
 *
 * W2(c) = eps/(2 alpha) * int_0^{2 pi} J(c)(e^{i theta})^{-alpha} d theta   (section 4.1.1, ERRATA B2)
 * is computed with the trapezoidal rule on Q equally spaced nodes. J^{-alpha} is analytic and
 * periodic, so the rule converges geometrically (ERRATA B4: Q = 256 gives ~1e-14 relative for
 * min J >= 0.008); tests/test_kernels.c shows the convergence. Near the boundary of D, J^{-alpha}
 * has a peak of width ~ sqrt(min J) and a complex singularity at that distance from the real
 * axis, so the rate of convergence degrades like sqrt(min J): the adaptive rule keeps the same
 * resolution by taking Q = 256 sqrt(0.008 / min J) nodes (a power of two, up to 65536, min J
 * measured on the nodes themselves), so W2 stays accurate down to min J ~ 1e-7.
 */
#ifndef SWIM_SHAPE_SHAPE_H
#define SWIM_SHAPE_SHAPE_H

#include "kernel/swim_kernel.h"

#define SWIM_BARRIER_NODES 256          /* base rule */
#define SWIM_BARRIER_MAX_NODES 65536    /* finest rule of the adaptive quadrature */

/* The barrier_sums of a kernel (generic or scene): sums over Q nodes, see swim_kernel.h. */
typedef int (*swim_barrier_sums_fn)(const double *x, const double *cs, const double *sn, int Q,
                                    double alpha, double *sum, double *gsum, double *jlow);

/* Precomputed cos(m theta_q), sin(m theta_q), m = 0..N-1, on Q nodes; owns its arrays. Coarser
 * rules down to SWIM_BARRIER_NODES nodes (every 2^l-th node) get contiguous tables of their own,
 * so that the adaptive rule reads memory in order. */
typedef struct {
    int modes, nodes;
    double *cs, *sn;         /* nodes x max(N,1), row q for node q (= level 0) */
    int levels;              /* tables for nodes >> l, l = 0 .. levels-1 */
    double *lcs[20], *lsn[20];
} swim_circle;

int swim_circle_init(swim_circle *c, int modes, int nodes);   /* 0, or -1 out of memory */
void swim_circle_free(swim_circle *c);

/* min over the closed disk of J (on the circle by the maximum principle, (4.1)): the smallest of
 * 64(N+1) samples (J has frequencies up to N-1), refined by golden-section search. */
double swim_shape_jmin(int modes, const double *x);

/* W2 and (if grad != NULL) its gradient (ERRATA B3, ngrad entries as `sums` gives them) on all the
 * nodes of `circle`. Also returns the smallest J met on the nodes in *jnodes (may be NULL).
 * Returns +inf if J <= 0 at a node. */
double swim_barrier(const swim_circle *circle, swim_barrier_sums_fn sums, int ngrad, const double *x,
                    double eps, double alpha, double *grad, double *jnodes);
/* The same with the adaptive rule (see above) on subsets of the nodes of `circle`, which should
 * have SWIM_BARRIER_MAX_NODES nodes; *nodes_used (may be NULL) gets the Q taken. */
double swim_barrier_adaptive(const swim_circle *circle, swim_barrier_sums_fn sums, int ngrad,
                             const double *x, double eps, double alpha, double *grad,
                             double *jnodes, int *nodes_used);

#endif
