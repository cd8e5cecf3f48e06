/* specialize.h -- kernels specialized to a scene's structure (issue 5).
 *
 * The structure of a scene is what decides the shape of its equations, not its values: N, which
 * coordinates are free, which locked coordinates are 0 (folded away), which effects are present
 * (free coordinates with R != 0, with D != 0, the barrier, the forcing law and the coordinates
 * it drives), plus the generator's own sources and the compiler flags. Its text is the cache key:
 * the kernel is generated (generator/generate.py --scene) and compiled to a shared object in
 * $SWIM_CACHE (default build/cache in the source tree) under a hash of the key, and reused while
 * the key is unchanged. Initial values, t_end, tolerances, densities and the values of R, cref,
 * D, epsilon, alpha are run-time parameters: changing them never regenerates.
 */
#ifndef SWIM_SPECIALIZE_H
#define SWIM_SPECIALIZE_H

#include <stddef.h>

#include "scene/scene.h"
#include "swim_kernel.h"

typedef struct {
    const swim_scene_kernel *kernel;
    void *handle;             /* dlopen handle, owned */
    char dir[1024];           /* cache folder of this structure */
    char source[1100];        /* its generated C file */
    int from_cache;
    double generate_seconds, compile_seconds;
} swim_specialized;

/* The structure key of a scene (see above); returns its length. */
int swim_specialize_key(const swim_scene *s, char *buf, size_t len);
/* Load from the cache or generate + compile. 0, or -1 after one line on stderr saying why. */
int swim_specialize(const swim_scene *s, swim_specialized *out, int verbose);
void swim_specialized_close(swim_specialized *sp);

#endif
