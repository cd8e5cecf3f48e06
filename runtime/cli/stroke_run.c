/* swim run on a scene with a [stroke] table: a prescribed stroke (runtime/stroke/stroke.h).
 *
 * Same command line, outputs and summary as `swim run` (trajectory.csv with the same columns
 * and three more -- power, work_positive, phase_c1 --, summary.json with the same keys and a
 * "stroke" object, scene.toml, events.csv, snapshots.json), so that `swim plot`, `swim flow`,
 * `swim animate` and `swim sweep` serve stroke runs unchanged. Options that only mean something
 * for the dynamics (--generic, --no-projection, --trace-steps) are refused.
 *
 * Stages: options (scene + command line), kernels (N modes, and the stroke's laws generated with
 * their exact derivatives), the stroke checked on the whole interval (a stroke that is not
 * allowable or leaves D is bad input: one line naming the time, exit 2, nothing written),
 * outputs, integration (rows at k*output_step and t_end, and the state at the end of every
 * stroke k*T for the per-stroke report), report. A run that stops early keeps its rows and says
 * why in the summary ("failed"), exactly as `swim run`.
 */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_events.h"
#include "cli/run_outputs.h"
#include "cli/run_settings.h"
#include "cli/run_signals.h"
#include "codegen/codegen.h"
#include "io/csv.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"
#include "io/stdout_check.h"
#include "model/dynamics.h"
#include "model/flow.h"
#include "ode/ode.h"
#include "scene/scene.h"
#include "scene/toml.h"
#include "stroke/stroke.h"

#define MAX_SETS 64
#define NCOLS_MAX (8 + 4 * SWIM_NMAX + 64)
#define SNAPSHOTS 10
#define MAX_STROKES 100000    /* strokes reported one by one in the summary */

/* One stroke [t0, t1]: the state at both ends (r, theta, psi, work) and the positive work. */
typedef struct {
    double t0, t1, y0[SWIM_STROKE_DIM], y1[SWIM_STROKE_DIM], wpos0, wpos1;
} stroke_record;

typedef struct {
    swim_scene s;
    const char *scene_file, *out_opt;
    int quiet, summary_only, snapshots;
    swim_override sets[MAX_SETS];
    int nsets;
    swim_run_events *events;
    const char *names[NCOLS_MAX];
    char storage[2 * SWIM_NMAX][24];
    int ncol;
    /* kernels and model */
    swim_compiled kn, law;
    swim_stroke st;
    int st_ready;
    swim_dynamics d;          /* diagnostics and flow snapshots of a row (no right-hand side) */
    int d_ready;
    double period;
    const char *period_source;
    /* outputs */
    swim_run_paths paths;        /* the output folder and its files */
    swim_csv csv;
    FILE *snap;
    char *snap_buf;
    size_t snap_len;
    int nsnap;
    char *output_error;
    /* integration */
    swim_ode *ode;
    swim_ode_options o;
    double y[SWIM_STROKE_DIM], full[4 + 2 * SWIM_NMAX], row[NCOLS_MAX];
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
    double t_start, integrate_seconds, diagnostics_seconds, output_seconds;
} stroke_ctx;

/* ---- is it a stroke scene? ---------------------------------------------------------------- */

/* The scene named on the command line of `swim run` (the first word that is not an option or an
 * option's value), or NULL. */
static const char *scene_argument(int argc, char **argv)
{
    static const char *const valued[] = {"out", "t-end", "output-step", "rtol", "atol", "integrator",
                                         "step-lookahead", "trace-steps", "event", "set"};
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "--", 2) != 0) return a;
        if (strchr(a, '=')) continue;
        for (size_t k = 0; k < sizeof valued / sizeof valued[0]; k++)
            if (strcmp(a + 2, valued[k]) == 0) {
                i++;
                break;
            }
    }
    return NULL;
}

int swim_stroke_requested(int argc, char **argv)
{
    const char *path = scene_argument(argc, argv);
    FILE *f = path ? fopen(path, "rb") : NULL;
    if (!f) return 0;   /* swim run says what is wrong with it */
    char *buf = malloc(SWIM_SCENE_MAX_BYTES + 1);
    size_t len = buf ? fread(buf, 1, SWIM_SCENE_MAX_BYTES + 1, f) : 0;
    fclose(f);
    int stroke = 0;
    if (buf && len <= SWIM_SCENE_MAX_BYTES) {
        char err[256];
        const size_t bom = len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
        toml_value *root = toml_parse(buf + bom, len - bom, err, sizeof err);
        stroke = root && toml_get(root, "stroke") != NULL;
        toml_free(root);
    }
    free(buf);
    return stroke;
}

/* ---- options ------------------------------------------------------------------------------ */

static int columns(const swim_scene *s, const char **names, char storage[][24])
{
    static const char *const tail[] = {
        "kinetic_fluid", "kinetic_shape", "kinetic_rigid", "potential", "energy",
        "impulse_body_x", "impulse_body_y", "impulse_body_ang",
        "impulse_fluid_rigid_x", "impulse_fluid_rigid_y", "impulse_fluid_rigid_ang",
        "impulse_fluid_shape_x", "impulse_fluid_shape_y", "impulse_fluid_shape_ang",
        "res_volume", "res_volume_rate", "res_angular", "res_locks", "jmin", "work", "w1", "w2",
        "power", "work_positive", "phase_c1"};
    int c = swim_run_state_columns(s->n, names, storage);
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) names[c++] = tail[i];
    return c;
}

static int read_options(int argc, char **argv, stroke_ctx *c)
{
    swim_opt opts[] = {{"out", 1, NULL}, {"t-end", 1, NULL}, {"rtol", 1, NULL}, {"output-step", 1, NULL},
                       {"atol", 1, NULL}, {"integrator", 1, NULL}, {"quiet", 0, NULL}, {"generic", 0, NULL},
                       {"no-projection", 0, NULL}, {"step-lookahead", 1, NULL}, {"trace-steps", 1, NULL},
                       {"event", 2, NULL}, {"snapshots", 0, NULL}, {"summary-only", 0, NULL},
                       {"sensitivity", 1, NULL}, {"sensitivity-steps", 1, NULL}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *vals[MAX_SETS], *pos[1];
    int npos = 0;
    c->nsets = swim_args_take_all("run", &argc, argv, 2, "set", vals, MAX_SETS);
    if (c->nsets < 0) return 2;
    for (int i = 0; i < c->nsets; i++) {
        char err[256];
        if (swim_override_parse(vals[i], &c->sets[i], err, sizeof err) != 0) {
            swim_message(stderr, "swim run: --set: %s", err);
            return 2;
        }
    }
    if (swim_args_parse("run", argc, argv, 2, opts, nopts, pos, 1, &npos)) return 2;
    /* The variational equations are those of the free shape dynamics; a prescribed stroke has
     * none (its shape is a given function of time), so there is nothing to differentiate. */
    const char *sens = swim_args_get(opts, nopts, "sensitivity") ? "sensitivity"
                       : swim_args_get(opts, nopts, "sensitivity-steps") ? "sensitivity-steps" : NULL;
    if (sens) {
        swim_message(stderr, "swim run: --%s: not available on a prescribed stroke ([stroke] in %s): "
                     "sensitivities are computed for free shape dynamics only", sens, npos ? pos[0] : "the scene");
        return 2;
    }
    if (npos != 1) {
        swim_message(stderr, "swim run: expected one scene file, e.g. swim run models/stroke_loop.toml");
        return 2;
    }
    static const char *const refused[] = {"generic", "no-projection", "trace-steps"};
    for (int i = 0; i < 3; i++)
        if (swim_args_get(opts, nopts, refused[i])) {
            swim_message(stderr, "swim run: --%s: does not apply to a prescribed stroke (%s has [stroke]: "
                         "only (3.21) is integrated)", refused[i], pos[0]);
            return 2;
        }
    swim_scene *s = &c->s;
    c->scene_file = pos[0];
    if (swim_scene_load_with(pos[0], c->sets, c->nsets, s)) return 2;
    if (swim_run_settings_options(opts, nopts, s) != 0) return 2;
    c->quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    c->out_opt = swim_args_get(opts, nopts, "out");
    c->summary_only = swim_args_get(opts, nopts, "summary-only") != NULL;
    c->snapshots = swim_args_get(opts, nopts, "snapshots") != NULL && !c->summary_only;
    c->ncol = columns(s, c->names, c->storage);
    return swim_run_events_parse(s, argc, argv, c->names, c->ncol, &c->events);
}

/* ---- kernels and the stroke ----------------------------------------------------------------- */

/* One line naming the scene, the first law's key and the time: the stroke is refused. */
static int refuse(const stroke_ctx *c, double t, const char *why)
{
    const swim_scene *s = &c->s;
    char name[24];
    swim_coord_name(s->stroke_index[0], name, sizeof name);
    char where[512];
    swim_message(stderr, "swim: %s: stroke.%s: the stroke is not allowable at t = %.9g: %s",
                 swim_scene_where(s, s->stroke_line[0], where, sizeof where), name, t, why);
    return 2;
}

/* One line naming the law the generator refused (swim_codegen_stroke -2): bad input, exit 2. */
static int law_refused(const stroke_ctx *c)
{
    char where[640];
    swim_message(stderr, "swim: %s: %s", swim_scene_stroke_where(&c->s, c->law.refused_index, where, sizeof where),
                 c->law.refused);
    return 2;
}

/* The kernels, the stroke model, the check over [0, t_end], the period. 0, 1 or 2. */
static int prepare_stroke(stroke_ctx *c)
{
    swim_scene *s = &c->s;
    const int verbose = c->quiet ? 0 : 1;
    int got = swim_codegen_kernel(s->modes, &c->kn, verbose) != 0 ? -1 : swim_codegen_stroke(s, &c->law, verbose);
    if (got == -2) return law_refused(c);
    if (got != 0) {
        swim_message(stderr, "swim run: %s: no kernel for this stroke, nothing computed", s->path);
        return 1;
    }
    int rc = swim_stroke_init(&c->st, s, c->kn.kernel, c->law.stroke, s->param_values);
    if (rc == -1) {
        swim_message(stderr, "swim run: out of memory");
        return 1;
    }
    c->st_ready = 1;
    c->st.interrupt = (volatile int *)&swim_run_stop;
    if (rc == SWIM_STROKE_EVOLUME) {
        char where[512];
        swim_message(stderr, "swim: %s: shape.c0: c1 is 0: its phase, which c1's completion (2.14) integrates, "
                     "is undefined", swim_scene_where(s, s->line_c0, where, sizeof where));
        return 2;
    }
    if (rc != 0) return refuse(c, 0.0, swim_stroke_strerror(rc));
    /* the scene's initial state becomes the stroke's: the diagnostics measure the volume and the
     * locks against it, and the magnitude check of the model runs on it */
    double y[SWIM_STROKE_DIM], full[4 + 2 * SWIM_NMAX];
    swim_stroke_initial_state(&c->st, y);
    if ((rc = swim_stroke_full_state(&c->st, 0.0, y, full, NULL)) != 0) return refuse(c, 0.0, swim_stroke_strerror(rc));
    memcpy(s->c0, full + 3, sizeof(double) * s->n);
    memcpy(s->dc0, full + 3 + s->n, sizeof(double) * s->n);
    if (s->rhof_neutral) s->rhof = s->rho0 / c->st.mu2;   /* (2.10) with the stroke's volume */
    if (swim_scene_check_model(s, c->kn.kernel)) return 2;
    double t_bad;
    char why[512];
    if (swim_stroke_check(&c->st, s->t_end, s->output_step, SWIM_STROKE_CHECK_SAMPLES, &t_bad, why, sizeof why))
        return refuse(c, t_bad, why);
    if (s->stroke_period > 0) {
        c->period = s->stroke_period;
        c->period_source = "scene";
    } else {
        c->period = swim_stroke_detect_period(&c->st, s->t_end);
        c->period_source = c->period > 0 ? "detected" : "none";
    }
    if (swim_dynamics_init(&c->d, s, c->kn.kernel) != 0) {
        swim_message(stderr, "swim run: out of memory");
        return 1;
    }
    c->d_ready = 1;
    return 0;
}

static int open_outputs(stroke_ctx *c)
{
    const int prc = swim_run_paths_open(&c->paths, c->out_opt, c->s.path);
    if (prc == 1) goto oom;
    if (prc != 0) return prc;
    if (swim_copy_file(c->scene_file, c->paths.scene_copy_path) != 0) {
        swim_message(stderr, "swim run: --out: cannot write '%s': %s", c->paths.scene_copy_path, strerror(errno));
        return 2;
    }
    if (!c->summary_only && swim_csv_open(&c->csv, c->paths.csv_path, c->names, c->ncol) != 0) {
        swim_message(stderr, "swim run: --out: cannot write '%s': %s", c->paths.csv_path, strerror(errno));
        return 2;
    }
    const char *const stale[] = {c->paths.summary_path, c->paths.snap_path, c->paths.events_path, c->summary_only ? c->paths.csv_path : NULL};
    for (size_t i = 0; i < sizeof stale / sizeof stale[0]; i++)
        if (stale[i] && unlink(stale[i]) != 0 && errno != ENOENT) {
            swim_message(stderr, "swim run: --out: cannot remove the old '%s': %s", stale[i], strerror(errno));
            return 2;
        }
    if (c->snapshots) {
        if (!(c->snap = open_memstream(&c->snap_buf, &c->snap_len))) goto oom;
        fputs("[\n", c->snap);
    }
    return 0;
oom:
    swim_message(stderr, "swim run: out of memory");
    return 1;
}

/* ---- integration -------------------------------------------------------------------------- */

static void output_failed(stroke_ctx *c, const char *path, int err);
static void end_run(stroke_ctx *c, int failed, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void end_run(stroke_ctx *c, int failed, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    free(c->reason);
    c->reason = swim_vstrprintf(fmt, ap);
    va_end(ap);
    c->status = failed;
}

/* The columns of trajectory.csv at state y (full: the state of model/dynamics.h). */
static int row_values(stroke_ctx *c, double t, const double *y, double *full, double *v, int all, swim_diag *g)
{
    const swim_scene *s = &c->s;
    double power = NAN;
    int rc = swim_stroke_full_state(&c->st, t, y, full, all ? &power : NULL);
    if (rc != 0) return rc;
    int k = 0;
    v[k++] = t;
    for (int i = 0; i < 3 + 2 * s->n; i++) v[k++] = full[i];
    if (!all) return 0;
    if (swim_dynamics_diagnostics(&c->d, full, g) != 0) return SWIM_RHS_EMASS;
    const double tail[] = {
        g->kinetic_fluid, g->kinetic_shape, g->kinetic_rigid, g->w1 + g->w2, g->energy,
        g->impulse_body[0], g->impulse_body[1], g->impulse_body[2],
        g->impulse_fluid_rigid[0], g->impulse_fluid_rigid[1], g->impulse_fluid_rigid[2],
        g->impulse_fluid_shape[0], g->impulse_fluid_shape[1], g->impulse_fluid_shape[2],
        g->res_volume, g->res_volume_rate, g->res_angular, g->res_locks, g->jmin, g->work, g->w1, g->w2,
        power, c->pw.total, s->stroke_complete_c1 ? y[SWIM_STROKE_PSI] : NAN};
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) v[k++] = tail[i];
    return 0;
}

/* Event columns at an integrator state (swim_run_row_func). */
static int event_row(void *p, double t, const double *ys, int all, double *row)
{
    stroke_ctx *c = p;
    swim_diag g;
    return row_values(c, t, ys, c->evfull, row, all, &g) == 0 ? 0 : -1;
}

static void track(stroke_ctx *c, double t, const swim_diag *g, double power, int first)
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
static int emit_row(stroke_ctx *c, long k, long every, int last, double t)
{
    swim_diag g;
    double td = swim_wall();
    int rc = row_values(c, t, c->y, c->full, c->row, 1, &g);
    c->diagnostics_seconds += swim_wall() - td;
    if (rc != 0) {
        end_run(c, 1, "diagnostics failed at t = %.6g (%s)", t, swim_stroke_strerror(rc));
        return -1;
    }
    track(c, t, &g, c->row[c->ncol - 3], k == 0);
    const double to = swim_wall();
    if (!c->summary_only && swim_csv_row(&c->csv, c->row) != 0) {
        output_failed(c, c->paths.csv_path, errno);
        return -1;
    }
    c->rows++;
    if (c->snap && (k % every == 0 || last) && c->nsnap < SNAPSHOTS + 1) {
        if (c->nsnap++) fputs(",\n", c->snap);
        if (swim_flow_snapshot(&c->d, t, c->full, c->snap) != 0) {
            output_failed(c, c->paths.snap_path, ENOMEM);
            return -1;
        }
    }
    c->output_seconds += swim_wall() - to;
    if (!(g.jmin > 0)) {
        c->left_D_t = t;
        end_run(c, 1, "the shape left the admissible set D at t = %.6g (min J = %.3g)", t, g.jmin);
        return -1;
    }
    return 0;
}

static void stop_on_integrator(stroke_ctx *c, int rc)
{
    const double t = c->ode ? swim_ode_time(c->ode) : 0.0;
    if (swim_run_stop) {
        int sig = swim_run_stop;
        end_run(c, 1, "%s at t = %.6g", sig == SIGINT ? "interrupted (SIGINT)" : sig == SIGTERM ? "terminated by SIGTERM"
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
static void integrate(stroke_ctx *c)
{
    const swim_scene *s = &c->s;
    swim_ode_system sys = {swim_stroke_rhs, SWIM_STROKE_DIM, &c->st, NULL};
    swim_ode_options_default(&c->o);
    c->o.rtol = s->rtol;
    c->o.atol = s->atol;
    if (s->step_lookahead >= 0) c->o.lookahead = s->step_lookahead;
    if (c->events && swim_run_events_attach(c->events, &c->o, SWIM_STROKE_DIM, 3 + 2 * s->n, event_row, c) != 0) {
        end_run(c, 1, "out of memory");
        return;
    }
    swim_stroke_initial_state(&c->st, c->y);
    c->t_start = swim_wall();
    int rc = swim_ode_create(s->integrator, &sys, &c->o, 0.0, c->y, &c->ode);
    if (rc != SWIM_ODE_OK) {
        end_run(c, 1, "integrator '%s' could not start: %s", s->integrator, swim_ode_strerror(rc));
        return;
    }
    const long rows = (long)floor(s->t_end / s->output_step + 1e-9);
    const int tail_row = rows * s->output_step < s->t_end * (1 - 1e-12);
    const long every = rows / (SNAPSHOTS - 1) > 0 ? rows / (SNAPSHOTS - 1) : 1;
    const long nstrokes = c->period > 0 ? (long)fmin(floor(s->t_end / c->period * (1 + 1e-12)), MAX_STROKES) : 0;
    const double h_sample = fmin(0.25 * s->output_step, (c->period > 0 ? c->period : s->t_end) / SWIM_STROKE_POSWORK_SAMPLES);
    if (nstrokes > 0 && !(c->strokes = calloc((size_t)nstrokes, sizeof *c->strokes))) {
        end_run(c, 1, "out of memory");
        return;
    }
    double last_progress = c->t_start, y_prev_stroke[SWIM_STROKE_DIM], w_prev_stroke = 0.0, t = 0.0;
    memcpy(y_prev_stroke, c->y, sizeof y_prev_stroke);
    if ((rc = swim_stroke_poswork_add(&c->st, &c->pw, 0.0, c->y[SWIM_STROKE_PSI])) != 0) {
        end_run(c, 1, "%s at t = 0", swim_stroke_strerror(rc));
        return;
    }
    long k = 0, j = 1;   /* next row, next stroke end */
    if (emit_row(c, k++, every, rows == 0 && !tail_row, 0.0) != 0) return;
    for (;;) {
        const double tr = k <= rows ? (k == rows && fabs(k * s->output_step - s->t_end) < 1e-9 * s->output_step
                                           ? s->t_end : k * s->output_step)
                        : (k == rows + 1 && tail_row ? s->t_end : INFINITY);
        const double ts = j <= nstrokes ? fmin(j * c->period, s->t_end) : INFINITY;
        const double target = fmin(tr, ts);
        if (!isfinite(target)) break;
        t = fmin(target, t + h_sample);
        if (target - t < 1e-3 * h_sample) t = target;   /* no sliver of a sample before a target */
        const double ta = swim_wall();
        rc = swim_ode_advance(c->ode, t, c->y);
        c->integrate_seconds += swim_wall() - ta;
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
        if (swim_run_stop) {
            stop_on_integrator(c, SWIM_ODE_ERHS);
            break;
        }
        const double now = swim_wall();
        if (!c->quiet && now - last_progress > 1.0) {
            fprintf(stderr, "\rswim run: t = %.4g / %.4g (%.0f%%)   ", t, s->t_end, 100.0 * t / s->t_end);
            last_progress = now;
        }
    }
    if (!c->quiet && last_progress > c->t_start) fputc('\n', stderr);
    if (!c->reason) end_run(c, 0, "reached t_end = %.6g", s->t_end);
}

/* ---- report ------------------------------------------------------------------------------- */

/* The stroke object of the summary: laws, completion, period, per-stroke displacement and work. */
static void stroke_json(FILE *f, const stroke_ctx *c)
{
    const swim_scene *s = &c->s;
    char name[24];
    fprintf(f, ",\n  \"stroke\": {\"laws\": {");
    for (int k = 0; k < s->stroke_count; k++) {
        swim_coord_name(s->stroke_index[k], name, sizeof name);
        fprintf(f, "%s\"%s\": ", k ? ", " : "", name);
        swim_json_string(f, s->stroke_law[k]);
    }
    fprintf(f, "},\n    \"completed_c1\": %s, \"completion\": ", s->stroke_complete_c1 ? "true" : "false");
    if (s->stroke_complete_c1)
        swim_json_string(f, "c1 completed: |c1| from the volume (2.5), its phase integrated from (2.14)");
    else
        fprintf(f, "null");
    fprintf(f, ",\n    \"mu2\": %.17g, \"check_samples\": %d,\n    \"period\": ", c->st.mu2, SWIM_STROKE_CHECK_SAMPLES);
    swim_json_number(f, c->period > 0 ? c->period : NAN);
    fprintf(f, ", \"period_source\": \"%s\",\n    \"work\": ", c->period_source);
    swim_json_number(f, c->y[SWIM_STROKE_WORK]);
    fprintf(f, ", \"work_positive\": ");
    swim_json_number(f, c->pw.total);
    fprintf(f, ", \"power_max\": ");
    swim_json_number(f, c->pmax);
    fprintf(f, ", \"power_min\": ");
    swim_json_number(f, c->pmin);
    fprintf(f, ",\n    \"strokes\": [");
    for (long j = 0; j < c->nstrokes; j++) {
        const stroke_record *r = &c->strokes[j];
        const double dx = r->y1[0] - r->y0[0], dy = r->y1[1] - r->y0[1], th = r->y0[2];
        /* the displacement in the body frame at the start of the stroke: R(theta)^T dr */
        const double bx = cos(th) * dx + sin(th) * dy, by = -sin(th) * dx + cos(th) * dy;
        fprintf(f, "%s\n      {\"stroke\": %ld, \"t_start\": %.17g, \"t_end\": %.17g, \"dx\": %.17g, \"dy\": %.17g, "
                "\"dtheta\": %.17g, \"distance\": %.17g, \"body_dx\": %.17g, \"body_dy\": %.17g, \"work\": %.17g, "
                "\"work_positive\": %.17g}", j ? "," : "", j + 1, r->t0, r->t1, dx, dy, r->y1[2] - r->y0[2],
                hypot(dx, dy), bx, by, r->y1[SWIM_STROKE_WORK] - r->y0[SWIM_STROKE_WORK],
                r->wpos1 - r->wpos0);
    }
    fprintf(f, "%s]}", c->nstrokes ? "\n    " : "");
}

static void summary_json(FILE *f, void *ctx)
{
    const stroke_ctx *c = ctx;
    const swim_scene *s = &c->s;
    const double *y = c->full;
    char name[24];
    swim_ode_stats st;
    memset(&st, 0, sizeof st);
    if (c->ode) swim_ode_get_stats(c->ode, &st);
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, s->path);
    fprintf(f, ",\n  \"title\": ");
    swim_json_string(f, s->title);
    fprintf(f, ",\n  \"out\": ");
    swim_json_string(f, c->paths.dir);
    fprintf(f, ",\n  \"modes\": %d,\n  \"rho0\": %.17g,\n  \"rhof\": %.17g,\n  \"integrator\": ", s->modes, s->rho0, s->rhof);
    swim_json_string(f, s->integrator);
    fprintf(f, ",\n  \"integrator_switch_t\": null,\n  \"rtol\": %.3g,\n  \"atol\": %.3g,\n  \"step_lookahead\": %d,\n  \"free\": [",
            s->rtol, s->atol, c->o.lookahead);
    for (int i = 0, first = 1; i < s->n; i++)
        if (s->free_mask[i]) {
            swim_coord_name(i, name, sizeof name);
            fprintf(f, "%s\"%s\"", first ? "" : ", ", name);
            first = 0;
        }
    fprintf(f, "],\n  \"effects\": {\"elastic\": false, \"barrier\": false, \"damping\": false, \"forcing\": false},\n");
    fprintf(f, "  \"kernel\": {\"kind\": \"stroke\", \"state_dimension\": %d, \"cache\": ", SWIM_STROKE_DIM);
    swim_json_string(f, c->law.dir);
    fprintf(f, ", \"from_cache\": %s, \"generate_seconds\": %.3f, \"compile_seconds\": %.3f},\n",
            c->law.from_cache ? "true" : "false", c->law.generate_seconds, c->law.compile_seconds);
    fprintf(f, "  \"projection\": {\"enabled\": false, \"steps\": 0, \"max_change\": 0},\n");
    fprintf(f, "  \"status\": \"%s\",\n  \"reason\": ", c->status ? "failed" : "completed");
    swim_json_string(f, c->reason ? c->reason : "out of memory");
    fprintf(f, ",\n  \"t_end\": %.17g,\n  \"t_reached\": %.17g,\n  \"rows\": %ld,\n", s->t_end, c->t_reached, c->rows);
    fprintf(f, "  \"initial_velocity_projected\": false,\n  \"projection_change\": 0,\n");
    fprintf(f, "  \"final_state\": {\"t\": %.17g, \"x\": %.17g, \"y\": %.17g, \"theta\": %.17g, \"c\": ", c->t_reached,
            y[0], y[1], y[2]);
    swim_json_vector(f, y + 3, s->n);
    fprintf(f, ", \"dc\": ");
    swim_json_vector(f, y + 3 + s->n, s->n);
    fprintf(f, "},\n  \"energy_initial\": ");
    swim_json_number(f, c->e0);
    fprintf(f, ",\n  \"energy_drift_abs\": ");
    swim_json_number(f, c->drift_abs);
    fprintf(f, ",\n  \"energy_drift_rel\": ");
    swim_json_number(f, c->emax > 0 ? c->drift_abs / c->emax : 0.0);
    fprintf(f, ",\n  \"max_residuals\": {\"volume\": %.3g, \"volume_rate\": %.3g, \"angular\": %.3g, \"locks\": 0},\n",
            c->res_volume, c->res_volume_rate, c->res_angular);
    fprintf(f, "  \"jmin\": ");
    swim_json_number(f, c->jmin);
    fprintf(f, ",\n  \"jmin_t\": ");
    swim_json_number(f, c->jmin_t);
    fprintf(f, ",\n  \"left_D_t\": ");
    swim_json_number(f, c->left_D_t);
    /* the shape is prescribed: no stiff switch, and min J is checked on the rows and the
     * allowability samples (swim_stroke_check), not by the per-step watch of swim run */
    fprintf(f, ",\n  \"stiff_switch\": null,\n  \"step_checks\": {\"enabled\": false, \"steps\": 0, \"seconds\": 0}");
    fprintf(f, ",\n  \"origin_shift\": {\"enabled\": false, \"restarts\": 0}");   /* no barrier in a stroke */
    fprintf(f, ",\n  \"impacts\": {\"enabled\": false, \"impact_depth\": 0, \"count\": 0, \"first_t\": null, \"last_t\": null, "
               "\"jmin_max\": null, \"turning_min\": null}");   /* the shape is prescribed */
    fprintf(f, ",\n  \"energy_control\": {\"enabled\": false, \"tolerance\": 0, \"rejected_steps\": 0}");   /* (3.21) alone: no energy */
    swim_run_events_json(c->events, f);
    stroke_json(f, c);
    const swim_run_timing t = {c->integrate_seconds, c->diagnostics_seconds, c->output_seconds, c->st.rhs_seconds,
                               swim_wall() - c->t_start, c->st.rhs_calls, "none", 0, 0.0};
    swim_run_stats_json(f, &st, &t);
    fprintf(f, "\n}\n");
}

static void output_failed(stroke_ctx *c, const char *path, int err)
{
    if (!c->output_error) c->output_error = swim_strprintf("cannot write %s: %s", path, strerror(err ? err : EIO));
    if (c->status == 0) end_run(c, 1, "%s", c->output_error ? c->output_error : "an output could not be written");
}

static int report(stroke_ctx *c)
{
    const swim_scene *s = &c->s;
    if (c->csv.line && swim_csv_close(&c->csv) != 0) output_failed(c, c->paths.csv_path, errno);
    if (c->snap) {
        fputs("\n]\n", c->snap);
        int bad = ferror(c->snap);
        if (fclose(c->snap) != 0 || bad) output_failed(c, c->paths.snap_path, ENOMEM);
        else if (swim_replace_file(c->paths.snap_path, c->snap_buf, c->snap_len) != 0) output_failed(c, c->paths.snap_path, errno);
        c->snap = NULL;
    }
    if (c->events && swim_run_events_write_csv(c->events, c->paths.events_path) != 0) output_failed(c, c->paths.events_path, errno);
    if (swim_replace_file_with(c->paths.summary_path, summary_json, c) != 0) {
        swim_message(stderr, "swim run: cannot write %s: %s (the run %s: %s)", c->paths.summary_path, strerror(errno),
                     c->status ? "FAILED" : "completed", c->reason ? c->reason : "out of memory");
        c->status = 1;
    }
    swim_message(stdout, c->summary_only ? "%s: %s (%s); %ld rows computed, summary in %s" : "%s: %s (%s); %ld rows in %s",
                 s->path, c->status ? "FAILED" : "completed", c->reason ? c->reason : "out of memory", c->rows,
                 c->summary_only ? c->paths.summary_path : c->paths.csv_path);
    printf("  prescribed stroke: %d laws%s; (3.21) integrated with %s, rtol %.3g: %ld RHS evaluations\n",
           s->stroke_count, s->stroke_complete_c1 ? ", c1 completed from the volume (2.5) and (2.14)" : "",
           s->integrator, s->rtol, c->st.rhs_calls);
    if (c->period > 0)
        printf("  period %.10g (%s), %ld strokes; per stroke: first displacement (%.6g, %.6g), dtheta %.6g, "
               "positive work %.6g\n", c->period, c->period_source, c->nstrokes,
               c->nstrokes ? c->strokes[0].y1[0] - c->strokes[0].y0[0] : NAN,
               c->nstrokes ? c->strokes[0].y1[1] - c->strokes[0].y0[1] : NAN,
               c->nstrokes ? c->strokes[0].y1[2] - c->strokes[0].y0[2] : NAN,
               c->nstrokes ? c->strokes[0].wpos1 - c->strokes[0].wpos0 : NAN);
    else
        printf("  no period: the laws do not repeat within t_end (set [stroke] period to report strokes)\n");
    printf("  work %.6g, positive work %.6g, energy check |E - E0 - work| <= %.3g; min J %.4g\n",
           c->y[SWIM_STROKE_WORK], c->pw.total, c->drift_abs, c->jmin);
    printf("  final position x = %.6g, y = %.6g, theta = %.6g\n", c->full[0], c->full[1], c->full[2]);
    if (swim_stdout_check("run") != 0) return 1;
    return c->status ? 1 : 0;
}

static void release(stroke_ctx *c)
{
    swim_csv_close(&c->csv);
    if (c->snap) fclose(c->snap);
    free(c->snap_buf);
    swim_run_events_free(c->events);
    swim_ode_free(c->ode);
    if (c->d_ready) swim_dynamics_free(&c->d);
    if (c->st_ready) swim_stroke_free(&c->st);
    swim_compiled_close(&c->law);
    swim_compiled_close(&c->kn);
    free(c->strokes);
    free(c->reason);
    free(c->output_error);
    swim_run_paths_free(&c->paths);
    swim_scene_free(&c->s);
    free(c);
}

int swim_cmd_stroke(int argc, char **argv)
{
    stroke_ctx *c = calloc(1, sizeof *c);
    if (!c) {
        swim_message(stderr, "swim run: out of memory");
        return 1;
    }
    swim_run_signals sig;
    swim_run_stop = 0;
    int rc = read_options(argc, argv, c);
    if (rc == 0) rc = prepare_stroke(c);
    if (rc == 0) rc = open_outputs(c);
    if (rc == 0) {
        swim_run_signals_install(&sig);
        integrate(c);
        rc = report(c);
        swim_run_signals_restore(&sig);
    }
    release(c);
    return rc;
}
