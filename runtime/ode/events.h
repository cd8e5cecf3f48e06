/* Event location over the steps of any integrator with dense output (ode.c's
 * helper; the contract for users is in ode.h, "Events"). */
#ifndef SWIM_ODE_EVENTS_H
#define SWIM_ODE_EVENTS_H

#include "ode/ode_internal.h"

typedef struct ode_events ode_events;

/* Copies opt->events; NULL when out of memory. */
ode_events *ode_events_create(size_t n, const swim_ode_options *opt);
void ode_events_free(ode_events *e);

/* After an accepted step [ta, tb] of the backend: locate and report the events
 * in it (be->dense must be valid on [ta, tb]).  Returns SWIM_ODE_OK, or
 * SWIM_ODE_TERMINATED with *t_stop and *y_stop (owned by e) at a terminal
 * event, or an error. */
int ode_events_step(ode_events *e, const ode_backend *be, void *impl, double ta, double tb, double *t_stop,
                    const double **y_stop);

/* Event-function evaluations and events located so far. */
void ode_events_counts(const ode_events *e, long *evals, long *found);

#endif
