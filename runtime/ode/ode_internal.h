/* Internal backend interface shared by ode.c and the peer wrappers. */
#ifndef SWIM_ODE_INTERNAL_H
#define SWIM_ODE_INTERNAL_H

#include "ode/ode.h"

typedef struct ode_backend {
    void (*destroy)(void *impl);
    int (*advance)(void *impl, double tout, double *yout);
    void (*stats)(const void *impl, swim_ode_stats *st);
    double (*time)(const void *impl);
    int (*rhs_status)(const void *impl);
} ode_backend;

/* Each constructor validates nothing that ode.c has already checked and
 * returns a SWIM_ODE_* status with *impl and *be set on success. */
int swim_ode_gsl_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                        double t0, const double *y0, void **impl, const ode_backend **be);
int swim_ode_cvode_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                          double t0, const double *y0, void **impl, const ode_backend **be);

#endif
