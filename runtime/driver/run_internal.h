/* run_internal.h -- the state of one scene run (driver/run.c, the scene kind of driver/run.h).
 * Not part of the driver's contract. */
#ifndef SWIM_DRIVER_RUN_INTERNAL_H
#define SWIM_DRIVER_RUN_INTERNAL_H

#include "driver/run.h"
#include "driver/watch.h"

typedef struct {
    double t_reached, jmin, e0, drift_abs, emax, res_volume, res_volume_rate, res_angular, res_locks;
    double jmin_t;        /* when min J was smallest (rows and, with the watch, every accepted step) */
    double left_t;        /* where the shape left D (the crossing), or NAN */
    long rows;
    int status;           /* 0 completed, 1 failed */
    char *reason;         /* why it stopped (owned) */
    double switch_t;      /* time of a switch to the stiff fallback integrator, or -1 */
    double integrate_seconds;   /* time inside the integrator (steps, RHS, interpolation) */
    double diagnostics_seconds; /* energies, impulses, residuals, min J of the output rows */
    double output_seconds;      /* in the sink: formatting and writing rows and snapshots */
    char used[80];        /* integrator(s) used: two names of at most 31 characters */
    int event_stop;       /* a :stop event ended the run (status completed, reason says which) */
    int left_stop;        /* the row just reached is where the shape left D: the last one */
} run_report;

/* The row of trajectory.csv at an integrator state (event functions evaluate columns). */
typedef struct {
    const swim_scene *s;
    swim_dynamics *d;
    double *full;
} row_ctx;

typedef struct scene_run scene_run;

struct scene_run {
    swim_run_request req;
    swim_scene *s;              /* req.scene */
    const swim_run_settings *set;   /* req.settings: what the run reads, never s->run */
    const swim_compiled *kn, *spz;   /* req.kernel, req.system */
    swim_run_events *events;    /* req.events */
    swim_dynamics d;
    int d_ready;
    swim_ode *ode;
    swim_ode_system sys;
    swim_ode_options o;
    swim_ode_stats total;
    int sdim, ncol;
    double *y, *row, *ys, *ys_last, *ys_row;
    double *y_inside;           /* full state of the last row with min J > 0 (NULL: none yet) ... */
    double kinetic_inside;      /* ... its kinetic energy, for the barrier's reach when D is left */
    int have_inside;
    const char *names[SWIM_RUN_MAX_COLUMNS];
    char storage[2 * SWIM_NMAX][24];
    row_ctx rowc;
    double bal_scale;           /* energy scale of abm's balance test: max(|E0|, max |E| so far) */
    double *tol_scale;          /* abm's per-component tolerance factors near the barrier (or NULL) */
    /* shifted coordinates near the barrier (model/dynamics.h, swim_dynamics_set_origin) */
    int shift_ok;               /* the integrator in use may shift */
    int shift_pending;          /* the integrator stopped at shift_t to move the origin (1), drop it (2)
                                   or take an impact (3) */
    double shift_t;             /* in the integrator's time (absolute: d.t_origin + shift_t) */
    double left_native;         /* the watch's crossing, in the integrator's time */
    double row_jmin;            /* min J of the row's exact state with an origin (else NAN) */
    double row_clock;           /* clock at the end of the row's integration: its diagnostics start there (0: none) */
    double out_clock;           /* clock at the end of a row's output: the next row's integration starts there
                                   (0: none; cleared when the loop hands control back, advance_rows) */
    double *ys_shift;           /* the accepted state at shift_t, in the integrator's coordinates */
    double *atolv;              /* absolute tolerances with an origin: atol + rtol |origin_i| */
    long shifts;                /* restarts for the origin */
    long steps_since_shift;     /* accepted steps since the last one */
    /* bounces too deep to follow, taken as impacts (model/bounce.h, impact_wanted) */
    double impact_dv[SWIM_NMAX];   /* the pending impact's change of cdot (full shape layout) */
    double impact_j, impact_reach; /* its min J and predicted turning depth, over |c_1|^2 */
    long impacts;
    double impact_first_t, impact_last_t, impact_j_max, impact_reach_min;
    swim_run_watch watch;       /* checks at every accepted step (integrators with dense output) */
    int watch_ready;
    run_report r;
    swim_run_result res;        /* filled at the end of the integration */
    int nsnap;                  /* rows flagged for a flow snapshot */
    /* the output loop (start_loop, next_row), kept between calls of swim_run_advance */
    int loop_started, loop_done, loop_rc;
    long k, nrows, every;       /* the next row, the rows of the grid, the snapshot spacing */
    double t_last;              /* the last row's time */
    int invariant_on;           /* the energy balance is in the error test (summary: energy_control) */
    /* the work of the forcing alone, W_F (forcing_step, forcing_row) */
    int fw_on, fw_bad;
    double fw_done, fw_pending, fw_ta, fw_tb, fw_at_row;
    double *fw_full, *fw_ys;
    /* the last row's energy and work */
    double last_energy, last_work;
    double t_start;
    /* the last accepted step, absolute times (swim_run_state_at), and the origin it was taken in */
    double last_ta, last_tb, last_origin;
    int have_step;
    /* variational equations on the run's steps (swim_run_set_variational) */
    int ndim;                   /* the integrator's dimension: sdim, + var.dim with them */
    int var_on;                 /* attached and still carried */
    swim_run_variational var;
    swim_ode_system sys_state;  /* the state alone (for a fallback that cannot carry them) */
    char var_reason[200];       /* why they stopped ("" while carried) */
    double var_t;               /* ... at the last row they hold */
    double *var_buf;            /* ndim: the interpolant at a mark */
    double lyap_scale;          /* ln of what the renormalizations took out of w so far */
    double lyap_scale_row;      /* ... at the last row (ys_last) */
    double *lyap_t, *lyap_g;    /* the marks: time, ln |w| */
    long lyap_n, lyap_cap;
    char lyap_reason[160];
    swim_run_var_result var_res;
    double *var_final;          /* ndim: var_res.final */
    /* the request's section (swim_run_request.section) as the integrator's one event */
    swim_ode_event sec_ev;
    volatile int sec_stop;      /* its hit asked to end the run at the event just located */
};

#endif
