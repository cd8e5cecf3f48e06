/* Variable-step, variable-order (1-12) Adams-Bashforth-Moulton PECE integrator
 * in modified divided-difference form (the Shampine-Gordon / ode113 class).
 * Low-level API used by ode.c; status codes are the SWIM_ODE_* values of ode.h.
 * The abm object owns its memory (including a copy of atol_vec). */
#ifndef SWIM_ODE_ABM_H
#define SWIM_ODE_ABM_H

#include <stddef.h>
#include "ode/ode.h"

#define ABM_MAXORDER 12

typedef struct abm abm;

/* Allocate and initialise at (t0, y0).  Options as in swim_ode_options
 * (validated by the caller except for what only the stepper can know). */
int abm_create(const swim_ode_system *sys, const swim_ode_options *opt, double t0,
               const double *y0, abm **out);
void abm_free(abm *a);

/* One step attempt.  Returns a status; *accepted is 1 if the step was
 * accepted, 0 if it was rejected (state restored exactly, smaller h/order). */
int abm_step(abm *a, int *accepted);

/* One accepted step (after as many rejected attempts as it takes), or *done = 1
 * without a step when tout is covered (t >= tout, or tstop reached up to
 * rounding).  SWIM_ODE_ESTIFF after the step when stiff_stop is set and the
 * diagnostic has fired. */
int abm_step_toward(abm *a, double tout, int *done);

/* Step until tout is covered (t >= tout or tstop reached) and interpolate. */
int abm_advance(abm *a, double tout, double *yout);

/* Evaluate the interpolant of the last accepted step at tout (y and,
 * if ypout != NULL, y').  Needs at least one accepted step. */
void abm_interp(const abm *a, double tout, double *yout, double *ypout);

void abm_get_stats(const abm *a, swim_ode_stats *st);
double abm_time(const abm *a);
int abm_rhs_status(const abm *a);
/* Current solution y_n at abm_time() (read-only view, length n). */
const double *abm_state(const abm *a);

/* For tests: copy the complete integration state that a rejected step must
 * leave unchanged (t, y, difference table, step history and its coefficients) into buf; returns the
 * number of doubles written (call with buf = NULL to get the size). */
size_t abm_snapshot(const abm *a, double *buf);
/* Proposed size of the next step. */
double abm_next_h(const abm *a);
/* swim_ode_scale: components [from, from + count) of y, its carries and the difference tables
 * times factor. */
void abm_scale(abm *a, size_t from, size_t count, double factor);

#endif
