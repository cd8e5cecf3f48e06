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
    /* problem and options (fixed after abm_create) */
    size_t n;                    /* dimension */
    size_t m;                    /* the error control looks at components 0 .. m-1 (swim_ode_options.error_dim) */
    swim_ode_func f;             /* right-hand side */
    void *par;                   /* its params (borrowed) */
    double rtol, atol;           /* scalar tolerances */
    double *atolv;               /* per-component atol (owned copy) or NULL */
    const double *tol_scale;     /* per-component factors on the tolerance (caller's, live) or NULL */
    double (*invariant)(double t, const double *y, double *noise, void *data);   /* balance under error control, or NULL */
    void *invariant_data;
    double invariant_tol;
    double hmax, tstop;          /* largest step (INFINITY = none); never step past tstop */
    long max_steps;              /* accepted steps allowed */
    int stiff_stop;              /* the caller wants SWIM_ODE_ESTIFF when the diagnostic fires */
    int lookahead;               /* p of the look-ahead (0 = STEP's rule) */
    int (*project)(double t, double *y, void *params);          /* optional projection of y_{n+1} */
    void (*on_step)(const swim_ode_step *step, void *data);     /* optional step report */
    void *on_step_data;          /* its data */

    /* solution */
    double t;                    /* t_n */
    double tc;                   /* compensated-summation carry for t (t_n = t + tc exactly up to rounding) */
    double *y;                   /* y_n */
    double *yc;                  /* compensated-summation carry for y */
    double *yn, *ycn;            /* y_{n+1} and its carry during a step attempt (swapped with y, yc on acceptance) */
    double *base;                /* the one allocation holding all vectors */

    /* method state */
    double *phi, *phin;          /* difference tables phi_i(n), phi_i(n+1): NROW rows of n (row i at i*n) */
    double *p, *pinc, *fp;       /* predictor p, its increment p - y_n, f at p (then at y_{n+1}) */
    double *rw;                  /* 1/weights of this step (weighted max norm) */
    double *rwp;                 /* 1/weights of the last accepted step (look-ahead) */
    double psi[KM + 3];          /* psi_i = t_{n+1} - t_{n+1-i} */
    double alpha[KM + 3];        /* alpha_i = h / psi_i */
    double beta[KM + 3];         /* beta_i: phi*_i = beta_i phi_i(n) */
    double sig[KM + 3];          /* sigma_i: error-estimate factors for variable steps */
    double g[KM + 3];            /* integration coefficients g_{i,1} */
    double v[KM + 3];            /* g_{ns,q} carried over runs of equal steps */
    double gstar[KM + 3];        /* |gamma*_m|, error constants of the order-m Adams-Moulton formula */
    double psi_save[KM + 3], v_save[KM + 3];   /* step history before this attempt changed it ... */
    double alpha_save[KM + 3], beta_save[KM + 3], sig_save[KM + 3], g_save[KM + 3];   /* ... and its coefficients */
    double h, hold;              /* step size of this attempt; of the last accepted step */
    int k, kold;                 /* order of this attempt; of the last accepted step */
    int ns;                      /* steps taken with the current h (coefficients reused while ns > k) */
    int phase1;                  /* start phase: order and step grow until an estimate says stop */
    int ifail;                   /* failed attempts in a row (error test or domain) */
    int started;                 /* f(t0, y0) and the first step size are set */
    int compensate;              /* use compensated summation for y (tolerance near rounding) */
    int have_step;               /* an accepted step exists (the interpolant is valid) */
    int h_clamped;               /* current h limited by hmax or tstop */
    int saved;                   /* psi_save/v_save hold the history of this attempt */
    int domfail;                 /* domain failures of f in a row (since the last accepted step) */

    /* one step attempt */
    int ns_save;                 /* ns before the attempt, restored on rejection */
    double tnew, tcnew;          /* t_{n+1} of the attempt and its carry */
    double round;                /* rounding level 2u max|y/w| of the attempt's norm */

    /* look-ahead */
    double la_erk, la_h;         /* erk and h of the last accepted step (0: none) */

    /* stiffness diagnostic: blocks of STIFF_BLOCK accepted steps */
    int blk_n, blk_low, blk_clamped, blk_cuts;   /* steps, low-order steps, clamped steps, step cuts */
    long blk_rej0;               /* rejected count at the start of the block */
    double blk_hmin, blk_hmax;   /* range of h in the block */
    int stiff_run;               /* stiff-looking blocks in a row */
    int stiff_suspected;         /* the diagnostic has fired */

    /* statistics */
    long steps, nfe, rejected;   /* accepted steps, f evaluations, rejected attempts */
    long rejected_invariant;     /* ... of which rejected by the balance's error test */
    long hist[KM + 1];           /* accepted steps per order */
    double last_h;               /* size of the last accepted step */
    int last_order;              /* its order */
    int rhs_status;              /* last nonzero value of f or of the projection */
    double tout_last;            /* last output time (outputs must increase) */
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
    a->m = opt->error_dim > 0 && opt->error_dim < n ? opt->error_dim : n;
    a->f = sys->function;
    a->par = sys->params;
    a->rtol = opt->rtol;
    a->tol_scale = opt->tol_scale;
    a->invariant = opt->invariant;
    a->invariant_data = opt->invariant_data;
    a->invariant_tol = opt->invariant_tol;
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

/* Weights a->rw = 1/(rtol|y_n| + atol_i) for the weighted max norm, of the components under
 * error control (the others have none: no norm reads them). */
static double set_weights(abm *a)
{
    const size_t n = a->m;
    const double rt = a->rtol, at = a->atol;
    const double *restrict y = a->y, *restrict av = a->atolv;
    double *restrict rw = a->rw;
    /* the weights first (loops the compiler vectorizes: the divisions run 4 or 8 at a time), then
     * the maximum, a chain of comparisons in component order */
    if (a->tol_scale) {
        const double *restrict sc = a->tol_scale;
        for (size_t l = 0; l < n; l++)
            rw[l] = 1.0 / (sc[l] * (rt * fabs(y[l]) + (av ? av[l] : at)));
    } else if (av) {
        for (size_t l = 0; l < n; l++)
            rw[l] = 1.0 / (rt * fabs(y[l]) + av[l]);
    } else {
        for (size_t l = 0; l < n; l++)
            rw[l] = 1.0 / (rt * fabs(y[l]) + at);
    }
    double s = 0.0;
    for (size_t l = 0; l < n; l++) {
        const double q = fabs(y[l] * rw[l]);
        s = MAXD(s, q);
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
    for (size_t l = 0; l < a->m; l++) {
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

/* 1/q and 1/(q (q + 1)), q = 0..KM+2 (0 where undefined), as the divisions 1.0 / q and
 * 1.0 / (q * (q + 1.0)) round them (both are correctly rounded, at compile time or at run time):
 * after a change of h the coefficients are recomputed on the next k steps, and on this problem h
 * changes often enough that they are recomputed at nearly every step. */
static const double inv_q[KM + 3] = {0, 1.0 / 1, 1.0 / 2, 1.0 / 3, 1.0 / 4, 1.0 / 5, 1.0 / 6, 1.0 / 7,
                                     1.0 / 8, 1.0 / 9, 1.0 / 10, 1.0 / 11, 1.0 / 12, 1.0 / 13, 1.0 / 14};
#define INV_QQ1(q) (1.0 / ((q) * ((q) + 1.0)))
static const double inv_qq1[KM + 3] = {0, INV_QQ1(1), INV_QQ1(2), INV_QQ1(3), INV_QQ1(4), INV_QQ1(5),
                                       INV_QQ1(6), INV_QQ1(7), INV_QQ1(8), INV_QQ1(9), INV_QQ1(10),
                                       INV_QQ1(11), INV_QQ1(12), INV_QQ1(13), INV_QQ1(14)};

/* The columns of integration coefficients, g_{j,q} for q = 1 .. KM + 2 at the most, held in two
 * vectors of 8 lanes (lane q - 1), for the recurrences g_{j+1,q} = gam g_{j,q} - eta g_{j,q+1}
 * over all q at once: the lanes stay in registers from one j to the next instead of being stored
 * and loaded back (shifted by one entry) in every round. Each entry is computed by the same two
 * products and difference as entry by entry; entries past those a round needs are computed from
 * whatever lies there and never read. */
typedef double col8 __attribute__((vector_size(8 * sizeof(double))));
typedef struct {
    col8 lo, hi;                 /* q = 1..8, 9..16 */
} column;

/* w1[0 .. KM + 1] (g_{j,1 .. KM+2}, of which the caller's column is the first entries) into lanes
 * 0 .. KM + 1; fixed sizes, so no library call */
static inline column column_load(const double *w1)
{
    _Static_assert(KM + 2 > 8 && KM + 2 <= 16, "a column fits two vectors of 8");
    column c;
    double hi[8] = {0};
    memcpy(&c.lo, w1, sizeof c.lo);
    memcpy(hi, w1 + 8, sizeof(double) * (KM + 2 - 8));
    memcpy(&c.hi, hi, sizeof c.hi);
    return c;
}

/* lanes 0 .. len-1 into w1[0 .. len-1] (the rest of w1 as it was) */
static inline void column_store(const column *c, double *w1, int len)
{
    double buf[16];
    memcpy(buf, &c->lo, sizeof c->lo);
    memcpy(buf + 8, &c->hi, sizeof c->hi);
    for (int q = 0; q < len; q++)
        w1[q] = buf[q];
}

/* g_{j,q} <- gam g_{j,q} - eta g_{j,q+1} for every q; returns the new g_{j,1} */
static inline double column_step(column *c, double gam, double eta)
{
    const col8 zero = {0};   /* lane q + 1 of (lo, hi) and of (hi, 0): index 8 is the second vector's first */
    const col8 next_lo = __builtin_shufflevector(c->lo, c->hi, 1, 2, 3, 4, 5, 6, 7, 8),
               next_hi = __builtin_shufflevector(c->hi, zero, 1, 2, 3, 4, 5, 6, 7, 8);
    c->lo = gam * c->lo - eta * next_lo;
    c->hi = gam * c->hi - eta * next_hi;
    return c->lo[0];
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
    memcpy(a->alpha_save, a->alpha, sizeof a->alpha);
    memcpy(a->beta_save, a->beta, sizeof a->beta);
    memcpy(a->sig_save, a->sig, sizeof a->sig);
    memcpy(a->g_save, a->g, sizeof a->g);
    a->saved = 1;
    double *psi = a->psi, *alpha = a->alpha, *beta = a->beta, *sig = a->sig;
    double *v = a->v, *g = a->g;
    beta[ns] = 1.0;
    alpha[ns] = inv_q[ns];
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

    /* v holds g_{ns,q} carried over the run of equal steps; the working column w (from v) is
     * advanced to g_{k+1,q}. */
    column w;
    if (ns == 1) {
        for (int q = 1; q <= k; q++)
            v[q] = inv_qq1[q];
        w = column_load(inv_qq1 + 1);   /* v's entries, from the table: a load of v just stored stalls */
    } else {
        if (k > a->kold) {
            /* order went up: extend v by one entry along the anti-diagonal */
            v[k] = inv_qq1[k];
            for (int j = 1; j <= ns - 2; j++) {
                int i = k - j;
                v[i] -= alpha[j + 1] * v[i + 1];
            }
        }
        /* v_q <- v_q - alpha_ns v_{q+1}, q = 1 .. k + 1 - ns: a step of the column */
        w = column_load(v + 1);
        g[ns + 1] = column_step(&w, 1.0, alpha[ns]);
        column_store(&w, v + 1, k + 1 - ns);
    }
    for (int i = ns + 2; i <= k + 1; i++)   /* g_{i,q} = g_{i-1,q} - alpha_{i-1} g_{i-1,q+1} */
        g[i] = column_step(&w, 1.0, alpha[i - 1]);
}

/* Undo the changes a step attempt made to the step history (the difference
 * table, y and t were not touched). */
static void restore_history(abm *a, int ns_save)
{
    if (a->saved) {
        memcpy(a->psi, a->psi_save, sizeof a->psi);
        memcpy(a->v, a->v_save, sizeof a->v);
        /* the coefficients too: a doubled step that fails is retried at exactly hold, and with
         * ns restored coefficients() keeps those of the run of equal steps -- they must be the
         * run's, not the failed attempt's (with these, an error estimate of either sign let a
         * step with an arbitrary error through: an energy jump of 2.9e-5 on soft_n10_a05 at
         * atol 1e-14) */
        memcpy(a->alpha, a->alpha_save, sizeof a->alpha);
        memcpy(a->beta, a->beta_save, sizeof a->beta);
        memcpy(a->sig, a->sig_save, sizeof a->sig);
        memcpy(a->g, a->g_save, sizeof a->g);
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

/* Error estimates of one attempt, from phi_{k+1}(n+1) and its neighbours. */
typedef struct {
    double err;           /* error-test value of the order-k formula (<= 1 passes) */
    double erk;           /* estimated error at order k for a step of this size (STEP's erk) */
    double erkm1, erkm2;  /* the same at orders k-1, k-2 (0 when k is too low) */
    double sk_last;       /* norm of phi_{k+1}(n+1) in the last step's weights (look-ahead) */
    int knew;             /* order the estimates suggest: k or lower */
    int want_rho;         /* the look-ahead's growth factor can be formed */
} abm_estimate;

/* Stop before the attempt: too many steps, step size underflow, or a tolerance
 * below what double precision can hold (round = 2u max|y/w| > 1/2). */
static int check_attempt(abm *a)
{
    if (a->steps >= a->max_steps)
        return SWIM_ODE_EMAXSTEPS;
    if (!(a->h >= 4.0 * UROUND * fabs(a->t)) || !(a->h > 0))
        return SWIM_ODE_EHMIN;
    a->round = 2.0 * UROUND * set_weights(a);
    if (0.5 < a->round)
        return SWIM_ODE_ETOLTOOSMALL;
    a->compensate = 0.5 < 1e3 * a->round;
    return SWIM_ODE_OK;
}

/* Predictor of order k: p = y_n + h sum_{i<=k} g_i phi*_i; phin rows 1..k get the
 * partial sums sum_{j>=i} phi*_j that the corrector and the new differences need.
 * Blocks of 8 components (one vector) and of 4 with the order index inside keep the
 * partial sums in registers (independent chains, one per component, each in the order of
 * the one-component loop); the tail runs one component at a time. */
static void predict(abm *a)
{
    const size_t n = a->n;
    const int k = a->k;
    const double h = a->h;
    const double *g = a->g, *beta = a->beta, *phi = a->phi;
    double *phin = a->phin;
    double *restrict pinc = a->pinc, *restrict pp = a->p;
    const double *restrict yy = a->y, *restrict yc = a->yc;
    size_t l = 0;
    for (; l + 8 <= n; l += 8) {   /* 8 components in one vector, then blocks of 4, then one by one */
        col8 c = {0}, acc = {0}, p;
        for (int i = k; i >= 1; i--) {
            memcpy(&p, phi + i * n + l, sizeof p);
            p = beta[i] * p;
            c += p;
            memcpy(phin + i * n + l, &c, sizeof c);
            acc += g[i] * p;
        }
        acc = h * acc;
        memcpy(pinc + l, &acc, sizeof acc);
    }
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
 * reported at, and a time-dependent f evaluated at, the wrong times.  A step
 * clamped to tstop lands on it exactly. */
static void next_time(abm *a)
{
    const double h = a->h;
    double tau = h + a->tc, tnew = a->t + tau, tcnew = tau - (tnew - a->t);
    if (a->h_clamped && a->t + h >= a->tstop) {
        tnew = a->tstop;
        tcnew = 0.0;
    }
    a->tnew = tnew;
    a->tcnew = tcnew;
}

/* Error estimates at orders k, k-1, k-2 from phi_{k+1}, phi_k, phi_{k-1} at n+1
 * (a->fp holds f(t_{n+1}, p)), in the weighted max norm (the norm of ode113):
 * an RMS norm divides by n, so components whose error is zero (locked
 * coordinates, constants) would loosen the test on the others by sqrt(n / active). */
static void estimate_errors(const abm *a, abm_estimate *e)
{
    const size_t n = a->n, m = a->m;
    const int k = a->k;
    const double *phin = a->phin;
    double sk = 0.0, skm1 = 0.0, skm2 = 0.0;
    const double *restrict c1 = phin + n, *restrict ck = phin + k * n, *restrict ckm1 = phin + (k - 1) * n;
    const double *restrict fpv = a->fp, *restrict rwv = a->rw;
    if (k >= 3) {
        for (size_t l = 0; l < m; l++) {
            double d = fpv[l] - c1[l], r = rwv[l];
            double q0 = fabs(d * r), q1 = fabs((ck[l] + d) * r), q2 = fabs((ckm1[l] + d) * r);
            sk = MAXD(sk, q0);
            skm1 = MAXD(skm1, q1);
            skm2 = MAXD(skm2, q2);
        }
    } else {
        for (size_t l = 0; l < m; l++) {
            double d = fpv[l] - c1[l], r = rwv[l];
            double q0 = fabs(d * r), q1 = fabs((ck[l] + d) * r);
            sk = MAXD(sk, q0);
            skm1 = MAXD(skm1, q1);
        }
    }
    /* For the look-ahead: the same estimate in the norm of the last step (its weights), so
     * that its growth measures the solution, not weights that change with |y|. */
    e->sk_last = 0.0;
    e->want_rho = (a->lookahead > 0 || a->on_step) && a->la_erk > 10.0 * a->round;
    if (e->want_rho) {
        const double *restrict rpv = a->rwp;
        double s = 0.0;
        for (size_t l = 0; l < m; l++)
            s = MAXD(s, fabs((fpv[l] - c1[l]) * rpv[l]));
        e->sk_last = s;
    }
    const double absh = fabs(a->h);
    const double *sig = a->sig, *gs = a->gstar, *g = a->g;
    e->erk = absh * sig[k + 1] * gs[k] * sk;
    e->err = absh * (g[k] - g[k + 1]) * sk;
    e->erkm1 = e->erkm2 = 0.0;
    e->knew = k;
    if (k >= 2) {
        e->erkm1 = absh * sig[k] * gs[k - 1] * skm1;
        if (k >= 3) {
            e->erkm2 = absh * sig[k - 1] * gs[k - 2] * skm2;
            if (MAXD(e->erkm1, e->erkm2) <= e->erk)
                e->knew = k - 1;
        } else if (e->erkm1 <= 0.5 * e->erk) {
            e->knew = 1;
        }
    }
}

/* The error test failed: the old table was never touched; put back the step
 * history, halve the step (more after the third failure in a row, which also
 * drops to order 1). */
static int reject(abm *a, const abm_estimate *e)
{
    const double h = a->h;
    restore_history(a, a->ns_save);
    a->rejected++;
    a->la_erk = 0.0;
    a->phase1 = 0;
    if (a->on_step) {
        swim_ode_step s = {a->tnew, h, a->k, 0, e->err, e->erk, 0.0, NULL};
        a->on_step(&s, a->on_step_data);
    }
    a->ifail++;
    double fac = 0.5;
    if (a->ifail > 3 && 0.5 < 0.25 * e->erk)
        fac = sqrt(0.5 / e->erk);
    a->k = a->ifail >= 3 ? 1 : e->knew;
    a->h = clamp_h(a, fac * h);
    if (!(a->h >= 4.0 * UROUND * fabs(a->t)))
        return SWIM_ODE_EHMIN;
    return SWIM_ODE_OK;
}

/* Corrector with local extrapolation: y_{n+1} = p + h g_{k+1} phi_{k+1}(n+1),
 * written into the second buffers yn, ycn (y, yc stay as they are until the
 * final evaluation has succeeded). */
static void correct(abm *a)
{
    const size_t n = a->n;
    const double gk1h = a->h * a->g[a->k + 1];
    const double *restrict fpv = a->fp, *restrict c1 = a->phin + n;
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

/* Optional projection of y_{n+1} onto the caller's invariant manifold, before
 * the final evaluation so that the derivative history is the projected one. */
static int project(abm *a)
{
    if (!a->project)
        return SWIM_ODE_OK;
    int rc = a->project(a->tnew, a->yn, a->par);
    if (rc) {
        a->rhs_status = rc;
        return SWIM_ODE_ERHS;
    }
    if (a->compensate)   /* the carries belonged to the unprojected y (without, correct() left 0) */
        memset(a->ycn, 0, a->n * sizeof(double));
    return SWIM_ODE_OK;
}

/* The attempt passed: y_{n+1} and t_{n+1} become current. */
static void accept(abm *a)
{
    double *sw = a->y;
    a->y = a->yn;
    a->yn = sw;
    sw = a->yc;
    a->yc = a->ycn;
    a->ycn = sw;
    a->t = a->tnew;
    a->tc = a->tcnew;
    a->kold = a->k;
    a->hold = a->h;
    a->ifail = 0;
    a->domfail = 0;
    a->have_step = 1;
    a->steps++;
    a->hist[a->k]++;
    a->last_h = a->h;
    a->last_order = a->k;
}

/* Differences at n+1 (a->fp holds f(t_{n+1}, y_{n+1})): phi_{k+1}(n+1) = f - sum phi*_i,
 * phi_i(n+1) = phi*_i + ... + phi_{k+1}(n+1), and, when raising the order is to be
 * considered, phi_{k+2}(n+1) = phi_{k+1}(n+1) - phi_{k+1}(n) (beta_{k+1} = 1 after k+1
 * equal steps).  Returns the weighted norm of phi_{k+2}(n+1) (0 when not formed). */
static double update_differences(abm *a, int want_up)
{
    const size_t n = a->n;
    const int k = a->k;
    double *phi = a->phi, *phin = a->phin;
    const double *restrict fpv = a->fp, *restrict c1 = phin + n, *restrict rwv = a->rw;
    double *restrict ek1 = phin + (k + 1) * n, *restrict ek2 = phin + (k + 2) * n;
    const double *restrict ok1 = phi + (k + 1) * n;
    double sk2 = 0.0;
    for (size_t l = 0; l < n; l++)
        ek1[l] = fpv[l] - c1[l];
    if (want_up) {
        const size_t m = a->m;
        for (size_t l = 0; l < m; l++) {
            double d = ek1[l] - ok1[l];
            ek2[l] = d;
            d = fabs(d * rwv[l]);
            sk2 = MAXD(sk2, d);
        }
        for (size_t l = m; l < n; l++)   /* outside the error control: the table only */
            ek2[l] = ek1[l] - ok1[l];
    }
    size_t l = 0;
    for (; l + 8 <= n; l += 8) {   /* as in predict: 8, then 4, then 1 */
        col8 e, row;
        memcpy(&e, ek1 + l, sizeof e);
        for (int i = 1; i <= k; i++) {
            memcpy(&row, phin + i * n + l, sizeof row);
            row += e;
            memcpy(phin + i * n + l, &row, sizeof row);
        }
    }
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
    a->phi = phin;
    a->phin = phi;
    return sk2;
}

/* Order for the next step from the estimates at k-2 .. k+1 (k+1 only after
 * k+1 equal steps); sets a->k and returns the estimate at the chosen order. */
static double choose_order(abm *a, const abm_estimate *e, int want_up, double sk2)
{
    const int k = a->k;
    double erk = e->erk;
    int kn = k;
    if (e->knew == k - 1 || k == KM)
        a->phase1 = 0;
    if (a->phase1) {
        kn = k + 1;
    } else if (e->knew == k - 1) {
        kn = k - 1;
        erk = e->erkm1;
    } else if (want_up) {
        double erkp1 = fabs(a->h) * a->gstar[k + 1] * sk2;
        if (k == 1) {
            if (erkp1 < 0.5 * erk) {
                kn = 2;
                erk = erkp1;
            }
        } else if (e->erkm1 <= MIND(erk, erkp1)) {
            kn = k - 1;
            erk = e->erkm1;
        } else if (erkp1 < erk) {
            kn = k + 1;
            erk = erkp1;
        }
    }
    a->k = kn;
    return erk;
}

/* Look-ahead (see the top of the file): at an unchanged order k, extrapolate a
 * growing error estimate p steps ahead.  *erk is the estimate for the next
 * step; returns the growth rho (0 when it was not formed), for the step report. */
static double look_ahead(abm *a, const abm_estimate *e, int k, double *erk)
{
    const double h = a->h;
    double la_rho = 0.0;
    if (a->k != k || a->phase1) {
        a->la_erk = 0.0;
        return la_rho;
    }
    double est = *erk;
    /* estimates within 10x of the rounding level grow and shrink with noise: no trend */
    if (e->want_rho && est > 10.0 * a->round) {
        double rho = fabs(h) * a->sig[k + 1] * a->gstar[k] * e->sk_last / a->la_erk;
        if (a->la_h != h)
            rho *= pow(a->la_h / h, k + 1);
        la_rho = rho;   /* reported to on_step even when the look-ahead is off */
        if (a->lookahead > 0 && rho > 1.0) {
            rho = MIND(rho, ABM_GROWTH_CAP);
            for (int i = 0; i < a->lookahead; i++)
                *erk *= rho;
        }
    }
    a->la_erk = est;
    a->la_h = h;
    double *sw = a->rwp;     /* this step's weights become the reference norm */
    a->rwp = a->rw;
    a->rw = sw;
    return la_rho;
}

/* Step size for the next step at order a->k: double, keep, or reduce by a factor
 * in [0.5, 0.9], so that runs of equal steps reuse the coefficients.  Sets a->h;
 * *was_clamped says whether the step just taken was limited by hmax/tstop, and
 * the return value whether the error control cut the step. */
static int choose_step(abm *a, double erk, int *was_clamped)
{
    const double h = a->h;
    const int kn = a->k;
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
    *was_clamped = a->h_clamped;
    hn = clamp_h(a, hn);
    if (*was_clamped && hn == h) /* re-clamping to the same hmax keeps the run of equal steps */
        hn = h;
    a->h = hn;
    return cut;
}

/* Stiffness diagnostic.  Accepted steps are grouped in blocks of STIFF_BLOCK.
 * A block looks stability-limited when most of its steps are at order <= 4,
 * the step size stays within a factor 16 (pinned), the steps were not cut by
 * hmax/tstop, and the error control keeps cutting the step (error-test
 * failures, or reductions after accepted steps, which the look-ahead makes
 * where failures would come) although the step does not grow: an unstable
 * parasitic mode, not the solution, is being controlled.  STIFF_BLOCKS such
 * blocks in a row raise the flag.  k and h are those of the step just taken. */
static void stiffness_diagnostic(abm *a, int k, double h, int was_clamped, int cut)
{
    if (a->phase1)
        return;
    if (a->blk_n == 0) {
        a->blk_hmin = a->blk_hmax = h;
        a->blk_low = a->blk_clamped = a->blk_cuts = 0;
        a->blk_rej0 = a->rejected;
    }
    a->blk_n++;
    a->blk_low += k <= 4;
    a->blk_clamped += was_clamped;
    a->blk_cuts += cut;
    a->blk_hmin = MIND(h, a->blk_hmin);   /* fmin, fmax: h > 0 was checked before the attempt */
    a->blk_hmax = MAXD(h, a->blk_hmax);
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

/* The balance's share of the error estimate, in units of its tolerance (0 without one).
 * y_c - p = h g_{k+1} phi_{k+1}(n+1) and the order-k estimate is h (g_k - g_{k+1}) phi_{k+1}(n+1):
 * to first order the balance errs by (g_k - g_{k+1})/g_{k+1} (B(y_c) - B(p)). B is taken after
 * the final evaluation f(y_c), whose by-products make it cheap (swim_ode_options.invariant). The
 * tolerance is never below twice what rounding leaves of that difference: a test rounding can
 * fail would shrink the step to nothing (near the boundary of D, W2's rounding through the shape
 * can exceed any tolerance: there the componentwise test alone governs). */
static double invariant_error(abm *a, double bal_p, double noise_p)
{
    if (!a->invariant)
        return 0.0;
    const int k = a->k;
    const double r = fabs((a->g[k] - a->g[k + 1]) / a->g[k + 1]);
    double noise_c = 0.0;
    const double bal_c = a->invariant(a->tnew, a->yn, &noise_c, a->invariant_data);
    return r * fabs(bal_c - bal_p) / MAXD(a->invariant_tol, 2.0 * r * (noise_p + noise_c));
}

/* One PECE step attempt of order k and size h:
 *   coefficients -> predict -> evaluate f(p) -> estimate -> [reject]
 *   -> correct -> project -> evaluate f(y_{n+1}) -> [balance test: reject] -> accept -> differences
 *   -> order -> look-ahead -> step size -> stiffness -> report.
 * A positive value of f at either evaluation is a domain failure (restore,
 * smaller step); a negative one ends the integration. */
int abm_step(abm *a, int *accepted)
{
    *accepted = 0;
    int rc = check_attempt(a);
    if (rc)
        return rc;
    a->ns_save = a->ns;
    a->saved = 0;
    coefficients(a);
    predict(a);
    next_time(a);
    rc = eval(a, a->tnew, a->p, a->fp);
    if (rc < 0)
        return SWIM_ODE_ERHS;
    if (rc > 0)
        return domain_failure(a, a->ns_save, a->h);
    abm_estimate e;
    estimate_errors(a, &e);
    if (!(e.err <= 1.0))
        return reject(a, &e);

    const int k = a->k;
    const double h = a->h;
    /* the balance at the predictor, while the right-hand side's by-products are still its own */
    double noise_p = 0.0;
    const double bal_p = a->invariant ? a->invariant(a->tnew, a->p, &noise_p, a->invariant_data) : 0.0;
    correct(a);
    if ((rc = project(a)))
        return rc;
    rc = eval(a, a->tnew, a->yn, a->fp);
    if (rc < 0)
        return SWIM_ODE_ERHS;
    if (rc > 0)
        return domain_failure(a, a->ns_save, h);
    const double inv = invariant_error(a, bal_p, noise_p);
    if (!(inv <= 1.0)) {
        a->rejected_invariant++;
        e.err = MAXD(e.err, inv);
        e.erk = MAXD(e.erk, inv);
        return reject(a, &e);
    }
    accept(a);
    const int want_up = !a->phase1 && e.knew == k && k < KM && k + 1 <= a->ns;
    const double sk2 = update_differences(a, want_up);
    double erk = choose_order(a, &e, want_up, sk2);
    const double la_rho = look_ahead(a, &e, k, &erk);
    if (inv > e.err)   /* the balance limits this step: size the next one for it */
        erk *= inv / MAXD(e.err, 1e-300);
    int was_clamped;
    const int cut = choose_step(a, erk, &was_clamped);
    stiffness_diagnostic(a, k, h, was_clamped, cut);
    if (a->on_step) {
        swim_ode_step s = {a->t, h, k, 1, e.err, e.erk, la_rho, a->y};
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
    /* g_{1,q} = 1/q */
    double gi[KM + 3], cj[KM + 3];
    column wq = column_load(inv_q + 1);
    gi[1] = 1.0;
    cj[1] = 1.0;
    double prev = 0.0;   /* psi_{j-1} */
    for (int j = 1; j < ki; j++) {
        double pj = a->psi[j];
        double gam = (s + prev) / pj, eta = s / pj;
        gi[j + 1] = column_step(&wq, gam, eta);
        cj[j + 1] = cj[j] * gam;
        prev = pj;
    }
    const double *restrict phi = a->phi, *restrict yy = a->y, *restrict yc = a->yc;
    size_t l = 0;
    if (!ypout) {   /* the value alone (rows, the checks between steps): no derivative sums */
        /* blocks of 8 and 4 components, each its own sum in the same order, as in predict */
        for (; l + 8 <= n; l += 8) {
            col8 sy = {0}, row, y8, c8;
            for (int i = ki; i >= 1; i--) {
                memcpy(&row, phi + i * n + l, sizeof row);
                sy += gi[i] * row;
            }
            memcpy(&y8, yy + l, sizeof y8);
            memcpy(&c8, yc + l, sizeof c8);
            y8 = y8 + (s * sy + c8);
            memcpy(yout + l, &y8, sizeof y8);
        }
        for (; l + 4 <= n; l += 4) {
            double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
            for (int i = ki; i >= 1; i--) {
                const double *restrict row = phi + i * n + l, gv = gi[i];
                s0 += gv * row[0]; s1 += gv * row[1]; s2 += gv * row[2]; s3 += gv * row[3];
            }
            yout[l] = yy[l] + (s * s0 + yc[l]);
            yout[l + 1] = yy[l + 1] + (s * s1 + yc[l + 1]);
            yout[l + 2] = yy[l + 2] + (s * s2 + yc[l + 2]);
            yout[l + 3] = yy[l + 3] + (s * s3 + yc[l + 3]);
        }
        for (; l < n; l++) {
            double sy = 0.0;
            for (int i = ki; i >= 1; i--) sy += gi[i] * phi[i * n + l];
            yout[l] = yy[l] + (s * sy + yc[l]);
        }
        return;
    }
    for (; l < n; l++) {
        double sy = 0.0, sd = 0.0;
        for (int i = ki; i >= 1; i--) {
            double ph = phi[i * n + l];
            sy += gi[i] * ph;
            sd += cj[i] * ph;
        }
        yout[l] = yy[l] + (s * sy + yc[l]);
        ypout[l] = sd;
    }
}

int abm_step_toward(abm *a, double tout, int *done)
{
    *done = 0;
    if (!a->started) {
        int rc = start(a, tout);
        if (rc)
            return rc;
    }
    if (a->t >= tout ||
        (a->have_step && isfinite(a->tstop) && a->tstop - a->t <= 64.0 * UROUND * MAXD(fabs(a->t), fabs(a->tstop)))) {   /* both finite */
        *done = 1;   /* covered, or at tstop up to rounding: extrapolate the last polynomial */
        return SWIM_ODE_OK;
    }
    int acc;
    do {
        int rc = abm_step(a, &acc);
        if (rc)
            return rc;
    } while (!acc);
    if (a->stiff_stop && a->stiff_suspected)
        return SWIM_ODE_ESTIFF;
    return SWIM_ODE_OK;
}

int abm_advance(abm *a, double tout, double *yout)
{
    if (!(tout > a->tout_last) || tout > a->tstop)
        return SWIM_ODE_EBADARG;
    for (;;) {
        int done, rc = abm_step_toward(a, tout, &done);
        if (rc)
            return rc;
        if (done)
            break;
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
    st->rejected_invariant = a->rejected_invariant;
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

void abm_scale(abm *a, size_t from, size_t count, double factor)
{
    const size_t n = a->n;
    for (size_t l = from; l < from + count && l < n; l++) {
        a->y[l] *= factor;
        a->yc[l] *= factor;
        a->fp[l] *= factor;
        for (int i = 0; i < NROW; i++) {
            a->phi[i * n + l] *= factor;
            a->phin[i * n + l] *= factor;
        }
    }
}

size_t abm_snapshot(const abm *a, double *buf)
{
    size_t n = a->n, m = 0;
    size_t total = 1 + 2 * n + NROW * n + (KM + 3) * 6 + 1;
    if (!buf)
        return total;
    buf[m++] = a->t;
    memcpy(buf + m, a->y, n * sizeof(double)); m += n;
    memcpy(buf + m, a->yc, n * sizeof(double)); m += n;
    memcpy(buf + m, a->phi, NROW * n * sizeof(double)); m += NROW * n;
    memcpy(buf + m, a->psi, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->v, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->alpha, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->beta, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->sig, (KM + 3) * sizeof(double)); m += KM + 3;
    memcpy(buf + m, a->g, (KM + 3) * sizeof(double)); m += KM + 3;
    buf[m++] = a->ns;
    return m;
}
