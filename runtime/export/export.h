/* export.h -- a self-contained source tree for one scene (swim export, docs/export.md).
 *
 * swim_export writes into req->out everything `make -C DIR` needs to build DIR/simulate with a C
 * compiler, GSL and LAPACK (and SUNDIALS when the scene's integrator or stiff fallback is a CVODE
 * one): the scene as exported (DIR/scene.toml, the overrides written in), the C of its two kernels
 * (the kernel of N modes and the scene's right-hand side or stroke laws, obtained as a run obtains
 * them: linked in, cached or generated now), the runtime's C it runs with (scene reader, driver,
 * output folder, integrators, shape, io), a replacement for codegen that hands out the
 * compiled-in kernels (runtime/export/kernels.c), the program (runtime/export/simulate.c), a
 * Makefile with the compiler and flags of the build that made this bin/swim, and a README. No
 * Python, SymPy, kernel cache or jansson is needed to build or run it. DIR/simulate runs the scene
 * as `swim run` does, to the last digit.
 *
 * The runtime's sources are taken from the source tree this program runs from (swim_share_dir):
 * an installed swim, which carries only the kernel headers, cannot export.
 */
#ifndef SWIM_EXPORT_EXPORT_H
#define SWIM_EXPORT_EXPORT_H

#include "scene/scene.h"

typedef struct {
    const char *cmd;              /* "export", for messages */
    const char *scene_file;
    const char *out;              /* the tree's folder: made, or an earlier export's, or empty */
    const swim_override *sets;    /* --set, applied before the scene is validated and written in */
    int nsets;
    int verbose;                  /* 1: progress of a kernel generation on stderr */
} swim_export_request;

typedef struct {
    int files;                    /* files written into the tree */
    long long bytes;              /* their size */
    int cvode;                    /* the tree links SUNDIALS by default (CVODE = yes) */
    int stroke;                   /* the scene is a prescribed stroke */
    int modes;
    char kernel_source[64];       /* where the kernel of N modes came from: "generated/", "cache", "generator" */
} swim_export_result;

/* 0; 1 (no kernel, a file that cannot be written) or 2 (bad input) with the cause in st. */
int swim_export(const swim_export_request *req, swim_export_result *res, swim_status *st);

#endif
