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
 * The search runs in unbounded variables u, with the key's value lo + (hi - lo) (1 + sin u) / 2:
 * every evaluated value lies in [lo, hi] and the bounds are reachable (sin u = +-1). Methods:
 *   Nelder-Mead (gsl_multimin_fminimizer_nmsimplex2): no gradient; for any quantity, also one
 *     that is not smooth or has no sensitivity (displacement_per_work: W_F is not a kernel
 *     state); converged when the simplex is smaller than tol in u;
 *   BFGS (gsl_multimin_fdfminimizer_vector_bfgs2): the gradient from the exact sensitivities of
 *     the final state (driver/flow.h: carried by the evaluation's own run, on its steps) for x,
 *     y, theta, displacement, work and energy of free dynamics; converged when |grad_u| < tol.
 * Both are local. With starts K > 1 the search is repeated from K space-filling points of the box
 * (the middle first, then a Halton sequence) and the best of all is kept. Then the best point is
 * evaluated again at 100x tighter rtol and atol: the value there and its change are reported, and
 * an optimum whose value moves by more than the value tolerance tol max(1, |q|) is not called
 * converged (its value is an artefact of the integration's error, or not yet resolved by it).
 */
#ifndef SWIM_CONTROL_OPTIMIZE_H
#define SWIM_CONTROL_OPTIMIZE_H

#include <stdio.h>

#include "scene/scene.h"

#define SWIM_OPT_MAX_KEYS 8
#define SWIM_OPT_MAX_SETS 64   /* --set overrides */
#define SWIM_OPT_MAX_STARTS 64

enum { SWIM_OPT_NELDER_MEAD, SWIM_OPT_BFGS };

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
    int have_grad;       /* BFGS: the gradient of the quantity in the keys' values */
    double grad[SWIM_OPT_MAX_KEYS];
} swim_eval_result;

/* One local search (one start). */
typedef struct {
    double start[SWIM_OPT_MAX_KEYS];
    double best_value[SWIM_OPT_MAX_KEYS], best_q;
    int iterations, converged, ok;
    long evaluations;
} swim_opt_start;

typedef struct {
    const char *scene_path;      /* names the scene in messages and in optimize.json */
    const char *scene_text;      /* the scene file's text, read once (swim_scene_read) by the caller:
                                    the evaluations' problem is made from it, so the file is opened
                                    once and an edit during the search changes nothing */
    size_t scene_len;
    const swim_override *sets;   /* --set overrides, applied first */
    int nsets;
    int nkeys;
    swim_override keys[SWIM_OPT_MAX_KEYS];   /* the varied keys (values filled per evaluation) */
    double lo[SWIM_OPT_MAX_KEYS], hi[SWIM_OPT_MAX_KEYS];
    int quantity, maximize;
    int method;                  /* SWIM_OPT_NELDER_MEAD or SWIM_OPT_BFGS */
    int starts;                  /* local searches from space-filling points (1: the middle) */
    int max_iter;                /* per start */
    double tol;                  /* simplex size (Nelder-Mead) or |grad_u| (BFGS) at which a search
                                    stops; also the relative value tolerance of the tight check */
    FILE *log_csv;               /* per-iteration rows (may be NULL) */
    int quiet;                   /* no progress lines */
    swim_status *status;         /* where a failure of the search goes (out of memory) and, by its
                                    note, one progress line per iteration (may be NULL) */
    volatile int *interrupt;     /* set asynchronously (SIGINT): the current run stops, the search
                                    ends with what it has (may be NULL) */
    /* results */
    double best_value[SWIM_OPT_MAX_KEYS], best_q;
    swim_eval_result best;
    long evaluations, failed, gradients;
    int iterations, converged, interrupted;
    swim_opt_start start[SWIM_OPT_MAX_STARTS];
    int nstarts, best_start;
    int search_converged;        /* the best start's search met its tolerance */
    /* the best point again at rtol / 100, atol / 100 */
    int tight_status;            /* 0 ran; else the run failed */
    double tight_q, tight_change, value_tol;
    double seconds;
    struct swim_problem_s *problem;   /* the evaluations' scene, kernels and dynamics (problem/problem.h),
                                         made at the first one, closed when the search ends */
} swim_opt_problem;

/* One run with values v[0..nkeys): 0, or the status (1 failed, 2 refused) with the reason. */
int swim_opt_evaluate(swim_opt_problem *p, const double *v, swim_eval_result *r);
double swim_opt_quantity(const swim_opt_problem *p, const swim_eval_result *r);
/* 1 when `quantity` has a gradient from the sensitivities (BFGS), else 0. */
int swim_opt_has_gradient(int quantity);
/* Whether every varied key has a sensitivity at the scene with overrides ov (the scene's
 * kernel): 0, or 2 with the line "swim optimize: --vary: KEY: reason" (or the scene's) in st. */
int swim_opt_check_gradient(const swim_opt_problem *p, const swim_override *ov, int nov, swim_status *st);
/* KEY=LO:HI (spec, as --vary takes it) into the next of p->keys, lo, hi: a number of the scene
 * (an item of a vector), LO < HI finite, each value varied once and not also one of p->sets
 * (compared by the value set, whatever its spelling: shape.c0.am1 is shape.c0[2]; a value varied
 * twice, or varied and set, would leave one of them a dead variable the search "converges" over).
 * Needs p->scene_path, sets and nsets. 0, or 2 with the line "swim optimize: --vary ..." in st. */
int swim_opt_vary(swim_opt_problem *p, const char *spec, swim_status *st);
/* The problem checked before any run, as swim optimize checks it: the scene with every key at LO,
 * then at HI, then in the middle (a bound the scene refuses is named by its --vary now, not met by
 * a run halfway through), BFGS only for a quantity with a gradient, on free dynamics, with keys
 * that have sensitivities; forcing_work and displacement_per_work need a forcing law or a stroke.
 * Needs p's scene, sets, keys, quantity and method. 0, or 2 with the line in st (the scene
 * reader's notices go to st's note callback). */
int swim_opt_check(const swim_opt_problem *p, swim_status *st);
/* The best value holds at the tight tolerances (optimize.json's tight_check.holds). */
int swim_opt_holds(const swim_opt_problem *p);
/* optimize.json of a finished search on f; best_path: the best scene's file (NULL: null). */
void swim_opt_json(FILE *f, const swim_opt_problem *p, const char *best_path);
/* The search (every start, then the tight check); 0, or 1 when no evaluation succeeded.
 * converged = the best start's search met tol and its value held at the tight tolerances. */
int swim_opt_run(swim_opt_problem *p);
/* The scene file with the --set overrides and the best values written in: 0, or -1 (errno). */
int swim_opt_write_scene(const swim_opt_problem *p, const char *path);

#endif
