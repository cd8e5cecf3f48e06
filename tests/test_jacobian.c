/* The exact Jacobian of the generated right-hand side (swim_scene_kernel.jacobian, the tangent
 * code of runtime/kernel/scene_rhs.h with the derivatives SymPy emits, and the barrier's Hessian
 * of shape/barrier.c) against difference quotients of that right-hand side, and the stiff
 * integrators with it against the same integrators by differences.
 *
 *  1. swim_barrier_hessian against central differences of swim_barrier_w2's gradient, N = 1, 4,
 *     7, 15, 32, interior and near the boundary of D (both quadrature rules).
 *  2. J against central differences with two Richardson levels (O(h^6), steps h, h/2, h/4, h
 *     scaled to the distance from the boundary of D), column by column:
 *     max_i |J_ij - Q_ij| / max(max_i |Q_ij|, 1e-8 max |Q|) <= 1e-7, where Q is the extrapolated
 *     quotient. The quotient's own error is estimated by |Q - Q'| (Q' the one-level value with
 *     steps h/2, h/4), printed, and must itself be far below the bound (else the comparison says
 *     nothing and the check fails). Structures: N = 0..3, 7, 12; all free, some locked
 *     (deletion: one at 0, folded, one at a value), --generic (locks by multipliers); effects
 *     all on, all off, and each alone; the barrier with alpha = 1/2, 1, 3/2 at a moderate and at
 *     a small min J (the graded quadrature).
 *     With J, the kernel's exact partials with respect to every run-time parameter it reads
 *     (jacobian_params: the densities, stiffness, reference, damping, forcing direction, a
 *     law's [parameters], the barrier's scale eps d/d eps) against the same extrapolated
 *     central differences in that parameter, to the same bound.
 *  3. cvode-bdf and msbdf: the final state of a short stiff run with the exact Jacobian agrees
 *     with the run by difference quotients to a few tolerances, and the exact one is called.
 * Kernels come from the cache ($SWIM_CACHE; `make test` keeps it in build/cache). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "codegen/codegen.h"
#include "io/message.h"
#include "model/dynamics.h"
#include "ode/ode.h"
#include "shape/barrier.h"
#include "shape/shape.h"

#define NMAX (2 * (SWIM_KERNEL_MAX_MODES + 1))
#define DMAX (4 + 2 * NMAX)
#define TOL 1e-7
#define PSTEP 1e-2   /* relative step of the parameter quotients (the barrier quadrature's tolerance is noise below it) */

static double urand(void) { return 2.0 * rand() / (double)RAND_MAX - 1.0; }

/* ---- 1. the barrier's Hessian ------------------------------------------------------------ */

static void check_barrier_hessian(int N, double alpha, const double *x, const char *what)
{
    const int n = 2 * (N + 1);
    swim_barrier_quad *b = swim_barrier_quad_new(N);
    if (!b) abort();
    double W, g[NMAX], H[NMAX * NMAX], gp[NMAX], gm[NMAX], xp[NMAX];
    swim_barrier_info info;
    int rc = swim_barrier_hessian(b, x, 0.03, alpha, &W, g, H, &info);
    CHECK(rc == SWIM_BARRIER_OK, "barrier N=%d %s: status %d", N, what, rc);
    if (rc != SWIM_BARRIER_OK) { swim_barrier_quad_free(b); return; }
    double jmin = swim_shape_jmin(N, x);
    double h = 1e-3 * fmin(1.0, jmin), err = 0.0, scale = 0.0;
    for (int j = 0; j < n; j++) {
        double D[3][NMAX];
        for (int lev = 0; lev < 3; lev++) {
            const double hh = h / (1 << lev);
            memcpy(xp, x, sizeof(double) * n);
            xp[j] = x[j] + hh;
            swim_barrier_w2(b, xp, 0.03, alpha, &W, gp, NULL);
            xp[j] = x[j] - hh;
            swim_barrier_w2(b, xp, 0.03, alpha, &W, gm, NULL);
            for (int i = 0; i < n; i++) D[lev][i] = (gp[i] - gm[i]) / (2 * hh);
        }
        for (int i = 0; i < n; i++) {
            double r1 = (4 * D[1][i] - D[0][i]) / 3, r2 = (4 * D[2][i] - D[1][i]) / 3;
            double q = (16 * r2 - r1) / 15;
            err = fmax(err, fabs(H[n * j + i] - q));
            scale = fmax(scale, fabs(q));
        }
    }
    CHECK(err <= TOL * scale, "barrier N=%d %s: Hessian vs differences of the gradient %.3g", N, what,
          err / scale);
    printf("  barrier Hessian N = %2d %-28s min J %.2e  %s rule  relative %.2e\n", N, what, jmin,
           info.graded ? "graded" : "trapezoidal", err / scale);
    swim_barrier_quad_free(b);
}

/* ---- 2. the Jacobian of the right-hand side ------------------------------------------------ */

typedef struct {
    const char *name;
    int generic, locked;        /* multipliers; some coordinates locked */
    int elastic, damping, forcing, barrier;
} kind;

/* A random shape well inside D: sum_m m |c_-m| <= spread |c_1|. */
static void random_shape(int N, double *x, const int *keep, double spread)
{
    double c1 = 1.0 + 0.2 * urand(), ang = 3.0 * urand(), w[SWIM_KERNEL_MAX_MODES + 1], tot = 0.0;
    if (keep[0]) x[0] = c1 * cos(ang);
    if (keep[1]) x[1] = c1 * sin(ang);
    c1 = hypot(x[0], x[1]);
    for (int m = 1; m <= N; m++) {
        w[m] = (0.2 + fabs(urand())) / m;
        tot += m * w[m];
    }
    for (int m = 1; m <= N; m++) {
        double r = spread * c1 * w[m] / tot, a = 3.14159 * urand();
        if (keep[2 * m]) x[2 * m] = r * cos(a);
        if (keep[2 * m + 1]) x[2 * m + 1] = r * sin(a);
    }
}

/* J at ys against the extrapolated central differences of the RHS; returns the worst column
 * error (relative) and the worst estimated error of the quotient in *qerr. Steps: hx on the
 * shape (small against min J near the boundary of D); 0.5 on the velocities, on which the RHS
 * is a quadratic (the quotient is exact but for rounding, which a large step keeps small next
 * to the barrier's large forces); 1e-2 on the position and orientation. */
static double compare_at(swim_dynamics *d, double t, const double *ys, int sdim, double hx,
                         double *qerr, int *status)
{
    static double J[DMAX * DMAX], Q[DMAX * DMAX], Q1[DMAX * DMAX];
    double yp[DMAX], fp[DMAX], fm[DMAX], D[3][DMAX];
    *status = swim_dynamics_jacobian(t, ys, J, d);
    if (*status != 0) return INFINITY;
    for (int j = 0; j < sdim; j++) {
        const int nf = (sdim - 4) / 2;
        double h = j < 3 ? 1e-2 : j < 3 + nf ? hx * fmax(1.0, fabs(ys[j])) : 0.5;
        for (int lev = 0; lev < 3; lev++) {
            const double hh = h / (1 << lev);
            memcpy(yp, ys, sizeof(double) * sdim);
            yp[j] = ys[j] + hh;
            int r1 = swim_dynamics_rhs(t, yp, fp, d);
            yp[j] = ys[j] - hh;
            int r2 = swim_dynamics_rhs(t, yp, fm, d);
            if (r1 || r2) { *status = r1 ? r1 : r2; return INFINITY; }
            for (int i = 0; i < sdim; i++) D[lev][i] = (fp[i] - fm[i]) / (2 * hh);
        }
        for (int i = 0; i < sdim; i++) {
            double ra = (4 * D[1][i] - D[0][i]) / 3, rb = (4 * D[2][i] - D[1][i]) / 3;
            Q[sdim * i + j] = (16 * rb - ra) / 15;
            Q1[sdim * i + j] = rb;
        }
    }
    double gmax = 0.0;
    for (int k = 0; k < sdim * sdim; k++) gmax = fmax(gmax, fabs(Q[k]));
    double worst = 0.0, qworst = 0.0;
    for (int j = 0; j < sdim; j++) {
        double cmax = 0.0, e = 0.0, qe = 0.0;
        for (int i = 0; i < sdim; i++) {
            cmax = fmax(cmax, fabs(Q[sdim * i + j]));
            e = fmax(e, fabs(J[sdim * i + j] - Q[sdim * i + j]));
            qe = fmax(qe, fabs(Q1[sdim * i + j] - Q[sdim * i + j]));
        }
        const double sc = fmax(cmax, 1e-8 * gmax);
        if (sc == 0.0) continue;
        worst = fmax(worst, e / sc);
        qworst = fmax(qworst, qe / sc);
    }
    *qerr = qworst;
    return worst;
}

/* The exact partials d rhs / d p at ys against extrapolated central differences in p (the
 * value changed where the right-hand side reads it, then restored bit for bit); returns the
 * worst relative column error, its quotient's error in *qerr, and how many parameters *count. */
static double compare_params(swim_dynamics *d, swim_scene *s, double t, const double *ys, int sdim,
                             double *qerr, int *count, int *status)
{
    swim_param par[4 + 4 * NMAX + 8];
    double *val[4 + 4 * NMAX + 8][2];
    int np = 0;
    par[np] = (swim_param){SWIM_PARAM_RHO0, 0};
    val[np][0] = &s->rho0, val[np++][1] = &d->spec_params.rho0;
    par[np] = (swim_param){SWIM_PARAM_RHOF, 0};
    val[np][0] = &s->rhof, val[np++][1] = &d->spec_params.rhof;
    for (int i = 0; i < s->n; i++) {
        double *arrays[4] = {&s->stiffness[i], &s->reference[i], &s->damping[i], &s->direction[i]};
        for (int a = 0; a < 4; a++) {
            par[np] = (swim_param){SWIM_PARAM_STIFFNESS + a, i};
            val[np][0] = arrays[a], val[np++][1] = NULL;
        }
    }
    for (int k = 0; k < s->nparams; k++) {
        par[np] = (swim_param){SWIM_PARAM_LAW, k};
        val[np][0] = &s->param_values[k], val[np++][1] = NULL;
    }
    par[np] = (swim_param){SWIM_PARAM_BARRIER_SCALE, 0};
    val[np][0] = &s->epsilon, val[np++][1] = NULL;
    static double dp[(4 + 4 * NMAX + 8) * DMAX];
    *status = swim_dynamics_jacobian_params(d, t, ys, NULL, np, par, dp);
    *count = np;
    if (*status != 0) return INFINITY;
    static double Qall[(4 + 4 * NMAX + 8) * DMAX], Q1all[(4 + 4 * NMAX + 8) * DMAX];
    double f0[DMAX], fp[DMAX], fm[DMAX], gmax = 0.0, fmax_rhs = 0.0;
    *status = swim_dynamics_rhs(t, ys, f0, d);
    if (*status != 0) return INFINITY;
    for (int i = 0; i < sdim; i++) fmax_rhs = fmax(fmax_rhs, fabs(f0[i]));
    for (int k = 0; k < np; k++) {
        const double base = *val[k][0], h = PSTEP * fmax(1.0, fabs(base));
        const double scale = par[k].kind == SWIM_PARAM_BARRIER_SCALE ? base : 1.0;
        double D[3][DMAX];
        for (int lev = 0; lev < 3; lev++) {
            const double hh = h / (1 << lev);
            for (int side = 0; side < 2; side++) {
                for (int j = 0; j < 2; j++)
                    if (val[k][j]) *val[k][j] = base + (side ? -hh : hh);
                int rc = swim_dynamics_rhs(t, ys, side ? fm : fp, d);
                if (rc != 0) *status = rc;
            }
            for (int j = 0; j < 2; j++)
                if (val[k][j]) *val[k][j] = base;
            if (*status != 0) return INFINITY;
            for (int i = 0; i < sdim; i++) D[lev][i] = scale * (fp[i] - fm[i]) / (2 * hh);
        }
        for (int i = 0; i < sdim; i++) {
            const double ra = (4 * D[1][i] - D[0][i]) / 3, rb = (4 * D[2][i] - D[1][i]) / 3;
            Qall[(size_t)k * sdim + i] = (16 * rb - ra) / 15;
            Q1all[(size_t)k * sdim + i] = rb;
            gmax = fmax(gmax, fabs(Qall[(size_t)k * sdim + i]));
        }
    }
    /* columns relative to their largest entry, but not below what rounding leaves of the
     * quotient over TOL (a parameter the right-hand side barely reads has a column of that
     * noise; near the boundary the barrier's forces, ~1e9 at min J 2e-4 with alpha 3/2, leave
     * more), nor below 1e-8 of the largest partial of all. The rounding r of one evaluation is
     * measured: r = max |rhs(p + delta) - rhs(p) - delta dp| for a change delta far below h, where
     * the linear term is known; the quotient's is ~ r / h. */
    double worst = 0.0, qworst = 0.0;
    for (int k = 0; k < np; k++) {
        double cmax = 0.0, e = 0.0, qe = 0.0;
        for (int i = 0; i < sdim; i++) {
            const double Q = Qall[(size_t)k * sdim + i];
            cmax = fmax(cmax, fabs(Q));
            e = fmax(e, fabs(dp[(size_t)k * sdim + i] - Q));
            qe = fmax(qe, fabs(Q1all[(size_t)k * sdim + i] - Q));
        }
        const double base = *val[k][0], delta = 1e-9 * fmax(1.0, fabs(base));
        const double scale = par[k].kind == SWIM_PARAM_BARRIER_SCALE ? base : 1.0;
        for (int j = 0; j < 2; j++)
            if (val[k][j]) *val[k][j] = base + delta;
        *status = swim_dynamics_rhs(t, ys, fm, d);
        for (int j = 0; j < 2; j++)
            if (val[k][j]) *val[k][j] = base;
        if (*status != 0) return INFINITY;
        double r = 10 * 2.2e-16 * fmax(fmax_rhs, 1.0);
        for (int i = 0; i < sdim; i++)
            r = fmax(r, fabs(fm[i] - f0[i] - delta * dp[(size_t)k * sdim + i] / scale));
        const double noise = 10 * scale * r / (PSTEP * fmax(1.0, fabs(base)));
        const double sc = fmax(fmax(cmax, 1e-8 * gmax), noise / TOL);
        if (e / sc > TOL && getenv("SWIM_TEST_JACOBIAN_VERBOSE"))
            printf("    parameter kind %d index %d: relative %.2e (max %.2e, quotient's error %.1e) %s\n",
                   par[k].kind, par[k].index, e / sc, cmax, qe / sc, s->path);
        worst = fmax(worst, e / sc);
        qworst = fmax(qworst, qe / sc);
    }
    *qerr = qworst;
    return worst;
}

static void fill_scene(swim_scene *s, int N, const kind *kd)
{
    memset(s, 0, sizeof *s);
    const int n = 2 * (N + 1);
    s->path = swim_strprintf("test_jacobian N=%d %s", N, kd->name);
    if (!s->path) abort();
    s->modes = N;
    s->n = n;
    s->rho0 = 0.7 + 0.6 * fabs(urand());
    s->rhof = 0.8 + 0.4 * fabs(urand());
    for (int i = 0; i < n; i++) s->free_mask[i] = 1;
    int ones[NMAX];
    for (int i = 0; i < NMAX; i++) ones[i] = 1;
    random_shape(N, s->c0, ones, 0.3);
    if (kd->locked && N >= 2) {
        s->free_mask[n - 1] = 0;
        s->c0[n - 1] = 0.0;        /* folded away in a specialized kernel */
        s->free_mask[3] = 0;       /* b_-1 locked at its (non-zero) value */
    }
    s->elastic = kd->elastic;
    s->damped = kd->damping;
    s->forced = kd->forcing;
    s->barrier = kd->barrier;
    s->epsilon = 0.03;
    s->alpha = 0.5;
    if (kd->forcing && !(s->forcing_text = swim_strprintf("%s", "A*sin(w*t)^2 + exp(-t)*cos(3*t)")))
        abort();
    if (kd->forcing) {   /* [parameters] the law reads at run time */
        s->nparams = 2;
        snprintf(s->param_names[0], sizeof s->param_names[0], "A");
        snprintf(s->param_names[1], sizeof s->param_names[1], "w");
        s->param_values[0] = 0.3;
        s->param_values[1] = 2.0;
    }
    for (int i = 0; i < n; i++) {
        s->stiffness[i] = i % 3 ? 0.5 + fabs(urand()) : 0.0;
        s->reference[i] = 0.1 * urand();
        s->damping[i] = i % 2 ? 0.2 * fabs(urand()) : 0.05;
        s->direction[i] = i % 4 == 1 ? urand() : 0.0;
    }
    s->direction[n - 2] = 0.7;
}

/* A shape with a sharp minimum of J near the boundary of D: the free coordinates of c_-1 and
 * c_-2 are set to (0.3, t (1 - 0.3)/2) |c_1| (the others keep their values) with t found by
 * bisection so that min J = target (min J falls as t grows: at t = 1 the shape is on or
 * beyond the boundary). 0, or -1 when the structure cannot get there. */
static int near_boundary(int N, const int *free_mask, double *x, double target)
{
    if (N < 2 || !free_mask[2] || !free_mask[4]) return -1;
    const double c1 = hypot(x[0], x[1]);
    x[2] = 0.3 * c1;
    x[3] = free_mask[3] ? 0.0 : x[3];
    double lo = 0.0, hi = 2.0;
    for (int it = 0; it < 200; it++) {
        const double mid = 0.5 * (lo + hi);
        x[4] = mid * 0.35 * c1;
        if (swim_shape_jmin(N, x) > target) lo = mid;
        else hi = mid;
    }
    x[4] = lo * 0.35 * c1;
    const double j = swim_shape_jmin(N, x);
    return j > 0.5 * target && j < 2.0 * target ? 0 : -1;
}

static void compare(int N, const kind *kd, int trials)
{
    static swim_scene s;
    fill_scene(&s, N, kd);
    swim_compiled sc;
    if (swim_codegen_scene(&s, kd->generic, &sc, 0, NULL) != 0) {
        CHECK(0, "N=%d %s: no kernel", N, kd->name);
        swim_scene_free(&s);
        return;
    }
    CHECK(sc.scene->jacobian != NULL, "N=%d %s: the kernel offers no Jacobian", N, kd->name);
    swim_dynamics d;
    if (swim_dynamics_init(&d, &s, NULL) != 0) abort();
    swim_dynamics_use_scene_kernel(&d, sc.scene, kd->generic);
    const int n = s.n, sdim = swim_dynamics_state_dim(&d);
    /* (min J regime, alpha): the random interior shapes; with a barrier and N >= 2 also a shape
     * near the boundary of D, for each alpha */
    static const double alphas[3] = {0.5, 1.0, 1.5};
    const int near = kd->barrier && N >= 2 && s.free_mask[2] && s.free_mask[4];
    const double targets[3] = {2e-2, 2e-3, 2e-4};   /* min J near the boundary, per alpha */
    double worst = 0.0, qworst = 0.0, pworst = 0.0, pqworst = 0.0;
    for (int trial = 0; trial < trials + (near ? 3 : 0); trial++) {
        double y[DMAX], ys[DMAX];
        memset(y, 0, sizeof y);
        int keep[NMAX] = {0};
        for (int i = 0; i < n; i++) keep[i] = s.free_mask[i];
        memcpy(y + 3, s.c0, sizeof(double) * n);
        /* J moves by up to 2m h when a coordinate of mode -m moves by h */
        const double hscale = 1.0 / (2.0 * (N > 0 ? N : 1));
        double h0 = 1e-3 * hscale;
        s.alpha = alphas[trial % 3];
        if (trial < trials) random_shape(N, y + 3, keep, 0.4);
        else {
            random_shape(N, y + 3, keep, 0.2);
            if (near_boundary(N, s.free_mask, y + 3, targets[trial % 3]) != 0) {
                CHECK(0, "N=%d %s: no shape near the boundary", N, kd->name);
                continue;
            }
            h0 = 1e-2 * hscale * swim_shape_jmin(N, y + 3);
        }
        for (int i = 0; i < n; i++) y[3 + n + i] = s.free_mask[i] ? 0.5 * urand() : 0.0;
        y[0] = urand();
        y[1] = urand();
        y[2] = 3.0 * urand();
        y[3 + 2 * n] = urand();
        const double t = 2.0 * fabs(urand());
        swim_dynamics_pack(&d, y, ys);
        int status;
        double qerr;
        double e = compare_at(&d, t, ys, sdim, h0, &qerr, &status);
        CHECK(status == 0, "N=%d %s trial %d: status %d", N, kd->name, trial, status);
        if (status != 0) continue;
        if (trial >= trials)
            printf("    near the boundary: min J %.2e, alpha %.1f: relative %.2e (quotient's error %.1e)\n",
                   swim_shape_jmin(N, y + 3), s.alpha, e, qerr);
        worst = fmax(worst, e);
        qworst = fmax(qworst, qerr);
        int count;
        e = compare_params(&d, &s, t, ys, sdim, &qerr, &count, &status);
        CHECK(status == 0, "N=%d %s trial %d: parameter partials: status %d", N, kd->name, trial, status);
        if (status != 0) continue;
        if (e > TOL && getenv("SWIM_TEST_JACOBIAN_VERBOSE"))
            printf("    trial %d (%s): parameters relative %.2e, min J %.2e\n", trial,
                   trial < trials ? "interior" : "near the boundary", e, swim_shape_jmin(N, y + 3));
        pworst = fmax(pworst, e);
        pqworst = fmax(pqworst, qerr);
    }
    CHECK(pworst <= TOL, "N=%d %s: exact parameter partials vs differences, relative %.3g", N, kd->name, pworst);
    CHECK(pqworst <= 0.1 * TOL, "N=%d %s: the parameter quotients' own error %.3g is not small enough to judge",
          N, kd->name, pqworst);
    CHECK(worst <= TOL, "N=%d %s: exact Jacobian vs differences, relative %.3g", N, kd->name, worst);
    CHECK(qworst <= 0.1 * TOL, "N=%d %s: the difference quotient's own error %.3g is not small enough to judge",
          N, kd->name, qworst);
    printf("  N = %2d  %-34s state %3d  max relative difference %.2e (quotient's error %.1e), "
           "parameters %.2e (%.1e)\n", N, kd->name, sdim, worst, qworst, pworst, pqworst);
    swim_dynamics_free(&d);
    swim_compiled_close(&sc);
    swim_scene_free(&s);
}

/* ---- 3. the stiff integrators ---------------------------------------------------------------- */

static void integrate(const char *method, int N)
{
    static swim_scene s;
    kind kd = {"stiff", 0, 0, 1, 1, 0, 1};
    fill_scene(&s, N, &kd);
    for (int i = 0; i < s.n; i++) {
        s.stiffness[i] = 50.0 * (1 + i);   /* stiff modes */
        s.reference[i] = s.c0[i];
        s.damping[i] = 0.3;
    }
    memset(s.dc0, 0, sizeof s.dc0);
    s.dc0[4] = 0.2;   /* G1, G2 are violated a little: the RHS does not care */
    swim_compiled sc;
    if (swim_codegen_scene(&s, 0, &sc, 0, NULL) != 0) {
        CHECK(0, "%s: no kernel", method);
        swim_scene_free(&s);
        return;
    }
    swim_dynamics d;
    if (swim_dynamics_init(&d, &s, NULL) != 0) abort();
    swim_dynamics_use_scene_kernel(&d, sc.scene, 0);
    const int sdim = swim_dynamics_state_dim(&d);
    double y0[DMAX], ys0[DMAX], yout[2][DMAX];
    swim_dynamics_initial_state(&d, y0);
    swim_dynamics_pack(&d, y0, ys0);
    long calls[2] = {0, 0}, rhs[2] = {0, 0};
    for (int exact = 0; exact < 2; exact++) {
        swim_ode_system sys = {swim_dynamics_rhs, (size_t)sdim, &d, exact ? swim_dynamics_jacobian : NULL};
        swim_ode_options o;
        swim_ode_options_default(&o);
        o.rtol = 1e-9;
        o.atol = 1e-11;
        swim_ode *ode;
        d.jac_calls = 0;
        int rc = swim_ode_create(method, &sys, &o, 0.0, ys0, &ode);
        CHECK(rc == SWIM_ODE_OK, "%s: create %d", method, rc);
        if (rc != SWIM_ODE_OK) continue;
        rc = swim_ode_advance(ode, 2.0, yout[exact]);
        CHECK(rc == SWIM_ODE_OK, "%s (%s): advance %s", method, exact ? "exact" : "differences",
              swim_ode_strerror(rc));
        swim_ode_stats st;
        swim_ode_get_stats(ode, &st);
        calls[exact] = d.jac_calls;
        rhs[exact] = st.rhs_evals;
        swim_ode_free(ode);
    }
    double diff = 0.0, scale = 0.0;
    for (int i = 0; i < sdim; i++) {
        diff = fmax(diff, fabs(yout[0][i] - yout[1][i]));
        scale = fmax(scale, fabs(yout[0][i]));
    }
    CHECK(calls[1] > 0 && calls[0] == 0, "%s: exact Jacobian calls %ld (with differences %ld)", method,
          calls[1], calls[0]);
    CHECK(diff <= 1e-6 * scale, "%s: exact vs differences, final states differ by %.3g (relative)",
          method, diff / scale);
    CHECK(rhs[1] < rhs[0], "%s: RHS evaluations with the exact Jacobian %ld, by differences %ld", method,
          rhs[1], rhs[0]);
    printf("  %-10s N = %d, t = 0..2, rtol 1e-9: final states differ by %.2e relative; RHS evaluations "
           "%ld (exact, %ld Jacobians) vs %ld (differences)\n", method, N, diff / scale, rhs[1], calls[1],
           rhs[0]);
    swim_dynamics_free(&d);
    swim_compiled_close(&sc);
    swim_scene_free(&s);
}

int main(void)
{
    srand(4242);
    /* 1. barrier Hessian: interior shapes and shapes near the boundary of D */
    static const double alphas[3] = {0.5, 1.0, 1.5};
    static const int bmodes[] = {1, 4, 7, 15, 32};
    for (size_t bm = 0; bm < sizeof bmodes / sizeof bmodes[0]; bm++)
        for (int a = 0, N = bmodes[bm]; a < 3; a++) {
            double x[NMAX] = {0};
            int keep[NMAX];
            for (int i = 0; i < NMAX; i++) keep[i] = 1;
            random_shape(N, x, keep, 0.5);
            char what[64];
            snprintf(what, sizeof what, "interior, alpha %.1f", alphas[a]);
            check_barrier_hessian(N, alphas[a], x, what);
            if (N < 2) continue;
            const double target = a == 0 ? 1e-5 : a == 1 ? 1e-3 : 1e-4;
            if (near_boundary(N, keep, x, target) != 0) abort();
            snprintf(what, sizeof what, "near boundary, alpha %.1f", alphas[a]);
            check_barrier_hessian(N, alphas[a], x, what);
        }
    if (getenv("SWIM_TEST_JACOBIAN_BARRIER_ONLY")) return check_report("test_jacobian");
    /* 2. J against differences */
    static const kind kinds[] = {
        {"all free, every effect", 0, 0, 1, 1, 1, 1},
        {"some locked, every effect", 0, 1, 1, 1, 1, 1},
        {"generic (multipliers), every effect", 1, 1, 1, 1, 1, 1},
        {"all free, no effect", 0, 0, 0, 0, 0, 0},
    };
    static const kind alone[] = {
        {"elastic only", 0, 0, 1, 0, 0, 0},
        {"damping only", 0, 0, 0, 1, 0, 0},
        {"forcing only", 0, 0, 0, 0, 1, 0},
        {"barrier only", 0, 0, 0, 0, 0, 1},
        {"generic, no effect", 1, 1, 0, 0, 0, 0},
    };
    static const int modes[] = {0, 1, 2, 3, 7, 12};
    for (size_t c = 0; c < sizeof modes / sizeof modes[0]; c++)
        for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
            compare(modes[c], &kinds[k], modes[c] >= 12 ? 2 : 4);
    for (size_t k = 0; k < sizeof alone / sizeof alone[0]; k++) compare(3, &alone[k], 3);
    /* 3. the stiff integrators */
    integrate("cvode-bdf", 3);
    integrate("msbdf", 3);
    return check_report("test_jacobian");
}
