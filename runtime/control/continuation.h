/* continuation.h -- a branch of periodic orbits in a parameter (swim continue).
 *
 * The parameter is the energy of a conservative scene (the family of orbits by energy), or a
 * scene key the right-hand side reads at run time (elastic.stiffness[4], model.rho0,
 * parameters.A, ...: the keys of --sensitivity, model/sensitivity.h, whose numbers are set
 * in place between points). Natural-parameter continuation: the orbit of the scene
 * (control/periodic.h, swim_periodic_solve) is the first point; the requested values
 * START .. STOP (count points, both ends included) are visited outwards from it on each side,
 * each point started from the secant through the two before it (state and period) and solved
 * by swim_periodic_refine -- with the energy as the target when the parameter is the energy,
 * and the first point's energy kept when it is a key of a conservative scene. A point that does
 * not converge is approached again in halved parameter steps (at most 4 halvings); then that
 * side of the branch ends, saying why. No pseudo-arclength: a fold in the parameter ends the
 * branch there (reported as such).
 *
 * The branch stays on the invariant subspace the first orbit lies in (a mirror symmetry's fixed
 * set: entries of the shape state that are 0 on it, swim_periodic_invariant_zeros), held by one
 * Newton row dz_i = 0 per such entry: a symmetric orbit of a reversible system has neutral
 * directions across the subspace (a multiplier at 1 on the complement), and without the rows the
 * corrector drifted along them, so the branch depended on the path (Example 3's librations left
 * the mirror plane from E ~ 0.12). Where multipliers of the directions across the subspace leave
 * the unit circle (M is block-triangular there: its across-block's eigenvalues) the special point
 * is a branch point where orbits leaving the subspace branch off; the branch itself stays in it.
 *
 * At each point: period, displacement and rotation per period, energy, the largest |multiplier|
 * on the complement of the exact 1s and the stability (control/floquet.h, SWIM_CONT_OUTSIDE_TOL). Between two points the number of
 * multipliers outside the unit circle may change: a special point, classified by where the
 * multipliers leave it (at -1: period doubling; a complex pair: Neimark-Sacker; at +1: fold or
 * branch point) and then refined by bisection: the orbit at the midpoint (Newton from the
 * interpolated state and period), kept on the side with the same count, until the bracket is
 * SWIM_CONT_BISECTIONS halvings narrower (or a midpoint does not converge: then said).
 */
#ifndef SWIM_CONTROL_CONTINUATION_H
#define SWIM_CONTROL_CONTINUATION_H

#include <stdio.h>

#include "control/periodic.h"

#define SWIM_CONT_MAX_POINTS 1000
#define SWIM_CONT_BISECTIONS 24        /* bracket of a special point: 2^-24 of its first width */
/* A multiplier is outside the unit circle when |lambda| > 1 + this: the complement's multipliers
 * (floquet.h: no Jordan block at 1) of the shooting's monodromy (rtol 1e-12) are good to ~1e-10,
 * so a point is stable when none is outside, and a special point is where one leaves. */
#define SWIM_CONT_OUTSIDE_TOL 1e-6

typedef struct {
    double param;
    int converged;
    double period, dx, dy, dtheta, energy, residual;
    double max_abs;                /* largest |lambda| on the manifold */
    int outside;                   /* multipliers with |lambda| > 1 + tol */
    int negative_real;             /* a real multiplier < -1 + tol (period doubling side) */
    int complex_outside;           /* a complex multiplier outside */
    int stable;
    int iterations;
    double re[SWIM_FLOQUET_MAX], im[SWIM_FLOQUET_MAX];
    int nt;
    double z[SWIM_FLOQUET_MAX];    /* the shape state at the phase point (n2 entries) */
    int n2;
    int outside_across;            /* of the multipliers outside: those of the directions across the
                                    * invariant subspace (0 when none is held) */
} swim_cont_point;

typedef struct {
    double lo, hi;                 /* between these parameters */
    const char *kind;              /* "period doubling", "Neimark-Sacker", "fold or branch point", or
                                    * the branch point where orbits leaving the invariant subspace
                                    * branch off */
    int bisections;                /* halvings of the bracket done */
    int refined;                   /* all SWIM_CONT_BISECTIONS done */
    char why[160];                 /* why refining stopped early ("" otherwise) */
    swim_cont_point at;            /* the orbit at the bracket's end outside the circle */
} swim_cont_special;

typedef struct {
    const char *key;               /* "energy" or a run-time scene key */
    double start, stop;
    int points;
    swim_periodic_options periodic;
    void (*progress)(void *ctx, double param, double period);   /* after each point of the branch (NULL: none) */
    void *progress_ctx;
} swim_cont_options;

typedef struct {
    swim_cont_point *pt;           /* sorted by parameter (owned) */
    int n;
    swim_cont_special special[64];
    int nspecial;
    char ended[2][256];            /* why each side ended early ("" when it reached its end) */
    double param0;                 /* the scene's own orbit's parameter */
    int stopped;                   /* d->interrupt's value when the caller stopped the work (a signal
                                    * number for swim continue): the points so far are kept */
    int n2;                        /* shape state entries of the phase points ... */
    char znames[SWIM_FLOQUET_MAX][24];   /* ... and their names (velocities as dNAME) */
    signed char hold[SWIM_FLOQUET_MAX];  /* the invariant subspace held: entries at 0 */
    int nhold;
    long rhs_calls;
    double seconds;
} swim_branch;

/* 0 (points computed; some may be missing: see ended), 1 (no first orbit, out of memory), 2 bad
 * input (energy of a scene that is not conservative, a key the right-hand side does not read),
 * the cause in st ("swim continue: ..."). A point whose integration fails along the branch is
 * not a failure of the branch: its cause goes to st's note. */
int swim_continue(swim_dynamics *d, swim_scene *scene, const swim_floquet_section *sec, const swim_cont_options *o,
                  swim_branch *out, swim_status *st);
void swim_branch_free(swim_branch *b);
/* branch.csv's columns: the parameter (named key, energy_target for the energy), period, dx, dy,
 * dtheta, energy, dy_per_time, max_abs_multiplier, stable, residual, iterations, displacement,
 * then the phase point's entries (b->znames). Their count; column j's name. */
#define SWIM_BRANCH_FIXED_COLUMNS 12
int swim_branch_columns(const swim_branch *b);
const char *swim_branch_column(const swim_branch *b, const char *key, int j);
/* Row i of branch.csv as numbers, swim_branch_columns(b) of them (stable 1 or 0). */
void swim_branch_row(const swim_branch *b, int i, double *values);
void swim_branch_csv(FILE *f, const swim_branch *b, const char *key);
void swim_branch_json(FILE *f, const swim_branch *b, const char *scene, const char *key);

#endif
