/* bounce.h -- a bounce off the barrier as an impact: its impulsive limit.
 *
 * Near the boundary of D the barrier force -grad W2 (ERRATA B3) is concentrated where J is
 * smallest on the circle: at one contact angle theta* it is a scalar times grad_c J(theta*) (to
 * O(min J): the direction varies over the peak's width ~sqrt(min J / J'')); a symmetric shape
 * touches at two mirrored angles at once, and the force is then along the sum of their two
 * gradients (min J itself has a kink there). Either way the direction is that of grad W2 at the
 * state, g below. With alpha = 1/2 the barrier rises only logarithmically (barrier.h,
 * swim_barrier_reach) and an approach carrying the kinetic energy T toward the boundary turns at
 * min J ~ j0 e^(-T/kappa): below double precision (1e-100 and less under strong forcing), in a
 * time of the same order. What such a bounce does to the motion is then an impulse along g, and
 * nothing else:
 *
 *   cdot+ = cdot - 2 (g.cdot) / (g.w) w,   [K G^T; G 0] [w; mu] = [g; 0],
 *
 * with K the reduced mass matrix (section 4.1.2) and G the constraint rows (constraints.h: volume
 * (2.8), angular momentum (2.14), locks): w = M g is the velocity an impulse along g produces
 * on {G cdot = 0}, and the reflection keeps the kinetic energy 1/2 cdot^T K cdot (w^T K cdot =
 * g.cdot and w^T K w = g.w since G cdot = G w = 0), keeps G cdot = 0 and reverses g.cdot = dW2/dt.
 * The rigid velocities follow from (3.21) with the new cdot. Of the kinetic energy, the part an
 * impulse along g can take away (the least energy of a velocity with the same g.cdot) is
 * T_n = (g.cdot)^2 / (2 g.w): what the barrier must absorb to stop the approach.
 *
 * Taken at a depth j of min J instead of the true turning point, the impact misses what happens
 * during the rest of the bounce, which lasts ~2 j / |d min J/dt| when the turning point is much
 * deeper than j (the speed toward the wall barely changes until the last e-folds): the motion
 * along the wall and the other forces over that time, O(j) of the state. */
#ifndef SWIM_BOUNCE_H
#define SWIM_BOUNCE_H

#include "model/dynamics.h"

typedef struct {
    double rate;              /* g.cdot: with g = grad W2, dW2/dt, > 0 while the shape approaches the wall */
    double normal_kinetic;    /* T_n = (g.cdot)^2 / (2 g.w) */
    double dv[SWIM_NMAX];     /* cdot+ - cdot, full shape layout (0 on locked coordinates) */
} swim_bounce;

/* The impact along g (n entries, shape layout; any positive multiple of grad W2 at the state) at
 * full state y (dynamics.h layout). 0, or -1 when K is not positive definite, the constraints
 * are degenerate, or g vanishes on {G cdot = 0} (no impulse along g can move the shape). */
int swim_bounce_along(const swim_dynamics *d, const double *y, const double *g, swim_bounce *b);

#endif
