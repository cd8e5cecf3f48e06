#include "control/optimize.h"

#include <errno.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multimin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "driver/run.h"
#include "io/files.h"
#include "io/message.h"
#include "ode/ode.h"
#include "scene/resolve.h"

/* What the minimizer sees for a run that failed or values that were refused: worse than any
 * finite quantity it will meet, finite (nmsimplex2 refuses non-finite values). */
#define FAILED_PENALTY 1e30

static const char *const quantity_names[SWIM_Q_COUNT] = {
    "x", "y", "theta", "displacement", "work", "forcing_work", "displacement_per_work", "energy"};

int swim_quantity_index(const char *name)
{
    for (int i = 0; i < SWIM_Q_COUNT; i++)
        if (strcmp(name, quantity_names[i]) == 0) return i;
    return -1;
}

const char *swim_quantity_name(int index)
{
    return index >= 0 && index < SWIM_Q_COUNT ? quantity_names[index] : "?";
}

const char *swim_quantity_list(void)
{
    return "x, y, theta, displacement, work, forcing_work, displacement_per_work, energy";
}

/* ---- one evaluation -------------------------------------------------------------------------- */

/* One run of the scene with the overrides ov, by the run driver (driver/run.h) exactly as swim run
 * makes it (same settings, restarts near the barrier, energy control, rows), so that `swim run` of
 * best.toml gives the value reported to the last bit; no rows are kept. Fills r. */
static void integrate(const swim_opt_problem *p, const swim_override *ov, int nov, swim_eval_result *r)
{
    swim_scene s;
    swim_compiled kn, sys;
    memset(&kn, 0, sizeof kn);
    memset(&sys, 0, sizeof sys);
    swim_run *run = NULL;
    r->status = 1;
    if (swim_scene_load_with(p->scene_path, ov, nov, &s) != 0) {
        r->status = 2;
        snprintf(r->reason, sizeof r->reason, "values refused by the scene checks");
        return;
    }
    int rc = swim_codegen_for_scene("optimize", &s, 0, 0, &kn, &sys);
    if (rc) {
        r->status = rc == 2 ? 2 : 1;
        snprintf(r->reason, sizeof r->reason, rc == 2 ? "values refused by the scene checks" : "no kernel");
        goto done;
    }
    const swim_run_request req = {&s, &kn, &sys, 0, NULL, (volatile sig_atomic_t *)p->interrupt, {NULL, NULL, NULL, NULL, NULL}};
    char err[512] = "";
    rc = swim_run_open(&req, &run, err, sizeof err);
    if (rc) {
        r->status = rc == 2 ? 2 : 1;
        snprintf(r->reason, sizeof r->reason, "%s", rc == 2 ? "stroke not allowable" : "out of memory");
        goto done;
    }
    const swim_run_result *res = (swim_run_integrate(run), swim_run_get_result(run));
    if (res->status != 0) {
        snprintf(r->reason, sizeof r->reason, "%s", res->reason ? res->reason : "out of memory");
        goto done;
    }
    r->x = res->final_state[0];
    r->y = res->final_state[1];
    r->theta = res->final_state[2];
    r->energy = res->energy;
    /* a stroke's work is what the body spends on it, the positive work int max(P, 0) dt */
    r->work = res->is_stroke ? res->forcing_work : res->work;
    r->forcing_work = res->forcing_work;
    r->status = 0;
done:
    swim_run_free(run);
    swim_compiled_close(&sys);
    swim_compiled_close(&kn);
    swim_scene_free(&s);
}

static int all_overrides(const swim_opt_problem *p, const double *v, swim_override *ov)
{
    int k = 0;
    for (int i = 0; i < p->nsets; i++) ov[k++] = p->sets[i];
    for (int i = 0; i < p->nkeys; i++) {
        ov[k] = p->keys[i];
        ov[k].value = v[i];
        k++;
    }
    return k;
}

int swim_opt_evaluate(swim_opt_problem *p, const double *v, swim_eval_result *r)
{
    memset(r, 0, sizeof *r);
    swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, v, ov);
    /* a refused value (outside D, a bound of the run settings) is one line on stderr from the
     * scene reader: keep it off the terminal, the log row says "refused" */
    fflush(stderr);
    int fd = dup(fileno(stderr));
    if (fd >= 0 && !freopen("/dev/null", "w", stderr)) {
        close(fd);
        fd = -1;
    }
    integrate(p, ov, nov, r);
    fflush(stderr);
    if (fd >= 0) {
        dup2(fd, fileno(stderr));
        close(fd);
        clearerr(stderr);
    }
    p->evaluations++;
    if (r->status) p->failed++;
    return r->status;
}

double swim_opt_quantity(const swim_opt_problem *p, const swim_eval_result *r)
{
    const double disp = hypot(r->x, r->y);
    switch (p->quantity) {
    case SWIM_Q_X: return r->x;
    case SWIM_Q_Y: return r->y;
    case SWIM_Q_THETA: return r->theta;
    case SWIM_Q_DISPLACEMENT: return disp;
    case SWIM_Q_WORK: return r->work;
    case SWIM_Q_FORCING_WORK: return r->forcing_work;
    case SWIM_Q_DISPLACEMENT_PER_WORK: return disp / r->forcing_work;
    case SWIM_Q_ENERGY: return r->energy;
    }
    return NAN;
}

/* ---- the search ------------------------------------------------------------------------------ */

static double value_of(const swim_opt_problem *p, int i, double u)
{
    return p->lo[i] + (p->hi[i] - p->lo[i]) * 0.5 * (1.0 + sin(u));
}

static double objective(const gsl_vector *u, void *params)
{
    swim_opt_problem *p = params;
    double v[SWIM_OPT_MAX_KEYS];
    for (int i = 0; i < p->nkeys; i++) v[i] = value_of(p, i, gsl_vector_get(u, i));
    swim_eval_result r;
    if (p->interrupt && *p->interrupt) return FAILED_PENALTY;   /* no more runs */
    if (swim_opt_evaluate(p, v, &r) != 0) return FAILED_PENALTY;
    const double q = swim_opt_quantity(p, &r);
    if (!isfinite(q)) return FAILED_PENALTY;
    if (p->evaluations == 1 || p->best.status != 0 || (p->maximize ? q > p->best_q : q < p->best_q)) {
        p->best_q = q;
        p->best = r;
        memcpy(p->best_value, v, sizeof(double) * p->nkeys);
    }
    return p->maximize ? -q : q;
}

static void log_iteration(swim_opt_problem *p, int iter, double size)
{
    if (p->log_csv) {
        fprintf(p->log_csv, "%d,%ld", iter, p->evaluations);
        for (int i = 0; i < p->nkeys; i++) fprintf(p->log_csv, ",%.17g", p->best_value[i]);
        fprintf(p->log_csv, ",%.17g,%.17g\n", p->best_q, size);
        fflush(p->log_csv);
    }
    if (!p->quiet) {
        fprintf(stderr, "swim optimize: iteration %3d, %4ld runs:", iter, p->evaluations);
        for (int i = 0; i < p->nkeys; i++) fprintf(stderr, " %s=%.8g", p->keys[i].text, p->best_value[i]);
        fprintf(stderr, "  %s = %.10g  (simplex size %.2g)\n", quantity_names[p->quantity], p->best_q, size);
    }
}

int swim_opt_run(swim_opt_problem *p)
{
    const int n = p->nkeys;
    gsl_set_error_handler_off();
    if (p->log_csv) {
        fprintf(p->log_csv, "iteration,evaluations");
        for (int i = 0; i < n; i++) fprintf(p->log_csv, ",%s", p->keys[i].text);
        fprintf(p->log_csv, ",%s,size\n", quantity_names[p->quantity]);
    }
    gsl_multimin_function fn = {objective, (size_t)n, p};
    gsl_vector *u = gsl_vector_alloc(n), *step = gsl_vector_alloc(n);
    gsl_multimin_fminimizer *mm = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, n);
    if (!u || !step || !mm) {
        swim_message(stderr, "swim optimize: out of memory");
        return 1;
    }
    gsl_vector_set_all(u, 0.0);      /* the middle of every range */
    gsl_vector_set_all(step, 0.6);   /* a first simplex across ~ half of each range */
    p->best.status = 1;
    int status = gsl_multimin_fminimizer_set(mm, &fn, u, step);
    double size = gsl_multimin_fminimizer_size(mm);
    log_iteration(p, 0, size);
    for (int iter = 1; status == GSL_SUCCESS && iter <= p->max_iter; iter++) {
        if (p->interrupt && *p->interrupt) {
            p->interrupted = 1;
            break;
        }
        status = gsl_multimin_fminimizer_iterate(mm);
        if (p->interrupt && *p->interrupt) {   /* this iteration's runs were cut short */
            p->interrupted = 1;
            break;
        }
        if (status != GSL_SUCCESS) break;
        size = gsl_multimin_fminimizer_size(mm);
        p->iterations = iter;
        log_iteration(p, iter, size);
        if (gsl_multimin_test_size(size, p->tol) == GSL_SUCCESS) {
            p->converged = 1;
            break;
        }
    }
    gsl_multimin_fminimizer_free(mm);
    gsl_vector_free(u);
    gsl_vector_free(step);
    return p->best.status == 0 ? 0 : 1;
}

/* ---- best.toml --------------------------------------------------------------------------------- */

int swim_opt_write_scene(const swim_opt_problem *p, const char *path)
{
    size_t len = 0, outlen = 0;
    char *text = swim_read_file(p->scene_path, SWIM_SCENE_MAX_BYTES, &len), err[512];
    if (!text) return -1;
    swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, p->best_value, ov);
    char *out = NULL;
    /* the scene as the best run ran it (scene/resolve.h): swim run of it is that run */
    int rc = swim_scene_resolve(text, len, p->scene_path, ov, nov, &out, &outlen, err, sizeof err);
    free(text);
    if (rc != 0) {
        errno = EINVAL;
        return -1;
    }
    rc = swim_replace_file(path, out, outlen);
    free(out);
    return rc;
}
