#include "problem/problem.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen/structure.h"
#include "scene/keys.h"
#include "scene/resolve.h"

/* ---- the scene ------------------------------------------------------------------------------- */

/* The problem's text with the overrides sets[0..nsets) read into s: 0, or 2 with st. */
static int scene_read(const swim_problem *p, const swim_override *sets, int nsets, swim_scene *s, swim_status *st)
{
    return swim_scene_parse_with(p->text, p->len, p->name, sets, nsets, s, st) != 0 ? 2 : 0;
}

/* The text with sets written in (SWIM_PROBLEM_RESOLVE), or NULL without any: 0, or 2 with st
 * (key: the override being set, NULL when opening). */
static int resolve(const swim_problem *p, const swim_override *sets, int nsets, const char *key, char **out,
                   swim_status *st)
{
    *out = NULL;
    if (!(p->flags & SWIM_PROBLEM_RESOLVE) || nsets == 0) return 0;
    size_t outlen;
    char why[512];
    if (swim_scene_resolve(p->text, p->len, p->name, sets, nsets, out, &outlen, why, sizeof why) != 0) {
        swim_status_fail(st, "swim", p->name, 0, key, "%s: %s", p->name, why);
        return 2;
    }
    return 0;
}

int swim_problem_read(swim_problem *p, const swim_problem_source *src, swim_status *st)
{
    memset(p, 0, sizeof *p);
    p->flags = src->flags;
    p->s = src->into ? src->into : &p->own;
    const char *name = src->name ? src->name : src->path;
    if (src->path) {
        p->text = swim_scene_read(src->path, &p->len, st);   /* the one read of the file */
        if (!p->text) return 2;
    } else if ((p->text = malloc(src->len + 1))) {
        memcpy(p->text, src->text, src->len);
        p->text[src->len] = '\0';
        p->len = src->len;
    }
    if (!p->text || !(p->name = strdup(name))) {
        swim_status_fail(st, "swim", name, 0, NULL, "%s: out of memory", name);
        return 1;
    }
    if (src->nsets > SWIM_PROBLEM_MAX_SETS) {
        swim_status_fail(st, "swim", name, 0, NULL, "%s: more than %d overrides", name, SWIM_PROBLEM_MAX_SETS);
        return 2;
    }
    if (src->nsets > 0) memcpy(p->sets, src->sets, sizeof *src->sets * (size_t)src->nsets);
    p->nsets = src->nsets;
    if (scene_read(p, p->sets, p->nsets, p->s, st)) return 2;
    p->loaded = 1;
    return resolve(p, p->sets, p->nsets, NULL, &p->resolved, st);
}

/* ---- kernels and dynamics -------------------------------------------------------------------- */

/* The kernel structure of s as the cache keys it (codegen/structure.h), malloc'd or NULL. */
static char *structure_of(const swim_scene *s, int generic)
{
    return s->stroke_count > 0 ? swim_codegen_stroke_text(s, NULL) : swim_codegen_structure_text(s, generic, NULL);
}

/* The dynamics on p->s (d->scene points at it): 0, or 1 out of memory. */
static int dynamics_open(swim_problem *p, swim_status *st)
{
    if (swim_dynamics_init(&p->d, p->s, p->kn.kernel) != 0) {
        swim_status_fail(st, p->cmd, NULL, 0, NULL, "out of memory");
        return 1;
    }
    p->dyn_ready = 1;
    if (!p->s->stroke_count) swim_dynamics_use_scene_kernel(&p->d, p->spz.scene, p->generic);
    return 0;
}

static void dynamics_close(swim_problem *p)
{
    if (p->dyn_ready) swim_dynamics_free(&p->d);
    p->dyn_ready = 0;
}

int swim_problem_kernels(swim_problem *p, const char *cmd, int generic, int verbose, swim_status *st)
{
    snprintf(p->cmd, sizeof p->cmd, "swim %s", cmd);
    p->generic = generic;
    p->verbose = verbose;
    const int rc = swim_codegen_for_scene(cmd, p->s, generic, verbose, &p->kn, &p->spz, st);
    if (rc) return rc;
    if (!(p->structure = structure_of(p->s, generic))) {
        swim_status_fail(st, p->cmd, NULL, 0, NULL, "out of memory");
        return 1;
    }
    p->kernels = 1;
    return dynamics_open(p, st);
}

int swim_problem_open(swim_problem *p, const swim_problem_source *src, const char *cmd, int generic, int verbose,
                      swim_status *st)
{
    const int rc = swim_problem_read(p, src, st);
    return rc ? rc : swim_problem_kernels(p, cmd, generic, verbose, st);
}

/* ---- values set in place --------------------------------------------------------------------- */

/* "KEY" of an override's "KEY=VALUE" (its text as given), for the status. */
static void key_of(const swim_override *o, char *buf, size_t n)
{
    const size_t k = strcspn(o->text, "=");
    snprintf(buf, n, "%.*s", (int)(k < n ? k : n - 1), o->text);
}

/* The key's row refuses a value set in place: a structure key that is no run-time value. */
static int structure_only(const swim_problem *p, const swim_override *o, swim_status *st)
{
    const swim_scene_key *row = swim_scene_key_find(o->table, o->key);
    if (!row || !(row->flags & SWIM_KEY_STRUCTURE) || (row->flags & SWIM_KEY_RUNTIME)) return 0;
    char key[128];
    key_of(o, key, sizeof key);
    swim_status_fail(st, "swim", p->name, 0, key, "%s: --set %s: %s.%s is a structure key (%s): it is given when the "
                     "model is opened, not set in place", p->name, o->text, o->table, o->key, row->doc);
    return 2;
}

int swim_problem_apply(swim_problem *p, const swim_override *ov, int n, int flags, swim_status *st)
{
    flags |= p->flags;
    for (int i = 0; i < n; i++)
        if (!(flags & SWIM_PROBLEM_RESTRUCTURE) && structure_only(p, &ov[i], st)) return 2;
    /* the problem's overrides with these in place of any that set the same value */
    swim_override *sets = malloc(sizeof *sets * SWIM_PROBLEM_MAX_SETS);
    if (!sets) {
        swim_status_fail(st, "swim", p->name, 0, NULL, "%s: out of memory", p->name);
        return 1;
    }
    int nsets = 0;
    for (int i = 0; i < p->nsets; i++) {
        int replaced = 0;
        for (int j = 0; j < n; j++)
            replaced |= swim_override_same_target(&p->sets[i], &ov[j]) && p->sets[i].index == ov[j].index;
        if (!replaced) sets[nsets++] = p->sets[i];
    }
    char key[128] = "";
    if (n > 0) key_of(&ov[n - 1], key, sizeof key);
    if (nsets + n > SWIM_PROBLEM_MAX_SETS) {
        swim_status_fail(st, "swim", p->name, 0, key, "%s: more than %d overrides", p->name, SWIM_PROBLEM_MAX_SETS);
        free(sets);
        return 2;
    }
    for (int j = 0; j < n; j++) sets[nsets++] = ov[j];

    /* read and checked on a scene of its own: the problem is as it was until all is well */
    swim_scene *s = calloc(1, sizeof *s);
    char *resolved = NULL, *now = NULL;
    swim_compiled kn = {0}, spz = {0};
    int rc = !s ? 1 : scene_read(p, sets, nsets, s, st), restructured = 0, parsed = s && rc == 0;
    if (!s) swim_status_fail(st, "swim", p->name, 0, NULL, "%s: out of memory", p->name);
    if (rc == 0 && p->kernels) {
        /* against the structure the kernels were had for (a run may have written into p->s) */
        const char *was = p->structure;
        now = structure_of(s, p->generic);
        if (!now) {
            swim_status_fail(st, "swim", p->name, 0, NULL, "%s: out of memory", p->name);
            rc = 1;
        } else if (strcmp(was, now) != 0 && !(flags & SWIM_PROBLEM_RESTRUCTURE)) {
            const swim_scene_key *row = n > 0 ? swim_scene_key_find(ov[n - 1].table, ov[n - 1].key) : NULL;
            swim_status_fail(st, "swim", p->name, 0, key, "%s: --set %s: the value changes the kernel's "
                             "structure%s%s%s: it is given when the model is opened, not set in place", p->name,
                             n > 0 ? ov[n - 1].text : "", row ? " (" : "", row ? row->doc : "", row ? ")" : "");
            rc = 2;
        } else if (strcmp(was, now) != 0) {
            /* the kernels of the new structure, as a fresh run of this scene gets them */
            rc = swim_codegen_for_scene(p->cmd + 5, s, p->generic, p->verbose, &kn, &spz, st);
            restructured = rc == 0;
        } else if (s->stroke_count == 0) {
            /* the magnitude check opening the problem made with the kernel (codegen_for_scene's) */
            rc = swim_scene_check_model(s, p->kn.kernel, st);
        }
    }
    if (rc == 0) rc = resolve(p, sets, nsets, key, &resolved, st);
    if (rc) {
        free(now);
        if (parsed) swim_scene_free(s);
        free(s);
        swim_compiled_close(&spz);
        swim_compiled_close(&kn);
        free(sets);
        return rc;
    }
    /* kept, in place: the values move into the problem's scene, whose compiled laws read its
     * parameters where they are; the dynamics follow it */
    dynamics_close(p);
    if (swim_scene_take_values(p->s, s) != 0) {   /* other laws (a new structure): the scene read again */
        swim_status quiet = {0};   /* its notices were given by the read above */
        swim_scene_free(p->s);
        p->loaded = scene_read(p, sets, nsets, p->s, &quiet) == 0;
    }
    swim_scene_free(s);
    free(s);
    if (restructured) {
        swim_compiled_close(&p->spz);
        swim_compiled_close(&p->kn);
        p->kn = kn;
        p->spz = spz;
        free(p->structure);
        p->structure = now;
    } else {
        free(now);
    }
    memcpy(p->sets, sets, sizeof *sets * (size_t)nsets);
    p->nsets = nsets;
    free(sets);
    if (p->flags & SWIM_PROBLEM_RESOLVE) {
        free(p->resolved);
        p->resolved = resolved;
    }
    if (!p->loaded) {   /* the text and values just read: memory */
        swim_status_fail(st, "swim", p->name, 0, NULL, "%s: out of memory", p->name);
        return 1;
    }
    return p->kernels ? dynamics_open(p, st) : 0;
}

int swim_problem_set(swim_problem *p, const char *key, const char *value, swim_status *st)
{
    swim_override ov;
    char text[sizeof ov.text], why[256];
    if (snprintf(text, sizeof text, "%s=%s", key, value) >= (int)sizeof text) {
        swim_status_fail(st, "swim", p->name, 0, key, "%s: %s=%s: longer than the %zu characters of an override",
                         p->name, key, value, sizeof text - 1);
        return 2;
    }
    if (swim_override_parse(text, &ov, why, sizeof why) != 0) {
        swim_status_fail(st, "swim", p->name, 0, key, "%s: --set: %s", p->name, why);
        return 2;
    }
    return swim_problem_apply(p, &ov, 1, 0, st);
}

void swim_problem_close(swim_problem *p)
{
    dynamics_close(p);
    swim_compiled_close(&p->spz);   /* after the dynamics, which point into the kernels */
    swim_compiled_close(&p->kn);
    if (p->loaded) swim_scene_free(p->s);
    free(p->text);
    free(p->name);
    free(p->resolved);
    free(p->structure);
    memset(p, 0, sizeof *p);
}
