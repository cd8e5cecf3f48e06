/* analyses.c -- sensitivities and the Lyapunov tangent vector on the run's own steps
 * (driver/analyses.h). */
#include "driver/analyses.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/clock.h"
#include "io/message.h"
#include "ode/ode.h"

/* What the tangent vector needs of the integrator: left out of the error control, the marks on
 * the interpolant of each accepted step, and the renormalization in place. */
#define TANGENT_CAPS (SWIM_ODE_CAP_ERROR_DIM | SWIM_ODE_CAP_EVENTS | SWIM_ODE_CAP_RESCALE)

int swim_analyses_check(const char *integrator, const swim_analyses_request *req, const char *who, swim_status *st)
{
    const unsigned caps = swim_ode_capabilities(integrator);
    if (req->keys && !req->in_error_test && !(caps & SWIM_ODE_CAP_ERROR_DIM)) {
        swim_status_fail(st, who, NULL, 0, NULL, "--sensitivity: integrator %s cannot leave the sensitivities out of "
                         "its error control (--sensitivity-steps state, the default); use --sensitivity-steps all, "
                         "or one of: %s", integrator, swim_ode_method_list_with(SWIM_ODE_CAP_ERROR_DIM));
        return 2;
    }
    if (req->lyapunov > 0 && (caps & TANGENT_CAPS) != TANGENT_CAPS) {
        swim_status_fail(st, who, NULL, 0, NULL, "--lyapunov: integrator %s cannot carry the tangent vector on the "
                         "run's steps (outside its error control, renormalized in place); use one of: %s",
                         integrator, swim_ode_method_list_with(TANGENT_CAPS));
        return 2;
    }
    return 0;
}

/* A sensitivity row at each trajectory row (swim_run_variational.row). */
static int sens_row(void *ctx, double t, const double *Y, char *why, size_t len)
{
    swim_analyses *a = ctx;
    const double t0 = swim_clock_seconds();
    swim_sens_row(&a->S, a->nsens, t, Y, a->row);
    const int rc = a->sink(a->ctx, (const char *const *)a->names, a->ncol, a->row, why, len);
    a->row_seconds += swim_clock_seconds() - t0;
    if (rc != 0) return rc;
    a->rows++;
    a->t_last = t;
    return 0;
}

int swim_analyses_attach(swim_analyses *a, swim_run *run, swim_scene *scene, const char *cmd,
                         const swim_analyses_request *req, swim_status *st)
{
    memset(a, 0, sizeof *a);
    a->sink = req->sink;
    a->ctx = req->ctx;
    swim_sens *S = &a->S;
    char why[512] = "";
    if (swim_sens_init(S, swim_run_dynamics(run)) != 0) goto oom;
    a->ready = 1;
    if (req->keys) {
        const int rc = swim_sens_add_list(S, scene, cmd, req->keys, st);
        if (rc) return rc;
        if (req->differences) swim_sens_use_differences(S);
    }
    a->nsens = S->nkeys;
    const int n = S->dim;
    if (req->lyapunov > 0) {   /* after the keys (exact whatever their method): w' = J w */
        if (swim_sens_add_state(S, 3, "w") != 0) goto oom;
        swim_lyapunov_start(S->keys[S->nkeys - 1].s0, n, 3, n - 4);   /* on the shape state c, cdot */
    }
    const size_t dim = (size_t)S->nkeys * (size_t)n;
    if (!(a->y0 = malloc(sizeof(double) * dim))) goto oom;
    for (int k = 0; k < S->nkeys; k++) memcpy(a->y0 + (size_t)k * n, S->keys[k].s0, sizeof(double) * n);
    if (req->keys) {
        if (swim_sens_names(S, a->nsens, &a->names, &a->ncol) != 0 || !(a->row = malloc(sizeof(double) * a->ncol)))
            goto oom;
        if (a->sink(a->ctx, (const char *const *)a->names, a->ncol, NULL, why, sizeof why) != 0) {
            swim_status_fail(st, NULL, NULL, 0, NULL, "%s", why);
            return 1;
        }
    }
    const size_t tangent = (size_t)a->nsens * n;
    const swim_run_variational v = {dim, swim_sens_rhs, S, a->y0, req->keys && req->in_error_test,
                                    req->keys && a->sink ? sens_row : NULL, a,
                                    req->lyapunov > 0 ? req->lyapunov : 0.0,
                                    tangent, (size_t)n, tangent + 3, (size_t)(n - 4)};
    return swim_run_set_variational(run, &v, st);
oom:
    swim_status_fail(st, NULL, NULL, 0, NULL, "swim %s: out of memory", cmd);
    return 1;
}

int swim_analyses_lyapunov(swim_analyses *a, swim_run *run, double interval, double rtol, swim_lyapunov *l)
{
    const swim_run_result *r = swim_run_get_result(run);
    const swim_run_var_result *v = swim_run_get_var_result(run);
    (void)a;
    if (swim_lyapunov_from_marks(l, interval, rtol, v->t, v->log_norm, v->marks) != 0) return -1;
    l->rhs_calls = r->stats.rhs_evals;
    l->seconds = r->integrate_seconds;
    if (!v->carried || v->tangent_reason[0]) {
        l->status = 1;
        snprintf(l->reason, sizeof l->reason, "the variational equations stopped at t = %.6g: %s",
                 v->carried ? l->t_end : v->t_stop, v->carried ? v->tangent_reason : v->reason);
    }
    return 0;
}

void swim_analyses_free(swim_analyses *a)
{
    if (a->ready) swim_sens_free(&a->S);
    swim_sens_names_free(a->names, a->ncol);
    free(a->y0);
    free(a->row);
    memset(a, 0, sizeof *a);
}
