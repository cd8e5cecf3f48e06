/* sensitivity.h -- the variational equations (model/sensitivity.h) integrated on their own, from
 * t = 0 to a time, outside any run: what swim optimize's BFGS gradient uses (a run carries them on
 * its own steps instead: driver/analyses.h). */
#ifndef SWIM_CONTROL_SENSITIVITY_H
#define SWIM_CONTROL_SENSITIVITY_H

#include "model/sensitivity.h"

/* The augmented system from the scene's initial state at t = 0 to t_end with `integrator` at the
 * run's settings (a difference key in the error test floors the tolerances for its noise;
 * S->error_control 0 leaves the sensitivities out of it): Y (swim_sens_dimension entries) gets the
 * augmented state at t_end. 0, or 1 with the cause in st. */
int swim_sens_final(swim_sens *S, const char *integrator, double t_end, double *Y, long *rhs_calls, swim_status *st);

#endif
