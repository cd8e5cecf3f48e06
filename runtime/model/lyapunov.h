/* lyapunov.h -- the largest Lyapunov exponent of a run and its predictability horizon.
 *
 * One tangent vector w of the shape state is carried along the trajectory by the exact
 * variational equations (model/sensitivity.h: w' = J w with the kernel's exact Jacobian),
 * from a fixed pseudo-random start. Every `interval` of time the integration stops, the growth
 * r_k = |w| over the shape state (c, cdot of the carried coordinates; x, y, theta and the work
 * are not part of the dynamics' own state) is taken and w is scaled back to 1 (Benettin's
 * method); the exponent is lambda = (1/T) sum_k ln r_k. Almost every start has a component along
 * the fastest-growing direction, so lambda is the largest exponent once T is long against
 * 1/(lambda_1 - lambda_2).
 *
 * Predictability horizon at the run's tolerance: an integration with relative error ~ rtol
 * diverges from the exact trajectory by rtol times the growth of a perturbation, so it stays
 * within a relative separation delta (SWIM_LYAPUNOV_SEPARATION) of it until the cumulative
 * growth sum ln r_k reaches ln(delta / rtol): that time (interpolated within its segment) is the
 * horizon. The growth is far from uniform before the motion gets chaotic, so the horizon is taken
 * from the growth itself, not from ln(delta / rtol) / lambda (also reported). Beyond it the
 * trajectory is one of the many the tolerance allows, and only what does not depend on the
 * particular one (the energy balance, time averages, statistics over a family) is a result.
 * INFINITY when the growth never gets there.
 *
 * The tangent vector rides on the run's own integration (driver/analyses.h, driver/run.h: on
 * the state's steps, outside the error test, through the origin shifts near the barrier); its
 * length is taken on the interpolant at the marks and renormalized by a power of two at the next
 * step boundary, exactly, without stopping the state's steps. Runs that took impacts are not
 * differentiable there and are refused by the caller (as for sensitivities).
 */
#ifndef SWIM_MODEL_LYAPUNOV_H
#define SWIM_MODEL_LYAPUNOV_H

#include <stdio.h>

#include "model/dynamics.h"

#define SWIM_LYAPUNOV_SEPARATION 1e-2
/* At most this many renormalizations (rows of lyapunov.csv, two doubles each in memory): an
 * interval below t_end / 10^6 is refused before the run rather than asking for 10^9 rows. */
#define SWIM_LYAPUNOV_MAX_SEGMENTS 1000000

/* The verdict on the growth (swim_lyapunov_from_marks sets it from the segments).
 * G(t) = sum ln r_k is fitted by least squares with a line in t over each half of the segments
 * (rates a1, a2) and with a line in ln t over the second half (power p: |w| ~ t^p).
 *   converged: |a1 - a2| <= SWIM_LYAPUNOV_AGREE * max(|a1|, |a2|), the second half grows (or shrinks)
 *     by at least SWIM_LYAPUNOV_EFOLDS e-folds and there are SWIM_LYAPUNOV_MIN_SEGMENTS segments:
 *     the growth is exponential at one rate, the exponent is a result;
 *   regular: otherwise, p <= SWIM_LYAPUNOV_POWER: the tangent vector grows like a power of t (the
 *     drift along a family of periodic orbits or tori grows linearly), the exponent is p ln t / t
 *     and tends to 0; an exponential rate, if any, is below about 2 p / T, so it cannot matter
 *     within the run; the horizon is where the power law reaches ln(separation / rtol);
 *   not converged: neither; t_end_needed says how long to run. */
#define SWIM_LYAPUNOV_AGREE 0.2
#define SWIM_LYAPUNOV_EFOLDS 3.0
#define SWIM_LYAPUNOV_POWER 3.0
#define SWIM_LYAPUNOV_MIN_SEGMENTS 8

typedef enum { SWIM_LYAP_NOT_CONVERGED = 0, SWIM_LYAP_CONVERGED, SWIM_LYAP_REGULAR } swim_lyapunov_verdict;

typedef struct swim_lyapunov_s {
    double interval;       /* renormalization interval */
    double t_end;          /* where the pass ended (t_end, or where it failed) */
    int n;                 /* segments done */
    double *t, *log_growth;   /* per segment: its end and ln r_k (owned, n entries) */
    double exponent;       /* (1/t_end) sum ln r_k */
    double exponent_half;  /* the same over the second half of the segments (a convergence check) */
    double rtol;           /* the run's relative tolerance */
    double horizon;        /* where sum ln r_k reaches ln(SWIM_LYAPUNOV_SEPARATION / rtol), or INFINITY */
    double horizon_mean;   /* ln(SWIM_LYAPUNOV_SEPARATION / rtol) / exponent, or INFINITY */
    swim_lyapunov_verdict verdict;
    double rate_first, rate_second;   /* least-squares slopes of sum ln r_k over each half (NAN: too few) */
    double power;          /* least-squares slope of sum ln r_k against ln t over the second half */
    double horizon_power;  /* regular: where t^power growth reaches ln(separation / rtol); else NAN */
    double t_end_needed;   /* not converged: the t_end to run to next; else NAN */
    long rhs_calls;
    double seconds;
    int status;            /* 0 completed; 1 the integration failed (then t_end says where) */
    char reason[160];
} swim_lyapunov;

/* The pseudo-random start: w (n entries) zero but for components [from, from + count), a unit
 * vector there. */
void swim_lyapunov_start(double *w, int n, int from, int count);
/* The results from the growth the run measured (driver/run.h, swim_run_var_result): ln |w| at the
 * marks t[0 .. marks) (t[k] = (k+1) interval, the last where the run ended); rhs_calls, seconds,
 * status and reason are the caller's. 0, or -1 out of memory. */
int swim_lyapunov_from_marks(swim_lyapunov *l, double interval, double rtol, const double *t, const double *log_norm,
                             long marks);
void swim_lyapunov_free(swim_lyapunov *l);
/* "converged", "regular" or "not_converged" (the summary's words). */
const char *swim_lyapunov_verdict_name(swim_lyapunov_verdict v);

#endif
