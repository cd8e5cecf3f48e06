#include "output/job.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen/codegen.h"
#include "driver/analyses.h"
#include "driver/events.h"
#include "driver/summary.h"
#include "io/clock.h"
#include "io/csv.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"
#include "problem/problem.h"
#include "scene/resolve.h"

struct swim_job {
    swim_run_job req;
    swim_scene s;                /* the problem's scene (P.s) */
    swim_problem P;              /* the scene with the overrides, its kernels and dynamics */
    int stroke;                  /* the scene has a [stroke] table */
    swim_override recorded[2 * SWIM_JOB_MAX_SETS];   /* DIR/scene.toml: the overrides and the adjustments */
    int nrecorded;
    char *resolved;              /* the scene with them written in (NULL without any) */
    swim_run_events *events;
    swim_folder *folder;
    swim_run *run;
    const char *sens_status, *sens_method;
    double sens_t, sens_t_last;
    long sens_jacobians, sens_rhs;
    double sens_seconds;
    long sens_rows;
    swim_lyapunov lyap;
    const char *lyap_status;     /* written, failed, skipped (NULL: not asked for) */
    /* the variational equations on the run's own steps: the --sensitivity keys, then the
     * Lyapunov tangent vector (one more column) */
    swim_analyses an;
    int an_ready;
    char *sens_path;
    swim_csv sens_csv;
    int sens_csv_open;
    int summary_failed;
};

/* ---- before the run ------------------------------------------------------------------------ */

/* Options that mean something for free dynamics only are refused on a prescribed stroke. */
static int refuse_for_stroke(const swim_job *j, swim_status *st)
{
    const swim_run_job *r = &j->req;
    char who[64];
    snprintf(who, sizeof who, "swim %s", r->cmd);
    if (r->sensitivity || r->lyapunov > 0) {
        /* the variational equations are those of the free shape dynamics; a prescribed stroke has
         * none (its shape is a given function of time) */
        swim_status_fail(st, who, NULL, 0, NULL, "--%s: not available on a prescribed stroke ([stroke] in %s): "
                         "the variational equations are those of free shape dynamics only",
                         r->sensitivity ? "sensitivity" : "lyapunov", r->scene_file);
        return 2;
    }
    const char *opt = r->generic ? "generic" : r->trace ? "trace-steps" : NULL;
    if (opt) {
        swim_status_fail(st, who, NULL, 0, NULL, "--%s: does not apply to a prescribed stroke (%s has [stroke]: "
                         "only (3.21) is integrated)", opt, r->scene_file);
        return 2;
    }
    return 0;
}

/* The scene read with the overrides, adjusted, its events checked; the text for DIR/scene.toml. */
static int read_scene(swim_job *j, swim_status *st)
{
    const swim_run_job *r = &j->req;
    swim_scene *s = &j->s;
    char who[64];
    snprintf(who, sizeof who, "swim %s", r->cmd);
    const swim_problem_source src = {.path = r->scene_file, .sets = r->sets, .nsets = r->nsets, .into = s};
    if (swim_problem_read(&j->P, &src, st)) return 2;
    char *name = r->scene_name ? strdup(r->scene_name) : NULL;
    if (r->scene_name && !name) {
        swim_status_fail(st, who, NULL, 0, NULL, "out of memory");
        return 2;
    }
    if (name) {
        free(s->path);
        s->path = name;
    }
    j->stroke = s->stroke_count > 0;
    int nadj = 0;
    swim_override adjusted[SWIM_JOB_MAX_SETS];
    if (r->adjust && r->adjust(s, adjusted, &nadj, r->adjust_ctx, st) != 0) return 2;
    if (j->stroke && refuse_for_stroke(j, st)) return 2;
    if (r->lyapunov > 0 && !(s->run.t_end / r->lyapunov <= SWIM_LYAPUNOV_MAX_SEGMENTS)) {
        swim_status_fail(st, who, NULL, 0, NULL, "--lyapunov-interval: %g gives %.3g renormalizations over t_end = %g, "
                         "more than %d (the rows of lyapunov.csv); give an interval >= %.3g", r->lyapunov,
                         s->run.t_end / r->lyapunov, s->run.t_end, SWIM_LYAPUNOV_MAX_SEGMENTS,
                         s->run.t_end / SWIM_LYAPUNOV_MAX_SEGMENTS);
        return 2;
    }
    if (r->trace && !(swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_STEP_TRACE)) {
        swim_status_fail(st, who, NULL, 0, NULL, "--trace-steps: integrator '%s' does not report its steps", s->run.integrator);
        return 2;
    }
    /* events name columns of trajectory.csv: checked against them, before any output */
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24];
    const int ncol = swim_run_columns(s, names, storage);
    const int erc = swim_run_events_parse(s, r->events, r->nevents, names, ncol, &j->events, st);
    if (erc) return erc;
    /* the record of the run: the overrides, except those an adjustment sets again, then those */
    for (int i = 0; i < r->nsets; i++) {
        int again = 0;
        for (int k = 0; k < nadj; k++) again |= swim_override_same_target(&r->sets[i], &adjusted[k]);
        if (!again) j->recorded[j->nrecorded++] = r->sets[i];
    }
    for (int k = 0; k < nadj; k++) j->recorded[j->nrecorded++] = adjusted[k];
    if (j->nrecorded == 0) return 0;
    size_t outlen = 0;
    char why[512];
    const int rc = swim_scene_resolve(j->P.text, j->P.len, r->scene_name ? r->scene_name : r->scene_file, j->recorded,
                                      j->nrecorded, &j->resolved, &outlen, why, sizeof why);
    if (rc != 0) {
        swim_status_fail(st, who, r->scene_file, 0, NULL, "%s: cannot write the overrides into the output's scene.toml: %s",
                         r->scene_file, why);
        return 2;
    }
    return 0;
}

static int acquire_kernels(swim_job *j, swim_status *st)
{
    return swim_problem_kernels(&j->P, j->req.cmd, j->req.generic, j->req.quiet ? 0 : 1, st);
}

/* --sensitivity: the keys resolved on the problem's dynamics, before any output (exit 2). */
static int check_sensitivity(swim_job *j, swim_status *st)
{
    swim_sens S;
    int rc = swim_sens_init(&S, &j->P.d) != 0 ? 1 : swim_sens_add_list(&S, &j->s, j->req.cmd, j->req.sensitivity, st);
    swim_sens_free(&S);
    return rc;
}

/* What --sensitivity and --lyapunov ask of the run (driver/analyses.h). */
static swim_analyses_request analyses_request(swim_job *j);

/* The integrator carries them on the run's steps as asked, or the run is refused before any
 * output (exit 2). */
static int check_variational(swim_job *j, swim_status *st)
{
    char who[64];
    snprintf(who, sizeof who, "swim %s", j->req.cmd);
    const swim_analyses_request ar = analyses_request(j);
    return ar.keys || ar.lyapunov > 0 ? swim_analyses_check(j->s.run.integrator, &ar, who, st) : 0;
}

static swim_folder_request folder_request(const swim_job *j, const char **names, char storage[][24])
{
    const int ncol = swim_run_columns(&j->s, names, storage);
    return (swim_folder_request){j->req.cmd, j->req.out, j->req.scene_file, j->s.path, j->resolved, j->req.trace,
                                 j->req.summary_only, j->req.snapshots && !j->req.summary_only, names, ncol};
}

static int preflight(const swim_job *j, swim_status *st)
{
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24], err[2 * 4096 + 256];
    const swim_folder_request fr = folder_request(j, names, storage);
    const int rc = swim_folder_preflight(&fr, err, sizeof err);
    if (rc) swim_status_fail(st, NULL, NULL, 0, NULL, "%s", err);
    return rc;
}

/* The rows to the folder, the rest to the caller's callbacks. */
static int sink_row(void *ctx, const swim_run_row *row, char *why, size_t len)
{
    swim_job *j = ctx;
    const swim_run_sink f = swim_folder_sink(j->folder);
    return f.row(f.ctx, row, why, len);
}

static void sink_step(void *ctx, const swim_ode_step *st, swim_dynamics *d)
{
    swim_job *j = ctx;
    const swim_run_sink f = swim_folder_sink(j->folder);
    if (f.step) f.step(f.ctx, st, d);
}

static void sink_notice(void *ctx, const char *line)
{
    const swim_job *j = ctx;
    if (j->req.notice) j->req.notice(j->req.ctx, line);
}

static void sink_progress(void *ctx, double t, double t_end)
{
    const swim_job *j = ctx;
    if (j->req.progress) j->req.progress(j->req.ctx, t, t_end);
}

/* The run (whose opening checks a stroke on its whole interval), then the folder. */
static int open_run(swim_job *j, swim_status *st)
{
    if (!j->req.quiet && j->P.spz.from_cache && !j->stroke && j->req.notice) {
        char *line = swim_strprintf("swim: scene kernel from cache %s", j->P.spz.dir);
        if (line) j->req.notice(j->req.ctx, line);
        free(line);
    }
    const swim_run_request rr = {&j->s, &j->P.kn, &j->P.spz, j->req.generic, j->events, j->req.stop,
                                 {sink_row, j->req.trace ? sink_step : NULL, sink_notice, sink_progress, j}, 0};
    int rc = swim_run_open(&rr, &j->run, st);
    if (rc) return rc;
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24], ferr[2 * 4096 + 256];
    const swim_folder_request fr = folder_request(j, names, storage);
    rc = swim_folder_open(&fr, &j->folder, ferr, sizeof ferr);
    if (rc) swim_status_fail(st, NULL, NULL, 0, NULL, "%s", ferr);
    return rc;
}

static int attach_variational(swim_job *j, swim_status *st);

int swim_job_open(const swim_run_job *req, swim_job **out, swim_status *st)
{
    *out = NULL;
    swim_job *j = calloc(1, sizeof *j);
    if (!j) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "swim %s: out of memory", req->cmd);
        return 1;
    }
    j->req = *req;
    int rc = read_scene(j, st);
    if (rc == 0) rc = preflight(j, st);
    if (rc == 0) rc = acquire_kernels(j, st);
    if (rc == 0 && req->sensitivity) rc = check_sensitivity(j, st);
    if (rc == 0 && !j->stroke) rc = check_variational(j, st);
    if (rc == 0) rc = open_run(j, st);
    if (rc == 0) rc = attach_variational(j, st);
    if (rc) {
        swim_job_free(j);
        return rc;
    }
    *out = j;
    return 0;
}

/* ---- the run ------------------------------------------------------------------------------- */

/* sensitivity.csv: the header, then a row at each row of the run (swim_analyses_sink). */
static int sens_csv_row(void *ctx, const char *const *names, int ncol, const double *row, char *why, size_t len)
{
    swim_job *j = ctx;
    if (!row) {
        if (swim_csv_open(&j->sens_csv, j->sens_path, names, ncol) == 0) {
            j->sens_csv_open = 1;
            return 0;
        }
        snprintf(why, len, "%s: cannot write: %s", j->sens_path, strerror(errno));
        return 1;
    }
    if (swim_csv_row(&j->sens_csv, row) == 0) return 0;
    snprintf(why, len, "%s: write failed at t = %.6g: %s", j->sens_path, row[0], strerror(errno));
    return 1;
}

static swim_analyses_request analyses_request(swim_job *j)
{
    const swim_run_job *r = &j->req;
    return (swim_analyses_request){r->sensitivity, r->sens_differences, !r->sens_state_steps,
                                   r->lyapunov > 0 ? r->lyapunov : 0.0, sens_csv_row, j};
}

/* --sensitivity and --lyapunov: the state's variational equations ride on the run's own
 * integration (driver/analyses.h); sensitivity.csv gets a row at each row of the trajectory.
 * The keys were checked before any output (check_sensitivity). */
static int attach_variational(swim_job *j, swim_status *st)
{
    const swim_analyses_request ar = analyses_request(j);
    if (j->stroke || (!ar.keys && !(ar.lyapunov > 0))) return 0;
    if (ar.keys && !(j->sens_path = swim_strprintf("%s/sensitivity.csv", swim_folder_paths(j->folder)->dir))) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "swim %s: out of memory", j->req.cmd);
        return 1;
    }
    j->an_ready = 1;
    const int rc = swim_analyses_attach(&j->an, j->run, &j->s, j->req.cmd, &ar, st);
    if (rc == 0 && ar.keys) j->sens_method = swim_sens_exact(&j->an.S) ? "exact" : "differences";
    return rc;
}

/* DIR/sensitivity.csv, written row by row with the trajectory, closed: its outcome. A run that did
 * not complete keeps the rows up to where it stopped; sensitivities that stopped before the run
 * did (an impact, a stiff fallback that cannot carry them) fail the run, so that the summary and
 * the exit status say so. */
static void finish_sensitivity(swim_job *j, swim_status *st)
{
    const swim_run_result *r = swim_run_get_result(j->run);
    const swim_run_var_result *v = swim_run_get_var_result(j->run);
    char why[512];
    if (j->sens_csv_open && swim_csv_close(&j->sens_csv) != 0 && r->status == 0) {
        snprintf(why, sizeof why, "%s: cannot write: %s", j->sens_path, strerror(errno));
        swim_run_fail(j->run, why);
    }
    j->sens_csv_open = 0;
    j->sens_jacobians = j->an.S.jac_calls;
    j->sens_rhs = r->stats.rhs_evals + j->an.S.rhs_calls;   /* the run's evaluations carry the columns */
    j->sens_seconds = j->an.row_seconds + swim_run_dynamics(j->run)->jac_seconds;
    j->sens_rows = j->an.rows;
    j->sens_t_last = j->an.rows > 0 ? j->an.t_last : NAN;
    j->sens_t = r->status == 0 ? r->t_reached : j->s.run.t_end;
    const int sig = j->req.stop ? *j->req.stop : 0;
    if (r->impacts) {   /* the variational equations would need the impact's jump (a saltation matrix) */
        j->sens_status = "failed";
        if (j->sens_path) remove(j->sens_path);
        j->sens_rows = 0;
        snprintf(why, sizeof why, "no sensitivity.csv: the run took %ld bounce(s) off the barrier as impacts, "
                 "across which sensitivities are not computed; set run.impact_depth = 0 to follow them", r->impacts);
        swim_run_fail(j->run, why);
    } else if (sig) {   /* the run says how it was stopped; the rows up to there are kept */
        j->sens_status = "interrupted";
    } else if (r->status != 0) {
        j->sens_status = "failed";
        swim_status_note(st, "swim %s: sensitivity.csv holds the rows up to t = %.6g: the run did not complete",
                         j->req.cmd, j->sens_rows > 0 ? j->sens_t_last : 0.0);
    } else if (!v->carried) {
        j->sens_status = "failed";
        snprintf(why, sizeof why, "sensitivity.csv is incomplete: the sensitivities stopped at t = %.6g: %s",
                 v->t_stop, v->reason);
        swim_run_fail(j->run, why);
    } else {
        j->sens_status = "written";
        if (j->req.sens_done)
            j->req.sens_done(j->req.ctx, j->an.nsens, j->sens_path, j->sens_t, j->sens_seconds, j->sens_rhs);
    }
}

/* DIR/lyapunov.csv: t, ln growth of the interval, running exponent. 0, or -1 (errno). */
static int lyapunov_csv(const swim_lyapunov *l, const char *path)
{
    static const char *const names[] = {"t", "log_growth", "exponent"};
    swim_csv csv = {0};
    if (swim_csv_open(&csv, path, names, 3) != 0) return -1;
    double sum = 0.0;
    int rc = 0;
    for (int k = 0; k < l->n && rc == 0; k++) {
        sum += l->log_growth[k];
        const double row[3] = {l->t[k], l->log_growth[k], sum / l->t[k]};
        rc = swim_csv_row(&csv, row);
    }
    if (swim_csv_close(&csv) != 0) rc = -1;
    return rc;
}

/* DIR/lyapunov.csv after the run: the largest Lyapunov exponent over [0, t_reached] and the
 * predictability horizon at the run's rtol (model/lyapunov.h) from the growth of the tangent
 * vector the run carried. One that fails is said in the summary; it does not fail the run. A run
 * that stopped (a signal, a failure) keeps the intervals up to its last row. */
static void finish_lyapunov(swim_job *j, swim_status *st)
{
    const swim_run_result *r = swim_run_get_result(j->run);
    if (r->impacts || !(r->t_reached > 0)) {
        j->lyap_status = "skipped";
        swim_status_note(st, "swim %s: no lyapunov.csv: %s", j->req.cmd,
                         r->impacts ? "the run took impacts, across which the variational equations do not hold"
                                    : "the run has no time span");
        return;
    }
    char *path = swim_strprintf("%s/lyapunov.csv", swim_folder_paths(j->folder)->dir);
    const int rc = path ? swim_analyses_lyapunov(&j->an, j->run, j->req.lyapunov, j->s.run.rtol, &j->lyap) : -1;
    const int sig = j->req.stop ? *j->req.stop : 0;
    if (rc == 0 && r->status != 0 && j->lyap.status == 0) {
        j->lyap.status = 1;
        snprintf(j->lyap.reason, sizeof j->lyap.reason, "%s: lyapunov.csv holds its %d intervals up to t = %.6g",
                 sig ? "the run was stopped" : "the run did not complete", j->lyap.n, j->lyap.t_end);
    }
    if (rc != 0) {
        j->lyap_status = "failed";
        snprintf(j->lyap.reason, sizeof j->lyap.reason, "out of memory");
    } else if (lyapunov_csv(&j->lyap, path) != 0) {
        j->lyap_status = "failed";
        snprintf(j->lyap.reason, sizeof j->lyap.reason, "cannot write lyapunov.csv: %s", strerror(errno));
    } else {
        j->lyap_status = j->lyap.status == 0 ? "written" : sig ? "interrupted" : "failed";
        if (j->lyap.status == 0 && j->req.lyapunov_done) j->req.lyapunov_done(j->req.ctx, path, &j->lyap);
    }
    if (j->lyap.status != 0 || rc != 0) swim_status_note(st, "swim %s: lyapunov.csv: %s", j->req.cmd, j->lyap.reason);
    free(path);
}

/* The "lyapunov" entry of summary.json (after the run's own fields). 0, or -1 when out of memory. */
static int lyapunov_json(json_t *summary, const void *ctx)
{
    const swim_job *j = ctx;
    if (!j->lyap_status) return 0;
    const swim_lyapunov *l = &j->lyap;
    json_t *o = json_object();
    if (!o) return -1;
    char *verdict_note = swim_strprintf(
        "sum ln r_k fitted by a line in t over each half (rate_first_half, "
        "rate_second_half) and by a line in ln t over the second half (growth_power p: |w| ~ t^p); "
        "converged: the rates agree within agreement_tolerance (relative), the second half grows by at "
        "least %g e-folds and there are at least %d intervals: the exponent is a result; regular: else "
        "p <= %g, the growth is a power of t, not exponential (regular motion), the exponent tends to 0 "
        "and horizon_from_power extrapolates t^p to ln(separation / rtol); not_converged: neither, run "
        "to t_end_needed", SWIM_LYAPUNOV_EFOLDS, SWIM_LYAPUNOV_MIN_SEGMENTS, SWIM_LYAPUNOV_POWER);
    char *horizon_note = swim_strprintf(
        "a run at this rtol follows the exact trajectory to a relative separation of "
        "%g until the growth of a perturbation (the sum of log_growth) reaches ln(separation / rtol); beyond "
        "it only quantities that do not depend on the particular trajectory (energy balance, time averages, "
        "statistics over a family) are results; null: not within the run", SWIM_LYAPUNOV_SEPARATION);
    int bad = !verdict_note || !horizon_note;
    bad |= swim_json_set(o, "status", swim_json_str(j->lyap_status));
    bad |= swim_json_set(o, "exponent", swim_json_num(l->n > 0 ? l->exponent : NAN));
    bad |= swim_json_set(o, "exponent_second_half", swim_json_num(l->n > 0 ? l->exponent_half : NAN));
    bad |= swim_json_set(o, "verdict", swim_json_str(swim_lyapunov_verdict_name(l->verdict)));
    bad |= swim_json_set(o, "rate_first_half", swim_json_num(l->rate_first));
    bad |= swim_json_set(o, "rate_second_half", swim_json_num(l->rate_second));
    bad |= swim_json_set(o, "agreement_tolerance", swim_json_num(SWIM_LYAPUNOV_AGREE));
    bad |= swim_json_set(o, "growth_power", swim_json_num(l->power));
    bad |= swim_json_set(o, "horizon_from_power", swim_json_num(l->horizon_power));
    bad |= swim_json_set(o, "t_end_needed", swim_json_num(l->t_end_needed));
    bad |= swim_json_set(o, "verdict_note", swim_json_str(verdict_note));
    bad |= swim_json_set(o, "interval", swim_json_num(l->interval));
    bad |= swim_json_set(o, "t_end", swim_json_num(l->t_end));
    bad |= swim_json_set(o, "rtol", swim_json_num(l->rtol));
    bad |= swim_json_set(o, "separation", swim_json_num(SWIM_LYAPUNOV_SEPARATION));
    bad |= swim_json_set(o, "horizon", swim_json_num(l->n > 0 && isfinite(l->horizon) ? l->horizon : NAN));
    bad |= swim_json_set(o, "horizon_from_exponent",
                         swim_json_num(l->n > 0 && isfinite(l->horizon_mean) ? l->horizon_mean : NAN));
    bad |= swim_json_set(o, "horizon_note", swim_json_str(horizon_note));
    if (l->reason[0]) bad |= swim_json_set(o, "reason", swim_json_str(l->reason));
    bad |= swim_json_set(o, "rhs_evaluations", json_integer(l->rhs_calls));
    bad |= swim_json_set(o, "seconds", swim_json_num(l->seconds));
    bad |= swim_json_set(o, "file", swim_json_str("lyapunov.csv"));
    free(verdict_note);
    free(horizon_note);
    bad |= swim_json_set(summary, "lyapunov", o);
    return bad ? -1 : 0;
}

static json_t *summary(const swim_job *j)
{
    const swim_summary_context x = {swim_folder_paths(j->folder)->dir, j->req.command,
                                    j->req.scene_name ? j->req.scene_name : j->req.scene_file,
                                    j->recorded, j->nrecorded, j->req.sensitivity != NULL, j->sens_status,
                                    j->sens_t, j->sens_rows, j->sens_t_last, j->sens_method,
                                    j->sens_jacobians, j->sens_rhs, j->sens_seconds, lyapunov_json, j};
    return swim_run_summary(j->run, &x);
}

static void write_json(FILE *f, void *ctx) { swim_json_write(f, ctx); }

int swim_job_run(swim_job *j, swim_status *st)
{
    swim_run_integrate(j->run);
    if (swim_folder_finish(j->folder, j->events) != 0) swim_run_fail(j->run, swim_folder_error(j->folder));
    if (j->req.sensitivity && !j->stroke) finish_sensitivity(j, st);
    if (j->req.lyapunov > 0 && !j->stroke) finish_lyapunov(j, st);
    const swim_run_result *r = swim_run_get_result(j->run);
    json_t *sum = summary(j);
    if (!sum) errno = ENOMEM;   /* nothing written */
    if (!sum || swim_folder_write_summary(j->folder, write_json, sum) != 0) {
        char who[64];
        snprintf(who, sizeof who, "swim %s", j->req.cmd);
        swim_status_fail(st, who, NULL, 0, NULL, "cannot write %s: %s (the run %s: %s)",
                         swim_folder_paths(j->folder)->summary_path, strerror(errno), r->status ? "FAILED" : "completed",
                         r->reason ? r->reason : "out of memory");
        j->summary_failed = 1;
    }
    json_decref(sum);
    return r->status || j->summary_failed ? 1 : 0;
}

/* ---- what it found ------------------------------------------------------------------------- */

const swim_scene *swim_job_scene(const swim_job *j) { return &j->s; }
const swim_run_result *swim_job_result(const swim_job *j) { return swim_run_get_result(j->run); }
const swim_run_paths *swim_job_paths(const swim_job *j) { return swim_folder_paths(j->folder); }
swim_dynamics *swim_job_dynamics(swim_job *j) { return swim_run_dynamics(j->run); }
int swim_job_summary_failed(const swim_job *j) { return j->summary_failed; }

const char *swim_job_output_error(const swim_job *j)
{
    const char *e = swim_folder_error(j->folder), *reason = swim_job_result(j)->reason;
    return e && !(reason && strstr(reason, e)) ? e : NULL;
}

void swim_job_free(swim_job *j)
{
    if (!j) return;
    if (j->sens_csv_open) swim_csv_close(&j->sens_csv);
    free(j->sens_path);
    if (j->an_ready) swim_analyses_free(&j->an);
    swim_run_free(j->run);
    swim_folder_free(j->folder);
    swim_run_events_free(j->events);
    free(j->resolved);
    swim_lyapunov_free(&j->lyap);
    swim_problem_close(&j->P);   /* after everything that may still point into the kernels */
    free(j);
}

int swim_job_execute(const swim_run_job *req, swim_status *st)
{
    swim_job *j;
    int rc = swim_job_open(req, &j, st);
    if (rc) return rc;
    rc = swim_job_run(j, st);
    swim_job_free(j);
    return rc;
}
