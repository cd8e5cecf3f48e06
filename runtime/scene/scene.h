/* scene.h -- a simulation scene read from TOML (keys documented in models/README.md).
 *
 * swim_scene_load validates everything before any work: unknown keys, wrong types or lengths,
 * non-finite numbers, a shape outside D (4.1), initial velocities that violate G1 (2.8),
 * G2 (2.14) or the locks. Each problem is reported as one line on stderr,
 * "FILE:LINE: KEY: message (value)", and the call returns 2. With `project_initial = true`
 * in [run], an inconsistent initial velocity is instead projected onto the constraints (the
 * l2-orthogonal projection of ERRATA D5) and the change is reported on stderr.
 */
#ifndef SWIM_SCENE_H
#define SWIM_SCENE_H

#include <stddef.h>

#include "kernel/coords.h"
#include "kernel/swim_kernel.h"
#include "scene/expr.h"

#define SWIM_NMAX (2 * (SWIM_KERNEL_MAX_MODES + 1))

typedef struct {
    char path[512];
    char title[256];
    int modes, n;
    double rho0, rhof;
    int rhof_neutral;                 /* rhof = rho0 / mu^2 (2.10) */
    double c0[SWIM_NMAX], dc0[SWIM_NMAX];
    int free_mask[SWIM_NMAX];         /* 1 = free, 0 = locked (section 4.2.2) */
    int elastic;                      /* W1 = 1/2 (c - cref)^T R (c - cref) (ERRATA E2) */
    double stiffness[SWIM_NMAX], reference[SWIM_NMAX];
    int barrier;                      /* W2 with epsilon, alpha (section 4.1.1) */
    double epsilon, alpha;
    int damped;                       /* -D cdot with D diagonal (4.15) */
    double damping[SWIM_NMAX];
    int forced;                       /* F(t) = f(t) * direction (5.1) */
    swim_expr *forcing;
    char forcing_text[512];
    double direction[SWIM_NMAX];
    double t_end, output_step, rtol, atol;
    char integrator[32];
    char stiff_fallback[32];          /* integrator to switch to when ABM detects stiffness, or "" */
    int project_initial;
    int projection;                   /* drift control after each step (ABM), default on */
    int step_lookahead;               /* ABM step-size look-ahead p (swim_ode_options.lookahead); -1 = the integrator default */
    double projection_change;         /* max |change| of dc0 when projected */
    char events[32][128];             /* [events] list: "COLUMN:KIND[:stop]" entries (checked by swim run) */
    int nevents, events_line;         /* how many; the line of the list, for messages */
} swim_scene;

/* 0 on success; 2 after printing a one-line error naming the file, the key and the value. */
int swim_scene_load(const char *path, swim_scene *scene);
/* The same on text already in memory (len bytes, not necessarily NUL-terminated); `path` names
 * it in messages. */
int swim_scene_parse(const char *text, size_t len, const char *path, swim_scene *scene);
void swim_scene_free(swim_scene *scene);

/* An override `KEY=VALUE` (swim run --set, swim sweep --vary) applied to the parsed TOML tree
 * before the scene is validated, so an overridden value is checked like one in the file. KEY is
 * `table.key` (a number), `table.key[I]` (item I, 0-based, of a vector) or `table.key.NAME`
 * (the item of the shape coordinate NAME: a1, b1, am1, bm1, am2, ...), e.g. `run.t_end`,
 * `elastic.stiffness[4]`, `shape.dc0.bm2`, `barrier.epsilon`. */
typedef struct {
    char table[32], key[32];
    long index;          /* -1: the value itself */
    double value;
    char text[160];      /* KEY=VALUE as given, for messages */
} swim_override;

/* Parses KEY (the part before '=') into o->table, o->key, o->index. 0, or -1 with a reason. */
int swim_override_key(const char *key, swim_override *o, char *err, size_t errlen);
/* Parses KEY=VALUE (VALUE a finite number). 0, or -1 with a one-line reason in err. */
int swim_override_parse(const char *text, swim_override *o, char *err, size_t errlen);
/* swim_scene_load / swim_scene_parse with overrides applied first; an override that does not
 * fit the file (no such table, not a number, index out of range) is one line
 * "swim: FILE: --set KEY=VALUE: reason" and 2. */
int swim_scene_load_with(const char *path, const swim_override *ov, int nov, swim_scene *scene);
int swim_scene_parse_with(const char *text, size_t len, const char *path, const swim_override *ov,
                          int nov, swim_scene *scene);

/* Coordinate names, modes and mu^2: kernel/coords.h. */

#endif
