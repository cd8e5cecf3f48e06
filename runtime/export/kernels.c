/* kernels.c -- the kernels of an exported tree (swim export, runtime/export/export.h): the part of
 * codegen.h a run uses, handing out the kernels compiled into this program instead of generating,
 * compiling and caching them. Not part of bin/swim: `swim export` copies it into the tree, where
 * export_info.h (written by the export) says which kernels are linked in:
 *   SWIM_EXPORT_MODES        N, the kernel of N modes (swim_kernel_n<N>)
 *   SWIM_EXPORT_STROKE       1: the second kernel is a stroke's laws (swim_stroke_kernel_entry),
 *                            0: a scene's right-hand side (swim_scene_kernel_entry)
 *   SWIM_EXPORT_SYSTEM_DIR   the kernel cache entry it came from (summary.json: kernel.cache and
 *                            provenance.kernel_key, as a run that loads it from the cache says)
 * A scene whose structure is not the one of the compiled-in kernel (a --set that zeroes a
 * stiffness, frees a coordinate, changes the forcing law...) is refused with one line: the tree
 * has no kernel for it.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen/codegen.h"
#include "codegen/structure.h"
#include "export_info.h"
#include "io/message.h"

#define KERNEL_SYM_(n) swim_kernel_n##n
#define KERNEL_SYM(n) KERNEL_SYM_(n)
extern const swim_kernel KERNEL_SYM(SWIM_EXPORT_MODES);
#if SWIM_EXPORT_STROKE
extern const swim_stroke_kernel swim_stroke_kernel_entry;
#else
extern const swim_scene_kernel swim_scene_kernel_entry;
#endif

const swim_kernel *swim_kernel_find(int modes)
{
    return modes == SWIM_EXPORT_MODES ? &KERNEL_SYM(SWIM_EXPORT_MODES) : NULL;
}

int swim_kernel_list(int *modes, int cap)
{
    if (cap > 0) modes[0] = SWIM_EXPORT_MODES;
    return 1;
}

int swim_codegen_kernel(int modes, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
    if (!(out->kernel = swim_kernel_find(modes))) {
        swim_status_fail(st, "swim", NULL, 0, NULL, "this program has the kernel of N = %d modes only, not of N = %d",
                         SWIM_EXPORT_MODES, modes);
        return -1;
    }
    return 0;
}

/* Whether the compiled-in kernel's key ("scene {structure} abi=..." or "stroke {...} abi=...")
 * is for the structure text of s. */
static int same_structure(const char *key, const char *kind, char *structure)
{
    if (!structure) return 0;
    structure[strcspn(structure, "\n")] = '\0';
    const size_t k = strlen(kind), n = strlen(structure);
    const int same = strncmp(key, kind, k) == 0 && key[k] == ' ' && strncmp(key + k + 1, structure, n) == 0 &&
                     strncmp(key + k + 1 + n, " abi=", 5) == 0;
    free(structure);
    return same;
}

static void system_from_cache(swim_compiled *out)
{
    snprintf(out->dir, sizeof out->dir, "%s", SWIM_EXPORT_SYSTEM_DIR);
    snprintf(out->source, sizeof out->source, "%s/kernel.c", SWIM_EXPORT_SYSTEM_DIR);
    out->from_cache = 1;   /* as a run that finds it in the cache: generate and compile times 0 */
}

int swim_codegen_scene(const swim_scene *s, int generic, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
    out->generic = generic;
#if SWIM_EXPORT_STROKE
    swim_status_fail(st, "swim", s->path, 0, NULL, "%s: this program was exported for a prescribed stroke: it has no scene kernel", s->path);
    return -1;
#else
    if (!same_structure(swim_scene_kernel_entry.structure, "scene", swim_codegen_structure_text(s, generic, NULL))) {
        swim_status_fail(st, "swim", s->path, 0, NULL, "%s: the scene's structure (free and locked coordinates, effects, forcing law) is not "
                     "the one this program was exported for: export the scene again (swim export)", s->path);
        return -1;
    }
    out->scene = &swim_scene_kernel_entry;
    system_from_cache(out);
    return 0;
#endif
}

int swim_codegen_stroke(const swim_scene *s, swim_compiled *out, int verbose, swim_status *st)
{
    memset(out, 0, sizeof *out);
#if SWIM_EXPORT_STROKE
    if (!same_structure(swim_stroke_kernel_entry.structure, "stroke", swim_codegen_stroke_text(s, NULL))) {
        swim_status_fail(st, "swim", s->path, 0, NULL, "%s: the stroke's laws are not those this program was exported for: export the "
                     "scene again (swim export)", s->path);
        return -1;
    }
    out->stroke = &swim_stroke_kernel_entry;
    system_from_cache(out);
    return 0;
#else
    swim_status_fail(st, "swim", s->path, 0, NULL, "%s: this program was exported for a scene without [stroke]: it has no stroke kernel", s->path);
    return -1;
#endif
}

void swim_compiled_close(swim_compiled *c)
{
    c->kernel = NULL;
    c->scene = NULL;
    c->stroke = NULL;
}

/* As codegen.c's, with the compiled-in kernels: a structure they do not fit is bad input here
 * (2), since no kernel can be made for it. */
int swim_codegen_for_scene(const char *cmd, const swim_scene *s, int generic, int verbose, swim_compiled *kn, swim_compiled *sys,
                           swim_status *st)
{
    if (s->stroke_count > 0) {
        if (swim_codegen_kernel(s->modes, kn, verbose, st) != 0 || swim_codegen_stroke(s, sys, verbose, st) != 0) return 2;
        return 0;
    }
    if (swim_codegen_kernel(s->modes, kn, verbose, st) != 0 || swim_codegen_scene(s, generic, sys, verbose, st) != 0) return 2;
    return swim_scene_check_model(s, kn->kernel, st);
}
