/* Events of `swim run` (run_events.h).
 *
 * A zero event is a sign change of the column q(y) itself.  A min/max event is a sign
 * change of dq/dt = grad q . y', with y' the derivative of the integrator's interpolant
 * (the ODE layer passes it; for ABM it is the polynomial through the stored values of f,
 * as accurate as y itself, so no extra right-hand-side evaluation is spent).  The
 * columns are diagnostics of the state without an analytic gradient, so grad q . y' is
 * the derivative of q along y' by a central difference with one Richardson step,
 *     D(e) = (q(y + e y') - q(y - e y')) / 2e,   dq/dt = (4 D(e) - D(2e)) / 3,
 * whose truncation error is O(e^4 q^(5)) and rounding error O(u |q| / e); e is 1e-3 in
 * time, shortened so that e |y'| <= 1e-3 (a displacement well inside D).  For columns
 * that are state components the difference is exact up to rounding.
 *
 * Period and displacement per period.  Successive events of one sequence (same column,
 * kind and, for zero events, the same direction of crossing) are one period of the
 * motion apart when the column is periodic; the differences of t and of x, y, theta
 * between them are reported as the period and the displacement per period (stroke). */
#include "driver/events.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/files.h"
#include "io/json.h"
#include "io/message.h"

enum { KIND_ZERO, KIND_MIN, KIND_MAX };
static const char *const kind_names[] = {"zero", "min", "max"};

typedef struct {
    int column;              /* index into the row (0 = t is not allowed) */
    int kind;                /* KIND_* */
    int stop;                /* terminal */
    char name[128];          /* column name */
} spec;

typedef struct {
    double t, value, x, y, theta;
    int spec, rising;
} record;

struct swim_run_events;
typedef struct {
    struct swim_run_events *ev;
    int spec;
} gctx;

struct swim_run_events {
    int nspec;
    spec specs[SWIM_RUN_MAX_EVENTS];
    swim_ode_event ode_ev[SWIM_RUN_MAX_EVENTS];
    gctx gctxs[SWIM_RUN_MAX_EVENTS];      /* data of each event function */
    /* located events (in time order) */
    record *rec;
    size_t nrec, cap;
    int stopped_by;          /* spec index of the terminal event, -1 */
    double t0;               /* the integrator's time is t - t0 (swim_run_events_time_origin) */
    /* column evaluation */
    swim_run_row_func row;
    void *ctx;
    size_t dim;              /* integrator state dimension */
    int ncol;                /* columns of a row */
    int nstate;              /* state columns after t */
    int all;                 /* some event needs a column beyond the state (diagnostics) */
    double *work;            /* perturbed state (dim) */
    double *rowv, *rowp[4];  /* row at y; rows at y + e y', y - e y', y + 2e y', y - 2e y' */
    /* cache: the point of the last evaluation */
    double ct;
    double *cy, *cyp;        /* dim each */
    int cache_value, cache_deriv;
    double *drow;            /* dq/dt of every column at the cached point */
    swim_run_event_listener listener;   /* swim_run_events_listen */
    void *listener_ctx;
    volatile int caller_stop;   /* the listener asked to stop (swim_ode_options.event_stop) */
};

static int parse_one(const char *text, const char *const *names, int ncol, spec *sp, char *why, size_t len)
{
    char buf[128];
    if (strlen(text) >= sizeof buf) {
        snprintf(why, len, "'%.40s...' is too long", text);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", text);
    char *kind = strchr(buf, ':');
    if (!kind) {
        snprintf(why, len, "'%s': expected COLUMN:KIND[:stop] with KIND zero, min or max", text);
        return -1;
    }
    *kind++ = '\0';
    char *stop = strchr(kind, ':');
    if (stop)
        *stop++ = '\0';
    sp->column = -1;
    for (int c = 1; c < ncol; c++)
        if (strcmp(names[c], buf) == 0)
            sp->column = c;
    if (sp->column < 0) {
        snprintf(why, len, "unknown column '%s' (any column of trajectory.csv but t: x, y, theta, %s, ..., jmin, work, w1, w2)",
                 buf, ncol > 4 ? names[4] : "energy");
        return -1;
    }
    sp->kind = -1;
    for (int k = 0; k < 3; k++)
        if (strcmp(kind, kind_names[k]) == 0)
            sp->kind = k;
    if (sp->kind < 0) {
        snprintf(why, len, "'%s': unknown kind '%s' (zero, min or max)", text, kind);
        return -1;
    }
    if (stop && strcmp(stop, "stop") != 0) {
        snprintf(why, len, "'%s': expected ':stop' after the kind, got ':%s'", text, stop);
        return -1;
    }
    sp->stop = stop != NULL;
    snprintf(sp->name, sizeof sp->name, "%s", buf);
    return 0;
}

int swim_run_events_parse(const swim_scene *s, const char *const *extra, int nextra, const char *const *names,
                          int ncol, swim_run_events **out, swim_status *st)
{
    *out = NULL;
    spec specs[SWIM_RUN_MAX_EVENTS];
    int n = 0;
    char why[400];
    for (int i = 0; i < s->nevents; i++) {
        if (n == SWIM_RUN_MAX_EVENTS || parse_one(s->events[i], names, ncol, &specs[n], why, sizeof why)) {
            if (n == SWIM_RUN_MAX_EVENTS)
                snprintf(why, sizeof why, "more than %d events", SWIM_RUN_MAX_EVENTS);
            char where[512];
            swim_status_fail(st, "swim", s->path, s->events_line > 0 ? s->events_line : 0, "events.list", "%s: events.list: %s",
                             swim_scene_where(s, s->events_line, where, sizeof where), why);
            return 2;
        }
        n++;
    }
    for (int a = 0; a < nextra; a++) {
        if (n == SWIM_RUN_MAX_EVENTS || parse_one(extra[a], names, ncol, &specs[n], why, sizeof why)) {
            if (n == SWIM_RUN_MAX_EVENTS)
                snprintf(why, sizeof why, "more than %d events", SWIM_RUN_MAX_EVENTS);
            swim_status_fail(st, "swim run", NULL, 0, "events", "--event: %s", why);
            return 2;
        }
        n++;
    }
    if (n == 0)
        return 0;
    if (!(swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_EVENTS)) {
        swim_status_fail(st, "swim run", NULL, 0, "events", "--event: integrator '%s' cannot locate events (it has no dense "
                         "output)", s->run.integrator);
        return 2;
    }
    if (s->run.stiff_fallback[0] && !(swim_ode_capabilities(s->run.stiff_fallback) & SWIM_ODE_CAP_EVENTS)) {
        swim_status_fail(st, "swim", s->path, 0, "run.stiff_fallback", "%s: run.stiff_fallback: integrator '%s' cannot "
                         "locate the events asked for", s->path, s->run.stiff_fallback);
        return 2;
    }
    swim_run_events *ev = calloc(1, sizeof *ev);
    if (!ev) {
        swim_status_fail(st, "swim run", NULL, 0, NULL, "out of memory");
        return 1;
    }
    ev->nspec = n;
    ev->ncol = ncol;
    memcpy(ev->specs, specs, sizeof specs);
    ev->stopped_by = -1;
    *out = ev;
    return 0;
}

/* Rows at (t, y) and, for derivatives, at y +- e y', y +- 2e y' (cached per point). */
static int eval_point(swim_run_events *ev, double t, const double *y, const double *yp, int deriv)
{
    const size_t n = ev->dim;
    int same = ev->ct == t && memcmp(ev->cy, y, n * sizeof(double)) == 0 && memcmp(ev->cyp, yp, n * sizeof(double)) == 0;
    if (!same) {
        ev->ct = t;
        memcpy(ev->cy, y, n * sizeof(double));
        memcpy(ev->cyp, yp, n * sizeof(double));
        ev->cache_value = ev->cache_deriv = 0;
    }
    if (!deriv && !ev->cache_value) {
        if (ev->row(ev->ctx, ev->t0 + t, y, ev->all, ev->rowv))
            return -1;
        ev->cache_value = 1;
    }
    if (deriv && !ev->cache_deriv) {
        double big = 0.0;
        for (size_t i = 0; i < n; i++)
            big = fmax(big, fabs(yp[i]));
        const double e = big > 1.0 ? 1e-3 / big : 1e-3;
        static const double mult[4] = {1.0, -1.0, 2.0, -2.0};
        for (int k = 0; k < 4; k++) {
            for (size_t i = 0; i < n; i++)
                ev->work[i] = y[i] + mult[k] * e * yp[i];
            if (ev->row(ev->ctx, ev->t0 + t, ev->work, ev->all, ev->rowp[k]))
                return -1;
        }
        for (int c = 0; c < (ev->all ? ev->ncol : 1 + ev->nstate); c++) {
            double d1 = (ev->rowp[0][c] - ev->rowp[1][c]) / (2.0 * e);
            double d2 = (ev->rowp[2][c] - ev->rowp[3][c]) / (4.0 * e);
            ev->drow[c] = (4.0 * d1 - d2) / 3.0;
        }
        ev->cache_deriv = 1;
    }
    return 0;
}

static double g_column(double t, const double *y, const double *yp, void *data)
{
    const gctx *g = data;
    swim_run_events *ev = g->ev;
    const spec *sp = &ev->specs[g->spec];
    int deriv = sp->kind != KIND_ZERO;
    if (eval_point(ev, t, y, yp, deriv))
        return NAN;
    return deriv ? ev->drow[sp->column] : ev->rowv[sp->column];
}

static void on_event(const swim_ode_event_hit *hit, void *data)
{
    swim_run_events *ev = data;
    const spec *sp = &ev->specs[hit->index];
    if (eval_point(ev, hit->t, hit->y, hit->yp, 0))
        return;
    if (ev->nrec == ev->cap) {
        size_t cap = ev->cap ? 2 * ev->cap : 64;
        record *r = realloc(ev->rec, cap * sizeof *r);
        if (!r)
            return;
        ev->rec = r;
        ev->cap = cap;
    }
    ev->rec[ev->nrec++] = (record){ev->t0 + hit->t, ev->rowv[sp->column], ev->rowv[1], ev->rowv[2], ev->rowv[3],
                                   hit->index, hit->rising};
    if (hit->terminal)
        ev->stopped_by = hit->index;
    if (ev->listener && ev->listener(ev->listener_ctx, ev->t0 + hit->t, sp->name, kind_names[sp->kind],
                                     ev->rowv[sp->column], ev->rowv + 1, ev->nstate) != 0) {
        ev->caller_stop = 1;
        ev->stopped_by = hit->index;
    }
}

void swim_run_events_listen(swim_run_events *ev, swim_run_event_listener fn, void *ctx)
{
    if (!ev)
        return;
    ev->listener = fn;
    ev->listener_ctx = ctx;
}

int swim_run_events_caller_stopped(const swim_run_events *ev) { return ev && ev->caller_stop; }

int swim_run_events_attach(swim_run_events *ev, swim_ode_options *o, size_t state_dim, int nstate,
                           swim_run_row_func row, void *ctx)
{
    if (!ev)
        return 0;
    ev->all = 0;
    ev->nstate = nstate;
    for (int i = 0; i < ev->nspec; i++)
        ev->all |= ev->specs[i].column > nstate;
    ev->row = row;
    ev->ctx = ctx;
    ev->dim = state_dim;
    const size_t nc = (size_t)ev->ncol;
    ev->work = malloc((3 * state_dim + 6 * nc) * sizeof(double));
    if (!ev->work)
        return -1;
    ev->cy = ev->work + state_dim;
    ev->cyp = ev->cy + state_dim;
    ev->rowv = ev->cyp + state_dim;
    for (int k = 0; k < 4; k++)
        ev->rowp[k] = ev->rowv + (size_t)(k + 1) * nc;
    ev->drow = ev->rowv + 5 * nc;
    ev->ct = NAN;
    for (int i = 0; i < ev->nspec; i++) {
        ev->gctxs[i] = (gctx){ev, i};
        const spec *sp = &ev->specs[i];
        ev->ode_ev[i] = (swim_ode_event){g_column, &ev->gctxs[i], sp->kind == KIND_MIN ? 1 : sp->kind == KIND_MAX ? -1 : 0,
                                         sp->stop};
    }
    o->events = ev->ode_ev;
    o->nevents = (size_t)ev->nspec;
    o->on_event = on_event;
    o->on_event_data = ev;
    o->event_stop = ev->listener ? &ev->caller_stop : NULL;
    return 0;
}

void swim_run_events_rewind(swim_run_events *ev, double t)
{
    if (!ev)
        return;
    while (ev->nrec > 0 && ev->rec[ev->nrec - 1].t > t)
        ev->nrec--;
    ev->stopped_by = -1;
}

void swim_run_events_time_origin(swim_run_events *ev, double t0)
{
    if (!ev) return;
    ev->t0 = t0;
    ev->ct = NAN;   /* a cached point is keyed by the integrator's time */
}

const char *swim_run_events_stop_name(const swim_run_events *ev)
{
    static _Thread_local char buf[100];   /* per thread: two runs may stop on two threads */
    if (!ev || ev->stopped_by < 0)
        return "";
    const spec *sp = &ev->specs[ev->stopped_by];
    snprintf(buf, sizeof buf, "%s:%s", sp->name, kind_names[sp->kind]);
    return buf;
}

/* The sequence of spec i used for periods: all its events (min/max), or the crossings in
 * the direction that occurs first (zero).  Returns how many, their indices in idx. */
static size_t sequence(const swim_run_events *ev, int i, size_t *idx)
{
    size_t m = 0;
    int dir = -1;
    for (size_t r = 0; r < ev->nrec; r++) {
        if (ev->rec[r].spec != i)
            continue;
        if (ev->specs[i].kind == KIND_ZERO) {
            if (dir < 0)
                dir = ev->rec[r].rising;
            if (ev->rec[r].rising != dir)
                continue;
        }
        idx[m++] = r;
    }
    return m;
}

/* {"x": dx, "y": dy, "theta": dtheta} */
static json_t *displacement(double dx, double dy, double dtheta, int *bad)
{
    json_t *o = json_object();
    if (!o) return NULL;
    *bad |= swim_json_set(o, "x", swim_json_num(dx));
    *bad |= swim_json_set(o, "y", swim_json_num(dy));
    *bad |= swim_json_set(o, "theta", swim_json_num(dtheta));
    return o;
}

int swim_run_events_summary(const swim_run_events *ev, json_t *summary)
{
    int bad = 0;
    json_t *list = json_array();
    for (size_t r = 0; list && r < ev->nrec; r++) {
        const record *e = &ev->rec[r];
        const spec *sp = &ev->specs[e->spec];
        json_t *o = json_object();
        if (o) {
            bad |= swim_json_set(o, "t", swim_json_num(e->t));
            bad |= swim_json_set(o, "column", swim_json_str(sp->name));
            bad |= swim_json_set(o, "kind", swim_json_str(kind_names[sp->kind]));
            bad |= swim_json_set(o, "value", swim_json_num(e->value));
            bad |= swim_json_set(o, "direction", swim_json_str(e->rising ? "rising" : "falling"));
        }
        bad |= !o || json_array_append_new(list, o) != 0;
    }
    bad |= swim_json_set(summary, "events", list);
    bad |= swim_json_set(summary, "event_stop", swim_json_str(swim_run_events_stop_name(ev)));
    json_t *periodic = json_array();
    size_t *idx = malloc((ev->nrec + 1) * sizeof *idx);
    bad |= !idx;
    for (int i = 0; periodic && idx && i < ev->nspec; i++) {
        size_t m = sequence(ev, i, idx);
        if (m < 2)
            continue;
        double pmin = INFINITY, pmax = 0.0;
        for (size_t j = 1; j < m; j++) {
            double p = ev->rec[idx[j]].t - ev->rec[idx[j - 1]].t;
            pmin = fmin(pmin, p);
            pmax = fmax(pmax, p);
        }
        const record *a = &ev->rec[idx[0]], *b = &ev->rec[idx[m - 1]], *c = &ev->rec[idx[m - 2]];
        const double np = (double)(m - 1);
        json_t *o = json_object();
        if (o) {
            bad |= swim_json_set(o, "column", swim_json_str(ev->specs[i].name));
            bad |= swim_json_set(o, "kind", swim_json_str(kind_names[ev->specs[i].kind]));
            bad |= swim_json_set(o, "periods", json_integer((json_int_t)(m - 1)));
            bad |= swim_json_set(o, "period", swim_json_num((b->t - a->t) / np));
            bad |= swim_json_set(o, "period_min", swim_json_num(pmin));
            bad |= swim_json_set(o, "period_max", swim_json_num(pmax));
            bad |= swim_json_set(o, "displacement_per_period",
                                 displacement((b->x - a->x) / np, (b->y - a->y) / np, (b->theta - a->theta) / np, &bad));
            bad |= swim_json_set(o, "displacement_last_period",
                                 displacement(b->x - c->x, b->y - c->y, b->theta - c->theta, &bad));
        }
        bad |= !o || json_array_append_new(periodic, o) != 0;
    }
    free(idx);
    bad |= swim_json_set(summary, "periodic", periodic);
    return bad ? -1 : 0;
}

static void fill_csv(FILE *f, void *ctx)
{
    const swim_run_events *ev = ctx;
    fprintf(f, "t,column,kind,value\n");
    for (size_t r = 0; r < ev->nrec; r++) {
        const record *e = &ev->rec[r];
        swim_number_print(f, e->t);
        fprintf(f, ",%s,%s,", ev->specs[e->spec].name, kind_names[ev->specs[e->spec].kind]);
        swim_number_print(f, e->value);
        fputc('\n', f);
    }
}

void swim_run_events_csv(const swim_run_events *ev, FILE *f)
{
    if (ev) fill_csv(f, (void *)ev);
    else fprintf(f, "t,column,kind,value\n");
}

int swim_run_events_write_csv(const swim_run_events *ev, const char *path)
{
    if (!ev)
        return 0;
    return swim_replace_file_with(path, fill_csv, (void *)ev);
}

void swim_run_events_free(swim_run_events *ev)
{
    if (!ev)
        return;
    free(ev->work);
    free(ev->rec);
    free(ev);
}
