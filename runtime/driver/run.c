/* run.c -- one run of a dynamic scene (driver/run.h): rows at k*output_step and t_end from the
 * integrator's interpolant, every accepted step checked (driver/watch.h), restarts near the
 * boundary of D (a shifted origin, impacts), the stiff fallback, and why the run stopped.
 *
 * A shape that leaves D (4.1) ends the run at the crossing, whose row is the last (the trial
 * states beyond it are refused by the right-hand side, model/dynamics.h). When ABM's stiffness
 * diagnostic fires, the run goes on from the last row with the scene's stiff_fallback (cvode-bdf
 * unless "none"). A run that stops early (NaN, step-size underflow, the shape leaving D, a stop
 * request, a row the sink could not keep) says where and why in its result; a run ended by a
 * :stop event has its last row at the event and is completed. */
#include "driver/run.h"

#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/columns.h"
#include "driver/run_internal.h"
#include "io/clock.h"
#include "io/message.h"
#include "model/bounce.h"
#include "shape/barrier.h"
#include "shape/shape.h"

static double ode_time(const scene_run *c) { return c->d.t_origin + swim_ode_time(c->ode); }

/* A stop was asked for (a signal, through req.stop). */
static int stop_requested(const scene_run *c) { return c->req.stop && *c->req.stop; }

/* A line for the user (printf-like), through the sink. */
static void notice(scene_run *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void notice(scene_run *c, const char *fmt, ...)
{
    if (!c->req.sink.notice) return;
    va_list ap;
    va_start(ap, fmt);
    char *line = swim_vstrprintf(fmt, ap);
    va_end(ap);
    if (line) c->req.sink.notice(c->req.sink.ctx, line);
    free(line);
}

/* ---- the error test near the barrier -------------------------------------------------------- */

/* Near the boundary of D the barrier energy W2 ~ kappa ln(1/min J) (alpha = 1/2; steeper for
 * larger alpha) turns an error dx of the shape into an energy error ~ kappa |grad J|_1 |dx| / min J:
 * with the usual weights rtol |x_i| + atol, a bounce to min J = 1e-8 at rtol 1e-8 loses 1e-5 of the
 * energy (measured on soft_n15_a05). So after every accepted step the tolerance of each carried
 * shape coordinate is cut to rtol min J / |grad J|_1 (J then moves by at most rtol of itself),
 * when that is smaller and min J < 1e-3 |c_1|^2. Farther from the boundary the factors stay 1 and
 * the run is unchanged: cutting them there too (from min J < 0.1 |c_1|^2 on) made the drift of
 * the soft scenes 3-7x larger, not smaller (abm's step control reacts to the changing weights). The
 * floor 40 u / rtol keeps abm's round-off test (2u max|y/w| < 1/2) satisfied ten times over. */
static double barrier_tolerance(scene_run *c, const double *y, double h)
{
    const swim_scene *s = c->s;
    const swim_scene_kernel *k = c->d.spec;
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    swim_dynamics_unpack(&c->d, y, full);
    const double *x = full + 3;
    double theta, j0;
    if (c->watch_ready && c->watch.end_y == y) {   /* the watch has just computed it at this step end */
        j0 = c->watch.end_j;
        theta = c->watch.end_theta;
    } else {
        j0 = swim_dynamics_jmin(&c->d, y, &theta);
    }
    const double c1 = x[0] * x[0] + x[1] * x[1];
    double scale[SWIM_NMAX];
    for (int i = 0; i < k->nfree; i++) scale[i] = 1.0;
    if (j0 > 0 && j0 < 1e-3 * c1) {
        double e[SWIM_NMAX] = {0.0}, g1 = 0.0, umax = 0.0, vmax = 0.0;
        for (int i = 0; i < k->nfree; i++) {
            e[k->free_index[i]] = 1.0;
            g1 += fabs(swim_shape_j_rate(s->modes, x, e, theta));
            e[k->free_index[i]] = 0.0;
            umax = fmax(umax, fabs(y[3 + i]));
            vmax = fmax(vmax, fabs(x[s->n + k->free_index[i]]));
        }
        const double want = c->set->rtol * j0 / g1, floor_s = 40.0 * 1.11e-16 / c->set->rtol;
        for (int i = 0; i < k->nfree; i++) {
            const double allowed = c->set->rtol * fabs(x[k->free_index[i]]) + c->set->atol;
            /* with an origin abm rounds u, not the shape: the floor follows the largest |u| (and
             * what one more step can add to it) instead of the shape itself */
            const double floor_i = c->d.origin ? 40.0 * 1.11e-16 * (umax + h * vmax) / allowed : floor_s;
            scale[i] = fmin(1.0, fmax(floor_i, want / allowed));
        }
    }
    for (int i = 0; i < k->nfree; i++) c->tol_scale[3 + i] = scale[i];
    return j0 / c1;
}

/* ---- the energy balance in the error test ------------------------------------------------ */

/* abm keeps each component's local error within rtol of it, yet lets the balance E - E0 - work
 * drift by a systematic amount per step: for the oscillations of a conservative scene Adams
 * methods are slightly dissipative, and the drift adds up over the steps (measured on a soft
 * alpha = 1/2 scene at rtol 1e-8: ~1e-12 of E per step at every step size, 1.1e-7 over 67 000
 * steps; rtol 1e-9 only halved it). So the balance's share of the error estimate is tested too,
 * against ENERGY_CONTROL rtol of the energy scale (swim_ode_options.invariant). Chosen on
 * perturbed families at rtol 1e-8 (tests/bench/bench_soft_family.py, rebuilt with other values):
 * 16 copies of soft_n10_a05 kept balance median / max 1.2e-8 / 2.5e-8 at 1e-2, 3.7e-9 / 6.1e-9
 * at 3e-3 and 1.4e-9 / 3.0e-9 at 1e-3 (3.6e-8 / 1.1e-7 without), for 14, 17 and 27 % more steps;
 * 4 copies of soft_n20_a05: 2.5e-8 / 4.6e-8, 1.3e-8 / 1.4e-8, 4.9e-9 / 6.4e-9 (1.1e-7 / 1.6e-7
 * without). 1e-1 changed nothing. */
#define ENERGY_CONTROL 3e-3

static double scaled_balance(double t, const double *u, double *noise, void *data)
{
    scene_run *c = data;
    if (!(c->bal_scale > 0)) {   /* before E0 is known, or E0 = 0 and no energy yet */
        *noise = 0.0;
        return 0.0;
    }
    const double B = swim_dynamics_balance(t, u, noise, &c->d);
    *noise /= c->bal_scale;
    return B / c->bal_scale;
}

/* Where abm carries the state relative to an origin (model/dynamics.h): from min J below
 * SHIFT_IN |c_1|^2 at a step end until it is back above SHIFT_OUT |c_1|^2, with a new origin
 * when the state has moved too far from it for the depth (shift_wanted). The
 * rounding of the shape costs ~kappa 1e-16 |grad J| / min J of the energy per step, a random walk
 * over the 10^4-10^5 steps a soft scene spends near the wall: on 8 perturbed soft_n10_a05 runs
 * at rtol 1e-8 (tests/bench/bench_soft_family.py, rebuilt with other values here) the largest
 * balance was 3.8e-7 with SHIFT_IN = 1e-6 and 1.1e-7 with 1e-3, for ~10 % more steps; 1e-2 was
 * no better and took 50 % more steps. The gap
 * between the two levels keeps an approach that hovers from restarting abm at every step. */
#define SHIFT_IN 1e-3
#define SHIFT_OUT 1e-2
#define SHIFT_DEEP 1e-12
#define SHIFT_EVERY 64
#define SHIFT_URGENT 1e-6

/* A step in the integrator's time seen in absolute time (the watch keeps absolute times): an
 * absolute t maps back to the step, its ends exactly (in a deep bounce t0 + ta and t0 + tb can be
 * one double). */
typedef struct {
    const swim_ode_accepted *st;
    double t0, ta, tb;
} absolute_step;

static int absolute_interp(void *ctx, double t, double *y, double *yp)
{
    const absolute_step *a = ctx;
    const double tau = t == a->tb ? a->st->tb : t == a->ta ? a->st->ta : fmin(fmax(t - a->t0, a->st->ta), a->st->tb);
    return a->st->interp(a->st->ctx, tau, y, yp);
}

/* Where the next origin goes (0: stay, 1: move it to the step end, 2: drop it), from min J /
 * |c_1|^2 = j at the step end and the state u there. */
static int shift_wanted(const scene_run *c, double j, const double *u)
{
    /* a restart costs abm a new start (order 1, a few rejected steps): above SHIFT_URGENT, where
     * the rounding of the shape costs little per step, not more often than every SHIFT_EVERY
     * steps (a forced shape vibrating near the wall would otherwise restart it every few steps) */
    if (c->steps_since_shift < SHIFT_EVERY && j > SHIFT_URGENT) return 0;
    if (!c->d.origin) return j < SHIFT_IN;
    if (j > SHIFT_OUT) return 2;
    /* u rounds by ~u|u|, which costs ~kappa u |u| / (min J) of the energy per step; without an
     * origin at SHIFT_OUT that is kappa u / SHIFT_OUT: keep |u| below j / SHIFT_OUT for the same
     * cost at depth j (as a bounce deepens, this moves the origin each time min J falls ~100x) */
    double umax = 0.0;
    for (int i = 0; i < c->d.spec->nfree; i++) umax = fmax(umax, fabs(u[3 + i]));
    return umax > j / SHIFT_OUT;
}

/* ---- the work of the forcing -------------------------------------------------------------- */

/* W_F = int_0^t f(s) direction . cdot ds, the work of F(t) = f(t) direction (5.1) alone (the
 * state's work also holds the damping's), measured on the integrator's own interpolant so that
 * the trajectory is the one without it: 4-point Gauss-Legendre on every accepted step, and on the
 * part of the latest step up to each row. NAN without dense output. */
static const double GL_X[4] = {-0.86113631159405258, -0.33998104358485626, 0.33998104358485626, 0.86113631159405258};
static const double GL_W[4] = {0.34785484513745385, 0.65214515486254609, 0.65214515486254609, 0.34785484513745385};

/* The power f(t) direction . cdot at the integrator state ys (absolute time t). */
static double forcing_power(scene_run *c, double t, const double *ys)
{
    const swim_scene *s = c->s;
    swim_dynamics_unpack(&c->d, ys, c->fw_full);
    double p = 0.0;
    for (int i = 0; i < s->n; i++) p += s->direction[i] * c->fw_full[3 + s->n + i];
    return p * swim_expr_eval(s->forcing, t);
}

/* int_a^b of the power (absolute times) on an interpolant in the integrator's time. -1 if it fails. */
static int forcing_integral(scene_run *c, double a, double b, int (*interp)(void *, double, double *, double *),
                            void *ctx, double *out)
{
    double sum = 0.0;
    const double h = 0.5 * (b - a), m = 0.5 * (a + b);
    for (int k = 0; k < 4 && h > 0; k++) {
        const double t = m + h * GL_X[k];
        if (interp(ctx, t - c->d.t_origin, c->fw_ys, NULL) != 0) return -1;
        sum += GL_W[k] * forcing_power(c, t, c->fw_ys);
    }
    *out = h * sum;
    return 0;
}

static int step_interp(void *ctx, double tau, double *y, double *yp)
{
    const swim_ode_accepted *st = ctx;
    return st->interp(st->ctx, tau, y, yp);
}

static int ode_interp(void *ctx, double tau, double *y, double *yp)
{
    return swim_ode_dense(ctx, tau, y, yp) == SWIM_ODE_OK ? 0 : -1;
}

/* An accepted step [ta, tb] (integrator's time): the one before it is now wholly part of the run. */
static void forcing_step(scene_run *c, const swim_ode_accepted *step)
{
    c->fw_done += c->fw_pending;
    c->fw_ta = c->d.t_origin + step->ta;
    c->fw_tb = c->d.t_origin + step->tb;
    if (forcing_integral(c, c->fw_ta, c->fw_tb, step_interp, (void *)step, &c->fw_pending) != 0) c->fw_bad = 1;
}

/* W_F at a row t (in the latest step, or at its end). */
static void forcing_row(scene_run *c, double t)
{
    double part = c->fw_pending;
    if (t < c->fw_tb && (!c->ode || forcing_integral(c, c->fw_ta, t, ode_interp, c->ode, &part) != 0)) c->fw_bad = 1;
    c->fw_at_row = c->fw_bad ? NAN : c->fw_done + part;
}

/* The stiff fallback restarts from the row at t: the work there is where it goes on from. */
static void forcing_rewind(scene_run *c, double t)
{
    c->fw_done = c->fw_at_row;
    c->fw_pending = 0.0;
    c->fw_ta = c->fw_tb = t;
}

/* ---- bounces too deep to follow ---------------------------------------------------------- */

/* With alpha = 1/2 an approach carrying the normal kinetic energy T turns at min J ~ j0 e^(-T/kappa)
 * (shape/barrier.h, swim_barrier_reach), far below what double precision resolves under strong
 * forcing (1e-25 ... 1e-110 in models/hard/large_forcing.toml), in a time of the same order. Such a
 * bounce is an impact (model/bounce.h). It is taken once min J, falling, is below IMPACT_AT rtol
 * |c_1|^2, when the turning point is predicted below impact_depth |c_1|^2 (by default the
 * resolution of J in double precision) and below IMPACT_DEEPER times the depth reached (then the speed
 * toward the wall hardly changes before the last e-folds, as the impulsive limit assumes). The
 * rest of the bounce lasts ~2 min J / |d min J/dt|; what the impact neglects over that time is
 * O(min J) of the state (measured: ~6 min J, tests/test_impact.py), a few hundredths of rtol. */
#define IMPACT_AT 0.01
#define IMPACT_DEEPER 1e-3

/* The impact at full state y (model/bounce.h), along the barrier's gradient there, computed on
 * the diagnostics' quadrature (its warm start is not the right-hand side's). 0 or -1. */
static int bounce_at(scene_run *c, const double *y, swim_bounce *b)
{
    const swim_scene *s = c->s;
    double grad[SWIM_NMAX], W;
    if (!c->d.diag_barrier ||
        swim_barrier_w2(c->d.diag_barrier, y + 3, s->epsilon, s->alpha, &W, grad, NULL) != SWIM_BARRIER_OK)
        return -1;
    return swim_bounce_along(&c->d, y, grad, b);
}

/* Whether the step end y, at min J / |c_1|^2 = j, is where a bounce becomes an impact; then its
 * change of cdot is left in c->impact_dv. */
static int impact_wanted(scene_run *c, const double *y, double j)
{
    const swim_scene *s = c->s;
    if (!(c->set->impact_depth > 0) || !(j < IMPACT_AT * c->set->rtol) || !c->d.diag_barrier) return 0;
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    swim_dynamics_unpack(&c->d, y, full);
    const double j0 = c->watch_ready && c->watch.end_y == y ? c->watch.end_j   /* just computed at this step end */
                                                             : swim_dynamics_jmin(&c->d, y, NULL);
    swim_bounce b;
    if (!(j0 > 0) || bounce_at(c, full, &b) != 0 || !(b.rate > 0)) return 0;
    const double reach = swim_barrier_reach(c->d.diag_barrier, full + 3, s->epsilon, s->alpha, b.normal_kinetic, NULL);
    const double c1 = full[3] * full[3] + full[4] * full[4];
    if (!(reach > 0) || !(reach < c->set->impact_depth * c1) || !(reach < IMPACT_DEEPER * j0)) return 0;
    memcpy(c->impact_dv, b.dv, sizeof(double) * (size_t)s->n);
    c->impact_j = j0 / c1;
    c->impact_reach = reach / c1;
    return 1;
}

/* Ends the integration at the step's end, keeping its state, for a restart of kind `pending`
 * (shift_pending: 1, 2 an origin, 3 an impact) that advance_to carries out. Returns 1. */
static int stop_for(scene_run *c, const swim_ode_accepted *step, int pending, double *t_stop)
{
    c->shift_pending = pending;
    c->shift_t = step->tb;
    *t_stop = step->tb;
    memcpy(c->ys_shift, step->y_end, sizeof(double) * c->sys.dimension);
    return 1;
}

/* ---- the tangent vector's renormalization ------------------------------------------------ */

/* |w| over its norm components in the integrator's augmented state Y. */
static double tangent_norm(const scene_run *c, const double *Y)
{
    const double *w = Y + c->sdim + c->var.norm_from;
    double s = 0.0;
    for (size_t i = 0; i < c->var.norm_count; i++) s += w[i] * w[i];
    return sqrt(s);
}

/* A mark: ln |w(t)| of the unscaled w is ln |w| + what the renormalizations took out. */
static void tangent_mark(scene_run *c, double t, double r)
{
    if (c->lyap_reason[0]) return;
    if (!(r > 0) || !isfinite(r)) {
        snprintf(c->lyap_reason, sizeof c->lyap_reason, "the tangent vector %s at t = %.6g",
                 r > 0 ? "overflowed" : "vanished", t);
        return;
    }
    if (c->lyap_n == c->lyap_cap) {
        const long cap = c->lyap_cap ? 2 * c->lyap_cap : 256;
        double *a = realloc(c->lyap_t, sizeof(double) * (size_t)cap), *b = a ? realloc(c->lyap_g, sizeof(double) * (size_t)cap) : NULL;
        if (a) c->lyap_t = a;
        if (b) c->lyap_g = b;
        if (!a || !b) {
            snprintf(c->lyap_reason, sizeof c->lyap_reason, "out of memory");
            return;
        }
        c->lyap_cap = cap;
    }
    c->lyap_t[c->lyap_n] = t;
    c->lyap_g[c->lyap_n++] = log(r) + c->lyap_scale;
}

/* The marks k * interval (before t_end; the last row is the last mark) inside the accepted step,
 * on its interpolant; then w back to |w| in [1/2, 1) by a power of two (exact): the integration
 * goes on as from the scaled start, which for linear homogeneous equations is the same solution
 * scaled (Benettin's renormalization without stopping the state's steps). */
static void tangent_step(scene_run *c, const swim_ode_accepted *step)
{
    const double iv = c->var.interval, t0 = c->d.t_origin;
    double r = NAN;
    for (;;) {
        const double tm = (double)(c->lyap_n + 1) * iv;
        if (c->lyap_reason[0] || !(tm < c->set->t_end - 1e-9 * iv) || !(tm <= t0 + step->tb)) break;
        const double tau = fmin(fmax(tm - t0, step->ta), step->tb);
        const double *Y = tau == step->tb && step->y_end ? step->y_end
                        : step->interp(step->ctx, tau, c->var_buf, NULL) == 0 ? c->var_buf : NULL;
        r = Y ? tangent_norm(c, Y) : NAN;
        tangent_mark(c, tm, r);
    }
    if (isnan(r) || c->lyap_reason[0] || !(swim_ode_capabilities(swim_ode_method_name(c->ode)) & SWIM_ODE_CAP_RESCALE))
        return;
    int e;
    frexp(r, &e);
    if (e != 0 && swim_ode_scale(c->ode, (size_t)c->sdim + c->var.tangent_from, c->var.tangent_count, ldexp(1.0, -e)) == SWIM_ODE_OK)
        c->lyap_scale += e * 0.69314718055994530942;   /* ln 2 */
}

/* The augmented system's right-hand side and projection (params: the run): the caller's
 * right-hand side, and the state's projection (the columns are not projected). */
static int var_rhs(double t, const double *y, double *dydt, void *params)
{
    const scene_run *c = params;
    return c->var.rhs(t, y, dydt, c->var.ctx);
}

static int var_project(double t, double *y, void *params)
{
    scene_run *c = params;
    return swim_dynamics_project(t, y, &c->d);
}

/* The variational equations stop (the trajectory goes on): at the last row, for `why`. */
static void var_stop(scene_run *c, const char *why)
{
    if (!c->var_on) return;
    c->var_on = 0;
    c->var_t = c->t_last;
    snprintf(c->var_reason, sizeof c->var_reason, "%s", why);
    c->sys = c->sys_state;   /* the next integrator (a restart) carries the state alone */
    c->o.error_dim = 0;
    if (c->o.project == var_project) c->o.project = swim_dynamics_project;
}

static int accept_step(const swim_ode_accepted *step, void *data, double *t_stop)
{
    scene_run *c = data;
    int rc;
    if (c->var_on && c->var.interval > 0) tangent_step(c, step);
    const double t0 = c->d.t_origin;
    c->last_ta = t0 + step->ta;   /* swim_run_state_at: the interpolant's interval */
    c->last_tb = t0 + step->tb;
    c->last_origin = t0;
    c->have_step = 1;
    if (t0 == 0.0) {
        rc = swim_run_watch_step(step, &c->watch, t_stop);
        if (rc) c->left_native = *t_stop;
    } else {
        absolute_step a = {step, t0, t0 + step->ta, t0 + step->tb};
        const swim_ode_accepted abs_step = {a.ta, a.tb, absolute_interp, &a, step->y_end};
        double t_abs;
        rc = swim_run_watch_step(&abs_step, &c->watch, &t_abs);
        if (rc) {
            *t_stop = t_abs == a.tb ? step->tb : fmin(fmax(t_abs - t0, step->ta), step->tb);
            if (!(*t_stop > step->ta)) *t_stop = step->tb;
            c->left_native = *t_stop;
        }
    }
    if (c->watch.pend.balanced) c->bal_scale = swim_run_max_of(c->bal_scale, c->watch.pend.e);   /* pend.e = |E| */
    if (c->fw_on) forcing_step(c, step);
    if (!c->tol_scale || !step->y_end) return rc;
    const double j = barrier_tolerance(c, step->y_end, step->tb - step->ta);
    c->steps_since_shift++;
    if (!rc && impact_wanted(c, step->y_end, j)) return stop_for(c, step, 3, t_stop);
    if (rc || !c->shift_ok) return rc;
    const int want = shift_wanted(c, j, step->y_end);
    return want ? stop_for(c, step, want, t_stop) : 0;
}

/* ---- the rows ---------------------------------------------------------------------------- */

/* A scene with an [elastic] energy law has the law's W after the diagnostics (only then: other
 * scenes' columns are unchanged). */
static double w_law(const swim_run_quantities *q) { return q->g->w_law; }
static const swim_run_column law_column[] = {{"W_law", w_law}};

/* The table of a scene run's columns (driver/columns.h): its parts and their count. */
static int scene_parts(const swim_scene *s, swim_run_columns_part *parts)
{
    parts[0] = swim_run_diagnostics;
    parts[1] = (swim_run_columns_part){law_column, 1};
    return s->energy ? 2 : 1;
}

/* The columns of a scene run (swim_run_scene_kind.columns). */
static int scene_columns(const swim_scene *s, const char **names, char storage[][24])
{
    swim_run_columns_part parts[2];
    const int nparts = scene_parts(s, parts);
    return swim_run_column_names(s->n, parts, nparts, names, storage);
}

/* Every attempted step, in absolute time, to the sink (--trace-steps). */
static void trace_step(const swim_ode_step *st, void *data)
{
    scene_run *c = data;
    swim_ode_step abs_st = *st;
    abs_st.t = c->d.t_origin + st->t;
    c->req.sink.step(c->req.sink.ctx, &abs_st, &c->d);
}

static int packed_row(void *p, double t, const double *ys, int all, double *row);

/* The request's section on the integrator's state u (relative to the origin, constant between
 * restarts: the derivative is u's). */
static double section_g(double t, const double *u, const double *up, void *data)
{
    const scene_run *c = data;
    const int i = c->req.section->index;
    (void)t;
    if (c->req.section->kind != 'z') return up[i];
    return c->d.origin ? c->d.origin[i] + u[i] : u[i];
}

static void section_hit(const swim_ode_event_hit *hit, void *data)
{
    scene_run *c = data;
    if (c->req.section->hit(c->req.section->ctx, c->d.t_origin + hit->t)) c->sec_stop = 1;
}

static int prepare(scene_run *c)
{
    swim_scene *s = c->s;
    if (swim_dynamics_init(&c->d, s, c->kn->kernel) != 0) goto oom;
    c->d_ready = 1;
    c->d.interrupt = (volatile int *)c->req.stop;
    swim_dynamics_use_scene_kernel(&c->d, c->spz->scene, c->req.generic);
    c->sdim = swim_dynamics_state_dim(&c->d);
    c->ndim = c->sdim;
    c->y = calloc((size_t)c->d.dim, sizeof(double));
    c->row = calloc((size_t)c->ncol, sizeof(double));
    c->ys = calloc((size_t)c->sdim, sizeof(double));
    c->ys_last = calloc((size_t)c->sdim, sizeof(double));
    c->ys_row = calloc((size_t)c->sdim, sizeof(double));
    c->y_inside = calloc((size_t)c->d.dim, sizeof(double));
    if (!c->y || !c->row || !c->ys || !c->ys_last || !c->ys_row || !c->y_inside) goto oom;
    if (c->req.y0) {   /* a flow map's start */
        memcpy(c->ys, c->req.y0, sizeof(double) * (size_t)c->sdim);
        swim_dynamics_unpack(&c->d, c->ys, c->y);
    } else {
        swim_dynamics_initial_state(&c->d, c->y);
        swim_dynamics_pack(&c->d, c->y, c->ys);
    }
    memcpy(c->ys_last, c->ys, sizeof(double) * c->sdim);
    c->sys = (swim_ode_system){swim_dynamics_rhs, (size_t)c->sdim, &c->d, NULL};
    if (c->set->jacobian_exact && c->spz->scene->jacobian)   /* [run] jacobian: BDF methods use it */
        c->sys.jacobian = swim_dynamics_jacobian;
    c->sys_state = c->sys;
    swim_ode_options *o = &c->o;
    swim_run_ode_options_projected(c->set, o);
    swim_dynamics_track_balance(&c->d, 1);   /* the step checks and the balance test read it */
    /* by default where the scene has a barrier: its long stays near the wall (10^4-10^5 steps) are
     * where the drift adds up; a smooth paper scene at rtol 1e-8 keeps ~1e-10 without it, and would
     * pay 30-40 % more steps for 1e-12 (any scene can ask for it) */
    const int energy_control = c->set->energy_control < 0 ? s->barrier : c->set->energy_control;
    const unsigned caps = swim_ode_capabilities(c->set->integrator);
    if (energy_control && (caps & SWIM_ODE_CAP_INVARIANT)) {
        o->invariant = scaled_balance;
        o->invariant_data = c;
        o->invariant_tol = ENERGY_CONTROL * c->set->rtol;   /* abm never asks for less than B's rounding */
        c->invariant_on = 1;
    }
    o->stiff_stop = (caps & SWIM_ODE_CAP_STIFFNESS) != 0;   /* stop and report (or switch) on stiffness */
    if (c->req.sink.step && (caps & SWIM_ODE_CAP_STEP_TRACE)) {
        o->on_step = trace_step;
        o->on_step_data = c;
    }
    if (c->events) {
        c->rowc = (row_ctx){s, &c->d, calloc((size_t)c->d.dim, sizeof(double))};
        if (!c->rowc.full ||
            swim_run_events_attach(c->events, o, (size_t)c->sdim, 3 + 2 * s->n, packed_row, &c->rowc) != 0)
            goto oom;
    }
    if (c->req.section && !c->events) {
        const swim_run_section *sec = c->req.section;
        c->sec_ev = (swim_ode_event){section_g, c, sec->kind == 'x' ? -1 : +1, 0};
        o->events = &c->sec_ev;
        o->nevents = 1;
        o->on_event = section_hit;
        o->on_event_data = c;
        o->event_stop = &c->sec_stop;
    }
    if (caps & SWIM_ODE_CAP_EVENTS) {   /* dense output: the watch sees every accepted step */
        if (swim_run_watch_init(&c->watch, &c->d, c->sdim, 1) != 0) goto oom;
        c->watch_ready = 1;
        o->on_accept = accept_step;
        o->on_accept_data = c;
        if (s->forced) {
            c->fw_full = calloc((size_t)c->d.dim, sizeof(double));
            c->fw_ys = calloc((size_t)c->sdim, sizeof(double));
            if (!c->fw_full || !c->fw_ys) goto oom;
            c->fw_on = 1;
        }
        /* near the barrier: per-component weights (barrier_tolerance) and the shifted origin */
        if (s->barrier && (caps & SWIM_ODE_CAP_WEIGHTS)) {
            c->tol_scale = malloc(sizeof(double) * (size_t)c->sdim);
            if (!c->tol_scale) goto oom;
            for (int i = 0; i < c->sdim; i++) c->tol_scale[i] = 1.0;
            barrier_tolerance(c, c->ys, 0.0);
            o->tol_scale = c->tol_scale;
            c->ys_shift = malloc(sizeof(double) * (size_t)c->sdim);
            c->atolv = malloc(sizeof(double) * (size_t)c->sdim);
            if (!c->ys_shift || !c->atolv) goto oom;
            c->shift_ok = c->set->origin_shift;
        }
    }
    c->r.switch_t = -1.0;
    c->r.left_t = NAN;
    c->r.jmin_t = NAN;
    c->row_jmin = NAN;
    snprintf(c->r.used, sizeof c->r.used, "%s", c->set->integrator);
    return 0;
oom:
    return 1;
}

static int row_values(const swim_scene *s, double t, const double *y, const swim_diag *g, double *v)
{
    swim_run_columns_part parts[2];
    const int nparts = scene_parts(s, parts);
    const swim_run_quantities q = {g, NULL};
    return swim_run_column_values(t, y, s->n, &q, parts, nparts, v);
}

static void track(run_report *r, double t, const swim_diag *g, int first)
{
    if (first) { r->e0 = g->energy; r->jmin = INFINITY; }
    r->t_reached = t;
    r->drift_abs = swim_run_max_of(r->drift_abs, fabs(g->energy - r->e0 - g->work));
    r->emax = swim_run_max_of(r->emax, fabs(g->energy));
    if (g->jmin < r->jmin || isnan(g->jmin)) {
        r->jmin = g->jmin;
        r->jmin_t = t;
    }
    r->res_volume = swim_run_max_of(r->res_volume, fabs(g->res_volume));
    r->res_volume_rate = swim_run_max_of(r->res_volume_rate, fabs(g->res_volume_rate));
    r->res_angular = swim_run_max_of(r->res_angular, fabs(g->res_angular));
    r->res_locks = swim_run_max_of(r->res_locks, g->res_locks);   /* >= 0 (swim_constraint_residuals) */
}

/* The columns at integrator state ys for the event functions (swim_run_row_func): all, or t and
 * the state columns only (no diagnostics needed). */
static int packed_row(void *p, double t, const double *ys, int all, double *row)
{
    row_ctx *rc = p;
    swim_diag g;
    swim_dynamics_unpack(rc->d, ys, rc->full);
    if (!all) {
        row[0] = t;
        memcpy(row + 1, rc->full, sizeof(double) * (3 + 2 * rc->s->n));
        return 0;
    }
    if (swim_dynamics_diagnostics(rc->d, rc->full, &g) != 0) return -1;
    row_values(rc->s, t, rc->full, &g, row);
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
    total->rejected_invariant += st.rejected_invariant;
    total->jac_evals += st.jac_evals;
    for (int i = 0; i < 13; i++) total->order_hist[i] += st.order_hist[i];
    total->last_h = st.last_h;
    total->last_order = st.last_order;
    total->stiff_suspected |= st.stiff_suspected;
}

/* Why the run ended (printf-like); `failed` sets the status. */
static void end_run(scene_run *c, int failed, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void end_run(scene_run *c, int failed, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    free(c->r.reason);
    c->r.reason = swim_vstrprintf(fmt, ap);   /* NULL: reported as out of memory */
    va_end(ap);
    c->r.status = failed;
}
#define stop(c, ...) end_run((c), 1, __VA_ARGS__)

static void stop_by_signal(scene_run *c, double t)
{
    int sig = *c->req.stop;
    if (c->req.stop_by_caller) stop(c, "stopped by the caller at t = %.6g", t);
    else if (sig == SIGINT) stop(c, "interrupted (SIGINT) at t = %.6g", t);
    else stop(c, "terminated by %s at t = %.6g", sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal", t);
}


/* The remedy that keeps the scene as it is, when the run did not use it. */
static const char *impact_hint(const swim_run_settings *set)
{
    return set->impact_depth > 0 ? "" : ", or take such bounces as impacts (run.impact_depth, default 1e-16)";
}

/* With a barrier, why it did not stop the shape: from the last row inside D, how deep into the
 * barrier the kinetic energy there could carry the shape (shape/barrier.h, swim_barrier_reach),
 * compared with the resolution of J = |c_1|^2 - |h|^2 in double precision. Empty when the reach
 * is resolvable (then the crossing is not explained by the barrier's weakness). */
static void barrier_diagnosis(scene_run *c, char *buf, size_t len)
{
    buf[0] = '\0';
    const swim_scene *s = c->s;
    if (!s->barrier || !c->d.barrier) return;
    /* the integrator's last accepted state when it is inside D (closest to the failure), else the
     * last row inside D */
    double *full = malloc(sizeof(double) * (size_t)c->d.dim);
    if (!full) return;
    double *ys = malloc(sizeof(double) * (size_t)c->ndim), j0 = NAN;
    int have = ys && c->ode && swim_ode_dense(c->ode, swim_ode_time(c->ode), ys, NULL) == SWIM_ODE_OK;
    if (have) {
        swim_dynamics_unpack(&c->d, ys, full);
        j0 = swim_dynamics_jmin(&c->d, ys, NULL);
    }
    free(ys);
    if (!(j0 > 0)) {
        if (!c->have_inside) {
            free(full);
            return;
        }
        memcpy(full, c->y_inside, sizeof(double) * (size_t)c->d.dim);
        j0 = swim_shape_jmin(s->modes, full + 3);
    }
    const double *x = full + 3, c1 = x[0] * x[0] + x[1] * x[1];
    swim_bounce bn;
    const double T = bounce_at(c, full, &bn) == 0 ? bn.normal_kinetic : NAN;
    double kappa = NAN;
    double reach = swim_barrier_reach(c->d.barrier, x, s->epsilon, s->alpha, T, &kappa);
    if (!(kappa > 0) && c->have_inside) {
        /* a shape deeper than its rounding (J(x) <= 0, shifted coordinates): kappa, which follows
         * J'' at the foot and barely changes with depth, from the last row inside D */
        swim_barrier_reach(c->d.barrier, c->y_inside + 3, s->epsilon, s->alpha, T, &kappa);
        if (kappa > 0 && fabs(s->alpha - 0.5) < 1e-12) reach = j0 * exp(-T / kappa);
    }
    free(full);
    /* Without shifted coordinates the shape is known to rounding, which moves J by ~4u |c_1|^2
     * (u = 2^-53) and so W2 by kappa 4u |c_1|^2 / min J: deeper than where that exceeds rtol of
     * the energy scale, a bounce cannot be followed to the tolerance. With them (abm), rounding
     * is no longer the limit; what remains is time itself: a bounce to min J turns within
     * ~min J / |dJ/dt|, and the step sizes, the forces (~kappa / min J) and their rounding follow
     * it: a failure inside a bounce deeper than SHIFT_DEEP |c_1|^2 is put down to its depth. */
    const double escale = fmax(fmax(c->r.emax, T), 1e-300);
    const double floor_j = kappa * 4.0 * 1.11e-16 * c1 / (c->set->rtol * escale);
    if (!(kappa > 0) || !(c->shift_ok ? j0 < SHIFT_DEEP * c1 : reach < floor_j)) return;
    if (reach > 0 && c->shift_ok)
        snprintf(buf, len, "; at min J = %.3g the barrier (alpha = %g, epsilon = %g) rises by only %.3g per e-fold "
                 "of min J, and absorbing the kinetic energy still moving toward the boundary (%.3g) takes min J "
                 "down to ~1e%d: abm, in coordinates shifted to the bounce, could not follow it; "
                 "use alpha >= 1, a larger epsilon or a looser rtol%s",
                 j0, s->alpha, s->epsilon, kappa, T, (int)floor(log10(reach)), impact_hint(c->set));
    else if (reach > 0)
        snprintf(buf, len, "; at min J = %.3g the barrier (alpha = %g, epsilon = %g) rises by only %.3g per e-fold "
                 "of min J, and absorbing the kinetic energy still moving toward the boundary (%.3g) takes min J "
                 "down to ~1e%d, where the rounding of the shape (~1e-16 in J = |c1|^2 - |h|^2) moves W2 by "
                 "more than rtol of the energy (min J < %.1e): double precision cannot follow this bounce "
                 "without run.origin_shift; use alpha >= 1, a larger epsilon or a looser rtol%s",
                 j0, s->alpha, s->epsilon, kappa, T, (int)floor(log10(reach)), floor_j, impact_hint(c->set));
    else
        snprintf(buf, len, "; the barrier (alpha = %g < 1/2, epsilon = %g) is finite at the boundary of D and "
                 "cannot stop the kinetic energy moving toward it (%.3g)", s->alpha, s->epsilon, T);
}

/* The shape left D at t (4.1): the crossing of min J = 0, located at a step (see advance_to). */
static void stop_left_D(scene_run *c, double t)
{
    char why[1024];
    barrier_diagnosis(c, why, sizeof why);
    stop(c, "left D at t = %.10g: the shape left the admissible set D (min J reaches 0 on the circle, (4.1))%s%s", t,
         c->s->barrier ? "; the barrier did not stop it" : "; the scene has no barrier", why);
}

/* Why the integrator could not reach t. */
static void stop_on_integrator(scene_run *c, int rc, double t)
{
    const swim_scene *s = c->s;
    if (stop_requested(c)) {
        stop_by_signal(c, c->r.t_reached);
        return;
    }
    /* A forcing law that is finite at t0 (checked when the scene is read) may not stay so. */
    if (s->forced && !swim_expr_defined(s->forcing, c->d.last_rhs_t, NULL, 0)) {
        stop(c, "the forcing law is NaN or Inf at t = %.9g", fmin(c->d.last_rhs_t, c->set->forcing_finite_until));
        return;
    }
    if (rc == SWIM_ODE_ERHS && swim_ode_rhs_status(c->ode) == SWIM_DYN_EBARRIER)
        stop_left_D(c, c->r.left_t);
    else {
        /* near the boundary of D with a barrier too weak to be resolved, that is the cause */
        char why[1024];
        barrier_diagnosis(c, why, sizeof why);
        if (rc == SWIM_ODE_ERHS)
            stop(c, "%s near t = %.6g%s", swim_dynamics_strerror(swim_ode_rhs_status(c->ode)), c->d.last_rhs_t, why);
        else if (rc == SWIM_ODE_ESTIFF && !why[0])
            stop(c, "stiffness detected near t = %.6g: Adams PECE is "
                 "stability-limited here; rerun with --integrator cvode-bdf (or msbdf), or remove "
                 "[run] stiff_fallback = \"none\" from the scene (the default switches to cvode-bdf)",
                 c->ode ? ode_time(c) : t);
        else
            stop(c, "%s near t = %.6g%s", swim_ode_strerror(rc), c->ode ? ode_time(c) : t, why);
    }
}

/* Restart from the last output row (exact state there) with the stiff fallback integrator. */
static int switch_to_fallback(scene_run *c, double t_last, double t)
{
    double ts = ode_time(c);
    accumulate_stats(&c->total, c->ode);
    swim_ode_free(c->ode);
    c->ode = NULL;
    /* for the user even in a quiet run: the rest of the run is computed by another method than asked for */
    notice(c, "swim run: stiffness detected near t = %.6g; switching from %s to %s at t = %.6g",
           ts, c->set->integrator, c->set->stiff_fallback, t_last);
    c->r.switch_t = t_last;
    swim_run_events_rewind(c->events, t_last);   /* the fallback locates them again from t_last */
    if (c->watch_ready) swim_run_watch_rewind(&c->watch, t_last);
    if (c->fw_on) forcing_rewind(c, t_last);
    snprintf(c->r.used, sizeof c->r.used, "%s+%s", c->set->integrator, c->set->stiff_fallback);
    memcpy(c->ys, c->ys_last, sizeof(double) * c->ndim);
    if (c->var_on && c->var.interval > 0) {   /* the tangent vector as it was at the row */
        while (c->lyap_n > 0 && c->lyap_t[c->lyap_n - 1] > t_last) c->lyap_n--;
        c->lyap_scale = c->lyap_scale_row;
    }
    if (c->d.origin || c->d.t_origin != 0.0) {
        /* the fallback carries the absolute state, the row's (c->y, projected), in absolute time */
        swim_dynamics_set_origin(&c->d, NULL);
        swim_dynamics_pack(&c->d, c->y, c->ys);
        c->o.atol_vec = NULL;
        c->d.t_origin = 0.0;
        swim_run_events_time_origin(c->events, 0.0);
    }
    c->shift_ok = 0;
    c->shift_pending = 0;
    c->o.stiff_stop = 0;
    const unsigned caps = swim_ode_capabilities(c->set->stiff_fallback);
    if (!(caps & SWIM_ODE_CAP_PROJECTION)) c->o.project = NULL;
    if (!(caps & SWIM_ODE_CAP_WEIGHTS)) c->o.tol_scale = NULL;   /* the cut near the barrier is abm's */
    if (!(caps & SWIM_ODE_CAP_INVARIANT)) c->o.invariant = NULL;
    if (!(caps & SWIM_ODE_CAP_STEP_TRACE)) c->o.on_step = NULL;
    if (c->var_on && c->o.error_dim && !(caps & SWIM_ODE_CAP_ERROR_DIM)) {
        /* it would put them into its error control, and the trajectory would change with them */
        char why[200];
        snprintf(why, sizeof why, "the stiff fallback %s at t = %.6g cannot leave them out of its error control",
                 c->set->stiff_fallback, t_last);
        var_stop(c, why);
    }
    int rc = swim_ode_create(c->set->stiff_fallback, &c->sys, &c->o, t_last, c->ys, &c->ode);
    return rc == SWIM_ODE_OK ? swim_ode_advance(c->ode, t, c->ys) : rc;
}

/* The integrator stopped at shift_t (accept_step): close it, keeping its statistics, and take
 * the state it accepted there. */
static void stop_at_shift(scene_run *c)
{
    accumulate_stats(&c->total, c->ode);
    swim_ode_free(c->ode);
    c->ode = NULL;
    memcpy(c->ys, c->ys_shift, sizeof(double) * (size_t)c->ndim);
    c->shift_pending = 0;
}

/* A new integrator `method` from c->ys at its time tau0 (absolute d.t_origin + tau0), on to
 * tout. An ODE status. */
static int resume(scene_run *c, const char *method, double tau0, double tout)
{
    barrier_tolerance(c, c->ys, 0.0);
    int rc = swim_ode_create(method, &c->sys, &c->o, tau0, c->ys, &c->ode);
    if (rc != SWIM_ODE_OK || !(tout - c->d.t_origin > tau0)) return rc;   /* at tout already: ys is its state */
    return swim_ode_advance(c->ode, tout - c->d.t_origin, c->ys);
}

/* The integrator stopped at shift_t (accept_step): start it again from the state there, relative
 * to the new origin (or to none), and go on to tout. An ODE status. */
static int shift_origin(scene_run *c, double tout)
{
    const int clear = c->shift_pending == 2;
    stop_at_shift(c);
    if (swim_dynamics_rebase(&c->d, c->ys, clear) != 0) return SWIM_ODE_ENOMEM;
    /* the clock too: t0' + tau0 = t0 + shift_t exactly (TwoSum), the integrator starts at tau0 */
    const double a = c->d.t_origin, b = c->shift_t, t0 = a + b, bb = t0 - a;
    const double tau0 = (a - (t0 - bb)) + (b - bb);
    c->d.t_origin = t0;
    swim_run_events_time_origin(c->events, t0);
    c->shifts++;
    c->steps_since_shift = 0;
    /* abm weighs errors by rtol |y_i| + atol; with u = y - origin small that is rtol |u_i| + atol_i */
    if (c->d.origin) {
        for (int i = 0; i < c->ndim; i++) c->atolv[i] = c->set->atol + (i < c->sdim ? c->set->rtol * fabs(c->d.origin[i]) : 0.0);
        c->o.atol_vec = c->atolv;
    } else {
        c->o.atol_vec = NULL;
    }
    return resume(c, c->set->integrator, tau0, tout);
}

/* The integrator stopped at shift_t (accept_step) at the step end where a bounce becomes an
 * impact: start it again from the state there with the reflected cdot (model/bounce.h), at the
 * same origin and clock, and go on to tout. An ODE status. */
static int take_impact(scene_run *c, double tout)
{
    stop_at_shift(c);
    const swim_scene_kernel *k = c->d.spec;
    for (int f = 0; f < k->nfree; f++) c->ys[3 + k->nfree + f] += c->impact_dv[k->free_index[f]];
    const double t = c->d.t_origin + c->shift_t;
    /* the variational equations would need the impact's jump (a saltation matrix) */
    var_stop(c, "an impact (a bounce off the barrier taken as a jump of cdot)");
    if (c->impacts++ == 0) {
        c->impact_first_t = t;
        c->impact_j_max = c->impact_j;
        c->impact_reach_min = c->impact_reach;
        /* for the user even in a quiet run: from here on the run is the impulsive limit of the bounce */
        notice(c, "swim run: t = %.10g: a bounce off the barrier predicted to turn at min J ~ %.1e |c1|^2 "
               "(below run.impact_depth = %g) taken as an impact at min J = %.2e |c1|^2 (docs/barrier.md); "
               "summary.json counts them",
               t, c->impact_reach, c->set->impact_depth, c->impact_j);
    }
    c->impact_last_t = t;
    c->impact_j_max = fmax(c->impact_j_max, c->impact_j);
    c->impact_reach_min = fmin(c->impact_reach_min, c->impact_reach);
    return resume(c, c->r.switch_t >= 0 ? c->set->stiff_fallback : c->set->integrator, c->shift_t, tout);
}

/* Advance to output time *t and leave the row's full state in c->y. A :stop event before *t
 * ends the run there: *t becomes the event time, whose row is the last. An ODE status. */
static int advance_to(scene_run *c, double *t, double *t_last)
{
    double ta = c->out_clock > 0 ? c->out_clock : swim_clock_seconds();   /* chained: one read less a row */
    c->out_clock = 0;
    int rc = swim_ode_advance(c->ode, *t - c->d.t_origin, c->ys);
    while (rc == SWIM_ODE_TERMINATED && c->shift_pending && swim_ode_time(c->ode) == c->shift_t)
        rc = c->shift_pending == 3 ? take_impact(c, *t) : shift_origin(c, *t);
    if (rc == SWIM_ODE_ESTIFF && c->set->stiff_fallback[0] && c->r.switch_t < 0 && !stop_requested(c)) {
        /* An alarm raised by a bounce off the barrier that double precision cannot follow is
         * not stiffness: BDF's larger steps would only cross the unresolved wall with a wrong
         * energy. The run stops there, saying why (stop_on_integrator). */
        char why[1024];
        barrier_diagnosis(c, why, sizeof why);
        if (!why[0]) rc = switch_to_fallback(c, *t_last, *t);
    }
    if (rc == SWIM_ODE_TERMINATED && c->watch_ready && c->watch.left && swim_ode_time(c->ode) == c->left_native) {
        *t = c->watch.t_left;   /* min J reached 0 inside a step: ys holds the state at the crossing */
        c->r.left_t = *t;
        c->r.left_stop = 1;
        rc = SWIM_ODE_OK;
    } else if (rc == SWIM_ODE_TERMINATED && c->sec_stop) {   /* the section's hit ended the run there */
        *t = ode_time(c);
        end_run(c, 0, "ended at an event of the section at t = %.10g", *t);
        c->r.event_stop = 1;
        rc = SWIM_ODE_OK;
    } else if (rc == SWIM_ODE_TERMINATED) {   /* ys holds the state at the event */
        *t = ode_time(c);
        if (swim_run_events_caller_stopped(c->events))   /* the caller's listener said stop */
            stop(c, "stopped by the caller at event %s at t = %.10g", swim_run_events_stop_name(c->events), *t);
        else
            end_run(c, 0, "stopped by event %s at t = %.10g", swim_run_events_stop_name(c->events), *t);
        c->r.event_stop = 1;
        rc = SWIM_ODE_OK;
    } else if (rc == SWIM_ODE_ERHS && swim_ode_rhs_status(c->ode) == SWIM_DYN_EBARRIER && !stop_requested(c)) {
        /* Every trial state beyond the crossing was refused, so the integrator crept up to it
         * with ever smaller steps until the step size underflowed: its last accepted state is
         * the crossing (to a few units of rounding in t). Its row is the last. */
        const double tb = ode_time(c);
        c->r.left_t = tb;
        if (tb > *t_last && tb < *t && swim_ode_dense(c->ode, swim_ode_time(c->ode), c->ys, NULL) == SWIM_ODE_OK) {
            *t = tb;
            c->r.left_stop = 1;
            rc = SWIM_ODE_OK;
        }
    }
    /* the integration ends here; what follows prepares the row and is its diagnostics' (one clock
     * read ends the one and starts the other: a read costs about a tenth of Example 3's RHS) */
    c->row_clock = swim_clock_seconds();
    c->r.integrate_seconds += c->row_clock - ta;
    if (rc != SWIM_ODE_OK) return rc;
    const double tr = *t;
    /* Rows come from the interpolant, which leaves the constraint manifold by the local error
     * between two projected steps: project the row as well (a copy; the integrator's state is
     * untouched). */
    const double *row = c->ys;
    if (c->o.project && c->ode) {
        memcpy(c->ys_row, c->ys, sizeof(double) * c->sdim);
        c->o.project(tr, c->ys_row, c->sys.params);
        row = c->ys_row;
    }
    swim_dynamics_unpack(&c->d, row, c->y);
    c->row_jmin = c->d.origin ? swim_dynamics_jmin(&c->d, row, NULL) : NAN;
    memcpy(c->ys_last, c->ys, sizeof(double) * c->ndim);
    c->lyap_scale_row = c->lyap_scale;
    *t_last = tr;
    if (c->fw_on) forcing_row(c, tr);
    if (c->watch_ready) swim_run_watch_mark(&c->watch);   /* where a stiff fallback would restart */
    return SWIM_ODE_OK;
}

/* Diagnostics, the CSV row and maybe a snapshot at t. 0, or -1 when the run must stop. */
static int emit_row(scene_run *c, long k, long rows, long every, double t)
{
    swim_diag g;
    const double t_diag = c->row_clock > 0 ? c->row_clock : swim_clock_seconds();
    c->row_clock = 0;
    const int diag_rc = swim_dynamics_diagnostics(&c->d, c->y, &g);
    if (diag_rc != 0) {
        c->r.diagnostics_seconds += swim_clock_seconds() - t_diag;
        stop(c, "diagnostics failed at t = %.6g (K not positive definite)", t);
        return -1;
    }
    if (!isnan(c->row_jmin)) g.jmin = c->row_jmin;   /* the rounded row may show 0 in a deep bounce */
    track(&c->r, t, &g, k == 0);
    c->last_energy = g.energy;
    c->last_work = g.work;
    if (g.jmin > 0) {
        memcpy(c->y_inside, c->y, sizeof(double) * (size_t)c->d.dim);
        c->kinetic_inside = g.kinetic_fluid + g.kinetic_shape + g.kinetic_rigid;
        c->have_inside = 1;
    }
    const double t_out = swim_clock_seconds();   /* the diagnostics end, the output begins */
    c->r.diagnostics_seconds += t_out - t_diag;
    row_values(c->s, t, c->y, &g, c->row);
    swim_run_row row = {k, t, c->row, c->ncol, c->y, &c->d, 0};
    if ((k % every == 0 || k > rows || c->r.event_stop) && c->nsnap < SWIM_RUN_SNAPSHOTS + 1) {
        row.snapshot = 1;
        c->nsnap++;
    }
    char why[1024] = "";
    int rc = c->req.sink.row ? c->req.sink.row(c->req.sink.ctx, &row, why, sizeof why) : 0;
    if (rc == 0 || rc == SWIM_RUN_ROW_STOP) c->r.rows++;   /* kept (with --summary-only: computed) */
    if (rc == 0 && c->var_on && c->var.row && c->var.row(c->var.row_ctx, t, c->ys, why, sizeof why) != 0)
        rc = SWIM_RUN_ROW_FAILED;
    if (rc == 0 && c->var_on) c->var_t = t;
    c->out_clock = swim_clock_seconds();
    c->r.output_seconds += c->out_clock - t_out;
    if (rc != 0) {
        stop(c, "%s (at t = %.6g)", why[0] ? why : "an output could not be written", t);
        return -1;
    }
    if (!(g.jmin > 0)) {   /* only at a crossing located by the watch, or without dense output */
        c->r.left_t = t;
        stop_left_D(c, t);
        return -1;
    }
    return 0;
}

/* The maxima and min J over the accepted steps into the report, which holds those over the rows.
 * A run that ended at its last row (t_end, a :stop event, the crossing) counts the last step up
 * to that row only; a failed one every step it accepted. */
static void take_watch(run_report *r, swim_run_watch *w)
{
    swim_run_watch_finish(w, r->status == 0 || r->left_stop ? r->t_reached : INFINITY);
    const swim_run_watch_results *s = &w->r;
    if (s->jmin < r->jmin || isnan(s->jmin)) {
        r->jmin = s->jmin;
        r->jmin_t = s->jmin_t;
    }
    r->drift_abs = fmax(r->drift_abs, s->drift_abs);
    r->emax = fmax(r->emax, s->emax);
    r->res_volume = fmax(r->res_volume, s->res_volume);
    r->res_volume_rate = fmax(r->res_volume_rate, s->res_volume_rate);
    r->res_angular = fmax(r->res_angular, s->res_angular);
    r->res_locks = fmax(r->res_locks, s->res_locks);
}

/* The output loop, one row at a time (swim_run_advance stops between rows): rows at
 * k*output_step up to t_end, stopping at the first failure. */
static void start_loop(scene_run *c)
{
    c->loop_started = 1;
    c->t_start = swim_clock_seconds();
    c->t_last = 0.0;
    c->loop_rc = swim_ode_create(c->set->integrator, &c->sys, &c->o, 0.0, c->ys, &c->ode);
    c->nrows = (long)floor(c->set->t_end / c->set->output_step + 1e-9);
    c->every = c->nrows / (SWIM_RUN_SNAPSHOTS - 1) > 0 ? c->nrows / (SWIM_RUN_SNAPSHOTS - 1) : 1;
    if (c->loop_rc != SWIM_ODE_OK) {
        stop(c, "integrator '%s' could not start: %s", c->set->integrator, swim_ode_strerror(c->loop_rc));
        c->loop_done = 1;
    }
}

/* The time of row k, or NAN past the last row. */
static double row_time(const scene_run *c, long k)
{
    double t = k <= c->nrows ? k * c->set->output_step : c->set->t_end;
    if (k == c->nrows && fabs(t - c->set->t_end) < 1e-9 * c->set->output_step) t = c->set->t_end;
    if (k > c->nrows && (c->nrows * c->set->output_step >= c->set->t_end * (1 - 1e-12))) return NAN;
    if (k > c->nrows + 1) return NAN;
    return t;
}

/* Row c->k: 0, or 1 when the run has ended (its last row written, or a failure). */
static int next_row(scene_run *c)
{
    const swim_scene *s = c->s;
    const long k = c->k;
    double t = row_time(c, k);
    if (isnan(t)) return 1;
    if (s->forced && t >= c->set->forcing_finite_until) {   /* found when the settings were checked */
        stop(c, "the forcing law is NaN or Inf at t = %.9g; stopped before the step to t = %.6g",
             c->set->forcing_finite_until, t);
        return 1;
    }
    if (k > 0 && (c->loop_rc = advance_to(c, &t, &c->t_last)) != SWIM_ODE_OK) {
        stop_on_integrator(c, c->loop_rc, t);
        return 1;
    }
    if (emit_row(c, k, c->nrows, c->every, t) != 0) return 1;
    c->k++;
    if (k == 0 && c->watch_ready) c->watch.e0 = c->r.e0;
    if (k == 0) c->bal_scale = fabs(c->r.e0);
    if (c->r.left_stop) {
        stop_left_D(c, t);
        return 1;
    }
    if (stop_requested(c)) {
        stop_by_signal(c, t);
        return 1;
    }
    if (c->r.event_stop) return 1;   /* the row at the event was the last */
    if (c->req.sink.progress) {
        c->out_clock = 0;   /* the report's time is the caller's, not the next row's */
        c->req.sink.progress(c->req.sink.ctx, t, c->set->t_end);
    }
    return 0;
}

static void finish_loop(scene_run *c)
{
    if (c->ndim > c->sdim && c->var.interval > 0) {
        /* marks beyond the last row (in its step) are not the run's; the last row is the last mark */
        const double tl = c->var_on ? c->t_last : c->var_t;
        while (c->lyap_n > 0 && c->lyap_t[c->lyap_n - 1] > tl) c->lyap_n--;
        if (c->var_on && tl > 0 && (c->lyap_n == 0 || c->lyap_t[c->lyap_n - 1] < tl)) {
            c->lyap_scale = c->lyap_scale_row;
            tangent_mark(c, tl, tangent_norm(c, c->ys_last));
        }
    }
    if (c->r.status == 0 && !c->r.event_stop) end_run(c, 0, "reached t_end = %.6g", c->set->t_end);
    if (c->ode) accumulate_stats(&c->total, c->ode);
    if (c->watch_ready) take_watch(&c->r, &c->watch);
}

/* Rows up to time t (every row at or before it); the run's end when it comes. */
static void advance_rows(scene_run *c, double t)
{
    if (!c->loop_started) start_loop(c);
    while (!c->loop_done) {
        const double tk = row_time(c, c->k);
        if (!isnan(tk) && tk > t) break;
        if (next_row(c)) c->loop_done = 1;
    }
    c->out_clock = 0;   /* the time until the next call is the caller's */
}


/* The kernel of N modes (diagnostics) and the scene's right-hand side or the stroke's laws:
 * linked in, cached, or generated and compiled now (runtime/codegen); then the magnitude check of
 * a dynamic scene's initial state, which needs the kernel (a stroke's runs on the stroke's own
 * initial state, when its run opens). 0; 1 when no kernel could be had; 2 for a law the generator
 * refuses or numbers that overflow. */
void swim_run_ode_options(const swim_run_settings *set, swim_ode_options *o)
{
    swim_ode_options_default(o);
    o->rtol = set->rtol;
    o->atol = set->atol;
    if (set->step_lookahead >= 0) o->lookahead = set->step_lookahead;
}

void swim_run_ode_options_projected(const swim_run_settings *set, swim_ode_options *o)
{
    swim_run_ode_options(set, o);
    if (set->projection && (swim_ode_capabilities(set->integrator) & SWIM_ODE_CAP_PROJECTION))
        o->project = swim_dynamics_project;   /* drift control */
}

/* ---- the scene kind (driver/run.h, swim_run_kind) ------------------------------------------- */

/* The report and the features of the run into its public result. */
static void fill_result(scene_run *c)
{
    swim_run_result *res = &c->res;
    const run_report *r = &c->r;
    res->status = r->status;
    res->reason = r->reason;
    res->t_reached = r->t_reached;
    res->rows = r->rows;
    res->e0 = r->e0;
    res->drift_abs = r->drift_abs;
    res->emax = r->emax;
    res->res_volume = r->res_volume;
    res->res_volume_rate = r->res_volume_rate;
    res->res_angular = r->res_angular;
    res->res_locks = r->res_locks;
    res->jmin = r->jmin;
    res->jmin_t = r->jmin_t;
    res->left_t = r->left_t;
    res->switch_t = r->switch_t;
    snprintf(res->used, sizeof res->used, "%s", r->used);
    res->event_stop = r->event_stop;
    res->stats = c->total;
    res->integrate_seconds = r->integrate_seconds;
    res->diagnostics_seconds = r->diagnostics_seconds;
    res->output_seconds = r->output_seconds;
    res->wall_seconds = swim_clock_seconds() - c->t_start;
    res->projection = c->set->projection && (swim_ode_capabilities(c->set->integrator) & SWIM_ODE_CAP_PROJECTION);
    res->step_checks = c->watch_ready;
    res->step_check_steps = c->watch.r.steps;
    res->step_check_seconds = swim_clock_sample_total(&c->watch.time);
    res->origin_shift_enabled = c->shift_ok || c->shifts;
    res->shifts = c->shifts;
    res->impacts_enabled = c->ys_shift && c->set->impact_depth > 0;
    res->impacts = c->impacts;
    res->impact_first_t = c->impact_first_t;
    res->impact_last_t = c->impact_last_t;
    res->impact_j_max = c->impact_j_max;
    res->impact_reach_min = c->impact_reach_min;
    res->energy_control = c->invariant_on;
    res->energy_control_tol = c->invariant_on ? c->o.invariant_tol : 0.0;
    res->final_state = c->y;
    res->energy = c->last_energy;
    res->work = c->last_work;
    res->forcing_work = !c->s->forced ? 0.0 : c->fw_on ? c->fw_at_row : NAN;
    res->step_lookahead = c->o.lookahead;
}

/* What the summary says of the model and its kernel: fixed when the run opens. */
static void describe(scene_run *c)
{
    const swim_scene *s = c->s;
    swim_run_result *res = &c->res;
    res->effects.elastic = s->elastic;
    res->effects.barrier = s->barrier;
    res->effects.damping = s->damped;
    res->effects.forcing = s->forced;
    res->effects.energy_law = s->energy_text;
    res->compiled = c->spz;
    res->kernel_kind = c->d.generic ? "generic" : "specialized";
    res->state_dimension = swim_dynamics_state_dim(&c->d);
    res->projection_change = s->projection_change;
    res->impact_depth = c->set->impact_depth;
    res->jacobian = c->sys_state.jacobian ? "exact" : "differences";   /* what the BDF methods use */
}

static void scene_free(void *p);

static int scene_open(const swim_run_request *req, void **out, swim_status *st)
{
    *out = NULL;
    scene_run *c = calloc(1, sizeof *c);
    if (!c) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    c->req = *req;
    c->s = req->scene;
    c->set = req->settings;
    c->kn = req->kernel;
    c->spz = req->system;
    c->events = req->events;
    c->ncol = scene_columns(c->s, c->names, c->storage);
    const int prc = prepare(c);
    c->req.y0 = NULL;   /* copied by prepare, not kept */
    if (prc != 0) {
        scene_free(c);
        swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
        return 1;
    }
    /* the result before any row: the run's features, nothing found yet */
    fill_result(c);
    c->res.wall_seconds = 0.0;
    c->res.forcing_work = 0.0;
    describe(c);
    *out = c;
    return 0;
}

static int scene_advance(void *p, double t)
{
    scene_run *c = p;
    if (c->res.finished) return c->r.status;
    advance_rows(c, t);
    if (c->loop_done) {
        finish_loop(c);
        fill_result(c);
        c->res.finished = 1;
    } else {
        fill_result(c);   /* so far: the reason and the summary's wall time are the end's */
    }
    return c->r.status;
}

static void scene_fail(void *p, const char *reason)
{
    scene_run *c = p;
    if (c->r.status == 0) stop(c, "%s", reason);
    c->res.status = c->r.status;
    c->res.reason = c->r.reason;
}

static const swim_run_result *scene_result(void *p)
{
    scene_run *c = p;
    const swim_dynamics *d = &c->d;
    swim_run_result *res = &c->res;
    res->projection_steps = d->projections;
    res->projection_max_change = d->max_projection;
    res->rhs_calls = d->rhs_calls;
    res->rhs_seconds = swim_dynamics_rhs_seconds(d);
    res->jacobian_calls = d->jac_calls;
    res->jacobian_seconds = d->jac_seconds;
    return res;
}

static int scene_state_at(void *p, double t, double *state, double *t_from, double *t_to)
{
    scene_run *c = p;
    if (!c->ode || !c->have_step || c->last_origin != c->d.t_origin) return -1;
    *t_from = c->last_ta;
    *t_to = c->last_tb;
    if (!(t >= c->last_ta && t <= c->last_tb)) return 1;
    double *ys = malloc(sizeof(double) * (size_t)c->ndim), *full = malloc(sizeof(double) * (size_t)c->d.dim);
    int rc = !ys || !full ? -1 : swim_ode_dense(c->ode, t - c->d.t_origin, ys, NULL) == SWIM_ODE_OK ? 0 : -1;
    if (rc == 0) {   /* as a row is made (advance_to): the interpolant projected, then unpacked */
        if (c->o.project) c->o.project(t, ys, c->sys.params);
        swim_dynamics_unpack(&c->d, ys, full);
        memcpy(state, full, sizeof(double) * (size_t)(3 + 2 * c->s->n));
    }
    free(ys);
    free(full);
    return rc;
}

static swim_dynamics *scene_dynamics(void *p) { return &((scene_run *)p)->d; }

/* *p (n doubles) grown to m, the new entries `fill`. 0 or -1. */
static int grow(double **p, int n, int m, double fill)
{
    if (!*p) return 0;
    double *q = realloc(*p, sizeof(double) * (size_t)m);
    if (!q) return -1;
    for (int i = n; i < m; i++) q[i] = fill;
    *p = q;
    return 0;
}

static int scene_set_variational(void *p, const swim_run_variational *v, swim_status *st)
{
    scene_run *c = p;
    if (c->loop_started || c->ndim > c->sdim || v->dim == 0 || !v->rhs) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "variational equations: attach them once, before the run");
        return 2;
    }
    const unsigned caps = swim_ode_capabilities(c->set->integrator);
    const unsigned need = (v->error_control ? 0u : SWIM_ODE_CAP_ERROR_DIM) |
                          (v->interval > 0 ? SWIM_ODE_CAP_ERROR_DIM | SWIM_ODE_CAP_EVENTS | SWIM_ODE_CAP_RESCALE : 0u);
    if ((caps & need) != need) {
        swim_status_fail(st, NULL, NULL, 0, NULL, "integrator %s cannot carry %s on the run's steps outside its error "
                         "control; use one of: %s", c->set->integrator,
                         v->interval > 0 ? "the Lyapunov tangent vector" : "the sensitivities", swim_ode_method_list_with(need));
        return 2;
    }
    const int n = c->sdim, m = c->sdim + (int)v->dim;
    /* their Jacobians between the state's evaluations, and the diagnostics of their rows, must
     * not move the warm starts of the run's own (model/dynamics.h) */
    if (swim_dynamics_set_aside(&c->d) != 0) goto oom;
    if (grow(&c->ys, n, m, 0.0) || grow(&c->ys_last, n, m, 0.0) || grow(&c->ys_row, n, m, 0.0) ||
        grow(&c->ys_shift, n, m, 0.0) || grow(&c->atolv, n, m, c->set->atol) || grow(&c->tol_scale, n, m, 1.0) ||
        grow(&c->fw_ys, n, m, 0.0) || !(c->var_buf = calloc((size_t)m, sizeof(double))) ||
        (free(c->var_final), !(c->var_final = malloc(sizeof(double) * (size_t)m))))
        goto oom;
    if (c->watch_ready) {   /* its buffer takes the interpolant's whole vector */
        swim_run_watch_free(&c->watch);
        c->watch_ready = 0;
        if (swim_run_watch_init(&c->watch, &c->d, m, 1) != 0) goto oom;
        c->watch_ready = 1;
    }
    memcpy(c->ys + n, v->y0, sizeof(double) * v->dim);
    memcpy(c->ys_last + n, v->y0, sizeof(double) * v->dim);
    c->var = *v;
    c->var.y0 = NULL;
    c->ndim = m;
    c->var_on = 1;
    c->sys = (swim_ode_system){var_rhs, (size_t)m, c, NULL};
    if (c->o.project) c->o.project = var_project;
    /* the state's error control alone, or with the sensitivities (the tangent vector is never in it) */
    const size_t controlled = v->error_control ? (v->interval > 0 ? v->tangent_from : v->dim) : 0;
    c->o.error_dim = (size_t)n + controlled < (size_t)m ? (size_t)n + controlled : 0;
    if (c->o.tol_scale) c->o.tol_scale = c->tol_scale;
    return 0;
oom:
    swim_status_fail(st, NULL, NULL, 0, NULL, "out of memory");
    return 1;
}

static const swim_run_var_result *scene_var_result(void *p)
{
    scene_run *c = p;
    swim_run_var_result *r = &c->var_res;
    r->carried = c->var_on;
    r->t_stop = c->var_on ? c->t_last : c->var_t;
    r->reason = c->var_reason;
    r->marks = c->lyap_n;
    r->t = c->lyap_t;
    r->log_norm = c->lyap_g;
    r->tangent_reason = c->lyap_reason;
    r->final = NULL;
    if (!c->var_final && c->ndim == c->sdim) c->var_final = malloc(sizeof(double) * (size_t)c->sdim);
    if ((c->var_on || c->ndim == c->sdim) && c->var_final) {   /* the last row's, the state part absolute */
        memcpy(c->var_final, c->ys_last, sizeof(double) * (size_t)c->ndim);
        for (int i = 0; c->d.origin && i < c->sdim; i++) c->var_final[i] += c->d.origin[i];
        r->final = c->var_final;
    }
    return r;
}

static void scene_free(void *p)
{
    scene_run *c = p;
    if (!c) return;
    free(c->rowc.full);
    if (c->watch_ready) swim_run_watch_free(&c->watch);
    swim_ode_free(c->ode);
    if (c->d_ready) swim_dynamics_free(&c->d);
    free(c->y);
    free(c->row);
    free(c->ys);
    free(c->ys_last);
    free(c->ys_row);
    free(c->y_inside);
    free(c->tol_scale);
    free(c->ys_shift);
    free(c->atolv);
    free(c->fw_full);
    free(c->fw_ys);
    free(c->var_buf);
    free(c->var_final);
    free(c->lyap_t);
    free(c->lyap_g);
    free(c->r.reason);
    free(c);
}

const swim_run_kind swim_run_scene_kind = {
    "scene", scene_columns, scene_open, scene_advance, scene_fail, scene_result, scene_state_at, scene_dynamics,
    NULL, scene_set_variational, scene_var_result, scene_free,
};
