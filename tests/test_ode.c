/* Tests of the ODE module: the ABM stepper and the peers behind swim_ode. */
#include "check.h"
#include "ode/abm.h"
#include "ode/ode.h"
#include "ode_problems.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static const double AREN_MU = 0.012277471;
static const double AREN_T = 17.0652165601579625588917206249;
static const double AREN_Y0[4] = { 0.994, 0.0, 0.0, -2.00158510637908252240537862224 };
static int arenstorf_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    double mu = AREN_MU, mp = 1.0 - mu;
    double d1 = pow((y[0] + mu) * (y[0] + mu) + y[1] * y[1], 1.5);
    double d2 = pow((y[0] - mp) * (y[0] - mp) + y[1] * y[1], 1.5);
    f[0] = y[2];
    f[1] = y[3];
    f[2] = y[0] + 2 * y[3] - mp * (y[0] + mu) / d1 - mu * (y[0] - mp) / d2;
    f[3] = y[1] - 2 * y[2] - mp * y[1] / d1 - mu * y[1] / d2;
    return 0;
}

/* y' = -1000 (y - cos t) - sin t, solution cos t: stiff for explicit methods */
static int stiff_rhs(double t, const double *y, double *f, void *p)
{
    (void)p;
    f[0] = -1000.0 * (y[0] - cos(t)) - sin(t);
    return 0;
}

/* smooth but with a sharp pulse at t = 5 that forces rejections */
static int pulse_rhs(double t, const double *y, double *f, void *p)
{
    (void)p;
    double z = (t - 5.0) / 0.02;
    f[0] = -0.1 * y[0] + 30.0 * exp(-z * z);
    f[1] = y[0] - y[1];
    return 0;
}

static int failing_rhs(double t, const double *y, double *f, void *p)
{
    (void)p;
    if (t > 1.0)
        return 42;
    f[0] = -y[0];
    return 0;
}

/* y' = -y + cos t, y(0) = 1/2: y = (cos t + sin t)/2, |y| <= 0.71.  The RHS
 * reports a domain failure (+1) when |y| >= bound, a region the exact solution
 * never reaches, so only trial states of too large steps are refused; after
 * t > fatal_t (if set) it returns fatal_rc (negative: fatal, positive: a
 * domain failure from which no step can recover). */
typedef struct {
    double bound, fatal_t;
    int fatal_rc;
    long calls, dom_fails, calls_after_fatal;
    int seen_fatal;
} dom_par;

static int dom_rhs(double t, const double *y, double *f, void *p)
{
    dom_par *d = p;
    d->calls++;
    if (d->seen_fatal)
        d->calls_after_fatal++;
    if (d->fatal_rc && t > d->fatal_t) {
        if (d->fatal_rc < 0)
            d->seen_fatal = 1;
        return d->fatal_rc;
    }
    if (!(fabs(y[0]) < d->bound)) {
        d->dom_fails++;
        return 1;
    }
    f[0] = -y[0] + cos(t);
    return 0;
}

/* Kepler with a RHS that refuses (+1) exactly the call numbered fail_call. */
typedef struct {
    long calls, fail_call;
} inject_par;

static int inject_rhs(double t, const double *y, double *f, void *p)
{
    inject_par *q = p;
    if (q->calls++ == q->fail_call)
        return 1;
    return kepler_rhs(t, y, f, NULL);
}

/* y' = -y + cos t (y(0) = 1/2), returning inj_rc once, from call number
 * inj_call on.  A positive value stands for a state outside the domain, so it
 * is not returned for a repeat of the last successful call (same t and y):
 * GSL's evolve evaluates f at the accepted state again at the start of each
 * step, outside its retry logic, and a function of (t, y) cannot fail there. */
typedef struct {
    long calls, inj_call, calls_after;
    int inj_rc, injected;
    double last_t, last_y;
} sweep_par;

static int sweep_rhs(double t, const double *y, double *f, void *p)
{
    sweep_par *q = p;
    long c = q->calls++;
    if (q->injected)
        q->calls_after++;
    int repeat = c > 0 && t == q->last_t && y[0] == q->last_y;
    if (c >= q->inj_call && !q->injected && (q->inj_rc < 0 || !repeat)) {
        q->injected = 1;
        return q->inj_rc;
    }
    q->last_t = t;
    q->last_y = y[0];
    f[0] = -y[0] + cos(t);
    return 0;
}

static int reject_project(double t, double *y, void *p)
{
    (void)y; (void)p;
    return t > 1.0 ? 3 : 0;
}

static void kepler_init(double e, double *y)
{
    y[0] = 1.0 - e;
    y[1] = 0.0;
    y[2] = 0.0;
    y[3] = sqrt((1.0 + e) / (1.0 - e));
}

static double run(const char *method, const swim_ode_system *sys, double rtol, double atol, double t0,
                  const double *y0, double t1, double *y, swim_ode_stats *st, int *status)
{
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = rtol;
    o.atol = atol;
    swim_ode *s = NULL;
    int rc = swim_ode_create(method, sys, &o, t0, y0, &s);
    if (rc == 0)
        rc = swim_ode_advance(s, t1, y);
    if (st && s)
        swim_ode_get_stats(s, st);
    swim_ode_free(s);
    *status = rc;
    return 0;
}

static void test_harmonic(void)
{
    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 }, y[2];
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-10;
    o.atol = 1e-10;
    swim_ode *s;
    CHECK(swim_ode_create(NULL, &sys, &o, 0.0, y0, &s) == 0, "create abm");
    CHECK(strcmp(swim_ode_method_name(s), "abm") == 0, "default method is abm");
    double maxerr = 0;
    int ok = 1;
    for (int i = 1; i <= 50; i++) {
        double t = 0.4 * i;
        ok &= swim_ode_advance(s, t, y) == 0;
        maxerr = fmax(maxerr, fmax(fabs(y[0] - cos(t)), fabs(y[1] + sin(t))));
    }
    CHECK(ok, "advance ok");
    CHECK(maxerr < 1e-8, "harmonic oscillator max error %g", maxerr);
    swim_ode_stats st;
    swim_ode_get_stats(s, &st);
    long sum = 0;
    int maxord = 0;
    for (int k = 0; k <= 12; k++) {
        sum += st.order_hist[k];
        if (st.order_hist[k])
            maxord = k;
    }
    CHECK(sum == st.steps && st.steps > 0, "order histogram sums to steps (%ld vs %ld)", sum, st.steps);
    CHECK(st.rhs_evals >= 2 * st.steps && st.rhs_evals <= 2 * (st.steps + st.rejected) + 1,
          "PECE: 2 evaluations per step (%ld evals, %ld steps)", st.rhs_evals, st.steps);
    CHECK(maxord >= 8, "high order used at tight tolerance (max order %d)", maxord);
    CHECK(st.last_h > 0 && st.last_order >= 1 && !st.stiff_suspected, "stats fields");
    CHECK(swim_ode_time(s) >= 20.0, "internal time covers tout");
    swim_ode_free(s);

    /* every method behind the same interface */
    for (const char *const *m = swim_ode_methods(); *m; m++) {
        int rc;
        swim_ode_stats st2;
        run(*m, &sys, 1e-9, 1e-9, 0.0, y0, 10.0, y, &st2, &rc);
        double err = fmax(fabs(y[0] - cos(10.0)), fabs(y[1] + sin(10.0)));
        CHECK(rc == 0 && err < 1e-5, "%s: status %d error %g", *m, rc, err);
        CHECK(st2.rhs_evals > 0 && st2.steps > 0, "%s: stats", *m);
    }
}

static void test_kepler(void)
{
    swim_ode_system sys = { kepler_rhs, 4, NULL, NULL };
    double y0[4], y[4];
    kepler_init(0.5, y0);
    double E0 = 0.5 * (y0[2] * y0[2] + y0[3] * y0[3]) - 1.0 / hypot(y0[0], y0[1]);
    double L0 = y0[0] * y0[3] - y0[1] * y0[2];
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-12;
    o.atol = 1e-12;
    swim_ode *s;
    CHECK(swim_ode_create("abm", &sys, &o, 0.0, y0, &s) == 0, "create");
    double dE = 0, dL = 0;
    int ok = 1;
    for (int i = 1; i <= 100; i++) {
        ok &= swim_ode_advance(s, 0.2 * PI * i, y) == 0;   /* 10 periods */
        double E = 0.5 * (y[2] * y[2] + y[3] * y[3]) - 1.0 / hypot(y[0], y[1]);
        double L = y[0] * y[3] - y[1] * y[2];
        dE = fmax(dE, fabs(E - E0));
        dL = fmax(dL, fabs(L - L0));
    }
    CHECK(ok, "kepler advance");
    CHECK(dE < 1e-9, "Kepler energy drift %g", dE);
    CHECK(dL < 1e-9, "Kepler angular momentum drift %g", dL);
    double err = 0;
    for (int i = 0; i < 4; i++)
        err = fmax(err, fabs(y[i] - y0[i]));
    CHECK(err < 1e-7, "Kepler orbit closes after 10 periods (error %g)", err);
    swim_ode_free(s);
}

static void test_arenstorf(void)
{
    swim_ode_system sys = { arenstorf_rhs, 4, NULL, NULL };
    const double *y0 = AREN_Y0;
    double y[4];
    int rc;
    swim_ode_stats st;
    run("abm", &sys, 1e-12, 1e-12, 0.0, y0, AREN_T, y, &st, &rc);
    double err = 0;
    for (int i = 0; i < 4; i++)
        err = fmax(err, fabs(y[i] - y0[i]));
    CHECK(rc == 0 && err < 1e-6, "Arenstorf orbit closes after one period (error %g)", err);
    /* and it really went around: at half period it is far from the start */
    run("abm", &sys, 1e-10, 1e-10, 0.0, y0, 0.5 * AREN_T, y, &st, &rc);
    CHECK(rc == 0 && fabs(y[0] - y0[0]) > 0.5, "Arenstorf half period is elsewhere (x = %g)", y[0]);
}

/* Exact Kepler orbit (mu = 1, a = 1, period 2 pi) from pericentre, as kepler_init:
 * eccentric anomaly E from Kepler's equation E - e sin E = t by Newton. */
static void kepler_exact(double e, double t, double *y)
{
    double E = t;
    for (int i = 0; i < 60; i++) {
        double dE = (E - e * sin(E) - t) / (1.0 - e * cos(E));
        E -= dE;
        if (fabs(dE) < 1e-16)
            break;
    }
    double c = cos(E), s = sin(E), q = sqrt(1.0 - e * e), d = 1.0 - e * c;
    y[0] = c - e;
    y[1] = q * s;
    y[2] = -s / d;
    y[3] = q * c / d;
}

/* Global error roughly proportional to the tolerance over four decades.  The error is the
 * largest over 64 times along two orbits, against the exact solution: at a single instant
 * signed local errors can cancel and give an outlier far below the trend (measured: 5 tol at
 * 1e-8 between 30 and 150 tol at the neighbouring tolerances). */
static void test_proportionality(void)
{
    swim_ode_system sys = { kepler_rhs, 4, NULL, NULL };
    double y0[4], y[4], ye[4];
    kepler_init(0.5, y0);
    double d0 = 0, d1 = 0;
    kepler_exact(0.5, 0.0, ye);
    for (int c = 0; c < 4; c++)
        d0 = fmax(d0, fabs(ye[c] - y0[c]));
    kepler_exact(0.5, 2 * PI, ye);
    for (int c = 0; c < 4; c++)
        d1 = fmax(d1, fabs(ye[c] - y0[c]));
    CHECK(d0 < 1e-15 && d1 < 1e-14, "exact Kepler orbit starts at kepler_init and closes (%g, %g)", d0, d1);
    double lt[5], le[5];
    int m = 0;
    for (int j = 0; j <= 4; j++) {
        double tol = pow(10.0, -6.0 - j), err = 0;
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = o.atol = tol;
        swim_ode *s = NULL;
        int rc = swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
        for (int i = 1; i <= 64 && rc == 0; i++) {
            double t = 4 * PI * i / 64;
            rc = swim_ode_advance(s, t, y);
            kepler_exact(0.5, t, ye);
            for (int c = 0; c < 4; c++)
                err = fmax(err, fabs(y[c] - ye[c]));
        }
        swim_ode_free(s);
        CHECK(rc == 0, "proportionality run %d", rc);
        lt[m] = log10(tol);
        le[m] = log10(err);
        m++;
    }
    /* least-squares slope of log(err) against log(tol) */
    double mt = 0, me = 0, sxy = 0, sxx = 0;
    for (int i = 0; i < m; i++) { mt += lt[i] / m; me += le[i] / m; }
    for (int i = 0; i < m; i++) { sxy += (lt[i] - mt) * (le[i] - me); sxx += (lt[i] - mt) * (lt[i] - mt); }
    double slope = sxy / sxx, worst = 0;
    for (int i = 0; i < m; i++)
        worst = fmax(worst, fabs(le[i] - (me + slope * (lt[i] - mt))));
    CHECK(slope > 0.8 && slope < 1.25, "error ~ tolerance: slope %.3f", slope);
    CHECK(worst < 0.6, "error/tolerance ratio stays within a factor 4 of the fit (%.2f decades)", worst);
    CHECK(le[4] < le[0] - 3.0, "four decades of tolerance give >= 3 decades of error (%.2f -> %.2f)", le[0], le[4]);
}

/* No error floor: on Kepler (e = 0.5, 10 periods, ~2000-4000 steps) the error
 * keeps falling as the tolerance goes from 1e-12 to 1e-15.  The bounds: each
 * step's local error is <= tol, and an energy error dE puts a phase error
 * ~3 dE t on the orbit, so with dE ~ 10..30 tol (measured 2e-11 at 1e-12) the
 * position error after t = 20 pi is ~1e3..4e3 tol; measured 2.7e-9 at 1e-12
 * and 1.5e-11 at 1e-15.  The bounds leave a factor ~4..7 of room. */
static void test_no_floor(void)
{
    swim_ode_system sys = { kepler_rhs, 4, NULL, NULL };
    double y0[4], y[4], err[2];
    const double tol[2] = { 1e-12, 1e-15 }, bound[2] = { 1e-8, 1e-10 };
    kepler_init(0.5, y0);
    for (int j = 0; j < 2; j++) {
        int rc;
        run("abm", &sys, tol[j], tol[j], 0.0, y0, 20 * PI, y, NULL, &rc);
        err[j] = 0;
        for (int i = 0; i < 4; i++)
            err[j] = fmax(err[j], fabs(y[i] - y0[i]));
        CHECK(rc == 0 && err[j] < bound[j], "Kepler 10 periods at tol %g: error %g < %g", tol[j], err[j], bound[j]);
    }
    CHECK(err[1] < err[0] / 20, "error keeps falling below tol 1e-12 (%g -> %g)", err[0], err[1]);
}

/* dense output between steps, and outputs never shorten steps */
static void test_interpolant(void)
{
    swim_ode_system sys = { kepler_rhs, 4, NULL, NULL };
    double y0[4], y[4];
    kepler_init(0.5, y0);
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-11;
    o.atol = 1e-11;
    swim_ode *s1, *s2;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s1);
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s2);
    /* reference for t in one period: the same orbit integrated much tighter */
    swim_ode_options o2 = o;
    o2.rtol = o2.atol = 1e-14;
    swim_ode *r;
    swim_ode_create("abm", &sys, &o2, 0.0, y0, &r);
    double yr[4], maxerr = 0;
    int ok = 1;
    srand(12345);
    double t = 0;
    for (int i = 0; i < 1000; i++) {
        t += (2 * PI / 1000) * (0.5 + (double)rand() / RAND_MAX);
        if (t > 2 * PI) break;
        ok &= swim_ode_advance(s1, t, y) == 0;
        ok &= swim_ode_advance(r, t, yr) == 0;
        for (int k = 0; k < 4; k++)
            maxerr = fmax(maxerr, fabs(y[k] - yr[k]));
    }
    ok &= swim_ode_advance(s1, 2 * PI, y) == 0;
    ok &= swim_ode_advance(s2, 2 * PI, yr) == 0;
    CHECK(ok, "dense advance ok");
    CHECK(maxerr < 1e-8, "interpolant error between steps %g", maxerr);
    swim_ode_stats a, b;
    swim_ode_get_stats(s1, &a);
    swim_ode_get_stats(s2, &b);
    CHECK(a.steps == b.steps && a.rhs_evals == b.rhs_evals,
          "1000 outputs do not change the steps (%ld/%ld steps, %ld/%ld evals)", a.steps, b.steps, a.rhs_evals, b.rhs_evals);
    CHECK(memcmp(y, yr, sizeof y) == 0, "same final value with and without dense output");

    /* the interpolant reproduces the step end points and is smooth in between */
    swim_ode_system hs = { ho_rhs, 2, NULL, NULL };
    double z0[2] = { 1.0, 0.0 };
    abm *ab;
    abm_create(&hs, &o, 0.0, z0, &ab);
    double z[2];
    abm_advance(ab, 3.0, z);
    double tn = abm_time(ab), zz[2], zp[2];
    abm_interp(ab, tn, zz, zp);
    /* t is accumulated with compensated summation, so the double abm_time()
     * differs from the exact t_n by a carry below ulp(t_n)/2: the interpolant
     * there equals y_n up to |y'| ulp(t_n) */
    CHECK(fabs(zz[0] - abm_state(ab)[0]) <= 4 * DBL_EPSILON * 3.0 && fabs(zz[1] - abm_state(ab)[1]) <= 4 * DBL_EPSILON * 3.0,
          "interpolant at t_n is y_n (%g, %g)", zz[0] - abm_state(ab)[0], zz[1] - abm_state(ab)[1]);
    CHECK(fabs(zp[0] - zz[1]) < 1e-9 && fabs(zp[1] + zz[0]) < 1e-9, "interpolant derivative matches f");
    abm_free(ab);
    swim_ode_free(s1);
    swim_ode_free(s2);
    swim_ode_free(r);
}

/* a rejected step leaves the complete state bit-for-bit unchanged */
static void test_reject_restore(void)
{
    swim_ode_system sys = { pulse_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 };
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-8;
    o.atol = 1e-8;
    /* hmax well below the pulse width (~0.06): without it, whether a step
     * lands on the pulse or jumps over it depends on the step sequence */
    o.hmax = 0.02;
    abm *a;
    CHECK(abm_create(&sys, &o, 0.0, y0, &a) == 0, "abm create");
    double y[2];
    abm_advance(a, 1e-3, y);   /* starts the integrator */
    size_t m = abm_snapshot(a, NULL);
    double *before = malloc(m * sizeof(double)), *after = malloc(m * sizeof(double));
    int rejections = 0, restored = 0, shrunk = 0, rc = 0;
    while (abm_time(a) < 10.0 && rc == 0) {
        abm_snapshot(a, before);
        double h = abm_next_h(a);
        int acc;
        rc = abm_step(a, &acc);
        if (rc == 0 && !acc) {
            rejections++;
            abm_snapshot(a, after);
            restored += memcmp(before, after, m * sizeof(double)) == 0;
            shrunk += abm_next_h(a) < h;
        }
    }
    CHECK(rc == 0, "pulse integration status %d", rc);
    CHECK(rejections >= 2, "the pulse causes rejections (%d)", rejections);
    CHECK(restored == rejections, "state restored exactly after %d of %d rejections", restored, rejections);
    CHECK(shrunk == rejections, "step reduced after each rejection");
    /* the pulse integral is 30*0.02*sqrt(pi); compare with a tight run */
    swim_ode_options o2 = o;
    o2.rtol = o2.atol = 1e-12;
    abm *b;
    abm_create(&sys, &o2, 0.0, y0, &b);
    double yb[2], ya[2];
    abm_advance(b, 10.0, yb);
    abm_interp(a, 10.0, ya, NULL);
    CHECK(fabs(ya[0] - yb[0]) < 1e-5 && fabs(ya[1] - yb[1]) < 1e-5, "pulse solution %g vs %g", ya[0], yb[0]);
    free(before);
    free(after);
    abm_free(a);
    abm_free(b);
}

static void test_bad_args(void)
{
    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 }, y[2];
    swim_ode_options o;
    swim_ode *s = NULL;
    for (const char *const *m = swim_ode_methods(); *m; m++) {
        swim_ode_options_default(&o);
        o.rtol = -1e-6;
        CHECK(swim_ode_create(*m, &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG && !s, "%s: negative rtol", *m);
        swim_ode_options_default(&o);
        o.atol = -1.0;
        CHECK(swim_ode_create(*m, &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG, "%s: negative atol", *m);
        swim_ode_options_default(&o);
        o.rtol = 0;
        o.atol = 0;
        CHECK(swim_ode_create(*m, &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG, "%s: zero tolerances", *m);
        swim_ode_options_default(&o);
        double ynan[2] = { 1.0, NAN };
        CHECK(swim_ode_create(*m, &sys, &o, 0.0, ynan, &s) == SWIM_ODE_EBADARG, "%s: NaN in y0", *m);
        CHECK(swim_ode_create(*m, &sys, &o, 0.0, y0, &s) == 0, "%s: create", *m);
        CHECK(swim_ode_advance(s, 0.0, y) == SWIM_ODE_EBADARG, "%s: t_end = t0", *m);
        CHECK(swim_ode_advance(s, 1.0, y) == 0, "%s: advance", *m);
        CHECK(swim_ode_advance(s, 0.5, y) == SWIM_ODE_EBADARG, "%s: tout decreasing", *m);
        CHECK(swim_ode_advance(s, NAN, y) == SWIM_ODE_EBADARG, "%s: NaN tout", *m);
        swim_ode_free(s);
        s = NULL;
    }
    swim_ode_options_default(&o);
    CHECK(swim_ode_create("euler", &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG, "unknown method");
    o.atol_vec = (const double[]){ 1e-9, -1e-9 };
    CHECK(swim_ode_create("abm", &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG, "negative atol_vec entry");
    swim_ode_options_default(&o);
    o.tstop = 0.0;
    CHECK(swim_ode_create("abm", &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG, "tstop = t0");

    /* tolerance too small for double precision: an error, not a hang */
    swim_ode_options_default(&o);
    o.rtol = 1e-17;
    o.atol = 1e-30;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    CHECK(swim_ode_advance(s, 1.0, y) == SWIM_ODE_ETOLTOOSMALL, "tolerance too small");
    swim_ode_free(s);

    /* a RHS failure no step can avoid (42 > 0: a persistent domain failure) is passed back with its value */
    swim_ode_system fs = { failing_rhs, 1, NULL, NULL };
    for (const char *const *m = swim_ode_methods(); *m; m++) {
        swim_ode_options_default(&o);
        swim_ode_create(*m, &fs, &o, 0.0, y0, &s);
        int rc = swim_ode_advance(s, 2.0, y);
        CHECK(rc == SWIM_ODE_ERHS && swim_ode_rhs_status(s) == 42, "%s: RHS error (%d, %d)", *m, rc,
              swim_ode_rhs_status(s));
        swim_ode_free(s);
    }

    /* step budget */
    swim_ode_options_default(&o);
    o.max_steps = 10;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    CHECK(swim_ode_advance(s, 100.0, y) == SWIM_ODE_EMAXSTEPS, "max_steps");
    swim_ode_free(s);
    CHECK(strcmp(swim_ode_strerror(SWIM_ODE_ETOLTOOSMALL), "tolerance too small for double precision") == 0, "strerror");
}

/* Positive RHS values are recoverable domain failures, negative ones fatal,
 * for every method. */
static void test_domain_failures(void)
{
    for (const char *const *m = swim_ode_methods(); *m; m++) {
        swim_ode_options o;
        swim_ode *s = NULL;
        swim_ode_stats st;
        double y0[1] = { 0.5 }, y[1];

        /* recoverable: h0 = 5 (and, at the end, a loose tolerance) put trial states outside |y| < bound */
        const double bounds[2] = { 2.0, 0.75 };
        for (int b = 0; b < 2; b++) {
            for (int loose = 0; loose < 2; loose++) {
                dom_par d = { .bound = bounds[b] };
                swim_ode_system sys = { dom_rhs, 1, &d, NULL };
                swim_ode_options_default(&o);
                o.rtol = loose ? 1e-3 : 1e-8;
                o.atol = loose ? 1e-3 : 1e-8;
                o.h0 = 5.0;
                swim_ode_create(*m, &sys, &o, 0.0, y0, &s);
                int rc = 0;
                double err = 0;
                for (int i = 0; i <= 4 && rc == 0; i++) {
                    double t = 10.0 + 0.5 * i;   /* the GSL peers cap the first step at tout - t0 */
                    rc = swim_ode_advance(s, t, y);
                    err = fmax(err, fabs(y[0] - 0.5 * (cos(t) + sin(t))));
                }
                swim_ode_get_stats(s, &st);
                double tol = loose ? 1e-2 : 1e-5;
                CHECK(rc == 0 && err < tol, "%s: domain failures |y| >= %g at rtol %g: status %d, error %g (%ld refused)",
                      *m, bounds[b], o.rtol, rc, err, d.dom_fails);
                if (!loose)
                    CHECK(d.dom_fails > 0 && st.rejected >= 1,
                          "%s: trial states refused (%ld) and counted as rejected steps (%ld)", *m, d.dom_fails,
                          st.rejected);
                swim_ode_free(s);
            }
        }

        /* fatal: -7 at t > 1 stops at once */
        {
            dom_par d = { .bound = 2.0, .fatal_t = 1.0, .fatal_rc = -7 };
            swim_ode_system sys = { dom_rhs, 1, &d, NULL };
            swim_ode_options_default(&o);
            o.rtol = o.atol = 1e-8;
            swim_ode_create(*m, &sys, &o, 0.0, y0, &s);
            int rc = swim_ode_advance(s, 2.0, y);
            CHECK(rc == SWIM_ODE_ERHS && swim_ode_rhs_status(s) == -7 && d.calls_after_fatal == 0,
                  "%s: negative RHS value is fatal (status %d, rhs %d, %ld calls after it)", *m, rc,
                  swim_ode_rhs_status(s), d.calls_after_fatal);
            swim_ode_free(s);
        }

        /* a domain failure no step can avoid: +1 for all t > 1 ends the run, not hangs */
        for (int loose = 0; loose < 2; loose++) {
            dom_par d = { .bound = 2.0, .fatal_t = 1.0, .fatal_rc = 1 };
            swim_ode_system sys = { dom_rhs, 1, &d, NULL };
            swim_ode_options_default(&o);
            o.rtol = o.atol = loose ? 1e-4 : 1e-10;
            swim_ode_create(*m, &sys, &o, 0.0, y0, &s);
            int rc = swim_ode_advance(s, 2.0, y);
            swim_ode_get_stats(s, &st);
            CHECK(rc == SWIM_ODE_ERHS && swim_ode_rhs_status(s) == 1 && d.calls < 2000 && swim_ode_time(s) <= 1.0,
                  "%s: persistent domain failure at tol %g ends the run (status %d, rhs %d, %ld calls, t = %.17g)",
                  *m, o.rtol, rc, swim_ode_rhs_status(s), d.calls, swim_ode_time(s));
            swim_ode_free(s);
        }

        /* a positive value at (t0, y0) is fatal: the initial state itself is invalid */
        {
            dom_par d = { .bound = 0.1 };
            swim_ode_system sys = { dom_rhs, 1, &d, NULL };
            swim_ode_options_default(&o);
            o.h0 = 0.01;
            swim_ode_create(*m, &sys, &o, 0.0, y0, &s);
            int rc = swim_ode_advance(s, 1.0, y);
            CHECK(rc == SWIM_ODE_ERHS && swim_ode_rhs_status(s) == 1 && d.calls <= 2,
                  "%s: invalid initial state (status %d, rhs %d, %ld calls)", *m, rc, swim_ode_rhs_status(s), d.calls);
            swim_ode_free(s);
        }
    }
}

/* One failing call, at every position in the first 80 calls (which covers the
 * start-up, the first steps and, for the BDF methods, the difference-quotient
 * Jacobians): +1 anywhere but at (t0, y0) is recovered from, -7 anywhere stops
 * the run at once. */
static void test_failure_sweep(void)
{
    for (const char *const *m = swim_ode_methods(); *m; m++) {
        int bad_pos = 0, bad_neg = 0, first_fatal = 0;
        for (long n = 0; n < 80; n++) {
            for (int neg = 0; neg < 2; neg++) {
                sweep_par q = { .inj_call = n, .inj_rc = neg ? -7 : 1 };
                swim_ode_system sys = { sweep_rhs, 1, &q, NULL };
                swim_ode_options o;
                swim_ode_options_default(&o);
                o.rtol = o.atol = 1e-8;
                swim_ode *s = NULL;
                double y0[1] = { 0.5 }, y[1];
                swim_ode_create(*m, &sys, &o, 0.0, y0, &s);
                int rc = swim_ode_advance(s, 3.0, y);
                int rs = swim_ode_rhs_status(s);
                if (!q.injected) {
                    /* the run needed fewer than n calls */
                } else if (neg) {
                    bad_neg += !(rc == SWIM_ODE_ERHS && rs == -7 && q.calls_after == 0);
                } else if (n == 0) {
                    first_fatal = rc == SWIM_ODE_ERHS && rs == 1 && q.calls == 1;
                } else {
                    double err = fabs(y[0] - 0.5 * (cos(3.0) + sin(3.0)));
                    if (!(rc == 0 && err < 1e-6)) {
                        bad_pos++;
                        fprintf(stderr, "%s: +1 at call %ld: status %d, error %g\n", *m, n, rc, err);
                    }
                }
                swim_ode_free(s);
            }
        }
        CHECK(first_fatal, "%s: +1 at (t0, y0) is fatal", *m);
        CHECK(bad_pos == 0, "%s: one +1 at any later call is recovered from (%d failures)", *m, bad_pos);
        CHECK(bad_neg == 0, "%s: one -7 at any call stops at once (%d failures)", *m, bad_neg);
    }
}

/* ABM: a domain failure at the predicted state (P E) or at the corrected
 * y_{n+1} (final E) leaves the state bit-for-bit intact and cuts h by 4; the
 * run then goes on to the right answer.  With and without compensated
 * summation (tolerance 1e-14 / 1e-9). */
static void test_abm_domain_restore(void)
{
    const double tols[2] = { 1e-9, 1e-14 };
    for (int it = 0; it < 2; it++) {
        inject_par q = { 0, -1 };
        swim_ode_system sys = { inject_rhs, 4, &q, NULL };
        double y0[4], y[4];
        kepler_init(0.5, y0);
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = o.atol = tols[it];
        abm *a;
        CHECK(abm_create(&sys, &o, 0.0, y0, &a) == 0, "abm create");
        abm_advance(a, 1e-3, y);
        size_t m = abm_snapshot(a, NULL);
        double *before = malloc(m * sizeof(double)), *after = malloc(m * sizeof(double));
        int injected = 0, refused = 0, restored = 0, cut = 0, rc = 0, i = 0;
        while (abm_time(a) < 2 * PI && rc == 0) {
            int acc;
            if (++i % 7 == 0) {
                /* step attempt i: the predictor evaluation is call q.calls, the final one q.calls + 1 */
                q.fail_call = q.calls + (i % 14 == 0);
                injected++;
                abm_snapshot(a, before);
                double h = abm_next_h(a), t = abm_time(a);
                long rej0;
                swim_ode_stats st;
                abm_get_stats(a, &st);
                rej0 = st.rejected;
                rc = abm_step(a, &acc);
                abm_get_stats(a, &st);
                if (rc == 0 && !acc && st.rejected == rej0 + 1) {
                    refused++;
                    abm_snapshot(a, after);
                    restored += memcmp(before, after, m * sizeof(double)) == 0 && abm_time(a) == t;
                    cut += abm_next_h(a) == 0.25 * h;
                }
                q.fail_call = -1;
            } else {
                rc = abm_step(a, &acc);
            }
        }
        CHECK(rc == 0 && injected >= 10, "injected domain failures: status %d, %d injected", rc, injected);
        CHECK(refused == injected && restored == injected && cut == injected,
              "tol %g: %d domain failures: %d rejected, %d restored exactly, %d cut by 4", tols[it], injected, refused,
              restored, cut);
        abm_interp(a, 2 * PI, y, NULL);
        double err = 0;
        for (int k = 0; k < 4; k++)
            err = fmax(err, fabs(y[k] - y0[k]));
        CHECK(err < 1e4 * tols[it] + 1e-11, "tol %g: Kepler orbit closes despite the refused steps (error %g)", tols[it], err);
        free(before);
        free(after);
        abm_free(a);
    }

    /* a failing projection still stops the run */
    swim_ode_system hs = { ho_rhs, 2, NULL, NULL };
    double z0[2] = { 1.0, 0.0 }, z[2];
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.project = reject_project;
    swim_ode *s;
    swim_ode_create("abm", &hs, &o, 0.0, z0, &s);
    int rc = swim_ode_advance(s, 2.0, z);
    CHECK(rc == SWIM_ODE_ERHS && swim_ode_rhs_status(s) == 3 && swim_ode_time(s) <= 1.0,
          "failing projection stops with ERHS (%d, %d)", rc, swim_ode_rhs_status(s));
    swim_ode_free(s);
}

static void test_options(void)
{
    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 }, y[2], y2[2];
    swim_ode_options o;
    swim_ode *s;
    /* tstop: never step past it */
    swim_ode_options_default(&o);
    o.rtol = o.atol = 1e-10;
    o.tstop = 5.0;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    int rc = swim_ode_advance(s, 5.0, y);
    CHECK(rc == 0 && swim_ode_time(s) <= 5.0, "tstop respected (t = %.17g)", swim_ode_time(s));
    CHECK(fabs(y[0] - cos(5.0)) < 1e-8, "value at tstop");
    CHECK(swim_ode_advance(s, 6.0, y) == SWIM_ODE_EBADARG, "tout beyond tstop");
    swim_ode_free(s);
    /* hmax */
    swim_ode_options_default(&o);
    o.hmax = 0.01;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    swim_ode_advance(s, 2.0, y);
    swim_ode_stats st;
    swim_ode_get_stats(s, &st);
    CHECK(st.steps >= 200 && st.last_h <= 0.01, "hmax respected (%ld steps, last h %g)", st.steps, st.last_h);
    swim_ode_free(s);
    /* per-component atol equal to the scalar gives the identical result */
    swim_ode_options_default(&o);
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    swim_ode_advance(s, 3.0, y);
    swim_ode_free(s);
    double av[2] = { o.atol, o.atol };
    o.atol_vec = av;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    av[0] = 1.0;   /* copied at creation: later changes must not matter */
    swim_ode_advance(s, 3.0, y2);
    swim_ode_free(s);
    CHECK(memcmp(y, y2, sizeof y) == 0, "atol_vec equal to atol gives the same run");
}

static void test_stiffness(void)
{
    swim_ode_system sys = { stiff_rhs, 1, NULL, NULL };
    double y0[1] = { 1.0 }, y[1];
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-6;
    o.atol = 1e-6;
    swim_ode *s;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    int rc = swim_ode_advance(s, 10.0, y);
    swim_ode_stats st;
    swim_ode_get_stats(s, &st);
    CHECK(rc == 0 && fabs(y[0] - cos(10.0)) < 1e-4, "stiff problem still solved (%d, %g)", rc, y[0]);
    CHECK(st.stiff_suspected, "stiffness diagnostic fires on y' = -1000(y - cos t)");
    swim_ode_free(s);
    o.stiff_stop = 1;
    swim_ode_create("abm", &sys, &o, 0.0, y0, &s);
    rc = swim_ode_advance(s, 10.0, y);
    swim_ode_get_stats(s, &st);
    CHECK(rc == SWIM_ODE_ESTIFF && swim_ode_time(s) < 10.0, "stiff_stop returns ESTIFF early (%d)", rc);
    swim_ode_free(s);
    /* the BDF peers do the same problem cheaply */
    swim_ode_stats sb;
    run("cvode-bdf", &sys, 1e-6, 1e-6, 0.0, y0, 10.0, y, &sb, &rc);
    CHECK(rc == 0 && fabs(y[0] - cos(10.0)) < 1e-4 && sb.rhs_evals < st.rhs_evals, "cvode-bdf on the stiff problem");
    run("msbdf", &sys, 1e-6, 1e-6, 0.0, y0, 10.0, y, &sb, &rc);
    CHECK(rc == 0 && fabs(y[0] - cos(10.0)) < 1e-4 && sb.jac_evals > 0, "msbdf with FD Jacobian on the stiff problem");
    /* no false alarm on long nonstiff runs at loose and tight tolerances */
    swim_ode_system hs = { ho_rhs, 2, NULL, NULL };
    double z0[2] = { 1.0, 0.0 }, z[2];
    double tols[3] = { 1e-4, 1e-8, 1e-12 };
    for (int i = 0; i < 3; i++) {
        swim_ode_options_default(&o);
        o.rtol = o.atol = tols[i];
        o.stiff_stop = 1;
        swim_ode_create("abm", &hs, &o, 0.0, z0, &s);
        rc = swim_ode_advance(s, 500.0, z);
        swim_ode_get_stats(s, &st);
        CHECK(rc == 0 && !st.stiff_suspected, "no stiffness alarm on the oscillator at tol %g", tols[i]);
        swim_ode_free(s);
    }
}

/* Closure error and cost of one ABM run with the given look-ahead. */
static double closure(const swim_ode_system *sys, const double *y0, double T, double tol, int lookahead,
                      swim_ode_stats *st)
{
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = o.atol = tol;
    o.lookahead = lookahead;
    o.stiff_stop = 1;
    swim_ode *s = NULL;
    double y[4] = {0}, err = INFINITY;
    if (swim_ode_create("abm", sys, &o, 0.0, y0, &s) == 0 && swim_ode_advance(s, T, y) == 0) {
        err = 0.0;
        for (int i = 0; i < 4; i++)
            err = fmax(err, fabs(y[i] - y0[i]));
    }
    swim_ode_get_stats(s, st);
    swim_ode_free(s);
    return err;
}

/* The step-size look-ahead (abm.c): on orbits whose error estimate grows quickly near
 * close approaches (Arenstorf, Kepler with e = 0.9) it should avoid most error-test
 * failures and give a smaller closure error than STEP's rule (lookahead = 0) for a few
 * per cent more work -- over nine tolerances, as a geometric mean, since single runs of
 * either rule scatter by 10x. */
static void test_lookahead(void)
{
    swim_ode_system sa = { arenstorf_rhs, 4, NULL, NULL }, sk = { kepler_rhs, 4, NULL, NULL };
    const double *ya = AREN_Y0;
    double yk[4];
    kepler_init(0.9, yk);
    for (int prob = 0; prob < 2; prob++) {
        const swim_ode_system *sys = prob ? &sk : &sa;
        const double *y0 = prob ? yk : ya;
        double T = prob ? 20.0 * PI : AREN_T, lsum = 0.0;
        long nfe[2] = {0, 0}, rej[2] = {0, 0};
        int n = 0, alarms = 0;
        for (double tol = 1e-5; tol > 1e-13; tol /= 10.0, n++) {
            swim_ode_stats s0, s6;
            double e0 = closure(sys, y0, T, tol, 0, &s0), e6 = closure(sys, y0, T, tol, 6, &s6);
            lsum += log(e6 / e0);
            nfe[0] += s0.rhs_evals;
            nfe[1] += s6.rhs_evals;
            rej[0] += s0.rejected;
            rej[1] += s6.rejected;
            alarms += s0.stiff_suspected + s6.stiff_suspected;
        }
        const char *name = prob ? "Kepler e = 0.9" : "Arenstorf";
        double g = exp(lsum / n), w = (double)nfe[1] / nfe[0];
        printf("look-ahead on %s over 9 tolerances: error %.2fx, RHS evaluations %.3fx, rejected steps %ld "
               "(STEP's rule: %ld)\n", name, g, w, rej[1], rej[0]);
        CHECK(isfinite(g) && g < 1.0, "%s: look-ahead error / STEP error = %.2f (geometric mean)", name, g);
        CHECK(w < 1.1, "%s: look-ahead costs %.3fx the RHS evaluations of STEP", name, w);
        CHECK(4 * rej[1] < rej[0], "%s: rejected steps %ld with look-ahead, %ld without", name, rej[1], rej[0]);
        CHECK(alarms == 0, "%s: no stiffness alarm (%d)", name, alarms);
    }
    swim_ode_options o;
    swim_ode_options_default(&o);
    CHECK(o.lookahead == 6, "default look-ahead is 6");
    swim_ode *s = NULL;
    o.lookahead = 13;
    CHECK(swim_ode_create("abm", &sa, &o, 0.0, ya, &s) == SWIM_ODE_EBADARG && !s, "lookahead 13 rejected");
    o.lookahead = -1;
    CHECK(swim_ode_create("abm", &sa, &o, 0.0, ya, &s) == SWIM_ODE_EBADARG && !s, "lookahead -1 rejected");
}


/* The registry: one list of names, capabilities as documented in ode.h, and an option a
 * method cannot honour refused with SWIM_ODE_EUNSUPPORTED rather than ignored. */
static int unit_circle(double t, double *y, void *p)
{
    (void)t; (void)p;
    double r = sqrt(y[0] * y[0] + y[1] * y[1]);
    y[0] /= r;
    y[1] /= r;
    return 0;
}
static void ignore_step(const swim_ode_step *st, void *data) { (void)st; (void)data; }
static double ev_y0(double t, const double *y, const double *yp, void *d) { (void)t; (void)yp; (void)d; return y[0]; }
static void ev_ignore(const swim_ode_event_hit *h, void *d) { (void)h; (void)d; }
/* A balance that never moves: only what the registry says about it is tested here. */
static double zero_balance(double t, const double *y, double *noise, void *data)
{
    (void)t; (void)y; (void)data;
    *noise = 0.0;
    return 0.0;
}

static void test_registry(void)
{
    static const char *const want[] = {"abm", "rk8pd", "msadams", "rkf45", "msbdf", "cvode-adams", "cvode-bdf"};
    static const unsigned caps[] = {
        SWIM_ODE_CAP_PROJECTION | SWIM_ODE_CAP_STEP_TRACE | SWIM_ODE_CAP_EVENTS | SWIM_ODE_CAP_STIFFNESS |
            SWIM_ODE_CAP_WEIGHTS | SWIM_ODE_CAP_INVARIANT | SWIM_ODE_CAP_ERROR_DIM | SWIM_ODE_CAP_RESCALE,
        0, 0, 0, SWIM_ODE_CAP_JACOBIAN | SWIM_ODE_CAP_IMPLICIT, SWIM_ODE_CAP_EVENTS | SWIM_ODE_CAP_SUNDIALS,
        SWIM_ODE_CAP_PROJECTION | SWIM_ODE_CAP_EVENTS | SWIM_ODE_CAP_JACOBIAN | SWIM_ODE_CAP_IMPLICIT |
            SWIM_ODE_CAP_SUNDIALS};
    const char *const *m = swim_ode_methods();
    int i = 0;
    for (; m[i]; i++) {
        CHECK(i < 7 && strcmp(m[i], want[i]) == 0, "method %d is %s", i, m[i]);
        if (i < 7)
            CHECK(swim_ode_capabilities(m[i]) == caps[i], "capabilities of %s: %u", m[i], swim_ode_capabilities(m[i]));
    }
    CHECK(i == 7, "7 methods (%d)", i);
    CHECK(!swim_ode_method_known("ode45") && swim_ode_capabilities("ode45") == 0, "unknown name");
    CHECK(strcmp(swim_ode_method_list(), "abm, rk8pd, msadams, rkf45, msbdf, cvode-adams, cvode-bdf") == 0,
          "method list for messages: %s", swim_ode_method_list());

    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 };
    swim_ode_event ev = { ev_y0, NULL, 0, 0 };
    for (i = 0; i < 7; i++) {
        for (int opt = 0; opt < 7; opt++) {
            static const double scale[2] = {1.0, 1.0};
            swim_ode_options o;
            swim_ode_options_default(&o);
            unsigned need = 0;
            switch (opt) {
            case 0: o.project = unit_circle; need = SWIM_ODE_CAP_PROJECTION; break;
            case 1: o.on_step = ignore_step; need = SWIM_ODE_CAP_STEP_TRACE; break;
            case 2: o.events = &ev; o.nevents = 1; o.on_event = ev_ignore; need = SWIM_ODE_CAP_EVENTS; break;
            case 3: o.stiff_stop = 1; need = SWIM_ODE_CAP_STIFFNESS; break;
            case 4: o.tol_scale = scale; need = SWIM_ODE_CAP_WEIGHTS; break;
            case 5: o.invariant = zero_balance; o.invariant_tol = 1e-8; need = SWIM_ODE_CAP_INVARIANT; break;
            case 6: o.error_dim = 1; need = SWIM_ODE_CAP_ERROR_DIM; break;
            }
            swim_ode *s = NULL;
            int rc = swim_ode_create(want[i], &sys, &o, 0.0, y0, &s);
            if (caps[i] & need)
                CHECK(rc != SWIM_ODE_EUNSUPPORTED, "%s accepts option %d (rc %d)", want[i], opt, rc);
            else
                CHECK(rc == SWIM_ODE_EUNSUPPORTED && !s, "%s refuses option %d (rc %d)", want[i], opt, rc);
            swim_ode_free(s);
        }
    }
}

/* CVODE-BDF's projection (CVodeSetProjFn): the harmonic oscillator stays on the unit
 * circle to rounding with it, and drifts off it by the local errors without it. */
static void test_cvode_projection(void)
{
    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    double y0[2] = { 1.0, 0.0 }, y[2];
    double radius_err[2];
    for (int proj = 0; proj < 2; proj++) {
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-6;
        o.atol = 1e-9;
        if (proj)
            o.project = unit_circle;
        swim_ode *s = NULL;
        int rc = swim_ode_create("cvode-bdf", &sys, &o, 0.0, y0, &s);
        double worst = 0.0;
        for (int k = 1; rc == 0 && k <= 200; k++) {
            rc = swim_ode_advance(s, 0.5 * k, y);
            worst = fmax(worst, fabs(hypot(y[0], y[1]) - 1.0));
        }
        CHECK(rc == 0, "cvode-bdf %s projection ran (rc %d)", proj ? "with" : "without", rc);
        radius_err[proj] = worst;
        swim_ode_free(s);
    }
    /* outputs come from CVODE's interpolant between projected steps: off by its local error */
    CHECK(radius_err[1] < 1e-2 * radius_err[0],
          "projection keeps |y| = 1: %.3g with, %.3g without", radius_err[1], radius_err[0]);
    printf("cvode-bdf on the oscillator, 100 time units, rtol 1e-6: max ||y| - 1| %.3g with projection, %.3g without\n",
           radius_err[1], radius_err[0]);
}

/* Events on the oscillator y = (cos t, -sin t): zeros of y0 at pi/2 + k pi, extremes of y0
 * (zeros of y0' from the interpolant's derivative) at k pi, minima rising, maxima falling. */
typedef struct {
    int n;
    double t[64], y0[64], y1[64];
    int index[64], rising[64], terminal[64];
} ev_log;
static void ev_record(const swim_ode_event_hit *h, void *d)
{
    ev_log *L = d;
    if (L->n >= 64)
        return;
    L->t[L->n] = h->t;
    L->y0[L->n] = h->y[0];
    L->y1[L->n] = h->y[1];
    L->index[L->n] = h->index;
    L->rising[L->n] = h->rising;
    L->terminal[L->n] = h->terminal;
    L->n++;
}
static double ev_dy0(double t, const double *y, const double *yp, void *d) { (void)t; (void)y; (void)d; return yp[0]; }

static void test_events(void)
{
    swim_ode_system sys = { ho_rhs, 2, NULL, NULL };
    const double y0[2] = { 1.0, 0.0 }, T = 20.0;
    static const char *const methods[] = { "abm", "cvode-adams", "cvode-bdf" };
    /* location error: the interpolant's and the global error of the run (printed) */
    static const double tols[] = { 1e-10, 1e-10, 1e-10 };
    for (int mth = 0; mth < 3; mth++) {
        swim_ode_event ev[3] = {
            { ev_y0, NULL, 0, 0 },     /* zeros of y0, either way */
            { ev_dy0, NULL, +1, 0 },   /* minima of y0 */
            { ev_dy0, NULL, -1, 0 },   /* maxima of y0 */
        };
        ev_log L;
        memset(&L, 0, sizeof L);
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-12;
        o.atol = 1e-14;
        o.events = ev;
        o.nevents = 3;
        o.on_event = ev_record;
        o.on_event_data = &L;
        swim_ode *s = NULL;
        int rc = swim_ode_create(methods[mth], &sys, &o, 0.0, y0, &s);
        double y[2], worst = 0.0, worst_y = 0.0;
        for (int k = 1; rc == 0 && k <= 40; k++)
            rc = swim_ode_advance(s, T * k / 40, y);
        CHECK(rc == 0, "%s: run with events (rc %d)", methods[mth], rc);
        /* expected: k pi/2, k = 1..12 (t = 0 is not an event), in time order */
        int want = (int)floor(T / (PI / 2));
        CHECK(L.n == want, "%s: %d events (want %d)", methods[mth], L.n, want);
        for (int i = 0; i < L.n && i < want; i++) {
            int k = i + 1;
            double te = k * PI / 2;
            worst = fmax(worst, fabs(L.t[i] - te));
            worst_y = fmax(worst_y, fabs(L.y0[i] - cos(te)) + fabs(L.y1[i] + sin(te)));
            int idx = k % 2 ? 0 : ((k / 2) % 2 ? 1 : 2);   /* odd: zero; pi, 3pi: minimum; 2pi: maximum */
            CHECK(L.index[i] == idx, "%s: event %d at %.6f has index %d (want %d)", methods[mth], i, L.t[i], L.index[i], idx);
            if (idx == 0)
                CHECK(L.rising[i] == (k % 4 == 3), "%s: direction of the zero at %.6f", methods[mth], L.t[i]);
        }
        CHECK(worst <= tols[mth], "%s: event times within %g of k pi/2 (worst %.3g)", methods[mth], tols[mth], worst);
        CHECK(worst_y <= 10 * tols[mth], "%s: event states (worst %.3g)", methods[mth], worst_y);
        swim_ode_stats st;
        swim_ode_get_stats(s, &st);
        CHECK(st.events == L.n && st.event_evals > 3 * st.steps, "%s: event counters (%ld events, %ld evaluations, %ld steps)",
              methods[mth], st.events, st.event_evals, st.steps);
        printf("events on the oscillator, %s, rtol 1e-12: %d events, worst |t - k pi/2| %.2g, %ld g evaluations for %ld steps\n",
               methods[mth], L.n, worst, st.event_evals, st.steps);
        swim_ode_free(s);
    }

    /* Terminal: the first falling zero of y0 (t = pi/2) ends the run there, with the state
     * there, although the output times step over it; the object then refuses to go on. */
    for (int mth = 0; mth < 3; mth++) {
        swim_ode_event ev[2] = { { ev_dy0, NULL, +1, 0 }, { ev_y0, NULL, -1, 1 } };
        ev_log L;
        memset(&L, 0, sizeof L);
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-12;
        o.atol = 1e-14;
        o.events = ev;
        o.nevents = 2;
        o.on_event = ev_record;
        o.on_event_data = &L;
        swim_ode *s = NULL;
        int rc = swim_ode_create(methods[mth], &sys, &o, 0.0, y0, &s);
        double y[2] = { NAN, NAN };
        int k = 1;
        for (; rc == 0 && k <= 100; k++)
            rc = swim_ode_advance(s, 0.3 * k, y);
        k--;
        CHECK(rc == SWIM_ODE_TERMINATED && k == 6, "%s: terminal event returned by the call whose tout passes pi/2 (rc %d, call %d)",
              methods[mth], rc, k);
        CHECK(fabs(swim_ode_time(s) - PI / 2) <= tols[mth] && fabs(y[0]) <= tols[mth] && fabs(y[1] + 1.0) <= tols[mth],
              "%s: stopped at t = %.15g with y = (%.3g, %.15g)", methods[mth], swim_ode_time(s), y[0], y[1]);
        CHECK(L.n == 1 && L.terminal[0] && L.index[0] == 1, "%s: one terminal event reported (%d)", methods[mth], L.n);
        CHECK(swim_ode_advance(s, 10.0, y) == SWIM_ODE_EBADARG, "%s: no advance after a terminal event", methods[mth]);
        swim_ode_free(s);
    }

    /* A terminal event found in a step that reaches beyond the current tout is kept: the outputs
     * before it still come (from the interpolant), and the call whose tout passes it stops. */
    for (int mth = 0; mth < 3; mth++) {
        swim_ode_event ev = { ev_y0, NULL, -1, 1 };
        ev_log L;
        memset(&L, 0, sizeof L);
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-12;
        o.atol = 1e-14;
        o.events = &ev;
        o.nevents = 1;
        o.on_event = ev_record;
        o.on_event_data = &L;
        swim_ode *s = NULL;
        int rc = swim_ode_create(methods[mth], &sys, &o, 0.0, y0, &s);
        double y[2], worst = 0.0;
        int k = 1, early = 0;
        for (; rc == 0 && k <= 300; k++) {
            rc = swim_ode_advance(s, 0.01 * k, y);
            if (rc == 0) {
                worst = fmax(worst, fabs(y[0] - cos(0.01 * k)) + fabs(y[1] + sin(0.01 * k)));
                early += L.n > 0;   /* outputs after the event was located, before its time */
            }
        }
        k--;
        CHECK(rc == SWIM_ODE_TERMINATED && k == 158, "%s: the call with tout = 1.58 stops (rc %d, call %d)", methods[mth], rc, k);
        CHECK(early > 0, "%s: the event was located ahead of the outputs before it (%d outputs after)", methods[mth], early);
        CHECK(worst <= 1e-10, "%s: outputs before the terminal event (worst error %.3g)", methods[mth], worst);
        CHECK(fabs(y[0]) <= 1e-10 && fabs(swim_ode_time(s) - PI / 2) <= 1e-10, "%s: state at the event", methods[mth]);
        swim_ode_free(s);
    }

    /* bad event lists */
    swim_ode_event bad = { NULL, NULL, 0, 0 };
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.events = &bad;
    o.nevents = 1;
    o.on_event = ev_ignore;
    swim_ode *s = NULL;
    CHECK(swim_ode_create("abm", &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG && !s, "event without a function");
    bad.g = ev_y0;
    o.on_event = NULL;
    CHECK(swim_ode_create("abm", &sys, &o, 0.0, y0, &s) == SWIM_ODE_EBADARG && !s, "events without on_event");
}

/* The exact-Jacobian hook on two stiff problems: Robertson's kinetics (y0 + y1 + y2 = 1) and
 * Van der Pol with mu = 1000.  With the analytic Jacobian, cvode-bdf and msbdf spend fewer
 * evaluations of f (no difference quotients) at the same accuracy against a tight reference. */
static int robertson_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    f[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
    f[2] = 3e7 * y[1] * y[1];
    f[1] = -f[0] - f[2];
    return 0;
}
static int robertson_jac(double t, const double *y, double *J, void *p)
{
    (void)t; (void)p;
    J[0] = -0.04; J[1] = 1e4 * y[2]; J[2] = 1e4 * y[1];
    J[6] = 0.0; J[7] = 6e7 * y[1]; J[8] = 0.0;
    J[3] = -J[0] - J[6]; J[4] = -J[1] - J[7]; J[5] = -J[2] - J[8];
    return 0;
}
static int vdp_rhs(double t, const double *y, double *f, void *p)
{
    (void)t; (void)p;
    f[0] = y[1];
    f[1] = 1000.0 * (1.0 - y[0] * y[0]) * y[1] - y[0];
    return 0;
}
static int vdp_jac(double t, const double *y, double *J, void *p)
{
    (void)t; (void)p;
    J[0] = 0.0; J[1] = 1.0;
    J[2] = -2000.0 * y[0] * y[1] - 1.0; J[3] = 1000.0 * (1.0 - y[0] * y[0]);
    return 0;
}
static int counted_jac_calls;
static int counted_vdp_jac(double t, const double *y, double *J, void *p)
{
    counted_jac_calls++;
    return vdp_jac(t, y, J, p);
}

static void test_user_jacobian(void)
{
    struct { const char *name; swim_ode_func f; swim_ode_jacobian jac; size_t n; double y0[3], T; } prob[2] = {
        { "Robertson", robertson_rhs, robertson_jac, 3, { 1.0, 0.0, 0.0 }, 40.0 },
        { "Van der Pol mu = 1000", vdp_rhs, vdp_jac, 2, { 2.0, 0.0, 0.0 }, 1000.0 },
    };
    static const char *const methods[] = { "cvode-bdf", "msbdf" };
    for (int pi = 0; pi < 2; pi++) {
        /* reference: cvode-bdf, exact Jacobian, rtol 1e-12 */
        swim_ode_system sj = { prob[pi].f, prob[pi].n, NULL, prob[pi].jac };
        double ref[3], y[3];
        swim_ode_stats st;
        int rc;
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-12;
        o.atol = 1e-16;
        swim_ode *s = NULL;
        rc = swim_ode_create("cvode-bdf", &sj, &o, 0.0, prob[pi].y0, &s);
        if (rc == 0)
            rc = swim_ode_advance(s, prob[pi].T, ref);
        swim_ode_free(s);
        CHECK(rc == 0, "%s: reference run (rc %d)", prob[pi].name, rc);
        for (int m = 0; m < 2; m++) {
            double err[2];
            long nfe[2], nje[2];
            for (int withj = 0; withj < 2; withj++) {
                swim_ode_system sys = { prob[pi].f, prob[pi].n, NULL, withj ? prob[pi].jac : NULL };
                run(methods[m], &sys, 1e-6, 1e-10, 0.0, prob[pi].y0, prob[pi].T, y, &st, &rc);
                CHECK(rc == 0, "%s, %s, %s Jacobian: ran (rc %d)", prob[pi].name, methods[m], withj ? "exact" : "DQ", rc);
                double e = 0.0, scale = 0.0;
                for (size_t i = 0; i < prob[pi].n; i++) {
                    e = fmax(e, fabs(y[i] - ref[i]));
                    scale = fmax(scale, fabs(ref[i]));
                }
                err[withj] = e / scale;
                nfe[withj] = st.rhs_evals;
                nje[withj] = st.jac_evals;
            }
            CHECK(nfe[1] < nfe[0], "%s, %s: fewer evaluations of f with the exact Jacobian (%ld vs %ld)",
                  prob[pi].name, methods[m], nfe[1], nfe[0]);
            CHECK(nje[1] > 0, "%s, %s: the exact Jacobian is counted (%ld)", prob[pi].name, methods[m], nje[1]);
            /* same accuracy: both at the level the tolerance gives, neither 10x worse than the other */
            CHECK(err[1] <= 1e-3 && err[0] <= 1e-3 && err[1] <= 10 * err[0] && err[0] <= 10 * err[1],
                  "%s, %s: error %.3g with the exact Jacobian, %.3g with differences", prob[pi].name, methods[m], err[1], err[0]);
            printf("%s, %s, rtol 1e-6: %ld evaluations of f and %ld Jacobians (relative error %.2g) with the exact Jacobian; "
                   "%ld and %ld (%.2g) with difference quotients\n",
                   prob[pi].name, methods[m], nfe[1], nje[1], err[1], nfe[0], nje[0], err[0]);
        }
    }
    /* integrators that need no Jacobian never call it */
    counted_jac_calls = 0;
    swim_ode_system sc = { vdp_rhs, 2, NULL, counted_vdp_jac };
    double y0[2] = { 2.0, 0.0 }, y[2];
    int rc;
    run("abm", &sc, 1e-6, 1e-10, 0.0, y0, 1.0, y, NULL, &rc);
    run("cvode-adams", &sc, 1e-6, 1e-10, 0.0, y0, 1.0, y, NULL, &rc);
    CHECK(counted_jac_calls == 0, "abm and cvode-adams do not call the Jacobian (%d calls)", counted_jac_calls);
}

/* The balance in abm's error test (swim_ode_options.invariant), on Kepler's problem: its energy
 * is a first integral that Adams methods let drift by a systematic amount per step. */
static double inv_last_f[4];
static long inv_calls, inv_mismatch;
static int kepler_rhs_recorded(double t, const double *y, double *f, void *p)
{
    memcpy(inv_last_f, y, sizeof inv_last_f);
    return kepler_rhs(t, y, f, p);
}
static double kepler_energy(double t, const double *y, double *noise, void *data)
{
    (void)t;
    (void)data;
    if (noise) *noise = 4e-16;   /* a few roundings of terms of size 1 */
    inv_calls++;
    if (memcmp(y, inv_last_f, sizeof inv_last_f) != 0) inv_mismatch++;   /* the contract: right after f at y */
    return 0.5 * (y[2] * y[2] + y[3] * y[3]) - 1.0 / hypot(y[0], y[1]);
}
static double kepler_drift(double tol, swim_ode_stats *st, double *yend)
{
    swim_ode_system sys = { kepler_rhs_recorded, 4, NULL, NULL };
    double y0[4], y[4];
    kepler_init(0.6, y0);
    const double E0 = kepler_energy(0.0, y0, NULL, NULL);
    swim_ode_options o;
    swim_ode_options_default(&o);
    o.rtol = 1e-8;
    o.atol = 1e-10;
    if (tol > 0) {
        o.invariant = kepler_energy;
        o.invariant_tol = tol;
    }
    swim_ode *s;
    double dE = 0.0;
    if (swim_ode_create("abm", &sys, &o, 0.0, y0, &s) != 0) return INFINITY;
    for (int i = 1; i <= 200; i++) {   /* 100 periods */
        if (swim_ode_advance(s, PI * i, y) != 0) { dE = INFINITY; break; }
        dE = fmax(dE, fabs(kepler_energy(0.0, y, NULL, NULL) - E0) / fabs(E0));
    }
    swim_ode_get_stats(s, st);
    memcpy(yend, y, sizeof y);
    swim_ode_free(s);
    return dE;
}
static void test_invariant(void)
{
    swim_ode_stats s0, s1, s2;
    double y0[4], y1[4], y2[4];
    const double d0 = kepler_drift(0.0, &s0, y0);
    inv_calls = inv_mismatch = 0;
    const double d1 = kepler_drift(1e-3 * 1e-8 * 0.5, &s1, y1);   /* 1e-3 rtol |E| (E = -1/2) */
    const long calls = inv_calls, mismatch = inv_mismatch - 201;   /* the test's own 201 calls */
    const double d2 = kepler_drift(1e30, &s2, y2);
    CHECK(d1 < 0.1 * d0, "balance test: Kepler energy drift %.3g against %.3g without it (want 10x smaller)", d1, d0);
    CHECK(s1.rejected_invariant > 0 && s1.rejected_invariant <= s1.rejected && s0.rejected_invariant == 0,
          "balance test: %ld of %ld rejections are its own", s1.rejected_invariant, s1.rejected);
    CHECK(s1.steps < 2 * s0.steps, "balance test: %ld steps against %ld (not a tolerance cut everywhere)", s1.steps, s0.steps);
    CHECK(calls > 2 * s1.steps && mismatch == 0, "balance test: %ld calls, %ld not right after f at the same state",
          calls, mismatch);
    printf("balance test on Kepler (e = 0.6, rtol 1e-8, 100 periods): energy drift %.3g with it, %.3g without; "
           "%ld and %ld steps, %ld rejections by it\n", d1, d0, s1.steps, s0.steps, s1.rejected_invariant);
    CHECK(d2 == d0 && memcmp(y0, y2, sizeof y0) == 0 && s2.steps == s0.steps && s2.rhs_evals == s0.rhs_evals,
          "balance test that never binds: the same solution bit for bit");
}

/* Arenstorf's orbit (4 components) with two more, w' = (8 + y_0) w: linear, homogeneous, read by
 * no state equation, and growing fast enough to dominate any error test they are part of. */
static int aren_tangent_rhs(double t, const double *y, double *f, void *p)
{
    int rc = arenstorf_rhs(t, y, f, p);
    f[4] = (8.0 + y[0]) * y[4];
    f[5] = (8.0 + y[0]) * y[5] - y[4];
    return rc;
}

typedef struct {
    swim_ode *ode;
    long scaled;
    int exponent;   /* what the rescalings took out: w = 2^exponent times the carried one */
} rescale_ctx;

/* w back to |w_0| in [1/2, 1) after every accepted step, by a power of two */
static int rescale_every_step(const swim_ode_accepted *st, void *data, double *t_stop)
{
    (void)t_stop;
    rescale_ctx *c = data;
    int e;
    frexp(st->y_end[4], &e);
    if (swim_ode_scale(c->ode, 4, 2, ldexp(1.0, -e)) == SWIM_ODE_OK) {
        c->scaled++;
        c->exponent += e;
    }
    return 0;
}

/* error_dim: the state alone in the error control gives the state's run bit for bit (same steps,
 * same numbers); the extra components in it change the steps. swim_ode_scale by a power of two
 * in every accepted step: the extra components come out as the unscaled ones times that factor,
 * bit for bit, and the state is untouched. */
static void test_error_dim_and_rescale(void)
{
    const double y0[6] = {0.994, 0.0, 0.0, -2.00158510637908252240537862224, 1.0, 0.5};
    const double touts[3] = {1.0, 5.0, AREN_T};
    swim_ode_system plain = {arenstorf_rhs, 4, NULL, NULL}, aug = {aren_tangent_rhs, 6, NULL, NULL};
    double yp[3][4], ya[3][6], yall[3][6], ys[3][6];
    swim_ode_stats sp, sa, sall, ss;
    int rescaled_by = 0;
    for (int run = 0; run < 4; run++) {
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-10;
        o.atol = 1e-12;
        o.error_dim = run == 1 || run == 3 ? 4 : 0;
        rescale_ctx rc = {NULL, 0, 0};
        if (run == 3) {
            o.on_accept = rescale_every_step;
            o.on_accept_data = &rc;
        }
        swim_ode *s = NULL;
        int st = swim_ode_create("abm", run == 0 ? &plain : &aug, &o, 0.0, y0, &s);
        CHECK(st == SWIM_ODE_OK, "run %d created (%d)", run, st);
        if (st) return;
        rc.ode = s;
        double *out[4] = {NULL, NULL, NULL, NULL};
        for (int k = 0; k < 3 && st == SWIM_ODE_OK; k++) {
            out[0] = yp[k]; out[1] = ya[k]; out[2] = yall[k]; out[3] = ys[k];
            st = swim_ode_advance(s, touts[k], out[run]);
        }
        CHECK(st == SWIM_ODE_OK, "run %d reaches the end (%d)", run, st);
        if (run == 3) rescaled_by = rc.exponent;
        swim_ode_get_stats(s, run == 0 ? &sp : run == 1 ? &sa : run == 2 ? &sall : &ss);
        if (run == 3) CHECK(rc.scaled == ss.steps, "every step rescaled (%ld of %ld)", rc.scaled, ss.steps);
        swim_ode_free(s);
    }
    CHECK(sa.steps == sp.steps && sa.rejected == sp.rejected && sa.rhs_evals == sp.rhs_evals,
          "error_dim = 4: the state's steps (%ld/%ld/%ld vs %ld/%ld/%ld)", sa.steps, sa.rejected, sa.rhs_evals,
          sp.steps, sp.rejected, sp.rhs_evals);
    CHECK(memcmp(ya[0], yp[0], sizeof yp[0]) == 0 && memcmp(ya[1], yp[1], sizeof yp[1]) == 0 &&
          memcmp(ya[2], yp[2], sizeof yp[2]) == 0, "error_dim = 4: the state bit for bit");
    CHECK(sall.steps > sp.steps, "in the error test the growing components cost steps (%ld vs %ld)", sall.steps, sp.steps);
    CHECK(memcmp(ys[2], yp[2], sizeof yp[2]) == 0 && ss.steps == sp.steps, "rescaling leaves the state alone");
    CHECK(rescaled_by > 100 && fabs(ys[2][4]) < 2.0 && ldexp(ys[2][4], rescaled_by) == ya[2][4] &&
          ldexp(ys[2][5], rescaled_by) == ya[2][5],
          "rescaled by powers of two (2^-%d in all): w = %.17g, unscaled %.17g", rescaled_by, ys[2][4], ya[2][4]);
}

int main(void)
{
    test_harmonic();
    test_kepler();
    test_arenstorf();
    test_proportionality();
    test_no_floor();
    test_interpolant();
    test_reject_restore();
    test_bad_args();
    test_domain_failures();
    test_failure_sweep();
    test_abm_domain_restore();
    test_options();
    test_stiffness();
    test_lookahead();
    test_registry();
    test_cvode_projection();
    test_events();
    test_user_jacobian();
    test_invariant();
    test_error_dim_and_rescale();
    return check_report("test_ode");
}
