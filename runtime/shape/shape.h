/* shape.h -- quantities on the unit circle: J(c) (2.4) and admissibility (4.1). The barrier W2
 * built on J is in shape/barrier.h.
 */
#ifndef SWIM_SHAPE_SHAPE_H
#define SWIM_SHAPE_SHAPE_H

#include "kernel/swim_kernel.h"

/* min over the closed disk of J (on the circle by the maximum principle, (4.1)): 16(N+1) samples
 * (J is a trigonometric polynomial of degree N-1), then every sampled local minimum that
 * Bernstein's inequality allows to be the global one is refined by safeguarded Newton on J'.
 * About 2-5 us for N = 10 (cheap enough to run at every accepted step). */
double swim_shape_jmin(int modes, const double *x);

#endif
