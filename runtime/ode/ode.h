/* swim ODE integrators behind one interface.
 *
 * A problem is described GSL-style by a swim_ode_system (right-hand side,
 * dimension, opaque params, optional exact Jacobian).  swim_ode_create() picks
 * an integrator by name at run time from one registry: "abm" (default, our
 * Adams-Bashforth-Moulton code of the ode113 / Shampine-Gordon class), the GSL
 * odeiv2 steppers "rk8pd", "msadams", "rkf45", "msbdf", and SUNDIALS CVODE
 * "cvode-adams" (fixed-point iteration) and "cvode-bdf" (dense Newton).
 *
 * Capabilities.  What an integrator can do beyond y' = f(t, y) is a set of
 * SWIM_ODE_CAP_* flags, queried by name with swim_ode_capabilities() -- callers
 * never test integrator names.  An option an integrator cannot honour
 * (projection, step report, events, stiffness stop) makes swim_ode_create()
 * return SWIM_ODE_EUNSUPPORTED instead of being ignored:
 *
 *   name         projection  step trace  events  user Jacobian  stiffness diagnostic  implicit  live weights  balance test  error dim  rescale
 *   abm              x           x         x          -               x                -          x             x            x          x
 *   rk8pd            -           -         -          -               -                -          -             -            -          -
 *   msadams          -           -         -          -               -                -          -             -            -          -
 *   rkf45            -           -         -          -               -                -          -             -            -          -
 *   msbdf            -           -         -          x               -                x          -             -            -          -
 *   cvode-adams      -           -         x          -               -                -          -             -            -          -
 *   cvode-bdf        x           -         x          x               -                x          -             -            -          -
 *
 * A Jacobian in the system is information, not a request: integrators without
 * SWIM_ODE_CAP_JACOBIAN need none and do not call it.  The GSL steppers have no
 * dense output (GSL's driver shortens the last step onto tout), so they offer
 * no events; CVODE projects through CVodeSetProjFn (SUNDIALS >= 5.3, BDF only).
 *
 * Ownership: a swim_ode object owns all of its internal memory and is released
 * with swim_ode_free().  It copies y0, the options, atol_vec and the event
 * list (not the event functions' data) at creation, so the caller may reuse
 * those arrays.  The system's params pointer and the events' data pointers are
 * borrowed and must stay valid while the integrator is used.  yout arrays
 * belong to the caller.  Integration runs forward in time only.
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

/* Optional exact Jacobian J = df/dy at (t, y): dense, row-major, J[i*n + j] =
 * df_i/dy_j, n = dimension; J is owned by the integrator and must be filled
 * completely.  Return values as for swim_ode_func (positive: (t, y) outside
 * the domain, the integrator retries smaller; negative: fatal). */
typedef int (*swim_ode_jacobian)(double t, const double *y, double *J, void *params);

typedef struct {
    swim_ode_func function;
    size_t dimension;
    void *params;
    /* NULL: integrators with SWIM_ODE_CAP_JACOBIAN form J by difference quotients
     * (msbdf: forward differences, n + 2 calls of f with df/dt; cvode-bdf: CVODE's
     * own, n calls).  Given: cvode-bdf uses it as its dense Jacobian (CVodeSetJacFn);
     * msbdf through gsl_odeiv2_system.jacobian, whose df/dt is set to 0: msbdf reads
     * only df/dy (its Newton matrix is I - gamma J; GSL 2.7), so computing df/dt
     * would cost a call of f for nothing.  Counted in swim_ode_stats.jac_evals. */
    swim_ode_jacobian jacobian;
} swim_ode_system;

/* Events.  An event function g(t, y, y') is a scalar evaluated on the
 * integrator's interpolant: y = y(t) and yp = y'(t), the derivative of that
 * interpolant (for Adams methods the polynomial through the stored f values,
 * exact f at the step ends).  An event is a change of sign of g within a step
 * (0 counts as positive); direction filters it:
 *   +1  rising  (g goes from < 0 to >= 0; for g = dq/dt: a minimum of q),
 *   -1  falling (from >= 0 to < 0; for g = dq/dt: a maximum of q),
 *    0  either.
 * After every accepted step the sign of each g at the step end is compared
 * with its sign at the previous step end; on a change the time is located on
 * the step's interpolant by the Illinois variant of regula falsi (bracketing,
 * superlinear; bisection when it stalls) to a bracket of
 * max(event_tol, 4u|t|), then reported through on_event in time order.  A
 * terminal event ends the integration there: swim_ode_advance() returns
 * SWIM_ODE_TERMINATED with y(t_event) in yout (from the interpolant) and
 * swim_ode_time() = t_event; later events of that step are not reported and
 * the object cannot advance further.  g must depend on (t, y, yp) only; a NaN
 * value counts as "no sign information" (no event across it), and so does
 * g = 0 exactly at the initial time (no event at t0, as in ode113).  Extremes of a
 * quantity q(y) are zeros of dq/dt = grad q . y': pass that as g (e.g. yp[i] for
 * a component, or a difference of q along yp). */
typedef double (*swim_ode_event_func)(double t, const double *y, const double *yp, void *data);

typedef struct {
    swim_ode_event_func g;
    void *data;            /* borrowed, passed to g */
    int direction;         /* +1, -1 or 0 as above */
    int terminal;          /* nonzero: stop at the first occurrence */
} swim_ode_event;

typedef struct {
    int index;             /* position of the event in swim_ode_options.events */
    double t;              /* located time */
    const double *y;       /* y(t) from the interpolant (valid during the call only) */
    const double *yp;      /* y'(t) from the interpolant (valid during the call only) */
    int rising;            /* 1: g went from < 0 to >= 0, 0: the other way */
    int terminal;          /* the event ends the integration */
} swim_ode_event_hit;

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

/* One accepted step [ta, tb], as passed to swim_ode_options.on_accept.  interp(ctx, t, y, yp)
 * evaluates the step's interpolant (y and, when yp is not NULL, y') at t in [ta, tb]; 0 or -1.
 * y_end: the accepted state at tb itself (ABM: y_{n+1} as projected and evaluated, which the
 * interpolant at the rounded tb reproduces only up to rounding), or NULL. */
typedef struct {
    double ta, tb;
    int (*interp)(void *ctx, double t, double *y, double *yp);
    void *ctx;
    const double *y_end;
} swim_ode_accepted;

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
    /* Optional projection onto an invariant manifold (SWIM_ODE_CAP_PROJECTION): called after
     * each accepted step with the corrected y_{n+1}, which it may modify in place.  ABM: before
     * the final evaluation f(t_{n+1}, y_{n+1}) of PECE -- so the derivative history of the
     * method is the one of the projected states.  cvode-bdf: as CVODE's projection function
     * (the difference projected - corrected becomes CVODE's correction of its history; the
     * error estimate is not projected).  Nonzero return: stop with SWIM_ODE_ERHS. */
    int (*project)(double t, double *y, void *params);
    /* Optional report of every ABM step attempt (SWIM_ODE_CAP_STEP_TRACE), with its own data. */
    void (*on_step)(const swim_ode_step *step, void *data);
    void *on_step_data;
    /* Optional events (integrators with SWIM_ODE_CAP_EVENTS): nevents entries, the
     * array is copied.  Each located event is passed to on_event (required when
     * nevents > 0) with on_event_data. */
    const swim_ode_event *events;
    size_t nevents;
    void (*on_event)(const swim_ode_event_hit *hit, void *data);
    void *on_event_data;
    double event_tol;           /* width of the final bracket in t; 0 = default 1e-13 */
    /* Optional report of every accepted step (integrators with SWIM_ODE_CAP_EVENTS: those with
     * dense output), before the events of that step are located.  Return 0 to go on, or 1 with
     * *t_stop in (ta, tb] to end the integration at t_stop: swim_ode_advance() then behaves as
     * at a terminal event (SWIM_ODE_TERMINATED with y(t_stop) from the interpolant once tout
     * reaches t_stop; events of the step after t_stop are not located).  Ignored by the others. */
    int (*on_accept)(const swim_ode_accepted *step, void *data, double *t_stop);
    void *on_accept_data;
    /* SWIM_ODE_CAP_WEIGHTS: optional per-component factors in (0, 1] on the error weights, read live at every
     * step (not copied: the caller may change them between steps, e.g. from on_accept). The
     * tolerance of component i becomes tol_scale[i] (rtol |y_i| + atol_i). NULL = 1. */
    const double *tol_scale;
    /* SWIM_ODE_CAP_INVARIANT: an optional balance B(t, y) -- a first integral, or one whose source is carried
     * in y (energy minus the work of the forces, both in the state) -- whose local error joins
     * the error test.  To first order the step's error estimate moves B by
     * r (B(t_{n+1}, y_c) - B(t_{n+1}, p)), p the predictor, y_c the (projected) corrector,
     * r = (g_k - g_{k+1}) / g_{k+1}; an attempt passes only if that is at most
     * max(invariant_tol, 2 r (noise(p) + noise(y_c))), and the next step is sized for both tests.
     * Why: Adams methods keep each component's local error within its weight but let B drift by
     * a systematic amount per step (for oscillations, their dissipation), which adds up over
     * 10^5 steps where the components' errors do not.  B is called right after f at the same
     * (t, y) -- at p once the error test has passed, at y_c after the final evaluation -- so it
     * may reuse what f computed there; it stores in *noise (never NULL) an estimate of what
     * rounding leaves of B at y, so that the test never asks for less.  An attempt it fails has
     * cost both evaluations.  Rejections it causes are counted in swim_ode_stats.rejected and
     * .rejected_invariant.  NULL = none. */
    double (*invariant)(double t, const double *y, double *noise, void *data);
    void *invariant_data;
    double invariant_tol;
    /* Optional, with events: read right after on_event returns; nonzero makes the event just
     * reported terminal (a caller that decides at the event whether the integration ends there,
     * as a terminal event would). Not copied: the caller's int. NULL = never. */
    const volatile int *event_stop;
    /* SWIM_ODE_CAP_ERROR_DIM: the error control looks at the first error_dim components only
     * (0 = all): every norm, error estimate, order and step-size choice, round-off and stiffness
     * test. The other components are integrated on the same steps by the same formulas (CVODES's
     * errconS = false), so the first error_dim components come out bit for bit as without them
     * when their right-hand side does not depend on the others (a state with its variational
     * equations). abm only: its norms run over the first error_dim components. The GSL steppers'
     * control and CVODE's weights cannot leave components out (a zero error weight in CVODE
     * also makes its difference-quotient Jacobian divide by it), so they refuse it. */
    size_t error_dim;
} swim_ode_options;

/* rtol = 1e-6, atol = 1e-9, no hmax, automatic h0, tstop = INFINITY,
 * max_steps = 10^7, stiff_stop = 0, lookahead = 6, no projection, no step
 * report, no events, no accepted-step report. */
void swim_ode_options_default(swim_ode_options *opt);

typedef struct {
    long steps;            /* accepted steps */
    long rhs_evals;        /* calls of the right-hand side (including Jacobian differencing) */
    long rejected;         /* rejected step attempts (error test failures, convergence failures,
                              positive right-hand-side values) */
    long rejected_invariant; /* ABM: of those, attempts the balance's error test rejected */
    long jac_evals;        /* Jacobian evaluations (BDF methods; by differences or the user's) */
    long event_evals;      /* evaluations of event functions */
    long events;           /* events located */
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
    SWIM_ODE_EFAIL,         /* peer library failure */
    SWIM_ODE_EUNSUPPORTED,  /* an option the integrator cannot honour (see the capabilities) */
    SWIM_ODE_TERMINATED     /* not an error: a terminal event ended the integration */
};

/* Capabilities of an integrator (bit flags, see the table at the top). */
enum {
    SWIM_ODE_CAP_PROJECTION = 1,   /* swim_ode_options.project */
    SWIM_ODE_CAP_STEP_TRACE = 2,   /* swim_ode_options.on_step */
    SWIM_ODE_CAP_EVENTS = 4,       /* swim_ode_options.events */
    SWIM_ODE_CAP_JACOBIAN = 8,     /* uses swim_ode_system.jacobian (and differences without it) */
    SWIM_ODE_CAP_STIFFNESS = 16,   /* stiffness diagnostic (swim_ode_options.stiff_stop) */
    /* implicit (BDF with Newton iterations): its stability region holds the stiff modes whose
     * step-size limit stops an explicit or PECE method, so it is what a stiff fallback must be.
     * cvode-adams is not: its fixed-point corrector has the same limit as explicit Adams. */
    SWIM_ODE_CAP_IMPLICIT = 32,
    /* error weights that may change between steps: swim_ode_options.tol_scale, read live, and
     * atol_vec (what a caller that moves the state's origin needs, swim run near the barrier) */
    SWIM_ODE_CAP_WEIGHTS = 64,
    /* a balance in the error test: swim_ode_options.invariant */
    SWIM_ODE_CAP_INVARIANT = 128,
    /* implemented over SUNDIALS CVODE: a program built from a subset of the runtime (swim
     * export) links libsundials when its scene may use it */
    SWIM_ODE_CAP_SUNDIALS = 256,
    /* error control over the first components only: swim_ode_options.error_dim */
    SWIM_ODE_CAP_ERROR_DIM = 512,
    /* swim_ode_scale: a block of components that obeys a linear homogeneous equation scaled in
     * place with its history */
    SWIM_ODE_CAP_RESCALE = 1024
};

/* The registry.  swim_ode_methods(): NULL-terminated list of names, in the order
 * of the table above.  swim_ode_method_known(): 1 if name is one of them.
 * swim_ode_capabilities(): the SWIM_ODE_CAP_* flags of name (0 if unknown).
 * swim_ode_method_list(): the names as "abm, rk8pd, ..." for messages (static).
 * swim_ode_method_list_with(): likewise, only the integrators that have every flag of caps
 * (static, rewritten by the next call). */
const char *const *swim_ode_methods(void);
int swim_ode_method_known(const char *name);
unsigned swim_ode_capabilities(const char *name);
const char *swim_ode_method_list(void);
const char *swim_ode_method_list_with(unsigned caps);

typedef struct swim_ode swim_ode;   /* opaque; owns its memory; the caller owns y arrays */

/* method NULL or "" selects "abm".  On success *out receives a new object.
 * SWIM_ODE_EUNSUPPORTED when opt asks for something the method lacks. */
int swim_ode_create(const char *method, const swim_ode_system *sys, const swim_ode_options *opt,
                    double t0, const double *y0, swim_ode **out);
/* Integrate until tout is covered and write y(tout) (from the method's own
 * interpolant where it has one) into yout (caller-owned, length dimension).
 * tout must be > t0 and increase strictly between calls, and not exceed tstop.
 * Events located on the way are reported through on_event; a terminal one at
 * t_e <= tout ends the call with SWIM_ODE_TERMINATED and y(t_e) in yout (one
 * found in the last step beyond tout is kept for the next call).  After an
 * error or SWIM_ODE_TERMINATED the object should be freed. */
int swim_ode_advance(swim_ode *s, double tout, double *yout);
int swim_ode_get_stats(const swim_ode *s, swim_ode_stats *st);
double swim_ode_time(const swim_ode *s);  /* time reached by the internal steps (t_event after a terminal event) */
/* Last nonzero value returned by the right-hand side (or by the projection),
 * 0 if none; after SWIM_ODE_ERHS the value that ended the run.  It may be a
 * recovered positive value after a successful advance. */
int swim_ode_rhs_status(const swim_ode *s);
/* y (and yp when not NULL) at t from the interpolant of the last accepted step (there must be
 * one), also after a failed advance (e.g. the state where the integration stopped, at
 * swim_ode_time()).  ABM
 * extrapolates its polynomial beyond the step; CVODE accepts t within its last step only.
 * SWIM_ODE_OK, SWIM_ODE_EUNSUPPORTED (no dense output: the GSL steppers) or SWIM_ODE_EFAIL. */
int swim_ode_dense(swim_ode *s, double t, double *y, double *yp);
/* SWIM_ODE_CAP_RESCALE: multiply components [from, from + count) of the solution and of
 * everything the method keeps of their past (abm: y, its carries and the difference table) by
 * factor. For components whose equations are linear and homogeneous in themselves and that no
 * other component's equation reads (a tangent vector w' = J(t, y) w), that is the solution from
 * the scaled start, so the integration goes on unchanged; a power of two makes it exact in
 * floating point. Call it between steps (e.g. from on_accept). The error control must not look
 * at them (error_dim). SWIM_ODE_OK, SWIM_ODE_EUNSUPPORTED or SWIM_ODE_EBADARG. */
int swim_ode_scale(swim_ode *s, size_t from, size_t count, double factor);
const char *swim_ode_method_name(const swim_ode *s);
void swim_ode_free(swim_ode *s);
const char *swim_ode_strerror(int status);

#endif
