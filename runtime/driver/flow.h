/* flow.h -- the flow map of a scene's equations as a driver run: from a given state over a given
 * time, optionally with its variational equations, optionally ended at a section's events. What
 * the orbit analyses (control/floquet.h, control/periodic.h, control/continuation.h) and swim
 * optimize's gradient integrate, so that no integrator is created outside the driver: the flow is
 * a run (driver/run.h) with the scene's integrator, its projection, the near-wall policy, restarts
 * and origin shifts, rows only at 0 and the end (no rows kept).
 *
 * The variational equations are model/sensitivity.h's columns: d y / d y0_j for chosen components
 * of the packed state (the monodromy), then d y / d p for scene keys (the gradient of a quantity
 * at t_end). By default they ride on the state's steps, out of its error test (CVODES's errconS =
 * false; the trajectory is then bit for bit the run without them); error_control puts them in it.
 *
 * Ownership: a swim_flow owns its run (and so the dynamics its columns live on) until
 * swim_flow_free; the model and the request are borrowed for the call only.
 */
#ifndef SWIM_DRIVER_FLOW_H
#define SWIM_DRIVER_FLOW_H

#include "driver/run.h"
#include "model/sensitivity.h"

/* The variational columns to carry (none: state_count and nkeys 0). */
typedef struct {
    int state_from, state_count;    /* d y / d y0_j for j in [state_from, state_from + state_count)
                                       of the packed state */
    const char *const *keys;        /* then d y / d p for each scene key (--sensitivity's names) */
    int nkeys;
    const char *cmd;                /* names the command in a key's message ("optimize: --vary") */
    int error_control;              /* 1: in the integrator's error test (a column by differences
                                       then floors the tolerances for its noise) */
} swim_flow_vars;

typedef struct {
    const swim_dynamics *model;     /* the scene, its kernels and parameters as this dynamics has
                                       them (a scene run, not a stroke); its interrupt stops the flow */
    const double *y0;               /* the packed initial state at t = 0; NULL: the scene's */
    double t_end;                   /* > 0 */
    double rtol, atol;              /* 0: the scene's */
    const swim_run_section *section;   /* or NULL; its hit may end the flow early */
    swim_flow_vars vars;
} swim_flow_request;

typedef struct {
    swim_run *run;
    swim_sens S;                    /* the columns, on the run's dynamics */
    int have_sens;
    double *Y;                      /* the augmented state at the end (swim_sens_dimension(&S)
                                       entries; the state alone without columns), the state part
                                       absolute (model/dynamics.h, packed) */
    double t;                       /* the time reached */
    int section_ended;              /* the section's hit ended the flow (before t_end) */
    long rhs_calls;                 /* of the right-hand side, the columns' included */
    const char *reason;             /* why it failed (the run's reason), NULL when it did not */
    swim_compiled *compiled;        /* the model's kernels as the run takes them (owned) */
    swim_run_settings set;          /* the run's settings: the scene's [run] with the flow's horizon
                                       (rows at 0 and t_end only) and tolerances */
} swim_flow;

/* Attach the columns v to run (before it advances), on its dynamics: f->S and the initial
 * columns. 0; 2 (a key refused, or the integrator cannot carry them as asked) or 1 (out of
 * memory) with the cause in st. */
int swim_flow_attach(swim_flow *f, swim_run *run, const swim_flow_vars *v, swim_status *st);
/* After the run: the augmented state at its last row into f->Y (allocated), f->t. 0, or -1 when
 * the columns were not carried to it (f->reason says why) or out of memory. */
int swim_flow_final(swim_flow *f);

/* The flow of req: 0 (f->Y at t_end, or at the section's event that ended it); 1 when the run
 * failed or was stopped (f->reason; the model's interrupt says which) or out of memory; 2 for a
 * request the driver refuses (the cause in st). f is to be freed whatever the return. */
int swim_flow_map(const swim_flow_request *req, swim_flow *f, swim_status *st);
void swim_flow_free(swim_flow *f);

#endif
