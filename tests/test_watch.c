/* Checks at every accepted step: the ODE layer's on_accept report and swim_ode_dense, and the
 * run's watch (driver/watch.h) on paths of the shape whose minimum of J and crossing of J = 0
 * are known in closed form. */
#include "check.h"
#include "driver/watch.h"
#include "kernel/coords.h"
#include "model/dynamics.h"
#include "ode/ode.h"
#include "ode_problems.h"
#include "shape/constraints.h"
#include "shape/shape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* ---- on_accept -------------------------------------------------------------------------- */

/* Records the steps; asks to stop where y0 = cos t first falls to -1/2 (t = 2 pi / 3), located
 * on the step's interpolant by bisection. */
typedef struct {
    int steps, gaps, stops;
    double last_tb, worst_interp, t_stop;
} accept_log;

static int on_accept(const swim_ode_accepted *st, void *data, double *t_stop)
{
    accept_log *L = data;
    double y[2], yp[2];
    if (L->steps && st->ta != L->last_tb) L->gaps++;
    L->steps++;
    L->last_tb = st->tb;
    const double tm = 0.5 * (st->ta + st->tb);
    if (st->interp(st->ctx, tm, y, yp) == 0)
        L->worst_interp = fmax(L->worst_interp, fabs(y[0] - cos(tm)) + fabs(yp[0] + sin(tm)));
    st->interp(st->ctx, st->tb, y, NULL);
    if (y[0] > -0.5) return 0;
    double a = st->ta, b = st->tb;
    while (b - a > 1e-14) {
        const double c = 0.5 * (a + b);
        st->interp(st->ctx, c, y, NULL);
        if (y[0] > -0.5) a = c; else b = c;
    }
    L->stops++;
    L->t_stop = b;
    *t_stop = b;
    return 1;
}

typedef struct {
    int n;
    double t[8];
} event_log;

static void on_event(const swim_ode_event_hit *hit, void *data)
{
    event_log *L = data;
    if (L->n < 8) L->t[L->n++] = hit->t;
}

static double ev_y0(double t, const double *y, const double *yp, void *d)
{
    (void)t; (void)yp; (void)d;
    return y[0];
}

static double ev_dy0(double t, const double *y, const double *yp, void *d)
{
    (void)t; (void)y; (void)d;
    return yp[0];
}

static void test_on_accept(void)
{
    swim_ode_system sys = {ho_rhs, 2, NULL, NULL};
    const double y0[2] = {1.0, 0.0};
    static const char *const methods[] = {"abm", "cvode-adams", "cvode-bdf"};
    for (int m = 0; m < 3; m++) {
        accept_log L;
        event_log E;
        memset(&L, 0, sizeof L);
        memset(&E, 0, sizeof E);
        /* the zero of y0 at pi/2 comes before the stop, the minimum at pi after it */
        swim_ode_event ev[2] = {{ev_y0, NULL, 0, 0}, {ev_dy0, NULL, +1, 0}};
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-11;
        o.atol = 1e-13;
        o.on_accept = on_accept;
        o.on_accept_data = &L;
        o.events = ev;
        o.nevents = 2;
        o.on_event = on_event;
        o.on_event_data = &E;
        swim_ode *s = NULL;
        int rc = swim_ode_create(methods[m], &sys, &o, 0.0, y0, &s);
        double y[2], t = 0.0;
        for (int k = 1; rc == SWIM_ODE_OK && k <= 40; k++) {
            t = 0.25 * k;
            rc = swim_ode_advance(s, t, y);
        }
        const double ts = 2.0 * PI / 3.0;
        CHECK(rc == SWIM_ODE_TERMINATED && L.stops == 1, "%s: stopped by on_accept (rc %d, %d stops)", methods[m], rc,
              L.stops);
        CHECK(t >= L.t_stop && t - 0.25 < L.t_stop, "%s: the advance whose tout passes the stop ends (%g, stop %g)",
              methods[m], t, L.t_stop);
        CHECK(fabs(swim_ode_time(s) - L.t_stop) == 0.0 && fabs(L.t_stop - ts) < 1e-9,
              "%s: time %.15g = stop %.15g = 2 pi/3", methods[m], swim_ode_time(s), L.t_stop);
        CHECK(fabs(y[0] + 0.5) < 1e-9 && fabs(y[1] + sin(ts)) < 1e-9, "%s: y at the stop (%.12g, %.12g)", methods[m],
              y[0], y[1]);
        CHECK(L.gaps == 0 && L.steps > 5, "%s: %d contiguous steps reported (%d gaps)", methods[m], L.steps, L.gaps);
        /* the interpolant of the step, not of another one (BDF's interpolant between steps is the
         * least accurate of the three: ~2e-8 here) */
        CHECK(L.worst_interp < 1e-6, "%s: interp inside the step (error %.3g)", methods[m], L.worst_interp);
        CHECK(E.n == 1 && fabs(E.t[0] - PI / 2) < 1e-9, "%s: the event before the stop only (%d events, first %g)",
              methods[m], E.n, E.n ? E.t[0] : NAN);
        swim_ode_stats st;
        swim_ode_get_stats(s, &st);
        CHECK(st.steps == L.steps, "%s: every accepted step reported (%ld vs %d)", methods[m], st.steps, L.steps);
        swim_ode_free(s);
    }
    /* integrators without dense output ignore on_accept; swim_ode_dense says it has none */
    accept_log L;
    memset(&L, 0, sizeof L);
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.on_accept = on_accept;
    o.on_accept_data = &L;
    swim_ode *s = NULL;
    double y[2];
    int rc = swim_ode_create("rk8pd", &sys, &o, 0.0, y0, &s);
    if (rc == SWIM_ODE_OK) rc = swim_ode_advance(s, 10.0, y);
    CHECK(rc == SWIM_ODE_OK && L.steps == 0, "rk8pd: on_accept ignored (rc %d, %d reports)", rc, L.steps);
    CHECK(swim_ode_dense(s, 10.0, y, NULL) == SWIM_ODE_EUNSUPPORTED, "rk8pd: no dense output");
    swim_ode_free(s);
    /* swim_ode_dense after an advance: the last step's interpolant */
    swim_ode_options_default(&o);
    o.rtol = 1e-11;
    o.atol = 1e-13;
    rc = swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    if (rc == SWIM_ODE_OK) rc = swim_ode_advance(s, 3.0, y);
    const double tr = swim_ode_time(s);
    double yd[2], ypd[2];
    CHECK(rc == SWIM_ODE_OK && swim_ode_dense(s, tr, yd, ypd) == SWIM_ODE_OK && fabs(yd[0] - cos(tr)) < 1e-9 &&
              fabs(ypd[0] + sin(tr)) < 1e-9, "abm: swim_ode_dense at the time reached %g", tr);
    swim_ode_free(s);
}

/* ---- the watch -------------------------------------------------------------------------- */

/* A path of shapes with N = 2: c_1 = 1, c_-1 = 0.1, c_-2 = s(t) > 0 real, so J = 1 - |0.1 + 2 s w|^2
 * with w = e^{-i theta}: min J = 1 - (0.1 + 2 s)^2 at theta = 0, with s(t) = s0 + a sin(pi t). */
typedef struct {
    double s0, a;
    int n;
} path;

static int path_interp(void *ctx, double t, double *y, double *yp)
{
    const path *p = ctx;
    memset(y, 0, sizeof(double) * (4 + 2 * p->n));
    const double s = p->s0 + p->a * sin(PI * t), ds = p->a * PI * cos(PI * t);
    y[3] = 1.0;            /* a1 */
    y[3 + 2] = 0.1;        /* a-1 */
    y[3 + 4] = s;          /* a-2 */
    y[3 + p->n + 4] = ds;  /* its velocity */
    if (yp) memset(yp, 0, sizeof(double) * (4 + 2 * p->n));
    return 0;
}

static void test_watch(void)
{
    const swim_kernel *k = swim_kernel_find(2);
    CHECK(k != NULL, "kernel N = 2 linked in");
    if (!k) return;
    static swim_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.modes = 2;
    sc.n = 6;
    sc.rho0 = sc.rhof = 1.0;
    sc.c0[0] = 1.0;
    for (int i = 0; i < sc.n; i++) sc.free_mask[i] = 1;
    static const int free_index[6] = {0, 1, 2, 3, 4, 5};
    swim_scene_kernel spec = {.abi = SWIM_KERNEL_ABI, .modes = 2, .nfull = 6, .nfree = 6,
                              .free_index = free_index, .structure = "test"};
    swim_dynamics d;
    CHECK(swim_dynamics_init(&d, &sc, k) == 0, "dynamics");
    swim_dynamics_use_scene_kernel(&d, &spec, 0);
    const int sdim = swim_dynamics_state_dim(&d);

    /* s = 0.3 + 0.1 sin(pi t) over one step [0, 1]: both ends at J = 1 - 0.7^2, the minimum
     * 1 - 0.9^2 = 0.19 at t = 1/2 inside the step */
    path p = {0.3, 0.1, 6};
    swim_run_watch w;
    CHECK(swim_run_watch_init(&w, &d, sdim, 1) == 0, "watch");
    double ts = -1;
    swim_ode_accepted st = {0.0, 1.0, path_interp, &p, NULL};
    int stop = swim_run_watch_step(&st, &w, &ts);
    CHECK(stop == 0 && !w.left, "a dip that stays in D does not stop");
    /* a run ending at t = 0.4, inside the step, keeps what lies before: J(0) = 0.51 */
    swim_run_watch_results before = w.r;
    swim_run_watch_pending pend = w.pend;
    swim_run_watch_finish(&w, 0.4);
    CHECK(fabs(w.r.jmin - 0.51) < 1e-14 && w.r.jmin_t == 0.0, "run ending inside the step: min J %.17g at %g",
          w.r.jmin, w.r.jmin_t);
    w.r = before;
    w.pend = pend;
    swim_run_watch_finish(&w, INFINITY);
    CHECK(fabs(w.r.jmin - 0.19) < 1e-14 && fabs(w.r.jmin_t - 0.5) < 1e-7,
          "min J inside the step: %.17g at t = %.12g (want 0.19 at 0.5)", w.r.jmin, w.r.jmin_t);
    /* the next step [1, 2]: s decreases then increases, min J at its ends */
    st = (swim_ode_accepted){1.0, 2.0, path_interp, &p, NULL};
    swim_run_watch_step(&st, &w, &ts);
    swim_run_watch_finish(&w, INFINITY);
    CHECK(w.r.steps == 2 && fabs(w.r.jmin - 0.19) < 1e-14, "a later step with larger J keeps the minimum");
    swim_run_watch_free(&w);

    /* s = 0.3 + 0.25 sin(pi t): J = 0.51 at both ends of [0, 1], 1 - 1.2^2 < 0 at 1/2; the
     * crossing 0.1 + 2 s = 1 at sin(pi t) = 0.6 */
    p.a = 0.25;
    CHECK(swim_run_watch_init(&w, &d, sdim, 1) == 0, "watch");
    st = (swim_ode_accepted){0.0, 1.0, path_interp, &p, NULL};
    stop = swim_run_watch_step(&st, &w, &ts);
    const double tc = asin(0.6) / PI;
    CHECK(stop == 1 && w.left && ts == w.t_left, "a dip out of D inside a step stops (%d)", stop);
    CHECK(fabs(ts - tc) < 1e-12 && ts >= tc, "crossing at %.15g, want %.15g (on the far side)", ts, tc);
    swim_run_watch_finish(&w, ts);
    CHECK(fabs(w.r.jmin) < 1e-11 && w.r.jmin_t == ts, "min J at the crossing %.3g at %.15g", w.r.jmin, w.r.jmin_t);
    swim_run_watch_free(&w);

    /* the rate of min J is its time derivative (envelope theorem) at a shape with all modes */
    double x[6] = {1.0, 0.1, 0.3, -0.05, 0.1, 0.12}, v[6] = {0.02, -0.1, 0.3, 0.2, -0.4, 0.1}, th;
    swim_shape_jmin_at(2, x, &th);
    const double rate = swim_shape_j_rate(2, x, v, th), e = 1e-6;
    double xp[6], xm[6];
    for (int i = 0; i < 6; i++) {
        xp[i] = x[i] + e * v[i];
        xm[i] = x[i] - e * v[i];
    }
    const double fd = (swim_shape_jmin(2, xp) - swim_shape_jmin(2, xm)) / (2 * e);
    CHECK(fabs(rate - fd) < 1e-8, "d/dt min J %.12g vs central difference %.12g", rate, fd);
    /* mirror-symmetric shapes (real coefficients, alternating signs): by the triangle inequality
     * the minimum of J lies at theta = pi, on a sample of swim_shape_jmin_at, where the refined value
     * may be a rounding above the sample's; the angle must still be pi (the rate at a wrong angle
     * put spurious sign changes of d/dt min J into Section 5.2's steps) */
    int wrong = 0;
    double worst = 0.0;
    srand(7);
    for (int trial = 0; trial < 200; trial++) {
        const int modes = 3 + trial % 5, nn = 2 * (modes + 1);
        double xs[16] = {0}, vs[16] = {0}, xsp[16], xsm[16], ths;
        xs[0] = 1.0;
        for (int m = 1; m <= modes; m++) {
            xs[2 * m] = (m % 2 ? 1.0 : -1.0) * (0.02 + 0.2 * rand() / (double)RAND_MAX) / (m * modes);
            vs[2 * m] = rand() / (double)RAND_MAX - 0.5;   /* a real velocity keeps the mirror */
        }
        vs[0] = 0.1;
        swim_shape_jmin_at(modes, xs, &ths);
        for (int i = 0; i < nn; i++) {
            xsp[i] = xs[i] + e * vs[i];
            xsm[i] = xs[i] - e * vs[i];
        }
        const double r = swim_shape_j_rate(modes, xs, vs, ths);
        const double f = (swim_shape_jmin(modes, xsp) - swim_shape_jmin(modes, xsm)) / (2 * e);
        if (fabs(ths - PI) > 1e-6) wrong++;
        worst = fmax(worst, fabs(r - f));
    }
    CHECK(wrong == 0 && worst < 1e-7, "mirror shapes: %d of 200 angles not pi; worst d/dt min J vs central "
          "difference %.3g", wrong, worst);
    CHECK(swim_shape_in_D(2, x) == 1, "in D");
    double out[6] = {1.0, 0.0, 0.0, 0.0, 0.6, 0.0};   /* min J = 1 - 1.44 */
    CHECK(swim_shape_in_D(2, out) == 0 && fabs(swim_shape_jmin(2, out) + 0.44) < 1e-14, "outside D");
    /* a coefficient that is not a number: so is min J, and the shape is not in D */
    double bad[8] = {1.0, 0.0, 0.1, 0.0, 0.05, 0.0, NAN, 0.0};
    CHECK(isnan(swim_shape_jmin(3, bad)) && swim_shape_in_D(3, bad) == 0, "NaN coefficient: min J %g, in D %d",
          swim_shape_jmin(3, bad), swim_shape_in_D(3, bad));
    swim_dynamics_free(&d);
}

/* J(theta) = |c_1|^2 - |h|^2, h = sum_m m c_-m conj(z)^(m-1), z = e^{i theta} (ERRATA B2), summed
 * here independently of runtime/shape. */
static double j_direct(int modes, const double *x, double theta)
{
    double hr = 0.0, hi = 0.0;
    for (int m = 1; m <= modes; m++) {
        const double a = -(m - 1) * theta, re = m * x[2 * m], im = m * x[2 * m + 1];
        hr += re * cos(a) - im * sin(a);
        hi += re * sin(a) + im * cos(a);
    }
    return x[0] * x[0] + x[1] * x[1] - (hr * hr + hi * hi);
}

/* min J of random shapes with several dips against a fine sampling: never above the samples'
 * minimum, never below it by more than the sampling can miss, and the value is J at the angle
 * returned. */
static void test_jmin_sampled(void)
{
    enum { FINE = 20000 };
    int above = 0, below = 0, angle = 0, tried = 0;
    srand(11);
    for (int trial = 0; trial < 300; trial++) {
        const int modes = 3 + trial % 10;
        double x[2 * 13 + 2] = {0}, s0 = 0.0, s1 = 0.0, s2 = 0.0;   /* sums of (m-1)^j |m c_-m| */
        x[0] = 1.0;
        for (int m = 1; m <= modes; m++) {
            const double r = (0.1 + 0.8 * rand() / (double)RAND_MAX) / (m * sqrt((double)modes));
            const double phi = 2.0 * PI * rand() / (double)RAND_MAX;
            x[2 * m] = r * cos(phi);
            x[2 * m + 1] = r * sin(phi);
            s0 += m * r;
            s1 += (m - 1.0) * m * r;
            s2 += (m - 1.0) * (m - 1.0) * m * r;
        }
        double th, fine = INFINITY;
        const double J = swim_shape_jmin_at(modes, x, &th);
        for (int k = 0; k < FINE; k++) fine = fmin(fine, j_direct(modes, x, 2.0 * PI * k / FINE));
        /* |J''| <= 2 (s1^2 + s0 s2), and a minimum lies within half a spacing of a sample */
        const double miss = 2.0 * (s1 * s1 + s0 * s2) * (2.0 * PI / FINE) * (2.0 * PI / FINE) / 8.0 + 1e-13;
        tried++;
        above += J > fine + 1e-13;
        below += J < fine - miss;
        angle += fabs(j_direct(modes, x, th) - J) > 1e-13;
    }
    CHECK(tried == 300 && above == 0 && below == 0 && angle == 0,
          "min J of %d random shapes against %d samples: %d above the samples' minimum, %d below by more than "
          "they can miss, %d whose value is not J at its angle", tried, FINE, above, below, angle);
}

/* min J and its rate in closed form (P of degree <= 1 in w) against the sampled minimum and the
 * rate at its angle: J to the bit, the rate to rounding; a higher degree, or p_1 = 0, is left to
 * the angle (0 returned). */
static void test_jmin_rate(void)
{
    srand(11);
    int bits = 0, handled = 0, wrong = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 2000; trial++) {
        const int modes = 1 + trial % 7;
        double x[16] = {0}, v[16] = {0}, th, J, rate;
        x[0] = 1.0 + 0.1 * (rand() / (double)RAND_MAX - 0.5);
        x[1] = 0.1 * (rand() / (double)RAND_MAX - 0.5);
        const int top = trial % 3 ? (modes < 2 ? modes : 2) : modes;   /* the modes above `top` at 0 */
        for (int i = 0; i < 2 * (top + 1); i++) {
            if (i >= 2) x[i] = 0.3 * (rand() / (double)RAND_MAX - 0.5) / top;
            v[i] = rand() / (double)RAND_MAX - 0.5;
        }
        const double J0 = swim_shape_jmin_at(modes, x, &th), r0 = swim_shape_j_rate(modes, x, v, th);
        if (!swim_shape_jmin_rate(modes, x, v, &J, &rate)) {
            wrong += top <= 2;   /* refused where it has a closed form */
            continue;
        }
        handled++;
        wrong += top > 2;        /* taken where it has none */
        bits += memcmp(&J, &J0, sizeof J) != 0;
        worst = fmax(worst, fabs(rate - r0) / (1.0 + fabs(r0)));
    }
    CHECK(handled > 1000 && wrong == 0 && bits == 0 && worst < 1e-13, "closed-form min J and rate: %d shapes "
          "(%d taken or refused wrongly), %d values of J not those of swim_shape_jmin_at, worst rate difference "
          "%.3g", handled, wrong, bits, worst);
    double x[6] = {1.0, 0.0, 0.0, 0.0, 0.3, 0.1}, v[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6}, J, rate;
    CHECK(swim_shape_jmin_rate(2, x, v, &J, &rate) == 0, "p_1 = 0: |p_1| has no derivative, the angle decides");
}

/* The shortcuts of the checks at every step give the bits of what they replace: the inline
 * maximum those of fmax (NaN on either side included), the area constant without the modes at 0
 * those of swim_area_constant (signed zeros, and squares that underflow to 0, included). */
static void test_same_bits(void)
{
    const double vals[] = {0.0, 1.0, 2.5, 1e-300, INFINITY, NAN};
    const int nv = (int)(sizeof vals / sizeof vals[0]);
    int differ = 0;
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nv; j++) {
            const double a = swim_run_max_of(vals[i], vals[j]), b = fmax(vals[i], vals[j]);
            differ += memcmp(&a, &b, sizeof a) != 0;
        }
    CHECK(differ == 0, "swim_run_max_of: %d of %d pairs not fmax's bits", differ, nv * nv);
    srand(5);
    differ = 0;
    for (int trial = 0; trial < 1000; trial++) {
        const int n = 2 * (2 + trial % 7);
        double c[16];
        for (int i = 0; i < n; i++) {
            const int kind = rand() % 5;   /* 0, -0, a tiny value whose square is 0, or an ordinary one */
            c[i] = kind == 0 ? 0.0 : kind == 1 ? -0.0 : kind == 2 ? 1e-170 * (rand() % 2 ? 1 : -1)
                                                               : rand() / (double)RAND_MAX - 0.5;
        }
        const double a = swim_area_constant_moving(n, c), b = swim_area_constant(n, c);
        differ += memcmp(&a, &b, sizeof a) != 0;
    }
    CHECK(differ == 0, "swim_area_constant_moving: %d of 1000 shapes not swim_area_constant's bits", differ);
}

int main(void)
{
    test_on_accept();
    test_watch();
    test_jmin_rate();
    test_jmin_sampled();
    test_same_bits();
    return check_report("test_watch");
}
