/* keys.h -- the one table of scene keys: for every key of a scene file, its table, name, kind,
 * the field of swim_scene it sets, its bounds and default, the command-line option that sets it
 * too, what the equations do with it, and its documentation line (models/README.md has the same
 * rows; a test compares them).
 *
 * Who reads the table:
 *   - the scene reader: the keys a table may hold, and every plain key (a boolean, an integer or
 *     a number in bounds, one of a few words) read, bounded and defaulted from its row;
 *   - `swim run`: every row with an option becomes that option, applied over the scene, checked
 *     by the row's bounds and written into DIR/scene.toml;
 *   - `--sensitivity` and `swim optimize --vary`: the keys whose values the equations read at run
 *     time (SWIM_KEY_RUNTIME), and where that value is in the scene;
 *   - the kernel cache: SWIM_KEY_STRUCTURE marks the keys that change a scene's kernel (its
 *     structure key, codegen.h); every other value is read at run time (a test checks both).
 *
 * A new plain run setting is a field in swim_scene (scene.h), a row here (with its option if it
 * has one) and its use in the run driver (driver/run.c): three files.
 */
#ifndef SWIM_SCENE_KEYS_H
#define SWIM_SCENE_KEYS_H

#include <stddef.h>

typedef enum {
    SWIM_KEY_BOOL,        /* true / false -> int */
    SWIM_KEY_INTEGER,     /* an integer in [lo, hi] -> int */
    SWIM_KEY_NUMBER,      /* a finite number -> double */
    SWIM_KEY_CHOICE,      /* one of words[] -> int (its index) */
    SWIM_KEY_VECTOR,      /* n numbers (one per shape coordinate) -> double[n] */
    SWIM_KEY_TEXT         /* a string, a law, a list of names or of events */
} swim_key_kind;

enum {
    SWIM_KEY_PLAIN = 1,       /* read from its row alone: kind, bounds (expect), default */
    SWIM_KEY_RUNTIME = 2,     /* a value the right-hand side reads at run time (sensitivities, optimize) */
    SWIM_KEY_INITIAL = 4,     /* an initial condition (sensitivities with respect to it) */
    SWIM_KEY_STRUCTURE = 8,   /* changes the kernel's structure (a zero pattern, a law, a count) */
    SWIM_KEY_REQUIRED = 16    /* the table must have it */
};

#include "scene/settings.h"

#define SWIM_KEY_NONE ((size_t)-1)   /* no field of its own (read by custom code) */

typedef struct {
    const char *table;            /* "" for the top level (title) */
    const char *key;
    swim_key_kind kind;
    size_t offset;                /* offsetof(swim_scene, field), or SWIM_KEY_NONE */
    double lo, hi;                /* bounds of a plain INTEGER or NUMBER (a NUMBER: [lo, hi)) */
    double dflt;                  /* the value when absent (plain kinds) */
    const char *words[4];         /* CHOICE: the words, NULL-terminated (the field gets the index) */
    const char *expect;           /* a plain key's bounds in words, for its message */
    const char *option;           /* `swim run --OPTION VALUE` sets it too (plain kinds), or NULL */
    unsigned flags;
    const char *doc;              /* one line for users */
} swim_scene_key;

/* The field of row k, a key of table "run" with a field of its own (k->offset points into
 * swim_scene.run), in the run settings set (scene/settings.h). */
void *swim_run_settings_field(swim_run_settings *set, const swim_scene_key *k);
const void *swim_run_settings_field_const(const swim_run_settings *set, const swim_scene_key *k);

/* Every key, in the order of models/README.md's table. *count gets their number. */
const swim_scene_key *swim_scene_keys(int *count);
/* The row of table.key, or NULL. */
const swim_scene_key *swim_scene_key_find(const char *table, const char *key);
/* The numeric options of the commands (their own block of rows: table = the command, key = the
 * option without "--", with bounds, default and `expect`): the row of `swim COMMAND --OPTION`, or
 * NULL; and all of them (*count). */
const swim_scene_key *swim_command_option(const char *command, const char *option);
const swim_scene_key *swim_command_options(int *count);
/* The keys of one table into names[] (at most cap, NULL-terminated): their count. */
int swim_scene_table_keys(const char *table, const char **names, int cap);
/* The tables a scene file may have, NULL-terminated. */
const char *const *swim_scene_tables(void);

/* The bounds of a numeric argument of the library (lib/swim.h): the row whose table is the
 * function's name and whose key is the argument's, or NULL. */
#define SWIM_LIB_MAX_EVENTS 32
#define SWIM_STR_(x) #x
#define SWIM_STR(x) SWIM_STR_(x)
const swim_scene_key *swim_library_arg(const char *function, const char *arg);

#endif
