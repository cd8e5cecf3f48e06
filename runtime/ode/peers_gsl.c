/* GSL odeiv2 peers (rk8pd, msadams, rkf45, msbdf) behind the swim_ode interface.
 * GSL's driver ends each call exactly at tout (it shortens the last step);
 * these steppers have no dense output of their own.
 *
 * Right-hand-side failures (GSL 2.7, gsl_odeiv2_evolve_apply): a function
 * status of GSL_EBADFUNC makes evolve return at once; any other nonzero status
 * aborts the step attempt, restores y and retries with h/2 (the multistep
 * steppers restore their Nordsieck history / lower the order through their
 * failure handlers), until h no longer changes t, when that status is
 * returned.  A negative swim RHS value is therefore passed as GSL_EBADFUNC,
 * a positive one (state outside the domain of f) as GSL_RHS_DOMAIN, which GSL
 * retries.  More than GSL_MAXDOMFAIL positive returns without an accepted step
 * in between turn into GSL_EBADFUNC, so a RHS that fails for good ends the run
 * after a bounded number of evaluations.  Two failures GSL does not retry
 * end the run with SWIM_ODE_ERHS too: f(t0, y0) (evaluated here before the
 * driver exists: an invalid initial state), and evolve's evaluation of f at
 * the accepted state at the start of each step (dydt_in), which repeats the
 * successful final evaluation of the previous step and so cannot fail for a
 * right-hand side that is a function of (t, y). */
#include "ode/ode_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#define GSL_RHS_DOMAIN GSL_EDOM   /* retryable: anything but GSL_SUCCESS, GSL_EFAULT, GSL_EBADFUNC */
#define GSL_MAXDOMFAIL 20

typedef struct {
    swim_ode_system sys;
    gsl_odeiv2_system gsys;
    const gsl_odeiv2_step_type *type;
    gsl_odeiv2_driver *drv;
    swim_ode_options opt;
    double *scale_abs, *f0, *f1, *ytmp;
    double t, t0;
    double *y0;
    long nfe, njac;
    int rhs_status;      /* last nonzero value returned by the RHS */
    int last_failed;     /* the most recent RHS call returned nonzero */
    int domfail;         /* positive returns since the accepted step count was domfail_mark */
    size_t domfail_mark;
} gsl_peer;

static int gsl_rhs(double t, const double *y, double *f, void *p)
{
    gsl_peer *g = p;
    g->nfe++;
    int rc = g->sys.function(t, y, f, g->sys.params);
    g->last_failed = rc != 0;
    if (rc == 0)
        return GSL_SUCCESS;
    g->rhs_status = rc;
    if (rc < 0 || !g->drv)
        return GSL_EBADFUNC;   /* fatal; before the driver exists: f(t0, y0) itself failed */
    size_t count = g->drv->e->count;
    if (count != g->domfail_mark) {
        g->domfail_mark = count;
        g->domfail = 0;
    }
    if (++g->domfail > GSL_MAXDOMFAIL)
        return GSL_EBADFUNC;
    return GSL_RHS_DOMAIN;
}

/* The caller's Jacobian.  msbdf, the one GSL stepper here that calls a Jacobian, reads only
 * df/dy (its Newton matrix is I - gamma df/dy; GSL 2.7 msbdf.c never reads dfdt), so df/dt is
 * set to 0 instead of being formed by an extra evaluation of f. */
static int gsl_user_jac(double t, const double *y, double *dfdy, double *dfdt, void *p)
{
    gsl_peer *g = p;
    size_t n = g->sys.dimension;
    g->njac++;
    int rc = g->sys.jacobian(t, y, dfdy, g->sys.params);
    memset(dfdt, 0, n * sizeof(double));
    if (rc == 0)
        return GSL_SUCCESS;
    g->rhs_status = rc;
    return rc < 0 ? GSL_EBADFUNC : GSL_RHS_DOMAIN;   /* positive: msbdf's failure handler retries smaller */
}

/* Forward-difference Jacobian (n+2 RHS evaluations including df/dt). */
static int gsl_jac(double t, const double *y, double *dfdy, double *dfdt, void *p)
{
    gsl_peer *g = p;
    size_t n = g->sys.dimension;
    g->njac++;
    int rc = gsl_rhs(t, y, g->f0, g);
    if (rc != GSL_SUCCESS)
        return rc;   /* GSL_RHS_DOMAIN: msbdf's failure handler retries with a smaller step */
    memcpy(g->ytmp, y, n * sizeof(double));
    const double sq = sqrt(DBL_EPSILON);
    for (size_t j = 0; j < n; j++) {
        double at = g->opt.atol_vec ? g->scale_abs[j] : g->opt.atol;
        double d = sq * fmax(fabs(y[j]), fmax(at / fmax(g->opt.rtol, DBL_EPSILON), 1e-8));
        volatile double yj = y[j] + d;
        d = yj - y[j];
        g->ytmp[j] = yj;
        rc = gsl_rhs(t, g->ytmp, g->f1, g);
        if (rc != GSL_SUCCESS)
            return rc;
        g->ytmp[j] = y[j];
        for (size_t i = 0; i < n; i++)
            dfdy[i * n + j] = (g->f1[i] - g->f0[i]) / d;
    }
    double dt = sq * fmax(fabs(t), 1.0);
    rc = gsl_rhs(t + dt, y, g->f1, g);
    if (rc != GSL_SUCCESS)
        return rc;
    for (size_t i = 0; i < n; i++)
        dfdt[i] = (g->f1[i] - g->f0[i]) / dt;
    return GSL_SUCCESS;
}

static void gsl_destroy(void *p)
{
    gsl_peer *g = p;
    if (!g)
        return;
    if (g->drv)
        gsl_odeiv2_driver_free(g->drv);
    free(g->scale_abs);
    free(g);
}

/* Initial step from the same heuristic as ABM: h ~ 0.25 / sqrt(|f/w|), at most tout - t0.
 * f(t0, y0) is evaluated in any case: any failure there (a positive value too,
 * the initial state itself is invalid) is fatal; returns -1 then. */
static double initial_step(gsl_peer *g, double tout)
{
    size_t n = g->sys.dimension;
    double h = tout - g->t0;
    if (gsl_rhs(g->t0, g->y0, g->f0, g) != GSL_SUCCESS)
        return -1.0;
    if (g->opt.h0 > 0)
        return fmin(g->opt.h0, h);
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        double at = g->opt.atol_vec ? g->scale_abs[i] : g->opt.atol;
        double q = g->f0[i] / (g->opt.rtol * fabs(g->y0[i]) + at);
        s += q * q;
    }
    s = sqrt(s / n);
    if (16.0 * s * h * h > 1.0)
        h = 0.25 / sqrt(s);
    if (g->opt.hmax > 0)
        h = fmin(h, g->opt.hmax);
    return h;
}

static int gsl_advance(void *p, double tout, double *yout)
{
    gsl_peer *g = p;
    size_t n = g->sys.dimension;
    if (tout > g->opt.tstop)
        return SWIM_ODE_EBADARG;
    if (!g->drv) {
        double h = initial_step(g, tout);
        if (h < 0)
            return SWIM_ODE_ERHS;
        const double *sc = g->scale_abs;
        double eps_abs = 1.0;
        g->drv = gsl_odeiv2_driver_alloc_scaled_new(&g->gsys, g->type, h, eps_abs, g->opt.rtol, 1.0, 0.0, sc);
        if (!g->drv)
            return SWIM_ODE_ENOMEM;
        if (g->opt.hmax > 0)
            gsl_odeiv2_driver_set_hmax(g->drv, g->opt.hmax);
        gsl_odeiv2_driver_set_nmax(g->drv, 0);
    }
    double t = g->t;
    memcpy(yout, g->y0, n * sizeof(double));
    unsigned long maxs = g->opt.max_steps > 0 ? (unsigned long)g->opt.max_steps : 10000000UL;
    unsigned long left = maxs > g->drv->e->count ? maxs - g->drv->e->count : 0;
    if (left == 0)
        return SWIM_ODE_EMAXSTEPS;
    gsl_odeiv2_driver_set_nmax(g->drv, left);
    int rc = gsl_odeiv2_driver_apply(g->drv, &t, tout, g->y0);
    g->t = t;
    memcpy(yout, g->y0, n * sizeof(double));
    if (rc != GSL_SUCCESS && g->last_failed)
        return SWIM_ODE_ERHS;   /* fatal value, repeated domain failures, or h underflow on one */
    switch (rc) {
    case GSL_SUCCESS: return SWIM_ODE_OK;
    case GSL_EBADFUNC: return g->rhs_status ? SWIM_ODE_ERHS : SWIM_ODE_EFAIL;
    case GSL_EMAXITER: return SWIM_ODE_EMAXSTEPS;
    case GSL_ENOPROG: return SWIM_ODE_EHMIN;
    case GSL_ENOMEM: return SWIM_ODE_ENOMEM;
    default: return SWIM_ODE_EFAIL;
    }
}

static void gsl_stats(const void *p, swim_ode_stats *st)
{
    const gsl_peer *g = p;
    memset(st, 0, sizeof *st);
    st->rhs_evals = g->nfe;
    st->jac_evals = g->njac;
    if (g->drv) {
        st->steps = (long)g->drv->e->count;
        st->rejected = (long)g->drv->e->failed_steps;
        st->last_h = g->drv->e->last_step;
    }
}

static double gsl_time(const void *p) { return ((const gsl_peer *)p)->t; }
static int gsl_rhs_status(const void *p) { return ((const gsl_peer *)p)->rhs_status; }

/* No dense output: the event hooks stay NULL (the registry gives no SWIM_ODE_CAP_EVENTS). */
static const ode_backend gsl_backend = { gsl_destroy, gsl_advance, gsl_stats, gsl_time, gsl_rhs_status,
                                         NULL, NULL };

int swim_ode_gsl_create(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                        double t0, const double *y0, void **impl, const ode_backend **be)
{
    const gsl_odeiv2_step_type *type = NULL;
    switch (m->variant) {
    case ODE_GSL_RK8PD: type = gsl_odeiv2_step_rk8pd; break;
    case ODE_GSL_MSADAMS: type = gsl_odeiv2_step_msadams; break;
    case ODE_GSL_RKF45: type = gsl_odeiv2_step_rkf45; break;
    case ODE_GSL_MSBDF: type = gsl_odeiv2_step_msbdf; break;
    default: return SWIM_ODE_EBADARG;
    }
    if (opt->rtol == 0 && !opt->atol_vec && opt->atol == 0)
        return SWIM_ODE_EBADARG;
    /* GSL's default handler aborts the program; errors are reported by status here. */
    gsl_set_error_handler_off();
    size_t n = sys->dimension;
    gsl_peer *g = calloc(1, sizeof *g);
    if (!g)
        return SWIM_ODE_ENOMEM;
    g->scale_abs = malloc(5 * n * sizeof(double));
    if (!g->scale_abs) {
        free(g);
        return SWIM_ODE_ENOMEM;
    }
    g->f0 = g->scale_abs + n;
    g->f1 = g->f0 + n;
    g->ytmp = g->f1 + n;
    g->y0 = g->ytmp + n;
    for (size_t i = 0; i < n; i++)
        g->scale_abs[i] = opt->atol_vec ? opt->atol_vec[i] : opt->atol;
    memcpy(g->y0, y0, n * sizeof(double));
    g->sys = *sys;
    g->opt = *opt;
    g->opt.atol_vec = opt->atol_vec ? g->scale_abs : NULL;
    g->type = type;
    g->gsys.function = gsl_rhs;
    g->gsys.jacobian = sys->jacobian ? gsl_user_jac : gsl_jac;
    g->gsys.dimension = n;
    g->gsys.params = g;
    g->t = g->t0 = t0;
    *impl = g;
    *be = &gsl_backend;
    return SWIM_ODE_OK;
}
