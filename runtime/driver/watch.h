/* run_watch.h -- what `swim run` checks and accumulates at every accepted step of the integrator
 * (swim_ode_options.on_accept), not only at the output rows:
 *   - admissibility (4.1): min J over the circle at the step end; the minimum of J in time,
 *     located inside a step on the integrator's interpolant where d/dt min J changes sign from
 *     - to + (Illinois regula falsi; d/dt min J is exact by the envelope theorem,
 *     swim_shape_j_rate), with its time;
 *   - a step inside which min J reaches 0 (a dip that both step ends miss) ends the run at the
 *     crossing J = 0, located on the same interpolant: on_accept's stop;
 *   - the energy balance (5.3) |E - E0 - work| and the constraint residuals at each step end.
 * Trial states outside D are refused before a step is accepted (the right-hand side,
 * model/dynamics.h); the watch sees what gets through, inside a step. */
#ifndef SWIM_DRIVER_WATCH_H
#define SWIM_DRIVER_WATCH_H

#include <math.h>

#include "io/clock.h"
#include "model/dynamics.h"
#include "ode/ode.h"

/* Maxima and min J over a set of steps. */
typedef struct {
    long steps;
    double jmin, jmin_t;       /* smallest min J and when (INFINITY, NAN before any step) */
    double drift_abs, emax;    /* max |E - E0 - work|, max |E| */
    double res_volume, res_volume_rate, res_angular, res_locks;
} swim_run_watch_results;

/* What the latest step contributes, kept apart until it is known to be part of the run (a run
 * that ends inside that step -- t_end, a :stop event, the crossing -- keeps only what lies at or
 * before its end). */
typedef struct {
    int n;                     /* candidates for min J */
    double t[3], J[3];
    int balanced;              /* the balance at tb was evaluated */
    double tb, drift, e, res_volume, res_volume_rate, res_angular, res_locks;
} swim_run_watch_pending;

typedef struct {
    swim_dynamics *d;          /* borrowed */
    int sdim;                  /* integrator state dimension */
    double *ys, *full;         /* work: integrator state, full state (owned) */
    int energy;                /* also evaluate the energy balance and residuals at step ends */
    double e0;                 /* E(0), for the balance (set before the first step) */
    /* the previous step end */
    int have_prev;
    double t_prev, j_prev, rate_prev;
    swim_run_watch_results r;  /* over the steps before the latest one */
    swim_run_watch_pending pend;   /* the latest step */
    int left;                  /* min J reached 0 inside a step ... */
    double t_left;             /* ... at this time (the crossing, on the interpolant) */
    int diag_failed;           /* the diagnostics failed at a step end (K not positive definite) */
    double theta_last;         /* angle of the minimum of J at the last state j_at looked at */
    const double *end_y;       /* the latest step's y_end (NULL: none, or the step was not checked) ... */
    double end_j, end_theta;   /* ... its min J and the angle of that minimum (swim_dynamics_jmin) */
    swim_clock_sample time;    /* time spent here, sampled (io/clock.h) */
    swim_run_watch_results mark_r;        /* at the last mark (swim_run_watch_mark) */
    swim_run_watch_pending mark_pend;
} swim_run_watch;

/* 0, or -1 when out of memory. */
int swim_run_watch_init(swim_run_watch *w, swim_dynamics *d, int sdim, int energy);
void swim_run_watch_free(swim_run_watch *w);

/* Remember the results so far (at an output row t, where a stiff fallback may restart). */
void swim_run_watch_mark(swim_run_watch *w);
/* The integrator restarted from the last mark at t (stiff fallback): the results go back to it
 * (the steps after t are computed again) and the next step's start is evaluated afresh. */
void swim_run_watch_rewind(swim_run_watch *w, double t);

/* The run ended at t_end (its last row: t_end, a :stop event, the crossing; INFINITY when every
 * accepted step belongs to it): the latest step counts up to t_end. Results in w->r. */
void swim_run_watch_finish(swim_run_watch *w, double t_end);

/* swim_ode_options.on_accept with data = swim_run_watch *: 0, or 1 with *t_stop at the crossing. */
int swim_run_watch_step(const swim_ode_accepted *step, void *data, double *t_stop);

/* fmax(m, x) without the library call, for maxima taken at every step, NaN included (a NaN x
 * leaves m, a NaN m gives x). For m, x >= 0 or NaN (absolute values): no signed zero to order. */
static inline double swim_run_max_of(double m, double x) { return x > m || isnan(m) ? x : m; }

#endif
