/* flow.h -- the body and the flow at one state, for pictures (Figs 4.3, 4.8): the boundary,
 * the density rho0/J (2.3) inside the body, and the fluid velocity outside it, all in the fixed
 * frame. The potential is rebuilt from the boundary data with the signs of ERRATA A4. */
#ifndef SWIM_FLOW_H
#define SWIM_FLOW_H

#include <stdio.h>

#include "model/dynamics.h"

/* Writes one JSON object {"t", "x", "y", "theta", "boundary", "density", "arrows"}. */
int swim_flow_snapshot(swim_dynamics *d, double t, const double *y, FILE *f);

#endif
