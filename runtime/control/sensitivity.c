/* sensitivity.c -- the variational equations integrated on their own (control/sensitivity.h). */
#include "control/sensitivity.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "driver/run.h"
#include "ode/ode.h"

/* Central differences leave ~1e-10 relative noise in s' (model/sensitivity.c): an error test
 * tighter than that fights the noise (Example 3 at rtol 1e-12: 7x the evaluations and a result
 * wrong by 1e-2 relative), so an augmented system with a difference key in its error test is
 * integrated at no tighter than these. */
#define SENS_RTOL_MIN 1e-10
#define SENS_ATOL_MIN 1e-12

/* The run's integrator settings for the augmented system: a difference key floors the
 * tolerances for its noise; error_control 0 leaves the sensitivities out of the error test
 * (*atolv then owned by the caller, else NULL). 0, or -1 out of memory. */
static int augmented_options(const swim_sens *S, swim_ode_options *o, double **atolv)
{
    const swim_scene *s = S->d->scene;
    const int n = S->dim, N = swim_sens_dimension(S);
    *atolv = NULL;
    swim_run_ode_options(&s->run, o);
    if (!swim_sens_exact(S)) {
        o->rtol = fmax(s->run.rtol, SENS_RTOL_MIN);
        o->atol = fmax(s->run.atol, SENS_ATOL_MIN);
    }
    if (!S->error_control) {   /* the sensitivities ride on the state's steps */
        if (!(*atolv = malloc(sizeof(double) * N))) return -1;
        for (int i = 0; i < N; i++) (*atolv)[i] = i < n ? o->atol : 1e300;
        o->atol_vec = *atolv;
    }
    return 0;
}

/* The augmented system at t = 0 from the scene's initial state, on `integrator` with the run's
 * settings (a difference key floors the tolerances for its noise; error_control 0 leaves the
 * sensitivities out of the error test). Y gets the initial augmented state; *atolv is owned by
 * the caller (NULL when not needed). A swim_ode status, or -1 out of memory. */
static int open_augmented(swim_sens *S, const char *integrator, double *Y, double **atolv, swim_ode **ode)
{
    const int n = S->dim, N = swim_sens_dimension(S);
    double *y0 = calloc((size_t)S->d->dim, sizeof(double)), *ys = malloc(sizeof(double) * n);
    *atolv = NULL;
    *ode = NULL;
    if (!y0 || !ys) {
        free(y0);
        free(ys);
        return -1;
    }
    /* from t = 0 in absolute state and time: a run on the same dynamics may have left an origin
     * and a clock shift behind (driver/run.c, near the barrier), which would displace the state
     * and the forcing law's time */
    if ((S->d->origin || S->d->t_origin != 0.0) && swim_dynamics_set_origin(S->d, NULL) != 0) {
        free(y0);
        free(ys);
        return -1;
    }
    S->d->t_origin = 0.0;
    swim_dynamics_initial_state(S->d, y0);
    swim_dynamics_pack(S->d, y0, ys);
    swim_sens_initial(S, ys, Y);
    free(y0);
    free(ys);
    swim_ode_system sys = {swim_sens_rhs, (size_t)N, S, NULL};
    swim_ode_options o;
    if (augmented_options(S, &o, atolv) != 0) return -1;
    return swim_ode_create(integrator, &sys, &o, 0.0, Y, ode);
}

int swim_sens_final(swim_sens *S, const char *integrator, double t_end, double *Y, long *rhs_calls, swim_status *st)
{
    double *atolv = NULL;
    swim_ode *ode = NULL;
    int orc = open_augmented(S, integrator, Y, &atolv, &ode);
    if (orc == SWIM_ODE_OK && t_end > 0) orc = swim_ode_advance(ode, t_end, Y);
    if (ode) {
        swim_ode_stats stats;
        swim_ode_get_stats(ode, &stats);
        if (rhs_calls) *rhs_calls = stats.rhs_evals;
        if (orc != SWIM_ODE_OK) {
            const int rs = swim_ode_rhs_status(ode);
            swim_status_fail(st, "swim", NULL, 0, NULL, "sensitivities stopped before t = %.6g: %s%s%s", t_end,
                             swim_ode_strerror(orc), rs ? ": " : "", rs ? swim_dynamics_strerror(rs) : "");
        }
        swim_ode_free(ode);
    } else if (orc != SWIM_ODE_OK) {
        swim_status_fail(st, "swim", NULL, 0, NULL, "%s", orc < 0 ? "out of memory computing sensitivities"
                                                                  : swim_ode_strerror(orc));
    }
    free(atolv);
    return orc == SWIM_ODE_OK ? 0 : 1;
}

