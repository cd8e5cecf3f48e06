/* The one table of scene keys (runtime/scene/keys.h) against what uses it:
 *   - models/README.md documents exactly the keys of the table;
 *   - every plain key absent from a scene takes its row's default, and a value outside its
 *     bounds is refused naming the key;
 *   - the kernel's structure key (codegen.h) changes with the keys marked STRUCTURE (a zero put
 *     into a vector, epsilon 0) and not with the values marked RUNTIME alone: those the kernel
 *     reads at run time, so sweeps, sensitivities and optimize never regenerate it;
 *   - the commands' numeric options (their own block): each row bounded and worded, and the hard
 *     limits of the code that runs them are the rows' limits. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "codegen/codegen.h"
#include "control/continuation.h"
#include "control/optimize.h"
#include "control/periodic.h"
#include "io/files.h"
#include "kernel/coords.h"
#include "scene/keys.h"
#include "scene/scene.h"

#define SCENE "models/selfpropelled.toml"

static char *read_text(const char *path)
{
    size_t len;
    char *t = swim_read_file(path, 1 << 20, &len);
    CHECK(t != NULL, "read %s", path);
    return t;
}

/* README's rows "| `[table] key` |" (and "| `title` |") against the table's. */
static void test_documented(void)
{
    char *readme = read_text("models/README.md");
    if (!readme) return;
    int count;
    const swim_scene_key *keys = swim_scene_keys(&count);
    CHECK(count > 25, "the table has every key (%d)", count);
    for (int i = 0; i < count; i++) {
        char row[96];
        const char *key = strcmp(keys[i].key, "*") == 0 ? (strcmp(keys[i].table, "stroke") == 0 ? "COORD" : "NAME") : keys[i].key;
        if (keys[i].table[0]) snprintf(row, sizeof row, "| `[%s] %s` |", keys[i].table, key);
        else snprintf(row, sizeof row, "| `%s` |", key);
        CHECK(strstr(readme, row) != NULL, "models/README.md documents %s", row);
        CHECK(keys[i].doc && keys[i].doc[0], "%s has a documentation line", row);
    }
    int rows = 0;
    for (const char *p = strstr(readme, "| `["); p; p = strstr(p + 1, "| `[")) {
        char table[32], key[32];
        if (sscanf(p, "| `[%31[^]]] %31[^`]`", table, key) != 2) continue;
        rows++;
        const swim_scene_key *k = swim_scene_key_find(table, key);
        CHECK(k != NULL, "the table has [%s] %s, which models/README.md documents", table, key);
    }
    CHECK(rows >= count - 1, "README rows found (%d)", rows);
    free(readme);
}

/* A scene with overrides, parsed; 0 when it loads. */
static int load(const char *text, const char *const *sets, int nsets, swim_scene *s)
{
    swim_override ov[8];
    for (int i = 0; i < nsets; i++) CHECK(swim_override_parse(sets[i], &ov[i], NULL, 0) == 0, "override %s", sets[i]);
    memset(s, 0, sizeof *s);
    return swim_scene_parse_with(text, strlen(text), SCENE, ov, nsets, s, NULL);
}

static void test_plain_defaults(void)
{
    char *text = read_text(SCENE);
    if (!text) return;
    swim_scene s;
    CHECK(load(text, NULL, 0, &s) == 0, "the scene loads");
    int count;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count; i++) {
        const swim_scene_key *k = &keys[i];
        if (!(k->flags & SWIM_KEY_PLAIN) || strstr(text, k->key)) continue;   /* absent from the file */
        const void *f = (const char *)&s + k->offset;
        const double v = k->kind == SWIM_KEY_NUMBER ? *(const double *)f : *(const int *)f;
        CHECK(v == k->dflt, "run.%s absent: its default %g (got %g)", k->key, k->dflt, v);
    }
    swim_scene_free(&s);
    /* outside the bounds: refused (one line on stderr, status 2) */
    const char *bad[] = {"run.step_lookahead=13", "run.impact_depth=1", "run.jacobian=newton"};
    for (int i = 0; i < 3; i++) {
        swim_scene t;
        CHECK(load(text, &bad[i], 1, &t) == 2, "%s refused", bad[i]);
    }
    free(text);
}

static char *structure_key(const char *text, const char *const *sets, int nsets)
{
    swim_scene s;
    if (load(text, sets, nsets, &s) != 0) return NULL;
    char *key = swim_codegen_scene_key(&s, 0);
    swim_scene_free(&s);
    return key;
}

static void test_structure_key(void)
{
    char *text = read_text("models/control/selfpropelled_params.toml");
    if (!text) return;
    char *base = structure_key(text, NULL, 0);
    CHECK(base != NULL, "the structure key of the scene");
    swim_scene s0;
    CHECK(load(text, NULL, 0, &s0) == 0, "the scene loads");
    int count, runtime = 0, structure = 0;
    const swim_scene_key *keys = swim_scene_keys(&count);
    for (int i = 0; i < count && base; i++) {
        const swim_scene_key *k = &keys[i];
        if (!(k->flags & (SWIM_KEY_RUNTIME | SWIM_KEY_STRUCTURE)) || (k->kind != SWIM_KEY_NUMBER && k->kind != SWIM_KEY_VECTOR))
            continue;
        if (strcmp(k->table, "shape") == 0) continue;   /* c0 must stay in D; its locks are structure, not values */
        char set[96];
        char item[16] = "";
        if (k->kind == SWIM_KEY_VECTOR) {   /* an item that is not 0 in the scene (of a free coordinate) */
            const double *vec = (const double *)((const char *)&s0 + k->offset);
            int at = -1;
            for (int j = s0.n - 1; j >= 0; j--)
                if (vec[j] != 0 && s0.free_mask[j]) at = j;
            CHECK(at >= 0, "%s.%s has a nonzero item", k->table, k->key);
            snprintf(item, sizeof item, "[%d]", at);
        }
        const char *name = strcmp(k->key, "*") == 0 ? "A" : k->key;
        /* a changed value; for a STRUCTURE key a zero, which removes a term from the kernel */
        snprintf(set, sizeof set, "%s.%s%s=%s", k->table, name, item, k->flags & SWIM_KEY_STRUCTURE ? "0" : "0.37");
        const char *sets[1] = {set};
        char *key = structure_key(text, sets, 1);
        CHECK(key != NULL, "%s loads", set);
        if (!key) continue;
        if (k->flags & SWIM_KEY_STRUCTURE) {
            CHECK(strcmp(key, base) != 0, "%s (STRUCTURE) changes the kernel's structure key", set);
            structure++;
        } else {
            CHECK(strcmp(key, base) == 0, "%s (RUNTIME) leaves the kernel's structure key as it is", set);
            runtime++;
        }
        free(key);
    }
    CHECK(runtime >= 4 && structure >= 4, "keys tried: %d run-time, %d structure", runtime, structure);
    swim_scene_free(&s0);
    free(base);
    free(text);
}

static void test_command_options(void)
{
    int n;
    const swim_scene_key *rows = swim_command_options(&n);
    CHECK(n >= 12, "the commands' options have rows (%d)", n);
    for (int i = 0; i < n; i++) {
        const swim_scene_key *k = &rows[i];
        CHECK(k->kind == SWIM_KEY_INTEGER || k->kind == SWIM_KEY_NUMBER, "%s --%s: a number", k->table, k->key);
        CHECK(k->lo < k->hi && k->expect && k->expect[0], "%s --%s: bounds lo < hi and their words", k->table, k->key);
        CHECK(swim_command_option(k->table, k->key) == k, "%s --%s: found by name, once", k->table, k->key);
        CHECK(!isfinite(k->hi) || k->dflt == 0 || (k->dflt >= k->lo && k->dflt <= k->hi), "%s --%s: default %g in bounds",
              k->table, k->key, k->dflt);
    }
    CHECK(swim_command_option("periodic", "max-iter")->hi == SWIM_PERIODIC_MAX_ITER, "periodic --max-iter: the solver's limit");
    CHECK(swim_command_option("continue", "max-points")->hi == SWIM_CONT_MAX_POINTS, "continue --max-points: the branch's limit");
    CHECK(swim_command_option("optimize", "starts")->hi == SWIM_OPT_MAX_STARTS, "optimize --starts: the search's limit");
    CHECK(swim_command_option("run", "lyapunov-interval")->lo > 0, "--lyapunov-interval: 0 refused");
    CHECK(swim_command_option("periodic", "t-max")->hi <= 1e6 && swim_command_option("floquet", "t-max")->hi <= 1e6,
          "--t-max bounded");
    CHECK(swim_command_option("run", "no-such-option") == NULL, "an option without a row: NULL");
}

int main(void)
{
    test_command_options();
    test_documented();
    test_plain_defaults();
    test_structure_key();
    return check_report("test_scene_keys");
}
