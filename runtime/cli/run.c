/* swim run: one scene end to end -- trajectory.csv, summary.json and a copy of the scene
 * (scene.toml, so that DIR is self-contained: `swim flow` and `swim plot` need nothing else) in
 * DIR; events.csv with --event or an [events] list; snapshots.json only with --snapshots
 * (otherwise `swim flow DIR` computes them when needed); with --summary-only (a sweep member)
 * neither trajectory.csv nor snapshots.json.
 *
 * The command reads as its four stages: options (scene + command line, validated together),
 * outputs (folder, files, checks that no output overwrites another or the scene), the
 * integration loop, and the report (outputs closed and checked, summary written, lines printed).
 * Everything the stages own lives in one run_ctx, released by one function.
 *
 * Rows fall exactly on t0 + k*output_step and on t_end, produced by the integrator's own
 * interpolant. Every accepted step is checked too (cli/run_watch.h): min J with its time, the
 * energy balance and the residuals of the summary are taken over steps and rows. A shape that
 * leaves D (4.1) ends the run at the crossing, whose row is the last (the trial states beyond it
 * are refused by the right-hand side, model/dynamics.h). When ABM's stiffness diagnostic fires,
 * the run goes on from the last row with the scene's stiff_fallback (cvode-bdf unless "none").
 * A run that stops early (NaN, step-size underflow, the shape leaving D, SIGINT,
 * SIGTERM, SIGHUP, an output that cannot be written) keeps every row it wrote (each row is
 * flushed) and says in summary.json where and why it stopped; a run ended by a :stop event
 * has its last row at the event and is completed. summary.json, snapshots.json, events.csv and
 * scene.toml are written whole, atomically (swim_replace_file): a reader never sees a part. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/run_events.h"
#include "cli/run_outputs.h"
#include "cli/run_settings.h"
#include "cli/run_signals.h"
#include "cli/run_watch.h"
#include "io/csv.h"
#include "io/files.h"
#include "io/json.h"
#include "io/message.h"
#include "io/stdout_check.h"
#include "model/bounce.h"
#include "model/dynamics.h"
#include "model/flow.h"
#include "codegen/codegen.h"
#include "control/sensitivity.h"
#include "ode/ode.h"
#include "scene/scene.h"

#define SNAPSHOTS 10
#define NCOLS_MAX (8 + 4 * SWIM_NMAX + 64)
#define MAX_SETS 64   /* --set options */

/* The signal that asked the run to stop (SIGINT, SIGTERM or SIGHUP: a terminal, a batch
 * scheduler, a closed session), 0 while none did. The RHS polls it, so a long step stops too. */
/* What the command line asked for besides the scene's own settings. */
typedef struct {
    const char *scene_file, *out, *trace;
    int quiet, generic;
    int snapshots;      /* --snapshots: write snapshots.json */
    int summary_only;   /* --summary-only: rows computed (the summary needs them), not written */
    char *sensitivity;         /* --sensitivity KEY[,KEY...] (repeatable, joined): DIR/sensitivity.csv */
    int sens_state_steps;      /* --sensitivity-steps state: no error test on the sensitivities */
    swim_override sets[MAX_SETS];   /* --set KEY=VALUE, applied before the scene is validated */
    int nsets;
} run_options;

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
    double output_seconds;      /* formatting and writing rows and snapshots */
    char used[80];        /* integrator(s) used: two names of at most 31 characters */
    int event_stop;       /* a :stop event ended the run (status completed, reason says which) */
    int left_stop;        /* the row just reached is where the shape left D: the last one */
} run_report;

/* --trace-steps FILE: one row per ABM step attempt, with the energy of each accepted state. */
typedef struct {
    swim_csv csv;
    swim_dynamics *d;
    double *full;     /* full state for the diagnostics */
    int open;         /* csv is open */
    int err;          /* errno of the first write error, 0 while none */
} step_trace;

/* The row of trajectory.csv at an integrator state (event functions evaluate columns). */
typedef struct {
    const swim_scene *s;
    swim_dynamics *d;
    double *full;
} row_ctx;

typedef struct {
    swim_scene s;
    run_options opt;
    swim_run_events *events;    /* --event and [events] list, NULL without any */
    /* outputs */
    swim_run_paths paths;        /* the output folder and its files */
    swim_csv csv;
    FILE *snap;                 /* snapshots, in memory until the end (open_memstream); NULL
                                   without --snapshots */
    char *snap_buf;
    size_t snap_len;
    int nsnap;
    step_trace trace;
    char *output_error;         /* the first output that could not be written, and why */
    int outputs_bad;            /* an output failed (also when output_error could not be made) */
    /* integration */
    swim_dynamics d;
    int d_ready;
    swim_compiled kn, spz;      /* the kernel of N modes and the scene's right-hand side */
    swim_ode *ode;
    swim_ode_system sys;
    swim_ode_options o;
    swim_ode_stats total;
    int sdim, ncol;
    double *y, *row, *ys, *ys_last, *ys_row;
    double *y_inside;           /* full state of the last row with min J > 0 (NULL: none yet) ... */
    double kinetic_inside;      /* ... its kinetic energy, for the barrier's reach when D is left */
    int have_inside;
    const char *names[NCOLS_MAX];
    char storage[2 * SWIM_NMAX][24];
    row_ctx rowc;
    double bal_scale;           /* energy scale of abm's balance test: max(|E0|, max |E| so far) */
    double *tol_scale;          /* abm's per-component tolerance factors near the barrier (or NULL) */
    /* shifted coordinates near the barrier (model/dynamics.h, swim_dynamics_set_origin), abm only */
    int shift_ok;               /* the integrator in use may shift */
    int shift_pending;          /* the integrator stopped at shift_t to move the origin (1), drop it (2)
                                   or take an impact (3) */
    double shift_t;             /* in the integrator's time (absolute: d.t_origin + shift_t) */
    double left_native;         /* the watch's crossing, in the integrator's time */
    double row_jmin;            /* min J of the row's exact state with an origin (else NAN) */
    double *ys_shift;           /* the accepted state at shift_t, in the integrator's coordinates */
    double *atolv;              /* abm's absolute tolerances with an origin: atol + rtol |origin_i| */
    long shifts;                /* restarts for the origin */
    long steps_since_shift;     /* accepted steps since the last one */
    /* bounces too deep to follow, taken as impacts (model/bounce.h, impact_wanted) */
    double impact_dv[SWIM_NMAX];   /* the pending impact's change of cdot (full shape layout) */
    double impact_j, impact_reach; /* its min J and predicted turning depth, over |c_1|^2 */
    long impacts;
    const char *sens_status;   /* summary.json "sensitivity": written, failed, interrupted or skipped */
    double sens_t;             /* the time sensitivity.csv was meant to reach: where the trajectory ended */
    long sens_rows;            /* rows sensitivity.csv holds, the last at sens_t_last (NAN: none) */
    double sens_t_last;
    double impact_first_t, impact_last_t, impact_j_max, impact_reach_min;
    swim_run_watch watch;       /* checks at every accepted step (integrators with dense output) */
    int watch_ready;
    run_report r;
    double t_start;
} run_ctx;

static const char *const trace_columns[] = {"t", "h", "order", "accepted", "err", "erk", "growth", "energy", "work"};

/* The integrator's time, absolute (it runs at t - d.t_origin near the barrier, see accept_step). */
static double ode_time(const run_ctx *c) { return c->d.t_origin + swim_ode_time(c->ode); }

/* ---- the error test near the barrier -------------------------------------------------------- */

/* Near the boundary of D the barrier energy W2 ~ kappa ln(1/min J) (alpha = 1/2; steeper for
 * larger alpha) turns an error dx of the shape into an energy error ~ kappa |grad J|_1 |dx| / min J:
 * with the usual weights rtol |x_i| + atol, a bounce to min J = 1e-8 at rtol 1e-8 loses 1e-5 of the
 * energy (measured on soft_n15_a05). So after every accepted step the tolerance of each carried
 * shape coordinate is cut to rtol min J / |grad J|_1 (J then moves by at most rtol of itself),
 * when that is smaller and min J < 1e-3 |c_1|^2. Farther from the boundary the factors stay 1 and
 * the run is unchanged: cutting them there too (from min J < 0.1 |c_1|^2 on) made the drift of
 * the soft scenes 3-7x larger, not smaller (abm's step control reacts to the changing weights). The
 * floor 40 u / rtol keeps abm's round-off test (2u max|y/w| < 1/2) satisfied ten times over. */
static double barrier_tolerance(run_ctx *c, const double *y, double h)
{
    const swim_scene *s = &c->s;
    const swim_scene_kernel *k = c->d.spec;
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    swim_dynamics_unpack(&c->d, y, full);
    const double *x = full + 3;
    double theta, j0;
    if (c->watch_ready && c->watch.end_y == y) {   /* the watch has just computed it at this step end */
        j0 = c->watch.end_j;
        theta = c->watch.end_theta;
    } else {
        j0 = swim_dynamics_jmin(&c->d, y, &theta);
    }
    const double c1 = x[0] * x[0] + x[1] * x[1];
    double scale[SWIM_NMAX];
    for (int i = 0; i < k->nfree; i++) scale[i] = 1.0;
    if (j0 > 0 && j0 < 1e-3 * c1) {
        double e[SWIM_NMAX] = {0.0}, g1 = 0.0, umax = 0.0, vmax = 0.0;
        for (int i = 0; i < k->nfree; i++) {
            e[k->free_index[i]] = 1.0;
            g1 += fabs(swim_shape_j_rate(s->modes, x, e, theta));
            e[k->free_index[i]] = 0.0;
            umax = fmax(umax, fabs(y[3 + i]));
            vmax = fmax(vmax, fabs(x[s->n + k->free_index[i]]));
        }
        const double want = s->rtol * j0 / g1, floor_s = 40.0 * 1.11e-16 / s->rtol;
        for (int i = 0; i < k->nfree; i++) {
            const double allowed = s->rtol * fabs(x[k->free_index[i]]) + s->atol;
            /* with an origin abm rounds u, not the shape: the floor follows the largest |u| (and
             * what one more step can add to it) instead of the shape itself */
            const double floor_i = c->d.origin ? 40.0 * 1.11e-16 * (umax + h * vmax) / allowed : floor_s;
            scale[i] = fmin(1.0, fmax(floor_i, want / allowed));
        }
    }
    for (int i = 0; i < k->nfree; i++) c->tol_scale[3 + i] = scale[i];
    return j0 / c1;
}

/* ---- the energy balance in the error test ------------------------------------------------ */

/* abm keeps each component's local error within rtol of it, yet lets the balance E - E0 - work
 * drift by a systematic amount per step: for the oscillations of a conservative scene Adams
 * methods are slightly dissipative, and the drift adds up over the steps (measured on a soft
 * alpha = 1/2 scene at rtol 1e-8: ~1e-12 of E per step at every step size, 1.1e-7 over 67 000
 * steps; rtol 1e-9 only halved it). So the balance's share of the error estimate is tested too,
 * against ENERGY_CONTROL rtol of the energy scale (swim_ode_options.invariant). Chosen on
 * perturbed families at rtol 1e-8 (tests/bench/bench_soft_family.py, rebuilt with other values):
 * 16 copies of soft_n10_a05 kept balance median / max 1.2e-8 / 2.5e-8 at 1e-2, 3.7e-9 / 6.1e-9
 * at 3e-3 and 1.4e-9 / 3.0e-9 at 1e-3 (3.6e-8 / 1.1e-7 without), for 14, 17 and 27 % more steps;
 * 4 copies of soft_n20_a05: 2.5e-8 / 4.6e-8, 1.3e-8 / 1.4e-8, 4.9e-9 / 6.4e-9 (1.1e-7 / 1.6e-7
 * without). 1e-1 changed nothing. */
#define ENERGY_CONTROL 3e-3

static double scaled_balance(double t, const double *u, double *noise, void *data)
{
    run_ctx *c = data;
    if (!(c->bal_scale > 0)) {   /* before E0 is known, or E0 = 0 and no energy yet */
        *noise = 0.0;
        return 0.0;
    }
    const double B = swim_dynamics_balance(t, u, noise, &c->d);
    *noise /= c->bal_scale;
    return B / c->bal_scale;
}

/* Where abm carries the state relative to an origin (model/dynamics.h): from min J below
 * SHIFT_IN |c_1|^2 at a step end until it is back above SHIFT_OUT |c_1|^2, with a new origin
 * when the state has moved too far from it for the depth (shift_wanted). The
 * rounding of the shape costs ~kappa 1e-16 |grad J| / min J of the energy per step, a random walk
 * over the 10^4-10^5 steps a soft scene spends near the wall: on 8 perturbed soft_n10_a05 runs
 * at rtol 1e-8 (tests/bench/bench_soft_family.py, rebuilt with other values here) the largest
 * balance was 3.8e-7 with SHIFT_IN = 1e-6 and 1.1e-7 with 1e-3, for ~10 % more steps; 1e-2 was
 * no better and took 50 % more steps. The gap
 * between the two levels keeps an approach that hovers from restarting abm at every step. */
#define SHIFT_IN 1e-3
#define SHIFT_OUT 1e-2
#define SHIFT_DEEP 1e-12
#define SHIFT_EVERY 64
#define SHIFT_URGENT 1e-6

/* A step in the integrator's time seen in absolute time (the watch keeps absolute times): an
 * absolute t maps back to the step, its ends exactly (in a deep bounce t0 + ta and t0 + tb can be
 * one double). */
typedef struct {
    const swim_ode_accepted *st;
    double t0, ta, tb;
} absolute_step;

static int absolute_interp(void *ctx, double t, double *y, double *yp)
{
    const absolute_step *a = ctx;
    const double tau = t == a->tb ? a->st->tb : t == a->ta ? a->st->ta : fmin(fmax(t - a->t0, a->st->ta), a->st->tb);
    return a->st->interp(a->st->ctx, tau, y, yp);
}

/* Where the next origin goes (0: stay, 1: move it to the step end, 2: drop it), from min J /
 * |c_1|^2 = j at the step end and the state u there. */
static int shift_wanted(const run_ctx *c, double j, const double *u)
{
    /* a restart costs abm a new start (order 1, a few rejected steps): above SHIFT_URGENT, where
     * the rounding of the shape costs little per step, not more often than every SHIFT_EVERY
     * steps (a forced shape vibrating near the wall would otherwise restart it every few steps) */
    if (c->steps_since_shift < SHIFT_EVERY && j > SHIFT_URGENT) return 0;
    if (!c->d.origin) return j < SHIFT_IN;
    if (j > SHIFT_OUT) return 2;
    /* u rounds by ~u|u|, which costs ~kappa u |u| / (min J) of the energy per step; without an
     * origin at SHIFT_OUT that is kappa u / SHIFT_OUT: keep |u| below j / SHIFT_OUT for the same
     * cost at depth j (as a bounce deepens, this moves the origin each time min J falls ~100x) */
    double umax = 0.0;
    for (int i = 0; i < c->d.spec->nfree; i++) umax = fmax(umax, fabs(u[3 + i]));
    return umax > j / SHIFT_OUT;
}

/* ---- bounces too deep to follow ---------------------------------------------------------- */

/* With alpha = 1/2 an approach carrying the normal kinetic energy T turns at min J ~ j0 e^(-T/kappa)
 * (shape/barrier.h, swim_barrier_reach), far below what double precision resolves under strong
 * forcing (1e-25 ... 1e-110 in models/hard/large_forcing.toml), in a time of the same order. Such a
 * bounce is an impact (model/bounce.h). It is taken once min J, falling, is below IMPACT_AT rtol
 * |c_1|^2, when the turning point is predicted below impact_depth |c_1|^2 (by default the
 * resolution of J in double precision) and below IMPACT_DEEPER times the depth reached (then the speed
 * toward the wall hardly changes before the last e-folds, as the impulsive limit assumes). The
 * rest of the bounce lasts ~2 min J / |d min J/dt|; what the impact neglects over that time is
 * O(min J) of the state (measured: ~6 min J, tests/test_impact.py), a few hundredths of rtol. */
#define IMPACT_AT 0.01
#define IMPACT_DEEPER 1e-3

/* The impact at full state y (model/bounce.h), along the barrier's gradient there, computed on
 * the diagnostics' quadrature (its warm start is not the right-hand side's). 0 or -1. */
static int bounce_at(run_ctx *c, const double *y, swim_bounce *b)
{
    const swim_scene *s = &c->s;
    double grad[SWIM_NMAX], W;
    if (!c->d.diag_barrier ||
        swim_barrier_w2(c->d.diag_barrier, y + 3, s->epsilon, s->alpha, &W, grad, NULL) != SWIM_BARRIER_OK)
        return -1;
    return swim_bounce_along(&c->d, y, grad, b);
}

/* Whether the step end y, at min J / |c_1|^2 = j, is where a bounce becomes an impact; then its
 * change of cdot is left in c->impact_dv. */
static int impact_wanted(run_ctx *c, const double *y, double j)
{
    const swim_scene *s = &c->s;
    if (!(s->impact_depth > 0) || !(j < IMPACT_AT * s->rtol) || !c->d.diag_barrier) return 0;
    double full[4 + 4 * (SWIM_KERNEL_MAX_MODES + 1)];
    swim_dynamics_unpack(&c->d, y, full);
    const double j0 = c->watch_ready && c->watch.end_y == y ? c->watch.end_j   /* just computed at this step end */
                                                             : swim_dynamics_jmin(&c->d, y, NULL);
    swim_bounce b;
    if (!(j0 > 0) || bounce_at(c, full, &b) != 0 || !(b.rate > 0)) return 0;
    const double reach = swim_barrier_reach(c->d.diag_barrier, full + 3, s->epsilon, s->alpha, b.normal_kinetic, NULL);
    const double c1 = full[3] * full[3] + full[4] * full[4];
    if (!(reach > 0) || !(reach < s->impact_depth * c1) || !(reach < IMPACT_DEEPER * j0)) return 0;
    memcpy(c->impact_dv, b.dv, sizeof(double) * (size_t)s->n);
    c->impact_j = j0 / c1;
    c->impact_reach = reach / c1;
    return 1;
}

/* Ends the integration at the step's end, keeping its state, for a restart of kind `pending`
 * (shift_pending: 1, 2 an origin, 3 an impact) that advance_to carries out. Returns 1. */
static int stop_for(run_ctx *c, const swim_ode_accepted *step, int pending, double *t_stop)
{
    c->shift_pending = pending;
    c->shift_t = step->tb;
    *t_stop = step->tb;
    memcpy(c->ys_shift, step->y_end, sizeof(double) * (size_t)c->sdim);
    return 1;
}

static int accept_step(const swim_ode_accepted *step, void *data, double *t_stop)
{
    run_ctx *c = data;
    int rc;
    const double t0 = c->d.t_origin;
    if (t0 == 0.0) {
        rc = swim_run_watch_step(step, &c->watch, t_stop);
        if (rc) c->left_native = *t_stop;
    } else {
        absolute_step a = {step, t0, t0 + step->ta, t0 + step->tb};
        const swim_ode_accepted abs_step = {a.ta, a.tb, absolute_interp, &a, step->y_end};
        double t_abs;
        rc = swim_run_watch_step(&abs_step, &c->watch, &t_abs);
        if (rc) {
            *t_stop = t_abs == a.tb ? step->tb : fmin(fmax(t_abs - t0, step->ta), step->tb);
            if (!(*t_stop > step->ta)) *t_stop = step->tb;
            c->left_native = *t_stop;
        }
    }
    if (c->watch.pend.balanced) c->bal_scale = fmax(c->bal_scale, fabs(c->watch.pend.e));
    if (!c->tol_scale || !step->y_end) return rc;
    const double j = barrier_tolerance(c, step->y_end, step->tb - step->ta);
    c->steps_since_shift++;
    if (!rc && impact_wanted(c, step->y_end, j)) return stop_for(c, step, 3, t_stop);
    if (rc || !c->shift_ok) return rc;
    const int want = shift_wanted(c, j, step->y_end);
    return want ? stop_for(c, step, want, t_stop) : 0;
}

/* ---- options ------------------------------------------------------------------------------ */

static int columns(const swim_scene *s, const char **names, char storage[][24])
{
    static const char *const tail[] = {
        "kinetic_fluid", "kinetic_shape", "kinetic_rigid", "potential", "energy",
        "impulse_body_x", "impulse_body_y", "impulse_body_ang",
        "impulse_fluid_rigid_x", "impulse_fluid_rigid_y", "impulse_fluid_rigid_ang",
        "impulse_fluid_shape_x", "impulse_fluid_shape_y", "impulse_fluid_shape_ang",
        "res_volume", "res_volume_rate", "res_angular", "res_locks", "jmin", "work", "w1", "w2"};
    int c = swim_run_state_columns(s->n, names, storage);
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) names[c++] = tail[i];
    return c;
}

/* --set KEY=VALUE (repeatable), taken out of argv: overrides applied to the scene before it is
 * validated. How many, or -1 after one line on stderr. */
static int take_set_options(int *argc, char **argv, swim_override *sets)
{
    const char *vals[MAX_SETS];
    int n = swim_args_take_all("run", argc, argv, 2, "set", vals, MAX_SETS);
    if (n < 0) return -1;
    for (int i = 0; i < n; i++) {
        char err[256];
        if (swim_override_parse(vals[i], &sets[i], err, sizeof err) != 0) {
            swim_message(stderr, "swim run: --set: %s", err);
            return -1;
        }
    }
    return n;
}

/* --sensitivity KEYS (repeatable: each adds its keys), taken out of argv and joined with commas
 * into *out (NULL when absent). 0, or 2 after one line on stderr. */
static int take_sensitivity_options(int *argc, char **argv, char **out)
{
    const char *vals[MAX_SETS];
    int n = swim_args_take_all("run", argc, argv, 2, "sensitivity", vals, MAX_SETS);
    if (n < 0) return 2;
    *out = NULL;
    for (int i = 0; i < n; i++) {
        if (vals[i][0] == '\0') {
            swim_message(stderr, "swim run: --sensitivity: empty list of keys");
            return 2;
        }
        char *joined = *out ? swim_strprintf("%s,%s", *out, vals[i]) : strdup(vals[i]);
        free(*out);
        if (!(*out = joined)) {
            swim_message(stderr, "swim run: out of memory");
            return 1;
        }
    }
    return 0;
}

/* Parse argv, load the scene, apply the command line over it and validate the result: the run
 * settings pass the same checks (swim_run_settings_check) whether they came from the scene or
 * from here; the events (scene and --event) are checked against the columns and the integrator.
 * 0, 2 after one line on stderr, or 1 (out of memory). */
static int read_options(int argc, char **argv, run_ctx *c)
{
    swim_opt opts[] = {{"out", 1, NULL},  {"t-end", 1, NULL},      {"rtol", 1, NULL},
                       {"output-step", 1, NULL},
                       {"atol", 1, NULL}, {"integrator", 1, NULL}, {"quiet", 0, NULL},
                       {"generic", 0, NULL}, {"no-projection", 0, NULL}, {"step-lookahead", 1, NULL},
                       {"trace-steps", 1, NULL}, {"event", 2, NULL}, {"snapshots", 0, NULL},
                       {"summary-only", 0, NULL}, {"sensitivity-steps", 1, NULL}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    if ((c->opt.nsets = take_set_options(&argc, argv, c->opt.sets)) < 0) return 2;
    int trc = take_sensitivity_options(&argc, argv, &c->opt.sensitivity);
    if (trc) return trc;
    if (swim_args_parse("run", argc, argv, 2, opts, nopts, pos, 1, &npos)) return 2;
    if (npos != 1) {
        swim_message(stderr, "swim run: expected one scene file, e.g. swim run models/example3.toml");
        return 2;
    }
    swim_scene *s = &c->s;
    c->opt.scene_file = pos[0];
    if (swim_scene_load_with(pos[0], c->opt.sets, c->opt.nsets, s)) return 2;
    if (swim_run_settings_options(opts, nopts, s) != 0) return 2;
    c->opt.quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    c->opt.generic = swim_args_get(opts, nopts, "generic") != NULL;
    if (swim_args_get(opts, nopts, "no-projection")) s->projection = 0;
    c->opt.out = swim_args_get(opts, nopts, "out");
    c->opt.trace = swim_args_get(opts, nopts, "trace-steps");
    c->opt.summary_only = swim_args_get(opts, nopts, "summary-only") != NULL;
    const char *v = swim_args_get(opts, nopts, "sensitivity-steps");
    if (v) {
        if (strcmp(v, "all") != 0 && strcmp(v, "state") != 0) {
            swim_message(stderr, "swim run: --sensitivity-steps: expected all or state, got '%s'", v);
            return 2;
        }
        c->opt.sens_state_steps = strcmp(v, "state") == 0;
    }
    c->opt.snapshots = swim_args_get(opts, nopts, "snapshots") != NULL && !c->opt.summary_only;
    if (c->opt.trace && !(swim_ode_capabilities(s->integrator) & SWIM_ODE_CAP_STEP_TRACE)) {
        swim_message(stderr, "swim run: --trace-steps: integrator '%s' does not report its steps", s->integrator);
        return 2;
    }
    /* events name columns of trajectory.csv: checked against them, before any output */
    c->ncol = columns(s, c->names, c->storage);
    return swim_run_events_parse(s, argc, argv, c->names, c->ncol, &c->events);
}

/* ---- outputs ------------------------------------------------------------------------------ */

/* 1 when a and b name the same file: the same canonical path, or (both existing) the same
 * inode -- a second spelling, a symbolic link or a hard link of one file. */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char *ca = swim_canonical_path(a), *cb = swim_canonical_path(b);
    int same = ca && cb && strcmp(ca, cb) == 0;
    free(ca);
    free(cb);
    return same;
}

/* --trace-steps must not name one of the run's own outputs or the scene: it would interleave
 * two files, or truncate the scene. 0, or 2 after one line on stderr. */
static int check_trace_path(const run_ctx *c)
{
    const char *const others[] = {c->paths.csv_path, c->paths.snap_path, c->paths.summary_path, c->paths.scene_copy_path,
                                  c->paths.events_path, c->opt.scene_file};
    const size_t nown = sizeof others / sizeof others[0] - 1;
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++)
        if (same_file(c->opt.trace, others[i])) {
            swim_message(stderr, "swim run: --trace-steps: '%s' is %s %s; choose another file", c->opt.trace,
                         i < nown ? "the run's own" : "the scene file", others[i]);
            return 2;
        }
    return 0;
}

/* 1 when a file can be created at `path` (its folder exists and may be written), else 0 with
 * errno set. */
static int folder_writable(const char *path)
{
    char *copy = strdup(path);
    if (!copy) return 1;   /* out of memory: open_outputs will say so */
    char *slash = strrchr(copy, '/');
    const char *dir = slash == copy ? "/" : slash ? copy : ".";
    if (slash && slash != copy) *slash = '\0';
    int ok = access(dir, W_OK | X_OK) == 0, saved = errno;
    free(copy);
    errno = saved;
    return ok;
}

/* 1 when the folder `dir` exists and may be written, or can be created below the nearest folder
 * above it that exists and may be written; else 0 with errno set. */
static int folder_creatable(const char *dir)
{
    char *p = strdup(dir);
    if (!p) return 1;
    for (;;) {
        struct stat st;
        if (stat(p, &st) == 0) {
            int ok = S_ISDIR(st.st_mode) ? access(p, W_OK | X_OK) == 0 : (errno = ENOTDIR, 0);
            int saved = errno;
            free(p);
            errno = saved;
            return ok;
        }
        char *slash = strrchr(p, '/');
        if (!slash) {
            free(p);
            return access(".", W_OK | X_OK) == 0;
        }
        if (slash == p) slash[1] = '\0';
        else *slash = '\0';
    }
}

/* The outputs' folders, checked before the kernels are obtained (generating one can take a
 * minute): an output that cannot be created is bad input, refused with one line before any
 * work. open_outputs checks again as it creates them. 0 or 2. */
static int preflight_outputs(const run_ctx *c)
{
    if (c->opt.trace && !folder_writable(c->opt.trace)) {
        swim_message(stderr, "swim run: --trace-steps: cannot write '%s': %s", c->opt.trace, strerror(errno));
        return 2;
    }
    char *def = c->opt.out ? NULL : swim_run_default_out(c->s.path);
    const char *out = c->opt.out ? c->opt.out : def;
    int rc = 0;
    if (out && !folder_creatable(out)) {
        swim_message(stderr, "swim run: --out: cannot create directory '%s': %s", out, strerror(errno));
        rc = 2;
    }
    free(def);
    return rc;
}

/* Record the first output error ("cannot write PATH: why"); later ones are consequences. */
static void output_failed(run_ctx *c, const char *path, int err)
{
    c->outputs_bad = 1;
    if (!c->output_error)   /* NULL when out of memory: outputs_bad still fails the run */
        c->output_error = swim_strprintf("cannot write %s: %s", path, strerror(err ? err : EIO));
}

/* Create DIR, copy the scene into it, open trajectory.csv (not with --summary-only), the trace
 * and the in-memory snapshots (--snapshots); remove a summary, snapshots, events and rows left
 * by an earlier run in DIR that this run does not replace at once (they would describe another
 * run). 0, 1 (out of memory) or 2 (an output cannot be created; one line on stderr). */
static int open_outputs(run_ctx *c)
{
    const int prc = swim_run_paths_open(&c->paths, c->opt.out, c->s.path);
    if (prc == 1) goto oom;
    if (prc != 0) return prc;
    /* (DIR/scene.toml may be the scene itself: the copy is then a no-op) */
    const char *const written[] = {c->paths.csv_path, c->paths.snap_path, c->paths.summary_path, c->paths.events_path};
    for (size_t i = 0; i < sizeof written / sizeof written[0]; i++) {
        const char *p = written[i];
        if (same_file(p, c->opt.scene_file)) {
            swim_message(stderr, "swim run: --out: %s would overwrite the scene file %s", p, c->opt.scene_file);
            return 2;
        }
    }
    if (c->opt.trace) {
        if (check_trace_path(c)) return 2;
        if (swim_csv_open(&c->trace.csv, c->opt.trace, trace_columns, 9) != 0) {
            swim_message(stderr, "swim run: --trace-steps: cannot write '%s': %s", c->opt.trace, strerror(errno));
            return 2;
        }
        c->trace.open = 1;
    }
    if (swim_copy_file(c->opt.scene_file, c->paths.scene_copy_path) != 0) {
        swim_message(stderr, "swim run: --out: cannot write '%s': %s", c->paths.scene_copy_path, strerror(errno));
        return 2;
    }
    if (!c->opt.summary_only && swim_csv_open(&c->csv, c->paths.csv_path, c->names, c->ncol) != 0) {
        swim_message(stderr, "swim run: --out: cannot write '%s': %s", c->paths.csv_path, strerror(errno));
        return 2;
    }
    const char *const stale[] = {c->paths.summary_path, c->paths.snap_path, c->paths.events_path,
                                 c->opt.summary_only ? c->paths.csv_path : NULL};
    for (size_t i = 0; i < sizeof stale / sizeof stale[0]; i++) {
        if (!stale[i]) continue;
        if (unlink(stale[i]) != 0 && errno != ENOENT) {
            swim_message(stderr, "swim run: --out: cannot remove the old '%s': %s", stale[i], strerror(errno));
            return 2;
        }
    }
    if (c->opt.snapshots) {
        c->snap = open_memstream(&c->snap_buf, &c->snap_len);
        if (!c->snap) goto oom;
        fputs("[\n", c->snap);
    }
    return 0;
oom:
    swim_message(stderr, "swim run: out of memory");
    return 1;
}

/* ---- integration -------------------------------------------------------------------------- */

static void trace_step(const swim_ode_step *st, void *data)
{
    step_trace *tr = data;
    if (tr->err)
        return;
    double v[9] = {tr->d->t_origin + st->t, st->h, st->order, st->accepted, st->err, st->erk, st->growth, NAN, NAN};
    swim_diag g;
    if (st->y) {
        swim_dynamics_unpack(tr->d, st->y, tr->full);
        if (swim_dynamics_diagnostics(tr->d, tr->full, &g) == 0) {
            v[7] = g.energy;
            v[8] = g.work;
        }
    }
    if (swim_csv_row(&tr->csv, v) != 0)
        tr->err = errno ? errno : EIO;
}

static int packed_row(void *p, double t, const double *ys, int all, double *row);

/* The kernel of N modes (diagnostics) and the scene's right-hand side: linked in, cached, or
 * generated and compiled now (runtime/codegen); `--generic` is the generated generic structure,
 * there is no second implementation to fall back on. Then the magnitude check of the initial
 * state, which needs the kernel. Before any output is touched: 0; 1 when no kernel could be
 * had, 2 for a scene whose numbers overflow (one line on stderr each). */
static int acquire_kernels(run_ctx *c)
{
    const swim_scene *s = &c->s;
    /* progress of a generation only: a scene refused below or an output refused next gets its
     * one line alone (where a cached kernel came from is said by prepare) */
    const int verbose = c->opt.quiet ? 0 : 1;
    if (swim_codegen_kernel(s->modes, &c->kn, verbose) != 0 ||
        swim_codegen_scene(s, c->opt.generic, &c->spz, verbose) != 0) {
        swim_message(stderr, "swim run: %s: no kernel for this scene, nothing computed", s->path);
        return 1;
    }
    return swim_scene_check_model(s, c->kn.kernel);
}

/* Dynamics on the kernels of acquire_kernels, state buffers and integrator options
 * (with the events attached).
 * 0, or 1 after one line on stderr (out of memory). */
static int prepare(run_ctx *c)
{
    swim_scene *s = &c->s;
    if (swim_dynamics_init(&c->d, s, c->kn.kernel) != 0) goto oom;
    c->d_ready = 1;
    c->d.interrupt = (volatile int *)&swim_run_stop;
    swim_dynamics_use_scene_kernel(&c->d, c->spz.scene, c->opt.generic);
    if (!c->opt.quiet && c->spz.from_cache)
        swim_message(stderr, "swim: scene kernel from cache %s", c->spz.dir);
    c->sdim = swim_dynamics_state_dim(&c->d);
    c->y = calloc((size_t)c->d.dim, sizeof(double));
    c->row = calloc((size_t)c->ncol, sizeof(double));
    c->ys = calloc((size_t)c->sdim, sizeof(double));
    c->ys_last = calloc((size_t)c->sdim, sizeof(double));
    c->ys_row = calloc((size_t)c->sdim, sizeof(double));
    c->y_inside = calloc((size_t)c->d.dim, sizeof(double));
    if (!c->y || !c->row || !c->ys || !c->ys_last || !c->ys_row || !c->y_inside) goto oom;
    swim_dynamics_initial_state(&c->d, c->y);
    swim_dynamics_pack(&c->d, c->y, c->ys);
    memcpy(c->ys_last, c->ys, sizeof(double) * c->sdim);
    c->sys = (swim_ode_system){swim_dynamics_rhs, (size_t)c->sdim, &c->d, NULL};
    if (s->jacobian_exact && c->spz.scene->jacobian)   /* [run] jacobian: BDF methods use it */
        c->sys.jacobian = swim_dynamics_jacobian;
    swim_ode_options *o = &c->o;
    swim_ode_options_default(o);
    o->rtol = s->rtol;
    o->atol = s->atol;
    swim_dynamics_track_balance(&c->d, 1);   /* the step checks and the balance test read it */
    /* by default where the scene has a barrier: its long stays near the wall (10^4-10^5 steps) are
     * where the drift adds up; a smooth paper scene at rtol 1e-8 keeps ~1e-10 without it, and would
     * pay 30-40 % more steps for 1e-12 (any scene can ask for it) */
    if (s->energy_control < 0) s->energy_control = s->barrier;
    if (s->energy_control && strcmp(s->integrator, "abm") == 0) {
        o->invariant = scaled_balance;
        o->invariant_data = c;
        o->invariant_tol = ENERGY_CONTROL * s->rtol;   /* abm never asks for less than B's rounding */
    }
    if (s->step_lookahead >= 0) o->lookahead = s->step_lookahead;
    s->step_lookahead = o->lookahead;   /* the summary records the value used */
    const unsigned caps = swim_ode_capabilities(s->integrator);
    o->stiff_stop = (caps & SWIM_ODE_CAP_STIFFNESS) != 0;   /* stop and report (or switch) on stiffness */
    if (s->projection && (caps & SWIM_ODE_CAP_PROJECTION)) o->project = swim_dynamics_project;  /* drift control */
    if (c->trace.open) {
        c->trace.d = &c->d;
        c->trace.full = calloc((size_t)c->d.dim, sizeof(double));
        if (!c->trace.full) goto oom;
        o->on_step = trace_step;
        o->on_step_data = &c->trace;
    }
    if (c->events) {
        c->rowc = (row_ctx){s, &c->d, calloc((size_t)c->d.dim, sizeof(double))};
        if (!c->rowc.full ||
            swim_run_events_attach(c->events, o, (size_t)c->sdim, 3 + 2 * s->n, packed_row, &c->rowc) != 0)
            goto oom;
    }
    if (caps & SWIM_ODE_CAP_EVENTS) {   /* dense output: the watch sees every accepted step */
        if (swim_run_watch_init(&c->watch, &c->d, c->sdim, 1) != 0) goto oom;
        c->watch_ready = 1;
        o->on_accept = accept_step;
        o->on_accept_data = c;
        if (s->barrier && strcmp(s->integrator, "abm") == 0) {
            c->tol_scale = malloc(sizeof(double) * (size_t)c->sdim);
            if (!c->tol_scale) goto oom;
            for (int i = 0; i < c->sdim; i++) c->tol_scale[i] = 1.0;
            barrier_tolerance(c, c->ys, 0.0);
            o->tol_scale = c->tol_scale;
            c->ys_shift = malloc(sizeof(double) * (size_t)c->sdim);
            c->atolv = malloc(sizeof(double) * (size_t)c->sdim);
            if (!c->ys_shift || !c->atolv) goto oom;
            c->shift_ok = s->origin_shift;
        }
    }
    c->r.switch_t = -1.0;
    c->r.left_t = NAN;
    c->r.jmin_t = NAN;
    c->row_jmin = NAN;
    snprintf(c->r.used, sizeof c->r.used, "%s", s->integrator);
    return 0;
oom:
    swim_message(stderr, "swim run: out of memory");
    return 1;
}

static int row_values(const swim_scene *s, double t, const double *y, const swim_diag *g, double *v)
{
    int c = 0;
    v[c++] = t;
    for (int i = 0; i < 3 + 2 * s->n; i++) v[c++] = y[i];
    const double tail[] = {
        g->kinetic_fluid, g->kinetic_shape, g->kinetic_rigid, g->w1 + g->w2, g->energy,
        g->impulse_body[0], g->impulse_body[1], g->impulse_body[2],
        g->impulse_fluid_rigid[0], g->impulse_fluid_rigid[1], g->impulse_fluid_rigid[2],
        g->impulse_fluid_shape[0], g->impulse_fluid_shape[1], g->impulse_fluid_shape[2],
        g->res_volume, g->res_volume_rate, g->res_angular, g->res_locks, g->jmin, g->work, g->w1, g->w2};
    for (size_t i = 0; i < sizeof tail / sizeof tail[0]; i++) v[c++] = tail[i];
    return c;
}

static void track(run_report *r, double t, const swim_diag *g, int first)
{
    if (first) { r->e0 = g->energy; r->jmin = INFINITY; }
    r->t_reached = t;
    r->drift_abs = fmax(r->drift_abs, fabs(g->energy - r->e0 - g->work));
    r->emax = fmax(r->emax, fabs(g->energy));
    if (g->jmin < r->jmin || isnan(g->jmin)) {
        r->jmin = g->jmin;
        r->jmin_t = t;
    }
    r->res_volume = fmax(r->res_volume, fabs(g->res_volume));
    r->res_volume_rate = fmax(r->res_volume_rate, fabs(g->res_volume_rate));
    r->res_angular = fmax(r->res_angular, fabs(g->res_angular));
    r->res_locks = fmax(r->res_locks, g->res_locks);
}

/* The columns at integrator state ys for the event functions (swim_run_row_func): all, or t and
 * the state columns only (no diagnostics needed). */
static int packed_row(void *p, double t, const double *ys, int all, double *row)
{
    row_ctx *rc = p;
    swim_diag g;
    swim_dynamics_unpack(rc->d, ys, rc->full);
    if (!all) {
        row[0] = t;
        memcpy(row + 1, rc->full, sizeof(double) * (3 + 2 * rc->s->n));
        return 0;
    }
    if (swim_dynamics_diagnostics(rc->d, rc->full, &g) != 0) return -1;
    row_values(rc->s, t, rc->full, &g, row);
    return 0;
}

/* Add the counters of `ode` to `total` (a run may use two integrators). */
static void accumulate_stats(swim_ode_stats *total, const swim_ode *ode)
{
    swim_ode_stats st;
    if (swim_ode_get_stats(ode, &st) != SWIM_ODE_OK) return;
    total->steps += st.steps;
    total->rhs_evals += st.rhs_evals;
    total->rejected += st.rejected;
    total->rejected_invariant += st.rejected_invariant;
    total->jac_evals += st.jac_evals;
    for (int i = 0; i < 13; i++) total->order_hist[i] += st.order_hist[i];
    total->last_h = st.last_h;
    total->last_order = st.last_order;
    total->stiff_suspected |= st.stiff_suspected;
}

/* Why the run ended (printf-like); `failed` sets the status. */
static void end_run(run_ctx *c, int failed, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void end_run(run_ctx *c, int failed, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    free(c->r.reason);
    c->r.reason = swim_vstrprintf(fmt, ap);   /* NULL: reported as out of memory */
    va_end(ap);
    c->r.status = failed;
}
#define stop(c, ...) end_run((c), 1, __VA_ARGS__)

static void stop_by_signal(run_ctx *c, double t)
{
    int sig = swim_run_stop;
    if (sig == SIGINT) stop(c, "interrupted (SIGINT) at t = %.6g", t);
    else stop(c, "terminated by %s at t = %.6g", sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal", t);
}

/* An output failed at t: the run stops, its reason is the output error. */
static void stop_on_output(run_ctx *c, double t)
{
    stop(c, "%s (at t = %.6g)", c->output_error ? c->output_error : "an output could not be written", t);
}

/* The remedy that keeps the scene as it is, when the run did not use it. */
static const char *impact_hint(const swim_scene *s)
{
    return s->impact_depth > 0 ? "" : ", or take such bounces as impacts (run.impact_depth, default 1e-16)";
}

/* With a barrier, why it did not stop the shape: from the last row inside D, how deep into the
 * barrier the kinetic energy there could carry the shape (shape/barrier.h, swim_barrier_reach),
 * compared with the resolution of J = |c_1|^2 - |h|^2 in double precision. Empty when the reach
 * is resolvable (then the crossing is not explained by the barrier's weakness). */
static void barrier_diagnosis(run_ctx *c, char *buf, size_t len)
{
    buf[0] = '\0';
    const swim_scene *s = &c->s;
    if (!s->barrier || !c->d.barrier) return;
    /* the integrator's last accepted state when it is inside D (closest to the failure), else the
     * last row inside D */
    double *full = malloc(sizeof(double) * (size_t)c->d.dim);
    if (!full) return;
    double *ys = malloc(sizeof(double) * (size_t)c->sdim), j0 = NAN;
    int have = ys && c->ode && swim_ode_dense(c->ode, swim_ode_time(c->ode), ys, NULL) == SWIM_ODE_OK;
    if (have) {
        swim_dynamics_unpack(&c->d, ys, full);
        j0 = swim_dynamics_jmin(&c->d, ys, NULL);
    }
    free(ys);
    if (!(j0 > 0)) {
        if (!c->have_inside) {
            free(full);
            return;
        }
        memcpy(full, c->y_inside, sizeof(double) * (size_t)c->d.dim);
        j0 = swim_shape_jmin(s->modes, full + 3);
    }
    const double *x = full + 3, c1 = x[0] * x[0] + x[1] * x[1];
    swim_bounce bn;
    const double T = bounce_at(c, full, &bn) == 0 ? bn.normal_kinetic : NAN;
    double kappa = NAN;
    double reach = swim_barrier_reach(c->d.barrier, x, s->epsilon, s->alpha, T, &kappa);
    if (!(kappa > 0) && c->have_inside) {
        /* a shape deeper than its rounding (J(x) <= 0, shifted coordinates): kappa, which follows
         * J'' at the foot and barely changes with depth, from the last row inside D */
        swim_barrier_reach(c->d.barrier, c->y_inside + 3, s->epsilon, s->alpha, T, &kappa);
        if (kappa > 0 && fabs(s->alpha - 0.5) < 1e-12) reach = j0 * exp(-T / kappa);
    }
    free(full);
    /* Without shifted coordinates the shape is known to rounding, which moves J by ~4u |c_1|^2
     * (u = 2^-53) and so W2 by kappa 4u |c_1|^2 / min J: deeper than where that exceeds rtol of
     * the energy scale, a bounce cannot be followed to the tolerance. With them (abm), rounding
     * is no longer the limit; what remains is time itself: a bounce to min J turns within
     * ~min J / |dJ/dt|, and the step sizes, the forces (~kappa / min J) and their rounding follow
     * it: a failure inside a bounce deeper than SHIFT_DEEP |c_1|^2 is put down to its depth. */
    const double escale = fmax(fmax(c->r.emax, T), 1e-300);
    const double floor_j = kappa * 4.0 * 1.11e-16 * c1 / (s->rtol * escale);
    if (!(kappa > 0) || !(c->shift_ok ? j0 < SHIFT_DEEP * c1 : reach < floor_j)) return;
    if (reach > 0 && c->shift_ok)
        snprintf(buf, len, "; at min J = %.3g the barrier (alpha = %g, epsilon = %g) rises by only %.3g per e-fold "
                 "of min J, and absorbing the kinetic energy still moving toward the boundary (%.3g) takes min J "
                 "down to ~1e%d: abm, in coordinates shifted to the bounce, could not follow it; "
                 "use alpha >= 1, a larger epsilon or a looser rtol%s",
                 j0, s->alpha, s->epsilon, kappa, T, (int)floor(log10(reach)), impact_hint(s));
    else if (reach > 0)
        snprintf(buf, len, "; at min J = %.3g the barrier (alpha = %g, epsilon = %g) rises by only %.3g per e-fold "
                 "of min J, and absorbing the kinetic energy still moving toward the boundary (%.3g) takes min J "
                 "down to ~1e%d, where the rounding of the shape (~1e-16 in J = |c1|^2 - |h|^2) moves W2 by "
                 "more than rtol of the energy (min J < %.1e): double precision cannot follow this bounce "
                 "without run.origin_shift; use alpha >= 1, a larger epsilon or a looser rtol%s",
                 j0, s->alpha, s->epsilon, kappa, T, (int)floor(log10(reach)), floor_j, impact_hint(s));
    else
        snprintf(buf, len, "; the barrier (alpha = %g < 1/2, epsilon = %g) is finite at the boundary of D and "
                 "cannot stop the kinetic energy moving toward it (%.3g)", s->alpha, s->epsilon, T);
}

/* The shape left D at t (4.1): the crossing of min J = 0, located at a step (see advance_to). */
static void stop_left_D(run_ctx *c, double t)
{
    char why[1024];
    barrier_diagnosis(c, why, sizeof why);
    stop(c, "left D at t = %.10g: the shape left the admissible set D (min J reaches 0 on the circle, (4.1))%s%s", t,
         c->s.barrier ? "; the barrier did not stop it" : "; the scene has no barrier", why);
}

/* Why the integrator could not reach t. */
static void stop_on_integrator(run_ctx *c, int rc, double t)
{
    const swim_scene *s = &c->s;
    if (swim_run_stop) {
        stop_by_signal(c, c->r.t_reached);
        return;
    }
    /* A forcing law that is finite at t0 (checked when the scene is read) may not stay so. */
    if (s->forced && !swim_expr_defined(s->forcing, c->d.last_rhs_t, NULL, 0)) {
        stop(c, "the forcing law is NaN or Inf at t = %.9g", fmin(c->d.last_rhs_t, s->forcing_finite_until));
        return;
    }
    if (rc == SWIM_ODE_ERHS && swim_ode_rhs_status(c->ode) == SWIM_DYN_EBARRIER)
        stop_left_D(c, c->r.left_t);
    else {
        /* near the boundary of D with a barrier too weak to be resolved, that is the cause */
        char why[1024];
        barrier_diagnosis(c, why, sizeof why);
        if (rc == SWIM_ODE_ERHS)
            stop(c, "%s near t = %.6g%s", swim_dynamics_strerror(swim_ode_rhs_status(c->ode)), c->d.last_rhs_t, why);
        else if (rc == SWIM_ODE_ESTIFF && !why[0])
            stop(c, "stiffness detected near t = %.6g: Adams PECE is "
                 "stability-limited here; rerun with --integrator cvode-bdf (or msbdf), or remove "
                 "[run] stiff_fallback = \"none\" from the scene (the default switches to cvode-bdf)",
                 c->ode ? ode_time(c) : t);
        else
            stop(c, "%s near t = %.6g%s", swim_ode_strerror(rc), c->ode ? ode_time(c) : t, why);
    }
}

/* Restart from the last output row (exact state there) with the stiff fallback integrator. */
static int switch_to_fallback(run_ctx *c, double t_last, double t)
{
    const swim_scene *s = &c->s;
    double ts = ode_time(c);
    accumulate_stats(&c->total, c->ode);
    swim_ode_free(c->ode);
    c->ode = NULL;
    /* said even with --quiet: the rest of the run is computed by another method than asked for */
    swim_message(stderr, "swim run: stiffness detected near t = %.6g; switching from %s to %s at t = %.6g",
                 ts, s->integrator, s->stiff_fallback, t_last);
    c->r.switch_t = t_last;
    swim_run_events_rewind(c->events, t_last);   /* the fallback locates them again from t_last */
    if (c->watch_ready) swim_run_watch_rewind(&c->watch, t_last);
    snprintf(c->r.used, sizeof c->r.used, "%s+%s", s->integrator, s->stiff_fallback);
    memcpy(c->ys, c->ys_last, sizeof(double) * c->sdim);
    if (c->d.origin || c->d.t_origin != 0.0) {
        /* the fallback carries the absolute state, the row's (c->y, projected), in absolute time */
        swim_dynamics_set_origin(&c->d, NULL);
        swim_dynamics_pack(&c->d, c->y, c->ys);
        c->o.atol_vec = NULL;
        c->d.t_origin = 0.0;
        swim_run_events_time_origin(c->events, 0.0);
    }
    c->shift_ok = 0;
    c->shift_pending = 0;
    c->o.stiff_stop = 0;
    const unsigned caps = swim_ode_capabilities(s->stiff_fallback);
    if (!(caps & SWIM_ODE_CAP_PROJECTION)) c->o.project = NULL;
    if (!(caps & SWIM_ODE_CAP_STEP_TRACE)) c->o.on_step = NULL;
    int rc = swim_ode_create(s->stiff_fallback, &c->sys, &c->o, t_last, c->ys, &c->ode);
    return rc == SWIM_ODE_OK ? swim_ode_advance(c->ode, t, c->ys) : rc;
}

/* The integrator stopped at shift_t (accept_step): close it, keeping its statistics, and take
 * the state it accepted there. */
static void stop_at_shift(run_ctx *c)
{
    accumulate_stats(&c->total, c->ode);
    swim_ode_free(c->ode);
    c->ode = NULL;
    memcpy(c->ys, c->ys_shift, sizeof(double) * (size_t)c->sdim);
    c->shift_pending = 0;
}

/* A new integrator `method` from c->ys at its time tau0 (absolute d.t_origin + tau0), on to
 * tout. An ODE status. */
static int resume(run_ctx *c, const char *method, double tau0, double tout)
{
    barrier_tolerance(c, c->ys, 0.0);
    int rc = swim_ode_create(method, &c->sys, &c->o, tau0, c->ys, &c->ode);
    if (rc != SWIM_ODE_OK || !(tout - c->d.t_origin > tau0)) return rc;   /* at tout already: ys is its state */
    return swim_ode_advance(c->ode, tout - c->d.t_origin, c->ys);
}

/* The integrator stopped at shift_t (accept_step): start it again from the state there, relative
 * to the new origin (or to none), and go on to tout. An ODE status. */
static int shift_origin(run_ctx *c, double tout)
{
    const swim_scene *s = &c->s;
    const int clear = c->shift_pending == 2;
    stop_at_shift(c);
    if (swim_dynamics_rebase(&c->d, c->ys, clear) != 0) return SWIM_ODE_ENOMEM;
    /* the clock too: t0' + tau0 = t0 + shift_t exactly (TwoSum), the integrator starts at tau0 */
    const double a = c->d.t_origin, b = c->shift_t, t0 = a + b, bb = t0 - a;
    const double tau0 = (a - (t0 - bb)) + (b - bb);
    c->d.t_origin = t0;
    swim_run_events_time_origin(c->events, t0);
    c->shifts++;
    c->steps_since_shift = 0;
    /* abm weighs errors by rtol |y_i| + atol; with u = y - origin small that is rtol |u_i| + atol_i */
    if (c->d.origin) {
        for (int i = 0; i < c->sdim; i++) c->atolv[i] = s->atol + s->rtol * fabs(c->d.origin[i]);
        c->o.atol_vec = c->atolv;
    } else {
        c->o.atol_vec = NULL;
    }
    return resume(c, s->integrator, tau0, tout);
}

/* The integrator stopped at shift_t (accept_step) at the step end where a bounce becomes an
 * impact: start it again from the state there with the reflected cdot (model/bounce.h), at the
 * same origin and clock, and go on to tout. An ODE status. */
static int take_impact(run_ctx *c, double tout)
{
    const swim_scene *s = &c->s;
    stop_at_shift(c);
    const swim_scene_kernel *k = c->d.spec;
    for (int f = 0; f < k->nfree; f++) c->ys[3 + k->nfree + f] += c->impact_dv[k->free_index[f]];
    const double t = c->d.t_origin + c->shift_t;
    if (c->impacts++ == 0) {
        c->impact_first_t = t;
        c->impact_j_max = c->impact_j;
        c->impact_reach_min = c->impact_reach;
        /* said even with --quiet: from here on the run is the impulsive limit of the bounce */
        swim_message(stderr, "swim run: t = %.10g: a bounce off the barrier predicted to turn at min J ~ %.1e |c1|^2 "
                     "(below run.impact_depth = %g) taken as an impact at min J = %.2e |c1|^2 (docs/barrier.md); "
                     "summary.json counts them",
                     t, c->impact_reach, s->impact_depth, c->impact_j);
    }
    c->impact_last_t = t;
    c->impact_j_max = fmax(c->impact_j_max, c->impact_j);
    c->impact_reach_min = fmin(c->impact_reach_min, c->impact_reach);
    return resume(c, c->r.switch_t >= 0 ? s->stiff_fallback : s->integrator, c->shift_t, tout);
}

/* Advance to output time *t and leave the row's full state in c->y. A :stop event before *t
 * ends the run there: *t becomes the event time, whose row is the last. An ODE status. */
static int advance_to(run_ctx *c, double *t, double *t_last)
{
    double ta = swim_wall();
    int rc = swim_ode_advance(c->ode, *t - c->d.t_origin, c->ys);
    while (rc == SWIM_ODE_TERMINATED && c->shift_pending && swim_ode_time(c->ode) == c->shift_t)
        rc = c->shift_pending == 3 ? take_impact(c, *t) : shift_origin(c, *t);
    c->r.integrate_seconds += swim_wall() - ta;
    if (rc == SWIM_ODE_ESTIFF && c->s.stiff_fallback[0] && c->r.switch_t < 0 && !swim_run_stop) {
        /* An alarm raised by a bounce off the barrier that double precision cannot follow is
         * not stiffness: BDF's larger steps would only cross the unresolved wall with a wrong
         * energy. The run stops there, saying why (stop_on_integrator). */
        char why[1024];
        barrier_diagnosis(c, why, sizeof why);
        if (!why[0]) rc = switch_to_fallback(c, *t_last, *t);
    }
    if (rc == SWIM_ODE_TERMINATED && c->watch_ready && c->watch.left && swim_ode_time(c->ode) == c->left_native) {
        *t = c->watch.t_left;   /* min J reached 0 inside a step: ys holds the state at the crossing */
        c->r.left_t = *t;
        c->r.left_stop = 1;
        rc = SWIM_ODE_OK;
    } else if (rc == SWIM_ODE_TERMINATED) {   /* ys holds the state at the event */
        *t = ode_time(c);
        end_run(c, 0, "stopped by event %s at t = %.10g", swim_run_events_stop_name(c->events), *t);
        c->r.event_stop = 1;
        rc = SWIM_ODE_OK;
    } else if (rc == SWIM_ODE_ERHS && swim_ode_rhs_status(c->ode) == SWIM_DYN_EBARRIER && !swim_run_stop) {
        /* Every trial state beyond the crossing was refused, so the integrator crept up to it
         * with ever smaller steps until the step size underflowed: its last accepted state is
         * the crossing (to a few units of rounding in t). Its row is the last. */
        const double tb = ode_time(c);
        c->r.left_t = tb;
        if (tb > *t_last && tb < *t && swim_ode_dense(c->ode, swim_ode_time(c->ode), c->ys, NULL) == SWIM_ODE_OK) {
            *t = tb;
            c->r.left_stop = 1;
            rc = SWIM_ODE_OK;
        }
    }
    if (rc != SWIM_ODE_OK) return rc;
    const double tr = *t;
    /* Rows come from the interpolant, which leaves the constraint manifold by the local error
     * between two projected steps: project the row as well (a copy; the integrator's state is
     * untouched). */
    const double *row = c->ys;
    if (c->o.project && c->ode) {
        memcpy(c->ys_row, c->ys, sizeof(double) * c->sdim);
        c->o.project(tr, c->ys_row, &c->d);
        row = c->ys_row;
    }
    swim_dynamics_unpack(&c->d, row, c->y);
    c->row_jmin = c->d.origin ? swim_dynamics_jmin(&c->d, row, NULL) : NAN;
    memcpy(c->ys_last, c->ys, sizeof(double) * c->sdim);
    *t_last = tr;
    if (c->watch_ready) swim_run_watch_mark(&c->watch);   /* where a stiff fallback would restart */
    return SWIM_ODE_OK;
}

/* Diagnostics, the CSV row and maybe a snapshot at t. 0, or -1 when the run must stop. */
static int emit_row(run_ctx *c, long k, long rows, long every, double t)
{
    swim_diag g;
    const double t_diag = swim_wall();
    const int diag_rc = swim_dynamics_diagnostics(&c->d, c->y, &g);
    c->r.diagnostics_seconds += swim_wall() - t_diag;
    if (diag_rc != 0) {
        stop(c, "diagnostics failed at t = %.6g (K not positive definite)", t);
        return -1;
    }
    if (!isnan(c->row_jmin)) g.jmin = c->row_jmin;   /* the rounded row may show 0 in a deep bounce */
    track(&c->r, t, &g, k == 0);
    if (g.jmin > 0) {
        memcpy(c->y_inside, c->y, sizeof(double) * (size_t)c->d.dim);
        c->kinetic_inside = g.kinetic_fluid + g.kinetic_shape + g.kinetic_rigid;
        c->have_inside = 1;
    }
    const double t_out = swim_wall();
    int rc = 0;
    row_values(&c->s, t, c->y, &g, c->row);
    if (!c->opt.summary_only && swim_csv_row(&c->csv, c->row) != 0) {
        output_failed(c, c->paths.csv_path, errno);
        rc = -1;
    }
    if (rc == 0) c->r.rows++;   /* with --summary-only: rows computed */
    if (rc == 0 && c->snap && (k % every == 0 || k > rows || c->r.event_stop) && c->nsnap < SNAPSHOTS + 1) {
        if (c->nsnap++) fputs(",\n", c->snap);
        if (swim_flow_snapshot(&c->d, t, c->y, c->snap) != 0) {
            output_failed(c, c->paths.snap_path, ENOMEM);
            rc = -1;
        }
    }
    c->r.output_seconds += swim_wall() - t_out;
    if (rc != 0) {
        stop_on_output(c, t);
        return -1;
    }
    if (!(g.jmin > 0)) {   /* only at a crossing located by the watch, or without dense output */
        c->r.left_t = t;
        stop_left_D(c, t);
        return -1;
    }
    return 0;
}

/* The maxima and min J over the accepted steps into the report, which holds those over the rows.
 * A run that ended at its last row (t_end, a :stop event, the crossing) counts the last step up
 * to that row only; a failed one every step it accepted. */
static void take_watch(run_report *r, swim_run_watch *w)
{
    swim_run_watch_finish(w, r->status == 0 || r->left_stop ? r->t_reached : INFINITY);
    const swim_run_watch_results *s = &w->r;
    if (s->jmin < r->jmin || isnan(s->jmin)) {
        r->jmin = s->jmin;
        r->jmin_t = s->jmin_t;
    }
    r->drift_abs = fmax(r->drift_abs, s->drift_abs);
    r->emax = fmax(r->emax, s->emax);
    r->res_volume = fmax(r->res_volume, s->res_volume);
    r->res_volume_rate = fmax(r->res_volume_rate, s->res_volume_rate);
    r->res_angular = fmax(r->res_angular, s->res_angular);
    r->res_locks = fmax(r->res_locks, s->res_locks);
}

/* The output loop: rows at k*output_step up to t_end, stopping at the first failure. */
static void integrate(run_ctx *c)
{
    const swim_scene *s = &c->s;
    c->t_start = swim_wall();
    double last_progress = c->t_start, t_last = 0.0;
    int rc = swim_ode_create(s->integrator, &c->sys, &c->o, 0.0, c->ys, &c->ode);
    const long rows = (long)floor(s->t_end / s->output_step + 1e-9);
    const long every = rows / (SNAPSHOTS - 1) > 0 ? rows / (SNAPSHOTS - 1) : 1;
    if (rc != SWIM_ODE_OK)
        stop(c, "integrator '%s' could not start: %s", s->integrator, swim_ode_strerror(rc));
    for (long k = 0; rc == SWIM_ODE_OK; k++) {
        double t = k <= rows ? k * s->output_step : s->t_end;
        if (k == rows && fabs(t - s->t_end) < 1e-9 * s->output_step) t = s->t_end;
        if (k > rows && (rows * s->output_step >= s->t_end * (1 - 1e-12))) break;
        if (k > rows + 1) break;
        if (s->forced && t >= s->forcing_finite_until) {   /* found when the settings were checked */
            stop(c, "the forcing law is NaN or Inf at t = %.9g; stopped before the step to t = %.6g",
                 s->forcing_finite_until, t);
            break;
        }
        if (k > 0 && (rc = advance_to(c, &t, &t_last)) != SWIM_ODE_OK) {
            stop_on_integrator(c, rc, t);
            break;
        }
        if (emit_row(c, k, rows, every, t) != 0) break;
        if (k == 0 && c->watch_ready) c->watch.e0 = c->r.e0;
        if (k == 0) c->bal_scale = fabs(c->r.e0);
        if (c->r.left_stop) {
            stop_left_D(c, t);
            break;
        }
        if (c->trace.err) {
            output_failed(c, c->opt.trace, c->trace.err);
            stop_on_output(c, t);
            break;
        }
        if (swim_run_stop) {
            stop_by_signal(c, t);
            break;
        }
        if (c->r.event_stop) break;   /* the row at the event was the last */
        double now = swim_wall();
        if (!c->opt.quiet && now - last_progress > 1.0) {
            fprintf(stderr, "\rswim run: t = %.4g / %.4g (%.0f%%)   ", t, s->t_end, 100.0 * t / s->t_end);
            last_progress = now;
        }
    }
    if (!c->opt.quiet && last_progress > c->t_start) fputc('\n', stderr);
    if (c->r.status == 0 && !c->r.event_stop) end_run(c, 0, "reached t_end = %.6g", s->t_end);
    if (c->ode) accumulate_stats(&c->total, c->ode);
    if (c->watch_ready) take_watch(&c->r, &c->watch);
}

/* ---- report ------------------------------------------------------------------------------- */

/* The summary as JSON text on f (a memory stream). */
static void summary_json(FILE *f, const run_ctx *c, double wall_s)
{
    const swim_scene *s = &c->s;
    const run_report *r = &c->r;
    const swim_ode_stats *st = &c->total;
    const swim_dynamics *d = &c->d;
    const swim_compiled *sp = &c->spz;
    const double *y = c->y;
    char name[24];
    fprintf(f, "{\n  \"scene\": ");
    swim_json_string(f, s->path);
    fprintf(f, ",\n  \"title\": ");
    swim_json_string(f, s->title);
    fprintf(f, ",\n  \"out\": ");
    swim_json_string(f, c->paths.dir);
    fprintf(f, ",\n  \"modes\": %d,\n  \"rho0\": %.17g,\n  \"rhof\": %.17g,\n  \"integrator\": ", s->modes, s->rho0, s->rhof);
    swim_json_string(f, r->used);
    fprintf(f, ",\n  \"integrator_switch_t\": ");
    swim_json_number(f, r->switch_t >= 0 ? r->switch_t : NAN);
    fprintf(f, ",\n  \"rtol\": %.3g,\n  \"atol\": %.3g,\n  \"step_lookahead\": %d,\n  \"free\": [", s->rtol, s->atol, s->step_lookahead);
    for (int i = 0, first = 1; i < s->n; i++)
        if (s->free_mask[i]) {
            swim_coord_name(i, name, sizeof name);
            fprintf(f, "%s\"%s\"", first ? "" : ", ", name);
            first = 0;
        }
    fprintf(f, "],\n  \"effects\": {\"elastic\": %s, \"barrier\": %s, \"damping\": %s, \"forcing\": %s},\n",
            s->elastic ? "true" : "false", s->barrier ? "true" : "false", s->damped ? "true" : "false",
            s->forced ? "true" : "false");
    fprintf(f, "  \"kernel\": {\"kind\": \"%s\", \"state_dimension\": %d, \"cache\": ",
            d->generic ? "generic" : "specialized", swim_dynamics_state_dim(d));
    swim_json_string(f, sp->dir);
    fprintf(f, ", \"from_cache\": %s, \"generate_seconds\": %.3f, \"compile_seconds\": %.3f},\n",
            sp->from_cache ? "true" : "false", sp->generate_seconds, sp->compile_seconds);
    fprintf(f, "  \"projection\": {\"enabled\": %s, \"steps\": %ld, \"max_change\": %.3g},\n",
            s->projection && (swim_ode_capabilities(s->integrator) & SWIM_ODE_CAP_PROJECTION) ? "true" : "false",
            d->projections, d->max_projection);
    fprintf(f, "  \"status\": \"%s\",\n  \"reason\": ", r->status ? "failed" : "completed");
    swim_json_string(f, r->reason ? r->reason : "out of memory");
    fprintf(f, ",\n  \"t_end\": %.17g,\n  \"t_reached\": %.17g,\n  \"rows\": %ld,\n", s->t_end, r->t_reached, r->rows);
    if (c->opt.sensitivity) {
        fprintf(f, "  \"sensitivity\": {\"status\": \"%s\", \"t_end\": %.17g, \"rows\": %ld, \"t_reached\": ",
                c->sens_status ? c->sens_status : "skipped", c->sens_t, c->sens_rows);
        if (c->sens_rows > 0) swim_json_number(f, c->sens_t_last);
        else fprintf(f, "null");
        fprintf(f, ", \"file\": \"sensitivity.csv\"},\n");
    }
    fprintf(f, "  \"initial_velocity_projected\": %s,\n  \"projection_change\": %.3g,\n",
            s->projection_change > 0 ? "true" : "false", s->projection_change);
    fprintf(f, "  \"final_state\": {\"t\": %.17g, \"x\": %.17g, \"y\": %.17g, \"theta\": %.17g, \"c\": ", r->t_reached, y[0], y[1], y[2]);
    swim_json_vector(f, y + 3, s->n);
    fprintf(f, ", \"dc\": ");
    swim_json_vector(f, y + 3 + s->n, s->n);
    fprintf(f, "},\n  \"energy_initial\": ");
    swim_json_number(f, r->e0);
    fprintf(f, ",\n  \"energy_drift_abs\": ");
    swim_json_number(f, r->drift_abs);
    fprintf(f, ",\n  \"energy_drift_rel\": ");
    swim_json_number(f, r->emax > 0 ? r->drift_abs / r->emax : 0.0);
    fprintf(f, ",\n  \"max_residuals\": {\"volume\": %.3g, \"volume_rate\": %.3g, \"angular\": %.3g, \"locks\": %.3g},\n",
            r->res_volume, r->res_volume_rate, r->res_angular, r->res_locks);
    fprintf(f, "  \"jmin\": ");
    swim_json_number(f, r->jmin);
    fprintf(f, ",\n  \"jmin_t\": ");
    swim_json_number(f, r->jmin_t);
    fprintf(f, ",\n  \"left_D_t\": ");
    swim_json_number(f, r->left_t);
    fprintf(f, ",\n  \"stiff_switch\": ");
    if (r->switch_t >= 0) {
        fprintf(f, "{\"t\": %.17g, \"from\": ", r->switch_t);
        swim_json_string(f, s->integrator);
        fprintf(f, ", \"to\": ");
        swim_json_string(f, s->stiff_fallback);
        fputc('}', f);
    } else {
        fputs("null", f);
    }
    fprintf(f, ",\n  \"step_checks\": {\"enabled\": %s, \"steps\": %ld, \"seconds\": %.6f}",
            c->watch_ready ? "true" : "false", c->watch.r.steps, c->watch.seconds);
    fprintf(f, ",\n  \"origin_shift\": {\"enabled\": %s, \"restarts\": %ld}", c->shift_ok || c->shifts ? "true" : "false",
            c->shifts);
    fprintf(f, ",\n  \"impacts\": {\"enabled\": %s, \"impact_depth\": %.3g, \"count\": %ld",
            c->ys_shift && s->impact_depth > 0 ? "true" : "false", s->impact_depth, c->impacts);
    if (c->impacts)
        fprintf(f, ", \"first_t\": %.17g, \"last_t\": %.17g, \"jmin_max\": %.3g, \"turning_min\": %.3g}", c->impact_first_t,
                c->impact_last_t, c->impact_j_max, c->impact_reach_min);
    else
        fprintf(f, ", \"first_t\": null, \"last_t\": null, \"jmin_max\": null, \"turning_min\": null}");
    fprintf(f, ",\n  \"energy_control\": {\"enabled\": %s, \"tolerance\": %.3g, \"rejected_steps\": %ld}",
            c->o.invariant ? "true" : "false", c->o.invariant ? c->o.invariant_tol : 0.0, c->total.rejected_invariant);
    swim_run_events_json(c->events, f);   /* "events", "event_stop", "periodic" (with events) */
    /* which Jacobian the BDF methods used: the kernel's exact one (calls, time) or differences */
    const swim_run_timing t = {r->integrate_seconds, r->diagnostics_seconds, r->output_seconds, d->rhs_seconds, wall_s,
                               d->rhs_calls, c->sys.jacobian ? "exact" : "differences", d->jac_calls, d->jac_seconds};
    swim_run_stats_json(f, st, &t);
    fprintf(f, "\n}\n");
}

/* Close trajectory.csv and the trace (checking that they still are the files named by their
 * paths: a folder removed during the run leaves writes that succeed into nothing), then write
 * snapshots.json (--snapshots) and events.csv (with events). Any failure is an output error and
 * fails the run. */
static void close_outputs(run_ctx *c)
{
    const char *paths[2] = {c->paths.csv_path, c->opt.trace};
    swim_csv *files[2] = {&c->csv, c->trace.open ? &c->trace.csv : NULL};
    for (int i = 0; i < 2; i++) {
        if (!files[i] || !files[i]->line) continue;
        struct stat st = files[i]->st;
        errno = 0;
        if (swim_csv_close(files[i]) != 0) output_failed(c, paths[i], errno);
        else if (!swim_still_names(paths[i], &st) && !c->outputs_bad) {
            c->outputs_bad = 1;
            c->output_error = swim_strprintf("%s was removed or replaced during the run: its rows are lost", paths[i]);
        }
    }
    if (c->snap) {
        fputs("\n]\n", c->snap);
        int bad = ferror(c->snap);
        if (fclose(c->snap) != 0 || bad) output_failed(c, c->paths.snap_path, ENOMEM);
        else if (swim_replace_file(c->paths.snap_path, c->snap_buf, c->snap_len) != 0) output_failed(c, c->paths.snap_path, errno);
        c->snap = NULL;
    }
    if (c->events && swim_run_events_write_csv(c->events, c->paths.events_path) != 0)
        output_failed(c, c->paths.events_path, errno);
}

/* summary_json in the form of swim_replace_file_with */
typedef struct {
    const run_ctx *c;
    double wall_s;
} summary_job;

static void fill_summary(FILE *f, void *ctx)
{
    const summary_job *j = ctx;
    summary_json(f, j->c, j->wall_s);
}

/* Outputs closed, the summary written, the report printed. The exit status: 0 only when the
 * run reached t_end and every output was written. */
static int report(run_ctx *c)
{
    close_outputs(c);
    if (c->outputs_bad && c->r.status == 0)   /* the run completed, an output did not */
        stop(c, "%s", c->output_error ? c->output_error : "an output could not be written");
    const double wall_s = swim_wall() - c->t_start;
    summary_job job = {c, wall_s};
    if (swim_replace_file_with(c->paths.summary_path, fill_summary, &job) != 0) {
        int err = errno;
        swim_message(stderr, "swim run: cannot write %s: %s (the run %s: %s)", c->paths.summary_path, strerror(err),
                     c->r.status ? "FAILED" : "completed", c->r.reason ? c->r.reason : "out of memory");
        c->r.status = 1;
    }
    if (c->output_error && c->r.reason && !strstr(c->r.reason, c->output_error))
        swim_message(stderr, "swim run: %s", c->output_error);   /* the reason names another cause */
    const swim_scene *s = &c->s;
    const swim_ode_stats *st = &c->total;
    swim_message(stdout, c->opt.summary_only ? "%s: %s (%s); %ld rows computed, summary in %s"
                                             : "%s: %s (%s); %ld rows in %s",
                 s->path, c->r.status ? "FAILED" : "completed", c->r.reason ? c->r.reason : "out of memory",
                 c->r.rows, c->opt.summary_only ? c->paths.summary_path : c->paths.csv_path);
    printf("  %s kernel (state dimension %d)\n", c->d.generic ? "generic" : "specialized", c->sdim);
    swim_message(stdout, "  integrator %s, rtol %.3g: %ld steps, %ld RHS evaluations, %ld rejected; %.3f s (%.3f s in the RHS)",
                 c->r.used, s->rtol, st->steps, st->rhs_evals, st->rejected, swim_wall() - c->t_start, c->d.rhs_seconds);
    printf("  energy drift %.3g (E0 = %.6g), max residuals: volume %.2g, angular %.2g, locks %.2g; min J %.4g at t = %.6g\n",
           c->r.drift_abs, c->r.e0, c->r.res_volume, c->r.res_angular, c->r.res_locks, c->r.jmin, c->r.jmin_t);
    if (c->impacts)   /* min J above is over the computed steps, not the turning points of the impacts */
        printf("  %ld bounce(s) taken as impacts from t = %.6g to %.6g, turning points predicted down to min J ~ %.1e\n",
               c->impacts, c->impact_first_t, c->impact_last_t, c->impact_reach_min);
    printf("  final position x = %.6g, y = %.6g, theta = %.6g\n", c->y[0], c->y[1], c->y[2]);
    if (swim_stdout_check("run") != 0) return 1;
    return c->r.status ? 1 : 0;
}

/* The one cleanup: everything any stage may have created, whatever stage stopped. */
static void release(run_ctx *c)
{
    swim_csv_close(&c->csv);
    if (c->trace.open) swim_csv_close(&c->trace.csv);
    if (c->snap) fclose(c->snap);
    free(c->snap_buf);
    free(c->trace.full);
    free(c->rowc.full);
    swim_run_events_free(c->events);
    if (c->watch_ready) swim_run_watch_free(&c->watch);
    swim_ode_free(c->ode);
    if (c->d_ready) swim_dynamics_free(&c->d);
    swim_compiled_close(&c->spz);   /* after everything that may still point into the kernels */
    swim_compiled_close(&c->kn);
    free(c->y);
    free(c->row);
    free(c->ys);
    free(c->ys_last);
    free(c->ys_row);
    free(c->y_inside);
    free(c->tol_scale);
    free(c->ys_shift);
    free(c->atolv);
    free(c->r.reason);
    free(c->output_error);
    free(c->opt.sensitivity);
    swim_run_paths_free(&c->paths);
    swim_scene_free(&c->s);
    free(c);
}

/* --sensitivity: the keys resolved on a dynamics of their own, before any output (exit 2). */
static int check_sensitivity(run_ctx *c)
{
    swim_dynamics d;
    swim_sens S;
    if (swim_dynamics_init(&d, &c->s, c->kn.kernel) != 0) return 1;
    swim_dynamics_use_scene_kernel(&d, c->spz.scene, c->opt.generic);
    int rc = swim_sens_init(&S, &d) != 0 ? 1 : swim_sens_add_list(&S, &c->s, "run", c->opt.sensitivity);
    swim_sens_free(&S);
    swim_dynamics_free(&d);
    return rc;
}

/* DIR/sensitivity.csv after the trajectory, before the summary: a second integration, of the state
 * with its variational equations, by the same integrator at the same tolerances, up to where the
 * trajectory ended (t_end or a stopping event). Skipped when the trajectory failed or was
 * interrupted; a sensitivity pass that does not finish fails the run, so that the summary and the
 * exit status say so. */
static void run_sensitivity(run_ctx *c)
{
    c->sens_t = c->r.t_reached;
    if (c->r.status != 0 || c->outputs_bad) {
        c->sens_status = "skipped";
        swim_message(stderr, "swim run: no sensitivity.csv: the run did not complete");
        return;
    }
    if (c->impacts) {   /* the variational equations would need the impact's jump (a saltation matrix) */
        c->sens_status = "failed";
        stop(c, "no sensitivity.csv: the run took %ld bounce(s) off the barrier as impacts, "
                "across which sensitivities are not computed; set run.impact_depth = 0 to follow them", c->impacts);
        return;
    }
    swim_sens S;
    char *path = swim_strprintf("%s/sensitivity.csv", c->paths.dir);
    int rc = !path || swim_sens_init(&S, &c->d) != 0 ? 1 : swim_sens_add_list(&S, &c->s, "run", c->opt.sensitivity);
    double sec = 0.0;
    long evals = 0;
    S.error_control = !c->opt.sens_state_steps;
    if (rc == 0) {
        rc = swim_sens_write_run(&S, c->s.integrator, path, c->sens_t, &sec, &evals) ? 1 : 0;
        c->sens_rows = S.rows;
        c->sens_t_last = S.t_last;
    }
    if (rc == 0 && !c->opt.quiet)
        swim_message(stdout, "  sensitivities of %d key(s) in %s up to t = %.6g: %.3f s, %ld evaluations of the augmented RHS",
                     S.nkeys, path, c->sens_t, sec, evals);
    if (rc == 0) {
        c->sens_status = "written";
    } else if (swim_run_stop) {
        c->sens_status = "interrupted";
        stop(c, "interrupted (%s) during the sensitivities: sensitivity.csv is partial",
             swim_run_stop == SIGINT ? "SIGINT" : swim_run_stop == SIGTERM ? "SIGTERM" : "a signal");
    } else {
        c->sens_status = "failed";
        stop(c, "sensitivity.csv is incomplete: the sensitivities stopped before t = %.6g", c->sens_t);
    }
    if (path) swim_sens_free(&S);
    free(path);
}

int swim_cmd_run(int argc, char **argv)
{
    if (swim_stroke_requested(argc, argv)) return swim_cmd_stroke(argc, argv);   /* a prescribed stroke */
    run_ctx *c = calloc(1, sizeof *c);
    if (!c) {
        swim_message(stderr, "swim run: out of memory");
        return 1;
    }
    swim_run_signals sig;
    swim_run_stop = 0;
    int rc = read_options(argc, argv, c);
    if (rc == 0) rc = preflight_outputs(c);
    if (rc == 0) rc = acquire_kernels(c);
    if (rc == 0 && c->opt.sensitivity) rc = check_sensitivity(c);
    if (rc == 0) rc = open_outputs(c);
    if (rc == 0) {
        swim_run_signals_install(&sig);
        rc = prepare(c);
        if (rc == 0) {
            integrate(c);
            if (c->opt.sensitivity) run_sensitivity(c);
            rc = report(c);
        }
        swim_run_signals_restore(&sig);
    }
    release(c);
    return rc;
}
