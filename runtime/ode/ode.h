/* swim ODE integrators behind one interface.
 *
 * A problem is described GSL-style by a swim_ode_system (right-hand side,
 * dimension, opaque params).  swim_ode_create() picks an integrator by name at
 * run time: "abm" (default, our Adams-Bashforth-Moulton code of the ode113 /
 * Shampine-Gordon class), the GSL odeiv2 steppers "rk8pd", "msadams", "rkf45",
 * "msbdf" (Jacobian by finite differences), and SUNDIALS CVODE "cvode-adams"
 * (fixed-point iteration) and "cvode-bdf" (dense Newton, difference-quotient
 * Jacobian).
 *
 * Ownership: a swim_ode object owns all of its internal memory and is released
 * with swim_ode_free().  It copies y0, the options and atol_vec at creation, so
 * the caller may reuse those arrays.  The system's params pointer is borrowed
 * and must stay valid while the integrator is used.  yout arrays belong to the
 * caller.  Integration runs forward in time only.
 */
#ifndef SWIM_ODE_ODE_H
#define SWIM_ODE_ODE_H

#include <stddef.h>

/* Right-hand side: dydt = f(t, y).  The return value is the same contract for
 * every method:
 *   0         success.
 *   positive  recoverable: (t, y) lies outside the domain of f (typically a
 *             trial state of a step that was too large: the swimmer's shape
 *             left its admissible set, a mass matrix is no longer positive
 *             definite, NaN ...).  The integrator rejects the step attempt,
 *             restores its state exactly, retries with a smaller step (ABM:
 *             h/4, order 1 from the third failure in a row; GSL: h/2; CVODE:
 *             h/4) and counts the attempt in swim_ode_stats.rejected.  Only
 *             when the step size underflows or the failures persist (ABM and
 *             the GSL peers: more than 20 in a row without an accepted step;
 *             CVODE: its 10 convergence failures per step, or more than 20
 *             without an accepted step of size > 4 u |t|) does
 *             swim_ode_advance() return SWIM_ODE_ERHS, with
 *             swim_ode_rhs_status() the last value.  A positive value at the
 *             initial state (t0, y0) is fatal: the initial state is invalid.
 *   negative  fatal (e.g. an interrupt request): the integration stops at
 *             once, without further calls of f; swim_ode_advance() returns
 *             SWIM_ODE_ERHS and swim_ode_rhs_status() gives the value.
 * The value passed to the integrator should not depend on anything but
 * (t, y): the GSL peers evaluate f at each accepted state a second time, at
 * the start of the next step and outside their retry logic, so a failure
 * there (which a function of (t, y) cannot produce) ends the run. */
typedef int (*swim_ode_func)(double t, const double *y, double *dydt, void *params);

typedef struct {
    swim_ode_func function;
    size_t dimension;
    void *params;
} swim_ode_system;

/* One ABM step attempt, as passed to swim_ode_options.on_step (diagnostics, e.g. swim run
 * --trace-steps). Attempts that f refused (domain failures) are not reported. */
typedef struct {
    double t;              /* t_{n+1} of the attempt */
    double h;              /* its step size */
    int order;             /* k */
    int accepted;          /* 1: accepted; 0: rejected by the error test */
    double err;            /* the error-test value (<= 1 passes) */
    double erk;            /* estimate at order k for a step of the same size (STEP's erk) */
    double growth;         /* rho of the look-ahead (0 when it was not formed) */
    const double *y;       /* accepted: y_{n+1} after projection; rejected: NULL */
} swim_ode_step;

typedef struct {
    double rtol, atol;          /* scalar tolerances (weights rtol*|y_i| + atol_i) */
    const double *atol_vec;     /* optional per-component atol (length dimension), NULL = use atol; copied */
    double hmax;                /* 0 = no limit */
    double h0;                  /* 0 = automatic */
    double tstop;               /* never step past this time (INFINITY = no limit) */
    long max_steps;             /* 0 = default (10^7) */
    int stiff_stop;             /* nonzero: ABM returns SWIM_ODE_ESTIFF when its stiffness diagnostic fires */
    int lookahead;              /* ABM: when the error estimate grows by rho per step, the step-size
                                   decision uses rho^lookahead times it (abm.c); 0..12, 0 = the
                                   classic Shampine-Gordon rule; default 6 */
    /* Optional projection onto an invariant manifold (ABM only; the peers ignore it): called
     * after each accepted step with the corrected y_{n+1}, which it may modify in place, before
     * the final evaluation f(t_{n+1}, y_{n+1}) of PECE -- so the derivative history of the
     * method is the one of the projected states. Nonzero return: stop with SWIM_ODE_ERHS. */
    int (*project)(double t, double *y, void *params);
    /* Optional report of every ABM step attempt (the peers ignore it), with its own data. */
    void (*on_step)(const swim_ode_step *step, void *data);
    void *on_step_data;
} swim_ode_options;

/* rtol = 1e-6, atol = 1e-9, no hmax, automatic h0, tstop = INFINITY,
 * max_steps = 10^7, stiff_stop = 0, lookahead = 6, no projection. */
void swim_ode_options_default(swim_ode_options *opt);

typedef struct {
    long steps;            /* accepted steps */
    long rhs_evals;        /* calls of the right-hand side (including Jacobian differencing) */
    long rejected;         /* rejected step attempts (error test failures, convergence failures,
                              positive right-hand-side values) */
    long jac_evals;        /* Jacobian evaluations (BDF methods) */
    long order_hist[13];   /* accepted steps per order (ABM, CVODE); index = order */
    double last_h;         /* last step size taken */
    int last_order;        /* order of the last step (0 when the method does not report it) */
    int stiff_suspected;   /* ABM: stiffness diagnostic has fired */
} swim_ode_stats;

enum {
    SWIM_ODE_OK = 0,
    SWIM_ODE_EBADARG,       /* bad tolerance, NaN in y0, unknown method, tout not increasing ... */
    SWIM_ODE_ETOLTOOSMALL,  /* tolerance below what double precision can deliver */
    SWIM_ODE_EHMIN,         /* step size underflow */
    SWIM_ODE_ERHS,          /* right-hand side returned a negative value, or positive ones it could not recover from */
    SWIM_ODE_ESTIFF,        /* stiffness suspected (ABM with stiff_stop) */
    SWIM_ODE_EMAXSTEPS,     /* max_steps reached */
    SWIM_ODE_ENOMEM,        /* allocation failed */
    SWIM_ODE_EFAIL          /* peer library failure */
};

typedef struct swim_ode swim_ode;   /* opaque; owns its memory; the caller owns y arrays */

/* method NULL or "" selects "abm".  On success *out receives a new object. */
int swim_ode_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                    double t0, const double *y0, swim_ode **out);
/* Integrate until tout is covered and write y(tout) (from the method's own
 * interpolant where it has one) into yout (caller-owned, length dimension).
 * tout must be > t0 and increase strictly between calls, and not exceed tstop.
 * After an error the object should be freed. */
int swim_ode_advance(swim_ode *s, double tout, double *yout);
int swim_ode_get_stats(const swim_ode *s, swim_ode_stats *st);
double swim_ode_time(const swim_ode *s);  /* time reached by the internal steps */
/* Last nonzero value returned by the right-hand side (or by the projection),
 * 0 if none; after SWIM_ODE_ERHS the value that ended the run.  It may be a
 * recovered positive value after a successful advance. */
int swim_ode_rhs_status(const swim_ode *s);
const char *swim_ode_method_name(const swim_ode *s);
void swim_ode_free(swim_ode *s);
const char *swim_ode_strerror(int status);
const char *const *swim_ode_methods(void); /* NULL-terminated list of names */

#endif
