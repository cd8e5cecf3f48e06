/* swim.h -- libswim, the simulator of an elastic swimmer in a 2D perfect fluid as a C library.
 *
 * The model is Munnier's (a deformable body of N modes c = (c_1, c_-1, ..., c_-N) in a perfect
 * fluid); a scene is the TOML file `swim run` reads (models/README.md has its keys). The library
 * is the run driver of `swim run` (docs/run-driver.md): the same rows, the same summary, bit for
 * bit, without a process per run.
 *
 * Manner of GSL and CVODE: the caller owns its arrays; objects are created, used and freed
 * through functions of one pattern (swim_model_*, swim_sim_*); every function that can fail
 * returns a status (SWIM_OK = 0) and, given a swim_error, fills it (file, line and key of a bad
 * scene value, and one line of text). The library never exits and never prints; it keeps no
 * global state and installs no signal handler, so two simulations may run on two threads at
 * once. Kernels are generated and cached on first use of a structure as for `swim run` (the
 * kernel cache, docs/kernels-and-cache.md); two threads that need the same new kernel build it
 * once (one builds, the other waits on the cache entry's lock), and a kernel that cannot be had
 * is SWIM_EKERNEL with the cause in the error, nothing on stdout or stderr.
 *
 * Arguments are checked before anything is done (docs/trust.md): a NULL where an object, an
 * out-pointer or an array is needed, a NULL entry of a list, a count outside its bounds or a
 * number outside its bounds (the library's rows of scene/keys.c) is SWIM_EINPUT with err->key
 * naming the argument ("out", "model", "sim", "sets[1]", "nevents", "t", ...). The functions
 * without an error argument say so by their value (below).
 *
 * The structs the caller allocates (swim_error, swim_sim_options, swim_result, swim_inspection)
 * start with `size_t size`, which the caller sets to sizeof the struct it has (the SWIM_*_INIT
 * initialisers do): the library reads and fills only what that size holds, so a program built
 * against an older, smaller struct is never written past when fields are added at the end. A
 * size below the struct's first layout is SWIM_EINPUT naming the struct (a swim_error that small
 * is left untouched: the status alone says it).
 *
 *   swim_model *m;  swim_sim *s;
 *   swim_error e = SWIM_ERROR_INIT;  swim_result r = SWIM_RESULT_INIT;
 *   if (swim_model_from_file("models/example3.toml", NULL, 0, &m, &e)) { puts(e.message); ... }
 *   swim_sim_options o = SWIM_SIM_OPTIONS_INIT;   // rows to a callback, events, a stop flag
 *   swim_sim_create(m, &o, &s, &e);
 *   swim_sim_advance(s, 5.0, &e);              // rows up to t = 5, then on to t_end:
 *   swim_sim_run(s, &e);
 *   swim_sim_result(s, &r);                    // r.x, r.y, r.theta at r.t_reached
 *   swim_sim_free(s);  swim_model_free(m);
 */
#ifndef SWIM_H
#define SWIM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define SWIM_API __attribute__((visibility("default")))
#else
#define SWIM_API
#endif

/* The version of this header: VERSION's numbers (swim_version() gives the library's, which a
 * program may compare with these; a test checks that they agree). */
#define SWIM_VERSION_MAJOR 0
#define SWIM_VERSION_MINOR 3
#define SWIM_VERSION_PATCH 0
/* The ABI: the SONAME is libswim.so.SWIM_ABI. Raised when a function changes or a struct's first
 * layout does; growing a struct at its end (its size field says how much the caller has) and
 * adding functions keep it. */
#define SWIM_ABI 1

/* Initialisers of the caller's structs: the size set, everything else zero. */
#if defined(__cplusplus)
#define SWIM_SIZED_INIT_(type) { sizeof(type) }
#else
#define SWIM_SIZED_INIT_(type) { .size = sizeof(type) }
#endif
#define SWIM_ERROR_INIT SWIM_SIZED_INIT_(swim_error)
#define SWIM_SIM_OPTIONS_INIT SWIM_SIZED_INIT_(swim_sim_options)
#define SWIM_RESULT_INIT SWIM_SIZED_INIT_(swim_result)
#define SWIM_INSPECTION_INIT SWIM_SIZED_INIT_(swim_inspection)

enum {
    SWIM_OK = 0,
    SWIM_EFAILED = 1,       /* the run failed or stopped early (its reason in the error) */
    SWIM_EINPUT = 2,        /* bad input: a scene, an override, an event, an option */
    SWIM_ENOMEM = 3,
    SWIM_EKERNEL = 4        /* no kernel could be had for the scene (generation or compilation failed) */
};

/* What went wrong. file/line/key are set for a scene value ("" and 0 otherwise). */
typedef struct {
    size_t size;            /* sizeof(swim_error), set by the caller (SWIM_ERROR_INIT) */
    int status;
    char file[1024];
    int line;
    char key[128];
    char message[2048];     /* one line, without "swim: " */
} swim_error;

/* "MAJOR.MINOR.PATCH", the version of the library (VERSION). */
SWIM_API const char *swim_version(void);
/* The name of a status and what it means, "SWIM_EINPUT: bad input ..." (a status or its negative,
 * as swim_model_columns returns; "unknown status" for any other number). A static string. */
SWIM_API const char *swim_strerror(int status);
/* sizeof the library's struct of that name ("swim_error", "swim_sim_options", "swim_result",
 * "swim_inspection", "swim_event", "swim_lyapunov_result", "swim_orbit_options",
 * "swim_periodic_result", "swim_floquet_result", "swim_branch_result", "swim_member"), 0 for another
 * name or NULL: for bindings that mirror the structs (Python
 * checks its mirrors against these at import). */
SWIM_API size_t swim_struct_size(const char *name);

/* ---- a model: a scene read and validated, with its kernels -------------------------------- */

typedef struct swim_model swim_model;

/* The scene file at path, or the TOML text (named `name` in errors), with the overrides
 * sets[0..nsets) ("KEY=VALUE", the --set grammar: "run.t_end=5", "model.rho0=2",
 * "elastic.stiffness.am1=3", "run.integrator=cvode-bdf") applied before it is validated. */
SWIM_API int swim_model_from_file(const char *path, const char *const *sets, int nsets, swim_model **out,
                                  swim_error *err);
SWIM_API int swim_model_from_text(const char *toml, const char *name, const char *const *sets, int nsets,
                                  swim_model **out, swim_error *err);
/* The columns of the rows (trajectory.csv's names), *names valid while the model lives; their
 * count, or -SWIM_EINPUT when m or names is NULL. */
SWIM_API int swim_model_columns(const swim_model *m, const char *const **names);
/* The scene as it will run (the overrides written into its text), a string owned by the model
 * (NULL for a NULL model). */
SWIM_API const char *swim_model_scene_text(const swim_model *m);
/* Sets one run-time key, "KEY" to "VALUE" as `--set KEY=VALUE` would (model.rho0, model.rhof,
 * parameters.NAME, elastic.stiffness[I] or .NAME, elastic.reference, damping.diagonal,
 * barrier.alpha, shape.c0 / shape.dc0 items, run.t_end, run.rtol, run.integrator, ...), in
 * place: the scene file is not read again and the kernels stay (a simulation created afterwards
 * equals one of a model opened with that override, bit for bit). A key that changes the kernel's
 * structure (model.modes, shape.free, forcing.law, stroke.*, or a value that changes the
 * structure key the kernel cache uses: a zero of elastic.stiffness made nonzero or back, ...) is
 * SWIM_EINPUT naming it, and so is a value --set refuses; the model is then as before. Simulations already created keep the values they were created with. Not while another
 * thread uses the model (creating a simulation of it); the string of swim_model_scene_text is
 * replaced. */
SWIM_API int swim_model_set(swim_model *model, const char *key, const char *value, swim_error *err);
SWIM_API void swim_model_free(swim_model *m);

/* ---- a simulation of a model --------------------------------------------------------------- */

typedef struct swim_sim swim_sim;

/* A row: its time t, and values[0 .. ncol), the ncol columns named by swim_model_columns (the
 * header of trajectory.csv, whose first column is t again: values[0] == t). Return 0 to go on,
 * nonzero to stop the run (it then fails with "stopped by the caller"). */
typedef int (*swim_row_fn)(void *ctx, double t, const double *values, int ncol);

/* An event as it is located (swim_sim_options.on_event): filled by the library, its size that of
 * the library's struct (a caller built against a smaller one reads only its own fields). The
 * strings and the state are valid during the call only. */
typedef struct {
    size_t size;                      /* sizeof(swim_event) as the library has it */
    double t;                         /* where it is (located on the integrator's interpolant) */
    const char *column;               /* trajectory.csv's name of the column, "am1" */
    const char *kind;                 /* "zero", "min" or "max" */
    double value;                     /* the column's value there */
    const double *state;              /* the state there: nstate values in the layout of swim_sim_state, the
                                         interpolant's (a row there is it projected onto the
                                         constraints, as every row: equal to rounding) */
    int nstate;
} swim_event;

/* Return 0 to go on, nonzero to stop the run at this event: its row (at the event's time) is the
 * last, and the run fails with "stopped by the caller at event COLUMN:KIND at t = T". An event
 * in a step the stiff fallback takes back (summary's switch) may be told twice. */
typedef int (*swim_event_fn)(void *ctx, const swim_event *event);

typedef struct {
    size_t size;                      /* sizeof(swim_sim_options), set by the caller (SWIM_SIM_OPTIONS_INIT) */
    swim_row_fn rows;                 /* NULL: rows not delivered */
    void *rows_ctx;
    const char *const *events;        /* "COLUMN:KIND[:stop]" as `swim run --event`, besides the scene's */
    int nevents;
    volatile int *stop;               /* a flag, not a signal number: set to any nonzero value (from
                                         another thread or a signal handler) to stop the run at its
                                         next step; it then fails with "stopped by the caller at
                                         t = T", keeping the rows so far. NULL: never stopped. */
    /* added after the first layout (a caller with a smaller size gets their defaults): */
    swim_event_fn on_event;           /* every event of the run (the scene's and `events`); NULL: none */
    void *event_ctx;
    const char *sensitivity;          /* "KEY[,KEY...]" as `swim run --sensitivity` (model.rho0,
                                         parameters.NAME, c0.NAME, initial, ...): the forward
                                         sensitivities, computed once the run completes, as
                                         sensitivity.csv (swim_sim_sensitivity); a key that is not
                                         one is SWIM_EINPUT at swim_sim_create. NULL: none */
    double lyapunov;                  /* > 0: the largest Lyapunov exponent and the predictability
                                         horizon, renormalized at this interval, once the run
                                         completes (swim_sim_lyapunov), as `swim run --lyapunov` */
} swim_sim_options;

SWIM_API int swim_sim_create(const swim_model *m, const swim_sim_options *o, swim_sim **out, swim_error *err);
/* Rows up to time t, going on from where the last call stopped; the same rows, bit for bit, as
 * one swim_sim_run. SWIM_OK while the run goes on or when it completed; SWIM_EFAILED with the
 * reason when it failed or stopped early. A prescribed stroke runs to its end at the first call.
 * t must be a finite number >= 0 and not before the t of an earlier call (NaN, an infinity or a
 * step back is SWIM_EINPUT, key "t", nothing run); beyond t_end the run stops at t_end. */
SWIM_API int swim_sim_advance(swim_sim *s, double t, swim_error *err);
/* To t_end (or a :stop event). */
SWIM_API int swim_sim_run(swim_sim *s, swim_error *err);

typedef struct {
    size_t size;                      /* sizeof(swim_result), set by the caller (SWIM_RESULT_INIT) */
    int finished;                     /* the run has ended */
    int completed;                    /* ... and reached t_end or a :stop event */
    double t_reached;
    long rows;
    double x, y, theta;               /* the body's position at t_reached */
    double energy_initial, energy_drift_abs, energy_drift_rel, jmin;
    long steps, rhs_evaluations;
} swim_result;

/* SWIM_OK, or SWIM_EINPUT when s or r is NULL or r->size is below the first swim_result's. */
SWIM_API int swim_sim_result(const swim_sim *s, swim_result *r);
/* The state at t_reached in the layout of trajectory.csv's columns 1 .. 3 + 2n (x, y, theta,
 * c, cdot): at most len doubles into y; how many there are (-SWIM_EINPUT for a NULL s, len < 0,
 * or y NULL with len > 0). */
SWIM_API int swim_sim_state(const swim_sim *s, double *y, int len);
/* The state at time t inside the integrator's last accepted step (dense output: the interpolant
 * the rows come from, so a row's time gives that row's state bit for bit), in the layout of
 * swim_sim_state: at most len doubles into y; how many there are, or a negative status:
 * -SWIM_EINPUT with err->key "t" when t is outside the last step (err->message gives the step) or
 * for a NULL s or y, -SWIM_EFAILED when there is no step to interpolate (nothing run yet, a
 * prescribed stroke, an integrator without dense output: rk8pd, msadams, rkf45, msbdf). */
SWIM_API int swim_sim_state_at(swim_sim *s, double t, double *y, int len, swim_error *err);
/* The sensitivities the options asked for, once the run completed: the columns of
 * sensitivity.csv (*names, *ncol of them, "t", "dx/dmodel.rho0", ...) and *nrows rows of them,
 * row-major, in *values (pointers valid while the simulation lives); the same numbers as
 * `swim run --sensitivity` writes. SWIM_OK; SWIM_EINPUT for a NULL argument or when no
 * sensitivity was asked for; SWIM_EFAILED when they were not computed (the run did not complete,
 * it took impacts, or the integration failed: the summary says why; rows computed so far are
 * given). */
SWIM_API int swim_sim_sensitivity(const swim_sim *s, const char *const **names, int *ncol, const double **values,
                                  long *nrows);

/* The Lyapunov pass (swim_sim_options.lyapunov), the numbers of summary.json's "lyapunov". */
typedef struct {
    size_t size;                      /* sizeof(swim_lyapunov_result), set by the caller (SWIM_LYAPUNOV_RESULT_INIT) */
    int computed;                     /* 1: the pass ran to its end; 0: skipped or failed (reason) */
    double exponent;                  /* the largest exponent over [0, t_end] */
    double exponent_second_half;
    const char *verdict;              /* "converged", "regular" or "not_converged" */
    double horizon;                   /* where a run at rtol departs from the exact trajectory, INFINITY: not within */
    double horizon_from_exponent;
    double interval, t_end, rtol;
    int segments;                     /* renormalizations: t[i] and log_growth[i], i < segments */
    const double *t, *log_growth;     /* valid while the simulation lives */
    const char *reason;               /* why not computed, "" when it was */
} swim_lyapunov_result;
#define SWIM_LYAPUNOV_RESULT_INIT SWIM_SIZED_INIT_(swim_lyapunov_result)

/* SWIM_OK once the run ended with the pass asked for (out->computed says whether it was done);
 * SWIM_EINPUT for a NULL argument, a size below the struct's first layout, or no pass asked for. */
SWIM_API int swim_sim_lyapunov(const swim_sim *s, swim_lyapunov_result *out);
/* summary.json of the run as text, malloc'd: free it with swim_free (NULL for a NULL s). Its
 * "status" is "completed" or "failed" once the run ended, "in progress" after a swim_sim_advance
 * that stopped before t_end, "not started" before any. */
SWIM_API char *swim_sim_summary_json(const swim_sim *s);
/* events.csv of the run as text (header only without events), malloc'd; swim_free (NULL for a
 * NULL s). */
SWIM_API char *swim_sim_events_csv(const swim_sim *s);
SWIM_API void swim_sim_free(swim_sim *s);
/* Column i of a family's table after id, the varied keys, status and reason (members.csv of
 * `swim sweep`, family.h5): its name, and in *summary_path (may be NULL) where a member's
 * summary.json holds its value (keys joined by dots, e.g. "final_state.x"). NULL past the last
 * column. The strings are the library's. */
SWIM_API const char *swim_family_column(int i, const char **summary_path);

/* ---- a member of a family in one call -------------------------------------------------------- */

/* members.csv's numbers of a run (swim sweep's columns after the id and the varied keys), read
 * from the run's summary.json as swim sweep reads its members' summaries. */
typedef struct {
    size_t size;                      /* sizeof(swim_member), set by the caller (SWIM_MEMBER_INIT) */
    int completed;                    /* the run reached t_end or a :stop event */
    char status[32];                  /* summary.json's status: "completed", "failed" */
    char reason[1024];                /* its reason ("" when absent; cut at a character boundary) */
    double t_reached, x, y, theta;    /* NaN where the summary has none (null) */
    double energy_drift_rel, energy_balance_abs, jmin;
    long long steps, rhs_evaluations; /* -1 where the summary has none */
    double integrate_seconds, wall_seconds;
} swim_member;
#define SWIM_MEMBER_INIT SWIM_SIZED_INIT_(swim_member)

/* One member of a family, in one call: the run-time keys sets[0..nsets) ("KEY=VALUE") set in m
 * in place, in order, as swim_model_set sets them; a simulation of m with the extra events (as
 * swim_sim_options.events), run to its end without rows; its members.csv numbers into *out. The
 * same run, bit for bit, as swim_model_set for each key, then swim_sim_create and swim_sim_run
 * (what a binding would do in several calls, here without returning to the caller in between:
 * Python's swim.sweep runs its members on threads with one call each). SWIM_OK when the run was
 * made, completed or failed (out->completed, out->status and out->reason say which); a key
 * refused is SWIM_EINPUT naming it (the keys before it stay set); a bad event SWIM_EINPUT. */
SWIM_API int swim_model_run_member(swim_model *m, const char *const *sets, int nsets, const char *const *events,
                                   int nevents, swim_member *out, swim_error *err);

/* ---- periodic orbits, Floquet multipliers, continuation (`swim periodic`, `floquet`, `continue`) --
 *
 * The analyses of docs/control.md on a model (its scene with its overrides, docs/control.md has
 * the methods), computed as the commands compute them: the same numbers as periodic.json,
 * floquet.json and branch.csv / branch.json, nothing printed and no file written. A result is an
 * object whose arrays the result structs point into (valid while it lives); the JSON (and CSV)
 * the command would write come from swim_orbit_json / swim_orbit_csv. A scene the command refuses
 * (a prescribed stroke, [forcing] for periodic orbits, an integrator without events, a section that
 * is not a moving coordinate, ...) is SWIM_EINPUT with the command's message; no period found or
 * an integration that fails before any result is SWIM_EFAILED. An orbit that does not converge, a
 * branch that ends early or a run stopped by the flag is SWIM_OK with the result saying so (the
 * command writes its file and exits 1). Not while another thread sets a key of the model. */

typedef struct {
    size_t size;                      /* sizeof(swim_orbit_options), set by the caller (SWIM_ORBIT_OPTIONS_INIT) */
    const char *section;              /* "COLUMN:KIND[:COUNT]": the guess's section (periodic, continuation: the
                                         commands' --guess-event) or the period's (floquet: --event); NULL: the
                                         first moving coordinate's max */
    double tol;                       /* Newton's tolerance, in (0, 1); 0: 1e-11 (--tol) */
    int max_iter;                     /* Newton iterations 1..40; 0: 20 (swim periodic --max-iter) */
    double t_max;                     /* how long to look for the section's events; 0: run.t_end (--t-max;
                                         continuation: always run.t_end, as swim continue) */
    volatile int *stop;               /* a flag: nonzero stops the work, keeping what it has (stopped says so) */
    /* continuation only (swim continue --param PARAM=START:END --max-points POINTS) */
    const char *param;                /* "energy" or a run-time key ("model.rho0", "elastic.stiffness[4]") */
    double start, end;                /* finite, start != end */
    int points;                       /* 2..1000; 0: 11 */
} swim_orbit_options;
#define SWIM_ORBIT_OPTIONS_INIT SWIM_SIZED_INIT_(swim_orbit_options)

typedef struct swim_orbit swim_orbit;

/* A periodic orbit by Newton shooting (swim periodic). */
SWIM_API int swim_periodic_orbit(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err);
/* The monodromy matrix and multipliers of the orbit through the scene's initial state over the
 * time between two events of the section (swim floquet). */
SWIM_API int swim_floquet_multipliers(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err);
/* A branch of periodic orbits in o->param from o->start to o->end (swim continue). */
SWIM_API int swim_continuation(const swim_model *m, const swim_orbit_options *o, swim_orbit **out, swim_error *err);

/* periodic.json's numbers (swim_periodic_orbit). */
typedef struct {
    size_t size;                      /* sizeof(swim_periodic_result), set by the caller (SWIM_PERIODIC_RESULT_INIT) */
    int converged;
    int stopped;                      /* the stop flag's value when it stopped the work, else 0 */
    const char *reason;               /* why not converged ("" when converged) */
    int iterations;                   /* Newton iterations */
    double period, residual, state_scale;
    double dx, dy, dtheta;            /* per period, in the body frame at the phase point */
    double energy, energy_target;     /* energy_target: the energy held (NaN: none) */
    double t_guess, period_guess;     /* the guess: its first event and period */
    int n;                            /* entries of the shape state (carried coordinates, then their velocities) */
    const char *const *names;         /* their names, phase_point's keys ("am1", ..., "dam1", ...) */
    const double *phase_point;        /* n */
    int have_floquet;                 /* the multipliers below were computed (converged orbits) */
    const double *monodromy;          /* n x n, row-major (NULL without Floquet data) */
    int tangent_dimension;            /* multipliers on the constraint manifold ... */
    const double *multipliers_re, *multipliers_im;   /* ... floquet.multipliers_tangent */
    int stable;
    long rhs_evaluations;
    double seconds;
} swim_periodic_result;
#define SWIM_PERIODIC_RESULT_INIT SWIM_SIZED_INIT_(swim_periodic_result)

/* floquet.json's numbers (swim_floquet_multipliers). */
typedef struct {
    size_t size;                      /* sizeof(swim_floquet_result), set by the caller (SWIM_FLOQUET_RESULT_INIT) */
    int stopped;                      /* the stop flag's value when it stopped the work (then only the period
                                         may be known), else 0 */
    double period, t_first;           /* T and the time of the first event */
    double closure, closure_relative;
    int periodic;                     /* the orbit closes (closure_relative <= 1e-6) */
    int stable;                       /* periodic and every multiplier on the complement |lambda| = 1 to 1e-3 */
    int n;                            /* entries of the shape state: M is n x n */
    const double *monodromy;          /* n x n, row-major */
    const double *multipliers_re, *multipliers_im;   /* n: of M (multipliers_full) */
    int tangent_dimension;
    const double *tangent_re, *tangent_im;           /* multipliers_tangent */
    int complement_dimension;
    const double *complement_re, *complement_im;     /* checks.multipliers_complement */
    long rhs_evaluations;
    double seconds;
} swim_floquet_result;
#define SWIM_FLOQUET_RESULT_INIT SWIM_SIZED_INIT_(swim_floquet_result)

/* branch.csv's table and branch.json's summary (swim_continuation). */
typedef struct {
    size_t size;                      /* sizeof(swim_branch_result), set by the caller (SWIM_BRANCH_RESULT_INIT) */
    int stopped;                      /* the stop flag's value when it stopped the branch, else 0 */
    int points;                       /* rows of the table, sorted by the parameter */
    int columns;                      /* branch.csv's columns ... */
    const char *const *names;         /* ... and their names (the header) */
    const double *table;              /* points x columns, row-major: branch.csv's numbers ("stable" 1 or 0) */
    double start_parameter;           /* the scene's own orbit's parameter */
    const char *ended;                /* why the branch ended early ("" when it reached both ends) */
    int special_points;               /* where the count of multipliers outside the unit circle changes: */
    const double *special_lo, *special_hi;           /* between these parameters */
    const char *const *special_kind;  /* "period doubling", "Neimark-Sacker", ... */
    long rhs_evaluations;
    double seconds;
} swim_branch_result;
#define SWIM_BRANCH_RESULT_INIT SWIM_SIZED_INIT_(swim_branch_result)

/* The result as far as out->size holds: SWIM_OK, or SWIM_EINPUT for a NULL argument, a size
 * below the struct's first layout or a result of another analysis. */
SWIM_API int swim_orbit_periodic(const swim_orbit *a, swim_periodic_result *out);
SWIM_API int swim_orbit_floquet(const swim_orbit *a, swim_floquet_result *out);
SWIM_API int swim_orbit_branch(const swim_orbit *a, swim_branch_result *out);
/* periodic.json, floquet.json, branch.json or optimize.json as the command writes it; branch.csv
 * or optimize.csv (NULL for the others). Malloc'd text: free it with swim_free (NULL for a NULL a). */
SWIM_API char *swim_orbit_json(const swim_orbit *a);
SWIM_API char *swim_orbit_csv(const swim_orbit *a);
SWIM_API void swim_orbit_free(swim_orbit *a);

/* ---- the best values of run-time keys (`swim optimize`) --------------------------------------
 *
 * The search of docs/control.md on a model (its scene with its overrides, and none of them also
 * varied), as swim optimize searches: the same evaluations, the same optimize.json (from
 * swim_orbit_json; "best_scene" is null: no file is written) and optimize.csv (swim_orbit_csv:
 * the log of iterations), nothing printed. Input the command refuses (a --vary spec, a quantity,
 * a method without gradients, a bound the scene refuses, ...) is SWIM_EINPUT with its message and
 * err->key the option or the varied key; no evaluation that succeeded is SWIM_EFAILED. A search
 * that does not converge or is stopped by the flag is SWIM_OK with the result saying so (the
 * command writes its files and exits 1). Each evaluation reads the model's text again with its
 * values, as the command does (a value may change the kernel's structure). Not while another
 * thread sets a key of the model. */
typedef struct {
    size_t size;                      /* sizeof(swim_optimize_options), set by the caller (SWIM_OPTIMIZE_OPTIONS_INIT) */
    const char *const *vary;          /* "KEY=LO:HI", as --vary (1 to 8 of them) */
    int nvary;
    const char *quantity;             /* x, y, theta, displacement, work, forcing_work, displacement_per_work, energy */
    int maximize;                     /* nonzero: --maximize, else --minimize */
    const char *method;               /* "nelder-mead" (NULL) or "bfgs" */
    int starts;                       /* 1..64; 0: 1 */
    int max_iter;                     /* per start, 1..100000; 0: 60 */
    double tol;                       /* 0: 1e-3 */
    volatile int *stop;               /* a flag: nonzero ends the search with what it has (interrupted) */
} swim_optimize_options;
#define SWIM_OPTIMIZE_OPTIONS_INIT SWIM_SIZED_INIT_(swim_optimize_options)

/* optimize.json's numbers (swim_optimize). */
typedef struct {
    size_t size;                      /* sizeof(swim_optimize_result), set by the caller (SWIM_OPTIMIZE_RESULT_INIT) */
    int converged;                    /* the search converged and its value holds at the tight tolerances */
    int search_converged, interrupted;
    int nkeys;                        /* the varied keys ... */
    const char *const *keys;          /* ... as given */
    const double *best;               /* nkeys: their best values */
    double value;                     /* the quantity there */
    double x, y, theta, work, forcing_work, energy;   /* the best run's final values ("final") */
    int tight_status;                 /* 0: the best point ran again at rtol/100, atol/100 */
    double tight_value, tight_change, value_tolerance;
    int holds;                        /* |tight_change| <= value_tolerance */
    int iterations;                   /* of the best start */
    long evaluations, gradient_evaluations, failed_evaluations;
    int starts, best_start;           /* best_start: 1-based, as optimize.json */
    double seconds;
} swim_optimize_result;
#define SWIM_OPTIMIZE_RESULT_INIT SWIM_SIZED_INIT_(swim_optimize_result)

SWIM_API int swim_optimize(const swim_model *m, const swim_optimize_options *o, swim_orbit **out, swim_error *err);
/* The result as far as out->size holds (as swim_orbit_periodic). */
SWIM_API int swim_orbit_optimize(const swim_orbit *a, swim_optimize_result *out);

/* ---- the model's matrices at one shape (`swim inspect`) ----------------------------------- */

/* For N modes, n = 2(N + 1) shape coordinates (a_1, b_1, a_-1, b_-1, ..., a_-N, b_-N). The
 * arrays are the caller's, row-major; a NULL pointer skips that output. */
typedef struct {
    size_t size;              /* sizeof(swim_inspection), set by the caller (SWIM_INSPECTION_INIT) */
    double jmin;              /* out: min J on the unit circle, > 0 inside the admissible set (4.1) */
    double *mass_rigid;       /* 3 x 3: Mr (section 3.2) */
    double *mass_coupling;    /* 3 x n: N */
    double *mass_shape;       /* n x n: Md */
    double *mass_reduced;     /* n x n: K = Md - N^T Mr^-1 N */
    double *christoffel_vv;   /* n: Gamma(c)(v, v) (section 4.1.4); needs a velocity */
    double *christoffel;      /* n x n x n: Gamma^i_jk at [(i n + j) n + k] */
} swim_inspection;

/* The matrices of `modes` modes at `shape` (n doubles), velocity v (n doubles, or NULL), with
 * densities rho0 (body) and rhof (fluid). SWIM_EINPUT (err->key names the argument: "out",
 * "modes", "shape", "velocity", "rho0", "rhof") for a NULL out or shape, a value that is not
 * finite, a shape outside D, a density outside (0, 1e150) or values whose matrices overflow;
 * SWIM_EKERNEL when no kernel of that size can be had. */
SWIM_API int swim_inspect(int modes, const double *shape, const double *velocity, double rho0, double rhof,
                          swim_inspection *out, swim_error *err);

SWIM_API void swim_free(void *p);

#ifdef __cplusplus
}
#endif

#endif
