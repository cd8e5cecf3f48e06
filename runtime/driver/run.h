/* run.h -- one run of a dynamic scene: the policy of swim run below every command that integrates
 * a scene (swim run, sweep members, optimize, floquet, sensitivities).
 *
 * The driver owns the integration and everything that decides it: the output grid (rows exactly
 * at k*output_step and at t_end, from the integrator's interpolant), the one mapping of the scene's
 * settings to swim_ode_options (by the integrator's capabilities, never by its name), the checks
 * at every accepted step (driver/watch.h), the tolerance cut and the shifted origin near the
 * boundary of D, bounces taken as impacts, the stiff fallback, events (driver/events.h) and why
 * the run stopped. It owns no path and prints nothing: rows, notices and progress leave through
 * a sink of callbacks (the caller writes files, or keeps arrays), and the result is a struct that
 * summary.h writes as summary.json. A scene with a [stroke] table runs as the other kind behind
 * the same contract (swim_run_kind).
 *
 * Use: fill a swim_run_request (a validated scene and its kernels, which the caller obtains and
 * keeps open for the run's life), swim_run_open, swim_run_integrate, read swim_run_result (and the
 * dynamics for anything computed after), swim_run_free. Errors come back as a return code and a
 * status (io/status.h), never as an exit or a printed line.
 */
#ifndef SWIM_DRIVER_RUN_H
#define SWIM_DRIVER_RUN_H

#include <signal.h>
#include <stddef.h>

#include "codegen/codegen.h"
#include "driver/events.h"
#include "model/dynamics.h"
#include "ode/ode.h"
#include "scene/scene.h"

/* One row of trajectory.csv, handed to the sink as it is computed. */
typedef struct {
    long index;                 /* 0, 1, ...: the k of t = k*output_step (the last may be t_end or an event) */
    double t;
    const double *values;       /* the columns (swim_run_columns), ncol of them */
    int ncol;
    const double *full;         /* the full state (model/dynamics.h layout) at t */
    swim_dynamics *d;           /* for anything the sink computes from the state (flow snapshots) */
    int snapshot;               /* one of the rows a flow snapshot is taken at: SWIM_RUN_SNAPSHOTS
                                   evenly spaced, and the last */
} swim_run_row;

#define SWIM_RUN_SNAPSHOTS 10

enum { SWIM_RUN_ROW_FAILED = 1, SWIM_RUN_ROW_STOP = 2 };

/* Where the rows go. Every callback may be NULL. */
typedef struct {
    /* A row: 0 to go on; SWIM_RUN_ROW_FAILED when it could not be kept, SWIM_RUN_ROW_STOP when it
     * was and the run must end there (either way the run stops, failed, and `why` says why, e.g.
     * "cannot write PATH: No space left on device", "stopped by the caller"). */
    int (*row)(void *ctx, const swim_run_row *row, char *why, size_t len);
    /* Every attempted step of integrators that report them (SWIM_ODE_CAP_STEP_TRACE), in the
     * absolute time of the run, with the dynamics for the state's energy. */
    void (*step)(void *ctx, const swim_ode_step *st, swim_dynamics *d);
    /* A line the user must see even in a quiet run: the switch to the stiff fallback, the first
     * bounce taken as an impact. */
    void (*notice)(void *ctx, const char *line);
    /* After every row: where the run is. */
    void (*progress)(void *ctx, double t, double t_end);
    void *ctx;
} swim_run_sink;

typedef struct {
    swim_scene *scene;              /* validated (problem/problem.h); the driver writes no run setting
                                       into it (those it resolves, energy_control and step_lookahead,
                                       are in the result and the summary); a stroke's run writes its
                                       initial state (c0, dc0, a neutral rhof) into it */
    const swim_compiled *kernel;    /* the kernel of N modes (codegen) */
    const swim_compiled *system;    /* the scene's right-hand side (swim_codegen_scene) */
    int generic;                    /* the kernel of the generic structure was asked for */
    swim_run_events *events;        /* borrowed, may be NULL (swim_run_events_parse) */
    volatile sig_atomic_t *stop;    /* set by a signal handler to stop the run (NULL: never) */
    swim_run_sink sink;
    int stop_by_caller;             /* *stop is a caller's flag (libswim), any nonzero value, not a
                                       signal number: the run ends "stopped by the caller" */
    /* The run's settings, resolved by the caller from the scene's [run] and its own options and
     * checked (swim_run_settings_check); borrowed. NULL: the scene's [run] as read (scene->run,
     * which the reader checked). The driver reads these, never the scene's. */
    const swim_run_settings *settings;
    /* A flow map rather than the scene's own run (driver/flow.h; a scene run only, not a stroke):
     * its horizon and tolerances are its settings'. */
    const double *y0;               /* the packed initial state at t = 0 (model/dynamics.h layout,
                                       copied); NULL: the scene's */
    const struct swim_run_section *section;   /* events of one state component (only when
                                       `events` is NULL; borrowed for the run's life), or NULL */
} swim_run_request;

/* A section: the instants where one component of the packed state (absolute, whatever origin the
 * run has shifted to) crosses zero rising, or has a maximum or a minimum, located by the
 * integrator's events on its interpolant (the derivative is the interpolant's, no difference).
 * Each is told to `hit` in the run's absolute time; a nonzero return ends the run there,
 * completed, with the state there as its last row. What the driver's events (driver/events.h,
 * columns of trajectory.csv) cannot say: a crossing in one direction only. */
typedef struct swim_run_section {
    int index;                  /* the component (model/dynamics.h, packed) */
    char kind;                  /* 'z' zero (rising), 'x' maximum, 'n' minimum */
    int (*hit)(void *ctx, double t);
    void *ctx;
} swim_run_section;

/* What a prescribed stroke adds (scene with a [stroke] table). */
typedef struct {
    int laws, completed_c1;              /* the laws, and whether c1 is completed from the volume */
    long rhs_calls;
    double period;                       /* > 0, or none */
    const char *period_source;           /* "scene", "detected" or "none" */
    long strokes;                        /* whole strokes reported */
    double first_dx, first_dy, first_dtheta, first_work_positive;   /* of the first stroke (NAN: none) */
    double work, work_positive;
} swim_stroke_report;

/* What a run found: the numbers of summary.json. */
typedef struct {
    int status;                 /* 0 completed, 1 failed */
    char *reason;               /* why it stopped (NULL only when out of memory) */
    double t_reached;
    long rows;
    double e0, drift_abs, emax;          /* E(0), max |E - E0 - work|, max |E| over rows and steps */
    double res_volume, res_volume_rate, res_angular, res_locks;
    double jmin, jmin_t;                 /* smallest min J (rows and steps) and when */
    double left_t;                       /* where the shape left D, or NAN */
    double switch_t;                     /* the switch to the stiff fallback, or -1 */
    char used[80];                       /* the integrator(s) used: "abm" or "abm+cvode-bdf" */
    int event_stop;                      /* a :stop event ended the run */
    swim_ode_stats stats;                /* the integrators' counters, summed */
    double integrate_seconds, diagnostics_seconds, output_seconds, wall_seconds;
    /* features of the run and what they did */
    int projection, step_checks, origin_shift_enabled, impacts_enabled, energy_control;
    long step_check_steps;
    double step_check_seconds;
    long shifts, impacts;
    double impact_first_t, impact_last_t, impact_j_max, impact_reach_min;
    double energy_control_tol;
    const double *final_state;           /* full state of the last row (dynamics layout) */
    double energy, work;                 /* E and the work of forcing and damping (5.3) at the last row */
    double forcing_work;                 /* the work of the forcing alone to the last row (0 without
                                            forcing; NAN without dense output); a stroke: the positive work */
    int finished;                        /* the run has ended (swim_run_advance) */
    int is_stroke;                       /* a prescribed stroke: */
    swim_stroke_report stroke;
    /* what the summary says of the model, the kernel and the integrator, whatever the kind */
    int summary_brief;                   /* nothing run and nothing known yet: the summary holds the
                                            scene, status, reason and rows only (a stroke before its call) */
    struct {
        int elastic, barrier, damping, forcing;   /* the effects the run's equations hold */
        const char *energy_law;                   /* the [elastic] energy law, or NULL */
    } effects;
    const swim_compiled *compiled;       /* the scene's right-hand side or the stroke's laws */
    const char *kernel_kind;             /* "specialized", "generic" or "stroke" */
    int state_dimension;                 /* of the integrated state */
    int step_lookahead;                  /* the integrator's step look-ahead used */
    long projection_steps;               /* projections onto the constraints, and the largest change */
    double projection_max_change;
    double projection_change;            /* of the initial velocity (0: not projected) */
    double impact_depth;                 /* run.impact_depth in force (0: none) */
    /* the right-hand side and the Jacobian: calls and seconds, also of passes after the run on its
     * dynamics (read when the result is asked for) */
    long rhs_calls;
    double rhs_seconds;
    const char *jacobian;                /* "exact", "differences" or "none" */
    long jacobian_calls;
    double jacobian_seconds;
} swim_run_result;

typedef struct swim_run swim_run;

#define SWIM_RUN_MAX_COLUMNS (8 + 4 * SWIM_NMAX + 64)

struct json_t;
struct swim_run_variational;
struct swim_run_var_result;

/* A kind of run, in the manner of GSL's step types: a small table of functions, chosen once when
 * the run opens (swim_run_kind_for). Two kinds: a scene run (swim_run_scene_kind, driver/run.c)
 * and a prescribed stroke (swim_run_stroke_kind, driver/stroke_run.c, a scene with [stroke]).
 * The functions below (swim_run_open ... swim_run_free, driver/kinds.c) call the run's kind. */
typedef struct {
    const char *name;
    /* the columns of trajectory.csv for scene s: names[] pointing into storage; the count */
    int (*columns)(const swim_scene *s, const char **names, char storage[][24]);
    /* the run of req (copied): 0; 1 (out of memory) or 2 (bad input) with the cause in st */
    int (*open)(const swim_run_request *req, void **state, swim_status *st);
    /* rows up to time t (swim_run_advance); the result's status */
    int (*advance)(void *state, double t);
    void (*fail)(void *state, const char *reason);
    /* the result so far (counters a pass after the run adds to on its dynamics read now) */
    const swim_run_result *(*result)(void *state);
    /* swim_run_state_at; NULL: the kind has no dense output */
    int (*state_at)(void *state, double t, double *y, double *t_from, double *t_to);
    swim_dynamics *(*dynamics)(void *state);
    /* the kind's own entries of summary.json, set after the events (NULL: none): 0, or -1 */
    int (*summary)(const void *state, struct json_t *summary);
    /* swim_run_set_variational and swim_run_get_var_result (NULL: the kind has no variational
     * equations: a prescribed stroke's shape is a given function of time) */
    int (*set_variational)(void *state, const struct swim_run_variational *v, swim_status *st);
    const struct swim_run_var_result *(*var_result)(void *state);
    void (*free)(void *state);
} swim_run_kind;

extern const swim_run_kind swim_run_scene_kind, swim_run_stroke_kind;

/* The kind of run scene s makes. */
const swim_run_kind *swim_run_kind_for(const swim_scene *s);

/* The columns of trajectory.csv for scene s (swim_run_kind_for(s)->columns; a prescribed stroke
 * has three more): names[] (at most SWIM_RUN_MAX_COLUMNS) pointing into storage. The count. */
int swim_run_columns(const swim_scene *s, const char **names, char storage[][24]);

/* The run settings as swim_ode_options (defaults, then rtol, atol, the step look-ahead): the one
 * mapping every integration of a scene starts from. What a run adds on top (events, the checks
 * at every step, the error weights and the balance test near the barrier) depends on the
 * integrator's capabilities and is the driver's. */
void swim_run_ode_options(const swim_run_settings *set, swim_ode_options *o);
/* The same with the drift control of an integration of the scene's own state (the run, floquet's
 * and periodic's passes): the state put back on the constraints after each step when
 * set->projection is on and the integrator can (SWIM_ODE_CAP_PROJECTION). Not for an augmented
 * state (sensitivities, the monodromy), whose columns are not projected this way. */
void swim_run_ode_options_projected(const swim_run_settings *set, swim_ode_options *o);

/* The run of req (copied; what it points to is borrowed): a dynamic run, or a prescribed stroke
 * when the scene has a [stroke] table (req->system then holds its laws, swim_codegen_stroke).
 * 0; 1 (out of memory) or 2 (a stroke that is not allowable) with the cause in st. Nothing is
 * integrated yet. */
int swim_run_open(const swim_run_request *req, swim_run **out, swim_status *st);
/* Rows from t = 0 to t_end or until the run stops. Returns the result's status. */
int swim_run_integrate(swim_run *run);
/* Rows up to time t (every row at or before t), going on from where the last call stopped: the
 * same rows, bit for bit, as one swim_run_integrate. result.finished says when the run has
 * ended (t_end, a :stop event, a failure); before, the result holds the rows so far. A prescribed
 * stroke runs to its end at the first call. Returns the status. */
int swim_run_advance(swim_run *run, double t);
/* The output rows failed after the run (closing a file): the run is failed with this reason. */
void swim_run_fail(swim_run *run, const char *reason);
const swim_run_result *swim_run_get_result(const swim_run *run);
/* The request the run was opened with (its scene, kernels, events). */
const swim_run_request *swim_run_get_request(const swim_run *run);
/* The run's kind's own entries of the summary into `summary` (0, or -1 when out of memory). */
int swim_run_kind_summary(const swim_run *run, struct json_t *summary);
/* The state at time t (trajectory.csv's columns 1 .. 3 + 2n: x, y, theta, c, cdot) from the
 * interpolant of the last accepted step [*t_from, *t_to] (set whenever there is one), projected
 * as a row is: a row's time gives the row's state bit for bit. 0; 1 when t is outside that step;
 * -1 when there is no such step (a prescribed stroke, an integrator without dense output, no
 * step yet, a restart since) or out of memory. */
int swim_run_state_at(swim_run *run, double t, double *state, double *t_from, double *t_to);
/* Variational equations on the run's own steps: `dim` components after the state (sensitivity
 * columns dy/dp, a tangent vector w) integrated with it, by the same integrator on the same steps,
 * through the driver's restarts near the barrier (an origin shift is a constant: the columns go
 * on unchanged) and the stiff fallback. Out of the error control by default (CVODES's errconS =
 * false; SWIM_ODE_CAP_ERROR_DIM), so that the state, and every row, is bit for bit the run
 * without them. What they stop at (an impact, a fallback that cannot carry them) is in
 * swim_run_var_result; the trajectory goes on. */ 
typedef struct swim_run_variational {
    size_t dim;                 /* components after the state */
    /* the whole augmented right-hand side (state, then the dim others), params = ctx: its state
     * part is swim_dynamics_rhs on swim_run_dynamics(run) at the same (t, y), called last (the
     * balance test reuses what that call left) */
    swim_ode_func rhs;
    void *ctx;
    const double *y0;           /* the dim components at t = 0 (copied) */
    int error_control;          /* 1: in the error test too (the steps, and the trajectory, differ) */
    /* At every row: the integrator's augmented state there (relative to the driver's origin, as
     * swim_dynamics_unpack reads it). 0, or nonzero with `why` when it could not be kept (the run
     * stops, failed). NULL: none. */
    int (*row)(void *ctx, double t, const double *Y, char *why, size_t len);
    void *row_ctx;
    /* A tangent vector (w' = J w, linear and homogeneous) in components [tangent_from,
     * tangent_from + tangent_count) of the dim, renormalized by Benettin's method: |w| over
     * [norm_from, norm_from + norm_count) of them (absolute offsets into the dim) is taken on
     * the interpolant at every multiple of interval (and at the last row), and w is scaled by a
     * power of two at the next step boundary (exact, swim_ode_scale). 0 = no tangent vector. */
    double interval;
    size_t tangent_from, tangent_count, norm_from, norm_count;
} swim_run_variational;

typedef struct swim_run_var_result {
    int carried;                /* they were carried to the run's last row */
    double t_stop;              /* else: the last row they hold */
    const char *reason;         /* ... and why they stopped there ("" when carried) */
    /* the tangent vector: ln |w| at the marks (t[k] increasing; w has |w| = 1 at t = 0), up to
     * the last row; tangent_reason non-empty when it vanished or overflowed */
    long marks;
    const double *t, *log_norm;
    const char *tangent_reason;
    /* the integrator's state (with them: the state, then the dim others) at the run's last row,
     * unprojected, its state part absolute (the driver's origin added back); NULL when they were
     * attached and not carried to it (or out of memory). Valid until the next call. */
    const double *final;
} swim_run_var_result;

/* Attach them before the first swim_run_advance (not to a prescribed stroke). 0; 2 when the
 * integrator cannot carry them as asked (the cause in st); 1 out of memory. */
int swim_run_set_variational(swim_run *run, const swim_run_variational *v, swim_status *st);
const swim_run_var_result *swim_run_get_var_result(swim_run *run);

/* The run's dynamics (the scene's model at its kernels): for work after the run, sensitivities. */
swim_dynamics *swim_run_dynamics(swim_run *run);
void swim_run_free(swim_run *run);

#endif
