/* swim run: one scene end to end into its output folder DIR -- trajectory.csv, summary.json,
 * scene.toml (the scene as run: the overrides and run options written in, so that DIR is
 * self-contained: `swim flow`, `swim plot` and `swim run DIR/scene.toml` need nothing else),
 * events.csv with --event or an [events] list, snapshots.json with --snapshots, sensitivity.csv
 * with --sensitivity. A scene with a [stroke] table is a prescribed stroke, with the same outputs.
 *
 * The command is its command line and its report: argv becomes a job (output/job.h: the run of
 * driver/run.h into the folder of output/folder.h), the signals are caught while it runs, and the
 * report is printed from its result. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_settings.h"
#include "cli/run_signals.h"
#include "io/clock.h"
#include "io/message.h"
#include "cli/report.h"
#include "model/lyapunov.h"
#include "output/job.h"

typedef struct {
    swim_opt opts[40];
    int nopts;
    swim_override sets[SWIM_JOB_MAX_SETS];
    const char *events[SWIM_RUN_MAX_EVENTS + 1];
    char *sensitivity, *command;
    swim_run_job job;
    double t_start, last_progress;
    swim_status status;          /* what the layers below found wrong, and where their notices go */
} run_cmd;

/* --sensitivity KEYS (repeatable: each adds its keys), taken out of argv and joined with commas
 * into *out (NULL when absent). 0, or 2 after one line on stderr. */
static int take_sensitivity_options(int *argc, char **argv, char **out)
{
    const char *vals[SWIM_JOB_MAX_SETS];
    int n = swim_args_take_all("run", argc, argv, 2, "sensitivity", vals, SWIM_JOB_MAX_SETS);
    if (n < 0) return 2;
    *out = NULL;
    for (int i = 0; i < n; i++) {
        if (vals[i][0] == '\0') {
            swim_message(stderr, "swim run: --sensitivity: empty list of keys");
            return 2;
        }
        char *joined = *out ? swim_strprintf("%s,%s", *out, vals[i]) : strdup(vals[i]);
        free(*out);
        if (!(*out = joined)) {
            swim_message(stderr, "swim run: out of memory");
            return 1;
        }
    }
    return 0;
}

/* The run options over the read scene (checked with their option's names), and their record. */
static int adjust(const swim_scene *s, swim_run_settings *set, swim_override *recorded, int *nrecorded, void *ctx,
                  swim_status *st)
{
    (void)st;   /* the options' refusals are this command's own lines */
    run_cmd *c = ctx;
    /* the variational equations are those of the free shape dynamics; a prescribed stroke has
     * none (its shape is a given function of time) */
    const char *sens = c->sensitivity ? "sensitivity"
                     : swim_args_get(c->opts, c->nopts, "sensitivity-steps") ? "sensitivity-steps"
                     : swim_args_get(c->opts, c->nopts, "sensitivity-method") ? "sensitivity-method" : NULL;
    if (s->stroke_count > 0 && sens) {
        swim_message(stderr, "swim run: --%s: not available on a prescribed stroke ([stroke] in %s): "
                     "sensitivities are computed for free shape dynamics only", sens, c->job.scene_file);
        return 2;
    }
    if (s->stroke_count > 0 && swim_args_get(c->opts, c->nopts, "no-projection")) {
        swim_message(stderr, "swim run: --no-projection: does not apply to a prescribed stroke (%s has [stroke]: "
                     "only (3.21) is integrated)", c->job.scene_file);
        return 2;
    }
    if (swim_run_settings_options(c->opts, c->nopts, s, set) != 0) return 2;
    *nrecorded = swim_run_settings_record(c->opts, c->nopts, set, recorded);
    return 0;
}

/* argv into the job. 0, 2 after one line on stderr, or 1 (out of memory). */
static int read_options(int argc, char **argv, run_cmd *c)
{
    const swim_opt opts[] = {
        {"out", 1, NULL, "DIR", "the output folder (default: out/NAME, NAME the scene file's name without .toml)"},
        {"t-end", 1, NULL, "T", "final time (default: the scene's run.t_end)"},
        {"output-step", 1, NULL, "H", "time between output rows (default: the scene's run.output_step)"},
        {"rtol", 1, NULL, "R", "relative tolerance (default: the scene's run.rtol, else 1e-8)"},
        {"atol", 1, NULL, "A", "absolute tolerance (default: the scene's run.atol, else 1e-10)"},
        {"integrator", 1, NULL, "NAME", swim_run_settings_integrator_help()},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated, e.g. model.rho0=2 or "
                                      "shape.c0.am1=0.3 (keys: models/README.md); recorded in DIR/scene.toml"},
        {"event", 2, NULL, "COLUMN:KIND[:stop]", "locate the times where a trajectory column (a header name of "
                                                 "trajectory.csv) has KIND zero, min or max, into DIR/events.csv; "
                                                 ":stop ends the run there; besides the scene's [events] list"},
        {"quiet", 0, NULL, NULL, "print nothing but errors (no progress, no report)"},
        {"generic", 0, NULL, NULL, "use the generic kernel of N modes, not one specialized to the scene's structure"},
        {"no-projection", 0, NULL, NULL, "do not put the state back on the constraints after each step (run.projection = false)"},
        {"trace-steps", 1, NULL, "FILE", "write every step attempt to FILE as CSV (t, h, order, accepted, error estimates, energy, work); abm only"},
        {"snapshots", 0, NULL, NULL, "also DIR/snapshots.json: the body's boundary and density at the output rows"},
        {"summary-only", 0, NULL, NULL, "write summary.json (and events) but no trajectory.csv"},
        {"sensitivity", 2, NULL, "KEY[,KEY...]", "also DIR/sensitivity.csv: d(x, y, theta, E, work and the full state)/d(KEY) "
                                                 "by the exact variational equations, for run-time keys (docs/control.md)"},
        {"sensitivity-initial", 0, NULL, NULL, "with or without --sensitivity: also the derivatives with respect to the "
                                               "initial shape and velocity of every free coordinate (c0.NAME, dc0.NAME)"},
        {"sensitivity-method", 1, NULL, "exact|differences", "with --sensitivity: the kernel's exact Jacobian and parameter "
                                                             "partials (exact, default), or central differences of the right-hand "
                                                             "side along each sensitivity (differences: the older method, for comparison)"},
        {"lyapunov", 0, NULL, NULL, "also DIR/lyapunov.csv: the largest Lyapunov exponent by the exact variational "
                                    "equations and, in summary.json, the predictability horizon at the run's rtol"},
        {"lyapunov-interval", 1, NULL, "T", "with --lyapunov: renormalize the tangent vector every T (> 0, default 1)"},
        {"sensitivity-steps", 1, NULL, "all|state", "with --sensitivity: the sensitivities riding on the state's steps, "
                                                    "outside the error test (state, default: trajectory.csv as without them), "
                                                    "or in the error test too (all: the steps, and the trajectory, change)"}};
    c->nopts = (int)(sizeof opts / sizeof opts[0]);
    memcpy(c->opts, opts, sizeof opts);
    swim_run_settings_key_options(c->opts, &c->nopts, (int)(sizeof c->opts / sizeof c->opts[0]));
    swim_run_job *j = &c->job;
    if (!(c->command = swim_shell_words(argc, (const char *const *)argv))) return 1;
    if ((j->nsets = swim_args_take_sets("run", &argc, argv, 2, c->sets, SWIM_JOB_MAX_SETS)) < 0) return 2;
    int trc = take_sensitivity_options(&argc, argv, &c->sensitivity);
    if (trc) return trc;
    j->nevents = swim_args_take_all("run", &argc, argv, 2, "event", c->events, SWIM_RUN_MAX_EVENTS + 1);
    if (j->nevents < 0) return 2;
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("run", argc, argv, 2, c->opts, c->nopts, pos, 1, &npos);
    if (prc) return prc;
    if (npos != 1) {
        swim_message(stderr, "swim run: expected one scene file, e.g. swim run models/example3.toml");
        return 2;
    }
    const char *v = swim_args_get(c->opts, c->nopts, "sensitivity-steps");
    if (v && strcmp(v, "all") != 0 && strcmp(v, "state") != 0) {
        swim_message(stderr, "swim run: --sensitivity-steps: expected all or state, got '%s'", v);
        return 2;
    }
    const char *m = swim_args_get(c->opts, c->nopts, "sensitivity-method");
    if (m && strcmp(m, "exact") != 0 && strcmp(m, "differences") != 0) {
        swim_message(stderr, "swim run: --sensitivity-method: expected exact or differences, got '%s'", m);
        return 2;
    }
    j->cmd = "run";
    j->scene_file = pos[0];
    j->sets = c->sets;
    j->adjust = adjust;
    j->adjust_ctx = c;
    j->out = swim_args_get(c->opts, c->nopts, "out");
    j->trace = swim_args_get(c->opts, c->nopts, "trace-steps");
    j->quiet = swim_args_get(c->opts, c->nopts, "quiet") != NULL;
    j->generic = swim_args_get(c->opts, c->nopts, "generic") != NULL;
    j->summary_only = swim_args_get(c->opts, c->nopts, "summary-only") != NULL;
    j->snapshots = swim_args_get(c->opts, c->nopts, "snapshots") != NULL;
    j->events = c->events;
    if (swim_args_get(c->opts, c->nopts, "sensitivity-initial")) {   /* the key list's word `initial` */
        char *joined = c->sensitivity ? swim_strprintf("%s,initial", c->sensitivity) : strdup("initial");
        free(c->sensitivity);
        if (!(c->sensitivity = joined)) {
            swim_message(stderr, "swim run: out of memory");
            return 1;
        }
    }
    j->sensitivity = c->sensitivity;
    j->sens_state_steps = !(v && strcmp(v, "all") == 0);
    j->sens_differences = m && strcmp(m, "differences") == 0;
    const char *li = swim_args_get(c->opts, c->nopts, "lyapunov-interval");
    if (li && !swim_args_get(c->opts, c->nopts, "lyapunov")) {
        swim_message(stderr, "swim run: --lyapunov-interval: only with --lyapunov");
        return 2;
    }
    if (swim_args_get(c->opts, c->nopts, "lyapunov")) {
        j->lyapunov = 1.0;
        /* the row count over t_end is checked once the scene is read (output/job.c) */
        if (swim_args_bounded("run", c->opts, c->nopts, "lyapunov-interval", &j->lyapunov)) return 2;
    }
    j->command = c->command;
    return 0;
}

/* ---- what the user sees while it runs ----------------------------------------------------- */

static void on_notice(void *ctx, const char *line)
{
    run_cmd *c = ctx;
    if (c->last_progress > c->t_start) {   /* after a progress line (\r, no newline): a line of its own */
        fputc('\n', stderr);
        c->last_progress = c->t_start;
    }
    swim_message(stderr, "%s", line);
}

static void on_progress(void *ctx, double t, double t_end)
{
    run_cmd *c = ctx;
    if (c->job.quiet) return;   /* called at every row: no clock read for nothing */
    const double now = swim_clock_seconds();
    if (now - c->last_progress > 1.0) {
        fprintf(stderr, "\rswim run: t = %.4g / %.4g (%.0f%%)   ", t, t_end, 100.0 * t / t_end);
        c->last_progress = now;
    }
}

static void on_lyapunov(void *ctx, const char *path, const swim_lyapunov *l)
{
    const run_cmd *c = ctx;
    if (c->job.quiet) return;
    if (l->verdict == SWIM_LYAP_CONVERGED)
        swim_message(stdout, "  largest Lyapunov exponent %.4g, converged (rates over the halves %.4g and %.4g agree "
                     "within %g%%) (%s); predictability horizon at rtol %.0e: t = %.4g; %.2f s", l->exponent,
                     l->rate_first, l->rate_second, 100 * SWIM_LYAPUNOV_AGREE, path, l->rtol, l->horizon, l->seconds);
    else if (l->verdict == SWIM_LYAP_REGULAR)
        swim_message(stdout, "  Lyapunov: regular motion, no exponential growth: the tangent vector grows like t^%.2g "
                     "(linear growth and its powers), the exponent tends to 0 (%.4g over t = %.4g, %.4g over the "
                     "second half) (%s); predictability horizon at rtol %.0e from that growth: t = %.3g; %.2f s",
                     l->power, l->exponent, l->t_end, l->rate_second, path, l->rtol,
                     isfinite(l->horizon) ? l->horizon : l->horizon_power, l->seconds);
    else
        swim_message(stdout, "  Lyapunov exponent not converged: %.4g over t = %.4g, rates over the halves %.4g and "
                     "%.4g (%s); run to --t-end %.3g or more; %.2f s", l->exponent, l->t_end, l->rate_first,
                     l->rate_second, path, l->t_end_needed, l->seconds);
}

static void on_sensitivities(void *ctx, int nkeys, const char *path, double t, double seconds, long evals)
{
    const run_cmd *c = ctx;
    if (!c->job.quiet)
        swim_message(stdout, "  sensitivities of %d key(s) in %s up to t = %.6g: %.3f s, %ld evaluations of the augmented RHS",
                     nkeys, path, t, seconds, evals);
}

/* ---- report ------------------------------------------------------------------------------- */

static void report_stroke(const swim_run_settings *set, const swim_run_result *r)
{
    const swim_stroke_report *k = &r->stroke;
    printf("  prescribed stroke: %d laws%s; (3.21) integrated with %s, rtol %.3g: %ld RHS evaluations\n", k->laws,
           k->completed_c1 ? ", c1 completed from the volume (2.5) and (2.14)" : "", set->integrator, set->rtol, k->rhs_calls);
    if (k->period > 0)
        printf("  period %.10g (%s), %ld strokes; per stroke: first displacement (%.6g, %.6g), dtheta %.6g, "
               "positive work %.6g\n", k->period, k->period_source, k->strokes, k->first_dx, k->first_dy,
               k->first_dtheta, k->first_work_positive);
    else
        printf("  no period: the laws do not repeat within t_end (set [stroke] period to report strokes)\n");
    printf("  work %.6g, positive work %.6g, energy check |E - E0 - work| <= %.3g; min J %.4g\n", k->work,
           k->work_positive, r->drift_abs, r->jmin);
}

static void report_dynamics(run_cmd *c, swim_job *job, const swim_run_result *r)
{
    const swim_run_settings *set = swim_job_settings(job);
    const swim_dynamics *d = swim_job_dynamics(job);
    const swim_ode_stats *st = &r->stats;
    printf("  %s kernel (state dimension %d)\n", d->generic ? "generic" : "specialized", swim_dynamics_state_dim(d));
    swim_message(stdout, "  integrator %s, rtol %.3g: %ld steps, %ld RHS evaluations, %ld rejected; %.3f s (%.3f s in the RHS)",
                 r->used, set->rtol, st->steps, st->rhs_evals, st->rejected, swim_clock_seconds() - c->t_start, swim_dynamics_rhs_seconds(d));
    printf("  energy drift %.3g (E0 = %.6g), max residuals: volume %.2g, angular %.2g, locks %.2g; min J %.4g at t = %.6g\n",
           r->drift_abs, r->e0, r->res_volume, r->res_angular, r->res_locks, r->jmin, r->jmin_t);
    if (r->impacts)   /* min J above is over the computed steps, not the turning points of the impacts */
        printf("  %ld bounce(s) taken as impacts from t = %.6g to %.6g, turning points predicted down to min J ~ %.1e\n",
               r->impacts, r->impact_first_t, r->impact_last_t, r->impact_reach_min);
}

/* The lines printed. The exit status: 0 only when the run reached t_end and every output,
 * the summary and this report were written. */
/* A notice of the layers below (a projected initial velocity) as the run's own notices. */
static void on_status_note(void *ctx, const char *line) { on_notice(ctx, line); }

static int report(run_cmd *c, swim_job *job, int status)
{
    const swim_run_paths *p = swim_job_paths(job);
    const swim_run_result *r = swim_job_result(job);
    const char *oerr = swim_job_output_error(job);
    if (oerr) swim_message(stderr, "swim run: %s", oerr);   /* the reason names another cause */
    const swim_scene *s = swim_job_scene(job);
    if (c->job.quiet) {   /* nothing but errors: a failed run is one line on stderr */
        if (status)
            swim_message(stderr, "swim run: %s: FAILED (%s); %ld rows in %s", s->path,
                         r->reason ? r->reason : "out of memory", r->rows, c->job.summary_only ? p->summary_path : p->csv_path);
        return status ? 1 : 0;
    }
    swim_message(stdout, c->job.summary_only ? "%s: %s (%s); %ld rows computed, summary in %s" : "%s: %s (%s); %ld rows in %s",
                 s->path, status ? "FAILED" : "completed", r->reason ? r->reason : "out of memory", r->rows,
                 c->job.summary_only ? p->summary_path : p->csv_path);
    if (r->is_stroke) report_stroke(swim_job_settings(job), r);
    else report_dynamics(c, job, r);
    printf("  final position x = %.6g, y = %.6g, theta = %.6g\n", r->final_state[0], r->final_state[1], r->final_state[2]);
    if (swim_stdout_check("run") != 0) return 1;
    return status ? 1 : 0;
}

int swim_cmd_run(int argc, char **argv)
{
    run_cmd *c = calloc(1, sizeof *c);
    if (!c) {
        swim_message(stderr, "swim run: out of memory");
        return 1;
    }
    swim_run_stop = 0;
    c->status.note = on_status_note;
    c->status.note_ctx = c;
    int rc = read_options(argc, argv, c);
    swim_job *job = NULL;
    if (rc == 0) {
        c->job.stop = &swim_run_stop;
        c->job.notice = on_notice;
        c->job.progress = on_progress;
        c->job.sens_done = on_sensitivities;
        c->job.lyapunov_done = on_lyapunov;
        c->job.ctx = c;
        rc = swim_job_open(&c->job, &job, &c->status);
        swim_status_print(&c->status, stderr);
    }
    if (rc == 0) {
        swim_run_signals sig;
        swim_run_signals_install(&sig);
        c->last_progress = c->t_start = swim_clock_seconds();
        swim_status_clear(&c->status);
        const int status = swim_job_run(job, &c->status);
        if (!c->job.quiet && c->last_progress > c->t_start) fputc('\n', stderr);
        swim_status_print(&c->status, stderr);
        rc = report(c, job, status);
        swim_run_signals_restore(&sig);
    }
    swim_job_free(job);
    free(c->sensitivity);
    free(c->command);
    free(c);
    return rc;
}
