/* structure.h -- a scene's kernel structure as the generator reads it (structure.json) and as the
 * kernel cache keys it: for a scene's right-hand side (N, carried and locked-at-zero coordinates,
 * effects, the forcing law's text) and for a prescribed stroke's laws. Plain text, no cache, no
 * generator: also compiled into the trees of `swim export` (runtime/export/), which check a
 * scene's structure against the kernel compiled into them. */
#ifndef SWIM_CODEGEN_STRUCTURE_H
#define SWIM_CODEGEN_STRUCTURE_H

#include "scene/scene.h"

/* The structure of the scene's right-hand side as one JSON object and a newline (malloc'd,
 * NULL when out of memory); with key != NULL a "key" field holds it, with key == NULL it is the
 * structure part of the key itself. generic: see codegen.h. */
char *swim_codegen_structure_text(const swim_scene *s, int generic, const char *key);
/* The same for the laws of the scene's [stroke]. */
char *swim_codegen_stroke_text(const swim_scene *s, const char *key);

#endif
