/* Run-time dispatch of swim_ode_* calls to ABM, GSL odeiv2 and CVODE. */
#include "ode/ode.h"
#include "ode/abm.h"
#include "ode/ode_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct swim_ode {
    const char *name;
    void *impl;
    const ode_backend *be;
    size_t n;
    double tout_last;
};

static const char *const method_names[] = {
    "abm", "rk8pd", "msadams", "rkf45", "msbdf", "cvode-adams", "cvode-bdf", NULL
};

const char *const *swim_ode_methods(void) { return method_names; }

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
    default: return "unknown status";
    }
}

/* ABM adapter */
static void abm_destroy_(void *p) { abm_free(p); }
static int abm_advance_(void *p, double tout, double *yout) { return abm_advance(p, tout, yout); }
static void abm_stats_(const void *p, swim_ode_stats *st) { abm_get_stats(p, st); }
static double abm_time_(const void *p) { return abm_time(p); }
static int abm_rhs_status_(const void *p) { return abm_rhs_status(p); }
static const ode_backend abm_backend = { abm_destroy_, abm_advance_, abm_stats_, abm_time_, abm_rhs_status_ };

static int valid_pos(double x) { return isfinite(x) && x >= 0.0; }

int swim_ode_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                    double t0, const double *y0, swim_ode **out)
{
    if (!out)
        return SWIM_ODE_EBADARG;
    *out = NULL;
    if (!method || !*method)
        method = "abm";
    const char *name = NULL;
    for (int i = 0; method_names[i]; i++)
        if (strcmp(method, method_names[i]) == 0)
            name = method_names[i];
    if (!name || !sys || !sys->function || sys->dimension == 0 || !y0 || !isfinite(t0))
        return SWIM_ODE_EBADARG;
    swim_ode_options o;
    if (opt)
        o = *opt;
    else
        swim_ode_options_default(&o);
    size_t n = sys->dimension;
    if (!valid_pos(o.rtol) || !valid_pos(o.atol) || !valid_pos(o.hmax) || !valid_pos(o.h0) ||
        isnan(o.tstop) || o.tstop <= t0 || o.max_steps < 0 || o.lookahead < 0 || o.lookahead > 12)
        return SWIM_ODE_EBADARG;
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

    swim_ode *s = calloc(1, sizeof *s);
    if (!s)
        return SWIM_ODE_ENOMEM;
    s->name = name;
    s->n = n;
    s->tout_last = t0;
    int rc;
    if (strcmp(name, "abm") == 0) {
        abm *a;
        rc = abm_create(sys, &o, t0, y0, &a);
        s->impl = a;
        s->be = &abm_backend;
    } else if (strncmp(name, "cvode", 5) == 0) {
        rc = swim_ode_cvode_create(name, sys, &o, t0, y0, &s->impl, &s->be);
    } else {
        rc = swim_ode_gsl_create(name, sys, &o, t0, y0, &s->impl, &s->be);
    }
    if (rc) {
        free(s);
        return rc;
    }
    *out = s;
    return SWIM_ODE_OK;
}

int swim_ode_advance(swim_ode *s, double tout, double *yout)
{
    if (!s || !yout || !(tout > s->tout_last) || !isfinite(tout))
        return SWIM_ODE_EBADARG;
    int rc = s->be->advance(s->impl, tout, yout);
    if (rc == SWIM_ODE_OK)
        s->tout_last = tout;
    return rc;
}

int swim_ode_get_stats(const swim_ode *s, swim_ode_stats *st)
{
    if (!s || !st)
        return SWIM_ODE_EBADARG;
    s->be->stats(s->impl, st);
    return SWIM_ODE_OK;
}

double swim_ode_time(const swim_ode *s) { return s ? s->be->time(s->impl) : NAN; }
int swim_ode_rhs_status(const swim_ode *s) { return s ? s->be->rhs_status(s->impl) : 0; }
const char *swim_ode_method_name(const swim_ode *s) { return s ? s->name : NULL; }

void swim_ode_free(swim_ode *s)
{
    if (!s)
        return;
    s->be->destroy(s->impl);
    free(s);
}
