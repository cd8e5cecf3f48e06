/* shape.h -- quantities on the unit circle: J(c) (2.4) and admissibility (4.1). The barrier W2
 * built on J is in shape/barrier.h.
 */
#ifndef SWIM_SHAPE_SHAPE_H
#define SWIM_SHAPE_SHAPE_H

#include "kernel/swim_kernel.h"

/* min over the closed disk of J (on the circle by the maximum principle, (4.1)): the smallest of
 * 64(N+1) samples (J has frequencies up to N-1), refined by golden-section search. */
double swim_shape_jmin(int modes, const double *x);

#endif
