/* floquet.h -- monodromy matrix and Floquet multipliers of a periodic stroke.
 *
 * The period T is the time between two successive events of one state column (the events
 * machinery of ode/ode.h on the integrator's interpolant, with the run's drift control on), so
 * the shape state x = (c_carried, cdot_carried) returns to x(0) at T. The monodromy matrix
 * M = dx(T)/dx(0) comes from the variational equations (model/sensitivity.h) with the 2n
 * columns e_i. The rigid position r and the orientation theta do not enter the shape equations
 * (they are cyclic, (3.21)): their multipliers are trivially 1 and they are left out.
 *
 * The shape motion lives on the invariant manifold {mu^2(c) = mu^2(c0), G1 cdot = 0,
 * G2 cdot = 0} ((2.5), (2.8), (2.14)); M restricted to its tangent space at x(0) (an orthonormal
 * basis B from the SVD of the constraint gradients: M_t = B^T M B) carries the multipliers of
 * the swimmer's motion; the three transverse ones (the conserved G1 cdot, G2 cdot and the volume)
 * are 1 and are reported with the full M. Checks of the structure a conservative system imposes:
 *   - the flow direction f(x(0)) is an eigenvector with multiplier 1 (|M f - f| / |f|);
 *   - the energy gradient is a left eigenvector with multiplier 1 (|grad E M - grad E| / |grad E|);
 *   - the tangent multipliers come in reciprocal pairs (lambda, 1/lambda) and det M_t = 1.
 * Stable (in the linear sense) when every tangent multiplier has |lambda| = 1 to the tolerance.
 *
 * All of this presumes a periodic orbit: two events of a section need not be a period (a damped
 * or forced swimmer crosses its section again at another state). The orbit is periodic when it
 * closes, max |x(T) - x(0)| <= SWIM_FLOQUET_CLOSURE_TOL * max |x(0)| (the state's own scale, at
 * least atol). The tolerance is the square of the multipliers' one: an error eps in M moves the
 * double multiplier at 1 by ~sqrt(eps), and an orbit that misses closing by delta puts an error
 * of order delta into M, so delta <= tol^2 keeps that motion within tol. Otherwise periodic is 0
 * and stable means nothing (it is 0): the multipliers are those of the map over [0, T] only.
 */
#ifndef SWIM_CONTROL_FLOQUET_H
#define SWIM_CONTROL_FLOQUET_H

#include <stdio.h>

#include "io/status.h"
#include "model/dynamics.h"

#define SWIM_FLOQUET_MAX (2 * SWIM_NMAX)
#define SWIM_FLOQUET_NSYM 3                                     /* rotations tried as symmetries */
#define SWIM_FLOQUET_TOL 1e-3                                   /* on |lambda| (see floquet.c) */
#define SWIM_FLOQUET_CLOSURE_TOL (SWIM_FLOQUET_TOL * SWIM_FLOQUET_TOL)   /* relative closure */
/* The monodromy's columns in the integrator's error test (1), not riding on the state's steps as
 * a run's sensitivities do by default (0). Measured on example3 (swim floquet, and swim periodic's
 * multipliers; docs/control.md): outside the test the orbits are the same to 1e-13 (Newton needs
 * M only as a direction) for 26 % fewer evaluations, but M loses two digits -- the flow-direction
 * check |Mf - f|/|f| goes from 1e-10 to 8e-9, and the Jordan pair at 1 of the energy family, which
 * moves by sqrt of M's error, from 1 +- 3.1e-5 i to 1 +- 6.4e-5 -- so the analyses keep it in. */
#ifndef SWIM_FLOQUET_ERROR_CONTROL   /* a build may set it (-D) to measure the other choice */
#define SWIM_FLOQUET_ERROR_CONTROL 1
#endif

typedef struct {
    int stopped;                   /* d->interrupt's value when the caller stopped the work (a signal
                                    * number for swim floquet); then only period and t_first may be
                                    * known (NAN otherwise) and nothing else was computed */
    double period, t_first;        /* T and the time of the first event */
    double closure;                /* max |x(T) - x(0)| over the shape state */
    double closure_rel;            /* closure / max(max |x(0)|, atol) */
    int periodic;                  /* closure_rel <= SWIM_FLOQUET_CLOSURE_TOL */
    int n2;                        /* 2 * carried coordinates: size of M */
    int nt;                        /* dimension of the tangent space */
    double *M;                     /* n2 x n2, row-major (owned) */
    double *B;                     /* n2 x nt: orthonormal basis of the tangent space (owned) */
    double *Mt;                    /* nt x nt: M on the tangent space, M_t = B^T M B (owned) */
    double flow[SWIM_FLOQUET_MAX];         /* f(x(0)) on the shape state */
    double grad_energy[SWIM_FLOQUET_MAX];  /* grad E(x(0)) on the shape state */
    /* Continuous symmetries tried at x(0) (swim_floquet_symmetry_names): the generator g of a
     * rotation c_k -> e^{i m_k t} c_k of the shape coordinates, on the tangent space; a symmetry
     * of the scene makes g an eigenvector of M with multiplier 1, ||M g - g|| / ||g|| at the
     * error of M (NAN when the carried coordinates cannot represent g). */
    double symmetry[SWIM_FLOQUET_NSYM][SWIM_FLOQUET_MAX];
    double symmetry_residual[SWIM_FLOQUET_NSYM];
    double re[SWIM_FLOQUET_MAX], im[SWIM_FLOQUET_MAX];       /* multipliers of M */
    double tre[SWIM_FLOQUET_MAX], tim[SWIM_FLOQUET_MAX];     /* of M_t */
    double flow_residual;          /* |M f - f| / |f| */
    double energy_residual;        /* |grad E M - grad E| / |grad E| */
    double reciprocal_residual;    /* max over tangent lambda of min_j |lambda_j - 1/lambda| */
    double det_tangent;            /* det M_t */
    double max_abs_dev;            /* max | |lambda| - 1 | over the tangent multipliers */
    int unit_count;                /* tangent multipliers within tol of 1 */
    /* The multipliers known to be exactly 1 -- the time shift (f), the energy of a scene that
     * conserves it (grad E a left eigenvector: energy_residual <= SWIM_FLOQUET_SYMMETRY_TOL) and
     * each symmetry found -- taken out, the rest computed on the complement: M_t acts on
     * V = {grad E . u = 0} (or the whole tangent space) and leaves W = span(f, g_s) fixed, so it
     * induces a map on V / W, represented on Q, an orthonormal basis of V orthogonal to W:
     * M_c = Q^T M_t Q. Its eigenvalues are the other multipliers, free of the Jordan block at 1
     * that the time shift and the energy form (which an error eps of M splits by sqrt(eps)). */
    int energy_conserved;
    int exact_ones;                /* 1 (time) + energy_conserved + symmetries found */
    int nc;                        /* dimension of the complement, nt - exact_ones */
    double cre[SWIM_FLOQUET_MAX], cim[SWIM_FLOQUET_MAX];    /* multipliers of M_c */
    double comp_reciprocal;        /* reciprocal residual on the complement */
    double comp_max_abs_dev;       /* max | |lambda| - 1 | on the complement */
    /* On an odd-dimensional complement whose multipliers come in reciprocal pairs (a reversible
     * system's symmetric orbit: R M R = M^-1) one multiplier is its own inverse, +-1; the index
     * of that real multiplier (the one nearest 1) when the pairs hold to tol, else -1. */
    int forced_one;
    int stable;                    /* periodic and every complement |lambda| = 1 to tol */
    double tol;                    /* the tolerance of the checks */
    long rhs_calls;
    double seconds;
} swim_floquet;

#define SWIM_FLOQUET_SYMMETRY_TOL 1e-6   /* ||M g - g|| / ||g|| of a symmetry, with M to ~1e-8 */
extern const char *const swim_floquet_symmetry_names[SWIM_FLOQUET_NSYM];

/* Event that defines the period: extremum (kind 'x' max, 'n' min) or rising zero ('z') of the
 * integrator-state component `index` of d's state (c or cdot of a carried coordinate); the period
 * spans `count` events after the first (COLUMN:KIND:COUNT, 1 by default): a libration of more
 * than 90 degrees passes the maximum of a coordinate that goes as the sine of its angle twice. */
#define SWIM_FLOQUET_MAX_CROSSINGS 16
typedef struct {
    int index;
    char kind;
    int count;
} swim_floquet_section;

/* Computes everything above; t_max bounds the search for two events; on_period (may be NULL) is
 * told the period once found. 0 (also for an orbit that does not close: see periodic; and when
 * d->interrupt stopped the work: then fl->stopped), or 1 with the cause in st ("swim floquet: ...":
 * no period found before t_max, an integration failure, a scene without free shape dynamics). */
int swim_floquet_compute(swim_dynamics *d, const swim_floquet_section *sec, double t_max,
                         void (*on_period)(void *ctx, double t_first, double period), void *ctx, swim_floquet *out,
                         swim_status *st);
/* The same analysis of the map over [0, period] from the integrator state ys (a point of the
 * orbit, e.g. the phase point of control/periodic.h); t_first is left 0. 0 or 1 (the cause in st,
 * as "swim floquet: ..."; nothing when d->interrupt stopped the integration). */
int swim_floquet_at(swim_dynamics *d, const double *ys, double period, swim_floquet *out, swim_status *st);
/* COLUMN:KIND (spec; NULL: the first moving coordinate's max) with COLUMN a carried coordinate
 * or its velocity (d + name), KIND max, min or zero: the integrator-state index and kind, and
 * the section as text (len bytes). 0, or 2 with "swim CMD: --OPTION: ..." in st (key OPTION). */
int swim_floquet_parse_section(const swim_dynamics *d, const char *cmd, const char *option, const char *spec,
                               swim_floquet_section *sec, char *text, size_t len, swim_status *st);
/* T and the time t_first of the first of count + 1 successive events of the section from state ys0
 * at t = 0, on the scene's integrator with its drift control (messages "swim CMD: ..."; with
 * fewer than two events before t_max the remedy names what sets t_max and the section, e.g.
 * "--t-max" and "--event"). 0, or 1 with the cause in st (nothing when d->interrupt stopped it). */
int swim_floquet_period(swim_dynamics *d, const char *cmd, const swim_floquet_section *sec, double t_max,
                        const char *t_max_from, const char *section_option, const double *ys0, double *t_first,
                        double *period, swim_status *st);
/* What swim floquet refuses in a scene (of file path), the checks in what: SWIM_FLOQUET_NO_STROKE a
 * prescribed stroke (no shape state to perturb), SWIM_FLOQUET_EVENTS an integrator that cannot
 * locate the section's events. 0, or 2 with the cause in st. */
#define SWIM_FLOQUET_NO_STROKE 1
#define SWIM_FLOQUET_EVENTS 2
int swim_floquet_check(const swim_scene *s, const char *path, int what, swim_status *st);
void swim_floquet_free(swim_floquet *f);
/* floquet.json and the table printed by swim floquet. */
/* "SIGINT", "SIGTERM", "SIGHUP" for a stop flag holding that signal's number (swim periodic,
 * continue and floquet report what stopped them), else "a signal". */
const char *swim_floquet_signal_name(int sig);
/* The eigenvalues of the n x n row-major matrix M into re, im. 0, or -1 (out of memory, LAPACK). */
int swim_floquet_eigenvalues(const double *M, int n, double *re, double *im);
void swim_floquet_json(FILE *f, const swim_floquet *fl, const char *scene, const char *section);
void swim_floquet_table(FILE *f, const swim_floquet *fl);
/* The "checks" object of floquet.json (flow, energy, reciprocal residuals, det M_t, ...). */
void swim_floquet_checks_json(FILE *f, const swim_floquet *fl);

#endif
