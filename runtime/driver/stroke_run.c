/* stroke_run.c -- one run of a prescribed stroke (runtime/stroke/stroke.h) behind the driver's
 * contract (driver/run.h): the same rows, sink, events and summary keys as a dynamic run, and a
 * "stroke" object (laws, completion, period, per-stroke displacement and work).
 *
 * Before anything is integrated the stroke is checked on the whole interval: a stroke that is not
 * allowable or leaves D is bad input (swim_run_open returns 2 with the line naming the time).
 * Rows fall at k*output_step and t_end; the state at the end of every stroke k*T is kept for the
 * per-stroke report, and the positive work is sampled in between. */
#include "driver/run.h"

#include "driver/columns.h"

#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/clock.h"
#include "io/json.h"
#include "io/message.h"
#include "kernel/coords.h"
#include "stroke/stroke.h"

#define MAX_STROKES 100000    /* strokes reported one by one in the summary */

/* One stroke [t0, t1]: the state at both ends (r, theta, psi, work) and the positive work. */
typedef struct {
    double t0, t1, y0[SWIM_STROKE_DIM], y1[SWIM_STROKE_DIM], wpos0, wpos1;
} stroke_record;

typedef struct swim_stroke_run swim_stroke_run;

struct swim_stroke_run {
    swim_run_request req;
    swim_scene *s;
    const swim_compiled *kn, *law;
    swim_run_events *events;
    swim_stroke st;
    int st_ready;
    swim_dynamics d;          /* diagnostics and flow snapshots of a row (no right-hand side) */
    int d_ready;
    double period;
    const char *period_source;
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24];
    int ncol, nsnap;
    /* integration */
    swim_ode *ode;
    swim_ode_options o;
    double y[SWIM_STROKE_DIM], full[4 + 2 * SWIM_NMAX], row[SWIM_RUN_MAX_COLUMNS];
    double evfull[4 + 2 * SWIM_NMAX];
    stroke_record *strokes;
    long nstrokes;
    swim_stroke_poswork pw;   /* the positive work, summed over the samples of the run */
    long samples;
    /* report */
    int status;
    char *reason;
    long rows;
    double t_reached, e0, drift_abs, emax, res_volume, res_volume_rate, res_angular, jmin, pmax, pmin;
    double jmin_t, left_D_t;   /* when min J was smallest (rows); where the shape left D, or NAN */
    double t_start, integrate_seconds, diagnostics_seconds, output_seconds, wall_seconds;
    double last_energy, last_work;
    swim_run_result res;
};

static int stop_requested(const swim_stroke_run *c) { return c->req.stop && *c->req.stop; }


/* A stroke's own columns after the diagnostics, from the row's extra quantities (row_values). */
enum { EXTRA_POWER, EXTRA_WORK_POSITIVE, EXTRA_PHASE_C1, EXTRAS };
static double own_power(const swim_run_quantities *q) { return q->extra[EXTRA_POWER]; }
static double own_work_positive(const swim_run_quantities *q) { return q->extra[EXTRA_WORK_POSITIVE]; }
static double own_phase_c1(const swim_run_quantities *q) { return q->extra[EXTRA_PHASE_C1]; }
static const swim_run_column stroke_own[] = {{"power", own_power}, {"work_positive", own_work_positive}, {"phase_c1", own_phase_c1}};

/* The table of a stroke's columns: those of a dynamic run and power, work_positive, phase_c1. */
static int stroke_parts(swim_run_columns_part *parts)
{
    parts[0] = swim_run_diagnostics;
    parts[1] = (swim_run_columns_part){stroke_own, EXTRAS};
    return 2;
}

static int stroke_columns(const swim_scene *s, const char **names, char storage[][24])
{
    swim_run_columns_part parts[2];
    const int nparts = stroke_parts(parts);
    return swim_run_column_names(s->n, parts, nparts, names, storage);
}


/* One line naming the scene, the first law's key and the time: the stroke is refused. */
static int refuse(const swim_stroke_run *c, double t, const char *why, swim_status *st)
{
    const swim_scene *s = c->s;
    char name[24], key[32];
    swim_coord_name(s->stroke_index[0], name, sizeof name);
    snprintf(key, sizeof key, "stroke.%s", name);
    char where[512];
    swim_status_fail(st, "swim", s->path, s->stroke_line[0] > 0 ? s->stroke_line[0] : 0, key,
                     "%s: %s: the stroke is not allowable at t = %.9g: %s",
                     swim_scene_where(s, s->stroke_line[0], where, sizeof where), key, t, why);
    return 2;
}


/* The kernels, the stroke model, the check over [0, t_end], the period. 0, 1 or 2. */
static int prepare_stroke(swim_stroke_run *c, swim_status *st)
{
    swim_scene *s = c->s;
    int rc = swim_stroke_init(&c->st, s, c->kn->kernel, c->law->stroke, s->param_values);
    if (rc == -1) {
        swim_status_fail(st, "swim run", NULL, 0, NULL, "out of memory");
        return 1;
    }
    c->st_ready = 1;
    c->st.interrupt = (volatile int *)c->req.stop;
    if (rc == SWIM_STROKE_EVOLUME) {
        char where[512];
        swim_status_fail(st, "swim", s->path, s->line_c0 > 0 ? s->line_c0 : 0, "shape.c0",
                         "%s: shape.c0: c1 is 0: its phase, which c1's completion (2.14) integrates, is undefined",
                         swim_scene_where(s, s->line_c0, where, sizeof where));
        return 2;
    }
    if (rc != 0) return refuse(c, 0.0, swim_stroke_strerror(rc), st);
    /* the scene's initial state becomes the stroke's: the diagnostics measure the volume and the
     * locks against it, and the magnitude check of the model runs on it */
    double y[SWIM_STROKE_DIM], full[4 + 2 * SWIM_NMAX];
    swim_stroke_initial_state(&c->st, y);
    if ((rc = swim_stroke_full_state(&c->st, 0.0, y, full, NULL)) != 0) return refuse(c, 0.0, swim_stroke_strerror(rc), st);
    memcpy(s->c0, full + 3, sizeof(double) * s->n);
    memcpy(s->dc0, full + 3 + s->n, sizeof(double) * s->n);
    if (s->rhof_neutral) s->rhof = s->rho0 / c->st.mu2;   /* (2.10) with the stroke's volume */
    if (swim_scene_check_model(s, c->kn->kernel, st)) return 2;
    double t_bad;
    char why[512];
    if (swim_stroke_check(&c->st, s->run.t_end, s->run.output_step, SWIM_STROKE_CHECK_SAMPLES, &t_bad, why, sizeof why))
        return refuse(c, t_bad, why, st);
    if (s->stroke_period > 0) {
        c->period = s->stroke_period;
        c->period_source = "scene";
    } else {
        c->period = swim_stroke_detect_period(&c->st, s->run.t_end);
        c->period_source = c->period > 0 ? "detected" : "none";
    }
    if (swim_dynamics_init(&c->d, s, c->kn->kernel) != 0) {
        swim_status_fail(st, "swim run", NULL, 0, NULL, "out of memory");
        return 1;
    }
    c->d_ready = 1;
    return 0;
}

static void end_run(swim_stroke_run *c, int failed, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void end_run(swim_stroke_run *c, int failed, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    free(c->reason);
    c->reason = swim_vstrprintf(fmt, ap);
    va_end(ap);
    c->status = failed;
}

/* The columns of trajectory.csv at state y (full: the state of model/dynamics.h). */
static int row_values(swim_stroke_run *c, double t, const double *y, double *full, double *v, int all, swim_diag *g)
{
    const swim_scene *s = c->s;
    double power = NAN;
    int rc = swim_stroke_full_state(&c->st, t, y, full, all ? &power : NULL);
    if (rc != 0) return rc;
    if (!all) {   /* the state's columns only (events that need no diagnostics) */
        v[0] = t;
        for (int i = 0; i < 3 + 2 * s->n; i++) v[1 + i] = full[i];
        return 0;
    }
    if (swim_dynamics_diagnostics(&c->d, full, g) != 0) return SWIM_RHS_EMASS;
    double extra[EXTRAS];
    extra[EXTRA_POWER] = power;
    extra[EXTRA_WORK_POSITIVE] = c->pw.total;
    extra[EXTRA_PHASE_C1] = s->stroke_complete_c1 ? y[SWIM_STROKE_PSI] : NAN;
    swim_run_columns_part parts[2];
    const int nparts = stroke_parts(parts);
    const swim_run_quantities q = {g, extra};
    swim_run_column_values(t, full, s->n, &q, parts, nparts, v);
    return 0;
}

/* Event columns at an integrator state (swim_run_row_func). */
static int event_row(void *p, double t, const double *ys, int all, double *row)
{
    swim_stroke_run *c = p;
    swim_diag g;
    return row_values(c, t, ys, c->evfull, row, all, &g) == 0 ? 0 : -1;
}

static void track(swim_stroke_run *c, double t, const swim_diag *g, double power, int first)
{
    if (first) {
        c->e0 = g->energy;
        c->jmin = INFINITY;
        c->jmin_t = c->left_D_t = NAN;
        c->pmax = -INFINITY;
        c->pmin = INFINITY;
    }
    c->t_reached = t;
    c->drift_abs = fmax(c->drift_abs, fabs(g->energy - c->e0 - g->work));
    c->emax = fmax(c->emax, fabs(g->energy));
    if (!(g->jmin >= c->jmin)) c->jmin_t = t;
    c->jmin = fmin(c->jmin, g->jmin);
    c->res_volume = fmax(c->res_volume, fabs(g->res_volume));
    c->res_volume_rate = fmax(c->res_volume_rate, fabs(g->res_volume_rate));
    c->res_angular = fmax(c->res_angular, fabs(g->res_angular));
    c->pmax = fmax(c->pmax, power);
    c->pmin = fmin(c->pmin, power);
}

/* The row at t (state c->y): diagnostics, CSV, snapshot. 0, or -1 when the run must stop. */
static int emit_row(swim_stroke_run *c, long k, long every, int last, double t)
{
    swim_diag g;
    double td = swim_clock_seconds();
    int rc = row_values(c, t, c->y, c->full, c->row, 1, &g);
    c->diagnostics_seconds += swim_clock_seconds() - td;
    if (rc != 0) {
        end_run(c, 1, "diagnostics failed at t = %.6g (%s)", t, swim_stroke_strerror(rc));
        return -1;
    }
    track(c, t, &g, c->row[c->ncol - 3], k == 0);
    c->last_energy = g.energy;
    c->last_work = g.work;
    const double to = swim_clock_seconds();
    swim_run_row row = {k, t, c->row, c->ncol, c->full, &c->d, 0};
    if ((k % every == 0 || last) && c->nsnap < SWIM_RUN_SNAPSHOTS + 1) {
        row.snapshot = 1;
        c->nsnap++;
    }
    char why[1024] = "";
    const int src = c->req.sink.row ? c->req.sink.row(c->req.sink.ctx, &row, why, sizeof why) : 0;
    if (src == 0 || src == SWIM_RUN_ROW_STOP) c->rows++;
    if (src != 0) {
        end_run(c, 1, "%s", why[0] ? why : "an output could not be written");
        return -1;
    }
    c->output_seconds += swim_clock_seconds() - to;
    if (!(g.jmin > 0)) {
        c->left_D_t = t;
        end_run(c, 1, "the shape left the admissible set D at t = %.6g (min J = %.3g)", t, g.jmin);
        return -1;
    }
    return 0;
}

static void stop_on_integrator(swim_stroke_run *c, int rc)
{
    const double t = c->ode ? swim_ode_time(c->ode) : 0.0;
    if (stop_requested(c)) {
        int sig = *c->req.stop;
        end_run(c, 1, "%s at t = %.6g", c->req.stop_by_caller ? "stopped by the caller" : sig == SIGINT ? "interrupted (SIGINT)" : sig == SIGTERM ? "terminated by SIGTERM"
                : "terminated by SIGHUP", c->t_reached);
    } else if (rc == SWIM_ODE_ERHS) {
        end_run(c, 1, "%s near t = %.6g", swim_stroke_strerror(swim_ode_rhs_status(c->ode)), c->st.last_rhs_t);
    } else {
        end_run(c, 1, "%s near t = %.6g", swim_ode_strerror(rc), t);
    }
}

/* Positive work: P is sampled at every target of the loop, at most this fraction of the period
 * (or of t_end without one) and a quarter of output_step apart, so that P changes sign at most
 * once between samples (a stroke's power has a few zeros per period). */

/* Rows at k*output_step and t_end, the ends of the strokes k*T, and the samples of the positive
 * work in between, merged in time order: the integrator only ever advances (interpolating). */
static void integrate(swim_stroke_run *c)
{
    const swim_scene *s = c->s;
    swim_ode_system sys = {swim_stroke_rhs, SWIM_STROKE_DIM, &c->st, NULL};
    swim_run_ode_options(&s->run, &c->o);
    if (c->events && swim_run_events_attach(c->events, &c->o, SWIM_STROKE_DIM, 3 + 2 * s->n, event_row, c) != 0) {
        end_run(c, 1, "out of memory");
        return;
    }
    swim_stroke_initial_state(&c->st, c->y);
    c->t_start = swim_clock_seconds();
    int rc = swim_ode_create(s->run.integrator, &sys, &c->o, 0.0, c->y, &c->ode);
    if (rc != SWIM_ODE_OK) {
        end_run(c, 1, "integrator '%s' could not start: %s", s->run.integrator, swim_ode_strerror(rc));
        return;
    }
    const long rows = (long)floor(s->run.t_end / s->run.output_step + 1e-9);
    const int tail_row = rows * s->run.output_step < s->run.t_end * (1 - 1e-12);
    const long every = rows / (SWIM_RUN_SNAPSHOTS - 1) > 0 ? rows / (SWIM_RUN_SNAPSHOTS - 1) : 1;
    const long nstrokes = c->period > 0 ? (long)fmin(floor(s->run.t_end / c->period * (1 + 1e-12)), MAX_STROKES) : 0;
    const double h_sample = fmin(0.25 * s->run.output_step, (c->period > 0 ? c->period : s->run.t_end) / SWIM_STROKE_POSWORK_SAMPLES);
    if (nstrokes > 0 && !(c->strokes = calloc((size_t)nstrokes, sizeof *c->strokes))) {
        end_run(c, 1, "out of memory");
        return;
    }
    double y_prev_stroke[SWIM_STROKE_DIM], w_prev_stroke = 0.0, t = 0.0;
    memcpy(y_prev_stroke, c->y, sizeof y_prev_stroke);
    if ((rc = swim_stroke_poswork_add(&c->st, &c->pw, 0.0, c->y[SWIM_STROKE_PSI])) != 0) {
        end_run(c, 1, "%s at t = 0", swim_stroke_strerror(rc));
        return;
    }
    long k = 0, j = 1;   /* next row, next stroke end */
    if (emit_row(c, k++, every, rows == 0 && !tail_row, 0.0) != 0) return;
    for (;;) {
        const double tr = k <= rows ? (k == rows && fabs(k * s->run.output_step - s->run.t_end) < 1e-9 * s->run.output_step
                                           ? s->run.t_end : k * s->run.output_step)
                        : (k == rows + 1 && tail_row ? s->run.t_end : INFINITY);
        const double ts = j <= nstrokes ? fmin(j * c->period, s->run.t_end) : INFINITY;
        const double target = fmin(tr, ts);
        if (!isfinite(target)) break;
        t = fmin(target, t + h_sample);
        if (target - t < 1e-3 * h_sample) t = target;   /* no sliver of a sample before a target */
        const double ta = swim_clock_seconds();
        rc = swim_ode_advance(c->ode, t, c->y);
        c->integrate_seconds += swim_clock_seconds() - ta;
        int event_stop = 0;
        if (rc == SWIM_ODE_TERMINATED) {
            t = swim_ode_time(c->ode);
            end_run(c, 0, "stopped by event %s at t = %.10g", swim_run_events_stop_name(c->events), t);
            event_stop = 1;
            rc = SWIM_ODE_OK;
        }
        if (rc != SWIM_ODE_OK) {
            stop_on_integrator(c, rc);
            break;
        }
        c->samples++;
        if ((rc = swim_stroke_poswork_add(&c->st, &c->pw, t, c->y[SWIM_STROKE_PSI])) != 0) {
            end_run(c, 1, "%s at t = %.6g", swim_stroke_strerror(rc), t);
            break;
        }
        if (!event_stop && ts <= t) {   /* the end of stroke j */
            stroke_record *r = &c->strokes[j - 1];
            r->t0 = (j - 1) * c->period;
            r->t1 = t;
            memcpy(r->y0, y_prev_stroke, sizeof r->y0);
            memcpy(r->y1, c->y, sizeof r->y1);
            r->wpos0 = w_prev_stroke;
            r->wpos1 = c->pw.total;
            memcpy(y_prev_stroke, c->y, sizeof y_prev_stroke);
            w_prev_stroke = c->pw.total;
            c->nstrokes = j++;
        }
        if (event_stop || tr <= t) {
            const int last = event_stop || k >= rows + tail_row;
            if (emit_row(c, k++, every, last, t) != 0) break;
        }
        if (event_stop) break;
        if (stop_requested(c)) {
            stop_on_integrator(c, SWIM_ODE_ERHS);
            break;
        }
        if (c->req.sink.progress) c->req.sink.progress(c->req.sink.ctx, t, s->run.t_end);
    }
    if (!c->reason) end_run(c, 0, "reached t_end = %.6g", s->run.t_end);
}

/* ---- report ------------------------------------------------------------------------------- */

/* The stroke object of the summary: laws, completion, period, per-stroke displacement and work. */
static json_t *stroke_object(const swim_stroke_run *c, int *bad)
{
    const swim_scene *s = c->s;
    char name[24];
    json_t *o = json_object(), *laws = json_object(), *list = json_array();
    if (!o || !laws || !list) {
        json_decref(o);
        json_decref(laws);
        json_decref(list);
        return NULL;
    }
    for (int k = 0; k < s->stroke_count; k++) {
        swim_coord_name(s->stroke_index[k], name, sizeof name);
        *bad |= swim_json_set(laws, name, swim_json_str(s->stroke_law[k]));
    }
    *bad |= swim_json_set(o, "laws", laws);
    *bad |= swim_json_set(o, "completed_c1", json_boolean(s->stroke_complete_c1));
    *bad |= swim_json_set(o, "completion", s->stroke_complete_c1 ? swim_json_str("c1 completed: |c1| from the volume "
                                                                                 "(2.5), its phase integrated from (2.14)")
                                                                  : json_null());
    *bad |= swim_json_set(o, "mu2", swim_json_num(c->st.mu2));
    *bad |= swim_json_set(o, "check_samples", json_integer(SWIM_STROKE_CHECK_SAMPLES));
    *bad |= swim_json_set(o, "period", swim_json_num(c->period > 0 ? c->period : NAN));
    *bad |= swim_json_set(o, "period_source", swim_json_str(c->period_source));
    *bad |= swim_json_set(o, "work", swim_json_num(c->y[SWIM_STROKE_WORK]));
    *bad |= swim_json_set(o, "work_positive", swim_json_num(c->pw.total));
    *bad |= swim_json_set(o, "power_max", swim_json_num(c->pmax));
    *bad |= swim_json_set(o, "power_min", swim_json_num(c->pmin));
    for (long j = 0; j < c->nstrokes; j++) {
        const stroke_record *r = &c->strokes[j];
        const double dx = r->y1[0] - r->y0[0], dy = r->y1[1] - r->y0[1], th = r->y0[2];
        /* the displacement in the body frame at the start of the stroke: R(theta)^T dr */
        const double bx = cos(th) * dx + sin(th) * dy, by = -sin(th) * dx + cos(th) * dy;
        json_t *e = json_object();
        if (e) {
            *bad |= swim_json_set(e, "stroke", json_integer(j + 1));
            *bad |= swim_json_set(e, "t_start", swim_json_num(r->t0));
            *bad |= swim_json_set(e, "t_end", swim_json_num(r->t1));
            *bad |= swim_json_set(e, "dx", swim_json_num(dx));
            *bad |= swim_json_set(e, "dy", swim_json_num(dy));
            *bad |= swim_json_set(e, "dtheta", swim_json_num(r->y1[2] - r->y0[2]));
            *bad |= swim_json_set(e, "distance", swim_json_num(hypot(dx, dy)));
            *bad |= swim_json_set(e, "body_dx", swim_json_num(bx));
            *bad |= swim_json_set(e, "body_dy", swim_json_num(by));
            *bad |= swim_json_set(e, "work", swim_json_num(r->y1[SWIM_STROKE_WORK] - r->y0[SWIM_STROKE_WORK]));
            *bad |= swim_json_set(e, "work_positive", swim_json_num(r->wpos1 - r->wpos0));
        }
        *bad |= !e || json_array_append_new(list, e) != 0;
    }
    *bad |= swim_json_set(o, "strokes", list);
    return o;
}

/* The stroke's own entry of summary.json (swim_run_stroke_kind.summary). */
static int stroke_summary(const void *p, json_t *summary)
{
    int bad = 0;
    bad |= swim_json_set(summary, "stroke", stroke_object(p, &bad));
    return bad ? -1 : 0;
}


/* ---- the contract ------------------------------------------------------------------------- */

static void stroke_free(void *p);

static int stroke_open(const swim_run_request *req, void **out, swim_status *st)
{
    *out = NULL;
    swim_stroke_run *c = calloc(1, sizeof *c);
    if (!c) {
        swim_status_fail(st, "swim run", NULL, 0, NULL, "out of memory");
        return 1;
    }
    c->req = *req;
    c->s = req->scene;
    c->kn = req->kernel;
    c->law = req->system;
    c->events = req->events;
    c->ncol = stroke_columns(c->s, c->names, c->storage);
    const int rc = prepare_stroke(c, st);
    if (rc) {
        stroke_free(c);
        return rc;
    }
    swim_run_result *r = &c->res;
    r->summary_brief = 1;   /* until the one call: nothing run, nothing known */
    r->compiled = c->law;   /* the model of a stroke: its laws alone, no effects, no projection */
    r->kernel_kind = "stroke";
    r->state_dimension = SWIM_STROKE_DIM;
    r->jacobian = "none";
    r->switch_t = -1.0;
    *out = c;
    return 0;
}

/* A stroke runs to its end at the first call. */
static int stroke_advance(void *p, double t_unused)
{
    swim_stroke_run *c = p;
    if (c->res.finished) return c->res.status;
    integrate(c);
    c->wall_seconds = swim_clock_seconds() - c->t_start;
    swim_run_result *r = &c->res;
    r->summary_brief = 0;
    r->finished = 1;
    r->is_stroke = 1;
    r->status = c->status;
    r->reason = c->reason;
    r->t_reached = c->t_reached;
    r->rows = c->rows;
    r->e0 = c->e0;
    r->drift_abs = c->drift_abs;
    r->emax = c->emax;
    r->res_volume = c->res_volume;
    r->res_volume_rate = c->res_volume_rate;
    r->res_angular = c->res_angular;
    r->jmin = c->jmin;
    r->jmin_t = c->jmin_t;
    r->left_t = c->left_D_t;
    r->switch_t = -1.0;
    snprintf(r->used, sizeof r->used, "%s", c->s->run.integrator);
    if (c->ode) swim_ode_get_stats(c->ode, &r->stats);
    r->integrate_seconds = c->integrate_seconds;
    r->diagnostics_seconds = c->diagnostics_seconds;
    r->output_seconds = c->output_seconds;
    r->wall_seconds = c->wall_seconds;
    r->final_state = c->full;
    r->energy = c->last_energy;
    r->work = c->last_work;
    r->forcing_work = c->pw.total;   /* a stroke: what the body spends on it, int max(P, 0) dt */
    swim_stroke_report *k = &r->stroke;
    k->laws = c->s->stroke_count;
    k->completed_c1 = c->s->stroke_complete_c1;
    k->rhs_calls = c->st.rhs_calls;
    k->period = c->period;
    k->period_source = c->period_source;
    k->strokes = c->nstrokes;
    if (c->nstrokes) {
        const stroke_record *f = &c->strokes[0];
        k->first_dx = f->y1[0] - f->y0[0];
        k->first_dy = f->y1[1] - f->y0[1];
        k->first_dtheta = f->y1[2] - f->y0[2];
        k->first_work_positive = f->wpos1 - f->wpos0;
    } else {
        k->first_dx = k->first_dy = k->first_dtheta = k->first_work_positive = NAN;
    }
    k->work = c->y[SWIM_STROKE_WORK];
    k->work_positive = c->pw.total;
    r->step_lookahead = c->o.lookahead;
    return c->status;
}

static void stroke_fail(void *p, const char *reason)
{
    swim_stroke_run *c = p;
    if (c->status == 0) end_run(c, 1, "%s", reason);
    c->res.status = c->status;
    c->res.reason = c->reason;
}

static const swim_run_result *stroke_result(void *p)
{
    swim_stroke_run *c = p;
    c->res.rhs_calls = c->st.rhs_calls;
    c->res.rhs_seconds = c->st.rhs_seconds;
    return &c->res;
}

static swim_dynamics *stroke_dynamics(void *p) { return &((swim_stroke_run *)p)->d; }

static void stroke_free(void *p)
{
    swim_stroke_run *c = p;
    if (!c) return;
    swim_ode_free(c->ode);
    if (c->d_ready) swim_dynamics_free(&c->d);
    if (c->st_ready) swim_stroke_free(&c->st);
    free(c->strokes);
    free(c->reason);
    free(c);
}

/* no dense output of the run's state: the stroke's state is (r, theta, psi, work) */
const swim_run_kind swim_run_stroke_kind = {
    "stroke", stroke_columns, stroke_open, stroke_advance, stroke_fail, stroke_result, NULL, stroke_dynamics,
    stroke_summary, NULL, NULL, stroke_free,
};
