/* scene.h -- a simulation scene read from TOML (keys documented in models/README.md).
 *
 * swim_scene_load validates everything before any work: unknown keys, wrong types or lengths,
 * non-finite numbers, a shape outside D (4.1), initial velocities that violate G1 (2.8),
 * G2 (2.14) or the locks. A problem fills the caller's status (io/status.h: file, line, key and
 * the line "swim: FILE:LINE: KEY: message (value)" a command shows) and the call returns 2;
 * nothing is printed here. With `project_initial = true` in [run], an inconsistent initial
 * velocity is instead projected onto the constraints (the l2-orthogonal projection of ERRATA D5)
 * and the change is a notice to the status's note callback.
 */
#ifndef SWIM_SCENE_H
#define SWIM_SCENE_H

#include <stddef.h>

#include "io/status.h"
#include "kernel/coords.h"
#include "kernel/swim_kernel.h"
#include "scene/expr.h"
#include "scene/settings.h"

#define SWIM_NMAX (2 * (SWIM_KERNEL_MAX_MODES + 1))
#define SWIM_PARAMS_MAX 32   /* names in [parameters] */

/* Bounds every run honours, whatever set the value (scene file or command line), checked in
 * one place, swim_run_settings_check:
 * - at most SWIM_ROWS_MAX output rows (t_end / output_step): 10^7 rows of a 16-mode scene are
 *   already ~10 GB of CSV;
 * - rtol in [SWIM_RTOL_MIN, SWIM_RTOL_MAX]: below 100 unit roundoffs (2.2e-14, ode113's floor)
 *   double precision cannot meet the error test; above 0.1 the local error estimate no longer
 *   bounds anything (rtol 10 "completes" with a 290 % energy error);
 * - atol in (0, SWIM_ATOL_MAX]: the states are O(1) (shape coefficients, positions), so an
 *   absolute tolerance above 0.1 would accept errors as large as the state itself. */
#define SWIM_ROWS_MAX 1e7
#define SWIM_RTOL_MIN 2.220446049250313e-14
#define SWIM_RTOL_MAX 0.1
#define SWIM_ATOL_MAX 0.1
/* Scene files are a few kB (the largest paper scene is ~1 kB); a file over 1 MiB is refused
 * before it is read, so a huge array cannot make the reader allocate gigabytes. */
#define SWIM_SCENE_MAX_BYTES (1L << 20)

/* The run settings, in the order of swim_run_settings_check's messages. */
enum { SWIM_SET_T_END, SWIM_SET_OUTPUT_STEP, SWIM_SET_RTOL, SWIM_SET_ATOL, SWIM_SET_LAW, SWIM_SET_COUNT };

typedef struct {
    char *path;                       /* the scene file as named (owned) */
    char *title;                      /* owned, "" when absent */
    int modes, n;
    double rho0, rhof;
    int rhof_neutral;                 /* rhof = rho0 / mu^2 (2.10) */
    double c0[SWIM_NMAX], dc0[SWIM_NMAX];
    int free_mask[SWIM_NMAX];         /* 1 = free, 0 = locked (section 4.2.2) */
    int elastic;                      /* W1 = 1/2 (c - cref)^T R (c - cref) (ERRATA E2) */
    double stiffness[SWIM_NMAX], reference[SWIM_NMAX];
    /* [elastic] energy: U(I1, J) of W = int_D U dz (ERRATA B5), in the law grammar with I1, J,
     * I1bar and [parameters] (scene/material.h); NULL when absent. energy_vars holds the values
     * the interpreted law reads: I1, J, I1bar, then the parameters (a copy of param_values). */
    char *energy_text;
    swim_expr *energy;
    int energy_line;
    double energy_vars[3 + SWIM_PARAMS_MAX];
    int barrier;                      /* W2 with epsilon, alpha (section 4.1.1) */
    double epsilon, alpha;
    int damped;                       /* -D cdot with D diagonal (4.15) */
    double damping[SWIM_NMAX];
    int forced;                       /* F(t) = f(t) * direction (5.1) */
    swim_expr *forcing;
    char *forcing_text;               /* the law as written (owned) */
    double direction[SWIM_NMAX];
    /* [run] as read from the file (its overrides included); nothing writes it after. The run
     * reads the settings its command resolved from it (scene/settings.h). */
    swim_run_settings run;
    double projection_change;         /* max |change| of dc0 when projected */
    int setting_line[SWIM_SET_COUNT]; /* line of each run setting in the file (0: absent) */
    int line_c0, line_dc0, line_rho0, line_rhof;  /* for swim_scene_check_model's messages */
    char events[32][128];             /* [events] list: "COLUMN:KIND[:stop]" entries (checked by swim run) */
    int nevents, events_line;         /* how many; the line of the list, for messages */
    /* [stroke]: a prescribed stroke (section 3.3): only (3.21) is integrated, the shape is given.
     * Coordinates not prescribed stay at c0, except c1, completed from (2.5) and (2.14) when
     * neither a1 nor b1 is prescribed. free_mask then marks the coordinates that move. */
    int stroke;                       /* a [stroke] table is present */
    int stroke_count;                 /* prescribed coordinates */
    int stroke_index[SWIM_NMAX];      /* their indices in the shape vector, in file order */
    char *stroke_law[SWIM_NMAX];      /* their laws as written (owned) */
    swim_expr *stroke_expr[SWIM_NMAX];/* the same, interpreted (checks; the run uses the kernel) */
    int stroke_line[SWIM_NMAX];       /* line of each law */
    double stroke_period;             /* [stroke] period, 0 when absent (then detected) */
    int stroke_period_line;
    int stroke_complete_c1;           /* c1 completed from the volume and (2.14) */
    /* [parameters]: named numbers the laws may use (A = 2, w = 0.3333). The kernels read their
     * values at run time (swim_scene_params.law_params), so changing a value (--set
     * parameters.A=3, a sweep, an optimizer) never regenerates a kernel; the names are part of
     * the structure key. The compiled law reads param_values in place (swim_expr_compile_params):
     * a loaded swim_scene is used where it was loaded, never copied by value. */
    int nparams, params_line;
    char param_names[SWIM_PARAMS_MAX][32];
    double param_values[SWIM_PARAMS_MAX];
    /* The overrides applied (swim_scene_parse_with), as given: a value an override set has the
     * "line" -(i + 1) in the line fields above, and messages name override i, not a line of a
     * file it never was on (swim_scene_where). */
    char **override_text;             /* nover strings (owned) */
    int nover;
} swim_scene;

/* Where a value of scene s came from, for a message: "FILE:LINE" for a line of the file,
 * "FILE: --set KEY=VALUE" for a value override -(line + 1) set, "FILE" for line 0 (no line).
 * Written to buf (n bytes, cut if longer); returns buf. */
const char *swim_scene_where(const swim_scene *s, int line, char *buf, size_t n);

/* "FILE:LINE: stroke.NAME" of the [stroke] law that prescribes coordinate `coord` (the first
 * law's when none does), for a message about that law. Written to buf; returns buf. */
const char *swim_scene_stroke_where(const swim_scene *s, int coord, char *buf, size_t n);

/* Which run settings came from the command line (nonzero: its messages name the option). */
typedef struct {
    int given[SWIM_SET_COUNT];
} swim_run_overrides;

/* 0 on success; 2 with st naming the file, the key and the value. */
int swim_scene_load(const char *path, swim_scene *scene, swim_status *st);
/* The scene file's text, read once into a new buffer (NUL-terminated, *len bytes), refused
 * before reading when it is not a regular file of at most SWIM_SCENE_MAX_BYTES: for a command
 * that parses one scene many times (swim sweep), so that every parse sees the same text even if
 * the file is edited meanwhile. NULL with the reason in st. */
char *swim_scene_read(const char *path, size_t *len, swim_status *st);
/* The same on text already in memory (len bytes, not necessarily NUL-terminated); `path` names
 * it in messages. */
int swim_scene_parse(const char *text, size_t len, const char *path, swim_scene *scene, swim_status *st);
void swim_scene_free(swim_scene *scene);
/* The values of `from` (a scene read from the same text, with other overrides) moved into
 * `scene` where it is: scene keeps its own compiled laws, which read its parameters in place and
 * now see the new values; from gets scene's former values (free it after). 0, or -1 when the two
 * differ in their laws or parameter names (their structure), and nothing is moved. */
int swim_scene_take_values(swim_scene *scene, swim_scene *from);

/* The one check of the run settings `set` of scene s (its own [run], as the reader checks it,
 * or the settings a command resolved from it), whatever set them: the row cap and the tolerance
 * bounds above, and the laws on the run's interval [0, t_end], before any kernel is asked for. A
 * law is finite at t when every part of it is (swim_expr_defined: step(sqrt(-1)) is not). The
 * forcing law not finite at t0 is an error; the first sampled time where it is not finite later
 * is recorded in set->forcing_finite_until (the run stops there). A stroke law not finite at t0
 * or at any sample is an error naming its key (stroke.am1). 0, or 2 with st naming the scene key
 * (FILE:LINE: run.rtol: ...) or, for a setting in `cli`, the option (swim run: --rtol: ...).
 * cli may be NULL. */
int swim_run_settings_check(const swim_scene *s, swim_run_settings *set, const swim_run_overrides *cli, swim_status *st);

/* The model's numbers at a state must leave room for the products the right-hand side forms
 * (K v, v^T K v, the constrained solve of (4.12)): every entry of Mr, N, Md, K, <Gamma, v, v>
 * and the kinetic energy must be finite and at most SWIM_MAGNITUDE_MAX in size, so that a
 * product of two of them is still a double. */
#define SWIM_MAGNITUDE_MAX 1e150
enum { SWIM_INPUT_OK, SWIM_INPUT_SHAPE, SWIM_INPUT_RHO0, SWIM_INPUT_RHOF, SWIM_INPUT_VELOCITY };
/* Which input puts the model beyond SWIM_MAGNITUDE_MAX at shape c, velocity v (may be NULL),
 * densities rho0, rhof: the first of shape (at unit densities, rest), rho0, rhof, velocity
 * whose own value does it, or SWIM_INPUT_OK. Used by the scene reader and by swim inspect. */
int swim_model_overflow(const swim_kernel *k, const double *c, const double *v, double rho0, double rhof);
/* swim_model_overflow on the scene's initial state with k, its kernel of N modes (which may
 * have to be generated, so the scene reader cannot run it): 0, or 2 with st naming the file,
 * line and key (shape.c0, model.rho0, model.rhof, shape.dc0). Every command that computes with
 * a scene calls it before any output is touched. */
int swim_scene_check_model(const swim_scene *s, const swim_kernel *k, swim_status *st);
/* An override `KEY=VALUE` (swim run --set, swim sweep --vary) applied to the parsed TOML tree
 * before the scene is validated, so an overridden value is checked like one in the file. KEY is
 * `table.key` (a number), `table.key[I]` (item I, 0-based, of a vector) or `table.key.NAME`
 * (the item of the shape coordinate NAME: a1, b1, am1, bm1, am2, ...), e.g. `run.t_end`,
 * `elastic.stiffness[4]`, `shape.dc0.bm2`, `barrier.epsilon`. */
typedef struct {
    char table[32], key[32];
    long index;          /* -1: the value itself */
    double value;
    char text[160];      /* KEY=VALUE as given, for messages ("--set KEY=VALUE"); a text that
                            starts with "--" names the option it came from itself */
    char word[32];       /* a VALUE that is a word rather than a number (run.jacobian=differences):
                            set as a string; "" for a number */
} swim_override;

/* Parses KEY (the part before '=') into o->table, o->key, o->index. 0, or -1 with a reason. */
int swim_override_key(const char *key, swim_override *o, char *err, size_t errlen);
/* Parses KEY=VALUE (VALUE a finite number, or a word of letters, digits, '-' and '_' that is
 * set as a string). 0, or -1 with a one-line reason in err. */
int swim_override_parse(const char *text, swim_override *o, char *err, size_t errlen);
/* The value an override sets, spelled one way: TABLE.KEY, or TABLE.KEY[I] for an item
 * (shape.c0.am1 and shape.c0[2] both name shape.c0[2]). */
void swim_override_target(const swim_override *o, char *buf, size_t len);
/* 1 when a and b set one value: the same table and key, and the same item or one of them the
 * whole key. Commands that take several overrides compare them with this, never by their text,
 * or two spellings of one key would both be accepted and one of them silently lost. */
int swim_override_same_target(const swim_override *a, const swim_override *b);
/* The first override of ov[0..n) that sets a value an earlier one sets differently (another
 * value, or the whole key against one item): its index, with the earlier one's in *earlier; or
 * -1. Given twice with the same value, an override is not ambiguous and not a conflict. */
int swim_override_conflict(const swim_override *ov, int n, int *earlier);
/* swim_scene_load / swim_scene_parse with overrides applied first; an override that does not
 * fit the file (no such table, not a number, index out of range) or that conflicts with an
 * earlier one (swim_override_conflict) is 2 with the line "swim: FILE: --set KEY=VALUE: reason"
 * in st. */
int swim_scene_load_with(const char *path, const swim_override *ov, int nov, swim_scene *scene, swim_status *st);
int swim_scene_parse_with(const char *text, size_t len, const char *path, const swim_override *ov,
                          int nov, swim_scene *scene, swim_status *st);

/* Coordinate names, modes and mu^2: kernel/coords.h. */

#endif
