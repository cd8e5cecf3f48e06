/* sensitivity.h -- forward sensitivities of a scene's state: the variational equations (model
 * math: the keys, the augmented right-hand side, sensitivity.csv's rows). A run carries them on its
 * own steps (driver/analyses.h, driver/flow.h); no integration of them is made outside a run.
 *
 * For a key p -- a run-time number the right-hand side reads (model.rho0, elastic.stiffness[4],
 * parameters.A, barrier.epsilon, ...) or an initial value (c0.NAME, dc0.NAME of a free
 * coordinate) -- the sensitivity s = dy/dp of the integrator state y (model/dynamics.h: q,
 * c_carried, cdot_carried, work) solves
 *     s' = (df/dy) s + df/dp,      s(0) = dy0/dp.
 * The augmented state (y, s_1, ..., s_K) is integrated by an integrator of ode/ode.h: in a run,
 * by default outside its error control (CVODES's errconS = false, swim_ode_options.error_dim).
 * Exact keys (every key but the two below): df/dy is the scene kernel's exact Jacobian and
 * df/dp its exact parameter partials (kernel/swim_kernel.h, jacobian_params: SymPy's
 * derivatives of the forces and of a forcing law, the densities through the mass matrices):
 * one Jacobian per evaluation of the augmented system, then a product per key.
 * Difference keys -- barrier.alpha, and the value of a locked coordinate, which the kernel
 * reads as data, not as a coordinate -- take (df/dy) s + df/dp as the central difference of
 * the right-hand side along (s, 1) in (y, p), a step scaled to the state and the key (error
 * ~1e-10 relative, 2 evaluations of f per key); an error test that covers them runs at
 * rtol >= 1e-10 (driver/flow.c), since a tighter one fights that noise.
 * dy0/dp of an initial value is the unit vector projected onto the constraints G1, G2 and the
 * locks at c0 (ERRATA D5): the derivative of the run that a scene with [run] project_initial =
 * true makes from perturbed initial data.
 *
 * Ownership: a swim_sens borrows the dynamics (and, through the keys, writes to the scene's
 * numbers while it differentiates; each is restored bit for bit before the call returns).
 */
#ifndef SWIM_MODEL_SENSITIVITY_H
#define SWIM_MODEL_SENSITIVITY_H

#include <stdio.h>

#include "model/dynamics.h"

#define SWIM_SENS_MAX_KEYS 160   /* --sensitivity-initial adds 2 per free coordinate */

/* One column of the variational equations. */
typedef struct {
    char name[64];          /* the key as given, e.g. "parameters.A" */
    double *value[2];       /* the run-time numbers the key is (nvalue of them; 0 for initial values) */
    int nvalue;
    double *s0;             /* dy0/dp on the integrator state (owned, state_dim entries) */
    int exact;              /* 1: J s + the kernel's exact partial; 0: a difference quotient */
    swim_param param;       /* exact keys: the kernel's parameter (kind 0: an initial value) */
    double param_scale;     /* d/dp = param_scale * the kernel's partial (1/eps for eps d/d eps) */
} swim_sens_key;

typedef struct {
    swim_dynamics *d;       /* borrowed; swim_dynamics_use_scene_kernel done */
    int dim;                /* integrator state dimension */
    int nkeys;
    swim_sens_key keys[SWIM_SENS_MAX_KEYS];
    double *yp, *ym, *fp, *fm;   /* workspace (owned) */
    double *J, *dp;              /* the exact Jacobian, the exact keys' partials (owned) */
    swim_param *plist;           /* the parameters of the exact keys, in key order (owned) */
    long rhs_calls, jac_calls;
    /* 1 (default) the error test covers the sensitivities too (as CVODES with errconS); 0 the
     * state only (a flow's columns, driver/flow.h, set it as asked) */
    int error_control;
} swim_sens;

/* 0, or -1 (out of memory). */
int swim_sens_init(swim_sens *S, swim_dynamics *d);
void swim_sens_free(swim_sens *S);

/* Adds the key `key` (the grammar of swim run --set, plus c0.NAME / dc0.NAME), resolved on the
 * scene of S->d (mutable: scene). 0, or 2 with the line "swim CMD: --sensitivity: KEY: reason"
 * in st (unknown key, a term the kernel does not have, a locked velocity, ...). A key that
 * another option gave names that option: cmd "COMMAND: --OPTION" (e.g. "continue: --param"),
 * and the line is "swim COMMAND: --OPTION: KEY: reason". */
int swim_sens_add_key(swim_sens *S, swim_scene *scene, const char *cmd, const char *key, swim_status *st);
/* Adds a column with the initial sensitivity e_i of integrator-state component i (Floquet:
 * monodromy columns). */
int swim_sens_add_state(swim_sens *S, int i, const char *name);
/* Adds c0.NAME and dc0.NAME for every free coordinate: the derivatives with respect to the
 * initial shape and velocity on the constraint manifold (swim run --sensitivity-initial).
 * 0, or 2 with the cause in st (too many keys). */
int swim_sens_add_initial(swim_sens *S, swim_scene *scene, const char *cmd, swim_status *st);
/* Every key by difference quotients, as before the exact partials (for comparisons). */
void swim_sens_use_differences(swim_sens *S);
/* 1 when every key is exact (no difference quotient anywhere). */
int swim_sens_exact(const swim_sens *S);
/* Adds every key of a comma-separated list (the word `initial` for swim_sens_add_initial);
 * 0 or 2 as swim_sens_add_key. */
int swim_sens_add_list(swim_sens *S, swim_scene *scene, const char *cmd, const char *list, swim_status *st);

/* Augmented state: dimension (1 + nkeys) * dim; Y = (y, s_1, ..., s_K). */
int swim_sens_dimension(const swim_sens *S);
void swim_sens_initial(const swim_sens *S, const double *y0, double *Y0);
/* The augmented right-hand side (swim_ode_func, params = swim_sens *). */
int swim_sens_rhs(double t, const double *Y, double *dY, void *params);

/* dE/dp at an augmented state Y for key k: E the total energy of the diagnostics (kinetic +
 * W1 + W2), differentiated along (s_k, 1) like the right-hand side. NAN when a diagnostic fails. */
double swim_sens_energy(swim_sens *S, const double *Y, int k);

/* sensitivity.csv's columns for the first nkeys keys (the rows below): *names (ncol of them, freed
 * with swim_sens_names_free). 0, or -1 out of memory. */
int swim_sens_names(const swim_sens *S, int nkeys, char ***names, int *ncol);
void swim_sens_names_free(char **names, int ncol);
/* The row of sensitivity.csv at time t from the augmented state Y (the state relative to the
 * dynamics' origin, as the integrator carries it): t, then for each of the first nkeys keys dx, dy,
 * dtheta, denergy, dwork, then their full-state columns. */
void swim_sens_row(swim_sens *S, int nkeys, double t, const double *Y, double *row);

/* Rows in memory: T->names[0 .. ncol) (sensitivity.csv's header) and T->values, nrows rows of ncol
 * numbers, row-major (swim_sens_table_free). */
typedef struct {
    char **names;
    int ncol;
    double *values;
    long nrows, cap;
} swim_sens_table;
void swim_sens_table_free(swim_sens_table *T);
/* The header (row NULL: the names copied) or a row (ncol numbers) appended to T. 0, or -1 out of memory. */
int swim_sens_table_add(swim_sens_table *T, const char *const *names, int ncol, const double *row);

#endif
