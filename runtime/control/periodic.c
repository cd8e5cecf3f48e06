/* periodic.c -- Newton shooting for a periodic orbit (control/periodic.h has the method). */
#include "control/periodic.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "driver/run.h"
#include "io/clock.h"
#include "io/json.h"
#include "io/message.h"
#include "kernel/coords.h"
#include "ode/ode.h"

/* The command whose messages these are (periodic.h). */
#define CMD(o) ((o)->cmd ? (o)->cmd : "periodic")

#define MAX_HALVINGS 8

/* The caller asked the work to stop (swim_dynamics.interrupt: the right-hand side then refuses,
 * so an integration under way ends at once): the value of the flag, else 0. */
static int stop_asked(const swim_dynamics *d) { return d->interrupt && *d->interrupt ? *d->interrupt : 0; }

/* The flow map: the integrator state ys at t = 0 carried to t = T by the scene's integrator and
 * drift control at rtol/atol (the rigid part and the work start from 0). 0, or 1 with the cause in st
 * (NULL: not said). */
static int flow(swim_dynamics *d, const double *ys, double T, const swim_periodic_options *o, double *out,
                long *rhs_calls, swim_status *st)
{
    const swim_scene *s = d->scene;
    const int N = swim_dynamics_state_dim(d);
    memcpy(out, ys, sizeof(double) * N);
    out[0] = out[1] = out[2] = out[N - 1] = 0.0;
    swim_ode_system sys = {swim_dynamics_rhs, (size_t)N, d, NULL};
    swim_ode_options opt;
    swim_run_ode_options(&s->run, &opt);
    opt.rtol = o->rtol;
    opt.atol = o->atol;
    if (s->run.projection && (swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_PROJECTION)) opt.project = swim_dynamics_project;
    swim_ode *ode = NULL;
    int rc = swim_ode_create(s->run.integrator, &sys, &opt, 0.0, out, &ode);
    if (rc == SWIM_ODE_OK) rc = swim_ode_advance(ode, T, out);
    if (ode) {
        swim_ode_stats st;
        swim_ode_get_stats(ode, &st);
        *rhs_calls += st.rhs_evals;
        swim_ode_free(ode);
    }
    if (rc != SWIM_ODE_OK) {
        if (!stop_asked(d))   /* a trial step of the line search that fails is only a step not taken (st NULL) */
            swim_status_fail_cmd(st, CMD(o), NULL, NULL, "the integration over one period (T = %.10g) failed: %s", T,
                                 swim_ode_strerror(rc));
        return 1;
    }
    return 0;
}

/* r = phi_T(z) - z on the shape state, and max |r| / scale. */
static int residual(swim_dynamics *d, const double *ys, double T, const swim_periodic_options *o, double scale,
                    double *r, double *rel, double *work, long *rhs_calls, swim_status *st)
{
    const int n2 = 2 * d->spec->nfree;
    if (flow(d, ys, T, o, work, rhs_calls, st)) return 1;
    double m = 0.0;
    for (int i = 0; i < n2; i++) {
        r[i] = work[3 + i] - ys[3 + i];
        m = fmax(m, fabs(r[i]));
    }
    *rel = m / scale;
    return 0;
}

static double energy_at(swim_dynamics *d, const double *ys, double *full)
{
    swim_diag g;
    swim_dynamics_unpack(d, ys, full);
    return swim_dynamics_diagnostics(d, full, &g) == 0 ? g.energy : NAN;
}

/* No damping on a carried coordinate and no forcing: energy is conserved, orbits come in a family
 * by energy, and the Newton system gets the energy row. */
int swim_periodic_conservative(const swim_dynamics *d)
{
    const swim_scene *s = d->scene;
    if (s->forcing) return 0;
    for (int f = 0; f < d->spec->nfree; f++)
        if (s->damping[d->spec->free_index[f]] != 0.0) return 0;
    return 1;
}

/* The Newton step (u, dT) of the bordered system, least squares. 0, or -1. */
static int newton_step(const swim_floquet *fl, const double *r, int with_energy, double energy_gap,
                       const signed char *hold, double *u, double *dT)
{
    int nsym = 0, sym[SWIM_FLOQUET_NSYM], held[SWIM_FLOQUET_MAX], nheld = 0;
    for (int k = 0; k < SWIM_FLOQUET_NSYM; k++)   /* a symmetry's orbit of orbits: a phase condition for it too */
        if (fl->symmetry_residual[k] <= SWIM_FLOQUET_SYMMETRY_TOL) sym[nsym++] = k;
    for (int i = 0; hold && i < fl->n2; i++)
        if (hold[i]) held[nheld++] = i;
    const int n2 = fl->n2, nt = fl->nt, m = n2 + 1 + with_energy + nsym + nheld, nc = nt + 1, ld = nc;
    const int rows = m > nc ? m : nc;
    double *A = calloc((size_t)rows * ld, sizeof(double)), *b = calloc((size_t)rows, sizeof(double));
    double *sv = malloc(sizeof(double) * (size_t)(m < nc ? m : nc));
    if (!A || !b || !sv) {
        free(A); free(b); free(sv);
        return -1;
    }
    for (int i = 0; i < n2; i++) {
        for (int k = 0; k < nt; k++) {
            double v = -fl->B[i * nt + k];   /* (M - I) B */
            for (int j = 0; j < n2; j++) v += fl->M[i * n2 + j] * fl->B[j * nt + k];
            A[i * ld + k] = v;
        }
        A[i * ld + nt] = fl->flow[i];
        b[i] = -r[i];
    }
    if (with_energy) b[n2 + 1] = energy_gap;   /* grad E . dz = E_target - E (0: keep it) */
    for (int k = 0; k < nt; k++)
        for (int j = 0; j < n2; j++) {
            A[n2 * ld + k] += fl->flow[j] * fl->B[j * nt + k];            /* phase: f . dz = 0 */
            if (with_energy) A[(n2 + 1) * ld + k] += fl->grad_energy[j] * fl->B[j * nt + k];   /* dE = 0 */
            for (int q = 0; q < nsym; q++)
                A[(n2 + 1 + with_energy + q) * ld + k] += fl->symmetry[sym[q]][j] * fl->B[j * nt + k];
        }
    /* the invariant subspace: dz_i = 0 for each held entry (z_i is 0 and stays 0). Without these
     * rows the least-squares step may move along the out-of-subspace directions a reversible
     * orbit leaves neutral (a multiplier 1 on the complement), and a branch drifts off its family */
    for (int q = 0; q < nheld; q++)
        for (int k = 0; k < nt; k++) A[(n2 + 1 + with_energy + nsym + q) * ld + k] = fl->B[held[q] * nt + k];
    /* rcond 1e-6: M is accurate to ~1e-8, so the multipliers at 1 of a symmetry or a conserved
     * quantity the rows above do not fix split by ~1e-4 and leave singular values of that size;
     * cut, they do not throw the step along a direction the orbit does not determine */
    lapack_int rank;
    const int rc = LAPACKE_dgelsd(LAPACK_ROW_MAJOR, m, nc, 1, A, ld, b, 1, sv, 1e-6, &rank);
    if (rc == 0) {
        memcpy(u, b, sizeof(double) * nt);
        *dT = b[nt];
    }
    free(A); free(b); free(sv);
    return rc == 0 ? 0 : -1;
}

/* The guess: the state at the first event of the section and the time to the next. */
static int guess(swim_dynamics *d, const swim_floquet_section *sec, const swim_periodic_options *o, double *ys,
                 double *full, swim_periodic *p, swim_status *st)
{
    const int N = swim_dynamics_state_dim(d);
    swim_dynamics_initial_state(d, full);
    swim_dynamics_pack(d, full, ys);
    if (swim_floquet_period(d, CMD(o), sec, o->t_max, o->t_max_from ? o->t_max_from : "--t-max", "--guess-event", ys,
                            &p->t_guess, &p->period_guess, st)) return 1;
    double *y1 = malloc(sizeof(double) * N);
    if (!y1) return 1;
    /* the state at the event, on the same map as the shooting (the event time is the
     * interpolant's; the phase condition takes up what its error leaves) */
    int rc = flow(d, ys, p->t_guess, o, y1, &p->rhs_calls, st);
    if (rc == 0) memcpy(ys, y1, sizeof(double) * N);
    free(y1);
    return rc;
}

int swim_periodic_solve(swim_dynamics *d, const swim_floquet_section *sec, const swim_periodic_options *o,
                        swim_periodic *p, swim_status *st)
{
    memset(p, 0, sizeof *p);
    const double t_start = swim_clock_seconds();
    if (d->scene->stroke || !d->spec) {
        swim_status_fail_cmd(st, CMD(o), d->scene->path, NULL, "%s: a prescribed stroke has no free shape dynamics",
                             d->scene->path);
        return 1;
    }
    const int N = swim_dynamics_state_dim(d);
    double *ys = malloc(sizeof(double) * N), *full = calloc((size_t)d->dim, sizeof(double));
    int rc = 1;
    const int g = ys && full ? guess(d, sec, o, ys, full, p, st) : -1;
    if (g < 0) swim_status_fail_cmd(st, CMD(o), NULL, NULL, "out of memory");
    else if (g != 0 && stop_asked(d)) {   /* stopped before any iterate */
        p->stopped = stop_asked(d);
        p->why = "stopped by a signal while the guess was looked for";
        p->n2 = 2 * d->spec->nfree;
        p->period = p->residual = p->energy = p->energy_target = NAN;
        p->dx = p->dy = p->dtheta = NAN;
        p->history[0].residual = p->history[0].period = p->history[0].energy = NAN;
        p->section_events = sec->count;
        p->seconds = swim_clock_seconds() - t_start;
        rc = 0;
    } else if (g == 0) {
        const double t_guess = p->t_guess, period_guess = p->period_guess;
        const long calls = p->rhs_calls;
        /* a conservative scene: the orbit of the guess's energy, held as a target (the bordered
         * row E(z) - E_guess = 0), not its linearization grad E . dz = 0, along which Newton
         * drifts to another member of the family (a libration at E = 0.3 became a rotation at
         * 0.544) */
        const double target = swim_periodic_conservative(d) ? energy_at(d, ys, full) : NAN;
        rc = swim_periodic_refine(d, ys, period_guess, target, o, p, st);
        p->t_guess = t_guess;
        p->section_events = sec->count;
        p->rhs_calls += calls;
        p->seconds = swim_clock_seconds() - t_start;   /* the guess's run included */
    }
    free(ys);
    free(full);
    return rc;
}

int swim_periodic_refine(swim_dynamics *d, const double *ys0, double T0, double energy_target,
                         const swim_periodic_options *o, swim_periodic *p, swim_status *st)
{
    memset(p, 0, sizeof *p);
    const double t0 = swim_clock_seconds();
    const int N = swim_dynamics_state_dim(d), n2 = 2 * d->spec->nfree;
    const int max_iter = o->max_iter < SWIM_PERIODIC_MAX_ITER ? o->max_iter : SWIM_PERIODIC_MAX_ITER;
    p->n2 = n2;
    p->conservative = swim_periodic_conservative(d);
    p->period_guess = T0;
    const int targeted = isfinite(energy_target) && p->conservative;
    p->energy_target = targeted ? energy_target : NAN;
    double *ys = malloc(sizeof(double) * N), *yt = malloc(sizeof(double) * N), *work = malloc(sizeof(double) * N);
    double *full = calloc((size_t)d->dim, sizeof(double));
    double r[SWIM_FLOQUET_MAX], rt[SWIM_FLOQUET_MAX], u[SWIM_FLOQUET_MAX];
    int rc = 1;
    if (!ys || !yt || !work || !full) {
        swim_status_fail_cmd(st, CMD(o), NULL, NULL, "out of memory");
        goto done;
    }
    memcpy(ys, ys0, sizeof(double) * N);
    ys[0] = ys[1] = ys[2] = ys[N - 1] = 0.0;
    for (int i = 0; o->hold_zero && i < n2; i++)
        if (o->hold_zero[i]) ys[3 + i] = 0.0;
    double T = T0, res;
    p->scale = d->scene->run.atol;
    for (int i = 0; i < n2; i++) p->scale = fmax(p->scale, fabs(ys[3 + i]));
    /* with a target energy the merit is the larger of the closing residual and the energy's
     * relative miss, so a step is taken for either */
    const double escale = targeted ? fmax(fabs(energy_target), 1e-300) : 1.0;
    double E = energy_at(d, ys, full);
    res = NAN;
    if (residual(d, ys, T, o, p->scale, r, &res, work, &p->rhs_calls, st) && !stop_asked(d)) goto done;
    double merit = targeted ? fmax(res, fabs(E - energy_target) / escale) : res;
    for (int it = 0;; it++) {
        swim_periodic_iteration *h = &p->history[it];
        if (stop_asked(d)) {   /* the last iterate stands, not converged */
            p->stopped = stop_asked(d);
            p->iterations = it > 0 ? it - 1 : 0;
            if (it == 0) {   /* the guess itself, its residual if it was computed */
                h->residual = res;
                h->merit = merit;
                h->period = T;
                h->energy = E;
            }
            p->why = "stopped by a signal before the residual reached the tolerance";
            break;
        }
        h->residual = res;
        h->merit = merit;
        h->period = T;
        h->energy = E;
        p->iterations = it;
        if (o->progress) o->progress(o->progress_ctx, it, res, T);
        if (merit <= o->tol) {
            /* a rest state closes for every T: that is not the orbit asked for */
            double rhs_max = 0.0;
            if (swim_dynamics_rhs(0.0, ys, work, d) == 0)
                for (int i = 0; i < n2; i++) rhs_max = fmax(rhs_max, fabs(work[3 + i]));
            if (rhs_max * T <= 1e3 * o->tol * p->scale)
                p->why = "the iteration went to a rest state (f = 0), which closes for any period: no periodic "
                         "orbit near the guess";
            else
                p->converged = 1;
            break;
        }
        if (it >= max_iter) {
            p->why = "the residual did not reach the tolerance within the iterations allowed";
            break;
        }
        if (it >= 3 && merit > 0.5 * p->history[it - 3].merit) {   /* Newton near a root halves it at least */
            p->why = "the residual stopped falling (not halved in three iterations): no periodic orbit near the guess";
            break;
        }
        swim_floquet fl;
        if (swim_floquet_at(d, ys, T, &fl, st) != 0) {
            if (!stop_asked(d)) goto done;
            continue;   /* said at the top */
        }
        p->rhs_calls += fl.rhs_calls;
        double dT = 0.0;
        const int step_rc = newton_step(&fl, r, p->conservative, targeted ? energy_target - E : 0.0, o->hold_zero, u,
                                        &dT);
        double dz[SWIM_FLOQUET_MAX];
        for (int i = 0; i < n2; i++) {
            dz[i] = 0.0;
            for (int k = 0; k < fl.nt; k++) dz[i] += fl.B[i * fl.nt + k] * u[k];
        }
        swim_floquet_free(&fl);
        if (step_rc != 0) {
            p->why = "the Newton system could not be solved (LAPACK dgelsd)";
            break;
        }
        /* the step, halved until the residual falls (or the halvings run out) */
        double lambda = 1.0, res_t = INFINITY;
        int accepted = 0;
        for (int hv = 0; hv <= MAX_HALVINGS && !accepted; hv++, lambda *= 0.5) {
            memcpy(yt, ys, sizeof(double) * N);
            for (int i = 0; i < n2; i++) yt[3 + i] += lambda * dz[i];
            yt[0] = yt[1] = yt[2] = yt[N - 1] = 0.0;
            swim_dynamics_project(0.0, yt, d);   /* back onto the constraint manifold */
            for (int i = 0; o->hold_zero && i < n2; i++)   /* the projection keeps them to rounding */
                if (o->hold_zero[i]) yt[3 + i] = 0.0;
            const double Tt = T + lambda * dT;
            if (!(Tt > 0.0)) continue;
            if (residual(d, yt, Tt, o, p->scale, rt, &res_t, work, &p->rhs_calls, NULL) != 0) continue;
            const double Et = energy_at(d, yt, full);
            const double merit_t = targeted ? fmax(res_t, fabs(Et - energy_target) / escale) : res_t;
            if (merit_t < merit) {
                accepted = 1;
                h->halvings = hv;
                h->step = 0.0;
                for (int i = 0; i < n2; i++) h->step = fmax(h->step, fabs(yt[3 + i] - ys[3 + i]));
                memcpy(ys, yt, sizeof(double) * N);
                memcpy(r, rt, sizeof(double) * n2);
                T = Tt;
                res = res_t;
                E = Et;
                merit = merit_t;
            }
        }
        if (!accepted && stop_asked(d)) continue;   /* the trials were cut short: said at the top */
        if (!accepted) {
            p->why = "no step along the Newton direction lowered the residual (at the tolerance of the flow map, "
                     "or no periodic orbit near the guess)";
            break;
        }
    }
    if (!p->converged && targeted && fabs(E - energy_target) / escale > fmax(o->tol, res)) {
        /* what keeps Newton from converging is the energy: a nearby orbit closes at another one */
        snprintf(p->why_text, sizeof p->why_text, "the orbit left the energy it was asked to keep (E = %.12g, target "
                 "%.12g): %s", E, energy_target, p->why ? p->why : "");
        p->why = p->why_text;
    }
    if (!p->converged && !p->conservative && !p->stopped) {   /* say what the scene makes likely */
        snprintf(p->why_text, sizeof p->why_text, "%s; the scene has %s, which %s energy, so only a rest state "
                 "can close", p->why ? p->why : "", d->scene->forcing ? "forcing" : "damping",
                 d->scene->forcing ? "supplies" : "dissipates");
        p->why = p->why_text;
    }
    p->period = T;
    p->residual = res;
    for (int i = 0; i < n2; i++) p->z[i] = ys[3 + i];
    p->energy = energy_at(d, ys, full);
    if (p->stopped) {   /* no more integrations: the displacement is unknown */
        p->dx = p->dy = p->dtheta = NAN;
        rc = 0;
        goto done;
    }
    if (flow(d, ys, T, o, work, &p->rhs_calls, st)) goto done;
    p->dx = work[0];
    p->dy = work[1];
    p->dtheta = work[2];
    if (p->converged) {
        if (swim_floquet_at(d, ys, T, &p->floquet, st) != 0) goto done;
        p->have_floquet = 1;
        p->rhs_calls += p->floquet.rhs_calls;
    }
    rc = 0;
done:
    free(ys); free(yt); free(work); free(full);
    p->seconds = swim_clock_seconds() - t0;
    return rc;
}

int swim_periodic_check(const swim_scene *s, const char *cmd, const char *path, swim_status *st)
{
    if (s->stroke) {
        swim_status_fail_cmd(st, cmd, path, "stroke", "%s: a prescribed stroke ([stroke]) is periodic by its laws: there "
                             "is no free shape dynamics to solve for (swim run reports its period and displacement per "
                             "stroke)", path);
        return 2;
    }
    if (s->forcing) {
        swim_status_fail_cmd(st, cmd, path, "forcing", "%s: [forcing] makes the equations depend on time; periodic orbits "
                             "are looked for in autonomous scenes only", path);
        return 2;
    }
    if (!(swim_ode_capabilities(s->run.integrator) & SWIM_ODE_CAP_EVENTS)) {
        swim_status_fail_cmd(st, cmd, path, "run.integrator", "%s: run.integrator = \"%s\" cannot locate the guess's "
                             "events; use one of %s (e.g. --set run.integrator=abm)", path, s->run.integrator,
                             swim_ode_method_list_with(SWIM_ODE_CAP_EVENTS));
        return 2;
    }
    return 0;
}

int swim_periodic_setup(swim_problem *m, const char *cmd, const char *path, const swim_override *sets, int nsets,
                        int generic, int quiet, const char *guess, swim_floquet_section *sec, char *text, size_t len,
                        swim_status *st)
{
    int rc = swim_problem_read(m, &(swim_problem_source){.path = path, .sets = sets, .nsets = nsets}, st);
    if (rc == 0) rc = swim_periodic_check(m->s, cmd, path, st);
    if (rc == 0) rc = swim_problem_kernels(m, cmd, generic, quiet ? 0 : 1, st);
    if (rc == 0) rc = swim_floquet_parse_section(&m->d, cmd, "guess-event", guess, sec, text, len, st);
    if (rc) swim_problem_close(m);
    return rc;
}

int swim_periodic_invariant_zeros(const swim_periodic *p, signed char *hold)
{
    const int n2 = p->n2;
    memset(hold, 0, (size_t)n2);
    if (!p->converged || !p->have_floquet) return 0;
    const swim_floquet *fl = &p->floquet;
    double fmax_ = 0.0, mmax = 0.0;
    for (int i = 0; i < n2; i++) fmax_ = fmax(fmax_, fabs(fl->flow[i]));
    for (int i = 0; i < n2 * n2; i++) mmax = fmax(mmax, fabs(fl->M[i]));
    int n = 0;
    for (int i = 0; i < n2; i++) {
        hold[i] = fabs(p->z[i]) <= 1e-10 * p->scale && fabs(fl->flow[i]) <= 1e-10 * fmax_;
        n += hold[i];
    }
    /* invariance to first order along the whole orbit: M maps the subspace into itself */
    for (int i = 0; i < n2 && n; i++)
        for (int j = 0; j < n2; j++)
            if (hold[i] && !hold[j] && fabs(fl->M[i * n2 + j]) > 1e-7 * mmax) {
                memset(hold, 0, (size_t)n2);
                return 0;
            }
    if (n == n2) memset(hold, 0, (size_t)n2);   /* a rest state, not a subspace */
    return n == n2 ? 0 : n;
}

void swim_periodic_free(swim_periodic *p)
{
    if (p->have_floquet) swim_floquet_free(&p->floquet);
    p->have_floquet = 0;
}

void swim_periodic_json(FILE *f, const swim_periodic *p, const swim_dynamics *d, const char *scene,
                        const char *section)
{
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, scene);
    fprintf(f, ",\n  \"section\": ");
    swim_json_string(f, section);
    if (p->section_events > 0) fprintf(f, ",\n  \"section_events_per_period\": %d", p->section_events);
    fprintf(f, ",\n  \"status\": \"%s\"", p->converged ? "converged" : p->stopped ? "stopped" : "not converged");
    if (p->stopped) {
        fprintf(f, ",\n  \"signal\": ");
        swim_json_string(f, swim_floquet_signal_name(p->stopped));
    }
    fprintf(f, ",\n  \"converged\": %s,\n  \"reason\": ", p->converged ? "true" : "false");
    if (p->why) swim_json_string(f, p->why);
    else fprintf(f, "null");
    fprintf(f, ",\n  \"period\": ");
    swim_json_number(f, p->period);
    fprintf(f, ",\n  \"residual\": ");
    swim_json_number(f, p->residual);
    fprintf(f, ",\n  \"residual_meaning\": \"max |phi_T(z) - z| / max(max |z|, atol) on the shape state\"");
    fprintf(f, ",\n  \"state_scale\": ");
    swim_json_number(f, p->scale);
    fprintf(f, ",\n  \"displacement_per_period\": {\"dx\": ");
    swim_json_number(f, p->dx);
    fprintf(f, ", \"dy\": ");
    swim_json_number(f, p->dy);
    fprintf(f, ", \"dtheta\": ");
    swim_json_number(f, p->dtheta);
    fprintf(f, ", \"frame\": \"the body's at the phase point (q = 0 there)\"}");
    fprintf(f, ",\n  \"energy\": ");
    swim_json_number(f, p->energy);
    fprintf(f, ",\n  \"energy_fixed\": %s", p->conservative ? "true" : "false");
    fprintf(f, ",\n  \"energy_target\": ");   /* the guess's energy, held (conservative scenes) */
    swim_json_number(f, p->energy_target);
    fprintf(f, ",\n  \"phase_point\": {");
    const int nf = p->n2 / 2;
    for (int i = 0; i < p->n2; i++) {
        char name[24];
        swim_coord_name(d->spec->free_index[i % nf], name, sizeof name);
        fprintf(f, "%s\"%s%s\": ", i ? ", " : "", i < nf ? "" : "d", name);
        swim_json_number(f, p->z[i]);
    }
    fprintf(f, "},\n  \"guess\": {\"first_event\": ");
    swim_json_number(f, p->t_guess);
    fprintf(f, ", \"period\": ");
    swim_json_number(f, p->period_guess);
    fprintf(f, "},\n  \"newton\": [");
    for (int i = 0; i <= p->iterations && i <= SWIM_PERIODIC_MAX_ITER; i++) {
        const swim_periodic_iteration *h = &p->history[i];
        fprintf(f, "%s\n    {\"iteration\": %d, \"residual\": ", i ? "," : "", i);
        swim_json_number(f, h->residual);
        fprintf(f, ", \"period\": ");
        swim_json_number(f, h->period);
        fprintf(f, ", \"energy\": ");
        swim_json_number(f, h->energy);
        fprintf(f, ", \"step\": ");
        swim_json_number(f, h->step);
        fprintf(f, ", \"halvings\": %d}", h->halvings);
    }
    fprintf(f, "\n  ],\n  \"floquet\": ");
    if (p->have_floquet) {
        const swim_floquet *fl = &p->floquet;
        fprintf(f, "{\"base\": \"the phase point\", \"tangent_dimension\": %d, \"multipliers_tangent\": [", fl->nt);
        for (int i = 0; i < fl->nt; i++) {
            fprintf(f, "%s{\"re\": ", i ? ", " : "");
            swim_json_number(f, fl->tre[i]);
            fprintf(f, ", \"im\": ");
            swim_json_number(f, fl->tim[i]);
            fprintf(f, ", \"abs\": ");
            swim_json_number(f, hypot(fl->tre[i], fl->tim[i]));
            fprintf(f, "}");
        }
        fprintf(f, "], \"checks\": ");
        swim_floquet_checks_json(f, fl);
        fprintf(f, ", \"stable\": %s", fl->stable ? "true" : "false");
        /* what accounts for the multipliers at 1: each with the residual of its eigenvector */
        /* M on the shape state and the tangent basis, so that every claim below can be checked */
        fprintf(f, ",\n    \"monodromy\": ");
        swim_json_matrix(f, fl->M, fl->n2, fl->n2, 4);
        fprintf(f, ",\n    \"tangent_basis\": ");
        swim_json_matrix(f, fl->B, fl->n2, fl->nt, 4);
        fprintf(f, ",\n    \"at_1\": [{\"reason\": \"time shift along the orbit (the flow f is an eigenvector)\", "
                   "\"residual\": ");
        swim_json_number(f, fl->flow_residual);
        fprintf(f, ", \"vector\": ");
        swim_json_vector(f, fl->flow, fl->n2);
        fprintf(f, "}");
        if (p->conservative) {
            fprintf(f, ", {\"reason\": \"energy: the family of orbits by energy (grad E a left eigenvector)\", \"residual\": ");
            swim_json_number(f, fl->energy_residual);
            fprintf(f, ", \"left_vector\": ");
            swim_json_vector(f, fl->grad_energy, fl->n2);
            fprintf(f, "}");
        }
        for (int k = 0; k < SWIM_FLOQUET_NSYM; k++) {
            fprintf(f, ", {\"reason\": \"%s\", \"residual\": ", swim_floquet_symmetry_names[k]);
            swim_json_number(f, fl->symmetry_residual[k]);
            fprintf(f, ", \"symmetry\": %s", fl->symmetry_residual[k] <= SWIM_FLOQUET_SYMMETRY_TOL ? "true" : "false");
            if (isfinite(fl->symmetry_residual[k])) {
                fprintf(f, ", \"vector\": ");
                swim_json_vector(f, fl->symmetry[k], fl->n2);
            }
            fprintf(f, "}");
        }
        if (fl->forced_one >= 0) {   /* computed on the complement, not taken out: its value is the check */
            const double mu = fl->cre[fl->forced_one];
            fprintf(f, ", {\"reason\": \"reversibility: the complement's multipliers come in reciprocal pairs "
                       "(lambda, 1/lambda) and its dimension %d is odd, so one is its own inverse\", \"multiplier\": ",
                    fl->nc);
            swim_json_number(f, mu);
            fprintf(f, ", \"residual\": ");
            swim_json_number(f, fabs(mu - 1.0));
            fprintf(f, "}");
        }
        int unnamed = 0;   /* multipliers at 1 on the complement that nothing above accounts for */
        for (int k = 0; k < fl->nc; k++)
            unnamed += k != fl->forced_one && hypot(fl->cre[k] - 1.0, fl->cim[k]) < fl->tol;
        fprintf(f, "], \"unidentified_at_1\": %d}", unnamed);
    } else {
        fprintf(f, "null");
    }
    fprintf(f, ",\n  \"rhs_evaluations\": %ld,\n  \"seconds\": ", p->rhs_calls);
    swim_json_number(f, p->seconds);
    fprintf(f, "\n}\n");
}
