/* optimize.h -- the best values of scene keys for one quantity of a run (swim optimize).
 *
 * Each evaluation is a whole run, in process: the scene read again with the varied keys as
 * overrides (so every value is validated like one of swim run --set, and a value that changes
 * the structure gets its own kernel from the cache), integrated to t_end by the scene's
 * integrator with swim run's drift control and tolerances, so that the final state is the one
 * `swim run` computes for the same scene (tested: best.toml run by swim run gives the reported
 * value). Besides the state, the run integrates the work of the internal forces,
 * W_F = int_0^T F(t) . cdot dt (5.1), outside the error control (it does not change the steps).
 *
 * Quantities (maximized or minimized): x, y, theta (final position and orientation),
 * displacement = |r(T) - r(0)|, work (the work column: W_F minus the dissipation, = E(T) - E(0)
 * by (5.3)), forcing_work (W_F), displacement_per_work (displacement / W_F; scenes with a
 * forcing law), energy (E(T)). For a prescribed stroke ([stroke]) work and forcing_work are the
 * positive work int max(P, 0) dt the body spends (stroke/stroke.h), so displacement_per_work is
 * the distance swum per unit of energy spent.
 *
 * The search is GSL's Nelder-Mead simplex (gsl_multimin_fminimizer_nmsimplex2) in unbounded
 * variables u, with the key's value lo + (hi - lo) (1 + sin u) / 2: every evaluated value lies in
 * [lo, hi] and the bounds are reachable (sin u = +-1). No gradient is used: a quantity such as
 * displacement_per_work has no sensitivity of its own (W_F is not a state of the kernel), and
 * a failed run (a shape leaving D) has none either.
 */
#ifndef SWIM_CONTROL_OPTIMIZE_H
#define SWIM_CONTROL_OPTIMIZE_H

#include <stdio.h>

#include "scene/scene.h"

#define SWIM_OPT_MAX_KEYS 8
#define SWIM_OPT_MAX_SETS 64   /* --set overrides */

enum { SWIM_Q_X, SWIM_Q_Y, SWIM_Q_THETA, SWIM_Q_DISPLACEMENT, SWIM_Q_WORK, SWIM_Q_FORCING_WORK,
       SWIM_Q_DISPLACEMENT_PER_WORK, SWIM_Q_ENERGY, SWIM_Q_COUNT };

/* The index of a quantity's name, or -1. */
int swim_quantity_index(const char *name);
const char *swim_quantity_name(int index);
/* "x, y, ..." for messages. */
const char *swim_quantity_list(void);

typedef struct {
    double x, y, theta, work, forcing_work, energy;
    int status;          /* 0 completed; 1 the run failed; 2 the values were refused */
    char reason[160];
} swim_eval_result;

typedef struct {
    const char *scene_path;
    const swim_override *sets;   /* --set overrides, applied first */
    int nsets;
    int nkeys;
    swim_override keys[SWIM_OPT_MAX_KEYS];   /* the varied keys (values filled per evaluation) */
    double lo[SWIM_OPT_MAX_KEYS], hi[SWIM_OPT_MAX_KEYS];
    int quantity, maximize;
    int max_iter;
    double tol;                  /* simplex size in u at which the search stops */
    FILE *log_csv;               /* per-iteration rows (may be NULL) */
    int quiet;                   /* no progress on stderr */
    volatile int *interrupt;     /* set asynchronously (SIGINT): the current run stops, the search
                                    ends with what it has (may be NULL) */
    /* results */
    double best_value[SWIM_OPT_MAX_KEYS], best_q;
    swim_eval_result best;
    long evaluations, failed;
    int iterations, converged, interrupted;
} swim_opt_problem;

/* One run with values v[0..nkeys): 0, or the status (1 failed, 2 refused) with the reason. */
int swim_opt_evaluate(swim_opt_problem *p, const double *v, swim_eval_result *r);
double swim_opt_quantity(const swim_opt_problem *p, const swim_eval_result *r);
/* The search; 0, or 1 when no evaluation succeeded. */
int swim_opt_run(swim_opt_problem *p);
/* The scene file with the --set overrides and the best values written in: 0, or -1 (errno). */
int swim_opt_write_scene(const swim_opt_problem *p, const char *path);

#endif
