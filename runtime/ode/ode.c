/* The integrator registry and the run-time dispatch of swim_ode_* calls to
 * ABM, GSL odeiv2 and CVODE. */
#include "ode/ode.h"
#include "ode/abm.h"
#include "ode/events.h"
#include "ode/ode_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct swim_ode {
    const ode_method *method;
    const char *name;
    void *impl;
    const ode_backend *be;
    size_t n;
    double tout_last;
    ode_events *events;       /* NULL without events */
    int stop_pending;         /* a terminal event was located (at t_stop, state y_stop) */
    int terminated;           /* ... and reported: the integration is over */
    double t_stop;
    double *y_stop;           /* n values (owned) */
    /* the caller's report of each accepted step (NULL without; only with dense output) */
    int (*on_accept)(const swim_ode_accepted *step, void *data, double *t_stop);
    void *on_accept_data;
};

static int abm_create_(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                       double t0, const double *y0, void **impl, const ode_backend **be);

#define CAP_PROJ SWIM_ODE_CAP_PROJECTION
#define CAP_TRACE SWIM_ODE_CAP_STEP_TRACE
#define CAP_EV SWIM_ODE_CAP_EVENTS
#define CAP_JAC SWIM_ODE_CAP_JACOBIAN
#define CAP_STIFF SWIM_ODE_CAP_STIFFNESS
#define CAP_IMPL SWIM_ODE_CAP_IMPLICIT
#define CAP_W SWIM_ODE_CAP_WEIGHTS
#define CAP_INV SWIM_ODE_CAP_INVARIANT
#define CAP_EDIM SWIM_ODE_CAP_ERROR_DIM
#define CAP_RESC SWIM_ODE_CAP_RESCALE

/* The one list of integrators: every message, option check and peer constructor uses it. */
static const ode_method registry[] = {
    {"abm", CAP_PROJ | CAP_TRACE | CAP_EV | CAP_STIFF | CAP_W | CAP_INV | CAP_EDIM | CAP_RESC, 0, abm_create_},
    {"rk8pd", 0, ODE_GSL_RK8PD, swim_ode_gsl_create},
    {"msadams", 0, ODE_GSL_MSADAMS, swim_ode_gsl_create},
    {"rkf45", 0, ODE_GSL_RKF45, swim_ode_gsl_create},
    {"msbdf", CAP_JAC | CAP_IMPL, ODE_GSL_MSBDF, swim_ode_gsl_create},
    {"cvode-adams", CAP_EV | SWIM_ODE_CAP_SUNDIALS, ODE_CVODE_ADAMS, swim_ode_cvode_create},
    {"cvode-bdf", CAP_PROJ | CAP_EV | CAP_JAC | CAP_IMPL | SWIM_ODE_CAP_SUNDIALS, ODE_CVODE_BDF, swim_ode_cvode_create},
};
#define NMETHODS (sizeof registry / sizeof registry[0])

static const ode_method *find_method(const char *name)
{
    if (!name)
        return NULL;
    for (size_t i = 0; i < NMETHODS; i++)
        if (strcmp(name, registry[i].name) == 0)
            return &registry[i];
    return NULL;
}

const char *const *swim_ode_methods(void)
{
    static const char *names[NMETHODS + 1];
    for (size_t i = 0; i < NMETHODS; i++)
        names[i] = registry[i].name;
    return names;
}

int swim_ode_method_known(const char *name) { return find_method(name) != NULL; }

unsigned swim_ode_capabilities(const char *name)
{
    const ode_method *m = find_method(name);
    return m ? m->caps : 0u;
}

const char *swim_ode_method_list(void)
{
    static _Thread_local char list[256];
    if (!list[0]) {
        size_t len = 0;
        for (size_t i = 0; i < NMETHODS && len < sizeof list; i++)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", registry[i].name);
    }
    return list;
}

const char *swim_ode_method_list_with(unsigned caps)
{
    static _Thread_local char list[256];
    size_t len = 0;
    list[0] = '\0';
    for (size_t i = 0; i < NMETHODS && len < sizeof list; i++)
        if ((registry[i].caps & caps) == caps)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "", registry[i].name);
    return list;
}

void swim_ode_options_default(swim_ode_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->rtol = 1e-6;
    opt->atol = 1e-9;
    opt->hmax = 0.0;
    opt->h0 = 0.0;
    opt->tstop = INFINITY;
    opt->max_steps = 0;
    opt->stiff_stop = 0;
    opt->lookahead = 6;
}

const char *swim_ode_strerror(int status)
{
    switch (status) {
    case SWIM_ODE_OK: return "success";
    case SWIM_ODE_EBADARG: return "invalid argument";
    case SWIM_ODE_ETOLTOOSMALL: return "tolerance too small for double precision";
    case SWIM_ODE_EHMIN: return "step size underflow";
    case SWIM_ODE_ERHS: return "right-hand side reported an error";
    case SWIM_ODE_ESTIFF: return "problem appears stiff";
    case SWIM_ODE_EMAXSTEPS: return "maximum number of steps reached";
    case SWIM_ODE_ENOMEM: return "out of memory";
    case SWIM_ODE_EFAIL: return "integrator library failure";
    case SWIM_ODE_EUNSUPPORTED: return "option not supported by this integrator";
    case SWIM_ODE_TERMINATED: return "stopped by a terminal event";
    default: return "unknown status";
    }
}

/* ABM adapter */
static void abm_destroy_(void *p) { abm_free(p); }
static int abm_advance_(void *p, double tout, double *yout) { return abm_advance(p, tout, yout); }
static void abm_stats_(const void *p, swim_ode_stats *st) { abm_get_stats(p, st); }
static double abm_time_(const void *p) { return abm_time(p); }
static int abm_rhs_status_(const void *p) { return abm_rhs_status(p); }
static int abm_step_(void *p, double tout, int *done) { return abm_step_toward(p, tout, done); }
static int abm_dense_(void *p, double t, double *y, double *yp)
{
    abm_interp(p, t, y, yp);
    return 0;
}
static const ode_backend abm_backend = { abm_destroy_, abm_advance_, abm_stats_, abm_time_, abm_rhs_status_,
                                         abm_step_, abm_dense_ };

static int abm_create_(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                       double t0, const double *y0, void **impl, const ode_backend **be)
{
    (void)m;
    abm *a;
    int rc = abm_create(sys, opt, t0, y0, &a);
    *impl = a;
    *be = &abm_backend;
    return rc;
}

/* SWIM_ODE_EUNSUPPORTED when opt asks for something m cannot do. */
static int check_capabilities(const ode_method *m, const swim_ode_options *o)
{
    if ((o->project && !(m->caps & SWIM_ODE_CAP_PROJECTION)) ||
        (o->on_step && !(m->caps & SWIM_ODE_CAP_STEP_TRACE)) ||
        (o->nevents > 0 && !(m->caps & SWIM_ODE_CAP_EVENTS)) ||
        (o->stiff_stop && !(m->caps & SWIM_ODE_CAP_STIFFNESS)) ||
        (o->tol_scale && !(m->caps & SWIM_ODE_CAP_WEIGHTS)) ||
        (o->invariant && !(m->caps & SWIM_ODE_CAP_INVARIANT)) ||
        (o->error_dim > 0 && !(m->caps & SWIM_ODE_CAP_ERROR_DIM)))
        return SWIM_ODE_EUNSUPPORTED;
    return SWIM_ODE_OK;
}

static int valid_pos(double x) { return isfinite(x) && x >= 0.0; }

int swim_ode_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                    double t0, const double *y0, swim_ode **out)
{
    if (!out)
        return SWIM_ODE_EBADARG;
    *out = NULL;
    if (!method || !*method)
        method = "abm";
    const ode_method *m = find_method(method);
    if (!m || !sys || !sys->function || sys->dimension == 0 || !y0 || !isfinite(t0))
        return SWIM_ODE_EBADARG;
    swim_ode_options o;
    if (opt)
        o = *opt;
    else
        swim_ode_options_default(&o);
    size_t n = sys->dimension;
    if ((o.nevents > 0 && (!o.events || !o.on_event)) || !(o.event_tol >= 0) ||
        !valid_pos(o.rtol) || !valid_pos(o.atol) || !valid_pos(o.hmax) || !valid_pos(o.h0) ||
        isnan(o.tstop) || o.tstop <= t0 || o.max_steps < 0 || o.lookahead < 0 || o.lookahead > 12 ||
        o.error_dim > n)
        return SWIM_ODE_EBADARG;
    if (o.error_dim == n)
        o.error_dim = 0;   /* all of them: no capability needed */
    int atol_pos = o.atol > 0;
    if (o.atol_vec) {
        atol_pos = 1;
        for (size_t i = 0; i < n; i++) {
            if (!valid_pos(o.atol_vec[i]))
                return SWIM_ODE_EBADARG;
            if (o.atol_vec[i] == 0)
                atol_pos = 0;
        }
    }
    /* a pure relative test needs rtol > 0; atol = 0 is allowed only with rtol > 0 */
    if (!(o.rtol > 0) && !atol_pos)
        return SWIM_ODE_EBADARG;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(y0[i]))
            return SWIM_ODE_EBADARG;
    int rc = check_capabilities(m, &o);
    if (rc)
        return rc;

    swim_ode *s = calloc(1, sizeof *s);
    if (!s)
        return SWIM_ODE_ENOMEM;
    s->method = m;
    s->name = m->name;
    s->n = n;
    s->tout_last = t0;
    for (size_t i = 0; i < o.nevents; i++)
        if (!o.events[i].g) {
            free(s);
            return SWIM_ODE_EBADARG;
        }
    if (o.on_accept && (m->caps & SWIM_ODE_CAP_EVENTS)) {
        s->on_accept = o.on_accept;
        s->on_accept_data = o.on_accept_data;
    }
    if (o.nevents > 0 || s->on_accept) {
        s->events = o.nevents > 0 ? ode_events_create(n, &o) : NULL;
        s->y_stop = malloc(n * sizeof(double));
        if ((o.nevents > 0 && !s->events) || !s->y_stop) {
            ode_events_free(s->events);
            free(s->y_stop);
            free(s);
            return SWIM_ODE_ENOMEM;
        }
    }
    rc = m->create(m, sys, &o, t0, y0, &s->impl, &s->be);
    if (rc) {
        ode_events_free(s->events);
        free(s->y_stop);
        free(s);
        return rc;
    }
    *out = s;
    return SWIM_ODE_OK;
}

/* The interpolant of the last accepted step, for swim_ode_accepted.interp. */
static int step_interp(void *ctx, double t, double *y, double *yp)
{
    swim_ode *s = ctx;
    return s->be->dense(s->impl, t, y, yp) ? -1 : 0;
}

/* Step by step, reporting each accepted step (on_accept) and locating events in it; a stop
 * (terminal event, or on_accept asking for one) beyond tout is kept (stop_pending) and returned
 * by the call whose tout reaches it, without further steps. */
static int advance_stepwise(swim_ode *s, double tout, double *yout)
{
    const ode_backend *be = s->be;
    while (!s->stop_pending) {
        int done = 0;
        double ta = be->time(s->impl);
        int rc = be->step(s->impl, tout, &done);
        if (rc)
            return rc;
        if (done)
            break;
        double tb = be->time(s->impl), tcut = tb;
        int cut = 0;
        if (s->on_accept) {
            /* ABM's accepted state itself (its interpolant at the rounded tb differs by rounding) */
            const double *y_end = be == &abm_backend ? abm_state(s->impl) : NULL;
            swim_ode_accepted st = {ta, tb, step_interp, s, y_end};
            double ts = tb;
            if (s->on_accept(&st, s->on_accept_data, &ts) == 1) {
                cut = 1;
                tcut = ts > ta && ts < tb ? ts : tb;
            }
        }
        if (s->events) {
            double te;
            const double *ye;
            rc = ode_events_step(s->events, be, s->impl, ta, tcut, &te, &ye);
            if (rc == SWIM_ODE_TERMINATED) {
                s->stop_pending = 1;
                s->t_stop = te;
                memcpy(s->y_stop, ye, s->n * sizeof(double));
            } else if (rc) {
                return rc;
            }
        }
        if (cut && !s->stop_pending) {
            if (be->dense(s->impl, tcut, s->y_stop, NULL))
                return SWIM_ODE_EFAIL;
            s->stop_pending = 1;
            s->t_stop = tcut;
        }
    }
    if (s->stop_pending && tout >= s->t_stop) {
        memcpy(yout, s->y_stop, s->n * sizeof(double));
        s->terminated = 1;
        return SWIM_ODE_TERMINATED;
    }
    return be->dense(s->impl, tout, yout, NULL) ? SWIM_ODE_EFAIL : SWIM_ODE_OK;
}

int swim_ode_advance(swim_ode *s, double tout, double *yout)
{
    if (!s || !yout || !(tout > s->tout_last) || !isfinite(tout) || s->terminated)
        return SWIM_ODE_EBADARG;
    int rc = s->events || s->on_accept ? advance_stepwise(s, tout, yout) : s->be->advance(s->impl, tout, yout);
    if (rc == SWIM_ODE_OK)
        s->tout_last = tout;
    return rc;
}

int swim_ode_get_stats(const swim_ode *s, swim_ode_stats *st)
{
    if (!s || !st)
        return SWIM_ODE_EBADARG;
    s->be->stats(s->impl, st);
    ode_events_counts(s->events, &st->event_evals, &st->events);
    return SWIM_ODE_OK;
}

double swim_ode_time(const swim_ode *s)
{
    if (!s)
        return NAN;
    return s->terminated ? s->t_stop : s->be->time(s->impl);
}
int swim_ode_rhs_status(const swim_ode *s) { return s ? s->be->rhs_status(s->impl) : 0; }
const char *swim_ode_method_name(const swim_ode *s) { return s ? s->name : NULL; }

int swim_ode_dense(swim_ode *s, double t, double *y, double *yp)
{
    if (!s || !y || !isfinite(t))
        return SWIM_ODE_EBADARG;
    if (!s->be->dense)
        return SWIM_ODE_EUNSUPPORTED;
    return s->be->dense(s->impl, t, y, yp) ? SWIM_ODE_EFAIL : SWIM_ODE_OK;
}

int swim_ode_scale(swim_ode *s, size_t from, size_t count, double factor)
{
    if (!s || from > s->n || count > s->n - from || !isfinite(factor))
        return SWIM_ODE_EBADARG;
    if (!(s->method->caps & SWIM_ODE_CAP_RESCALE) || s->be != &abm_backend)
        return SWIM_ODE_EUNSUPPORTED;
    abm_scale(s->impl, from, count, factor);
    return SWIM_ODE_OK;
}

void swim_ode_free(swim_ode *s)
{
    if (!s)
        return;
    s->be->destroy(s->impl);
    ode_events_free(s->events);
    free(s->y_stop);
    free(s);
}
