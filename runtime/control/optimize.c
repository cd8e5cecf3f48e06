#include "control/optimize.h"

#include <errno.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_blas.h>
#include <gsl/gsl_multimin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "driver/flow.h"
#include "driver/run.h"
#include "io/clock.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"
#include "ode/ode.h"
#include "problem/problem.h"
#include "scene/keys.h"
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

int swim_opt_has_gradient(int quantity)
{
    return !(quantity == SWIM_Q_FORCING_WORK || quantity == SWIM_Q_DISPLACEMENT_PER_WORK);   /* W_F: no state */
}

/* dE/dp of key k: the energy is evaluated on the run's dynamics, whose state is relative to the
 * origin the run may have left (model/dynamics.h), so the final state is given relative to it. */
static double energy_gradient(swim_flow *f, int k)
{
    const swim_dynamics *d = f->S.d;
    if (!d->origin) return swim_sens_energy(&f->S, f->Y, k);
    const int N = swim_sens_dimension(&f->S);
    double *u = malloc(sizeof(double) * (size_t)N);
    if (!u) return NAN;
    memcpy(u, f->Y, sizeof(double) * (size_t)N);
    for (int i = 0; i < f->S.dim; i++) u[i] -= d->origin[i];
    const double g = swim_sens_energy(&f->S, u, k);
    free(u);
    return g;
}

/* The gradient of the quantity in the keys' values from the sensitivities of the final state,
 * carried by the evaluation's own run (driver/flow.h) on its steps, out of its error test
 * (swim run --sensitivity-steps state): ~1e-5 relative, plenty for a search direction, at a
 * fraction of the error-controlled cost, and the run's value is bit for bit the one without them. */
static void gradient(const swim_opt_problem *p, swim_flow *f, swim_eval_result *r)
{
    if (swim_flow_final(f) != 0) return;   /* no gradient: said by r */
    const double *Y = f->Y;
    const int n = f->S.dim;
    const double disp = hypot(Y[0], Y[1]);
    for (int i = 0; i < p->nkeys; i++) {
        const double *si = Y + (size_t)(i + 1) * n;
        double g = NAN;
        switch (p->quantity) {
        case SWIM_Q_X: g = si[0]; break;
        case SWIM_Q_Y: g = si[1]; break;
        case SWIM_Q_THETA: g = si[2]; break;
        case SWIM_Q_DISPLACEMENT: g = disp > 0 ? (Y[0] * si[0] + Y[1] * si[1]) / disp : 0.0; break;
        case SWIM_Q_WORK: g = si[n - 1]; break;
        case SWIM_Q_ENERGY: g = energy_gradient(f, i); break;
        }
        if (!isfinite(g)) return;
        r->grad[i] = g;
    }
    r->have_grad = 1;
}

int swim_opt_check_gradient(const swim_opt_problem *p, const swim_override *ov, int nov, swim_status *st)
{
    swim_problem *P = malloc(sizeof *P);
    if (!P) {
        swim_status_fail(st, "swim optimize", NULL, 0, NULL, "out of memory");
        return 2;
    }
    const swim_problem_source src = {.text = p->scene_text, .len = p->scene_len, .name = p->scene_path, .sets = ov,
                                     .nsets = nov};
    int rc = swim_problem_open(P, &src, "optimize", 0, 0, st) ? 2 : 0;
    swim_sens S;
    if (rc == 0 && swim_sens_init(&S, &P->d) == 0) {
        for (int i = 0; i < p->nkeys && rc == 0; i++)
            rc = swim_sens_add_key(&S, P->s, "optimize: --vary", p->keys[i].text, st);
        swim_sens_free(&S);
    } else {
        rc = 2;
    }
    swim_problem_close(P);
    free(P);
    return rc ? 2 : 0;
}

/* The problem of the evaluations (problem/problem.h) with the overrides ov: read from the scene's
 * text and given its kernels at the first evaluation, the values set in place at the next ones
 * (no kernel looked up again unless a value changes the kernel's structure, when the kernels of
 * the new one are had as a fresh run would have them). 0, or the problem's code (2 refused, 1 no
 * kernel or out of memory). */
static int evaluation_problem(swim_opt_problem *p, const swim_override *ov, int nov, swim_status *st)
{
    if (p->problem) return swim_problem_apply(p->problem, ov, nov, 0, st);
    if (!(p->problem = malloc(sizeof *p->problem))) return 1;
    const swim_problem_source src = {.text = p->scene_text, .len = p->scene_len, .name = p->scene_path, .sets = ov,
                                     .nsets = nov, .flags = SWIM_PROBLEM_RESTRUCTURE};
    int rc = swim_problem_open(p->problem, &src, "optimize", 0, 0, st);
    if (rc) {   /* the next evaluation reads it again (values refused here may be accepted there) */
        swim_problem_close(p->problem);
        free(p->problem);
        p->problem = NULL;
    }
    return rc;
}

/* One run of the scene with the overrides ov, by the run driver (driver/run.h) exactly as swim run
 * makes it (same settings, restarts near the barrier, energy control, rows), so that `swim run` of
 * best.toml gives the value reported to the last bit; no rows are kept. Fills r, with the
 * gradient when want_grad. */
static void integrate(swim_opt_problem *p, const swim_override *ov, int nov, int want_grad, swim_eval_result *r)
{
    swim_run *run = NULL;
    swim_flow flow, alone;   /* the run with the columns on its steps; a flow of its own */
    memset(&flow, 0, sizeof flow);
    memset(&alone, 0, sizeof alone);
    r->status = 1;
    /* a refused value (outside D, a bound of the run settings) is not shown: the log row says
     * "refused" */
    swim_status st = {0};
    int rc = evaluation_problem(p, ov, nov, &st);
    if (rc) {
        r->status = rc == 2 ? 2 : 1;
        snprintf(r->reason, sizeof r->reason, rc == 2 ? "values refused by the scene checks" : "no kernel");
        return;
    }
    swim_scene *s = p->problem->s;
    const swim_run_request req = {.scene = s, .kernel = &p->problem->kn, .system = &p->problem->spz,
                                  .stop = (volatile sig_atomic_t *)p->interrupt};
    swim_status_clear(&st);
    rc = swim_run_open(&req, &run, &st);
    if (rc) {
        r->status = rc == 2 ? 2 : 1;
        snprintf(r->reason, sizeof r->reason, "%s", rc == 2 ? "stroke not allowable" : "out of memory");
        goto done;
    }
    const char *keys[SWIM_OPT_MAX_KEYS];
    for (int i = 0; i < p->nkeys; i++) keys[i] = p->keys[i].text;
    /* an integrator that cannot leave the columns out of its error test (no SWIM_ODE_CAP_ERROR_DIM)
     * would change the run's steps, and so the value: its columns take a flow of their own, in
     * its error test, after the run */
    const int ride = (swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_ERROR_DIM) != 0;
    const swim_flow_vars vars = {0, 0, keys, p->nkeys, "optimize: --vary", !ride};
    flow.run = run;
    if (want_grad && ride && swim_flow_attach(&flow, run, &vars, &st) != 0) {   /* the keys were checked before */
        snprintf(r->reason, sizeof r->reason, "the sensitivities failed");
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
    if (want_grad && !ride) {
        p->problem->d.interrupt = (volatile int *)p->interrupt;   /* the flow stops as the run does */
        const swim_flow_request fr = {.model = &p->problem->d, .t_end = s->run.t_end, .vars = vars};
        if (swim_flow_map(&fr, &alone, NULL) == 0) gradient(p, &alone, r);
    } else if (want_grad) {
        gradient(p, &flow, r);
        if (!r->have_grad) {   /* no gradient: the search cannot use this point */
            r->status = 1;
            snprintf(r->reason, sizeof r->reason, "the sensitivities failed");
        }
    }
done:
    swim_flow_free(&flow);   /* and the run */
    swim_flow_free(&alone);
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

/* One run with values v and extra overrides (the tight check's tolerances), which replace any
 * --set of the same value. */
static int evaluate_with(swim_opt_problem *p, const double *v, const swim_override *extra, int nextra, int want_grad,
                         swim_eval_result *r)
{
    memset(r, 0, sizeof *r);
    swim_override all[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS], ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS + 2];
    const int nall = all_overrides(p, v, all);
    int nov = 0;
    for (int i = 0; i < nall; i++) {
        int replaced = 0;
        for (int j = 0; j < nextra; j++) replaced |= swim_override_same_target(&all[i], &extra[j]);
        if (!replaced) ov[nov++] = all[i];
    }
    for (int i = 0; i < nextra; i++) ov[nov++] = extra[i];
    integrate(p, ov, nov, want_grad, r);
    p->evaluations++;
    p->gradients += r->have_grad;
    if (r->status) p->failed++;
    return r->status;
}

int swim_opt_evaluate(swim_opt_problem *p, const double *v, swim_eval_result *r)
{
    return evaluate_with(p, v, NULL, 0, 0, r);
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

/* d value / d u */
static double value_slope(const swim_opt_problem *p, int i, double u)
{
    return (p->hi[i] - p->lo[i]) * 0.5 * cos(u);
}

/* What the minimizer sees at u: F = -q (maximize) or q, and dF/du when grad is not NULL. A new
 * best (of the start and of all) is kept. 0, or 1 for a failed or refused run (F = penalty). */
static int evaluate_u(swim_opt_problem *p, const gsl_vector *u, double *F, gsl_vector *grad)
{
    double v[SWIM_OPT_MAX_KEYS];
    for (int i = 0; i < p->nkeys; i++) v[i] = value_of(p, i, gsl_vector_get(u, i));
    *F = FAILED_PENALTY;
    if (grad) gsl_vector_set_zero(grad);
    if (p->interrupt && *p->interrupt) return 1;   /* no more runs */
    swim_eval_result r;
    if (evaluate_with(p, v, NULL, 0, grad != NULL, &r) != 0) return 1;
    const double q = swim_opt_quantity(p, &r);
    if (!isfinite(q)) return 1;
    const double sign = p->maximize ? -1.0 : 1.0;
    *F = sign * q;
    if (grad)
        for (int i = 0; i < p->nkeys; i++)
            gsl_vector_set(grad, i, sign * r.grad[i] * value_slope(p, i, gsl_vector_get(u, i)));
    swim_opt_start *st = &p->start[p->nstarts - 1];
    if (!st->ok || (p->maximize ? q > st->best_q : q < st->best_q)) {
        st->ok = 1;
        st->best_q = q;
        memcpy(st->best_value, v, sizeof(double) * p->nkeys);
    }
    if (p->best.status != 0 || (p->maximize ? q > p->best_q : q < p->best_q)) {
        p->best_q = q;
        p->best = r;
        p->best_start = p->nstarts - 1;
        memcpy(p->best_value, v, sizeof(double) * p->nkeys);
    }
    return 0;
}

static double objective(const gsl_vector *u, void *params)
{
    double F;
    evaluate_u(params, u, &F, NULL);
    return F;
}

/* BFGS asks for F and its gradient, often at the same u twice in a row: one run per point. */
typedef struct {
    swim_opt_problem *p;
    gsl_vector *u, *g;
    double F;
    int valid;
} fdf_cache;

static void fdf_at(const gsl_vector *u, fdf_cache *c)
{
    if (c->valid && gsl_vector_equal(u, c->u)) return;
    gsl_vector_memcpy(c->u, u);
    evaluate_u(c->p, u, &c->F, c->g);
    c->valid = 1;
}

static double fdf_f(const gsl_vector *u, void *params)
{
    fdf_at(u, params);
    return ((fdf_cache *)params)->F;
}

static void fdf_df(const gsl_vector *u, void *params, gsl_vector *g)
{
    fdf_at(u, params);
    gsl_vector_memcpy(g, ((fdf_cache *)params)->g);
}

static void fdf_fdf(const gsl_vector *u, void *params, double *f, gsl_vector *g)
{
    fdf_at(u, params);
    *f = ((fdf_cache *)params)->F;
    gsl_vector_memcpy(g, ((fdf_cache *)params)->g);
}

static void log_iteration(swim_opt_problem *p, int iter, double size)
{
    const swim_opt_start *st = &p->start[p->nstarts - 1];
    if (p->log_csv) {
        fprintf(p->log_csv, "%d,%ld", iter, p->evaluations);
        const double tail[2] = {st->best_q, size};
        for (int i = 0; i < p->nkeys + 2; i++) {
            fputc(',', p->log_csv);
            swim_number_print(p->log_csv, i < p->nkeys ? st->best_value[i] : tail[i - p->nkeys]);
        }
        fprintf(p->log_csv, ",%d\n", p->nstarts);
        fflush(p->log_csv);
    }
    char *line = NULL;
    size_t len = 0;
    FILE *f = !p->quiet && p->status && p->status->note ? open_memstream(&line, &len) : NULL;
    if (f) {
        fprintf(f, "swim optimize: start %d, iteration %3d, %4ld runs:", p->nstarts, iter, p->evaluations);
        for (int i = 0; i < p->nkeys; i++) fprintf(f, " %s=%.8g", p->keys[i].text, st->best_value[i]);
        fprintf(f, "  %s = %.10g  (%s %.2g)", quantity_names[p->quantity], st->best_q,
                p->method == SWIM_OPT_BFGS ? "|gradient|" : "simplex size", size);
        if (fclose(f) == 0) swim_status_note(p->status, "%s", line);
    }
    free(line);
}

/* Whether the search must stop now (SIGINT or SIGTERM): said in p. */
static int interrupted(swim_opt_problem *p)
{
    if (p->interrupt && *p->interrupt) p->interrupted = 1;
    return p->interrupted;
}

/* One Nelder-Mead search from u0: a first simplex across ~ half of each range, divided by
 * K^(1/n) with K starts, so that each start explores its own part of the box. 0, or -1. */
static int search_nelder_mead(swim_opt_problem *p, const gsl_vector *u0, swim_opt_start *st)
{
    const int n = p->nkeys;
    gsl_multimin_function fn = {objective, (size_t)n, p};
    gsl_vector *step = gsl_vector_alloc(n);
    gsl_multimin_fminimizer *mm = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2, n);
    if (!step || !mm) {
        gsl_vector_free(step);
        gsl_multimin_fminimizer_free(mm);
        return -1;
    }
    gsl_vector_set_all(step, 0.6 / pow(p->starts > 1 ? p->starts : 1, 1.0 / n));
    int status = gsl_multimin_fminimizer_set(mm, &fn, u0, step);
    double size = gsl_multimin_fminimizer_size(mm);
    log_iteration(p, 0, size);
    for (int iter = 1; status == GSL_SUCCESS && iter <= p->max_iter && !interrupted(p); iter++) {
        status = gsl_multimin_fminimizer_iterate(mm);
        if (interrupted(p) || status != GSL_SUCCESS) break;   /* an interrupted iteration's runs were cut short */
        size = gsl_multimin_fminimizer_size(mm);
        st->iterations = iter;
        log_iteration(p, iter, size);
        if (gsl_multimin_test_size(size, p->tol) == GSL_SUCCESS) {
            st->converged = 1;
            break;
        }
    }
    gsl_multimin_fminimizer_free(mm);
    gsl_vector_free(step);
    return 0;
}

/* One BFGS search from u0 (first step 0.1 in u, line-search tolerance 0.1). 0, or -1. */
static int search_bfgs(swim_opt_problem *p, const gsl_vector *u0, swim_opt_start *st)
{
    const int n = p->nkeys;
    fdf_cache c = {p, gsl_vector_alloc(n), gsl_vector_alloc(n), 0.0, 0};
    gsl_multimin_function_fdf fn = {fdf_f, fdf_df, fdf_fdf, (size_t)n, &c};
    gsl_multimin_fdfminimizer *mm = gsl_multimin_fdfminimizer_alloc(gsl_multimin_fdfminimizer_vector_bfgs2, n);
    if (!c.u || !c.g || !mm) {
        gsl_vector_free(c.u);
        gsl_vector_free(c.g);
        gsl_multimin_fdfminimizer_free(mm);
        return -1;
    }
    int status = gsl_multimin_fdfminimizer_set(mm, &fn, u0, 0.1, 0.1);
    log_iteration(p, 0, gsl_blas_dnrm2(gsl_multimin_fdfminimizer_gradient(mm)));
    for (int iter = 1; status == GSL_SUCCESS && iter <= p->max_iter && !interrupted(p); iter++) {
        if (gsl_multimin_test_gradient(gsl_multimin_fdfminimizer_gradient(mm), p->tol) == GSL_SUCCESS) {
            st->converged = 1;
            break;
        }
        status = gsl_multimin_fdfminimizer_iterate(mm);
        if (interrupted(p)) break;
        const gsl_vector *g = gsl_multimin_fdfminimizer_gradient(mm);
        st->iterations = iter;
        log_iteration(p, iter, gsl_blas_dnrm2(g));
        /* no lower point along the line (GSL_ENOPROG) is the optimum to the runs' resolution
         * when the gradient is nearly small enough, else a stall */
        if (status == GSL_ENOPROG) st->converged = gsl_multimin_test_gradient(g, 10 * p->tol) == GSL_SUCCESS;
        else if (status == GSL_SUCCESS) st->converged = gsl_multimin_test_gradient(g, p->tol) == GSL_SUCCESS;
        if (st->converged) break;
    }
    gsl_multimin_fdfminimizer_free(mm);
    gsl_vector_free(c.u);
    gsl_vector_free(c.g);
    return 0;
}

/* The radical inverse of k in base b: a coordinate of the Halton sequence. */
static double halton(int k, int b)
{
    double f = 1.0, r = 0.0;
    for (; k > 0; k /= b) {
        f /= b;
        r += f * (k % b);
    }
    return r;
}

/* Start k in u: the middle of the box for k = 0, else the k-th Halton point (bases 2, 3, 5, ...),
 * kept off the bounds (u = +-pi/2 is a stationary point of the map from u to the value). */
static void start_point(const swim_opt_problem *p, int k, gsl_vector *u)
{
    static const int primes[SWIM_OPT_MAX_KEYS] = {2, 3, 5, 7, 11, 13, 17, 19};
    for (int i = 0; i < p->nkeys; i++) {
        const double h = k == 0 ? 0.5 : 0.02 + 0.96 * halton(k + 1, primes[i]);   /* index 1 is the middle */
        gsl_vector_set(u, i, asin(2.0 * h - 1.0));
    }
}

/* The best point again at 100x tighter tolerances (rtol not below the scene reader's floor). */
static void tight_check(swim_opt_problem *p)
{
    swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, p->best_value, ov);
    swim_scene s;
    p->tight_status = 1;
    if (swim_scene_parse_with(p->scene_text, p->scene_len, p->scene_path, ov, nov, &s, p->status) != 0) return;
    const double rtol = fmax(s.run.rtol / 100.0, SWIM_RTOL_MIN), atol = s.run.atol / 100.0;
    swim_scene_free(&s);
    swim_override extra[2];
    char err[200];
    if (swim_override_key("run.rtol", &extra[0], err, sizeof err) != 0
        || swim_override_key("run.atol", &extra[1], err, sizeof err) != 0) return;
    extra[0].value = rtol;
    extra[1].value = atol;
    swim_eval_result r;
    if (evaluate_with(p, p->best_value, extra, 2, 0, &r) != 0) return;
    p->tight_q = swim_opt_quantity(p, &r);
    p->tight_status = isfinite(p->tight_q) ? 0 : 1;
    p->tight_change = p->tight_q - p->best_q;
}

int swim_opt_run(swim_opt_problem *p)
{
    const int n = p->nkeys;
    const double t0 = swim_clock_seconds();
    gsl_set_error_handler_off();
    if (p->log_csv) {
        fprintf(p->log_csv, "iteration,evaluations");
        for (int i = 0; i < n; i++) fprintf(p->log_csv, ",%s", p->keys[i].text);
        fprintf(p->log_csv, ",%s,size,start\n", quantity_names[p->quantity]);
    }
    gsl_vector *u = gsl_vector_alloc(n);
    if (!u) {
        swim_status_fail(p->status, "swim optimize", NULL, 0, NULL, "out of memory");
        return 1;
    }
    p->best.status = 1;
    const int starts = p->starts > 0 ? p->starts : 1;
    for (int k = 0; k < starts && k < SWIM_OPT_MAX_STARTS && !interrupted(p); k++) {
        swim_opt_start *st = &p->start[p->nstarts++];
        memset(st, 0, sizeof *st);
        start_point(p, k, u);
        for (int i = 0; i < n; i++) st->start[i] = value_of(p, i, gsl_vector_get(u, i));
        const long before = p->evaluations;
        const int rc = p->method == SWIM_OPT_BFGS ? search_bfgs(p, u, st) : search_nelder_mead(p, u, st);
        st->evaluations = p->evaluations - before;
        if (rc != 0) {
            swim_status_fail(p->status, "swim optimize", NULL, 0, NULL, "out of memory");
            break;
        }
    }
    gsl_vector_free(u);
    if (p->best.status == 0) {
        const swim_opt_start *b = &p->start[p->best_start];
        p->iterations = b->iterations;
        p->search_converged = b->converged;
        p->value_tol = p->tol * fmax(1.0, fabs(p->best_q));
        if (!p->interrupted) tight_check(p);
        p->converged = p->search_converged && !p->interrupted && p->tight_status == 0
                       && fabs(p->tight_change) <= p->value_tol;
    }
    if (p->problem) swim_problem_close(p->problem);
    free(p->problem);
    p->problem = NULL;
    p->seconds = swim_clock_seconds() - t0;
    return p->best.status == 0 ? 0 : 1;
}

/* ---- best.toml --------------------------------------------------------------------------------- */

int swim_opt_write_scene(const swim_opt_problem *p, const char *path)
{
    size_t outlen = 0;
    char err[512];
    swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, p->best_value, ov);
    char *out = NULL;
    /* the scene as the best run ran it (scene/resolve.h): swim run of it is that run */
    int rc = swim_scene_resolve(p->scene_text, p->scene_len, p->scene_path, ov, nov, &out, &outlen, err, sizeof err);
    if (rc != 0) {
        errno = EINVAL;
        return -1;
    }
    rc = swim_replace_file(path, out, outlen);
    free(out);
    return rc;
}

/* ---- the problem as given: keys, bounds and quantity checked before any run --------------------- */

int swim_opt_vary(swim_opt_problem *p, const char *spec, swim_status *st)
{
    const int i = p->nkeys;
    const char *file = p->scene_path;
    if (i == SWIM_OPT_MAX_KEYS) {
        swim_status_fail_cmd(st, "optimize", file, "vary", "--vary: at most %d keys", SWIM_OPT_MAX_KEYS);
        return 2;
    }
    const char *eq = strchr(spec, '='), *colon = eq ? strchr(eq, ':') : NULL;
    char key[128], err[256];
    if (!eq || !colon || (size_t)(eq - spec) >= sizeof key) {
        swim_status_fail_cmd(st, "optimize", file, "vary", "--vary: expected KEY=LO:HI (e.g. parameters.A=0.5:4), "
                             "got '%s'", spec);
        return 2;
    }
    snprintf(key, sizeof key, "%.*s", (int)(eq - spec), spec);
    memset(&p->keys[i], 0, sizeof p->keys[i]);
    if (swim_override_key(key, &p->keys[i], err, sizeof err) != 0) {
        swim_status_fail_cmd(st, "optimize", file, key, "--vary %s: %s", spec, err);
        return 2;
    }
    /* a value that can be varied continuously: a number of the scene (scene/keys.h) */
    const swim_scene_key *row = swim_scene_key_find(p->keys[i].table, p->keys[i].key);
    if (!row || !(row->kind == SWIM_KEY_NUMBER || row->kind == SWIM_KEY_VECTOR)) {
        swim_status_fail_cmd(st, "optimize", file, key, "--vary %s: %s (vary a number: a [parameters] value, an item "
                             "of a vector such as elastic.stiffness.am1, model.rho0, ...)", spec,
                             !row ? "not a key of a scene" : "not a number");
        return 2;
    }
    if (row->kind == SWIM_KEY_VECTOR && p->keys[i].index < 0) {
        swim_status_fail_cmd(st, "optimize", file, key, "--vary %s: %s.%s is a vector: vary one item of it (%s.%s.am1 "
                             "or %s.%s[I])", spec, row->table, row->key, row->table, row->key, row->table, row->key);
        return 2;
    }
    snprintf(p->keys[i].text, sizeof p->keys[i].text, "%s", key);
    char lo[64], *end;
    snprintf(lo, sizeof lo, "%.*s", (int)(colon - eq - 1), eq + 1);
    p->lo[i] = strtod(lo, &end);
    int ok = end != lo && *end == '\0' && isfinite(p->lo[i]);
    p->hi[i] = strtod(colon + 1, &end);
    ok = ok && end != colon + 1 && *end == '\0' && isfinite(p->hi[i]) && p->lo[i] < p->hi[i];
    if (!ok) {
        swim_status_fail_cmd(st, "optimize", file, key, "--vary %s: LO and HI must be finite numbers with LO < HI", spec);
        return 2;
    }
    char target[100];
    swim_override_target(&p->keys[i], target, sizeof target);
    for (int k = 0; k < i; k++)
        if (swim_override_same_target(&p->keys[k], &p->keys[i])) {
            swim_status_fail_cmd(st, "optimize", file, key, "--vary %s: varies %s, which --vary %s already varies "
                                 "(vary each value once)", spec, target, p->keys[k].text);
            return 2;
        }
    for (int k = 0; k < p->nsets; k++)
        if (swim_override_same_target(&p->sets[k], &p->keys[i])) {
            swim_status_fail_cmd(st, "optimize", file, key, "--set %s: sets %s, which --vary %s varies (the set value "
                                 "would never be used)", p->sets[k].text, target, spec);
            return 2;
        }
    p->nkeys++;
    return 0;
}

int swim_opt_check(const swim_opt_problem *p, swim_status *st)
{
    const char *qname = swim_quantity_name(p->quantity), *scene = p->scene_path;
    if (p->method == SWIM_OPT_BFGS && !swim_opt_has_gradient(p->quantity)) {
        swim_status_fail_cmd(st, "optimize", scene, "method", "--method bfgs: %s has no gradient from the sensitivities "
                             "(W_F is not a state of the equations); use --method nelder-mead", qname);
        return 2;
    }
    if (p->nsets > SWIM_OPT_MAX_SETS) {
        swim_status_fail_cmd(st, "optimize", scene, "set", "more than %d --set overrides", SWIM_OPT_MAX_SETS);
        return 2;
    }
    swim_override ov[SWIM_OPT_MAX_SETS + SWIM_OPT_MAX_KEYS];
    int k = 0;
    for (int i = 0; i < p->nsets; i++) ov[k++] = p->sets[i];
    for (int i = 0; i < p->nkeys; i++) ov[k++] = p->keys[i];
    /* every key at LO, then at HI, then in the middle (kept): a bound the scene refuses is
     * refused now, named by its --vary, not met by a run halfway through the search */
    swim_scene s;
    for (int at = 0; at < 3; at++) {
        for (int i = 0; i < p->nkeys; i++) {
            swim_override *o = &ov[p->nsets + i];
            o->value = at == 0 ? p->lo[i] : at == 1 ? p->hi[i] : 0.5 * (p->lo[i] + p->hi[i]);
            snprintf(o->text, sizeof o->text, "--vary %s=%.10g:%.10g (at %s = %.10g)", p->keys[i].text, p->lo[i],
                     p->hi[i], p->keys[i].text, o->value);
        }
        if (swim_scene_parse_with(p->scene_text, p->scene_len, scene, ov, k, &s, st) != 0) return 2;
        if (at < 2) swim_scene_free(&s);
    }
    const int forced = s.forced || s.stroke;   /* a stroke's work is the body's positive work */
    const int stroke = s.stroke || s.stroke_count > 0;
    swim_scene_free(&s);
    if (p->method == SWIM_OPT_BFGS && stroke) {
        swim_status_fail_cmd(st, "optimize", scene, "method", "--method bfgs: %s is a prescribed stroke, which has no "
                             "sensitivities; use --method nelder-mead", scene);
        return 2;
    }
    if (p->method == SWIM_OPT_BFGS && swim_opt_check_gradient(p, ov, k, st)) return 2;
    if ((p->quantity == SWIM_Q_DISPLACEMENT_PER_WORK || p->quantity == SWIM_Q_FORCING_WORK) && !forced) {
        swim_status_fail_cmd(st, "optimize", scene, "quantity", "%s: %s needs a [forcing] law (the work of F(t)) or a "
                             "[stroke] (the positive work of the body)", scene, qname);
        return 2;
    }
    return 0;
}

/* ---- optimize.json ------------------------------------------------------------------------------ */

/* {"KEY": v[0], ...} of the varied keys; NaN (null) for all when ok is 0. */
static void json_keys(FILE *f, const swim_opt_problem *p, const double *v, int ok)
{
    fputc('{', f);
    for (int i = 0; i < p->nkeys; i++) {
        fprintf(f, "%s", i ? ", " : "");
        swim_json_string(f, p->keys[i].text);
        fprintf(f, ": ");
        swim_json_number(f, ok ? v[i] : NAN);
    }
    fputc('}', f);
}

void swim_opt_json(FILE *f, const swim_opt_problem *p, const char *best_path)
{
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, p->scene_path);
    fprintf(f, ",\n  \"quantity\": ");
    swim_json_string(f, swim_quantity_name(p->quantity));
    fprintf(f, ",\n  \"goal\": \"%s\",\n  \"best\": ", p->maximize ? "maximize" : "minimize");
    json_keys(f, p, p->best_value, 1);
    fprintf(f, ",\n  \"bounds\": {");
    for (int i = 0; i < p->nkeys; i++) {
        fprintf(f, "%s", i ? ", " : "");
        swim_json_string(f, p->keys[i].text);
        fprintf(f, ": [");
        swim_json_number(f, p->lo[i]);
        fprintf(f, ", ");
        swim_json_number(f, p->hi[i]);
        fprintf(f, "]");
    }
    fprintf(f, "},\n  \"value\": ");
    swim_json_number(f, p->best_q);
    const double final[6] = {p->best.x, p->best.y, p->best.theta, p->best.work, p->best.forcing_work, p->best.energy};
    static const char *const final_names[6] = {"x", "y", "theta", "work", "forcing_work", "energy"};
    fprintf(f, ",\n  \"final\": {");
    for (int i = 0; i < 6; i++) {
        fprintf(f, "%s\"%s\": ", i ? ", " : "", final_names[i]);
        swim_json_number(f, final[i]);
    }
    fprintf(f, "},\n  \"method\": \"%s\",\n  \"tolerance\": ", p->method == SWIM_OPT_BFGS ? "bfgs" : "nelder-mead");
    swim_json_number(f, p->tol);
    fprintf(f, ",\n  \"tight_check\": {\"rtol_factor\": 0.01, \"status\": \"%s\", \"value\": ",
            p->tight_status == 0 ? "completed" : "failed");
    swim_json_number(f, p->tight_status == 0 ? p->tight_q : NAN);
    fprintf(f, ", \"change\": ");
    swim_json_number(f, p->tight_status == 0 ? p->tight_change : NAN);
    fprintf(f, ", \"value_tolerance\": ");
    swim_json_number(f, p->value_tol);
    fprintf(f, ", \"holds\": %s},\n  \"search_converged\": %s,\n  \"best_start\": %d,\n  \"starts\": [",
            swim_opt_holds(p) ? "true" : "false", p->search_converged ? "true" : "false", p->best_start + 1);
    for (int s = 0; s < p->nstarts; s++) {
        const swim_opt_start *st = &p->start[s];
        fprintf(f, "%s\n    {\"start\": ", s ? "," : "");
        json_keys(f, p, st->start, 1);
        fprintf(f, ", \"best\": ");
        json_keys(f, p, st->best_value, st->ok);
        fprintf(f, ", \"value\": ");
        swim_json_number(f, st->ok ? st->best_q : NAN);
        fprintf(f, ", \"iterations\": %d, \"evaluations\": %ld, \"converged\": %s}", st->iterations,
                st->evaluations, st->converged ? "true" : "false");
    }
    fprintf(f, "\n  ],\n  \"iterations\": %d,\n  \"evaluations\": %ld,\n  \"gradient_evaluations\": %ld,\n"
            "  \"failed_evaluations\": %ld,\n  \"seconds\": ", p->iterations, p->evaluations, p->gradients, p->failed);
    swim_json_number(f, p->seconds);
    fprintf(f, ",\n  \"converged\": %s,\n  \"interrupted\": %s,\n  \"best_scene\": ",
            p->converged ? "true" : "false", p->interrupted ? "true" : "false");
    if (best_path) swim_json_string(f, best_path);
    else fputs("null", f);
    fprintf(f, "\n}\n");
}

int swim_opt_holds(const swim_opt_problem *p)
{
    return p->tight_status == 0 && fabs(p->tight_change) <= p->value_tol;
}
