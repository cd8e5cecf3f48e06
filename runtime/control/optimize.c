#include "control/optimize.h"

#include <errno.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multimin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "control/model_setup.h"
#include "io/files.h"
#include "io/message.h"
#include "ode/ode.h"
#include "stroke/stroke.h"

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

/* The state of swim run plus W_F, the work of F(t) = f(t) direction (5.1). */
typedef struct {
    swim_dynamics *d;
    int n;   /* the run's state dimension; W_F is component n */
} run_with_work;

static int rhs_with_work(double t, const double *y, double *dy, void *params)
{
    run_with_work *w = params;
    int rc = swim_dynamics_rhs(t, y, dy, w->d);
    if (rc != 0) return rc;
    const swim_scene *s = w->d->scene;
    const int nf = w->d->spec->nfree;
    double power = 0.0;
    if (s->forced) {
        for (int f = 0; f < nf; f++) power += s->direction[w->d->spec->free_index[f]] * y[3 + nf + f];
        power *= swim_expr_eval(s->forcing, t);
    }
    dy[w->n] = power;
    return 0;
}

static int project_with_work(double t, double *y, void *params)
{
    run_with_work *w = params;
    return swim_dynamics_project(t, y, w->d);
}

/* Integrates the set-up scene to t_end as swim run does; fills r. */
static void integrate(swim_model_setup *m, swim_eval_result *r)
{
    const swim_scene *s = &m->s;
    swim_dynamics *d = &m->d;
    const int n = swim_dynamics_state_dim(d);
    double *full = calloc((size_t)d->dim, sizeof(double)), *y = calloc((size_t)n + 1, sizeof(double));
    double *yr = calloc((size_t)n + 1, sizeof(double)), *atol = calloc((size_t)n + 1, sizeof(double));
    if (!full || !y || !yr || !atol) {
        r->status = 1;
        snprintf(r->reason, sizeof r->reason, "out of memory");
        goto done;
    }
    swim_dynamics_initial_state(d, full);
    swim_dynamics_pack(d, full, y);
    run_with_work w = {d, n};
    swim_ode_system sys = {rhs_with_work, (size_t)n + 1, &w, NULL};
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = s->rtol;
    o.atol = s->atol;
    for (int i = 0; i < n; i++) atol[i] = s->atol;
    atol[n] = 1e300;   /* W_F rides on the steps of the state: the run's steps, unchanged */
    o.atol_vec = atol;
    if (s->step_lookahead >= 0) o.lookahead = s->step_lookahead;
    const unsigned caps = swim_ode_capabilities(s->integrator);
    if (s->projection && (caps & SWIM_ODE_CAP_PROJECTION)) o.project = project_with_work;
    swim_ode *ode = NULL;
    int rc = swim_ode_create(s->integrator, &sys, &o, 0.0, y, &ode);
    if (rc == SWIM_ODE_OK) rc = swim_ode_advance(ode, s->t_end, y);
    if (rc != SWIM_ODE_OK) {
        const int st = ode ? swim_ode_rhs_status(ode) : 0;
        r->status = 1;
        snprintf(r->reason, sizeof r->reason, "%s%s%s", swim_ode_strerror(rc), st ? ": " : "",
                 st ? swim_dynamics_strerror(st) : "");
        swim_ode_free(ode);
        goto done;
    }
    swim_ode_free(ode);
    memcpy(yr, y, sizeof(double) * (n + 1));
    if (o.project) o.project(s->t_end, yr, &w);   /* as swim run's rows: the projected interpolant */
    swim_dynamics_unpack(d, yr, full);
    swim_diag g;
    if (swim_dynamics_diagnostics(d, full, &g) != 0) {
        r->status = 1;
        snprintf(r->reason, sizeof r->reason, "diagnostics failed at t_end");
        goto done;
    }
    r->x = full[0];
    r->y = full[1];
    r->theta = full[2];
    r->work = g.work;
    r->forcing_work = yr[n];
    r->energy = g.energy;
    r->status = 0;
done:
    free(full); free(y); free(yr); free(atol);
}

/* A prescribed stroke ([stroke]) integrated to t_end as swim run does it: (3.21) with the stroke's
 * allowability checked first (a refused stroke is status 2), the positive work sampled as there
 * (SWIM_STROKE_POSWORK_SAMPLES per period, at most a quarter of the output step). work and
 * forcing_work are the positive work int max(P, 0) dt: what the body spends on the stroke. */
static void integrate_stroke(swim_model_setup *m, swim_eval_result *r)
{
    swim_scene *s = &m->s;
    swim_compiled law;
    memset(&law, 0, sizeof law);
    swim_stroke st;
    memset(&st, 0, sizeof st);
    swim_ode *ode = NULL;
    r->status = 1;
    const int got = swim_codegen_stroke(s, &law, 0);
    if (got != 0) {
        snprintf(r->reason, sizeof r->reason, got == -2 ? "a stroke law is refused: %s" : "no stroke kernel", law.refused);
        goto done;
    }
    int rc = swim_stroke_init(&st, s, m->kn.kernel, law.stroke, s->param_values);
    if (rc == -1) {
        snprintf(r->reason, sizeof r->reason, "out of memory");
        goto done;
    }
    st.interrupt = m->d.interrupt;
    if (rc == 0 && s->rhof_neutral) s->rhof = s->rho0 / st.mu2;   /* (2.10) with the stroke's volume */
    double t_bad;
    char why[512];
    if (rc != 0 || swim_stroke_check(&st, s->t_end, s->output_step, SWIM_STROKE_CHECK_SAMPLES, &t_bad, why, sizeof why)) {
        r->status = 2;
        snprintf(r->reason, sizeof r->reason, "stroke not allowable");
        goto done;
    }
    const double period = s->stroke_period > 0 ? s->stroke_period : swim_stroke_detect_period(&st, s->t_end);
    const double h = fmin(0.25 * s->output_step, (period > 0 ? period : s->t_end) / SWIM_STROKE_POSWORK_SAMPLES);
    swim_ode_system sys = {swim_stroke_rhs, SWIM_STROKE_DIM, &st, NULL};
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = s->rtol;
    o.atol = s->atol;
    if (s->step_lookahead >= 0) o.lookahead = s->step_lookahead;
    double y[SWIM_STROKE_DIM];
    swim_stroke_initial_state(&st, y);
    swim_stroke_poswork pw;
    memset(&pw, 0, sizeof pw);
    rc = swim_ode_create(s->integrator, &sys, &o, 0.0, y, &ode);
    if (rc == SWIM_ODE_OK) rc = swim_stroke_poswork_add(&st, &pw, 0.0, y[SWIM_STROKE_PSI]) ? SWIM_ODE_ERHS : rc;
    for (double t = 0.0; rc == SWIM_ODE_OK && t < s->t_end;) {
        t = fmin(s->t_end, t + h);
        if (s->t_end - t < 1e-3 * h) t = s->t_end;
        rc = swim_ode_advance(ode, t, y);
        if (rc == SWIM_ODE_OK && swim_stroke_poswork_add(&st, &pw, t, y[SWIM_STROKE_PSI]) != 0) rc = SWIM_ODE_ERHS;
    }
    if (rc != SWIM_ODE_OK) {
        snprintf(r->reason, sizeof r->reason, "%s", swim_ode_strerror(rc));
        goto done;
    }
    double E, P;
    if (swim_stroke_energy_power(&st, s->t_end, y[SWIM_STROKE_PSI], &E, &P) != 0) {
        snprintf(r->reason, sizeof r->reason, "diagnostics failed at t_end");
        goto done;
    }
    r->x = y[0];
    r->y = y[1];
    r->theta = y[2];
    r->work = r->forcing_work = pw.total;
    r->energy = E;
    r->status = 0;
done:
    swim_ode_free(ode);
    swim_stroke_free(&st);
    swim_compiled_close(&law);
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
    swim_override ov[SWIM_SETUP_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, v, ov);
    static swim_model_setup m;
    /* a refused value (outside D, a bound of the run settings) is one line on stderr from the
     * scene reader: keep it off the terminal, the log row says "refused" */
    fflush(stderr);
    int fd = dup(fileno(stderr));
    if (fd >= 0 && !freopen("/dev/null", "w", stderr)) {
        close(fd);
        fd = -1;
    }
    int rc = swim_setup_open(&m, "optimize", p->scene_path, ov, nov, 0, 1);
    m.d.interrupt = p->interrupt;
    if (rc == 0) {
        if (m.s.stroke) integrate_stroke(&m, r);
        else integrate(&m, r);
    }
    fflush(stderr);
    if (fd >= 0) {
        dup2(fd, fileno(stderr));
        close(fd);
        clearerr(stderr);
    }
    if (rc != 0) {
        r->status = rc == 2 ? 2 : 1;
        snprintf(r->reason, sizeof r->reason, rc == 2 ? "values refused by the scene checks" : "no kernel");
    }
    swim_setup_close(&m);
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

static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            char *b = realloc(buf, cap = 2 * cap + 8192);
            if (!b) { free(buf); fclose(f); return NULL; }
            buf = b;
        }
        size_t got = fread(buf + n, 1, 4096, f);
        n += got;
        if (got == 0) break;
    }
    fclose(f);
    buf[n] = '\0';
    *len = n;
    return buf;
}

/* Start of the line after `[table]` and the end of that table's lines (next header or EOF). */
static int find_table(const char *text, const char *table, const char **start, const char **end)
{
    char header[48];
    snprintf(header, sizeof header, "[%.40s]", table);
    for (const char *p = text; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL) {
        const char *q = p;
        while (*q == ' ' || *q == '\t') q++;
        if (strncmp(q, header, strlen(header)) == 0) {
            const char *s = strchr(q, '\n');
            *start = s ? s + 1 : q + strlen(q);
            const char *e = *start;
            while (*e) {
                const char *r = e;
                while (*r == ' ' || *r == '\t') r++;
                if (*r == '[') break;
                const char *nl = strchr(e, '\n');
                e = nl ? nl + 1 : e + strlen(e);
            }
            *end = e;
            return 0;
        }
    }
    return -1;
}

/* The value text of `key = ...` in [start, end): [*vs, *ve) (an array: through its ']'). */
static int find_value(const char *start, const char *end, const char *key, const char **vs, const char **ve)
{
    const size_t kl = strlen(key);
    for (const char *p = start; p < end; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : end) {
        const char *q = p;
        while (*q == ' ' || *q == '\t') q++;
        if (strncmp(q, key, kl) != 0) continue;
        q += kl;
        while (*q == ' ' || *q == '\t') q++;
        if (*q != '=') continue;
        q++;
        while (*q == ' ' || *q == '\t') q++;
        *vs = q;
        if (*q == '[') {
            const char *r = strchr(q, ']');
            if (!r) return -1;
            *ve = r + 1;
        } else {
            const char *r = q;
            while (*r && *r != '\n' && *r != '#') r++;
            while (r > q && (r[-1] == ' ' || r[-1] == '\t' || r[-1] == '\r')) r--;
            *ve = r;
        }
        return 0;
    }
    return -1;
}

/* The vector behind table.key in a loaded scene (the keys an item override can name). */
static const double *scene_vector(const swim_scene *s, const char *table, const char *key)
{
    if (strcmp(table, "shape") == 0 && strcmp(key, "c0") == 0) return s->c0;
    if (strcmp(table, "shape") == 0 && strcmp(key, "dc0") == 0) return s->dc0;
    if (strcmp(table, "elastic") == 0 && strcmp(key, "stiffness") == 0) return s->stiffness;
    if (strcmp(table, "elastic") == 0 && strcmp(key, "reference") == 0) return s->reference;
    if (strcmp(table, "damping") == 0 && strcmp(key, "diagonal") == 0) return s->damping;
    if (strcmp(table, "forcing") == 0 && strcmp(key, "direction") == 0) return s->direction;
    return NULL;
}

/* text with [vs, ve) replaced by repl (a new string). */
static char *splice(const char *text, const char *vs, const char *ve, const char *repl)
{
    return swim_strprintf("%.*s%s%s", (int)(vs - text), text, repl, ve);
}

int swim_opt_write_scene(const swim_opt_problem *p, const char *path)
{
    size_t len;
    char *text = read_all(p->scene_path, &len);
    if (!text) return -1;
    swim_override ov[SWIM_SETUP_MAX_SETS + SWIM_OPT_MAX_KEYS];
    const int nov = all_overrides(p, p->best_value, ov);
    swim_scene s;
    if (swim_scene_load_with(p->scene_path, ov, nov, &s) != 0) {   /* the values of whole vectors */
        free(text);
        errno = EINVAL;
        return -1;
    }
    int rc = 0;
    for (int i = 0; i < nov && rc == 0; i++) {
        const char *ts, *te, *vs, *ve;
        char *repl = NULL, *next = NULL;
        if (find_table(text, ov[i].table, &ts, &te) != 0) { rc = -1; break; }
        if (ov[i].index < 0) {
            repl = swim_strprintf("%.17g", ov[i].value);
            if (find_value(ts, te, ov[i].key, &vs, &ve) == 0) next = repl ? splice(text, vs, ve, repl) : NULL;
            else if (repl) next = swim_strprintf("%.*s%s = %s\n%s", (int)(ts - text), text, ov[i].key, repl, ts);
        } else {
            const double *vec = scene_vector(&s, ov[i].table, ov[i].key);
            if (!vec || find_value(ts, te, ov[i].key, &vs, &ve) != 0) { rc = -1; break; }
            size_t cap = (size_t)s.n * 26 + 8, at = 0;
            repl = malloc(cap);
            if (repl) {
                at += snprintf(repl + at, cap - at, "[");
                for (int k = 0; k < s.n; k++) at += snprintf(repl + at, cap - at, "%s%.17g", k ? ", " : " ", vec[k]);
                snprintf(repl + at, cap - at, " ]");
                next = splice(text, vs, ve, repl);
            }
        }
        free(repl);
        if (!next) { rc = -1; break; }
        free(text);
        text = next;
    }
    swim_scene_free(&s);
    if (rc == 0) {
        char *head = swim_strprintf("# Written by swim optimize: %s with the best values found.\n%s", p->scene_path, text);
        rc = head ? swim_replace_file(path, head, strlen(head)) : -1;
        free(head);
    }
    free(text);
    return rc;
}
