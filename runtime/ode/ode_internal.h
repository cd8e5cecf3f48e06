/* Internal interface between ode.c (registry, dispatch, event location) and
 * the integrators (abm.c via an adapter, peers_gsl.c, peers_cvode.c). */
#ifndef SWIM_ODE_INTERNAL_H
#define SWIM_ODE_INTERNAL_H

#include "ode/ode.h"

typedef struct ode_backend {
    void (*destroy)(void *impl);
    /* Integrate until tout is covered, y(tout) into yout (the path without events). */
    int (*advance)(void *impl, double tout, double *yout);
    void (*stats)(const void *impl, swim_ode_stats *st);
    double (*time)(const void *impl);
    int (*rhs_status)(const void *impl);
    /* For events (NULL without SWIM_ODE_CAP_EVENTS).  step: one accepted step
     * towards tout, or *done = 1 without a step when the time reached covers
     * tout.  dense: y (and yp if not NULL) at t within the last accepted step,
     * from the method's interpolant. */
    int (*step)(void *impl, double tout, int *done);
    int (*dense)(void *impl, double t, double *y, double *yp);
} ode_backend;

/* One entry of the integrator registry (ode.c). */
typedef struct ode_method {
    const char *name;
    unsigned caps;            /* SWIM_ODE_CAP_* */
    int variant;              /* which stepper of the peer file (ODE_GSL_*, ODE_CVODE_*) */
    /* Validates nothing ode.c has already checked (tolerances, y0, capabilities);
     * returns a SWIM_ODE_* status with *impl and *be set on success. */
    int (*create)(const struct ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                  double t0, const double *y0, void **impl, const ode_backend **be);
} ode_method;

enum { ODE_GSL_RK8PD, ODE_GSL_MSADAMS, ODE_GSL_RKF45, ODE_GSL_MSBDF };
enum { ODE_CVODE_ADAMS, ODE_CVODE_BDF };

int swim_ode_gsl_create(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                        double t0, const double *y0, void **impl, const ode_backend **be);
int swim_ode_cvode_create(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                          double t0, const double *y0, void **impl, const ode_backend **be);

#endif
