/* Checks and diagnostics at every accepted step (run_watch.h). */
#include "driver/watch.h"

#include "io/clock.h"
#include "kernel/coords.h"
#include "shape/constraints.h"
#include "shape/shape.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define ROOT_MAXIT 100


int swim_run_watch_init(swim_run_watch *w, swim_dynamics *d, int sdim, int energy)
{
    memset(w, 0, sizeof *w);
    w->d = d;
    w->sdim = sdim;
    w->energy = energy;
    w->ys = calloc((size_t)sdim, sizeof(double));
    w->full = calloc((size_t)d->dim, sizeof(double));
    w->r.jmin = INFINITY;
    w->r.jmin_t = NAN;
    swim_run_watch_mark(w);
    return w->ys && w->full ? 0 : -1;
}

void swim_run_watch_free(swim_run_watch *w)
{
    free(w->ys);
    free(w->full);
    w->ys = w->full = NULL;
}

static void note_jmin(swim_run_watch_results *r, double t, double J)
{
    if (J < r->jmin || isnan(J)) {
        r->jmin = J;
        r->jmin_t = t;
    }
}

/* What p holds at or before t_end into r; p is emptied. */
static void commit(swim_run_watch_results *r, swim_run_watch_pending *p, double t_end)
{
    for (int i = 0; i < p->n; i++)
        if (p->t[i] <= t_end) note_jmin(r, p->t[i], p->J[i]);
    if (p->balanced && p->tb <= t_end) {
        r->drift_abs = swim_run_max_of(r->drift_abs, p->drift);
        r->emax = swim_run_max_of(r->emax, p->e);
        r->res_volume = swim_run_max_of(r->res_volume, p->res_volume);
        r->res_volume_rate = swim_run_max_of(r->res_volume_rate, p->res_volume_rate);
        r->res_angular = swim_run_max_of(r->res_angular, p->res_angular);
        r->res_locks = swim_run_max_of(r->res_locks, p->res_locks);
    }
    memset(p, 0, sizeof *p);
}

static void candidate(swim_run_watch_pending *p, double t, double J)
{
    if (p->n < 3) {
        p->t[p->n] = t;
        p->J[p->n++] = J;
    }
}

void swim_run_watch_mark(swim_run_watch *w)
{
    w->mark_r = w->r;
    w->mark_pend = w->pend;
}

void swim_run_watch_rewind(swim_run_watch *w, double t)
{
    w->r = w->mark_r;
    commit(&w->r, &w->mark_pend, t);
    memset(&w->pend, 0, sizeof w->pend);
    w->have_prev = 0;
}

void swim_run_watch_finish(swim_run_watch *w, double t_end) { commit(&w->r, &w->pend, t_end); }

/* min J and d/dt min J at t: of the state ys when given, else on the interpolant (the full state
 * is left in w->full). -1 when the interpolant cannot be evaluated there. */
static int j_at(swim_run_watch *w, const swim_ode_accepted *st, double t, const double *ys, double *J, double *rate)
{
    if (!ys && st->interp(st->ctx, t, w->ys, NULL)) return -1;
    swim_dynamics_unpack(w->d, ys ? ys : w->ys, w->full);
    const int n = w->d->n, modes = w->d->scene->modes;
    /* Without a barrier the angle of the minimum is asked for nowhere (the barrier's weights and
     * precise J take it): where min J and its rate have a closed form, no trigonometry at all. */
    if (!w->d->scene->barrier && !w->d->origin && swim_shape_jmin_rate(modes, w->full + 3, w->full + 3 + n, J, rate)) {
        w->theta_last = NAN;
        return 0;
    }
    double theta;
    *J = swim_dynamics_jmin_unpacked(w->d, ys ? ys : w->ys, w->full, &theta);
    w->theta_last = theta;
    *rate = swim_shape_j_rate(modes, w->full + 3, w->full + 3 + n, theta);
    return 0;
}

/* A sign change of f (rate or J, which = 0 or 1) in [a, b], f(a) = fa < 0 <= fb = f(b) for the
 * rate, fa > 0 >= fb for J, by the Illinois variant of regula falsi (as ode/events.c); returns
 * the end of the final bracket on b's side, its J in *Jb. */
static double locate(swim_run_watch *w, const swim_ode_accepted *st, int which, double a, double fa, double b,
                     double fb, double Jb0, double *Jb)
{
    const int sb = which ? !(fb > 0) : fb >= 0;   /* the class of b: J <= 0, or rate >= 0 */
    int side = 0;
    *Jb = Jb0;
    for (int it = 0; it < ROOT_MAXIT; it++) {
        /* a minimum: J is flat there, an error dt in t costs J'' dt^2 (or |J'| dt at a kink where
         * the angle of the minimum jumps), far below the integration error at dt = 1e-8; the
         * crossing: as precise as an event (ode.h) */
        const double tol = fmax(which ? 1e-13 : 1e-8, 4.0 * DBL_EPSILON * fmax(fabs(a), fabs(b)));
        if (b - a <= tol) break;
        double c = (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        double J, rate;
        if (j_at(w, st, c, NULL, &J, &rate)) break;
        const double fc = which ? J : rate;
        const int sc = which ? !(fc > 0) : fc >= 0;
        if (sc == sb) {
            b = c; fb = fc; *Jb = J;
            if (side == -1) fa *= 0.5;
            side = -1;
        } else {
            a = c; fa = fc;
            if (side == 1) fb *= 0.5;
            side = 1;
        }
    }
    return b;
}

/* Energy balance (5.3) and constraint residuals at the step end (integrator state u, full state
 * in w->full). The balance is swim_dynamics_balance: at the state the right-hand side has just
 * evaluated (the accepted y_{n+1} of abm) it reuses that evaluation's kinetic energy and W2. */
static void balance(swim_run_watch *w, double tb, const double *u)
{
    swim_dynamics *d = w->d;
    const swim_scene *s = d->scene;
    const int n = d->n;
    const double *c = w->full + 3, *v = w->full + 3 + n;
    const double B = swim_dynamics_balance(tb, u, NULL, d), work = w->full[3 + 2 * n];
    if (isnan(B)) {
        w->diag_failed = 1;
        return;
    }
    const double E = B + work;
    swim_run_watch_pending *p = &w->pend;
    p->balanced = 1;
    p->tb = tb;
    p->drift = fabs(E - w->e0 - work);
    p->e = fabs(E);
    swim_constraint_residuals res;
    swim_constraint_residuals_at(n, c, v, s->c0, d->mu0, s->free_mask, &res);
    p->res_volume = fabs(res.volume);
    p->res_volume_rate = fabs(res.volume_rate);
    p->res_angular = fabs(res.angular);
    p->res_locks = res.locks;
}

int swim_run_watch_step(const swim_ode_accepted *st, void *data, double *t_stop)
{
    swim_run_watch *w = data;
    const int timed = swim_clock_sample_start(&w->time);
    int stop = 0;
    commit(&w->r, &w->pend, INFINITY);   /* a step followed by another is part of the run */
    swim_run_watch_pending *p = &w->pend;
    if (!w->have_prev && j_at(w, st, st->ta, NULL, &w->j_prev, &w->rate_prev) == 0) {
        w->t_prev = st->ta;
        w->have_prev = 1;
        candidate(p, st->ta, w->j_prev);
    }
    double Jb, rb;
    w->end_y = NULL;
    if (j_at(w, st, st->tb, st->y_end, &Jb, &rb) != 0) {
        w->have_prev = 0;
        swim_clock_sample_stop(&w->time, timed);
        return 0;
    }
    const double theta_b = w->theta_last;
    w->r.steps++;
    if (w->energy) balance(w, st->tb, st->y_end ? st->y_end : w->ys);   /* w->full holds the state at tb */
    double tm = st->tb, Jm = Jb;
    if (w->have_prev && w->rate_prev < 0 && rb >= 0)   /* a minimum of J inside the step */
        tm = locate(w, st, 0, w->t_prev, w->rate_prev, st->tb, rb, Jb, &Jm);
    if (w->have_prev && w->j_prev > 0 && !(Jm > 0)) {
        /* J reached 0 inside the step: the first crossing, before tm */
        double Jc;
        double tc = locate(w, st, 1, w->t_prev, w->j_prev, tm, Jm, Jm, &Jc);
        w->left = 1;
        w->t_left = tc;
        candidate(p, tc, Jc);
        *t_stop = tc;
        stop = 1;
    } else {
        candidate(p, tm, Jm);
        candidate(p, st->tb, Jb);
    }
    w->t_prev = st->tb;
    w->j_prev = Jb;
    w->rate_prev = rb;
    w->have_prev = 1;
    w->end_y = st->y_end;
    w->end_j = Jb;
    w->end_theta = theta_b;
    swim_clock_sample_stop(&w->time, timed);
    return stop;
}
