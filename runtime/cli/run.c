/* swim run: one scene end to end -- trajectory.csv, summary.json and a copy of the scene
 * (scene.toml, so that DIR is self-contained: `swim flow` and `swim plot` need nothing else) in DIR;
 * snapshots.json only with --snapshots (otherwise `swim flow DIR` computes them when needed).
 *
 * Rows fall exactly on t0 + k*output_step and on t_end, produced by the integrator's own
 * interpolant. A run that stops early (NaN, step-size underflow, barrier crossed, SIGINT) keeps
 * every row it wrote (each row is flushed) and says in summary.json where and why it stopped. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_events.h"
#include "io/csv.h"
#include "io/files.h"
#include "io/json.h"
#include "model/dynamics.h"
#include "model/flow.h"
#include "codegen/codegen.h"
#include "ode/ode.h"
#include "scene/scene.h"

#define SNAPSHOTS 10

static volatile sig_atomic_t interrupted;
static void on_sigint(int sig) { (void)sig; interrupted = 1; }

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct {
    double t_reached, jmin, e0, drift_abs, emax, res_volume, res_volume_rate, res_angular, res_locks;
    long rows;
    int status;           /* 0 completed, 1 failed */
    char reason[256];
    double switch_t;      /* time of a switch to the stiff fallback integrator, or -1 */
    double integrate_seconds;   /* time inside the integrator (steps, RHS, interpolation) */
    double diagnostics_seconds; /* energies, impulses, residuals, min J of the output rows */
    double output_seconds;      /* formatting and writing rows and snapshots */
    char used[64];        /* integrator(s) used */
    swim_run_events *events;    /* located events, or NULL */
} run_report;

static int columns(const swim_scene *s, const char **names, char storage[][24])
{
    int c = 0;
    static const char *const head[] = {"t", "x", "y", "theta"};
    static const char *const tail[] = {
        "kinetic_fluid", "kinetic_shape", "kinetic_rigid", "potential", "energy",
        "impulse_body_x", "impulse_body_y", "impulse_body_ang",
        "impulse_fluid_rigid_x", "impulse_fluid_rigid_y", "impulse_fluid_rigid_ang",
        "impulse_fluid_shape_x", "impulse_fluid_shape_y", "impulse_fluid_shape_ang",
        "res_volume", "res_volume_rate", "res_angular", "res_locks", "jmin", "work", "w1", "w2"};
    for (int i = 0; i < 4; i++) names[c++] = head[i];
    for (int i = 0; i < s->n; i++) {
        swim_coord_name(i, storage[i], 24);
        names[c++] = storage[i];
    }
    for (int i = 0; i < s->n; i++) {
        storage[s->n + i][0] = 'd';
        swim_coord_name(i, storage[s->n + i] + 1, 23);
        names[c++] = storage[s->n + i];
    }
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) names[c++] = tail[i];
    return c;
}

static int row_values(const swim_scene *s, double t, const double *y, const swim_diag *g, double *v)
{
    int c = 0;
    v[c++] = t;
    for (int i = 0; i < 3 + 2 * s->n; i++) v[c++] = y[i];
    const double tail[] = {
        g->kinetic_fluid, g->kinetic_shape, g->kinetic_rigid, g->w1 + g->w2, g->energy,
        g->impulse_body[0], g->impulse_body[1], g->impulse_body[2],
        g->impulse_fluid_rigid[0], g->impulse_fluid_rigid[1], g->impulse_fluid_rigid[2],
        g->impulse_fluid_shape[0], g->impulse_fluid_shape[1], g->impulse_fluid_shape[2],
        g->res_volume, g->res_volume_rate, g->res_angular, g->res_locks, g->jmin, g->work, g->w1, g->w2};
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) v[c++] = tail[i];
    return c;
}

static void track(run_report *r, double t, const swim_diag *g, int first)
{
    if (first) { r->e0 = g->energy; r->jmin = INFINITY; }
    r->t_reached = t;
    r->drift_abs = fmax(r->drift_abs, fabs(g->energy - r->e0 - g->work));
    r->emax = fmax(r->emax, fabs(g->energy));
    r->jmin = fmin(r->jmin, g->jmin);
    r->res_volume = fmax(r->res_volume, fabs(g->res_volume));
    r->res_volume_rate = fmax(r->res_volume_rate, fabs(g->res_volume_rate));
    r->res_angular = fmax(r->res_angular, fabs(g->res_angular));
    r->res_locks = fmax(r->res_locks, g->res_locks);
}

static void write_summary(const char *path, const swim_scene *s, const char *dir, const run_report *r,
                          const double *y, const swim_ode_stats *st, const swim_dynamics *d,
                          const swim_compiled *sp, double wall_s)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "swim run: cannot write %s: %s\n", path, strerror(errno));
        return;
    }
    char name[24];
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, s->path);
    fprintf(f, ",\n  \"title\": ");
    swim_json_string(f, s->title);
    fprintf(f, ",\n  \"out\": ");
    swim_json_string(f, dir);
    fprintf(f, ",\n  \"modes\": %d,\n  \"rho0\": %.17g,\n  \"rhof\": %.17g,\n  \"integrator\": ", s->modes, s->rho0, s->rhof);
    swim_json_string(f, r->used);
    fprintf(f, ",\n  \"integrator_switch_t\": ");
    swim_json_number(f, r->switch_t >= 0 ? r->switch_t : NAN);
    fprintf(f, ",\n  \"rtol\": %.3g,\n  \"atol\": %.3g,\n  \"step_lookahead\": %d,\n  \"free\": [", s->rtol, s->atol, s->step_lookahead);
    for (int i = 0, first = 1; i < s->n; i++)
        if (s->free_mask[i]) {
            swim_coord_name(i, name, sizeof name);
            fprintf(f, "%s\"%s\"", first ? "" : ", ", name);
            first = 0;
        }
    fprintf(f, "],\n  \"effects\": {\"elastic\": %s, \"barrier\": %s, \"damping\": %s, \"forcing\": %s},\n",
            s->elastic ? "true" : "false", s->barrier ? "true" : "false", s->damped ? "true" : "false",
            s->forced ? "true" : "false");
    fprintf(f, "  \"kernel\": {\"kind\": \"%s\", \"state_dimension\": %d, \"cache\": ",
            d->generic ? "generic" : "specialized", swim_dynamics_state_dim(d));
    swim_json_string(f, sp->dir);
    fprintf(f, ", \"from_cache\": %s, \"generate_seconds\": %.3f, \"compile_seconds\": %.3f},\n",
            sp->from_cache ? "true" : "false", sp->generate_seconds, sp->compile_seconds);
    fprintf(f, "  \"projection\": {\"enabled\": %s, \"steps\": %ld, \"max_change\": %.3g},\n",
            s->projection && (swim_ode_capabilities(s->integrator) & SWIM_ODE_CAP_PROJECTION) ? "true" : "false", d->projections, d->max_projection);
    fprintf(f, "  \"status\": \"%s\",\n  \"reason\": ", r->status ? "failed" : "completed");
    swim_json_string(f, r->reason);
    fprintf(f, ",\n  \"t_end\": %.17g,\n  \"t_reached\": %.17g,\n  \"rows\": %ld,\n", s->t_end, r->t_reached, r->rows);
    fprintf(f, "  \"initial_velocity_projected\": %s,\n  \"projection_change\": %.3g,\n",
            s->projection_change > 0 ? "true" : "false", s->projection_change);
    fprintf(f, "  \"final_state\": {\"t\": %.17g, \"x\": %.17g, \"y\": %.17g, \"theta\": %.17g, \"c\": ", r->t_reached, y[0], y[1], y[2]);
    swim_json_vector(f, y + 3, s->n);
    fprintf(f, ", \"dc\": ");
    swim_json_vector(f, y + 3 + s->n, s->n);
    fprintf(f, "},\n  \"energy_initial\": ");
    swim_json_number(f, r->e0);
    fprintf(f, ",\n  \"energy_drift_abs\": ");
    swim_json_number(f, r->drift_abs);
    fprintf(f, ",\n  \"energy_drift_rel\": ");
    swim_json_number(f, r->emax > 0 ? r->drift_abs / r->emax : 0.0);
    fprintf(f, ",\n  \"max_residuals\": {\"volume\": %.3g, \"volume_rate\": %.3g, \"angular\": %.3g, \"locks\": %.3g},\n",
            r->res_volume, r->res_volume_rate, r->res_angular, r->res_locks);
    fprintf(f, "  \"jmin\": ");
    swim_json_number(f, r->jmin);
    swim_run_events_json(r->events, f);
    fprintf(f, ",\n  \"stats\": {\"steps\": %ld, \"rhs_evaluations\": %ld, \"rejected_steps\": %ld, "
            "\"jacobian_evaluations\": %ld, \"last_step\": %.6g, \"last_order\": %d, \"stiffness_suspected\": %s,\n"
            "            \"order_histogram\": [",
            st->steps, st->rhs_evals, st->rejected, st->jac_evals, st->last_h, st->last_order,
            st->stiff_suspected ? "true" : "false");
    for (int i = 0; i < 13; i++) fprintf(f, "%s%ld", i ? ", " : "", st->order_hist[i]);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(f, "],\n            \"integrate_seconds\": %.6f, \"diagnostics_seconds\": %.6f, \"output_seconds\": %.6f,",
            r->integrate_seconds, r->diagnostics_seconds, r->output_seconds);
    fprintf(f, "\n            \"rhs_seconds\": %.6f, \"wall_seconds\": %.6f, \"ns_per_rhs\": %.1f, \"max_rss_kb\": %ld}\n}\n",
            d->rhs_seconds, wall_s, d->rhs_calls ? 1e9 * d->rhs_seconds / d->rhs_calls : 0.0, ru.ru_maxrss);
    fclose(f);
}

/* --trace-steps FILE: one row per ABM step attempt, with the energy of each accepted state. */
typedef struct {
    swim_csv csv;
    swim_dynamics *d;
    double *full;     /* full state for the diagnostics */
    int open;         /* csv is open */
    int ok;           /* no write error so far */
} step_trace;

static const char *const trace_columns[] = {"t", "h", "order", "accepted", "err", "erk", "growth", "energy", "work"};

static void trace_step(const swim_ode_step *st, void *data)
{
    step_trace *tr = data;
    if (!tr->ok)
        return;
    double v[9] = {st->t, st->h, st->order, st->accepted, st->err, st->erk, st->growth, NAN, NAN};
    swim_diag g;
    if (st->y) {
        swim_dynamics_unpack(tr->d, st->y, tr->full);
        if (swim_dynamics_diagnostics(tr->d, tr->full, &g) == 0) {
            v[7] = g.energy;
            v[8] = g.work;
        }
    }
    if (swim_csv_row(&tr->csv, v) != 0)
        tr->ok = 0;
}

/* The row of trajectory.csv at integrator state ys (event functions evaluate columns). */
typedef struct {
    const swim_scene *s;
    swim_dynamics *d;
    double *full;
} row_ctx;

static int packed_row(void *p, double t, const double *ys, int all, double *row)
{
    row_ctx *c = p;
    swim_diag g;
    swim_dynamics_unpack(c->d, ys, c->full);
    if (!all) {   /* t and the state columns only */
        row[0] = t;
        memcpy(row + 1, c->full, sizeof(double) * (3 + 2 * c->s->n));
        return 0;
    }
    if (swim_dynamics_diagnostics(c->d, c->full, &g) != 0) return -1;
    row_values(c->s, t, c->full, &g, row);
    return 0;
}

/* Add the counters of `ode` to `total` (a run may use two integrators). */
static void accumulate_stats(swim_ode_stats *total, const swim_ode *ode)
{
    swim_ode_stats st;
    if (swim_ode_get_stats(ode, &st) != SWIM_ODE_OK) return;
    total->steps += st.steps;
    total->rhs_evals += st.rhs_evals;
    total->rejected += st.rejected;
    total->jac_evals += st.jac_evals;
    for (int i = 0; i < 13; i++) total->order_hist[i] += st.order_hist[i];
    total->last_h = st.last_h;
    total->last_order = st.last_order;
    total->stiff_suspected |= st.stiff_suspected;
}

static void default_out(const char *scene_path, char *out, size_t len)
{
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    snprintf(out, len, "out/%s", base);
    char *dot = strrchr(out, '.');
    if (dot && dot > out + 4) *dot = '\0';
}

/* --set KEY=VALUE (repeatable): overrides applied to the scene before it is validated. */
#define MAX_SETS 64
static int take_set_options(int *argc, char **argv, swim_override *sets)
{
    const char *vals[MAX_SETS];
    int n = swim_args_take_all("run", argc, argv, 2, "set", vals, MAX_SETS);
    for (int i = 0; i < n; i++) {
        char err[256];
        if (swim_override_parse(vals[i], &sets[i], err, sizeof err) != 0) {
            fprintf(stderr, "swim run: --set: %s\n", err);
            return -1;
        }
    }
    return n;
}

int swim_cmd_run(int argc, char **argv)
{
    swim_opt opts[] = {{"out", 1, NULL},  {"t-end", 1, NULL},      {"rtol", 1, NULL},
                       {"output-step", 1, NULL},
                       {"atol", 1, NULL}, {"integrator", 1, NULL}, {"quiet", 0, NULL},
                       {"generic", 0, NULL}, {"no-projection", 0, NULL}, {"step-lookahead", 1, NULL},
                       {"trace-steps", 1, NULL}, {"event", 1, NULL}, {"snapshots", 0, NULL},
                       {"summary-only", 0, NULL}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    static swim_override sets[MAX_SETS];
    const int nsets = take_set_options(&argc, argv, sets);
    if (nsets < 0) return 2;
    if (swim_args_parse("run", argc, argv, 2, opts, nopts, pos, 1, &npos)) return 2;
    if (npos != 1) {
        fprintf(stderr, "swim run: expected one scene file, e.g. swim run models/example3.toml\n");
        return 2;
    }
    static swim_scene s;
    if (swim_scene_load_with(pos[0], sets, nsets, &s)) return 2;
    const char *v;
    if ((v = swim_args_get(opts, nopts, "t-end"))) {
        if (swim_args_double("run", "t-end", v, &s.t_end)) return 2;
        if (!(s.t_end > 0)) { fprintf(stderr, "swim run: --t-end: must be > 0, got %s\n", v); return 2; }
    }
    if ((v = swim_args_get(opts, nopts, "output-step"))) {
        if (swim_args_double("run", "output-step", v, &s.output_step)) return 2;
        if (!(s.output_step > 0) || s.t_end / s.output_step > 1e7) {
            fprintf(stderr, "swim run: --output-step: must be > 0 and give at most 10^7 rows, got %s\n", v);
            return 2;
        }
    }
    if ((v = swim_args_get(opts, nopts, "rtol"))) {
        if (swim_args_double("run", "rtol", v, &s.rtol)) return 2;
        if (!(s.rtol > 0)) { fprintf(stderr, "swim run: --rtol: must be > 0, got %s\n", v); return 2; }
    }
    if ((v = swim_args_get(opts, nopts, "atol"))) {
        if (swim_args_double("run", "atol", v, &s.atol)) return 2;
        if (!(s.atol > 0)) { fprintf(stderr, "swim run: --atol: must be > 0, got %s\n", v); return 2; }
    }
    if ((v = swim_args_get(opts, nopts, "integrator"))) {
        if (!swim_ode_method_known(v) || strlen(v) >= sizeof s.integrator) {
            fprintf(stderr, "swim run: --integrator: unknown integrator '%s' (%s)\n", v, swim_ode_method_list());
            return 2;
        }
        snprintf(s.integrator, sizeof s.integrator, "%s", v);
    }
    if ((v = swim_args_get(opts, nopts, "step-lookahead"))) {
        long p;
        if (swim_args_int("run", "step-lookahead", v, 0, 12, &p)) return 2;
        s.step_lookahead = (int)p;
    }
    const int quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    /* A sweep member keeps only its summary: the rows are still computed (the summary's drift,
     * residuals and min J come from them) but neither formatted nor written. */
    const int summary_only = swim_args_get(opts, nopts, "summary-only") != NULL;
    if (swim_args_get(opts, nopts, "no-projection")) s.projection = 0;
    char dir[900];
    if ((v = swim_args_get(opts, nopts, "out"))) snprintf(dir, sizeof dir, "%s", v);
    else default_out(s.path, dir, sizeof dir);
    if (swim_mkdirs(dir) != 0) {
        fprintf(stderr, "swim run: --out: cannot create directory '%s': %s\n", dir, strerror(errno));
        swim_scene_free(&s);
        return 2;
    }
    char path[1024];
    const char *names[8 + 4 * SWIM_NMAX + 64];
    char storage[2 * SWIM_NMAX][24];
    int ncol = columns(&s, names, storage);
    swim_run_events *events = NULL;
    if (swim_run_events_parse(&s, argc, argv, names, ncol, &events)) { swim_scene_free(&s); return 2; }
    snprintf(path, sizeof path, "%s/scene.toml", dir);
    if (swim_copy_file(s.path, path) != 0) {
        fprintf(stderr, "swim run: --out: cannot write '%s': %s\n", path, strerror(errno));
        swim_scene_free(&s);
        swim_run_events_free(events);
        return 2;
    }
    step_trace trace = {.d = NULL, .full = NULL, .open = 0, .ok = 0};
    if ((v = swim_args_get(opts, nopts, "trace-steps"))) {
        if (!(swim_ode_capabilities(s.integrator) & SWIM_ODE_CAP_STEP_TRACE)) {
            fprintf(stderr, "swim run: --trace-steps: integrator '%s' does not report its steps\n", s.integrator);
            swim_scene_free(&s);
            swim_run_events_free(events);
            return 2;
        }
        if (swim_csv_open(&trace.csv, v, trace_columns, 9) != 0) {
            fprintf(stderr, "swim run: --trace-steps: cannot write '%s': %s\n", v, strerror(errno));
            swim_scene_free(&s);
            swim_run_events_free(events);
            return 2;
        }
        trace.open = trace.ok = 1;
    }
    /* The kernel of N modes (diagnostics) and the right-hand side: linked in, cached, or
     * generated and compiled now (runtime/codegen). */
    swim_compiled kn, spz;
    const int generic = swim_args_get(opts, nopts, "generic") != NULL;
    if (swim_codegen_kernel(s.modes, &kn, quiet ? 0 : 2) != 0 || swim_codegen_scene(&s, generic, &spz, quiet ? 0 : 2) != 0) {
        fprintf(stderr, "swim run: %s: no kernel for this scene, nothing computed\n", s.path);
        swim_compiled_close(&kn);
        if (trace.open) swim_csv_close(&trace.csv);
        swim_scene_free(&s);
        swim_run_events_free(events);
        return 1;
    }
    swim_dynamics d;
    if (swim_dynamics_init(&d, &s, kn.kernel) != 0) {
        fprintf(stderr, "swim run: out of memory\n");
        swim_compiled_close(&spz);
        swim_compiled_close(&kn);
        if (trace.open) swim_csv_close(&trace.csv);
        swim_scene_free(&s);
        swim_run_events_free(events);
        return 1;
    }
    d.interrupt = (volatile int *)&interrupted;
    swim_dynamics_use_scene_kernel(&d, spz.scene, generic);
    swim_csv csv;
    snprintf(path, sizeof path, "%s/trajectory.csv", dir);
    if (summary_only) remove(path);   /* never leave another run's rows beside this summary */
    if (!summary_only && swim_csv_open(&csv, path, names, ncol) != 0) {
        fprintf(stderr, "swim run: --out: cannot write '%s': %s\n", path, strerror(errno));
        if (trace.open) swim_csv_close(&trace.csv);
        swim_dynamics_free(&d);
        swim_compiled_close(&spz);
        swim_compiled_close(&kn);
        swim_scene_free(&s);
        swim_run_events_free(events);
        return 2;
    }
    snprintf(path, sizeof path, "%s/snapshots.json", dir);
    FILE *snap = NULL;
    if (swim_args_get(opts, nopts, "snapshots") && !summary_only) snap = fopen(path, "w");
    else remove(path);   /* a stale file from an earlier run would not match this trajectory */
    if (snap) fputs("[\n", snap);

    const int sdim = swim_dynamics_state_dim(&d);
    double *y = calloc((size_t)d.dim, sizeof(double)), *row = calloc((size_t)ncol, sizeof(double));
    double *ys = calloc((size_t)sdim, sizeof(double));
    swim_dynamics_initial_state(&d, y);
    swim_dynamics_pack(&d, y, ys);
    swim_ode_system sys = {swim_dynamics_rhs, (size_t)sdim, &d, NULL};
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = s.rtol;
    o.atol = s.atol;
    if (s.step_lookahead >= 0) o.lookahead = s.step_lookahead;
    s.step_lookahead = o.lookahead;   /* the summary records the value used */
    const unsigned caps = swim_ode_capabilities(s.integrator);
    o.stiff_stop = (caps & SWIM_ODE_CAP_STIFFNESS) != 0;   /* stop and report (or switch) on stiffness */
    if (s.projection && (caps & SWIM_ODE_CAP_PROJECTION)) o.project = swim_dynamics_project;  /* drift control */
    if (trace.open) {
        trace.d = &d;
        trace.full = calloc((size_t)d.dim, sizeof(double));
        trace.ok = trace.full != NULL;
        o.on_step = trace_step;
        o.on_step_data = &trace;
    }
    row_ctx rowc = {&s, &d, calloc((size_t)d.dim, sizeof(double))};
    if (events && (!rowc.full || swim_run_events_attach(events, &o, (size_t)sdim, 3 + 2 * s.n, packed_row, &rowc) != 0)) {
        fprintf(stderr, "swim run: out of memory\n");
        swim_run_events_free(events);
        return 1;
    }
    swim_ode *ode = NULL;
    run_report r;
    memset(&r, 0, sizeof r);
    r.events = events;
    r.switch_t = -1.0;
    snprintf(r.used, sizeof r.used, "%s", s.integrator);
    swim_ode_stats total;
    memset(&total, 0, sizeof total);
    double *ys_last = calloc((size_t)sdim, sizeof(double)), t_last = 0.0;
    double *ys_row = calloc((size_t)sdim, sizeof(double));
    memcpy(ys_last, ys, sizeof(double) * sdim);
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigaction(SIGINT, &sa, &old);
    const double t_start = wall();
    double last_progress = t_start;
    int rc = swim_ode_create(s.integrator, &sys, &o, 0.0, ys, &ode);
    const long rows = (long)floor(s.t_end / s.output_step + 1e-9);
    const long every = rows / (SNAPSHOTS - 1) > 0 ? rows / (SNAPSHOTS - 1) : 1;
    int nsnap = 0;
    if (rc != SWIM_ODE_OK) {
        r.status = 1;
        snprintf(r.reason, sizeof r.reason, "integrator '%s' could not start: %s", s.integrator, swim_ode_strerror(rc));
    }
    for (long k = 0; rc == SWIM_ODE_OK; k++) {
        double t = k <= rows ? k * s.output_step : s.t_end;
        if (k == rows && fabs(t - s.t_end) < 1e-9 * s.output_step) t = s.t_end;
        if (k > rows && (rows * s.output_step >= s.t_end * (1 - 1e-12))) break;
        if (k > rows + 1) break;
        if (k > 0) {
            double ta = wall();
            rc = swim_ode_advance(ode, t, ys);
            r.integrate_seconds += wall() - ta;
            if (rc == SWIM_ODE_ESTIFF && s.stiff_fallback[0] && r.switch_t < 0) {
                /* Restart the stiff integrator from the last output row (exact state there). */
                double ts = swim_ode_time(ode);
                accumulate_stats(&total, ode);
                swim_ode_free(ode);
                ode = NULL;
                if (!quiet)
                    fprintf(stderr, "swim run: stiffness detected near t = %.6g; switching from %s to %s at t = %.6g\n",
                            ts, s.integrator, s.stiff_fallback, t_last);
                r.switch_t = t_last;
                swim_run_events_rewind(events, t_last);
                snprintf(r.used, sizeof r.used, "%s+%s", s.integrator, s.stiff_fallback);
                memcpy(ys, ys_last, sizeof(double) * sdim);
                o.stiff_stop = 0;
                if (!(swim_ode_capabilities(s.stiff_fallback) & SWIM_ODE_CAP_PROJECTION)) o.project = NULL;
                if (!(swim_ode_capabilities(s.stiff_fallback) & SWIM_ODE_CAP_STEP_TRACE)) o.on_step = NULL;
                rc = swim_ode_create(s.stiff_fallback, &sys, &o, t_last, ys, &ode);
                if (rc == SWIM_ODE_OK) rc = swim_ode_advance(ode, t, ys);
            }
            if (rc == SWIM_ODE_TERMINATED) {   /* a :stop event: the last row is at its time */
                t = swim_ode_time(ode);
                snprintf(r.reason, sizeof r.reason, "stopped by event %s at t = %.10g", swim_run_events_stop_name(events), t);
                rc = SWIM_ODE_OK;
            }
            if (rc == SWIM_ODE_OK) {
                /* Rows come from the interpolant, which leaves the constraint manifold by the local
                 * error between two projected steps: project the row as well (a copy; the
                 * integrator's state is untouched). */
                if (o.project && ode) {
                    memcpy(ys_row, ys, sizeof(double) * sdim);
                    o.project(t, ys_row, &d);
                    swim_dynamics_unpack(&d, ys_row, y);
                } else {
                    swim_dynamics_unpack(&d, ys, y);
                }
                memcpy(ys_last, ys, sizeof(double) * sdim);
                t_last = t;
            }
            if (rc != SWIM_ODE_OK) {
                int rs = swim_ode_rhs_status(ode);
                r.status = 1;
                if (rc == SWIM_ODE_ERHS)
                    snprintf(r.reason, sizeof r.reason, "%s near t = %.6g", swim_dynamics_strerror(rs), d.last_rhs_t);
                else if (rc == SWIM_ODE_ESTIFF)
                    snprintf(r.reason, sizeof r.reason, "stiffness detected near t = %.6g: Adams PECE is "
                             "stability-limited here; rerun with --integrator cvode-bdf (or msbdf), or set "
                             "[run] stiff_fallback = \"cvode-bdf\" in the scene", ode ? swim_ode_time(ode) : t);
                else
                    snprintf(r.reason, sizeof r.reason, "%s near t = %.6g", swim_ode_strerror(rc), swim_ode_time(ode));
                break;
            }
        }
        swim_diag g;
        double t_diag = wall();
        int diag_rc = swim_dynamics_diagnostics(&d, y, &g);
        r.diagnostics_seconds += wall() - t_diag;
        if (diag_rc != 0) {
            r.status = 1;
            snprintf(r.reason, sizeof r.reason, "diagnostics failed at t = %.6g (K not positive definite)", t);
            break;
        }
        track(&r, t, &g, k == 0);
        double t_out = wall();
        row_values(&s, t, y, &g, row);
        if (!summary_only && swim_csv_row(&csv, row) != 0) {
            r.status = 1;
            snprintf(r.reason, sizeof r.reason, "write error on trajectory.csv at t = %.6g", t);
            break;
        }
        r.rows++;
        if (snap && (k % every == 0 || k > rows) && nsnap < SNAPSHOTS + 1) {
            if (nsnap++) fputs(",\n", snap);
            swim_flow_snapshot(&d, t, y, snap);
            fflush(snap);
        }
        r.output_seconds += wall() - t_out;
        if (!(g.jmin > 0)) {
            r.status = 1;
            snprintf(r.reason, sizeof r.reason, "the shape left the admissible set D at t = %.6g (min J = %.3g)", t, g.jmin);
            break;
        }
        if (interrupted) {
            r.status = 1;
            snprintf(r.reason, sizeof r.reason, "interrupted (SIGINT) at t = %.6g", t);
            break;
        }
        if (r.reason[0]) break;   /* stopped by an event */
        double now = wall();
        if (!quiet && now - last_progress > 1.0) {
            fprintf(stderr, "\rswim run: t = %.4g / %.4g (%.0f%%)   ", t, s.t_end, 100.0 * t / s.t_end);
            last_progress = now;
        }
    }
    if (!quiet && last_progress > t_start) fputc('\n', stderr);
    sigaction(SIGINT, &old, NULL);
    if (r.status == 0 && !r.reason[0]) snprintf(r.reason, sizeof r.reason, "reached t_end = %.6g", s.t_end);
    if (ode) accumulate_stats(&total, ode);
    swim_ode_stats st = total;
    if (snap) {
        fputs("\n]\n", snap);
        fclose(snap);
    }
    if (!summary_only) swim_csv_close(&csv);
    if (trace.open) {
        swim_csv_close(&trace.csv);
        free(trace.full);
    }
    swim_run_events_write_csv(events, dir);
    snprintf(path, sizeof path, "%s/summary.json", dir);
    write_summary(path, &s, dir, &r, y, &st, &d, &spz, wall() - t_start);
    if (summary_only)
        printf("%s: %s (%s); %ld rows computed, summary in %s/summary.json\n", s.path, r.status ? "FAILED" : "completed", r.reason, r.rows, dir);
    else
        printf("%s: %s (%s); %ld rows in %s/trajectory.csv\n", s.path, r.status ? "FAILED" : "completed", r.reason, r.rows, dir);
    printf("  %s kernel (state dimension %d)\n", d.generic ? "generic" : "specialized", sdim);
    printf("  integrator %s, rtol %.3g: %ld steps, %ld RHS evaluations, %ld rejected; %.3f s (%.3f s in the RHS)\n",
           r.used, s.rtol, st.steps, st.rhs_evals, st.rejected, wall() - t_start, d.rhs_seconds);
    printf("  energy drift %.3g (E0 = %.6g), max residuals: volume %.2g, angular %.2g, locks %.2g; min J %.4g\n",
           r.drift_abs, r.e0, r.res_volume, r.res_angular, r.res_locks, r.jmin);
    printf("  final position x = %.6g, y = %.6g, theta = %.6g\n", y[0], y[1], y[2]);
    swim_ode_free(ode);
    swim_run_events_free(events);
    free(rowc.full);
    swim_compiled_close(&spz);
    swim_compiled_close(&kn);
    free(ys);
    free(ys_last);
    free(ys_row);
    free(y);
    free(row);
    swim_dynamics_free(&d);
    swim_scene_free(&s);
    return r.status ? 1 : 0;
}
