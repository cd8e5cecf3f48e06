/* problem.h -- a problem built once: a scene (a file, read once, or a text) with its overrides
 * turned into the validated scene, its kernels and its dynamics, in one place for every command
 * (swim run and in-process sweep members through output/job.h, floquet, periodic, continue,
 * optimize, export) and for libswim and Python.
 *
 * The stages are those every command had, in the same order, so that a scene refused by one is
 * refused by all with the same line: the scene read with its overrides and validated
 * (scene/scene.h: overrides applied before validation), the kernels (codegen/codegen.h:
 * swim_codegen_for_scene: the kernel of N modes and the scene's right-hand side or a stroke's
 * laws, linked in, cached or generated) with the magnitude check of the initial state, then the
 * dynamics on the scene kernel (model/dynamics.h). A command that judges the scene before any
 * kernel is made (a stroke refused, events checked) calls swim_problem_read, judges, then
 * swim_problem_kernels.
 *
 * Afterwards values are set through the key table (scene/keys.h) with swim_problem_set: no file
 * is read and no kernel is looked up again. The key's row decides:
 *   - a structure key that is no run-time value (model.modes, shape.free, forcing.law,
 *     stroke.*, elastic.energy) is refused with a status naming it;
 *   - any other key is validated as `--set KEY=VALUE` on the command line is (the scene reader's
 *     checks and messages, on the text kept in memory, into a scene of its own), then, when the
 *     kernel's structure is what it was, moved into the problem's scene where it is
 *     (swim_scene_take_values: the scene's compiled laws stay and read the new parameters); a
 *     value that changes it (a stiffness, damping or direction item made zero,
 *     barrier.epsilon = 0) is refused, unless the caller allows a new structure
 *     (SWIM_PROBLEM_RESTRUCTURE: swim optimize, whose ranges may reach such a value, then gets
 *     the kernels of that structure exactly as a fresh run would);
 *   - the magnitude check runs again with the kernel at hand; the dynamics follow the new scene.
 * A refused value leaves the problem as it was.
 *
 * Library code: no printing, no exit, no global state; failures fill the caller's status
 * (io/status.h) with the line a command shows. Return codes are the commands': 0; 2 bad input
 * (the cause in st); 1 no kernel could be had or out of memory. */
#ifndef SWIM_PROBLEM_H
#define SWIM_PROBLEM_H

#include <stddef.h>

#include "codegen/codegen.h"
#include "io/status.h"
#include "model/dynamics.h"
#include "scene/scene.h"

/* the overrides a problem carries: a command's --set list, the values set since */
#define SWIM_PROBLEM_MAX_SETS 128
/* the --set overrides floquet, periodic and continue take */
#define SWIM_PROBLEM_CLI_SETS 64

typedef struct swim_problem_s {
    swim_scene *s;               /* as validated: &own, or the caller's storage (source.into); never
                                    moved (scene.h: its compiled laws read its parameters in place),
                                    so a problem is not copied once loaded */
    swim_scene own;
    swim_compiled kn, spz;       /* the kernel of N modes; the scene's right-hand side or stroke laws */
    swim_dynamics d;             /* on s and kn, with the scene kernel (not for a stroke) */
    char *text;                  /* the scene's text, read once (owned), len bytes */
    size_t len;
    char *name;                  /* names the scene in messages (its path, or the caller's name) */
    swim_override sets[SWIM_PROBLEM_MAX_SETS];   /* the overrides in force, in the order given */
    int nsets;
    char *resolved;              /* with SWIM_PROBLEM_RESOLVE: the text with the overrides written in
                                    (scene/resolve.h), NULL without overrides */
    char *structure;             /* the kernels' structure (codegen/structure.h), once they are had */
    char cmd[32];                /* "swim CMD" of the kernels' messages */
    int generic, verbose, flags;
    int loaded, kernels, dyn_ready;   /* stages done */
} swim_problem;

enum {
    SWIM_PROBLEM_RESOLVE = 1,      /* keep `resolved` up to date (libswim's swim_model_scene_text) */
    SWIM_PROBLEM_RESTRUCTURE = 2   /* swim_problem_apply may get the kernels of a new structure */
};

/* Where a problem's scene comes from. */
typedef struct {
    const char *path;            /* the scene file, read once (refused as the reader refuses what is
                                    not a scene file) ... */
    const char *text;            /* ... or its text (len bytes, copied), path then NULL */
    size_t len;
    const char *name;            /* names the text in messages (NULL: path) */
    const swim_override *sets;   /* applied before the scene is validated (--set) */
    int nsets;
    int flags;                   /* SWIM_PROBLEM_RESOLVE, SWIM_PROBLEM_RESTRUCTURE */
    swim_scene *into;            /* the caller's storage for the scene (NULL: the problem's own) */
} swim_problem_source;

/* The scene of src, its overrides applied, validated. 0, or 2 with st (1 out of memory). */
int swim_problem_read(swim_problem *p, const swim_problem_source *src, swim_status *st);
/* The kernels of the scene (cmd names the command in "swim CMD: FILE: no kernel for this scene,
 * nothing computed"; generic and verbose: codegen.h), the magnitude check, the dynamics. 0; 1
 * when no kernel could be had or out of memory; 2 for a law the generator refuses or numbers
 * that overflow (st names the key). */
int swim_problem_kernels(swim_problem *p, const char *cmd, int generic, int verbose, swim_status *st);
/* swim_problem_read, then swim_problem_kernels. */
int swim_problem_open(swim_problem *p, const swim_problem_source *src, const char *cmd, int generic, int verbose,
                      swim_status *st);
/* KEY = VALUE set in place (KEY as `--set` takes it: table.key, table.key[I], table.key.COORD;
 * VALUE a number or a word), as described above. 0, or 2 with st naming the key (1 out of
 * memory or, with SWIM_PROBLEM_RESTRUCTURE, no kernel for the new structure). */
int swim_problem_set(swim_problem *p, const char *key, const char *value, swim_status *st);
/* Several overrides at once (each replaces one of the problem's that sets the same value),
 * validated together; flags adds to the problem's (SWIM_PROBLEM_RESTRUCTURE). Same returns. */
int swim_problem_apply(swim_problem *p, const swim_override *ov, int n, int flags, swim_status *st);
void swim_problem_close(swim_problem *p);

#endif
