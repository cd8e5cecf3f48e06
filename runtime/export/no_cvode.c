/* no_cvode.c -- the CVODE peer of an exported tree built without SUNDIALS (make CVODE=no, or a
 * scene that uses no CVODE integrator): the registry (ode/ode.c) still lists cvode-adams and
 * cvode-bdf, and creating one fails as an option the build cannot honour. Not part of bin/swim:
 * `swim export` copies it into the tree (runtime/export/export.c). */
#include "ode/ode_internal.h"

int swim_ode_cvode_create(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                          double t0, const double *y0, void **impl, const ode_backend **be)
{
    (void)m, (void)sys, (void)opt, (void)t0, (void)y0;
    *impl = NULL;
    *be = NULL;
    return SWIM_ODE_EUNSUPPORTED;   /* this program was built without SUNDIALS (CVODE = no) */
}
