/* Adams-Bashforth-Moulton PECE integrator, variable step and order 1..12, in
 * modified divided-difference form.
 *
 * Notation (1-based indices throughout, as in the literature):
 *   t_n      current time,  y_n current solution,
 *   psi_i    = t_{n+1} - t_{n+1-i}            (step history),
 *   alpha_i  = h / psi_i,  beta_i = prod_{j<i} psi_j(n+1)/psi_j(n),
 *   phi_i(n) = prod_{j<i} psi_j(n) * f[t_n, ..., t_{n-i+1}]  (modified divided differences),
 *   phi*_i   = beta_i phi_i(n),
 *   g_i      = integration coefficients g_{i,1}, from g_{1,q} = 1/q and
 *              g_{i,q} = g_{i-1,q} - alpha_{i-1} g_{i-1,q+1}.
 * Predictor of order k:   p = y_n + h sum_{i<=k} g_i phi*_i.
 * Corrector (local extrapolation, order k+1):  y_{n+1} = p + h g_{k+1} phi_{k+1}(n+1)
 * where phi_{k+1}(n+1) = f(t_{n+1}, p) - sum_{i<=k} phi*_i.
 * The local error of the order-k formula, h (g_k - g_{k+1}) |phi_{k+1}(n+1)|
 * (weighted max norm, weights rtol|y_n| + atol_i, as in ode113),
 * is what the tolerance controls.  Orders are chosen by comparing error
 * estimates at orders k-2 .. k+1; the step is doubled, kept, or reduced by a
 * factor in [1/2, 0.9], so that on runs of equal steps the coefficients are
 * not recomputed (ns counts the equal steps).
 *
 * Look-ahead.  That rule (Shampine-Gordon's STEP) keeps h while the error
 * expected for the next step, erk, is at most half the tolerance, i.e. it
 * assumes erk changes little from one step to the next.  Where the solution's
 * high derivatives grow quickly the estimate grows by a factor rho per step at
 * fixed h, and, being built from the (k+1)-st difference over the last k+2
 * points, it lags behind the error actually committed.  Traced on the swimmer's
 * Example 3 (T = 1000, rtol 1e-10; make bench-drift, part 4) the steps of such
 * phases made the whole energy drift, with the same sign each time.  So when
 * the order is unchanged and the error normalised to the step size,
 * rho = (erk_n / erk_{n-1}) (h_{n-1} / h_n)^(k+1), exceeds 1, the step-size
 * decision uses erk rho^p (rho capped at ABM_GROWTH_CAP) instead of erk: it
 * keeps the error expected p steps ahead within the target.  Both
 * estimates in rho are taken in the weighted norm of step n-1 (weights change
 * with |y|, which is not a growing error), and estimates within 10x of the
 * rounding level are left alone (noise, not a trend).  It only ever shortens
 * steps, and p = 0 gives STEP's rule.  The default p = 6 was chosen by
 * measurement (README, "Step-size look-ahead").
 *
 * The difference table and the solution (y with its compensated-summation
 * carries) are double-buffered: a step attempt writes the new table and the
 * corrected y_{n+1} into second buffers and leaves the old ones untouched until
 * the step is complete, t_{n+1} and its carry are kept in locals, and the step
 * history (psi, v) is saved before it is modified, so a rejected step leaves
 * the state bit-for-bit as it was.
 *
 * A step attempt is rejected either by the error test or because the
 * right-hand side returned a positive value (its argument lies outside the
 * domain of f) at the predicted state p or at the corrected y_{n+1}.  In the
 * second case the step is cut by a factor 4 (and to order 1 from the third
 * failure in a row on); more than ABM_MAXDOMFAIL such failures in a row, or a
 * step size below the minimum, end the integration with SWIM_ODE_ERHS.
 */
#include "ode/abm.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define KM ABM_MAXORDER
#define NROW (KM + 3)            /* rows 1..KM+2 of the difference table used */
#define UROUND DBL_EPSILON       /* 2^-52 */
#define MAXD(x, y) ((x) > (y) ? (x) : (y))
#define MIND(x, y) ((x) < (y) ? (x) : (y))
#define STIFF_BLOCK 100          /* accepted steps per block of the stiffness diagnostic */
#define STIFF_BLOCKS 3           /* stiff-looking blocks in a row that raise the flag */
#define ABM_MAXDOMFAIL 20        /* domain failures of f (positive returns) in a row before giving up */
#define ABM_DOMFAC 0.25          /* step reduction after a domain failure */
#define ABM_GROWTH_CAP 4.0       /* largest per-step error growth the look-ahead extrapolates */

struct abm {
    size_t n;
    swim_ode_func f;
    void *par;
    double rtol, atol, *atolv;
    double hmax, tstop;
    long max_steps;
    int stiff_stop;
    int lookahead;               /* p of the look-ahead (0 = STEP's rule) */
    int (*project)(double t, double *y, void *params);
    void (*on_step)(const swim_ode_step *step, void *data);
    void *on_step_data;

    double t;                    /* t_n */
    double tc;                   /* compensated-summation carry for t (t_n = t + tc exactly up to rounding) */
    double *y;                   /* y_n */
    double *yc;                  /* compensated-summation carry for y */
    double *yn, *ycn;            /* y_{n+1} and its carry during a step attempt (swapped with y, yc on acceptance) */
    double *base;                /* the one allocation holding all vectors */
    double *phi, *phin;          /* difference tables, NROW rows of n (row i at i*n) */
    double *p, *pinc, *fp, *rw;  /* predictor, its increment, f at p / at y_{n+1}, 1/weights */
    double *rwp;                 /* 1/weights of the last accepted step (look-ahead) */

    double psi[KM + 3], alpha[KM + 3], beta[KM + 3], sig[KM + 3];
    double g[KM + 3], v[KM + 3], w[KM + 3], gstar[KM + 3];
    double psi_save[KM + 3], v_save[KM + 3];

    double h, hold;
    int k, kold, ns, phase1, ifail, started, compensate, have_step;
    double la_erk, la_h;         /* erk and h of the last accepted step, for the look-ahead (0: none) */
    int h_clamped;               /* current h limited by hmax or tstop */
    int saved;                   /* psi_save/v_save hold the history of this attempt */
    int domfail;                 /* domain failures of f in a row (since the last accepted step) */

    /* statistics */
    long steps, nfe, rejected, hist[KM + 1];
    double last_h;
    int last_order, stiff_run, stiff_suspected;
    int blk_n, blk_low, blk_clamped, blk_cuts;
    long blk_rej0;
    double blk_hmin, blk_hmax;
    int rhs_status;
    double tout_last;
};

/* Evaluate f; returns 0, or the (nonzero) value returned by f, which is also
 * recorded in rhs_status. */
static int eval(abm *a, double t, const double *y, double *f)
{
    a->nfe++;
    int rc = a->f(t, y, f, a->par);
    if (rc != 0)
        a->rhs_status = rc;
    return rc;
}

void abm_free(abm *a)
{
    if (!a)
        return;
    free(a->atolv);
    free(a->base);
    free(a);
}

int abm_create(const swim_ode_system *sys, const swim_ode_options *opt, double t0,
               const double *y0, abm **out)
{
    *out = NULL;
    size_t n = sys->dimension;
    abm *a = calloc(1, sizeof *a);
    if (!a)
        return SWIM_ODE_ENOMEM;
    /* one block for all vectors: y, yc, p, pinc, fp, rw, phi, phin, yn, ycn, rwp */
    a->base = calloc((9 + 2 * NROW) * n, sizeof(double));
    a->y = a->base;
    if (!a->base) {
        free(a);
        return SWIM_ODE_ENOMEM;
    }
    a->yc = a->y + n;
    a->p = a->yc + n;
    a->pinc = a->p + n;
    a->fp = a->pinc + n;
    a->rw = a->fp + n;
    a->phi = a->rw + n;
    a->phin = a->phi + NROW * n;
    a->yn = a->phin + NROW * n;
    a->ycn = a->yn + n;
    a->rwp = a->ycn + n;
    if (opt->atol_vec) {
        a->atolv = malloc(n * sizeof(double));
        if (!a->atolv) {
            abm_free(a);
            return SWIM_ODE_ENOMEM;
        }
        memcpy(a->atolv, opt->atol_vec, n * sizeof(double));
    }
    a->n = n;
    a->f = sys->function;
    a->par = sys->params;
    a->rtol = opt->rtol;
    a->atol = opt->atol;
    a->hmax = opt->hmax > 0 ? opt->hmax : INFINITY;
    a->tstop = opt->tstop;
    a->max_steps = opt->max_steps > 0 ? opt->max_steps : 10000000L;
    a->stiff_stop = opt->stiff_stop;
    a->lookahead = opt->lookahead;
    a->project = opt->project;
    a->on_step = opt->on_step;
    a->on_step_data = opt->on_step_data;
    a->h = opt->h0 > 0 ? opt->h0 : 0.0;
    a->t = t0;
    a->tout_last = t0;
    memcpy(a->y, y0, n * sizeof(double));

    /* Error constants of the order-m Adams-Moulton formula, |gamma*_m|, from
     * the generating function -z/log(1-z): c_0 = 1, c_m = -sum_{j=1}^m c_{m-j}/(j+1). */
    double c[KM + 3];
    c[0] = 1.0;
    for (int m = 1; m <= KM + 1; m++) {
        double s = 0.0;
        for (int j = 1; j <= m; j++)
            s += c[m - j] / (j + 1);
        c[m] = -s;
        a->gstar[m] = fabs(c[m]);
    }
    *out = a;
    return SWIM_ODE_OK;
}

/* Weights a->rw = 1/(rtol|y_n| + atol_i) for the weighted max norm. */
static double set_weights(abm *a)
{
    const size_t n = a->n;
    const double rt = a->rtol, at = a->atol;
    const double *restrict y = a->y, *restrict av = a->atolv;
    double *restrict rw = a->rw;
    double s = 0.0;
    if (av) {
        for (size_t l = 0; l < n; l++) {
            double r = 1.0 / (rt * fabs(y[l]) + av[l]), q = fabs(y[l] * r);
            rw[l] = r;
            s = MAXD(s, q);
        }
    } else {
        for (size_t l = 0; l < n; l++) {
            double r = 1.0 / (rt * fabs(y[l]) + at), q = fabs(y[l] * r);
            rw[l] = r;
            s = MAXD(s, q);
        }
    }
    return s;     /* max |y/w|, for the round-off test */
}

static double clamp_h(abm *a, double h)
{
    a->h_clamped = 0;
    if (h > a->hmax) {
        h = a->hmax;
        a->h_clamped = 1;
    }
    if (a->t + h > a->tstop) {
        h = a->tstop - a->t;
        a->h_clamped = 1;
    }
    return h;
}

/* First call: f(t0, y0), initial step, order 1, start phase.  Any failure of
 * f here is fatal, a positive value too: the initial state itself is invalid. */
static int start(abm *a, double tout)
{
    size_t n = a->n;
    if (eval(a, a->t, a->y, a->phi + n))
        return SWIM_ODE_ERHS;
    set_weights(a);
    double s = 0.0;
    for (size_t l = 0; l < n; l++) {
        double q = fabs(a->phi[n + l] * a->rw[l]);
        s = MAXD(s, q);
    }
    double h = a->h;
    if (!(h > 0)) {
        /* the step for which an order-1 error of size 1/16 * ... is expected:
         * h ~ 0.25 sqrt(1/|f/w|), never more than the distance to tout */
        h = tout - a->t;
        if (16.0 * s * h * h > 1.0)
            h = 0.25 * sqrt(1.0 / s);
    }
    double hmin = 4.0 * UROUND * fabs(a->t);
    if (h < hmin)
        h = hmin;
    a->h = clamp_h(a, h);
    a->hold = 0.0;
    a->k = 1;
    a->kold = 0;
    a->ns = 0;
    a->phase1 = 1;
    a->ifail = 0;
    a->g[1] = 1.0;
    a->g[2] = 0.5;
    a->sig[1] = 1.0;
    a->alpha[1] = 1.0;
    a->beta[1] = 1.0;
    a->started = 1;
    return SWIM_ODE_OK;
}

/* Coefficients alpha, beta, sigma, psi(n+1), g for the step of size h, order k.
 * Only the entries that change on a run of ns equal steps are recomputed. */
static void coefficients(abm *a)
{
    int k = a->k;
    double h = a->h;
    if (h != a->hold)
        a->ns = 0;
    if (a->ns <= a->kold)
        a->ns++;
    int ns = a->ns;
    if (k < ns)
        return;              /* everything needed is unchanged from the last step */
    /* save the parts of the step history that are about to be overwritten */
    memcpy(a->psi_save, a->psi, sizeof a->psi);
    memcpy(a->v_save, a->v, sizeof a->v);
    a->saved = 1;
    double *psi = a->psi, *alpha = a->alpha, *beta = a->beta, *sig = a->sig;
    double *v = a->v, *w = a->w, *g = a->g;
    beta[ns] = 1.0;
    alpha[ns] = 1.0 / ns;
    sig[ns + 1] = 1.0;
    double next = h * ns;    /* psi_ns(n+1) */
    for (int i = ns + 1; i <= k; i++) {
        double old = psi[i - 1];           /* psi_{i-1}(n) */
        psi[i - 1] = next;                 /* psi_{i-1}(n+1) */
        beta[i] = beta[i - 1] * next / old;
        next = old + h;                    /* psi_i(n+1) = psi_{i-1}(n) + h */
        alpha[i] = h / next;
        sig[i + 1] = i * alpha[i] * sig[i];
    }
    psi[k] = next;

    /* v holds g_{ns,q} carried over the run of equal steps; w is the working
     * column that is advanced to g_{k+1,q}. */
    if (ns == 1) {
        for (int q = 1; q <= k; q++) {
            v[q] = 1.0 / (q * (q + 1.0));
            w[q] = v[q];
        }
    } else {
        if (k > a->kold) {
            /* order went up: extend v by one entry along the anti-diagonal */
            v[k] = 1.0 / (k * (k + 1.0));
            for (int j = 1; j <= ns - 2; j++) {
                int i = k - j;
                v[i] -= alpha[j + 1] * v[i + 1];
            }
        }
        double an = alpha[ns];
        for (int q = 1; q <= k + 1 - ns; q++) {
            v[q] -= an * v[q + 1];
            w[q] = v[q];
        }
        g[ns + 1] = w[1];
    }
    for (int i = ns + 2; i <= k + 1; i++) {
        double ai = alpha[i - 1];
        for (int q = 1; q <= k + 2 - i; q++)
            w[q] -= ai * w[q + 1];
        g[i] = w[1];
    }
}

/* Undo the changes a step attempt made to the step history (the difference
 * table, y and t were not touched). */
static void restore_history(abm *a, int ns_save)
{
    if (a->saved) {
        memcpy(a->psi, a->psi_save, sizeof a->psi);
        memcpy(a->v, a->v_save, sizeof a->v);
    }
    a->ns = ns_save;
}

/* The attempt of size h failed because f returned rc > 0 (at p or at y_{n+1}):
 * restore, cut the step by ABM_DOMFAC and drop to order 1 from the third
 * failure in a row on.  Too many such failures in a row, or a step below the
 * minimum, make it fatal. */
static int domain_failure(abm *a, int ns_save, double h)
{
    restore_history(a, ns_save);
    a->rejected++;
    a->la_erk = 0.0;
    a->phase1 = 0;
    a->ifail++;
    a->domfail++;
    if (a->ifail >= 3)
        a->k = 1;
    a->h = clamp_h(a, ABM_DOMFAC * h);
    if (a->domfail > ABM_MAXDOMFAIL || !(a->h >= 4.0 * UROUND * fabs(a->t)) || !(a->h > 0))
        return SWIM_ODE_ERHS;
    return SWIM_ODE_OK;
}

int abm_step(abm *a, int *accepted)
{
    *accepted = 0;
    const size_t n = a->n;
    const int k = a->k;
    double h = a->h;

    if (a->steps >= a->max_steps)
        return SWIM_ODE_EMAXSTEPS;
    if (!(h >= 4.0 * UROUND * fabs(a->t)) || !(h > 0))
        return SWIM_ODE_EHMIN;

    /* Can double precision hold the requested accuracy?  round = 2u max|y/w|. */
    const double round = 2.0 * UROUND * set_weights(a);
    if (0.5 < round)
        return SWIM_ODE_ETOLTOOSMALL;
    a->compensate = 0.5 < 1e3 * round;
    int ns_save = a->ns;

    a->saved = 0;
    coefficients(a);

    /* Predict.  phin rows 1..k get the partial sums sum_{j>=i} phi*_j.
     * Loops run over rows outside and components inside so that the inner
     * loops are independent and vectorise. */
    const double *g = a->g, *beta = a->beta;
    double *phi = a->phi, *phin = a->phin;
    double *restrict pinc = a->pinc, *restrict pp = a->p;
    {
        /* Blocks of 4 components; the order index runs inside so that the
         * partial sums stay in registers (4 independent chains). */
        const double *restrict yy = a->y, *restrict yc = a->yc;
        size_t l = 0;
        for (; l + 4 <= n; l += 4) {
            double c0 = 0, c1 = 0, c2 = 0, c3 = 0, a0 = 0, a1 = 0, a2 = 0, a3 = 0;
            for (int i = k; i >= 1; i--) {
                const double *restrict s1 = phi + i * n + l;
                double *restrict d1 = phin + i * n + l;
                const double bi = beta[i], gi = g[i];
                double p0 = bi * s1[0], p1 = bi * s1[1], p2 = bi * s1[2], p3 = bi * s1[3];
                c0 += p0; c1 += p1; c2 += p2; c3 += p3;
                d1[0] = c0; d1[1] = c1; d1[2] = c2; d1[3] = c3;
                a0 += gi * p0; a1 += gi * p1; a2 += gi * p2; a3 += gi * p3;
            }
            pinc[l] = h * a0; pinc[l + 1] = h * a1; pinc[l + 2] = h * a2; pinc[l + 3] = h * a3;
        }
        for (; l < n; l++) {
            double c0 = 0, a0 = 0;
            for (int i = k; i >= 1; i--) {
                double p0 = beta[i] * phi[i * n + l];
                c0 += p0;
                phin[i * n + l] = c0;
                a0 += g[i] * p0;
            }
            pinc[l] = h * a0;
        }
        for (l = 0; l < n; l++)
            pp[l] = yy[l] + (pinc[l] + yc[l]);
    }
    /* t_{n+1} = t_n + h with compensated summation: over 10^5..10^6 steps the
     * rounding of t += h would otherwise drift t by up to steps * ulp(t)/2 (a
     * systematic shift for runs of equal steps), i.e. the solution would be
     * reported at, and a time-dependent f evaluated at, the wrong times. */
    double tau = h + a->tc, tnew = a->t + tau, tcnew = tau - (tnew - a->t);
    if (a->h_clamped && a->t + h >= a->tstop) {
        tnew = a->tstop;
        tcnew = 0.0;
    }
    int rc = eval(a, tnew, a->p, a->fp);
    if (rc < 0)
        return SWIM_ODE_ERHS;
    if (rc > 0)
        return domain_failure(a, ns_save, h);

    /* Error estimates at orders k, k-1, k-2 from phi_{k+1}, phi_k, phi_{k-1} at n+1,
     * in the weighted max norm (the norm of ode113): an RMS norm divides by n, so
     * components whose error is zero (locked coordinates, constants) would
     * loosen the test on the others by sqrt(n / active). */
    double sk = 0.0, skm1 = 0.0, skm2 = 0.0;
    const double *restrict c1 = phin + n, *restrict ck = phin + k * n, *restrict ckm1 = phin + (k - 1) * n;
    const double *restrict fpv = a->fp, *restrict rwv = a->rw;
    if (k >= 3) {
        for (size_t l = 0; l < n; l++) {
            double e = fpv[l] - c1[l], r = rwv[l];
            double q0 = fabs(e * r), q1 = fabs((ck[l] + e) * r), q2 = fabs((ckm1[l] + e) * r);
            sk = MAXD(sk, q0);
            skm1 = MAXD(skm1, q1);
            skm2 = MAXD(skm2, q2);
        }
    } else {
        for (size_t l = 0; l < n; l++) {
            double e = fpv[l] - c1[l], r = rwv[l];
            double q0 = fabs(e * r), q1 = fabs((ck[l] + e) * r);
            sk = MAXD(sk, q0);
            skm1 = MAXD(skm1, q1);
        }
    }
    /* For the look-ahead: the same estimate in the norm of the last step (its weights), so
     * that its growth measures the solution, not weights that change with |y|. */
    double sk_last = 0.0;
    const int want_rho = (a->lookahead > 0 || a->on_step) && a->la_erk > 10.0 * round;
    if (want_rho) {
        const double *restrict rpv = a->rwp;
        for (size_t l = 0; l < n; l++)
            sk_last = MAXD(sk_last, fabs((fpv[l] - c1[l]) * rpv[l]));
    }
    const double absh = fabs(h);
    const double *sig = a->sig, *gs = a->gstar;
    double erk = absh * sig[k + 1] * gs[k] * sk;
    const double erk_k = erk;
    double err = absh * (g[k] - g[k + 1]) * sk;
    double erkm1 = 0.0, erkm2 = 0.0;
    int knew = k;
    if (k >= 2) {
        erkm1 = absh * sig[k] * gs[k - 1] * skm1;
        if (k >= 3) {
            erkm2 = absh * sig[k - 1] * gs[k - 2] * skm2;
            if (MAXD(erkm1, erkm2) <= erk)
                knew = k - 1;
        } else if (erkm1 <= 0.5 * erk) {
            knew = 1;
        }
    }

    if (!(err <= 1.0)) {
        /* Rejected: the old table was never touched; put back the history. */
        restore_history(a, ns_save);
        a->rejected++;
        a->la_erk = 0.0;
        a->phase1 = 0;
        if (a->on_step) {
            swim_ode_step s = {tnew, h, k, 0, err, erk_k, 0.0, NULL};
            a->on_step(&s, a->on_step_data);
        }
        a->ifail++;
        double fac = 0.5;
        if (a->ifail > 3 && 0.5 < 0.25 * erk)
            fac = sqrt(0.5 / erk);
        if (a->ifail >= 3)
            knew = 1;
        a->k = knew;
        a->h = clamp_h(a, fac * h);
        if (!(a->h >= 4.0 * UROUND * fabs(a->t)))
            return SWIM_ODE_EHMIN;
        return SWIM_ODE_OK;
    }

    /* Passed the error test: correct into the second buffers yn, ycn (y, yc
     * stay as they are until the final evaluation has succeeded). */
    const double gk1h = h * g[k + 1];
    {
        const double *restrict yo = a->y, *restrict yco = a->yc, *restrict pi = a->pinc;
        double *restrict yn = a->yn, *restrict ycn = a->ycn;
        if (a->compensate) {
            for (size_t l = 0; l < n; l++) {
                double d = pi[l] + gk1h * (fpv[l] - c1[l]);
                double tau = d + yco[l];
                double y1 = yo[l] + tau;
                ycn[l] = tau - (y1 - yo[l]);
                yn[l] = y1;
            }
        } else {
            for (size_t l = 0; l < n; l++) {
                yn[l] = yo[l] + (pi[l] + gk1h * (fpv[l] - c1[l]));
                ycn[l] = 0.0;
            }
        }
    }
    if (a->project) {
        rc = a->project(tnew, a->yn, a->par);
        if (rc) {
            a->rhs_status = rc;
            return SWIM_ODE_ERHS;
        }
        memset(a->ycn, 0, n * sizeof(double));   /* the carries belonged to the unprojected y */
    }
    rc = eval(a, tnew, a->yn, a->fp);
    if (rc < 0)
        return SWIM_ODE_ERHS;
    if (rc > 0)
        return domain_failure(a, ns_save, h);
    /* Accepted: y_{n+1} becomes current, update the differences. */
    {
        double *sw = a->y;
        a->y = a->yn;
        a->yn = sw;
        sw = a->yc;
        a->yc = a->ycn;
        a->ycn = sw;
    }
    a->t = tnew;
    a->tc = tcnew;
    a->kold = k;
    a->hold = h;
    a->ifail = 0;
    a->domfail = 0;
    /* raising the order is only considered after k+1 equal steps; then
     * beta_{k+1} = 1 and phi_{k+2}(n+1) = phi_{k+1}(n+1) - phi_{k+1}(n). */
    int want_up = !a->phase1 && knew == k && k < KM && k + 1 <= a->ns;
    double *restrict ek1 = phin + (k + 1) * n, *restrict ek2 = phin + (k + 2) * n;
    const double *restrict ok1 = phi + (k + 1) * n;
    double sk2 = 0.0;
    for (size_t l = 0; l < n; l++)
        ek1[l] = fpv[l] - c1[l];
    if (want_up) {
        for (size_t l = 0; l < n; l++) {
            double d = ek1[l] - ok1[l];
            ek2[l] = d;
            d = fabs(d * rwv[l]);
            sk2 = MAXD(sk2, d);
        }
    }
    {
        size_t l = 0;
        for (; l + 4 <= n; l += 4) {
            const double e0 = ek1[l], e1 = ek1[l + 1], e2 = ek1[l + 2], e3 = ek1[l + 3];
            for (int i = 1; i <= k; i++) {
                double *restrict row = phin + i * n + l;
                row[0] += e0; row[1] += e1; row[2] += e2; row[3] += e3;
            }
        }
        for (; l < n; l++)
            for (int i = 1; i <= k; i++)
                phin[i * n + l] += ek1[l];
    }
    a->phi = phin;
    a->phin = phi;
    a->have_step = 1;
    a->steps++;
    a->hist[k]++;
    a->last_h = h;
    a->last_order = k;

    /* Order for the next step. */
    int kn = k;
    if (knew == k - 1 || k == KM)
        a->phase1 = 0;
    if (a->phase1) {
        kn = k + 1;
    } else if (knew == k - 1) {
        kn = k - 1;
        erk = erkm1;
    } else if (want_up) {
        double erkp1 = absh * gs[k + 1] * sk2;
        if (k == 1) {
            if (erkp1 < 0.5 * erk) {
                kn = 2;
                erk = erkp1;
            }
        } else if (erkm1 <= MIND(erk, erkp1)) {
            kn = k - 1;
            erk = erkm1;
        } else if (erkp1 < erk) {
            kn = k + 1;
            erk = erkp1;
        }
    }
    a->k = kn;

    /* Look-ahead (see the top of the file): at an unchanged order, extrapolate a
     * growing error estimate p steps ahead. */
    double la_rho = 0.0;
    if (kn == k && !a->phase1) {
        double e = erk;
        /* estimates within 10x of the rounding level grow and shrink with noise: no trend */
        if (want_rho && e > 10.0 * round) {
            double rho = absh * sig[k + 1] * gs[k] * sk_last / a->la_erk;
            if (a->la_h != h)
                rho *= pow(a->la_h / h, k + 1);
            la_rho = rho;   /* reported to on_step even when the look-ahead is off */
            if (a->lookahead > 0 && rho > 1.0) {
                rho = MIND(rho, ABM_GROWTH_CAP);
                for (int i = 0; i < a->lookahead; i++)
                    erk *= rho;
            }
        }
        a->la_erk = e;
        a->la_h = h;
        double *sw = a->rwp;     /* this step's weights become the reference norm */
        a->rwp = a->rw;
        a->rw = sw;
    } else {
        a->la_erk = 0.0;
    }

    /* Step size: double, keep, or reduce by a factor in [0.5, 0.9]. */
    double hn;
    if (a->phase1 || 0.5 >= erk * (double)(2 << kn)) {
        hn = 2.0 * h;
    } else if (0.5 >= erk) {
        hn = h;
    } else {
        double r = pow(0.5 / erk, 1.0 / (kn + 1));
        hn = h * MAXD(0.5, MIND(0.9, r));
    }
    const int cut = hn < h;
    double hmin = 4.0 * UROUND * fabs(a->t);
    if (hn < hmin)
        hn = hmin;
    int was_clamped = a->h_clamped;
    hn = clamp_h(a, hn);
    if (was_clamped && hn == h) /* re-clamping to the same hmax keeps the run of equal steps */
        hn = h;
    a->h = hn;

    /* Stiffness diagnostic.  Accepted steps are grouped in blocks of
     * STIFF_BLOCK.  A block looks stability-limited when most of its steps are
     * at order <= 4, the step size stays within a factor 16 (pinned), the
     * steps were not cut by hmax/tstop, and the error control keeps cutting the
     * step (error-test failures, or reductions after accepted steps, which the
     * look-ahead makes where failures would come) although the step does not
     * grow: an unstable parasitic mode, not the solution, is being controlled.
     * STIFF_BLOCKS such blocks in a row raise the flag. */
    if (!a->phase1) {
        if (a->blk_n == 0) {
            a->blk_hmin = a->blk_hmax = h;
            a->blk_low = a->blk_clamped = a->blk_cuts = 0;
            a->blk_rej0 = a->rejected;
        }
        a->blk_n++;
        a->blk_low += k <= 4;
        a->blk_clamped += was_clamped;
        a->blk_cuts += cut;
        a->blk_hmin = fmin(a->blk_hmin, h);
        a->blk_hmax = fmax(a->blk_hmax, h);
        if (a->blk_n == STIFF_BLOCK) {
            long cuts = a->rejected - a->blk_rej0 + a->blk_cuts;
            int stiff_like = a->blk_low >= STIFF_BLOCK / 2 && a->blk_clamped == 0 &&
                             a->blk_hmax <= 16.0 * a->blk_hmin && cuts >= STIFF_BLOCK / 20;
            a->stiff_run = stiff_like ? a->stiff_run + 1 : 0;
            if (a->stiff_run >= STIFF_BLOCKS)
                a->stiff_suspected = 1;
            a->blk_n = 0;
        }
    }

    if (a->on_step) {
        swim_ode_step s = {a->t, h, k, 1, err, erk_k, la_rho, a->y};
        a->on_step(&s, a->on_step_data);
    }
    *accepted = 1;
    return SWIM_ODE_OK;
}

void abm_interp(const abm *a, double tout, double *yout, double *ypout)
{
    const size_t n = a->n;
    const int ki = a->kold + 1;   /* phi_1 .. phi_{kold+1}(n+1) are valid */
    const double s = (tout - a->t) - a->tc;
    /* gi[j] = g_{j,1}(s), cj[j] = c_j(s) with
     * c_{j+1} = c_j (s + psi_{j-1})/psi_j and the integrals advanced by
     * g_{j+1,q} = gamma g_{j,q} - eta g_{j,q+1}, gamma = (s+psi_{j-1})/psi_j, eta = s/psi_j. */
    double wq[KM + 3], gi[KM + 3], cj[KM + 3];
    for (int q = 1; q <= ki; q++)
        wq[q] = 1.0 / q;
    gi[1] = 1.0;
    cj[1] = 1.0;
    double prev = 0.0;   /* psi_{j-1} */
    for (int j = 1; j < ki; j++) {
        double pj = a->psi[j];
        double gam = (s + prev) / pj, eta = s / pj;
        for (int q = 1; q <= ki - j; q++)
            wq[q] = gam * wq[q] - eta * wq[q + 1];
        gi[j + 1] = wq[1];
        cj[j + 1] = cj[j] * gam;
        prev = pj;
    }
    for (size_t l = 0; l < n; l++) {
        double sy = 0.0, sd = 0.0;
        for (int i = ki; i >= 1; i--) {
            double ph = a->phi[i * n + l];
            sy += gi[i] * ph;
            sd += cj[i] * ph;
        }
        yout[l] = a->y[l] + (s * sy + a->yc[l]);
        if (ypout)
            ypout[l] = sd;
    }
}

int abm_advance(abm *a, double tout, double *yout)
{
    if (!(tout > a->tout_last) || tout > a->tstop)
        return SWIM_ODE_EBADARG;
    if (!a->started) {
        int rc = start(a, tout);
        if (rc)
            return rc;
    }
    while (a->t < tout) {
        if (a->have_step && isfinite(a->tstop) && a->tstop - a->t <= 64.0 * UROUND * fmax(fabs(a->t), fabs(a->tstop)))
            break;   /* at tstop up to rounding: extrapolate the last polynomial */
        int acc, rc = abm_step(a, &acc);
        if (rc)
            return rc;
        if (acc && a->stiff_stop && a->stiff_suspected)
            return SWIM_ODE_ESTIFF;
    }
    abm_interp(a, tout, yout, NULL);
    a->tout_last = tout;
    return SWIM_ODE_OK;
}

void abm_get_stats(const abm *a, swim_ode_stats *st)
{
    memset(st, 0, sizeof *st);
    st->steps = a->steps;
    st->rhs_evals = a->nfe;
    st->rejected = a->rejected;
    st->jac_evals = 0;
    for (int i = 0; i <= KM; i++)
        st->order_hist[i] = a->hist[i];
    st->last_h = a->last_h;
    st->last_order = a->last_order;
    st->stiff_suspected = a->stiff_suspected;
}

double abm_time(const abm *a) { return a->t; }
int abm_rhs_status(const abm *a) { return a->rhs_status; }
const double *abm_state(const abm *a) { return a->y; }
double abm_next_h(const abm *a) { return a->h; }
int abm_next_order(const abm *a) { return a->k; }

size_t abm_snapshot(const abm *a, double *buf)
{
    size_t n = a->n, m = 0;
    size_t total = 1 + 2 * n + NROW * n + (KM + 3) * 2 + 1;
    if (!buf)
        return total;
    buf[m++] = a->t;
    memcpy(buf + m, a->y, n * sizeof(double)); m += n;
    memcpy(buf + m, a->yc, n * sizeof(double)); m += n;
    memcpy(buf + m, a->phi, NROW * n * sizeof(double)); m += NROW * n;
    memcpy(buf + m, a->psi, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->v, (KM + 3) * sizeof(double)); m += KM + 3;
    buf[m++] = a->ns;
    return m;
}
